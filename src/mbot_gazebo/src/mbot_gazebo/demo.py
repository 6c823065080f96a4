"""``./mbot demo``: the mbot with its lidar tours a world headless, then a picture shows what it saw.

Starts a private ROS master and the course's launch file in lockstep, drives a scripted tour through /cmd_vel
(closed loop on /odom at 20 Hz of sim time, stepping the simulation itself, so the tour is the same on any
machine and under any load), records /odom and /scan (through TF into odom), and writes out/demo.png with a
picture of the world, as the course's kinect sees it from the final pose, beside the top view.
"""
import argparse
import contextlib
import logging
import math
import os
import subprocess
import sys
import time

import numpy
import rospkg
import rospy
from mbot_sim_bridge.core.log import c_stdout_to, get_logger
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.lockstep import LockstepClient
from mbot_sim_bridge.processes import PrivateMaster, stop_process_group

from . import arm_demo, pick_demo
from .demo_plot import draw_demo
from .tour import Recorder, Tour

WORLDS = {"play_ground": "playground.world", "playground": "playground.world", "room": "room.world",
          "empty": "empty.world"}
STARTUP_TIMEOUT = 120.0


def main(argv=None):
    parser = argparse.ArgumentParser(prog="mbot demo", description=__doc__.splitlines()[0])
    parser.add_argument("--world", default="play_ground", choices=sorted(WORLDS), help="world to tour")
    parser.add_argument("--gui", action="store_true", help="show the simulator window (needs a DISPLAY)")
    parser.add_argument("--arm", action="store_true",
                        help="instead of the tour: the arm follows a trajectory, drawn to out/arm.png")
    parser.add_argument("--pick", action="store_true",
                        help="instead of the tour: the arm picks a box and places it, drawn to out/pick.png")
    parser.add_argument("--sim-seconds", type=float, default=math.inf,
                        help="end the tour after this much sim time, wherever it is (a short look)")
    parser.add_argument("--out", help="picture to write (default out/demo.png, out/arm.png or out/pick.png)")
    args = parser.parse_args(argv)
    if not args.sim_seconds > 0:
        parser.error(f"--sim-seconds must be a positive number of seconds, not {args.sim_seconds}")
    if (args.arm or args.pick) and args.sim_seconds != math.inf:
        parser.error(f"--sim-seconds shortens the tour; --{'arm' if args.arm else 'pick'} runs to its end")
    picture = "arm.png" if args.arm else "pick.png" if args.pick else "demo.png"
    args.out = args.out or os.path.join(os.getcwd(), "out", picture)
    if args.arm:
        return arm_demo.run(args.out, args.gui)
    if args.pick:
        return pick_demo.run(args.out, args.gui)

    world_path = os.path.join(rospkg.RosPack().get_path("mbot_gazebo"), "worlds", WORLDS[args.world])
    model = os.path.join(rospkg.RosPack().get_path("mbot_description"), "urdf", "gazebo",
                         "mbot_with_laser_gazebo.xacro")
    log_dir = os.path.join(os.path.dirname(os.path.abspath(args.out)), "demo_logs")
    os.makedirs(log_dir, exist_ok=True)
    started = time.monotonic()
    with PrivateMaster() as master:
        # This process talks to the private master too (rospy reads the environment at init_node).
        os.environ.update(ROS_MASTER_URI=master.uri, ROS_LOG_DIR=log_dir)
        with open(os.path.join(log_dir, "roslaunch.log"), "w") as launch_log:
            simulation = subprocess.Popen(
                ["roslaunch", "mbot_gazebo", "mbot_world.launch", "world_name:=" + world_path,
                 "model:=" + model, f"gui:={str(args.gui).lower()}", "lockstep:=true"],
                env=os.environ, stdout=launch_log, stderr=subprocess.STDOUT, start_new_session=True)
        try:
            print(f"mbot demo: {args.world} world, lidar mbot, stepped by the tour (log: {os.path.relpath(log_dir)})",
                  file=sys.stderr, flush=True)
            return tour_and_draw(args, world_path, started, log_dir)
        except KeyboardInterrupt:
            print("\nmbot demo: interrupted", file=sys.stderr)
            return 130
        finally:
            stop_process_group(simulation)


