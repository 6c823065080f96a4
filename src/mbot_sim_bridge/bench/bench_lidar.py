"""Wall time of one 360-beam rplidar scan in a small PyBullet world (DIRECT mode).

The world is a 10 m × 10 m walled room with a few boxes and a robot-sized body carrying the sensor, whose
collision group is filtered out as the bridge does. Prints the median, mean and 95th percentile of a full
LaserScanner.scan(), the median of the bare rayTestBatch call inside it, and ten scans' rays cast one call per
scan against one call for all, one figure per line.

    PYTHONPATH=src/mbot_sim_bridge/src .venv/bin/python src/mbot_sim_bridge/bench/bench_lidar.py
"""
import argparse
import os
import time

import numpy as np
import pybullet
from pybullet_utils.bullet_client import BulletClient

from mbot_sim_bridge.core.geometry import compose, pose_from_xyz_rpy, rotation_matrix
from mbot_sim_bridge.core.sensors.lidar import LaserScanner, RaySensorConfig
from mbot_sim_bridge.core.log import c_stdout_to
from results import parse_arguments, report


# The tutorial's rplidar (lidar_gazebo.xacro).
RPLIDAR = RaySensorConfig(sensor_name="rplidar", link="laser_link", samples=360, min_angle=-3.0,
                          max_angle=3.0, range_min=0.10, range_max=6.0, update_rate=5.5,
                          noise_mean=0.0, noise_stddev=0.01)
# The mbot's laser_link sits 0.08 m ahead of and 0.072 m above base_footprint.
LASER_IN_BASE = pose_from_xyz_rpy((0.08, 0.0, 0.072), (0.0, 0.0, 0.0))


def add_box(client, half_extents, xyz, yaw=0.0):
    shape = client.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half_extents)
    pose = pose_from_xyz_rpy(xyz, (0.0, 0.0, yaw))
    return client.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=shape,
                                  basePosition=pose.position, baseOrientation=pose.orientation)


def build_world(client):
    """A walled room with boxes; returns the robot's body id."""
    client.createMultiBody(baseMass=0.0,
                           baseCollisionShapeIndex=client.createCollisionShape(pybullet.GEOM_PLANE))
    for xyz, half_extents in (((5.0, 0, 0.5), [0.05, 5.0, 0.5]), ((-5.0, 0, 0.5), [0.05, 5.0, 0.5]),
                              ((0, 5.0, 0.5), [5.0, 0.05, 0.5]), ((0, -5.0, 0.5), [5.0, 0.05, 0.5])):
        add_box(client, half_extents, xyz)
    for xyz, yaw in (((2.0, 1.0, 0.25), 0.3), ((-1.5, 2.5, 0.25), 1.1), ((1.0, -2.0, 0.25), 0.0),
                     ((-3.0, -1.0, 0.25), 0.7)):
        add_box(client, [0.25, 0.25, 0.25], xyz, yaw)
    base = client.createCollisionShape(pybullet.GEOM_CYLINDER, radius=0.16, height=0.005)
    lidar = client.createCollisionShape(pybullet.GEOM_CYLINDER, radius=0.05, height=0.06)
    robot = client.createMultiBody(
        baseMass=20.0, baseCollisionShapeIndex=base, basePosition=[0, 0, 0.042],
        linkMasses=[0.1], linkCollisionShapeIndices=[lidar], linkVisualShapeIndices=[-1],
        linkPositions=[[0.08, 0, 0.03]], linkOrientations=[[0, 0, 0, 1]],
        linkInertialFramePositions=[[0, 0, 0]], linkInertialFrameOrientations=[[0, 0, 0, 1]],
        linkParentIndices=[0], linkJointTypes=[pybullet.JOINT_FIXED], linkJointAxis=[[0, 0, 1]])
    return robot


def angles(config):
    return config.min_angle + np.arange(config.range_count) * config.angle_increment


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scans", type=int, default=500, help="timed scans (default 500)")
    args = parse_arguments(parser, "ten scans")
    if args.short:
        args.scans = 10  # the ten-lidar figures need ten

    with open(os.devnull, "w") as devnull, c_stdout_to(devnull):  # PyBullet prints "argv[0]="
        client = BulletClient(connection_mode=pybullet.DIRECT)
    build_world(client)
    scanner = LaserScanner(client, RPLIDAR, np.random.default_rng(0))
    # The robot turns on the spot so that each scan sees a different part of the room.
    poses = [compose(pose_from_xyz_rpy((0.0, 0.0, 0.0), (0.0, 0.0, yaw)), LASER_IN_BASE)
             for yaw in np.linspace(0.0, 2.0 * np.pi, args.scans, endpoint=False)]
    for pose in poses[:20]:
        scanner.scan(pose)
    seconds = np.empty(args.scans)
    for i, pose in enumerate(poses):
        start = time.perf_counter()
        scanner.scan(pose)
        seconds[i] = time.perf_counter() - start
    # The same rays cast with the transform, range maths and noise left out: the engine's share of a scan.
    yaws = angles(RPLIDAR)
    directions = np.stack([np.cos(yaws), np.sin(yaws), np.zeros_like(yaws)], axis=1)
    ray_seconds = np.empty(args.scans)
    for i, pose in enumerate(poses):
        rotation = np.asarray(rotation_matrix(pose.orientation))
        starts = directions * RPLIDAR.range_min @ rotation.T + pose.position
        ends = directions * RPLIDAR.range_max @ rotation.T + pose.position
        start = time.perf_counter()
        client.rayTestBatch(starts, ends)
        ray_seconds[i] = time.perf_counter() - start
    separate, together = ten_sensors_cast(client, poses, directions)
    client.disconnect()
    beams = RPLIDAR.range_count
    report("lidar scan median", f"{np.median(seconds) * 1e3:.3f} ms ({beams} beams)")
    report("lidar scan mean", f"{seconds.mean() * 1e3:.3f} ms")
    report("lidar scan p95", f"{np.percentile(seconds, 95) * 1e3:.3f} ms")
    report("rayTestBatch alone, median", f"{np.median(ray_seconds) * 1e3:.3f} ms ({beams} rays)")
    report("ten lidars' rays, one rayTestBatch per lidar, median", f"{separate * 1e3:.3f} ms")
    report("ten lidars' rays in one rayTestBatch, median", f"{together * 1e3:.3f} ms")

def ten_sensors_cast(client, poses, directions):
    """Median seconds to cast ten sensors' rays (ten robots' lidars due at the same step), one call per sensor
    against one call for all: what batching every robot's rays into one call would save."""
    rounds = len(poses) // 10
    starts, ends = [], []
    for pose in poses:
        rotation = np.asarray(rotation_matrix(pose.orientation))
        starts.append(directions * RPLIDAR.range_min @ rotation.T + pose.position)
        ends.append(directions * RPLIDAR.range_max @ rotation.T + pose.position)
    separate, together = np.empty(rounds), np.empty(rounds)
    for i in range(rounds):
        group = slice(10 * i, 10 * i + 10)
        start = time.perf_counter()
        for ray_starts, ray_ends in zip(starts[group], ends[group]):
            [hit[2] for hit in client.rayTestBatch(ray_starts, ray_ends)]
        separate[i] = time.perf_counter() - start
        start = time.perf_counter()
        [hit[2] for hit in client.rayTestBatch(np.concatenate(starts[group]), np.concatenate(ends[group]))]
        together[i] = time.perf_counter() - start
    return np.median(separate), np.median(together)


if __name__ == "__main__":
    main()
