#!/usr/bin/env python3
"""launch_floor.launch's node: rospy started and one /odom published (latched), nothing else; then idle."""
import rospy
from nav_msgs.msg import Odometry

rospy.init_node("bare_odom")
odom = rospy.Publisher("/odom", Odometry, queue_size=1, latch=True)
odom.publish(Odometry())
rospy.spin()
