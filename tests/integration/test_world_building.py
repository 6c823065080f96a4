"""The tutorial's first way to build an environment: insert models by name, arrange them, "Save world as", and
load the saved world again (./mbot insert, move, delete, save-world; /gazebo/save_world)."""
import math
import os
import xml.etree.ElementTree as ET

import pytest
from mbot_sim_bridge.processes import stop_process_group
from mbot_sim_bridge.core.description.sdf_world import parse_world

from ros_processes import TESTS, call_service, rosrun, run, service_up, wait_until

pytestmark = pytest.mark.long

WORLDS = os.path.join(os.path.dirname(TESTS), "worlds")
POSITION_TOLERANCE = 1e-3  # m
ANGLE_TOLERANCE = 1e-3  # rad
START_TIMEOUT = 90  # s: the bridge on a loaded two-core machine


def start_bridge(ros_env, launch, *arguments):
    bridge = launch("mbot_sim_bridge", "empty_world.launch", "gui:=false", *arguments)
    wait_until(lambda: service_up(ros_env, "/gazebo/save_world"), START_TIMEOUT, "the simulator's services")
    return bridge


def mbot_world(ros_env, *arguments):
    return run(rosrun("mbot_gazebo", "mbot_world", *arguments), ros_env)


def ok(result):
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout


def model_poses(ros_env):
    """Every model's world pose, {name: ((x, y, z), (qx, qy, qz, qw))}, read through /gazebo/get_model_state (which
    answers while paused, when /gazebo/model_states is not published)."""
    poses = {}
    for name in call_service(ros_env, "/gazebo/get_world_properties")["model_names"]:
        pose = call_service(ros_env, "/gazebo/get_model_state", f"{{model_name: '{name}'}}")["pose"]
        poses[name] = (tuple(pose["position"][axis] for axis in "xyz"),
                       tuple(pose["orientation"][axis] for axis in "xyzw"))
    return poses


def paused(ros_env):
    return call_service(ros_env, "/gazebo/get_physics_properties")["pause"]


def angle_between(a, b):
    return 2.0 * math.acos(min(1.0, abs(sum(x * y for x, y in zip(a, b)))))


def assert_same_poses(actual, expected):
    assert sorted(actual) == sorted(expected)
    for name, (position, orientation) in expected.items():
        distance = math.dist(actual[name][0], position)
        angle = angle_between(actual[name][1], orientation)
        assert distance < POSITION_TOLERANCE and angle < ANGLE_TOLERANCE, (
            f"{name}: {distance:.4f} m and {angle:.4f} rad from its saved pose")


def relaunch(ros_env, launch, running, world):
    """Stop the running simulator, start one paused on ``world``: the poses it reports are those it loaded."""
    stop_process_group(running)
    wait_until(lambda: not service_up(ros_env, "/gazebo/save_world"), 30, "the first simulator to stop")
    start_bridge(ros_env, launch, f"world_name:={world}", "paused:=true")


def test_insert_move_save_and_relaunch_finds_every_model_where_it_was(ros_env, launch, tmp_path):
    bridge = start_bridge(ros_env, launch)
    ok(mbot_world(ros_env, "insert", "cafe_table", "-x", "2", "-y", "1"))
    ok(mbot_world(ros_env, "insert", "unit_box", "-x", "-1", "-y", "2", "-Y", "0.5"))
    assert "as 'unit_box_0'" in ok(mbot_world(ros_env, "insert", "unit_box", "-x", "-2", "-y", "-2"))
    ok(mbot_world(ros_env, "insert", "construction_barrel", "--as", "barrel", "-x", "3", "-y", "-1"))
    ok(mbot_world(ros_env, "insert", "coke_can", "-x", "4"))
    ok(mbot_world(ros_env, "delete", "coke_can"))
    ok(mbot_world(ros_env, "move", "unit_box_0", "-x", "0", "-y", "-3", "-Y", "1.0"))
    # Paused, nothing settles further between reading the poses and saving them.
    call_service(ros_env, "/gazebo/pause_physics")
    before = model_poses(ros_env)
    assert sorted(before) == ["barrel", "cafe_table", "ground_plane", "unit_box", "unit_box_0"]
    assert math.dist(before["unit_box_0"][0][:2], (0.0, -3.0)) < POSITION_TOLERANCE
    saved = tmp_path / "arranged.world"
    assert f"wrote {saved}" in ok(mbot_world(ros_env, "save-world", str(saved)))

    root = ET.parse(saved).getroot()
    assert root.get("version") == "1.6"
    includes = {include.findtext("name"): include.findtext("uri") for include in root.iter("include")
                if include.find("name") is not None}
    assert includes == {"ground_plane": "model://ground_plane", "cafe_table": "model://cafe_table",
                        "unit_box": "model://unit_box", "unit_box_0": "model://unit_box",
                        "barrel": "model://construction_barrel"}

    relaunch(ros_env, launch, bridge, saved)
    assert_same_poses(model_poses(ros_env), before)
    # The relaunched simulator, started paused, serves the bad-input checks (a start of their own cost 2 CPU s).
    assert_bad_input_one_line_each_and_paused_stays_paused(ros_env, tmp_path / "bad_input")


