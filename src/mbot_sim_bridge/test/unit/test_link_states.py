"""set_link_state, get_model_state relative to a link, and ~link_states (Simulation.set_link_state, model_state,
model_states.LinkStatesPublisher): a link is put where asked in the world or in any entity's frame with
upstream's velocity arithmetic, a robot moves as one body with its joints unchanged, one fixed to the world is
refused, bad requests get upstream's message or one naming the value and nothing moves; link_states lists every
link's state while subscribed."""
import math
from io import BytesIO

import numpy as np
import pytest
from gazebo_msgs.msg import LinkStates
from sensor_fixtures import world_simulation
from test_joint_efforts import CRATE, TURNTABLE
from test_model_states import CountedConnections

from mbot_sim_bridge import model_states
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.errors import ModelError
from mbot_sim_bridge.core.geometry import IDENTITY, Pose, compose, inverse, pose_from_xyz_rpy, rotate

ANCHORED = """<robot name="post"><link name="world"/>
  <joint name="anchor" type="fixed"><parent link="world"/><child link="base"/><origin xyz="0 3 0"/></joint>
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>
    </inertial><collision><geometry><box size="0.1 0.1 1"/></geometry></collision></link>
</robot>"""
TURNED = pose_from_xyz_rpy((0.5, -1.0, 2.0), (0.0, 0.0, math.pi / 2))


@pytest.fixture
def world(tmp_path):
    sim = world_simulation(tmp_path, CRATE)
    table = sim.spawn_robot(parse_robot(TURNTABLE, "model 'table'"), "table")
    sim.spawn_robot(parse_robot(ANCHORED, "model 'post'"), "post")
    sim.step(100)
    return sim, table


def assert_pose(actual, expected, tolerance=1e-6):
    assert actual.position == pytest.approx(expected.position, abs=tolerance)
    sign = 1.0 if np.dot(actual.orientation, expected.orientation) >= 0 else -1.0
    assert tuple(sign * v for v in actual.orientation) == pytest.approx(expected.orientation, abs=tolerance)


def test_a_world_models_link_is_set_in_the_world_and_in_another_entitys_frame(world):
    sim, _ = world
    sim.set_link_state("crate::link", "", TURNED, (0.0, 0.0, 1.0), (0.0, 0.0, 0.5))
    pose, linear, angular = sim.link_state("crate::link", "")
    assert_pose(pose, TURNED)
    assert (linear, angular) == (pytest.approx((0, 0, 1), abs=1e-9), pytest.approx((0, 0, 0.5), abs=1e-9))
    # In the crate's own (turned, moving) frame: the pose composes with the frame's; upstream subtracts the frame's
    # velocities and does not rotate them.
    sim.set_link_state("crate::link", "crate", Pose((1.0, 0.0, 0.0), IDENTITY.orientation), (0.0, 0.0, 0.0),
                       (0.0, 0.0, 0.0))
    pose, linear, angular = sim.link_state("crate::link", "")
    assert pose.position == pytest.approx((0.5, 0.0, 2.0), abs=1e-6)  # 1 m along the frame's x: the world's y
    assert linear == pytest.approx((0, 0, -1), abs=1e-9) and angular == pytest.approx((0, 0, -0.5), abs=1e-9)


def test_a_robots_link_moves_the_whole_robot_with_its_joints_unchanged(world):
    sim, table = world
    robot = table.robot
    sim.apply_joint_effort("turntable", 0.01, 0.0, 0.1)
    sim.step(150)
    angle, spin, _ = robot.joint_state(["turntable"])[0]
    plate_in_base = compose(inverse(robot.link_world_pose("base_link")), robot.link_world_pose("plate"))
    # The root link: the robot follows, the joint keeps its speed.
    sim.set_link_state("table::base_link", "", TURNED, (0.2, 0.0, 0.0), (0.0, 0.0, 0.0))
    assert_pose(robot.link_world_pose("base_link"), TURNED)
    assert robot.joint_state(["turntable"])[0][:2] == pytest.approx((angle, spin), abs=1e-9)
    assert robot.link_world_velocity("base_link")[0] == pytest.approx((0.2, 0, 0), abs=1e-6)
    # Another link: it lands where asked with the twist asked, the rest follows, the joints stop.
    target = pose_from_xyz_rpy((-1.0, 2.0, 1.0), (0.3, 0.0, 0.0))
    sim.set_link_state("table::plate", "world", target, (0.0, 0.1, 0.0), (0.0, 0.0, 0.2))
    assert_pose(robot.link_world_pose("plate"), target)
    assert_pose(compose(inverse(robot.link_world_pose("base_link")), robot.link_world_pose("plate")), plate_in_base)
    assert robot.joint_state(["turntable"])[0][:2] == pytest.approx((angle, 0.0), abs=1e-9)
    linear, angular = robot.link_world_velocity("plate")
    assert linear == pytest.approx((0, 0.1, 0), abs=1e-6) and angular == pytest.approx((0, 0, 0.2), abs=1e-6)


