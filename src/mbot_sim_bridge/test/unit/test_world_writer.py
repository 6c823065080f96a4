"""core/description/world_writer.py: a running world saved as SDF loads back to the same poses (no ROS master)."""
import math
import os
import stat
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from mbot_sim_bridge.core.errors import WorldError
from mbot_sim_bridge.core.geometry import Pose, compose, inverse, pose_from_xyz_rpy
from mbot_sim_bridge.core.description.model_path import default_model_path
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.description.sdf_spawn import spawn_world_xml
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.description.world_description import PhysicsConfig
from mbot_sim_bridge.core.lights import SUN, world_lights
from mbot_sim_bridge.core.simulation import Simulation
from mbot_sim_bridge.core.description.world_writer import pose_text, take_snapshot, world_sdf, write_world_file

HERE = os.path.dirname(os.path.abspath(__file__))
REPO_WORLDS = os.path.abspath(os.path.join(HERE, "..", "..", "..", "..", "worlds"))
TEST_WORLDS = os.path.join(HERE, "..", "worlds")
POSITION_TOLERANCE = 1e-3  # m
ANGLE_TOLERANCE = 1e-3  # rad

# The SDF 1.6 spec's children of the elements the writer makes (sdformat's sdf/1.6/world.sdf, physics.sdf).
SDF_1_6_WORLD_CHILDREN = {"audio", "wind", "include", "gravity", "magnetic_field", "atmosphere", "gui", "physics",
                          "scene", "light", "model", "actor", "plugin", "road", "spherical_coordinates", "state",
                          "population"}
SDF_1_6_INCLUDE_CHILDREN = {"uri", "name", "static", "pose", "plugin"}
SDF_1_6_PHYSICS_CHILDREN = {"max_step_size", "real_time_factor", "real_time_update_rate", "max_contacts",
                            "simbody", "bullet", "ode", "dart"}


@pytest.fixture(autouse=True)
def no_gazebo_model_path(monkeypatch):
    monkeypatch.delenv("GAZEBO_MODEL_PATH", raising=False)


def angle_between(a: Pose, b: Pose) -> float:
    dot = abs(float(np.dot(a.orientation, b.orientation)))
    return 2.0 * math.acos(min(1.0, dot))


def assert_same_pose(actual: Pose, expected: Pose, what: str):
    distance = float(np.linalg.norm(np.subtract(actual.position, expected.position)))
    assert distance < POSITION_TOLERANCE, f"{what}: {distance:.4f} m from {expected.position}"
    turned = angle_between(actual, expected)
    assert turned < ANGLE_TOLERANCE, f"{what}: turned by {turned:.4f} rad"


def save_and_reload(simulation, world, tmp_path, with_robots=False, name="saved.world"):
    snapshot = take_snapshot(simulation, with_robots)
    path = tmp_path / name
    write_world_file(str(path), world_sdf(world, snapshot.models, snapshot.poses, snapshot.robots,
                                          snapshot.link_states, snapshot.physics, snapshot.lights))
    return snapshot, path, parse_world(str(path), default_model_path())


def check_sdf_1_6_structure(path):
    root = ET.parse(path).getroot()
    assert root.tag == "sdf" and root.get("version") == "1.6"
    (world,) = root.findall("world")
    assert {child.tag for child in world} <= SDF_1_6_WORLD_CHILDREN
    for include in world.findall("include"):
        assert {child.tag for child in include} <= SDF_1_6_INCLUDE_CHILDREN
        assert include.findtext("uri").startswith("model://")
    (physics,) = world.findall("physics")
    assert {child.tag for child in physics} <= SDF_1_6_PHYSICS_CHILDREN
    return world


def test_play_ground_saved_and_reloaded_keeps_every_pose(tmp_path):
    world = parse_world(os.path.join(REPO_WORLDS, "playground.world"))
    simulation = Simulation(world, {})
    moved = pose_from_xyz_rpy((1.0, -1.0, 0.0), (0.0, 0.0, 0.7))
    simulation.engine.set_model_state("bookshelf", moved)
    simulation.step(50)
    snapshot, path, reloaded = save_and_reload(simulation, world, tmp_path)
    assert [model.name for model in reloaded.models] == [model.name for model in world.models]
    for model in reloaded.models:
        assert_same_pose(model.pose, snapshot.poses[model.name], model.name)
        original = next(m for m in world.models if m.name == model.name)
        assert model.static == original.static
        assert len(model.shapes) == len(original.shapes)
    assert_same_pose(next(m for m in reloaded.models if m.name == "bookshelf").pose, moved, "bookshelf")
    # And a simulator built from the saved file puts the bodies there too.
    again = Simulation(reloaded, {})
    for name, pose in snapshot.poses.items():
        assert_same_pose(again.engine.model_pose(name), pose, name)
    again.close()
    simulation.close()


