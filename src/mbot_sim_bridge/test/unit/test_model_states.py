"""model_states.py: the hand-made ModelStates bytes are what genpy would write for the same models; what it sends is
every model's pose and twist, and only while someone subscribes."""
import math
from io import BytesIO

import numpy as np
import pytest
from gazebo_msgs.msg import ModelStates
from geometry_msgs.msg import Pose, Twist
from sensor_fixtures import box, world_simulation

from mbot_sim_bridge import model_states
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy
from mbot_sim_bridge.model_states import serialized, serialized_names


def test_serialized_model_states_match_genpy():
    names = ["ground_plane", "mbot", "bücher"]
    poses = np.arange(21, dtype=float).reshape(3, 7) / 7.0
    twists = -np.arange(18, dtype=float).reshape(3, 6) / 3.0
    expected = ModelStates(name=names)
    for pose_row, twist_row in zip(poses, twists):
        pose, twist = Pose(), Twist()
        pose.position.x, pose.position.y, pose.position.z = pose_row[:3]
        pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = pose_row[3:]
        twist.linear.x, twist.linear.y, twist.linear.z = twist_row[:3]
        twist.angular.x, twist.angular.y, twist.angular.z = twist_row[3:]
        expected.pose.append(pose)
        expected.twist.append(twist)
    buffer = BytesIO()
    expected.serialize(buffer)
    assert serialized(serialized_names(names), poses, twists) == buffer.getvalue()


class CountedConnections:
    """The loop publisher's two calls ModelStatesPublisher makes, with a subscriber count the test sets."""

    def __init__(self, name, message_type):
        self.connections, self.sent = 0, []

    def get_num_connections(self):
        return self.connections

    def publish(self, message):
        self.sent.append(message)


def test_model_states_are_every_models_pose_and_twist_and_sent_only_while_subscribed(monkeypatch, tmp_path,
                                                                                      mbot_urdf):
    monkeypatch.setattr(model_states, "loop_publisher", CountedConnections)
    sim = world_simulation(tmp_path, box("crate", (3.0, 0.0, 0.5), (1.0, 1.0, 1.0)))
    sim.spawn_robot(parse_robot(mbot_urdf, "model 'mbot'"), "mbot")
    states = model_states.ModelStatesPublisher(sim)
    states.publish()
    assert states.publisher.sent == []  # nobody subscribes: nothing is sent
    states.publisher.connections = 1
    pose = pose_from_xyz_rpy((1.0, -2.0, 0.3), (0.0, 0.0, 0.6))
    sim.engine.set_model_state("mbot", pose, (0.5, 0.25, 0.0), (0.0, 0.0, -0.75))
    states.publish()
    (raw,) = states.publisher.sent
    buffer = BytesIO()
    raw.serialize(buffer)
    message = ModelStates().deserialize(buffer.getvalue())
    assert message.name == ["ground_plane", "crate", "mbot"]
    crate, mbot = message.pose[1], message.pose[2]
    assert (crate.position.x, crate.position.y, crate.position.z) == (3.0, 0.0, 0.5)
    # PyBullet keeps a body's centre of mass in float32 here and there: a micrometre is the engine's, not a fault.
    assert (mbot.position.x, mbot.position.y, mbot.position.z) == pytest.approx((1.0, -2.0, 0.3), abs=1e-6)
    assert (mbot.orientation.z, mbot.orientation.w) == pytest.approx((math.sin(0.3), math.cos(0.3)), abs=1e-6)
    twist = message.twist[2]
    assert (twist.linear.x, twist.linear.y, twist.angular.z) == pytest.approx((0.5, 0.25, -0.75), abs=1e-6)
    states.publisher.connections = 0
    states.publish()
    assert len(states.publisher.sent) == 1
