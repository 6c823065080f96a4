"""model_states.py: the hand-made ModelStates bytes are what genpy would write for the same models."""
from io import BytesIO

import numpy as np
from gazebo_msgs.msg import ModelStates
from geometry_msgs.msg import Pose, Twist

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