def test_includes_stay_includes_with_name_and_pose_and_the_rest_is_copied(tmp_path):
    world = parse_world(os.path.join(REPO_WORLDS, "playground.world"))
    simulation = Simulation(world, {})
    _, path, _ = save_and_reload(simulation, world, tmp_path)
    saved = check_sdf_1_6_structure(path)
    includes = {include.findtext("name"): include for include in saved.findall("include") if include.find("name")
                is not None}
    assert includes["construction_cone_left"].findtext("uri") == "model://construction_cone"
    assert includes["jersey_barrier"].findtext("pose").split()[:2] == ["5.3", "0"]
    assert [include.findtext("uri") for include in saved.findall("include")].count("model://sun") == 1
    assert saved.find("model") is None
    simulation.close()


def test_physics_settings_are_written(tmp_path):
    world = parse_world(os.path.join(REPO_WORLDS, "empty.world"))
    physics = PhysicsConfig(0.002, 0.5, 250.0, (0.0, 0.0, -5.0), erp=0.4, contact_max_correcting_vel=2.0,
                            contact_surface_layer=0.002)
    world = type(world)(world.name, world.path, physics, world.models, world.others)
    simulation = Simulation(world, {})
    _, path, reloaded = save_and_reload(simulation, world, tmp_path)
    assert reloaded.physics == physics
    check_sdf_1_6_structure(path)
    simulation.close()


def test_lights_and_physics_are_written_as_the_services_left_them(tmp_path):
    path = tmp_path / "lit.world"
    path.write_text("""<sdf version="1.6"><world name="default"><include><uri>model://sun</uri></include>
      <light name="lamp" type="spot"><pose>1 2 3 0 0 0</pose><diffuse>0.5 0.4 0.3 1</diffuse></light>
      <light name="spare" type="point"/></world></sdf>""")
    world = parse_world(str(path))
    simulation = Simulation(world, {})
    simulation.set_physics(0.002, 250.0, (0.0, 0.0, -5.0), simulation.ode_config()._replace(erp=0.4))
    sun = SUN._replace(diffuse=(0.1, 0.2, 0.3, 1.0), pose=pose_from_xyz_rpy((0.0, 1.0, 9.0), (0.0, 0.5, 0.0)))
    simulation.lights.set("sun", sun.cast_shadows, sun.diffuse, sun.specular, sun.attenuation, sun.direction,
                          sun.pose)
    simulation.lights.delete("spare")
    lights_now = dict(simulation.lights.lights)
    _, saved, reloaded = save_and_reload(simulation, world, tmp_path)
    assert reloaded.physics == simulation.engine.physics
    assert (reloaded.physics.max_step_size, reloaded.physics.gravity, reloaded.physics.erp) == (0.002, (0, 0, -5), 0.4)
    relit = world_lights(reloaded.others)
    assert relit.keys() == {"sun", "lamp"}
    assert relit["lamp"] == lights_now["lamp"]  # unchanged: copied as read
    assert relit["sun"].diffuse == sun.diffuse and relit["sun"].type == "directional"
    assert_same_pose(relit["sun"].pose, sun.pose, "the moved sun")
    check_sdf_1_6_structure(saved)
    simulation.close()


def test_inline_models_stay_inline_with_their_links_where_they_are_now(tmp_path):
    world = parse_world(os.path.join(TEST_WORLDS, "relative_to.world"))
    simulation = Simulation(world, {})
    simulation.engine.set_model_state("anchor", pose_from_xyz_rpy((4.0, 1.0, 0.5), (0.0, 0.0, 1.0)))
    snapshot, path, reloaded = save_and_reload(simulation, world, tmp_path)
    root = ET.parse(path).getroot()
    assert root.get("version") == "1.7"  # the model uses 1.7's relative_to, copied as it was
    assert {model.get("name") for model in root.find("world").findall("model")} == {m.name for m in world.models}
    for model in reloaded.models:
        assert_same_pose(model.pose, snapshot.poses[model.name], model.name)
        before = next(m for m in world.models if m.name == model.name)
        # Each link where it is now: the original link pose carried along with its model.
        for link, old_link in zip(model.links, before.links):
            expected = compose(snapshot.poses[model.name], compose(inverse(before.pose), old_link.pose))
            assert_same_pose(link.pose, expected, f"{model.name}::{link.name}")
    simulation.close()


def test_relative_mesh_files_are_found_from_the_saved_file(tmp_path):
    world = parse_world(os.path.join(TEST_WORLDS, "meshes.world"))
    simulation = Simulation(world, {})
    _, _, reloaded = save_and_reload(simulation, world, tmp_path)
    assert [shape.name for shape in reloaded.shapes] == [shape.name for shape in world.shapes]
    simulation.close()


