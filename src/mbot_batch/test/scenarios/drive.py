#!/usr/bin/env python3
"""A short scenario for the batch tests: the mbot drives at the run's speed and turn rate for a second of sim
time in lockstep, and reports where odometry puts it."""
import rospy
from geometry_msgs.msg import Twist
from mbot_batch import scenario
from mbot_sim_bridge.lockstep import LockstepClient
from nav_msgs.msg import Odometry


def drive(parameters: dict) -> dict:
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
    sim.close()
    return {"x": last.pose.pose.position.x, "y": last.pose.pose.position.y, "sim_time": sim_time}


if __name__ == "__main__":
    rospy.init_node("drive_scenario", disable_signals=True)
    for name, value in drive(scenario.parameters()).items():
        scenario.metric(name, value)
