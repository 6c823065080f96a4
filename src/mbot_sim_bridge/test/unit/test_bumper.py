"""libgazebo_ros_bumper.so (core/sensors/bumper.py): a bumper reports the box it touches by Gazebo's name, with the
normal pointing back at the robot, and nothing when clear; a collision name the link lacks is said once."""
import pytest
from sensor_fixtures import box, plugin_of, world_simulation

from mbot_sim_bridge.core.sensors.bumper import Bumper
from mbot_sim_bridge.core.geometry import Pose
from mbot_sim_bridge.core.description.robot_model import parse_robot

# A base with a bumper plate on a fixed joint: lumped into base_link, its collision keeps sdformat's lump name.
ROBOT = """<robot name="bumper_bot">
  <link name="base_link">
    <inertial><mass value="8"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.4 0.3 0.2"/></geometry></collision>
  </link>
  <link name="bumper_link">
    <collision><geometry><box size="0.02 0.3 0.1"/></geometry></collision>
  </link>
  <joint name="bumper_joint" type="fixed"><parent link="base_link"/><child link="bumper_link"/>
    <origin xyz="0.21 0 0.1"/></joint>
  <gazebo reference="bumper_link">
    <sensor type="contact" name="bumper">
      <update_rate>50</update_rate>
      <contact><collision>{collision}</collision></contact>
      <plugin name="bumper_controller" filename="libgazebo_ros_bumper.so">
        <bumperTopicName>bumper</bumperTopicName><frameName>world</frameName>
      </plugin>
    </sensor>
  </gazebo>
</robot>"""
LUMPED = "base_link_fixed_joint_lump__bumper_link_collision"


def bumper_bot(tmp_path, box_x, collision=LUMPED):
    # The plate's front face is at x = 0.22; a box whose back face is at box_x - 0.1.
    sim = world_simulation(tmp_path, box("crate", (box_x, 0.0, 0.1), (0.2, 0.6, 0.2)))
    spawned = sim.spawn_robot(parse_robot(ROBOT.format(collision=collision), "model 'bumper_bot'"), "bumper_bot",
                              Pose((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)))
    sim.step(50)
    return sim, plugin_of(spawned, Bumper)


def test_the_bumper_reports_the_box_it_touches_by_name_with_the_normal_towards_the_robot(tmp_path):
    sim, bumper = bumper_bot(tmp_path, 0.318)  # 2 mm into the plate
    bumper.update(sim.sim_time)
    assert [(c.collision1, c.collision2) for c in bumper.latest] == [
        (f"bumper_bot::base_link::{LUMPED}", "crate::link::c")]
    points = bumper.latest[0].points
    normals = [point.normal for point in points]
    print(f"figure: bumper touching 'crate': {len(points)} points, normal {tuple(round(v, 3) for v in normals[0])}, "
          f"total force x {sum(point.force[0] for point in points):.1f} N")
    for normal in normals:
        assert normal == pytest.approx((-1.0, 0.0, 0.0), abs=1e-3)  # from the crate back to the bumper
    assert all(0.2 < point.position[0] < 0.23 for point in points)
    assert sum(point.force[0] for point in points) < 0  # the crate pushes the robot back


def test_nothing_when_clear(tmp_path):
    sim, bumper = bumper_bot(tmp_path, 1.0)
    bumper.update(sim.sim_time)
    assert bumper.latest == []


def test_a_collision_name_the_link_lacks_is_said_once_and_reports_nothing(tmp_path, caplog):
    sim, bumper = bumper_bot(tmp_path, 0.318, collision="bumper_link_collision")
    bumper.update(sim.sim_time)
    assert bumper.latest == []
    assert f"'bumper_link_collision' is not a collision of link 'base_link' (base_link_collision, {LUMPED})" in \
        caplog.text
