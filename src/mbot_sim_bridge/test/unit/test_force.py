"""libgazebo_ros_force.so (core/manipulation/force.py): a Wrench pushes its link in the world frame at the centre of
mass until another replaces it; the plugin's tags are checked; NaN, inf and huge wrenches leave the world as it
was."""
import math

import pytest
from sensor_fixtures import plugin_of, world_simulation

from mbot_sim_bridge.core.errors import ConfigError
from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy, yaw
from mbot_sim_bridge.core.manipulation.force import Force
from mbot_sim_bridge.core.description.robot_model import parse_robot

PUCK_MASS, GRAVITY = 2.0, 9.8
# A puck resting on the ground, its link pushed by the plugin; friction 0 on the puck so a push slides it.
PUCK = """<robot name="puck">
  <link name="puck">
    <inertial><mass value="{mass}"/><inertia ixx="0.02" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><cylinder radius="0.1" length="0.1"/></geometry></collision>
  </link>
  <gazebo reference="puck"><mu1>0</mu1><mu2>0</mu2></gazebo>
  <gazebo><plugin name="push" filename="libgazebo_ros_force.so">
    <bodyName>{body}</bodyName><topicName>puck_force</topicName>
  </plugin></gazebo>
</robot>"""


def spawn(tmp_path, body="puck"):
    sim = world_simulation(tmp_path)
    spawned = sim.spawn_robot(parse_robot(PUCK.format(mass=PUCK_MASS, body=body), "model 'puck'"), "puck",
                              pose_from_xyz_rpy((0, 0, 0.05), (0, 0, 0)))
    sim.step(200)
    return sim, spawned, plugin_of(spawned, Force)


def test_a_force_accelerates_its_link_as_newton_says_until_replaced(tmp_path):
    sim, spawned, plugin = spawn(tmp_path)
    try:
        start = spawned.robot.root_pose().position
        plugin.set_wrench((1.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        sim.step(1000)  # 1 s at 0.5 m/s²: 0.25 m
        moved = spawned.robot.root_pose().position[0] - start[0]
        assert moved == pytest.approx(0.5 * (1.0 / PUCK_MASS) * 1.0 ** 2, rel=0.05)
        plugin.set_wrench((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        speed = spawned.robot.root_velocity()[0][0]
        sim.step(500)
        assert 0.9 * speed < spawned.robot.root_velocity()[0][0] <= speed  # coasts (Bullet's damping), no push
    finally:
        sim.close()


def test_a_torque_turns_the_link_about_the_world_z(tmp_path):
    sim, spawned, plugin = spawn(tmp_path)
    try:
        plugin.set_wrench((0.0, 0.0, 0.0), (0.0, 0.0, 0.02))
        sim.step(500)
        assert spawned.robot.root_velocity()[1][2] > 0.3  # 1 rad/s² for 0.5 s
        assert yaw(spawned.robot.root_pose().orientation) > 0.05
    finally:
        sim.close()


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf, 1e308, -1e7])
def test_nan_inf_and_huge_wrenches_are_refused_and_the_world_stays(tmp_path, value):
    sim, spawned, plugin = spawn(tmp_path)
    try:
        resting = spawned.robot.root_pose().position
        for index in range(6):
            wrench = [0.0] * 6
            wrench[index] = value
            assert plugin.set_wrench(wrench[:3], wrench[3:]) is not None
        sim.step(500)
        assert math.dist(spawned.robot.root_pose().position, resting) < 1e-3
        assert (plugin.force, plugin.torque) == ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    finally:
        sim.close()


def test_an_unknown_body_refuses_the_spawn(tmp_path):
    with pytest.raises(ConfigError, match="bodyName: link named: wheel does not exist"):
        spawn(tmp_path, body="wheel")
