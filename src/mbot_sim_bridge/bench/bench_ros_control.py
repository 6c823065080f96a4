#!/usr/bin/env python3
"""Real-time factor of the mbot driven through ros_control beside the mbot driven by the diff-drive plugin.

Each runs in the empty world at real-time factor 0 (as fast as the machine goes), headless, with
robot_state_publisher, driving a 0.3 m/s, 0.5 rad/s circle, and every topic subscribed; the figure is sim
seconds per wall second over the window, the median of rounds that run the three variants in turn. ros_control
runs its controllers every physics step (controlPeriod defaults to the step, as in gazebo_ros_control); the
plugin updates at its updateRate (100 Hz). The third variant gives the controllers the plugin's rate
(controlPeriod 0.01 s).
"""
import argparse
import os
import statistics
import subprocess
import time

import rospy
from geometry_msgs.msg import Twist
from mbot_sim_bridge.processes import PrivateMaster, stop_process_group
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from results import parse_arguments, report, wait_for_clock

HERE = os.path.dirname(os.path.abspath(__file__))


def real_time_factor(ros_control: bool, wall_seconds: float, control_period: str = "") -> float:
    """Launch one variant against the running master, measure, stop it."""
    launch = subprocess.Popen(["roslaunch", os.path.join(HERE, "mbot_bench.launch"),
                               f"ros_control:={str(ros_control).lower()}", f"control_period:={control_period}"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        prefix = "/mobile_base_controller" if ros_control else ""
        rospy.wait_for_message(prefix + "/odom", Odometry, timeout=120)
        command = rospy.Publisher(prefix + "/cmd_vel", Twist, queue_size=1)
        twist = Twist()
        twist.linear.x, twist.angular.z = 0.3, 0.5
        clock = []
        subscribers = [rospy.Subscriber("/clock", Clock, lambda m: clock.append((time.monotonic(),
                                                                                m.clock.to_sec())))]
        subscribers += [rospy.Subscriber(topic, rospy.AnyMsg, lambda message: None)
                        for topic, _ in rospy.get_published_topics() if topic != "/clock"]
        deadline = time.monotonic() + min(1.0, 4 * wall_seconds) + wall_seconds
        window_start = None
        while time.monotonic() < deadline:
            command.publish(twist)  # every 10 ms of wall time: within cmd_vel_timeout (0.5 s) at any speed here
            time.sleep(0.01)
            if window_start is None and time.monotonic() > deadline - wall_seconds:
                window_start = len(clock)
        wait_for_clock(clock, window_start + 2)  # a short window on a loaded machine may hold none yet
        (wall0, sim0), (wall1, sim1) = clock[window_start], clock[-1]
        for subscriber in subscribers:
            subscriber.unregister()
        command.unregister()
        return (sim1 - sim0) / (wall1 - wall0)
    finally:
        stop_process_group(launch)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--wall-seconds", type=float, default=5.0, help="wall time each robot is measured")
    parser.add_argument("--rounds", type=int, default=3, help="rounds of the three runs, measured in turn")
    args = parse_arguments(parser, "one round, tiny durations")
    if args.short:
        args.wall_seconds, args.rounds = 0.05, 1
    with PrivateMaster() as master:
        os.environ["ROS_MASTER_URI"] = master.uri  # for this process's rospy
        rospy.init_node("bench_ros_control", disable_signals=True)
        # One run's ratio moves by several hundredths with what else the machine does: runs in turn, medians.
        rounds = [(real_time_factor(False, args.wall_seconds), real_time_factor(True, args.wall_seconds),
                   real_time_factor(True, args.wall_seconds, "0.01")) for _ in range(args.rounds)]
        plugin, controlled, at_plugin_rate = (statistics.median(column) for column in zip(*rounds))
        report("plugin-driven mbot real-time factor", f"{plugin:.2f}")
        report("ros_control mbot real-time factor", f"{controlled:.2f}")
        ratios = sorted(run[1] / run[0] for run in rounds)
        report("ros_control / plugin", f"{statistics.median(ratios):.2f} (target >= 0.8; median of {len(rounds)} "
               f"rounds, {ratios[0]:.2f} to {ratios[-1]:.2f})")
        report("ros_control mbot with controlPeriod 0.01 s (the plugin's 100 Hz) real-time factor",
               f"{at_plugin_rate:.2f}; / plugin: {statistics.median(run[2] / run[0] for run in rounds):.2f}")

if __name__ == "__main__":
    main()
