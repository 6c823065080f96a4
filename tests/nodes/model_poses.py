#!/usr/bin/env python3
"""Print every model's world pose as JSON {name: [x, y, z, qx, qy, qz, qw]}, read through /gazebo/get_model_state
(which answers while paused, when /gazebo/model_states is not published)."""
import json

import rospy
from gazebo_msgs.srv import GetModelState, GetWorldProperties


def main():
    rospy.init_node("model_poses", anonymous=True)
    rospy.wait_for_service("/gazebo/get_model_state", timeout=60)
    names = rospy.ServiceProxy("/gazebo/get_world_properties", GetWorldProperties)().model_names
    get_state = rospy.ServiceProxy("/gazebo/get_model_state", GetModelState)
    poses = {}
    for name in names:
        pose = get_state(name, "").pose
        poses[name] = [pose.position.x, pose.position.y, pose.position.z, pose.orientation.x, pose.orientation.y,
                       pose.orientation.z, pose.orientation.w]
    print(json.dumps(poses))


if __name__ == "__main__":
    main()
