"""Velodyne's ``libgazebo_ros_velodyne_laser.so`` and ``libgazebo_ros_velodyne_gpu_laser.so`` without ROS
(velodyne_simulator 1.0.13, ``GazeboRosVelodyneLaser.cpp``), over the ray sensor of ``lidar.py``.

From one scan of the ``<sensor type="ray">`` (or ``gpu_ray``, cast on the CPU with the same ranges), points
are listed column by column as the driver lists them: for each horizontal ray i, every vertical ray j,
lowest first; ``ring`` is j. A reading r is kept when min_range < r < max_range (the plugin's tags, narrowed
by the sensor's <range>) and its intensity reaches ``min_intensity``; ``gaussianNoise`` is then added to r,
and r is checked again. The point is (r·cos p·cos y, r·cos p·sin y, r·sin p) in the sensor frame with
y = min_angle + i·(max − min)/(N − 1) and p likewise over the vertical rays; ``time`` is 0 (one sweep is
one instant, as upstream). ``organize_cloud`` keeps every ray (NaN where nothing valid was read), so the
cloud is N rows of ``rings`` points.
"""
import math
from typing import NamedTuple, Optional

import numpy as np

from .. import names
from ..errors import ConfigError
from .lidar import RaySensor
from ..params import ERROR_MODEL_LIMIT, Param, non_negative, positive


class VelodyneCloud(NamedTuple):
    """One sweep: float32 (points, 3) xyz, float32 intensities, uint16 rings; ``rows`` > 1 when organised."""
    xyz: np.ndarray
    intensity: np.ndarray
    ring: np.ndarray
    rows: int
    organized: bool


class VelodyneLaser(RaySensor):
    """Core of Velodyne's GazeboRosVelodyneLaser (and its GPU twin)."""
    NAMESPACE_RULE = names.ROOT
    GAZEBO_CLASS = "GazeboRosVelodyneLaser"
    PARAMS = (
        Param("robotNamespace", str, "/", "namespace of the topic; not '/': also the frame's prefix",
              warn_if_missing=False),
        Param("frameName", str, "/world", "frame_id, resolved with the tf prefix", warn_if_missing=False),
        Param("topicName", str, "/points", "sensor_msgs/PointCloud2", warn_if_missing=False),
        non_negative("min_range", float, 0.0, "m; nearer readings are dropped", warn_if_missing=False),
        positive("max_range", float, math.inf, "m; farther readings are dropped", warn_if_missing=False),
        Param("min_intensity", float, -math.inf, "readings of less intensity are dropped (intensity is 0 here)",
              warn_if_missing=False),
        non_negative("gaussianNoise", float, 0.0, "m; stddev added to each kept range", warn_if_missing=False,
                     maximum=ERROR_MODEL_LIMIT),
        Param("organize_cloud", bool, False, "true: rows of rings with NaN where nothing was read",
              warn_if_missing=False),
    )

    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        config = self.config
        self.min_range = max(self.params["min_range"], config.range_min)
        self.max_range = min(self.params["max_range"], config.range_max)
        if self.min_range >= self.max_range:
            raise ConfigError(f"{context.where(element)}: {self.label}: readings are kept between <min_range> "
                              f"{self.params['min_range']:g} (or the ray's min {config.range_min:g}) and <max_range> "
                              f"{self.params['max_range']:g} (or the ray's max {config.range_max:g}): none would be")
        self.noise_rng = context.random_stream(f"{config.sensor_name}/velodyne")

        def angles(count, low, high, rays):
            # One ray (upstream tests the ray count, not the range count): the minimum angle.
            return np.full(count, low) if rays <= 1 or count <= 1 else low + np.arange(count) * (high - low) / (
                count - 1)
        horizontal = config.range_count
        vertical = config.vertical_range_count
        yaw = angles(horizontal, config.min_angle, config.max_angle, horizontal)[:, np.newaxis]
        pitch = angles(vertical, config.vertical_min_angle, config.vertical_max_angle,
                       config.vertical_samples)[np.newaxis, :]
        # Unit directions in the driver's order: column i (horizontal), then ring j.
        self.directions = np.stack(np.broadcast_arrays(np.cos(pitch) * np.cos(yaw), np.cos(pitch) * np.sin(yaw),
                                                       np.sin(pitch)), axis=-1).reshape(-1, 3)
        self.rings = np.tile(np.arange(vertical, dtype=np.uint16), horizontal)
        self.shape = (vertical, horizontal)
        self.latest: Optional[VelodyneCloud] = None

    def cloud(self) -> VelodyneCloud:
        scan = self.scan()
        vertical, horizontal = self.shape
        # The scan is row-major by vertical layer; the driver's order is column-major.
        ranges = scan.ranges.astype(float).reshape(vertical, horizontal).T.reshape(-1)
        intensity = scan.intensities.reshape(vertical, horizontal).T.reshape(-1)
        kept = (self.min_range < ranges) & (ranges < self.max_range) & (intensity >= self.params["min_intensity"])
        organized = self.params["organize_cloud"]
        noise = self.params["gaussianNoise"]
        if noise:
            # One draw per ray, kept or not, so the stream does not depend on what was hit.
            ranges = ranges + self.noise_rng.normal(0.0, noise, ranges.size)
        # Organised, upstream checks the noisy range only: a ray dropped by the first check can come back.
        valid = (kept | organized) & (self.min_range < ranges) & (ranges < self.max_range)
        # Rays with no reading (an infinite range) are left out or made NaN below; multiplied out, inf times a
        # direction's zero component gave NaN warnings first (a sweep ending at 0 rad has such directions).
        xyz = (self.directions * np.where(valid, ranges, 0.0)[:, np.newaxis]).astype(np.float32)
        if organized:
            xyz[~valid] = np.nan
            intensity = np.where(valid, intensity, np.nan).astype(np.float32)
            return VelodyneCloud(xyz, intensity, self.rings, horizontal, True)
        return VelodyneCloud(xyz[valid], intensity[valid].astype(np.float32), self.rings[valid], 1, False)

    def update(self, now: float):
        self.latest = self.cloud()
