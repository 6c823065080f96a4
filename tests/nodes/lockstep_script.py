#!/usr/bin/env python3
"""A lockstep script against a running bridge (tests/launch/lockstep_mbot.launch), for test_lockstep.py.

1. A drive script with turns and stops from the launch's fresh start, recording /odom, /scan, /joint_states
   and /tf serialized, per publishing node.
2. Ordering: 20 times, reset_simulation, publish a command and step 11 then 10 steps. The diff drive reads
   its command at its first update (step 11); if the command had not been applied before the steps, the
   odometry after step 21 would still be at rest.
3. reset_simulation and the drive script again.
Writes a pickle to argv[1]: {"moved": [bool] * 20, "first": recording, "after_reset": recording}, where a
recording maps (topic, publishing node) to the serialized messages in arrival order.
"""
import pickle
import sys

import rospy
from gazebo_msgs.srv import GetWorldProperties
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from std_srvs.srv import Empty

from mbot_sim_bridge.lockstep import LockstepClient

# (linear m/s, angular rad/s, steps): 3.5 s of sim time with turns, reversing and stops.
SCRIPT = [(0.3, 0.0, 400), (0.3, 0.6, 300), (0.0, -1.0, 250), (-0.2, 0.0, 300), (0.5, 0.3, 500),
          (0.0, 0.0, 150), (0.2, -0.4, 600), (0.0, 0.0, 200), (0.4, 1.2, 350), (0.0, 0.0, 450)]


def twist(linear, angular=0.0):
    message = Twist()
    message.linear.x, message.angular.z = linear, angular
    return message


def deserialized(raw, message_type):
    message = message_type()
    message.deserialize(raw)
    return message


def ordering_trials(sim, cmd_vel, recorder, reset, count=20):
    moved = []
    for _ in range(count):
        reset()
        recorder.clear()
        cmd_vel.publish(twist(0.3))
        sim.step(11)
        sim.step(10)
        sim.settle()
        odometry = deserialized(recorder.messages("/odom")[("/odom", "/gazebo")][-1], Odometry)
        moved.append(odometry.twist.twist.linear.x > 0.001)
    return moved


def drive_script(sim, cmd_vel, recorder):
    recorder.clear()
    for linear, angular, steps in SCRIPT:
        cmd_vel.publish(twist(linear, angular))
        sim.step(steps)
    sim.settle()
    return recorder.messages()


def main():
    rospy.init_node("lockstep_script", disable_signals=True)
    sim = LockstepClient()
    world = rospy.ServiceProxy("/gazebo/get_world_properties", GetWorldProperties)
    sim._wait(lambda: "mbot" in world().model_names, "the mbot to be spawned")
    reset = rospy.ServiceProxy("/gazebo/reset_simulation", Empty)
    cmd_vel = sim.publisher("/cmd_vel", Twist)
    # /tf has two publishers, the bridge (odom) and robot_state_publisher; both are recorded.
    recorder = sim.recorder(["/odom", "/scan", "/joint_states", "/tf"], publishers={"/tf": 2})
    first = drive_script(sim, cmd_vel, recorder)
    moved = ordering_trials(sim, cmd_vel, recorder, reset)
    reset()
    after_reset = drive_script(sim, cmd_vel, recorder)
    with open(sys.argv[1], "wb") as stream:
        pickle.dump({"moved": moved, "first": first, "after_reset": after_reset}, stream)
    sim.close()


if __name__ == "__main__":
    main()
