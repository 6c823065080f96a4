#!/usr/bin/env python3
"""3D lidar cost figures, printed one per line (part of ``./mbot bench``).

The rover (rover_description) in the play ground with its VLP-16-style lidar (16 rings of 440 samples at
10 Hz, Velodyne's plugin): (a) the wall time of one sweep, cast, turned into points and packed and serialized
as the PointCloud2 a subscriber gets; (b) the rover's real-time factor with every sweep built and serialized,
against the same rover without the lidar.

    PYTHONPATH=src/mbot_sim_bridge/src .venv/bin/python src/mbot_sim_bridge/bench/bench_lidar3d.py
"""
import argparse
import logging
import os
import statistics
import time

import numpy as np
from bench_cameras import PLAY_GROUND, WORKSPACE, serialized, timed_rtf
from results import parse_arguments, report
from sensor_msgs.msg import PointCloud2

from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.simulation import Simulation
from mbot_sim_bridge.core.sensors.velodyne_laser import VelodyneLaser
from mbot_sim_bridge.package_uris import resolve_package_uris
from mbot_sim_bridge.plugins.gazebo_ros_velodyne_laser import FIELDS, POINT
from mbot_sim_bridge.robot_description import expand_xacro


def rover_urdf(lidar: bool) -> str:
    path = os.path.join(WORKSPACE, "src", "rover_description", "urdf", "rover.urdf.xacro")
    return resolve_package_uris(expand_xacro(path, lidar_3d_enabled=str(lidar).lower()))


def spawn(lidar: bool):
    sim = Simulation(parse_world(PLAY_GROUND), CORE_PLUGINS)
    spawned = sim.spawn_robot(parse_robot(rover_urdf(lidar), "model 'rover'"), "rover")
    return sim, next((plugin for plugin in spawned.plugins if isinstance(plugin, VelodyneLaser)), None)


def packed_sweep(lidar: VelodyneLaser) -> int:
    """One sweep as the ROS plugin publishes it; returns the serialized size."""
    cloud = lidar.cloud()
    points = np.zeros(len(cloud.ring), dtype=POINT)
    points["x"], points["y"], points["z"] = cloud.xyz.T
    points["intensity"], points["ring"] = cloud.intensity, cloud.ring
    message = PointCloud2(height=1, width=len(points), fields=FIELDS, point_step=POINT.itemsize,
                          row_step=POINT.itemsize * len(points), is_dense=True, data=points.tobytes())
    return serialized(message)


def rtf(lidar: bool, sim_seconds: float) -> float:
    sim, plugin = spawn(lidar)
    try:
        if plugin is not None:
            plugin.update = lambda now: packed_sweep(plugin)
        return timed_rtf(sim, sim_seconds)
    finally:
        sim.close()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sweeps", type=int, default=50, help="sweeps timed")
    parser.add_argument("--sim-seconds", type=float, default=5.0, help="sim time of each real-time-factor run")
    args = parse_arguments(parser, "one sweep, tiny durations")
    if args.short:
        args.sweeps, args.sim_seconds = 1, 0.1
    # The rover's Gazebo-only wheel tags and its robot_description lookup warn on every spawn; the figures are
    # what this prints.
    logging.getLogger("rosout.mbot_sim_bridge").setLevel(logging.ERROR)
    sim, lidar = spawn(True)
    try:
        sim.step(200)
        seconds, size = [], 0
        for _ in range(args.sweeps):
            start = time.perf_counter()
            size = packed_sweep(lidar)
            seconds.append(time.perf_counter() - start)
    finally:
        sim.close()
    rings, samples = lidar.config.vertical_range_count, lidar.config.range_count
    report("3D lidar sweep, cloud built and serialized, median", f"{statistics.median(seconds) * 1e3:.2f} ms "
           f"({rings} rings x {samples} samples, {size} bytes)")
    with_lidar, without = rtf(True, args.sim_seconds), rtf(False, args.sim_seconds)
    report("rover real-time factor with the 10 Hz 3D lidar subscribed / without the lidar",
           f"{with_lidar:.2f} / {without:.2f}; ratio {with_lidar / without:.2f}")

if __name__ == "__main__":
    main()
