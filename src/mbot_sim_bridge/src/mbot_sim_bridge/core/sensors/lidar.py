"""Gazebo's ray sensor (``type="ray"`` and ``"gpu_ray"``) on PyBullet ray casts.

``parse_ray_sensor`` reads a ``<sensor>`` from a URDF ``<gazebo reference="LINK">`` block through the
``RAY_SENSOR_PARAMS`` table; ``RaySensor`` is the core of ``libgazebo_ros_laser.so`` (and of
``libgazebo_ros_gpu_laser.so``, served by the same CPU ray casts). ``LaserScanner`` casts the rays and turns
the hits into ranges the way ``gazebo::sensors::RaySensor`` does:

- Ray (j, i) points at yaw = min + i·(max − min)/(samples − 1) and at
  pitch = vmin + j·(vmax − vmin)/(vsamples − 1) in the sensor frame (yaw counter-clockwise about +z,
  positive pitch up). Each ray runs from range_min to range_max, so anything closer is not seen.
- raw = range_min + hit distance; a ray that hits nothing reads range_max.
- If resolution ≠ 1, the samples·resolution outputs are bilinear interpolations of neighbouring raw rays.
- REP 117 masking: raw ≥ range_max gives +inf and raw ≤ range_min gives −inf. Gaussian noise goes on the
  remaining readings, which are then clamped to [range_min, range_max].
- Vertical layers are supported: ranges are row-major, one row of range_count values per vertical layer,
  lowest layer first, and the ROS plugin publishes them all, as gazebo_ros_laser does.
- Intensities are always 0, because ``<laser_retro>`` is not simulated (Gazebo's default retro is 0 as well).

Two PyBullet behaviours at the ray start, measured with pybullet 3.2.7:

- A ray that starts deeper than about 1 mm inside a convex shape does not see that shape, where Gazebo's ODE
  ray colliders report the shape's far face. This only matters when an obstacle reaches inside range_min.
- A ray that starts within about 1 mm of a surface reports hit fraction 0. That is raw = range_min, so the
  reading is −inf, as ODE gives for a ray that starts exactly on the surface.
"""
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import NamedTuple, Optional

import numpy as np
import pybullet

from .. import names
from ..clock import UpdateTimer
from ..errors import ConfigError
from ..geometry import IDENTITY, Pose, compose, rotation_matrix
from ..log import get_logger, info_once
from ..params import Param, PluginParams, non_negative, positive, rate
from ..plugin import Plugin
from .sensor_elements import gaussian_noise, sensor_label, sensor_pose
from ..xml_values import XmlDocument

_log = get_logger(__name__)

# A ray sensor's angles (rad) at most: far beyond any sweep, and small enough that the ray angles computed from
# them stay finite (1e308 overflowed).
MAX_ANGLE = 1e3
# The <sensor> values of a ray sensor (SDF names and defaults; Gazebo does not warn about missing SDF tags).
RAY_SENSOR_PARAMS = (
    rate("update_rate", 0.0, "Hz of sim time; 0 = every physics step", warn_if_missing=False),
    Param("ray/scan/horizontal/samples", int, None, "rays per sweep", required=True, minimum=1),
    positive("ray/scan/horizontal/resolution", float, 1.0, "ranges per ray (interpolated)", warn_if_missing=False),
    Param("ray/scan/horizontal/min_angle", float, None, "first ray (rad)", required=True, minimum=-MAX_ANGLE,
          maximum=MAX_ANGLE),
    Param("ray/scan/horizontal/max_angle", float, None, "last ray (rad)", required=True, minimum=-MAX_ANGLE,
          maximum=MAX_ANGLE),
    Param("ray/scan/vertical/samples", int, 1, "vertical layers", minimum=1, warn_if_missing=False),
    positive("ray/scan/vertical/resolution", float, 1.0, "ranges per layer", warn_if_missing=False),
    Param("ray/scan/vertical/min_angle", float, 0.0, "lowest layer (rad)", warn_if_missing=False,
          minimum=-MAX_ANGLE, maximum=MAX_ANGLE),
    Param("ray/scan/vertical/max_angle", float, 0.0, "highest layer (rad)", warn_if_missing=False,
          minimum=-MAX_ANGLE, maximum=MAX_ANGLE),
    non_negative("ray/range/min", float, None, "rays start here (m)", required=True),
    positive("ray/range/max", float, None, "longest reading (m)", required=True),
    non_negative("ray/range/resolution", float, 0.0, "checked, and without effect, as in Gazebo (no quantizing)",
                 warn_if_missing=False),
    Param("ray/noise/type", str, "gaussian", "gaussian or none", warn_if_missing=False),
    Param("ray/noise/mean", float, 0.0, "m", warn_if_missing=False),
    non_negative("ray/noise/stddev", float, 0.0, "m", warn_if_missing=False),
)
# libgazebo_ros_laser.so's tags. gazebo_ros_laser.cpp defaults both the topic and the frame to "/world"; the
# topic default is a known copy-paste slip, kept because Gazebo behaves that way.
LASER_PARAMS = (
    Param("topicName", str, "/world", "sensor_msgs/LaserScan topic, relative to the namespace"),
    Param("frameName", str, "/world", "frame_id of the scans (a leading '/' is dropped, as tf::resolve does)"),
    Param("robotNamespace", str, "", "absent: the simulator's namespace; empty: the model name",
          warn_if_missing=False),
)

