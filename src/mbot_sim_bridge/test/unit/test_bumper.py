"""libgazebo_ros_bumper.so (core/sensors/bumper.py): a bumper reports the box it touches by Gazebo's name, with the
normal pointing back at the robot, and nothing when clear; a collision name the link lacks is said once."""
import pytest
from plugin_robots import BUMPER_LUMPED_COLLISION, BUMPER_ROBOT
from sensor_fixtures import box, plugin_of, world_simulation

from mbot_sim_bridge.core.sensors.bumper import Bumper
from mbot_sim_bridge.core.geometry import Pose
from mbot_sim_bridge.core.description.robot_model import parse_robot


def bumper_bot(tmp_path, box_x, collision=BUMPER_LUMPED_COLLISION):
    # The plate's front face is at x = 0.22; a box whose back face is at box_x - 0.1.
    sim = world_simulation(tmp_path, box("crate", (box_x, 0.0, 0.1), (0.2, 0.6, 0.2)))
    spawned = sim.spawn_robot(parse_robot(BUMPER_ROBOT.format(collision=collision), "model 'bumper_bot'"), "bumper_bot",
                              Pose((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)))
    sim.step(50)
    return sim, plugin_of(spawned, Bumper)


def test_the_bumper_reports_the_box_it_touches_by_name_with_the_normal_towards_the_robot(tmp_path):
    sim, bumper = bumper_bot(tmp_path, 0.318)  # 2 mm into the plate
    bumper.update(sim.sim_time)
    assert [(c.collision1, c.collision2) for c in bumper.latest] == [
        (f"bumper_bot::base_link::{BUMPER_LUMPED_COLLISION}", "crate::link::c")]
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
    assert (f"'bumper_link_collision' is not a collision of link 'base_link' (base_link_collision, "
            f"{BUMPER_LUMPED_COLLISION})") in caplog.text
