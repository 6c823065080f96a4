"""``libgazebo_ros_block_laser.so`` without ROS (gazebo_plugins noetic-devel ``gazebo_ros_block_laser.cpp``), over
the ray sensor of ``lidar.py``.

At the sensor's update_rate, one point per output of the horizontal and vertical scan (samples·resolution by
vertical samples·resolution, row by row, lowest row first), in the sensor frame, as upstream computes them:
- the range is the bilinear interpolation of the four raw rays around the output (the laser shape's: range_min
  plus the hit distance, range_max when nothing is hit), −inf below range_min and +inf above range_max;
- the point's angles are the mid-angles of the rays it was interpolated from, 0.5·(a + b)·step + min (so with
  resolution 1 each point but the last of a row sits half a ray further on than the ray it was read with,
  as in Gazebo); a scan of one ray uses the minimum angle (upstream divides 0 by 0 there);
- x, y, z = r·cos p·cos y, r·cos p·sin y, r·sin p; each gets N(0, gaussianNoise) unless r is range_max;
- the intensity is the mean of the four rays' retro values (0: ``<laser_retro>`` is not simulated) plus
  N(0, gaussianNoise).
``updateRate`` and ``hokuyoMinIntensity`` have no effect, as upstream.
"""
import math
from typing import NamedTuple, Optional

import numpy as np

from .. import names
from .lidar import RaySensor
from ..params import ERROR_MODEL_LIMIT, Param, non_negative

# Upstream's EPSILON_DIFF: a point this close to range_max counts as a miss and gets no position noise.
_AT_RANGE_MAX = 1e-6


class BlockCloud(NamedTuple):
    """One scan: float32 (points, 3) xyz and float32 intensities, row by row."""
    xyz: np.ndarray
    intensity: np.ndarray


def _interpolation(outputs: int, rays: int):
    """For each output, the two rays it lies between (a, b) and its fraction from a, as upstream's loops."""
    position = np.zeros(outputs) if outputs == 1 else np.arange(outputs) * (rays - 1) / (outputs - 1)
    low = np.floor(position).astype(int)
    return low, np.minimum(low + 1, rays - 1), position - low


def _mid_angles(low, high, rays: int, minimum: float, maximum: float) -> np.ndarray:
    if rays == 1:
        return np.full(len(low), minimum)
    return 0.5 * (low + high) * (maximum - minimum) / (rays - 1) + minimum


class BlockLaser(RaySensor):
    """Core of libgazebo_ros_block_laser.so (GazeboRosBlockLaser)."""
    NAMESPACE_RULE = names.ROOT
    GAZEBO_CLASS = "GazeboRosBlockLaser"
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the topic", warn_if_missing=False),
        Param("frameName", str, "/world", "frame_id, resolved with the tf prefix"),
        Param("topicName", str, "/world", "sensor_msgs/PointCloud"),
        non_negative("gaussianNoise", float, 0.0, "m; stddev added to x, y, z and the intensity",
                     maximum=ERROR_MODEL_LIMIT),
    )
    # Read by upstream and never used: the sensor's update_rate governs.
    IGNORED_TAGS = ("alwaysOn", "hokuyoMinIntensity", "updateRate")

    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        config = self.config
        h_low, h_high, h_fraction = _interpolation(config.range_count, config.samples)
        v_low, v_high, v_fraction = _interpolation(config.vertical_range_count, config.vertical_samples)
        # Rows of outputs (vertical) by columns (horizontal), flattened row by row as upstream's loops.
        rows, columns = np.meshgrid(np.arange(len(v_low)), np.arange(len(h_low)), indexing="ij")
        rows, columns = rows.ravel(), columns.ravel()
        samples = config.samples
        self._corners = np.stack([h_low[columns] + v_low[rows] * samples, h_high[columns] + v_low[rows] * samples,
                                  h_low[columns] + v_high[rows] * samples, h_high[columns] + v_high[rows] * samples])
        self._h_fraction, self._v_fraction = h_fraction[columns], v_fraction[rows]
        yaw = _mid_angles(h_low, h_high, samples, config.min_angle, config.max_angle)[columns]
        pitch = _mid_angles(v_low, v_high, config.vertical_samples, config.vertical_min_angle,
                            config.vertical_max_angle)[rows]
        self._directions = np.stack([np.cos(pitch) * np.cos(yaw), np.cos(pitch) * np.sin(yaw), np.sin(pitch)],
                                    axis=-1)
        self.noise_rng = context.random_stream(f"{config.sensor_name}/block_laser")
        self.latest: Optional[BlockCloud] = None

    def cloud(self) -> BlockCloud:
        config = self.config
        r1, r2, r3, r4 = self.raw_ranges()[self._corners]
        hb, vb = self._h_fraction, self._v_fraction
        ranges = (1 - vb) * ((1 - hb) * r1 + hb * r2) + vb * ((1 - hb) * r3 + hb * r4)
        ranges = np.where(ranges < config.range_min, -math.inf, np.where(ranges > config.range_max, math.inf, ranges))
        with np.errstate(invalid="ignore"):  # ±inf times a zero direction component is NaN, as in C++
            xyz = self._directions * ranges[:, np.newaxis]
        intensity = np.zeros(len(ranges))
        noise = self.params["gaussianNoise"]
        if noise:
            # Every draw made, used or not, so the stream does not depend on what was hit.
            position_noise = self.noise_rng.normal(0.0, noise, xyz.shape)
            intensity += self.noise_rng.normal(0.0, noise, len(ranges))
            hit = np.abs(config.range_max - ranges) > _AT_RANGE_MAX
            xyz[hit] += position_noise[hit]
        with np.errstate(over="ignore"):  # Point32 is float32: beyond its range a coordinate is ±inf, as in C++
            return BlockCloud(xyz.astype(np.float32), intensity.astype(np.float32))

    def update(self, now: float):
        self.latest = self.cloud()
