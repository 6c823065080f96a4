"""libgazebo_ros_link_attacher.so (core/manipulation/link_attacher.py), the first world plugin: built from the
world's <plugin>, it joins two links where they are and releases them; bad names answer false and leave the
world as it was; resets and deletions release what it holds. World plugins in the wrong place are said once."""
import math

import pytest
from sensor_fixtures import world_simulation

from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.manipulation.link_attacher import LinkAttacher

ATTACHER = "<plugin name='attacher' filename='libgazebo_ros_link_attacher.so'/>"
CRATE = """<model name="{name}"><pose>{x} 0 0.05 0 0 0</pose><link name="link">
  <inertial><mass>1</mass><inertia><ixx>0.002</ixx><iyy>0.002</iyy><izz>0.002</izz></inertia></inertial>
  <collision name="c"><geometry><box><size>0.1 0.1 0.1</size></box></geometry></collision></link></model>"""
PAIR = ("a", "link", "b", "link")


@pytest.fixture
def sim(tmp_path):
    simulation = world_simulation(tmp_path, ATTACHER, CRATE.format(name="a", x=0.0), CRATE.format(name="b", x=0.3))
    simulation.step(200)
    yield simulation
    simulation.close()


def attacher_of(sim) -> LinkAttacher:
    plugin, = sim.world_plugins.plugins
    return plugin


def lift_a(sim, seconds=0.4):
    """Push crate a up with 25 N (it weighs 9.8 N alone, 19.6 N with b)."""
    sim.apply_body_wrench("a::link", "world", (0, 0, 0), (0, 0, 25.0), (0, 0, 0), sim.sim_time, seconds)
    sim.step(int(seconds / sim.step_size))


def positions(sim):
    return [sim.engine.model_pose(name).position for name in ("a", "b")]


def test_attached_crates_move_together_and_part_when_detached(sim):
    attacher = attacher_of(sim)
    assert attacher.attach(PAIR) == (True, "Attach finished.")
    assert attacher.attach(PAIR) == (True, "Joint already existed, reusing it.")
    lift_a(sim)
    a, b = positions(sim)
    assert a[2] > 0.2 and math.dist(a, b) == pytest.approx(0.3, abs=0.002)  # b hangs on a, 0.3 m away
    assert attacher.detach(PAIR) == (True, "")
    assert attacher.detach(PAIR)[0] is False
    sim.step(1000)
    assert positions(sim)[1][2] == pytest.approx(0.05, abs=0.005)  # b fell back to the ground


@pytest.mark.parametrize("names", [
    ("nope", "link", "b", "link"), ("a", "nope", "b", "link"), ("a", "link", "b", ""), ("", "", "", ""),
    ("a", "link", "a", "link"), ("nan", "inf", "1e308", "-inf"), ("a" * 100000, "link", "b", "link"),
    ("a::link", "link", "b", "link"), ("ground_plane", "link", "b", "nan")])
def test_bad_names_answer_false_and_leave_the_world_as_it_was(sim, names):
    attacher, before = attacher_of(sim), positions(sim)
    ok, said = attacher.attach(names)
    assert ok is False and said
    assert attacher.detach(names)[0] is False
    lift_a(sim, 0.2)
    assert positions(sim)[1] == pytest.approx(before[1], abs=1e-4)  # b was not attached to anything


@pytest.mark.parametrize("release", ["reset_world", "reset_simulation", "delete"])
def test_resets_and_deletions_release_the_attachments(sim, release):
    attacher = attacher_of(sim)
    assert attacher.attach(PAIR)[0]
    if release == "delete":
        sim.delete("b")
    else:
        sim.reset(simulation=release == "reset_simulation")
    assert not attacher.joints.holds(PAIR)
    lift_a(sim, 0.3)
    if release != "delete":
        assert positions(sim)[1] == pytest.approx((0.3, 0.0, 0.05), abs=0.005)  # b stayed where it was put
    assert attacher.attach(PAIR)[0] is (release != "delete")


def test_world_plugins_out_of_place_are_said_once_and_ignored(tmp_path, caplog):
    unknown = "<plugin name='p' filename='libgazebo_ros_state.so'/>"
    model_plugin = "<plugin name='d' filename='libgazebo_ros_diff_drive.so'/>"
    sim = world_simulation(tmp_path, unknown, model_plugin, ATTACHER)
    try:
        assert [type(plugin) for plugin in sim.world_plugins.plugins] == [LinkAttacher]
        assert "plugin 'p' (libgazebo_ros_state.so) is not emulated by the bridge; ignored" in caplog.text
        assert "plugin 'd' (libgazebo_ros_diff_drive.so) is not a world plugin; ignored" in caplog.text
        robot = parse_robot(f"<robot name='r'><link name='l'/><gazebo>{ATTACHER}</gazebo></robot>", "model 'r'")
        assert sim.spawn_robot(robot, "r").plugins == []
        assert "libgazebo_ros_link_attacher.so is a world plugin (it goes inside <world>)" in caplog.text
    finally:
        sim.close()