# Ranges in one scan at most: a 64-layer 3D lidar has about 130,000. Far more (a typo in <samples> or
# <resolution>) would take the memory and time of the whole simulator for each scan.
MAX_RANGES_PER_SCAN = 1 << 18

# A batch of exactly MAX_RAY_INTERSECTION_BATCH_SIZE rays returns one result short in pybullet 3.2.7.
_MAX_RAYS_PER_BATCH = pybullet.MAX_RAY_INTERSECTION_BATCH_SIZE - 1


@dataclass(frozen=True)
class RaySensorConfig:
    """One ray sensor, with the SDF and plugin values the bridge needs; lengths in m, angles in rad."""

    sensor_name: str
    link: str
    samples: int
    min_angle: float
    max_angle: float
    range_min: float
    range_max: float
    pose: Pose = IDENTITY  # of the sensor in the link frame
    update_rate: float = 0.0  # Hz; 0 = every physics step
    resolution: float = 1.0
    vertical_samples: int = 1
    vertical_resolution: float = 1.0
    vertical_min_angle: float = 0.0
    vertical_max_angle: float = 0.0
    noise_mean: Optional[float] = None  # None: no gaussian noise
    noise_stddev: Optional[float] = None

    @property
    def range_count(self) -> int:
        """Ranges per horizontal row; Gazebo truncates samples·resolution to an int."""
        return int(self.samples * self.resolution)

    @property
    def vertical_range_count(self) -> int:
        return int(self.vertical_samples * self.vertical_resolution)

    @property
    def angle_increment(self) -> float:
        """LaserScan.angle_increment: Gazebo's (max − min)/(N − 1), N = range_count; 0 for one range."""
        if self.range_count == 1:
            return 0.0
        return (self.max_angle - self.min_angle) / (self.range_count - 1)


class Scan(NamedTuple):
    """One scan: float32 arrays of vertical_range_count · range_count values, row-major."""

    ranges: np.ndarray
    intensities: np.ndarray


# --- parsing ---------------------------------------------------------------------------------------------

def parse_ray_sensor(sensor_element: ET.Element, link_name: str, document: XmlDocument) -> RaySensorConfig:
    """Read ``<sensor type="ray"|"gpu_ray">`` from ``<gazebo reference="link_name">`` of ``document``.

    Bad values raise ``ConfigError`` naming where, the sensor, the tag, the value and the valid range;
    unsupported noise types are logged once and ignored.
    """
    name, where, label = sensor_label(sensor_element, "lidar", link_name, document)
    if sensor_element.get("type") not in ("ray", "gpu_ray"):
        raise ConfigError(f"{where}: {label}: type '{sensor_element.get('type')}' is not a ray sensor "
                          f"(expected 'ray' or 'gpu_ray')")
    values = PluginParams(sensor_element, label, where=where, check_unknown=False).read(RAY_SENSOR_PARAMS)
    pose = sensor_pose(sensor_element, document, where, label)
    noisy = gaussian_noise(sensor_element.find("ray/noise"), values["ray/noise/type"], f"{where}: {label}", "the scan")
    noise_mean, noise_stddev = (values["ray/noise/mean"], values["ray/noise/stddev"]) if noisy else (None, None)
    config = RaySensorConfig(
        sensor_name=name,
        link=link_name,
        pose=pose,
        update_rate=values["update_rate"],
        samples=values["ray/scan/horizontal/samples"],
        resolution=values["ray/scan/horizontal/resolution"],
        min_angle=values["ray/scan/horizontal/min_angle"],
        max_angle=values["ray/scan/horizontal/max_angle"],
        vertical_samples=values["ray/scan/vertical/samples"],
        vertical_resolution=values["ray/scan/vertical/resolution"],
        vertical_min_angle=values["ray/scan/vertical/min_angle"],
        vertical_max_angle=values["ray/scan/vertical/max_angle"],
        range_min=values["ray/range/min"],
        range_max=values["ray/range/max"],
        noise_mean=noise_mean,
        noise_stddev=noise_stddev,
    )
    _check_consistency(config, f"{where}: {label}")
    return config


