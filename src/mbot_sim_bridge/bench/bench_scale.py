#!/usr/bin/env python3
"""Scale figures, each as raw, bridge and their ratio (``./mbot bench``):

- 1, 10 and 50 lidar mbots turning in the play ground (the scaling row; ten is the issue table's row): raw is
  the Simulation with the plugins' core classes (the same PyBullet stepping, wheel control and ray casts, no
  ROS); the bridge is multi_mbot.launch count:=N at real-time factor 0 with every scan and odometry subscribed;
- a world of 5,000 static boxes: raw is the PyBullet world stepped alone; the bridge loads it at real-time
  factor 0 with every topic (model_states included) subscribed.
Real-time factors are sim seconds per wall second; the bridge's is read from /clock over the window.
``--short``: 1, 2 and 3 robots and 300 boxes, over tiny durations.
"""
import argparse
import os
import subprocess
import tempfile
import time

import rospy
from mbot_sim_bridge.processes import PrivateMaster, stop_process_group
from rosgraph_msgs.msg import Clock
from results import parse_arguments, report, wait_for_clock

HERE = os.path.dirname(os.path.abspath(__file__))
WORKSPACE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
ROBOT_COUNTS, SHORT_ROBOT_COUNTS = (1, 10, 50), (1, 2, 3)
BOXES, SHORT_BOXES = 5000, 300