def test_play_ground_saved_and_reloaded_keeps_every_pose_robot_left_out(ros_env, launch, tmp_path):
    course = launch("mbot_gazebo", "view_mbot_gazebo_play_ground.launch", "gui:=false", "paused:=true")
    wait_until(lambda: "mbot" in model_poses(ros_env), START_TIMEOUT, "the mbot to be spawned")
    before = model_poses(ros_env)
    saved, with_robot = tmp_path / "play_ground.world", tmp_path / "play_ground_with_mbot.world"
    assert "robots left out" in ok(mbot_world(ros_env, "save-world", str(saved)))
    assert "plugins are kept as <plugin> tags" in ok(mbot_world(ros_env, "save-world", str(with_robot),
                                                                "--with-robots"))
    assert ET.parse(saved).getroot().find("world/model[@name='mbot']") is None
    assert ET.parse(with_robot).getroot().find("world/model[@name='mbot']") is not None
    # The robot's model frame is its root link, where get_model_state puts it too; with its joints and plugins it
    # reads back as a robot.
    robot = next(model for model in parse_world(str(with_robot)).robots if model.name == "mbot")
    assert_same_poses({"mbot": (robot.pose.position, robot.pose.orientation)}, {"mbot": before["mbot"]})

    relaunch(ros_env, launch, course, saved)
    assert_same_poses(model_poses(ros_env), {name: pose for name, pose in before.items() if name != "mbot"})


def assert_bad_input_one_line_each_and_paused_stays_paused(ros_env, tmp_path):
    """On a simulator started paused, with no model named unit_sphere: bad input gets one line each, and nothing
    unpauses it."""
    tmp_path.mkdir()
    assert paused(ros_env)
    unknown = mbot_world(ros_env, "insert", "cafe_tabel")
    assert unknown.returncode == 1
    (line,) = unknown.stderr.strip().splitlines()
    assert line.startswith("mbot_world: no model 'cafe_tabel' on the model path; nearest: cafe_table, table")

    assert "as 'unit_sphere'" in ok(mbot_world(ros_env, "insert", "unit_sphere", "-z", "2"))
    assert paused(ros_env)
    ode = call_service(ros_env, "/gazebo/get_physics_properties")["ode_config"]  # SDF's defaults, as saved
    assert (ode["erp"], ode["contact_max_correcting_vel"], ode["contact_surface_layer"]) == (0.2, 100.0, 0.001)
    assert model_poses(ros_env)["unit_sphere"][0] == pytest.approx((0.0, 0.0, 2.0), abs=1e-6)  # no fall: paused

    for target in (tmp_path / "missing" / "out.world", tmp_path):
        failed = mbot_world(ros_env, "save-world", str(target))
        assert failed.returncode == 1
        (line,) = [line for line in failed.stderr.splitlines() if line.startswith("mbot_world:")]
        assert line.startswith(f"mbot_world: save-world failed: cannot write {target}")
    assert not [name for name in os.listdir(tmp_path) if name.endswith(".tmp")]
    assert not (tmp_path / "missing").exists()

    moved = mbot_world(ros_env, "move", "no_such_model", "-x", "1")
    assert moved.returncode == 1 and "cannot move 'no_such_model'" in moved.stderr
    assert paused(ros_env)
