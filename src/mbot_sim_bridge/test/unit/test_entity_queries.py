"""get_model_properties and get_link_state on the arm and a falling box: links, collisions and joints as the
physics has them, link states relative to any entity as gazebo_ros computes them, and upstream's messages for
every unknown name."""
import os

import numpy as np
import pytest
from ros_control_fixtures import WORKSPACE_SRC, load_yaml, simulate
from sensor_fixtures import expanded

from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.errors import ModelError
from mbot_sim_bridge.core.geometry import IDENTITY, compose, inverse
from mbot_sim_bridge.package_uris import resolve_package_uris

ARM_XACRO = os.path.join(WORKSPACE_SRC, "arm_description", "urdf", "arm.urdf.xacro")
CONFIG = os.path.join(WORKSPACE_SRC, "arm_gazebo", "config", "arm_effort_controllers.yaml")
BOX_WORLD = ("<sdf version='1.6'><world name='w'><model name='box'><pose>2 0 1 0 0 0.5</pose><link name='link'>"
             "<inertial><mass>1</mass></inertial><collision name='c'><geometry><box><size>0.2 0.2 0.2</size>"
             "</box></geometry></collision></link></model></world></sdf>")
LINK_NOT_FOUND = "GetLinkState: link not found, did you forget to scope the link by model name?"
FRAME_NOT_FOUND = "GetLinkState: reference reference_frame not found, did you forget to scope the link by model name?"


@pytest.fixture
def world(tmp_path):
    sim, spawned, _ = simulate(expanded(ARM_XACRO), load_yaml(CONFIG), "robot",
                               package_uris=resolve_package_uris, namespace="/")
    path = tmp_path / "box.world"
    path.write_text(BOX_WORLD)
    sim.add_world(parse_world(str(path), []))
    with sim:
        yield sim, spawned


def assert_pose(actual, expected, tolerance=1e-6):  # Bullet keeps some poses in single precision
    assert actual.position == pytest.approx(expected.position, abs=tolerance)
    sign = 1.0 if np.dot(actual.orientation, expected.orientation) >= 0 else -1.0
    assert tuple(sign * v for v in actual.orientation) == pytest.approx(expected.orientation, abs=tolerance)


def test_model_properties_list_the_simulated_links_collisions_and_joints(world):
    sim, spawned = world
    arm = sim.model_properties("robot")
    assert arm.body_names == list(spawned.robot.link_index)
    assert "shoulder_link" in arm.body_names and "shoulder_pan_joint" in arm.joint_names
    assert set(spawned.robot.movable_joints) <= set(arm.joint_names)
    assert arm.geom_names and not arm.is_static
    box = sim.model_properties("box")
    assert (box.body_names, box.geom_names, box.joint_names, box.is_static) == (["link"], ["c"], [], False)
    with pytest.raises(ModelError, match="^GetModelProperties: model does not exist$"):
        sim.model_properties("no_such_model")


def test_link_state_in_the_world_and_relative_to_models_and_links(world):
    sim, spawned = world
    sim.step(300)  # the box falls
    pose, linear, angular = sim.link_state("box::link", "")
    assert_pose(pose, sim.engine.model_pose("box"))
    assert linear == pytest.approx(sim.engine.model_velocity("box")[0], abs=1e-9)
    assert linear[2] < -1.0
    for frame in ("world", "map", "/map"):
        assert_pose(sim.link_state("box::link", frame)[0], pose)
    wrist = spawned.robot.link_world_pose("wrist_3_link")
    relative, linear, angular = sim.link_state("box::link", "robot::wrist_3_link")
    assert_pose(relative, compose(inverse(wrist), pose))
    itself, linear, angular = sim.link_state("box::link", "box")
    assert_pose(itself, IDENTITY)
    assert linear == pytest.approx((0, 0, 0), abs=1e-6) and angular == pytest.approx((0, 0, 0), abs=1e-6)
    assert_pose(sim.link_state("robot::wrist_3_link", "robot")[0],
                compose(inverse(sim.engine.model_pose("robot")), wrist))


@pytest.mark.parametrize("link, frame, message", [
    ("wrist_3_link", "", LINK_NOT_FOUND),  # not scoped by its model
    ("robot::no_such_link", "", LINK_NOT_FOUND),
    ("no_such_model::link", "", LINK_NOT_FOUND),
    ("robot", "", LINK_NOT_FOUND),  # a model is not a link
    ("", "", LINK_NOT_FOUND),
    ("robot::wrist_3_link", "no_such_frame", FRAME_NOT_FOUND),
    ("robot::wrist_3_link", "robot::no_such_link", FRAME_NOT_FOUND),
    ("robot::wrist_3_link", "wrist_3_link", FRAME_NOT_FOUND),
])
def test_unknown_links_and_frames_get_upstreams_messages_and_nothing_moves(world, link, frame, message):
    sim, spawned = world
    sim.step(10)
    before = (sim.engine.model_pose("box"), spawned.robot.joint_state(spawned.robot.movable_joints))
    with pytest.raises(ModelError) as error:
        sim.link_state(link, frame)
    assert str(error.value) == message
    assert (sim.engine.model_pose("box"), spawned.robot.joint_state(spawned.robot.movable_joints)) == before