def raw_robots_rtf(robots: int, sim_seconds: float) -> float:
    from mbot_sim_bridge.core.drives.diff_drive import DiffDrive
    from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy
    from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS
    from mbot_sim_bridge.core.description.robot_model import parse_robot
    from mbot_sim_bridge.core.description.sdf_world import parse_world
    from mbot_sim_bridge.core.simulation import Simulation
    from mbot_sim_bridge.robot_description import expand_xacro

    urdf = expand_xacro(os.path.join(WORKSPACE, "src", "mbot_description", "urdf", "gazebo",
                                     "mbot_with_laser_gazebo.xacro"))
    sim = Simulation(parse_world(os.path.join(WORKSPACE, "worlds", "playground.world")), CORE_PLUGINS)
    for index in range(robots):  # the places and turn rates of multi_mbot.launch and the bridge run below
        place = pose_from_xyz_rpy((-1.0 + 0.8 * (index % 5), -0.5 + 1.0 * (index // 5), 0), (0, 0, 0))
        spawned = sim.spawn_robot(parse_robot(urdf), f"mbot_{index + 1}", place)
        next(p for p in spawned.plugins if isinstance(p, DiffDrive)).set_command(0.0, turn_rate(index))
    started = time.perf_counter()
    sim.step(int(sim_seconds / sim.step_size))
    elapsed = time.perf_counter() - started
    sim.close()
    return sim_seconds / elapsed


def turn_rate(index: int) -> float:
    return 0.1 * (index + 1) * (-1) ** index


def box_world(path: str, boxes: int):
    """``boxes`` static 0.2 m boxes on a 0.5 m grid, and the ground."""
    rows = ["<sdf version='1.6'><world name='boxes'><include><uri>model://ground_plane</uri></include>"]
    side = int(boxes ** 0.5) + 1
    for index in range(boxes):
        x, y = 0.5 * (index % side), 0.5 * (index // side)
        rows.append(f"<model name='box_{index}'><static>true</static><pose>{x:g} {y:g} 0.1 0 0 0</pose>"
                    "<link name='l'><collision name='c'><geometry><box><size>0.2 0.2 0.2</size></box></geometry>"
                    "</collision></link></model>")
    rows.append("</world></sdf>")
    with open(path, "w") as stream:
        stream.write("\n".join(rows))


def raw_boxes_rtf(world_path: str, sim_seconds: float) -> float:
    from mbot_sim_bridge.core.engine import Engine
    from mbot_sim_bridge.core.description.sdf_world import parse_world
    from mbot_sim_bridge.core.world_bodies import load_world

    engine = Engine()
    engine.add_world(load_world(engine.client, parse_world(world_path)))
    started = time.perf_counter()
    engine.step(int(sim_seconds / engine.physics.max_step_size))
    elapsed = time.perf_counter() - started
    engine.close()
    return sim_seconds / elapsed


def bridge_rtf(command, ready_topics, wall_seconds: float, commands=None) -> float:
    """Launch ``command``; once every topic of ``ready_topics`` publishes, subscribe every topic and measure."""
    launch = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        deadline = time.monotonic() + 300
        while not set(ready_topics) <= {topic for topic, _ in rospy.get_published_topics()}:
            if time.monotonic() > deadline or launch.poll() is not None:
                raise RuntimeError(f"{' '.join(command)} did not come up")
            time.sleep(0.2)
        publishers = [rospy.Publisher(topic, message.__class__, queue_size=1, latch=True)
                      for topic, message in (commands or {}).items()]
        for publisher, message in zip(publishers, (commands or {}).values()):
            publisher.publish(message)
        clock = []
        subscribers = [rospy.Subscriber("/clock", Clock, lambda m: clock.append((time.monotonic(),
                                                                                m.clock.to_sec())))]
        subscribers += [rospy.Subscriber(topic, rospy.AnyMsg, lambda message: None)
                        for topic, _ in rospy.get_published_topics() if topic != "/clock"]
        time.sleep(min(2.0, 4 * wall_seconds))  # every subscription connects, the robots reach their commanded turn
        window_start = len(clock)
        time.sleep(wall_seconds)
        wait_for_clock(clock, window_start + 2)  # a short window of a slow world may hold none yet
        (wall0, sim0), (wall1, sim1) = clock[window_start], clock[-1]
        for item in subscribers + publishers:
            item.unregister()
        return (sim1 - sim0) / (wall1 - wall0)
    finally:
        stop_process_group(launch)


def main():
    from geometry_msgs.msg import Twist

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sim-seconds", type=float, default=5.0,
                        help="sim time of each raw run of up to ten robots (fewer for more robots)")
    parser.add_argument("--box-sim-seconds", type=float, default=0.5, help="sim time of the raw box-world run")
    parser.add_argument("--wall-seconds", type=float, default=10.0, help="wall time each bridge run is measured")
    args = parse_arguments(parser, "1, 2 and 3 robots, 300 boxes, tiny durations")
    robot_counts, boxes = ROBOT_COUNTS, BOXES
    if args.short:
        robot_counts, boxes = SHORT_ROBOT_COUNTS, SHORT_BOXES
        args.sim_seconds, args.box_sim_seconds, args.wall_seconds = 0.1, 0.05, 0.05

    def report_ratio(what, raw, bridge):
        report(what, f"raw PyBullet {raw:.2f}, bridge {bridge:.2f}, bridge / raw {bridge / raw:.2f}")

    # The raw runs go first: once rospy is up, the plugins' rosDebugLevel Debug would print every tag read.
    raw_robots = {count: raw_robots_rtf(count, args.sim_seconds * min(1.0, 10 / count)) for count in robot_counts}
    with tempfile.TemporaryDirectory() as directory:
        world = os.path.join(directory, "boxes.world")
        box_world(world, boxes)
        raw_boxes = raw_boxes_rtf(world, args.box_sim_seconds)
        with PrivateMaster() as master:
            os.environ["ROS_MASTER_URI"] = master.uri
            rospy.init_node("bench_scale", disable_signals=True)
            for count in robot_counts:
                commands = {}
                for index in range(count):
                    twist = Twist()
                    twist.angular.z = turn_rate(index)
                    commands[f"/mbot_{index + 1}/cmd_vel"] = twist
                bridge = bridge_rtf(["roslaunch", "mbot_gazebo", "multi_mbot.launch", f"count:={count}",
                                     "gui:=false", "real_time_factor:=0"],
                                    [f"/mbot_{n}/odom" for n in range(1, count + 1)], args.wall_seconds, commands)
                report_ratio(f"scaling, {count} lidar mbot{'s' if count > 1 else ''}, real-time factor",
                             raw_robots[count], bridge)
            bridge = bridge_rtf(["roslaunch", "mbot_sim_bridge", "empty_world.launch", "gui:=false",
                                 "real_time_factor:=0", "world_name:=" + world], ["/clock"], args.wall_seconds)
            report_ratio(f"{boxes} static boxes, real-time factor", raw_boxes, bridge)


if __name__ == "__main__":
    main()