@pytest.mark.parametrize("link, frame, pose, linear, message", [
    ("crate", "", TURNED, (0, 0, 0), "^SetLinkState: link does not exist$"),  # a model, not a link
    ("link", "", TURNED, (0, 0, 0), "^SetLinkState: link does not exist$"),  # not scoped
    ("crate::lid", "", TURNED, (0, 0, 0), "^SetLinkState: link does not exist$"),
    ("crate::link", "nowhere", TURNED, (0, 0, 0), "^SetLinkState: failed$"),
    ("crate::link", "table::lid", TURNED, (0, 0, 0), "^SetLinkState: failed$"),
    ("crate::link", "", Pose((math.nan, 0, 0), (0, 0, 0, 1)), (0, 0, 0), "position.x is nan, not a finite number"),
    ("crate::link", "", Pose((0, math.inf, 0), (0, 0, 0, 1)), (0, 0, 0), "position.y is inf, not a finite number"),
    ("crate::link", "", Pose((1e300, 0, 0), (0, 0, 0, 1)), (0, 0, 0), r"position.x = 1e\+300 is outside"),
    ("crate::link", "table", Pose((9e4, 0, 0), (0, 0, 0, 1)), (0, 0, 0), r"position.x = .* is outside"),
    ("crate::link", "", TURNED, (0, -math.inf, 0), "linear velocity.y is -inf"),
    ("crate::link", "", TURNED, (0, 0, 1e300), r"linear velocity.z = 1e\+300 is outside"),
    ("post::world", "", TURNED, (0, 0, 0), "model 'post' is fixed to the world"),
])
def test_bad_requests_are_refused_and_nothing_moves(world, link, frame, pose, linear, message):
    sim, table = world
    sim.set_model_state("table", pose_from_xyz_rpy((9e4, 0, 0.1), (0, 0, 0)))  # so that "table" frames overflow
    before = {name: sim.engine.model_pose(name) for name in sim.model_names()}
    with pytest.raises(ModelError, match=message):
        sim.set_link_state(link, frame, pose, linear, (0.0, 0.0, 0.0))
    assert {name: sim.engine.model_pose(name) for name in sim.model_names()} == before


def test_model_state_relative_to_a_link_is_upstreams(world):
    sim, table = world
    sim.set_link_state("table::plate", "", TURNED, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))  # a turning frame
    sim.set_model_state("crate", pose_from_xyz_rpy((2.0, 0.0, 3.0), (0, 0, 0)), (1.0, 0.0, 0.0))
    plate = table.robot.link_world_pose("plate")
    pose, linear, angular = sim.model_state("crate", "table::plate")
    assert_pose(pose, compose(inverse(plate), sim.engine.model_pose("crate")))
    # The difference of the velocities, rotated into the frame: no ω × r term.
    frame_linear, _ = table.robot.link_world_velocity("plate")
    assert linear == pytest.approx(rotate(inverse(plate).orientation, np.subtract((1, 0, 0), frame_linear)), abs=1e-6)
    assert angular == pytest.approx((0, 0, -1), abs=1e-6)
    with pytest.raises(ModelError, match="^GetModelState: model does not exist$"):
        sim.model_state("nothing", "")
    with pytest.raises(ModelError, match="^GetModelState: reference relative_entity_name not found, did you forget "
                                         "to scope the body by model name\\?$"):
        sim.model_state("crate", "table::lid")


def test_link_states_are_every_links_state_and_sent_only_while_subscribed(world, monkeypatch):
    sim, table = world
    monkeypatch.setattr(model_states, "loop_publisher", CountedConnections)
    states = model_states.LinkStatesPublisher(sim)
    states.publish()
    assert states.publisher.sent == []
    states.publisher.connections = 1
    sim.set_link_state("table::plate", "", TURNED, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    states.publish()
    buffer = BytesIO()
    states.publisher.sent[0].serialize(buffer)
    message = LinkStates().deserialize(buffer.getvalue())
    assert message.name == ["ground_plane::link", "crate::link", "table::base_link", "table::plate", "post::world"]
    plate = message.pose[3]
    assert (plate.position.x, plate.position.y, plate.position.z) == pytest.approx(TURNED.position, abs=1e-6)
    assert message.twist[3].angular.z == pytest.approx(1.0, abs=1e-6)