def _check_consistency(config: RaySensorConfig, where: str) -> None:
    if config.min_angle > config.max_angle:
        raise ConfigError(f"{where}: <min_angle> ({config.min_angle}) must not exceed "
                          f"<max_angle> ({config.max_angle})")
    if config.vertical_min_angle > config.vertical_max_angle:
        raise ConfigError(f"{where}: <vertical><min_angle> ({config.vertical_min_angle}) must not exceed "
                          f"<vertical><max_angle> ({config.vertical_max_angle})")
    if config.range_max <= config.range_min:
        raise ConfigError(f"{where}: <range><max> ({config.range_max}) must exceed "
                          f"<range><min> ({config.range_min})")
    # Compared as floats first: the counts of a typo can be too large to turn into arrays, or into ints at all
    # (a resolution of 1e308 overflowed), each row's as well as their product.
    rows = (config.samples * config.resolution, config.vertical_samples * config.vertical_resolution)
    ranges = rows[0] * rows[1]
    largest = max(rows + (ranges,))
    if largest > MAX_RANGES_PER_SCAN:
        raise ConfigError(f"{where}: <samples> × <resolution> × <vertical><samples> × <vertical><resolution> = "
                          f"{largest:g} ranges per scan; at most {MAX_RANGES_PER_SCAN} are simulated")
    if config.range_count < 1:
        raise ConfigError(f"{where}: <samples> × <resolution> = {rows[0]} leaves no ranges")
    if config.vertical_range_count < 1:
        raise ConfigError(f"{where}: <vertical><samples> × <vertical><resolution> = {rows[1]} leaves no ranges")


class RaySensor(Plugin):
    """Core of libgazebo_ros_laser.so: the sensor's rays, cast from its link."""
    NAMESPACE_RULE = names.SENSOR

    GAZEBO_CLASS = "GazeboRosLaser"
    PARAMS = LASER_PARAMS
    SENSOR_TYPES = ("ray", "gpu_ray")
    SENSOR_PARAMS = RAY_SENSOR_PARAMS

    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        robot = context.robot
        self.config = parse_ray_sensor(sensor, context.link, robot.model.document)
        self.params = self.read_params()
        if sensor.get("type") == "gpu_ray":
            info_once(_log, f"{self.label}: sensor '{self.config.sensor_name}' is a gpu_ray; the bridge casts its "
                            f"rays on the CPU, with the same ranges")
        self.scanner = LaserScanner(robot.client, self.config, context.random_stream(self.config.sensor_name))
        self.timer = UpdateTimer(self.config.update_rate, start=context.simulation.sim_time)
        self.latest: Optional[Scan] = None

    def sensor_world_pose(self) -> Pose:
        return compose(self.context.robot.link_world_pose(self.config.link), self.config.pose)

    def scan(self) -> "Scan":
        return self.scanner.scan(self.sensor_world_pose())

    def raw_ranges(self) -> np.ndarray:
        """Every ray's raw range (the laser shape's, before the sensor's masking and noise)."""
        return self.scanner.cast(self.sensor_world_pose())

    def update(self, now: float):
        self.latest = self.scan()


# --- scanning --------------------------------------------------------------------------------------------

def _ray_directions(config: RaySensorConfig) -> np.ndarray:
    """Unit ray directions in the sensor frame, (vertical_samples · samples, 3), row-major."""
    def angles(count, low, high):
        # A single ray points straight ahead whatever the limits say (MultiRayShape::Init).
        if count == 1:
            return np.zeros(1)
        return np.arange(count) * (high - low) / (count - 1) + low

    yaw = angles(config.samples, config.min_angle, config.max_angle)[np.newaxis, :]
    pitch = angles(config.vertical_samples, config.vertical_min_angle,
                   config.vertical_max_angle)[:, np.newaxis]
    directions = np.stack(np.broadcast_arrays(np.cos(pitch) * np.cos(yaw), np.cos(pitch) * np.sin(yaw),
                                              np.sin(pitch)), axis=-1)
    return directions.reshape(-1, 3)


