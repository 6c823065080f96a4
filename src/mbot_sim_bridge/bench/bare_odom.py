#!/usr/bin/env python3
"""launch_floor.launch's node: rospy started as the simulator starts it and one /odom published (latched),
nothing else; then idle."""
import rospy
from mbot_sim_bridge.processes import init_node
from nav_msgs.msg import Odometry

init_node("bare_odom")
odom = rospy.Publisher("/odom", Odometry, queue_size=1, latch=True)
odom.publish(Odometry())
rospy.spin()
