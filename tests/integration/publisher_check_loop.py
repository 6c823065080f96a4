#!/usr/bin/env python3
"""publisher_check's loop without the simulator: node 'gazebo' publishes the mbot's moving joints at 100 Hz and
calls check_joint_state_publishers on every pass, as the bridge's loop (node.py) does; it prints a line each time a
check starts, which the simulator does not, so that the test can count the checks after the warning."""
import time

import rospy
from mbot_sim_bridge import publisher_check
from mbot_sim_bridge.publisher_check import check_joint_state_publishers
from sensor_msgs.msg import JointState

JOINTS = ["left_wheel_joint", "right_wheel_joint", "back_caster_joint"]

rospy.init_node("gazebo")
publisher = rospy.Publisher("joint_states", JointState, queue_size=10)
angle, checks = 0.0, 0.0
while not rospy.is_shutdown():
    angle += 0.01
    publisher.publish(JointState(name=JOINTS, position=[angle, angle, 0.0]))
    check_joint_state_publishers(rospy.get_name(), (namespace for namespace in ["/"]))
    if publisher_check._CHECK._next_check != checks:  # a check started: the test counts them
        checks = publisher_check._CHECK._next_check
        print("check started", flush=True)
    time.sleep(0.01)
