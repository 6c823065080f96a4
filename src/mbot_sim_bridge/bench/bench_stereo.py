#!/usr/bin/env python3
"""Stereo pair cost figures, printed one per line (part of ``./mbot bench``).

The workspace's stereo head (mobile_test_robots, libgazebo_ros_multicamera.so, two 320x240 cameras at 10 Hz) in
the play ground: (a) the wall time of one pair frame, both cameras rendered and their images built and
serialized as subscribers get them; (b) the real-time factor with both images subscribed, against the same
head with nothing subscribed (no rendering, as in Gazebo).

    PYTHONPATH=src/mbot_sim_bridge/src .venv/bin/python src/mbot_sim_bridge/bench/bench_stereo.py
"""
import argparse
import os
import statistics
import time

from bench_cameras import PLAY_GROUND, WORKSPACE, serialized, timed_rtf
from results import parse_arguments, report
from sensor_msgs.msg import Image

from mbot_sim_bridge.core.cameras.multicamera import MultiCamera
from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.simulation import Simulation
from mbot_sim_bridge.robot_description import expand_xacro


def spawn():
    path = os.path.join(WORKSPACE, "src", "mobile_test_robots", "urdf", "stereo_head.urdf.xacro")
    sim = Simulation(parse_world(PLAY_GROUND), CORE_PLUGINS)
    urdf = expand_xacro(path)
    spawned = sim.spawn_robot(parse_robot(urdf, "model 'stereo_head'"), "stereo_head")
    return sim, next(plugin for plugin in spawned.plugins if isinstance(plugin, MultiCamera))


def pair_frame(stereo: MultiCamera, now: float) -> int:
    """Both cameras rendered and serialized as the ROS plugin publishes them; returns the bytes serialized."""
    size = 0
    for side, camera in stereo.cameras.items():
        image = stereo.capture(side, now).image
        size += serialized(Image(height=image.shape[0], width=image.shape[1], encoding=camera.encoding,
                                 step=image.strides[0], data=image.tobytes()))
    return size


def rtf(subscribed: bool, sim_seconds: float) -> float:
    sim, stereo = spawn()
    try:
        stereo.update = (lambda now: pair_frame(stereo, now)) if subscribed else (lambda now: None)
        return timed_rtf(sim, sim_seconds)
    finally:
        sim.close()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=30, help="pair frames timed")
    parser.add_argument("--sim-seconds", type=float, default=5.0, help="sim time of each real-time-factor run")
    args = parse_arguments(parser, "one frame, tiny durations")
    if args.short:
        args.frames, args.sim_seconds = 1, 0.1
    sim, stereo = spawn()
    try:
        sim.step(200)
        seconds, size = [], 0
        for _ in range(args.frames):
            start = time.perf_counter()
            size = pair_frame(stereo, sim.sim_time)
            seconds.append(time.perf_counter() - start)
    finally:
        sim.close()
    config = stereo.cameras["left"].config
    report("stereo pair frame, rendered and serialized, median", f"{statistics.median(seconds) * 1e3:.2f} ms "
           f"({config.width}x{config.height} x 2, {size} bytes)")
    subscribed, idle = rtf(True, args.sim_seconds), rtf(False, args.sim_seconds)
    report("stereo head real-time factor with both images subscribed / with none",
           f"{subscribed:.2f} / {idle:.2f} ({stereo.frame_rate:g} Hz); ratio {subscribed / idle:.2f}")

if __name__ == "__main__":
    main()