def test_spawned_database_models_are_saved_as_includes(tmp_path):
    world = parse_world(os.path.join(REPO_WORLDS, "empty.world"))
    simulation = Simulation(world, {})
    for name, x in (("unit_box", 1.0), ("unit_box_0", 3.0)):
        xml = "<sdf version='1.6'><world name='default'><include><uri>model://unit_box</uri></include></world></sdf>"
        spawn = tmp_path / (f"spawn_{name}.world")
        spawn.write_text(spawn_world_xml(xml, name, pose_from_xyz_rpy((x, 2.0, 0.0), (0, 0, 0.5))))
        simulation.add_world(parse_world(str(spawn)))
    simulation.step(20)
    snapshot, path, reloaded = save_and_reload(simulation, world, tmp_path)
    saved = check_sdf_1_6_structure(path)
    names = [include.findtext("name") for include in saved.findall("include")
             if include.findtext("uri") == "model://unit_box"]
    assert names == ["unit_box", "unit_box_0"]
    for name in names:
        assert_same_pose(next(m for m in reloaded.models if m.name == name).pose, snapshot.poses[name], name)
    simulation.close()


def test_robots_are_left_out_unless_asked_for_then_inline_at_their_link_poses(tmp_path, mbot_urdf):
    world = parse_world(os.path.join(REPO_WORLDS, "empty.world"))
    simulation = Simulation(world, {})
    simulation.spawn_robot(parse_robot(mbot_urdf), "mbot", pose_from_xyz_rpy((1.0, 2.0, 0.0), (0, 0, 1.2)))
    simulation.step(200)
    snapshot, path, reloaded = save_and_reload(simulation, world, tmp_path)
    assert "mbot" not in [model.name for model in reloaded.models]
    assert snapshot.robot_names == ["mbot"]

    snapshot, path, reloaded = save_and_reload(simulation, world, tmp_path, with_robots=True, name="robots.world")
    (robot,) = snapshot.robots
    model = ET.parse(path).getroot().find("world/model[@name='mbot']")
    assert model is not None and model.find("include") is None
    assert [plugin.get("filename") for plugin in model.findall("plugin")] == ["libgazebo_ros_diff_drive.so"]
    assert {joint.get("type") for joint in model.findall("joint")} <= {"revolute", "fixed", "prismatic"}
    # Read back, it is a model with joints and a plugin again: a robot, whose links start where they were saved.
    (loaded,) = [m for m in reloaded.robots if m.name == "mbot"]
    assert_same_pose(loaded.pose, robot.link_poses[robot.model.root], "mbot model frame")
    assert set(loaded.robot.lumped_into) == set(robot.link_poses)
    with Simulation(reloaded, {}) as again:
        for link, pose in robot.link_poses.items():
            assert_same_pose(again.models["mbot"].robot.link_world_pose(link), pose, "mbot::" + link)
    simulation.close()


def test_pose_text_round_trips_within_tolerance():
    pose = pose_from_xyz_rpy((1.23456789, -2.5, 0.001), (0.1, -0.2, math.pi - 1e-4))
    values = [float(value) for value in pose_text(pose).split()]
    assert_same_pose(pose_from_xyz_rpy(values[:3], values[3:]), pose, "pose")


def test_unwritable_directory_fails_in_one_line_and_leaves_no_file(tmp_path):
    if os.geteuid() == 0:
        target_directory = tmp_path / "missing" / "deeper"  # root writes anywhere: a missing directory instead
    else:
        target_directory = tmp_path / "locked"
        target_directory.mkdir()
        target_directory.chmod(stat.S_IRUSR | stat.S_IXUSR)
    target = target_directory / "out.world"
    with pytest.raises(WorldError) as error:
        write_world_file(str(target), "<sdf/>")
    assert str(target) in str(error.value) and "\n" not in str(error.value)
    assert not target.exists()
    if target_directory.exists():
        assert list(target_directory.iterdir()) == []
        target_directory.chmod(stat.S_IRWXU)


def test_a_failed_write_leaves_the_old_file_and_no_temp_file(tmp_path, monkeypatch):
    target = tmp_path / "out.world"
    target.write_text("old")

    def full_disk(*_):
        raise OSError(28, "No space left on device")
    monkeypatch.setattr(os, "replace", full_disk)
    with pytest.raises(WorldError, match="No space left on device"):
        write_world_file(str(target), "new")
    assert target.read_text() == "old"
    assert [entry.name for entry in tmp_path.iterdir()] == ["out.world"]


def test_writing_replaces_the_file_whole(tmp_path):
    target = tmp_path / "out.world"
    target.write_text("old and longer than the new text")
    write_world_file(str(target), "new")
    assert target.read_text() == "new"
    assert [entry.name for entry in tmp_path.iterdir()] == ["out.world"]


def test_a_directory_in_the_way_fails_in_one_line_and_leaves_no_temp_file(tmp_path):
    (tmp_path / "taken.world").mkdir()
    with pytest.raises(WorldError, match="cannot write .*taken.world"):
        write_world_file(str(tmp_path / "taken.world"), "<sdf/>")
    assert [entry.name for entry in tmp_path.iterdir()] == ["taken.world"]
