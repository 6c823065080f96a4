#!/usr/bin/env python3
"""Speed figures of the simulator, printed one per line (``./mbot bench``).

(a) raw PyBullet: the course's mbot driven by the core's diff-drive loop in the empty world, no ROS;
(b) the bridge: mbot_gazebo's mbot_world.launch (the mbot in the empty world) at real-time factor 0 with every
topic subscribed; the real-time factor of each and their ratio, the CPU seconds per sim second of every process
(the bridge, its writer, rosmaster, robot_state_publisher, this subscribing client) and the ratio they leave room
for, and the wall time from roslaunch to the first /odom (median of several launches);
then 1, 10 and 50 robots and a 5,000-box world (bench_scale.py), ros_control beside the diff-drive plugin
(bench_ros_control.py), the cost of one lidar scan (bench_lidar.py), and the cameras' and IMU's (bench_cameras.py).
Every figure goes to results.json, from which the README's speed table is generated (results.py).
``--short`` runs every row at smoke-test sizes and durations (1, 2 and 3 robots, 300 boxes, quarter-size camera
images; one launch timed on the real-time factor's own launch) and writes no file unless ``--results`` says where.
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from typing import Dict

import rospy
from mbot_sim_bridge.processes import PrivateMaster, stop_process_group
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from results import (README, RECORD_ENV, RESULTS, load, parse_arguments, recorded, report, wait_for_clock,
                     with_table, write_results)

HERE = os.path.dirname(os.path.abspath(__file__))
WORKSPACE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
STEP = 0.001
WHEELS = ("left_wheel_joint", "right_wheel_joint")
# --short: every figure measured over this little time (each script has its own short settings).
SHORT_SIM_SECONDS = 0.2
SHORT_WALL_SECONDS = 0.05


def raw_pybullet_rtf(sim_seconds: float) -> float:
    from mbot_sim_bridge.core.drives.diff_drive import DiffDriveGeometry, WheelSpeedRamp
    from mbot_sim_bridge.core.engine import Engine
    from mbot_sim_bridge.core.description.robot_model import parse_robot
    from mbot_sim_bridge.core.description.sdf_world import parse_world
    from mbot_sim_bridge.core.world_bodies import load_world
    from mbot_sim_bridge.robot_description import expand_xacro

    urdf = expand_xacro(os.path.join(WORKSPACE, "src", "mbot_description", "urdf", "gazebo", "mbot_gazebo.xacro"))
    engine = Engine()
    engine.add_world(load_world(engine.client, parse_world(os.path.join(WORKSPACE, "worlds", "empty.world"))))
    robot = engine.spawn_robot(parse_robot(urdf), "mbot", driven_joints=WHEELS)
    geometry, ramp = DiffDriveGeometry(0.24, 0.032, True), WheelSpeedRamp(1.8)
    started, last = time.perf_counter(), 0.0
    # The bridge's work minus ROS: step, and at 100 Hz read the wheels and set their motors.
    for _ in range(int(sim_seconds / STEP)):
        engine.step()
        if engine.sim_time - last > 0.01 + 1e-9:
            measured = [rate * 0.032 for _, rate, _ in robot.joint_state(WHEELS)]
            speeds = ramp.step(geometry.wheel_rim_speeds(0.3, 0.5), measured, engine.sim_time - last)
            last += 0.01
            for joint, speed in zip(WHEELS, speeds):
                robot.set_joint_velocity(joint, speed / 0.032, 30.0)
    elapsed = time.perf_counter() - started
    engine.close()
    return sim_seconds / elapsed


MBOT_WORLD = ("mbot_gazebo", "mbot_world.launch", "gui:=false", "real_time_factor:=0")
# The same roslaunch with a bare rospy node publishing /odom in the simulator's place.
LAUNCH_FLOOR = (os.path.join(HERE, "launch_floor.launch"),)


def _launch(arguments=MBOT_WORLD):
    return subprocess.Popen(["roslaunch", *arguments], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)


def first_odom_seconds(arguments=MBOT_WORLD) -> float:
    """Wall time from roslaunch to the first /odom: one launch, stopped again."""
    started = time.monotonic()
    launch = _launch(arguments)
    try:
        rospy.wait_for_message("/odom", Odometry, timeout=120)
        return time.monotonic() - started
    finally:
        stop_process_group(launch)


# What each process on the machine is, by a word of its command line; this bench is the subscribing client.
PROCESS_KINDS = (("gzserver", "bridge"), ("wire_writer", "writer"), ("rosmaster", "rosmaster"),
                 ("robot_state_publisher", "robot_state_publisher"))


def cpu_seconds_by_kind() -> Dict[str, float]:
    """CPU seconds (user and system) used so far by every process on the machine, summed by kind."""
    tick, mine = os.sysconf("SC_CLK_TCK"), str(os.getpid())
    totals: Dict[str, float] = {}
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{pid}/stat") as stat, open(f"/proc/{pid}/cmdline", "rb") as cmdline:
                fields, command = stat.read().rsplit(")", 1)[1].split(), cmdline.read().decode(errors="replace")
        except OSError:  # the process ended meanwhile
            continue
        kind = "client" if pid == mine else next((kind for word, kind in PROCESS_KINDS if word in command), "other")
        totals[kind] = totals.get(kind, 0.0) + (int(fields[11]) + int(fields[12])) / tick
    return totals


def bridge_rtf(wall_seconds: float):
    """(real-time factor, topics subscribed, CPU seconds per sim second by process kind, cores busy, seconds from
    roslaunch to the first /odom) of one launch with every topic subscribed."""
    started = time.monotonic()
    launch = _launch()
    try:
        rospy.wait_for_message("/odom", Odometry, timeout=120)
        first_odom = time.monotonic() - started
        clock = []
        subscribers = [rospy.Subscriber("/clock", Clock, lambda m: clock.append((time.monotonic(),
                                                                                m.clock.to_sec())))]
        # rospy shares one connection per topic, so /clock is left out of the untyped subscriptions.
        subscribers += [rospy.Subscriber(topic, rospy.AnyMsg, lambda message: None)
                        for topic, _ in rospy.get_published_topics() if topic != "/clock"]
        time.sleep(min(1.0, 4 * wall_seconds))  # let every subscription connect before the measured window
        window_start, cpu_start = len(clock), cpu_seconds_by_kind()
        time.sleep(wall_seconds)
        wait_for_clock(clock, window_start + 2)  # a short window on a loaded machine may hold none yet
        cpu_end = cpu_seconds_by_kind()
        (wall0, sim0), (wall1, sim1) = clock[window_start], clock[-1]
        for subscriber in subscribers:
            subscriber.unregister()
        used = {kind: cpu_end[kind] - cpu_start.get(kind, 0.0) for kind in cpu_end}
        per_sim_second = {kind: seconds / (sim1 - sim0) for kind, seconds in used.items()}
        cores_busy = sum(used.values()) / (wall1 - wall0)
        return (sim1 - sim0) / (wall1 - wall0), len(subscribers), per_sim_second, cores_busy, first_odom
    finally:
        stop_process_group(launch)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sim-seconds", type=float, default=20.0, help="sim time of the raw PyBullet run")
    parser.add_argument("--wall-seconds", type=float, default=10.0, help="wall time the bridge is measured")
    parser.add_argument("--launches", type=int, default=7, help="launches timed to the first /odom")
    parser.add_argument("--results", metavar="FILE",
                        help=f"where the figures are written (default {os.path.relpath(RESULTS, WORKSPACE)}, whose "
                             "README table is then regenerated; --short writes only here)")
    args = parse_arguments(parser, "every row at smoke-test sizes and durations")
    if args.short:
        args.sim_seconds, args.wall_seconds = SHORT_SIM_SECONDS, SHORT_WALL_SECONDS
    with tempfile.TemporaryDirectory(prefix="mbot_bench_logs_") as logs:
        # Every ROS process of the bench logs here, not into ~/.ros/log: roslaunch measures the size of its log
        # directory (du) at each start, which grows with every run there and would count in the launch times.
        os.environ["ROS_LOG_DIR"] = logs
        os.environ[RECORD_ENV] = os.path.join(logs, "figures.jsonl")
        raw = run(args)
        if args.results or not args.short:
            write_results(args.results or RESULTS, recorded(os.environ[RECORD_ENV]), raw, args.short)
        if not args.results and not args.short:
            with open(README) as stream:
                text = stream.read()
            with open(README, "w") as stream:
                stream.write(with_table(text, load()))
            print(f"figures written to {RESULTS} and the speed table of {os.path.normpath(README)}")


def run(args) -> float:
    raw = raw_pybullet_rtf(args.sim_seconds)
    report("one mbot, raw PyBullet real-time factor", f"{raw:.2f}")
    with PrivateMaster() as master:
        os.environ["ROS_MASTER_URI"] = master.uri  # for this process's rospy and the launches
        rospy.init_node("bench_bridge", disable_signals=True)
        bridge, topics, cpu, cores_busy, first_odom = bridge_rtf(args.wall_seconds)
        report("one mbot, bridge real-time factor", f"{bridge:.2f} ({topics} topics subscribed)")
        report("one mbot, bridge / raw", f"{bridge / raw:.2f}")
        report("one mbot, CPU seconds per sim second",
               f"raw PyBullet {1 / raw:.4f}; "
               + ", ".join(f"{kind} {seconds:.4f}" for kind, seconds in sorted(cpu.items(), key=lambda kv: -kv[1]))
               + f"; cores busy {cores_busy:.2f} of {os.cpu_count()}")
        # The ceiling the other processes leave: a bridge costing what raw PyBullet costs, on every core.
        beside = sum(seconds for kind, seconds in cpu.items() if kind != "bridge")
        report("one mbot, bridge / raw at most (the processes beside the bridge as measured, a bridge costing what "
               "raw PyBullet does)", f"{os.cpu_count() / (1 / raw + beside) / raw:.2f}")
        # One launch varies by a few tenths of a second (process start-up, scheduling): the median of several,
        # each beside a launch of the floor, in turn. A short run times the launch measured above.
        if args.short:
            pairs = [(first_odom, first_odom_seconds(LAUNCH_FLOOR))]
        else:
            pairs = [(first_odom_seconds(), first_odom_seconds(LAUNCH_FLOOR)) for _ in range(args.launches)]
        launches, floors = sorted(launch for launch, _ in pairs), sorted(floor for _, floor in pairs)
        report("roslaunch to the first /odom", f"median {statistics.median(launches):.2f} s ({len(launches)} "
               f"launches, {launches[0]:.2f} to {launches[-1]:.2f} s)")
        report("the same roslaunch with a bare rospy node publishing /odom (launch_floor.launch)",
               f"median {statistics.median(floors):.2f} s ({floors[0]:.2f} to {floors[-1]:.2f} s); the simulator's "
               f"part: median {statistics.median(launch - floor for launch, floor in pairs):.2f} s")
    # The others, each in a process of its own (each starts its own master and rospy node).
    for script in ("bench_scale.py", "bench_ros_control.py", "bench_lidar.py", "bench_lidar3d.py", "bench_stereo.py",
                   "bench_cameras.py"):
        status = subprocess.call([sys.executable, os.path.join(HERE, script), *(["--short"] if args.short else [])])
        if status:
            sys.exit(status)
    return raw


if __name__ == "__main__":
    main()
