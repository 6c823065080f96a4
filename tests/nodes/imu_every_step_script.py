#!/usr/bin/env python3
"""libgazebo_ros_imu.so at updateRate 0 through the bridge, in lockstep (tests/launch/lockstep_imu.launch),
for test_imu_every_step.py: prints one 'figure:' line per check, or exits non-zero naming the check.

1. Once /imu is read, every physics step has its own message by the time step_simulation answers: one for
   one step, 237 for 237 steps, stamped a step apart, header.seq counting on.
2. While the robot turns, the messages say so (angular_velocity.z near the commanded rate).
3. reset_simulation and the same steps again: the same messages byte for byte (header.seq aside).
"""
import sys

import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import Imu
from std_srvs.srv import Empty

from mbot_sim_bridge.lockstep import LockstepClient

TOPIC = "/imu"
STEP = 0.001


def messages(recorder):
    raws = recorder.messages(TOPIC).get((TOPIC, "/gazebo"), [])
    decoded = []
    for raw in raws:
        message = Imu()
        message.deserialize(raw)
        decoded.append(message)
    return raws, decoded


def check(condition, what):
    if not condition:
        sys.exit(f"failed: {what}")


def steps_and_messages(sim, recorder, steps):
    sim.settle()  # earlier steps' messages are written but may not all be read yet
    recorder.clear()
    sim_time = sim.step(steps)
    sim.settle()
    raws, decoded = messages(recorder)
    check(len(decoded) == steps, f"{steps} steps gave {len(decoded)} {TOPIC} messages")
    stamps = [message.header.stamp.to_sec() for message in decoded]
    check(abs(stamps[-1] - sim_time) < 1e-9, f"the last stamp {stamps[-1]} is not the sim time {sim_time}")
    check(all(abs(b - a - STEP) < 1e-9 for a, b in zip(stamps, stamps[1:])), f"stamps not a step apart: {stamps}")
    seqs = [message.header.seq for message in decoded]
    check(seqs == list(range(seqs[0], seqs[0] + steps)), f"header.seq does not count on: {seqs}")
    return raws, decoded


def turning_run(sim, cmd_vel, recorder):
    command = Twist()
    command.angular.z = 0.8
    cmd_vel.publish(command)
    sim.step(300)
    raws, decoded = steps_and_messages(sim, recorder, 237)
    return [raw[4:] for raw in raws], decoded  # header.seq counts on across a reset


def main():
    rospy.init_node("imu_every_step_script", disable_signals=True)
    sim = LockstepClient()
    recorder = sim.recorder([TOPIC])
    cmd_vel = sim.publisher("/cmd_vel", Twist)
    sim.step(100)  # unread until now, the plugin looks every 50 ms of sim time; read, it records every step
    steps_and_messages(sim, recorder, 1)
    steps_and_messages(sim, recorder, 237)
    print("figure: /imu at updateRate 0 in lockstep: 1 message for 1 step, 237 for 237 steps, stamped 1 ms apart")

    reset = rospy.ServiceProxy("/gazebo/reset_simulation", Empty)
    reset()
    first, decoded = turning_run(sim, cmd_vel, recorder)
    rate = sum(message.angular_velocity.z for message in decoded) / len(decoded)
    check(abs(rate - 0.8) < 0.05, f"turning at 0.8 rad/s, /imu says {rate:.3f}")
    reset()
    again, _ = turning_run(sim, cmd_vel, recorder)
    check(again == first, "after reset_simulation the same steps gave different /imu messages")
    print(f"figure: turning: angular_velocity.z {rate:.3f} rad/s (commanded 0.8); after reset_simulation the same "
          f"{len(first)} messages byte for byte")
    sim.close()


if __name__ == "__main__":
    main()
