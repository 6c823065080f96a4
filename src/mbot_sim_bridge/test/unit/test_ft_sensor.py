"""libgazebo_ros_ft_sensor.so (core/sensors/ft_sensor.py): a load hanging from a wrist reads its weight and moment
within 2 %, in the child link's frame and with Gazebo's sign (the load's pull on the joint); a load resting on the
ground reads nothing; a sensor on a fixed joint is refused as Gazebo's "does not exist"; noise is seeded."""
import numpy as np
import pytest
from sensor_fixtures import plugin_of, world_simulation

from mbot_sim_bridge.core.errors import ConfigError
from mbot_sim_bridge.core.sensors.ft_sensor import FTSensor
from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy, rotation_matrix
from mbot_sim_bridge.core.description.robot_model import parse_robot

MASS, GRAVITY = 2.0, np.array([0.0, 0.0, -9.8])
CENTRE = np.array([0.1, 0.0, -0.2])  # the load's centre of mass in its own (the child's) frame
WRIST = """<robot name="wrist">
  <link name="stand">
    <inertial><mass value="200"/><inertia ixx="10" iyy="10" izz="10" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.05"/><geometry><box size="1 1 0.1"/></geometry></collision>
  </link>
  <link name="load">
    <inertial><origin xyz="{centre}"/><mass value="{mass}"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="{centre}"/><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <joint name="wrist_joint" type="{joint_type}"><parent link="stand"/><child link="load"/>
    <origin xyz="0 0 {height}" rpy="{rpy}"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="100" velocity="1"/></joint>
  <gazebo><plugin name="wrist_ft" filename="libgazebo_ros_ft_sensor.so">
    <jointName>wrist_joint</jointName><topicName>wrist_wrench</topicName><gaussianNoise>{noise}</gaussianNoise>
  </plugin></gazebo>
</robot>"""


def wrist(tmp_path, rpy="0 0 0", joint_type="revolute", height=1.0, noise=0.0, seed=0):
    sim = world_simulation(tmp_path, seed=seed)
    urdf = WRIST.format(centre=" ".join(map(str, CENTRE)), mass=MASS, joint_type=joint_type, height=height,
                        rpy=rpy, noise=noise)
    spawned = sim.spawn_robot(parse_robot(urdf, "model 'wrist'"), "wrist")
    return sim, spawned, plugin_of(spawned, FTSensor)


def hanging_load_reading(rpy):
    """What Gazebo reports for the load at rest: its weight and its moment about the joint, child frame."""
    rotation = np.asarray(rotation_matrix(pose_from_xyz_rpy((0, 0, 0), rpy).orientation))
    weight = rotation.T @ (MASS * GRAVITY)
    return weight, np.cross(CENTRE, weight)


@pytest.mark.parametrize("rpy", [(0.0, 0.0, 0.0), (1.5708, 0.0, 0.3)])
def test_a_hanging_load_reads_its_weight_and_moment_in_the_child_frame(tmp_path, rpy):
    sim, spawned, sensor = wrist(tmp_path, " ".join(map(str, rpy)))
    spawned.robot.set_joint_position("wrist_joint", 0.0, 1000.0)  # held where it is, whatever its axis
    sim.step(500)
    force, torque = hanging_load_reading(rpy)
    print(f"figure: ft sensor, {MASS} kg load (joint rpy {rpy}): force {np.round(sensor.latest.force, 3)} N for "
          f"{np.round(force, 3)}, torque {np.round(sensor.latest.torque, 3)} N·m for {np.round(torque, 3)}")
    assert sensor.latest.force == pytest.approx(force, abs=0.02 * MASS * 9.8)
    assert sensor.latest.torque == pytest.approx(torque, abs=0.02 * np.linalg.norm(torque))
    sim.close()


def test_a_load_resting_on_the_ground_reads_nothing(tmp_path):
    # A prismatic wrist low enough that the load sits on the ground: the ground carries it, not the joint.
    sim, spawned, sensor = wrist(tmp_path, joint_type="prismatic", height=0.3)
    sim.step(1000)
    print(f"figure: ft sensor, load resting on the ground: force {np.round(sensor.latest.force, 3)} N")
    assert np.linalg.norm(sensor.latest.force) < 0.02 * MASS * 9.8
    sim.close()


def test_a_sensor_on_a_fixed_joint_is_refused(tmp_path):
    with pytest.raises(ConfigError, match="jointName: wrist_joint is a fixed joint, lumped away"):
        wrist(tmp_path, joint_type="fixed")


def test_noise_is_seeded(tmp_path):
    readings = []
    for run in range(2):
        (tmp_path / str(run)).mkdir()
        sim, spawned, sensor = wrist(tmp_path / str(run), noise=0.5, seed=4)
        sim.step(50)
        readings.append(sensor.latest)
        sim.close()
    assert readings[0] == readings[1]