def _axis_interpolation(rays: int, ranges: int):
    """Per output: the lower and upper ray index and the upper one's weight, as RaySensor::UpdateImpl."""
    position = np.zeros(1) if ranges == 1 else np.arange(ranges) * (rays - 1) / (ranges - 1)
    lower = np.floor(position).astype(np.intp)
    return lower, np.minimum(lower + 1, rays - 1), position - lower


class LaserScanner:
    """Casts one sensor's rays in a PyBullet world and forms Gazebo-style ranges.

    ``client`` is a ``pybullet_utils.bullet_client.BulletClient``; ``rng`` draws the noise, so scanners seeded
    alike give identical scans of identical worlds.
    """

    def __init__(self, client, config: RaySensorConfig, rng: np.random.Generator):
        self._client = client
        self._config = config
        self._rng = rng
        directions = _ray_directions(config)
        self._ray_count = len(directions)
        # Ray starts, then ray ends, in the sensor frame, so that one product transforms them all.
        self._ray_points = np.concatenate([directions * config.range_min, directions * config.range_max])
        self._output_count = config.range_count * config.vertical_range_count
        self._corners = None
        if (config.range_count != config.samples
                or config.vertical_range_count != config.vertical_samples):
            h_low, h_high, h_weight = _axis_interpolation(config.samples, config.range_count)
            v_low, v_high, v_weight = _axis_interpolation(config.vertical_samples,
                                                          config.vertical_range_count)
            rows_low = (v_low * config.samples)[:, np.newaxis]
            rows_high = (v_high * config.samples)[:, np.newaxis]
            # Ray indices of the four corners around each output, as (4, outputs).
            self._corners = np.stack([rows_low + h_low, rows_low + h_high,
                                      rows_high + h_low, rows_high + h_high]).reshape(4, -1)
            self._h_weight = np.tile(h_weight, len(v_weight))
            self._v_weight = np.repeat(v_weight, len(h_weight))

    @property
    def config(self) -> RaySensorConfig:
        return self._config

    def cast(self, sensor_pose_world: Pose) -> np.ndarray:
        """Each ray's raw range, as Gazebo's laser shape gives it (``GetRange``): range_min plus the hit
        distance, range_max for a miss; no masking, interpolation or noise. Rays as ``_ray_directions``.
        As in Gazebo, rays see every collision, the robot's own links included."""
        config = self._config
        rotation = np.asarray(rotation_matrix(sensor_pose_world.orientation))
        origin = np.asarray(sensor_pose_world.position)
        points = self._ray_points @ rotation.T + origin
        count = self._ray_count
        fractions = np.empty(count)
        for first in range(0, count, _MAX_RAYS_PER_BATCH):
            last = min(first + _MAX_RAYS_PER_BATCH, count)
            hits = self._client.rayTestBatch(points[first:last], points[count + first:count + last])
            fractions[first:last] = [hit[2] for hit in hits]
        # Rays are cast from range_min; a miss (fraction 1) is set to range_max exactly, because
        # min + 1·(max − min) can round to just below max.
        return np.where(fractions >= 1.0, config.range_max,
                        config.range_min + fractions * (config.range_max - config.range_min))

    def scan(self, sensor_pose_world: Pose) -> Scan:
        """Scan from ``sensor_pose_world`` (link world pose ∘ ``config.pose``)."""
        config = self._config
        raw = self.cast(sensor_pose_world)
        if self._corners is not None:
            r1, r2, r3, r4 = raw[self._corners]
            hb, vb = self._h_weight, self._v_weight
            raw = (1 - vb) * ((1 - hb) * r1 + hb * r2) + vb * ((1 - hb) * r3 + hb * r4)

        ranges = np.where(raw >= config.range_max, np.inf, np.where(raw <= config.range_min, -np.inf, raw))
        if config.noise_stddev is not None:
            # One draw per output, used or not, so the noise stream does not depend on what was hit.
            noise = self._rng.normal(config.noise_mean, config.noise_stddev, self._output_count)
            noisy = np.minimum(np.maximum(raw + noise, config.range_min), config.range_max)
            ranges = np.where(np.isfinite(ranges), noisy, ranges)
        return Scan(ranges.astype(np.float32), np.zeros(self._output_count, dtype=np.float32))