@contextlib.contextmanager
def core_logs_to(path: str):
    """The simulation core's log records and PyBullet's own stdout go to ``path`` only: the course's xacro sets
    rosDebugLevel Debug, which would otherwise print every tag read on the console after the summary."""
    logger = logging.getLogger(get_logger("mbot_sim_bridge").name)
    handler = logging.FileHandler(path)
    handler.setFormatter(logging.Formatter("[%(levelname)s] %(name)s: %(message)s"))
    propagate, level = logger.propagate, logger.level
    logger.addHandler(handler)
    logger.propagate = False
    try:
        with c_stdout_to(handler.stream):
            yield
    finally:
        logger.removeHandler(handler)
        handler.close()
        logger.propagate, logger.level = propagate, level


def camera_frame(world_path: str, x: float, y: float, yaw: float, log_path: str):
    """What the course's kinect would see from the robot's final pose: one frame of the same camera code the
    simulator runs (core/cameras/camera.py), rendered in a world of its own, without ROS; its logs go to
    ``log_path``."""
    from mbot_sim_bridge.core.cameras.camera import DepthCamera
    from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy
    from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS
    from mbot_sim_bridge.core.description.robot_model import parse_robot
    from mbot_sim_bridge.core.simulation import Simulation
    from mbot_sim_bridge.robot_description import expand_xacro

    urdf = expand_xacro(os.path.join(rospkg.RosPack().get_path("mbot_description"), "urdf", "gazebo",
                                     "mbot_with_kinect_gazebo.xacro"))
    with core_logs_to(log_path):
        simulation = Simulation(parse_world(world_path), CORE_PLUGINS)
        try:
            spawned = simulation.spawn_robot(parse_robot(urdf, "model 'mbot'"), "mbot",
                                             pose_from_xyz_rpy((x, y, 0.0), (0.0, 0.0, yaw)))
            kinect = next(plugin for plugin in spawned.plugins if isinstance(plugin, DepthCamera))
            return kinect.capture(simulation.sim_time).rgb
        finally:
            simulation.close()


def tour_and_draw(args, world_path, started, log_dir):
    rospy.init_node("mbot_demo", disable_signals=True)
    world = parse_world(world_path)
    try:
        sim = LockstepClient(timeout=STARTUP_TIMEOUT)
        recorder = Recorder(sim)
        tour = Tour(sim, recorder, world.physics.max_step_size, on_terminal=sys.stderr.isatty(),
                    sim_seconds=args.sim_seconds)
    except (rospy.ROSException, RuntimeError) as error:
        print(f"mbot demo: the simulator did not come up: {error} (see the log)", file=sys.stderr)
        return 1
    wall_start = time.monotonic()
    try:
        tour.run()
    except (RuntimeError, rospy.ServiceException) as error:
        print(f"\nmbot demo: {error}", file=sys.stderr)
        return 1
    wall_seconds = time.monotonic() - wall_start
    sim_seconds, x, y, yaw = tour.pose
    path, headings, points, scans = recorder.until(sim_seconds)
    summary = [f"distance driven: {recorder.distance(sim_seconds):.2f} m",
               f"tour: {sim_seconds:.1f} s of sim time in {wall_seconds:.1f} s of wall time (real-time factor "
               f"{sim_seconds / wall_seconds:.1f})",
               f"scans received: {scans} ({len(points)} points)",
               f"final odometry: x {x:.3f} m, y {y:.3f} m, yaw {math.degrees(yaw):.1f} deg"]
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    camera = camera_frame(world_path, x, y, yaw, os.path.join(log_dir, "kinect_frame.log"))
    frame = draw_demo(world, numpy.array(path), numpy.array(points).reshape(-1, 2), args.out,
                      title=f"mbot demo: {args.world}", summary_lines=summary, headings=numpy.array(headings),
                      camera_image=camera, camera_caption="the course's kinect at the end pose (640x480)")
    # Beside the picture: the recorded odometry and where the plot sits in the PNG, so the two can be compared.
    stem = os.path.splitext(args.out)[0]
    numpy.savetxt(stem + "_odometry.csv", numpy.column_stack([path, headings]), delimiter=",",
                  header="x_m,y_m,yaw_rad", comments="")
    frame.save(stem + "_frame.json")
    for line in summary + [f"picture: {os.path.relpath(args.out)}",
                           f"total wall time: {time.monotonic() - started:.1f} s"]:
        print(line)
    return 0
