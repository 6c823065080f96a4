"""libgazebo_ros_vacuum_gripper.so (core/manipulation/vacuum_gripper.py): switched on, the pad pulls a box whose
top lies 1 cm below it and lifts it 0.2 m; switched off, the box falls; out of reach, nothing is pulled; the
services answer as upstream's; a missing link refuses the spawn."""
import pytest
from sensor_fixtures import plugin_of, world_simulation

from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.errors import ConfigError
from mbot_sim_bridge.core.manipulation.vacuum_gripper import VacuumGripper

PAD_HEIGHT = 0.3  # m, the pad's lower face above the ground at the start
BOX = 0.03  # m, the cube's side
# A pad on a vertical slide, its link frame on the pad's lower face.
LIFT = """<robot name="lift">
  <link name="world"/>
  <link name="base"><inertial><mass value="5"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="mount" type="fixed"><parent link="world"/><child link="base"/></joint>
  <link name="pad">
    <inertial><mass value="0.5"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.005"/><geometry><box size="0.04 0.04 0.01"/></geometry></collision>
  </link>
  <joint name="slide" type="prismatic"><parent link="base"/><child link="pad"/><origin xyz="0 0 {height}"/>
    <axis xyz="0 0 1"/><limit lower="-0.5" upper="0.5" effort="200" velocity="1"/></joint>
  <gazebo><plugin name="vacuum" filename="libgazebo_ros_vacuum_gripper.so">
    <bodyName>{body}</bodyName><topicName>grasping</topicName>
  </plugin></gazebo>
</robot>"""
CUBE = """<model name="cube"><pose>{x} 0 {z} 0 0 0</pose><link name="link">
  <inertial><mass>0.1</mass><inertia><ixx>2e-5</ixx><iyy>2e-5</iyy><izz>2e-5</izz></inertia></inertial>
  <collision name="c"><geometry><box><size>{side} {side} {side}</size></box></geometry></collision>
</link></model>"""


def spawn(tmp_path, gap=0.01, x=0.0, body="pad"):
    """The lift and a cube on a stand of its own height, its top ``gap`` below the pad."""
    top = PAD_HEIGHT - gap
    stand = f"""<model name="stand"><static>true</static><pose>{x} 0 {(top - BOX) / 2} 0 0 0</pose><link name="link">
      <collision name="c"><geometry><box><size>0.1 0.1 {top - BOX}</size></box></geometry></collision>
    </link></model>"""
    sim = world_simulation(tmp_path, stand, CUBE.format(x=x, z=top - BOX / 2, side=BOX))
    spawned = sim.spawn_robot(parse_robot(LIFT.format(height=PAD_HEIGHT, body=body), "model 'lift'"), "lift")
    spawned.robot.set_joint_position("slide", 0.0, 200.0)
    sim.step(200)
    return sim, spawned, plugin_of(spawned, VacuumGripper)


def cube_height(sim):
    return sim.engine.model_pose("cube").position[2]


def lift(sim, spawned, height, seconds=1.0):
    for step in range(1, int(seconds * 100) + 1):
        spawned.robot.set_joint_position("slide", height * step / (seconds * 100), 200.0)
        sim.step(10)


def test_the_pad_lifts_a_box_from_1_cm_below_and_drops_it_when_off(tmp_path):
    sim, spawned, plugin = spawn(tmp_path)
    try:
        start = cube_height(sim)
        assert plugin.switch(True) == "gazebo_ros_vacuum_gripper: status: off -> on"
        sim.step(300)
        assert plugin.grasping
        lift(sim, spawned, 0.2)
        sim.step(300)
        assert cube_height(sim) - start == pytest.approx(0.2 + 0.01, abs=0.01)  # lifted, up against the pad
        assert plugin.switch(False) == "gazebo_ros_vacuum_gripper: status: on -> off"
        sim.step(500)
        assert not plugin.grasping
        assert cube_height(sim) < start + 0.01  # fell back onto its stand
    finally:
        sim.close()


def test_out_of_reach_nothing_is_pulled_and_the_services_say_so(tmp_path):
    sim, spawned, plugin = spawn(tmp_path, x=0.2)
    try:
        start = sim.engine.model_pose("cube").position
        assert plugin.switch(False) == "gazebo_ros_vacuum_gripper: already status is 'off'"
        plugin.switch(True)
        assert plugin.switch(True) == "gazebo_ros_vacuum_gripper: already status is 'on'"
        sim.step(500)
        assert not plugin.grasping
        assert sim.engine.model_pose("cube").position == pytest.approx(start, abs=1e-3)
    finally:
        sim.close()


def test_a_missing_link_refuses_the_spawn(tmp_path):
    with pytest.raises(ConfigError, match="bodyName: link named: suction_cup does not exist"):
        spawn(tmp_path, body="suction_cup")
