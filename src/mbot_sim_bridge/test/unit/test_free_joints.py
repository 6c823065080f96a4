"""URDF planar and floating joints as Gazebo has them: sdformat's URDF import writes no joint for either, so the
child link moves freely (a planar one too, not held to its plane). Built here as a chain that holds nothing."""
import pytest

from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy, rpy
from sensor_fixtures import world_simulation

# A 0.2 m box on a free joint from the world, started 1 m up and tilted, with an arm on a revolute joint.
URDF = """<robot name="crate">
  <link name="world"/>
  <link name="base">
    <inertial><mass value="2"/><inertia ixx="0.02" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>
  </link>
  <joint name="free" type="{kind}"><parent link="world"/><child link="base"/><origin xyz="0 0 1" rpy="0.3 0.2 0.1"/>
    <axis xyz="0 0 1"/></joint>
  <link name="arm">
    <inertial><mass value="0.5"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0.2 0 0"/><geometry><box size="0.2 0.05 0.05"/></geometry></collision>
  </link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0.1 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"""


@pytest.fixture(scope="module")
def ground(tmp_path_factory):
    simulation = world_simulation(tmp_path_factory.mktemp("free_joints"))
    yield simulation
    simulation.close()


@pytest.mark.parametrize("kind", ["floating", "planar"])
def test_the_child_of_a_free_joint_falls_and_settles_on_a_face_and_a_reset_puts_it_back(ground, kind):
    spawned = ground.spawn_robot(parse_robot(URDF.format(kind=kind)), kind, pose_from_xyz_rpy((0.0, 0.0, 0.0),
                                                                                                 (0.0, 0.0, 0.0)))
    robot = spawned.robot
    assert robot.movable_joints == ["hinge"]  # Gazebo has no joint "free" to report or set
    assert set(robot.link_index) == {"world", "base", "arm"}
    start = robot.link_world_pose("base")
    ground.step(2000)
    resting = robot.link_world_pose("base")
    assert resting.position[2] == pytest.approx(0.1, abs=0.005)  # on a face, not on the corner it started above
    assert max(abs(angle) for angle in rpy(resting.orientation)[:2]) < 0.02
    ground.reset(simulation=False)
    assert robot.link_world_pose("base").position == pytest.approx(start.position, abs=1e-6)
    assert robot.link_world_pose("base").orientation == pytest.approx(start.orientation, abs=1e-6)
    ground.delete(kind)
