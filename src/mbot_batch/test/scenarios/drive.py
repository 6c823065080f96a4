"""A short scenario for the batch tests: the mbot drives straight at the run's speed for a second of sim time."""
import time

import rospy
from geometry_msgs.msg import Twist
from mbot_batch import scenario
from mbot_sim_bridge.lockstep import LockstepClient
from nav_msgs.msg import Odometry

parameters = scenario.parameters()
if parameters.get("hang"):
    print("hanging on purpose", flush=True)
    while True:
        time.sleep(1)
rospy.init_node("drive_scenario", disable_signals=True)
sim = LockstepClient(timeout=60)
cmd_vel = sim.publisher("/cmd_vel", Twist)
odometry = sim.recorder(["/odom"])
command = Twist()
command.linear.x = parameters.get("speed", 0.2)
command.angular.z = parameters.get("turn", 0.0)
cmd_vel.publish(command)
sim_time = sim.step(parameters.get("steps", 1000))
sim.settle()
last = Odometry()
last.deserialize(odometry.messages("/odom", "/gazebo")[("/odom", "/gazebo")][-1])
scenario.metric("x", last.pose.pose.position.x)
scenario.metric("y", last.pose.pose.position.y)
scenario.metric("sim_time", sim_time)
sim.close()
