"""Gazebo's ray sensor (``type="ray"`` and ``"gpu_ray"``) on PyBullet ray casts.

``parse_ray_sensor`` reads a ``<sensor>`` from a URDF ``<gazebo reference="LINK">`` block together with its
``libgazebo_ros_laser.so`` or ``libgazebo_ros_gpu_laser.so`` plugin. ``LaserScanner`` casts the rays and
turns the hits into ranges the way ``gazebo::sensors::RaySensor`` does:

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
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Callable, NamedTuple, Optional

import numpy as np
import pybullet

from mbot_sim_bridge.core.errors import ConfigError
from mbot_sim_bridge.core.geometry import IDENTITY, Pose, pose_from_xyz_rpy, rotation_matrix
from mbot_sim_bridge.core.log import get_logger, warn_once

_log = get_logger(__name__)

# The sensor type each ROS 1 laser plugin needs; any other pairing is a load error in Gazebo.
LASER_PLUGINS = {
    "libgazebo_ros_laser.so": "ray",
    "libgazebo_ros_gpu_laser.so": "gpu_ray",
}
PLUGIN_TAGS = ("frameName", "robotNamespace", "topicName")
# gazebo_ros_laser.cpp defaults both the topic and the frame to "/world"; the topic default is a known
# copy-paste slip, kept because Gazebo behaves that way.
DEFAULT_TOPIC_NAME = "/world"
DEFAULT_FRAME_NAME = "/world"

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
    range_resolution: float = 0.0  # reported in the message only; Gazebo does not quantize with it
    noise_mean: Optional[float] = None  # None: no gaussian noise
    noise_stddev: Optional[float] = None
    plugin_filename: Optional[str] = None  # None: no ROS plugin, so nothing to publish
    topic_name: str = DEFAULT_TOPIC_NAME
    frame_name: str = "world"  # DEFAULT_FRAME_NAME as tf::resolve leaves it
    robot_namespace: Optional[str] = None  # None: tag absent
    is_gpu: bool = False

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

_REQUIRED = object()


def _finite(text: str) -> Optional[float]:
    value = float(text)
    return value if math.isfinite(value) else None


def _non_negative(text: str) -> Optional[float]:
    value = _finite(text)
    return value if value is not None and value >= 0.0 else None


def _positive(text: str) -> Optional[float]:
    value = _finite(text)
    return value if value is not None and value > 0.0 else None


def _positive_int(text: str) -> Optional[int]:
    value = int(text)
    return value if value > 0 else None


# parser -> what the error message says the value must be
_KINDS = {
    _finite: "a finite number",
    _non_negative: "a non-negative number",
    _positive: "a positive number",
    _positive_int: "a positive integer",
}


def _read(element: ET.Element, path: str, tag: str, where: str, parse: Callable, default=_REQUIRED):
    """The value at ``path`` below ``element``; ``tag`` is how error messages name it."""
    node = element.find(path)
    if node is None:
        if default is _REQUIRED:
            raise ConfigError(f"{where}: missing {tag}")
        return default
    text = (node.text or "").strip()
    try:
        value = parse(text)
    except ValueError:
        value = None
    if value is None:
        raise ConfigError(f"{where}: {tag} must be {_KINDS[parse]}, got '{text}'")
    return value


def _block(element: ET.Element, path: str, where: str) -> ET.Element:
    node = element.find(path)
    if node is None:
        raise ConfigError(f"{where}: missing <{path.replace('/', '><')}>")
    return node


def _read_pose(sensor: ET.Element, where: str) -> Pose:
    node = sensor.find("pose")
    if node is None:
        return IDENTITY
    text = (node.text or "").strip()
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        values = []
    if len(values) != 6 or not all(math.isfinite(v) for v in values):
        raise ConfigError(f"{where}: <pose> must be six numbers 'x y z roll pitch yaw', got '{text}'")
    return pose_from_xyz_rpy(values[:3], values[3:])


def _read_noise(ray: ET.Element, where: str):
    """(mean, stddev) of the gaussian ray noise, or (None, None) when there is none to simulate."""
    noise = ray.find("noise")
    if noise is None:
        return None, None
    # "gaussian" is the SDF default of <ray><noise><type>.
    noise_type = (noise.findtext("type") or "gaussian").strip()
    if noise_type == "none":
        return None, None
    if noise_type != "gaussian":
        warn_once(_log, f"{where}: <noise><type> '{noise_type}' is not supported (only gaussian is); "
                        f"the scan is noise-free")
        return None, None
    return (_read(noise, "mean", "<noise><mean>", where, _finite, 0.0),
            _read(noise, "stddev", "<noise><stddev>", where, _non_negative, 0.0))


def _plugin_text(plugin: ET.Element, tag: str, default: str, label: str) -> str:
    node = plugin.find(tag)
    if node is None:
        warn_once(_log, f"{label}: missing <{tag}>, default is {default}")
        return default
    text = (node.text or "").strip()
    if not text:
        raise ConfigError(f"{label}: <{tag}> must not be empty")
    return text


def _read_plugin(sensor: ET.Element, sensor_type: str, where: str) -> dict:
    """Config fields from the sensor's ROS laser plugin; Gazebo's defaults when it has none."""
    plugins = sensor.findall("plugin")
    lasers = [p for p in plugins if p.get("filename") in LASER_PLUGINS]
    for plugin in plugins:
        if plugin.get("filename") not in LASER_PLUGINS:
            warn_once(_log, f"{where}: plugin '{plugin.get('filename')}' is not emulated; it is ignored "
                            f"(supported: {', '.join(sorted(LASER_PLUGINS))})")
    if not lasers:
        return {}
    if len(lasers) > 1:
        warn_once(_log, f"{where}: {len(lasers)} laser plugins; only the first, "
                        f"{lasers[0].get('filename')}, is emulated")
    plugin = lasers[0]
    filename = plugin.get("filename")
    label = f"{where}: {filename}"
    if LASER_PLUGINS[filename] != sensor_type:
        raise ConfigError(f"{label} needs <sensor type=\"{LASER_PLUGINS[filename]}\">, "
                          f"but the sensor's type is \"{sensor_type}\"")
    for child in plugin:
        if isinstance(child.tag, str) and child.tag not in PLUGIN_TAGS:  # not an XML comment
            warn_once(_log, f"{label}: unknown tag <{child.tag}> ignored; "
                            f"known tags: {', '.join(PLUGIN_TAGS)}")
    namespace = plugin.find("robotNamespace")
    frame_name = _plugin_text(plugin, "frameName", DEFAULT_FRAME_NAME, label)
    return {
        "plugin_filename": filename,
        "topic_name": _plugin_text(plugin, "topicName", DEFAULT_TOPIC_NAME, label),
        # tf::resolve with the (normally empty) tf_prefix strips one leading "/".
        "frame_name": frame_name[1:] if frame_name.startswith("/") else frame_name,
        "robot_namespace": None if namespace is None else (namespace.text or "").strip(),
    }


def parse_ray_sensor(sensor_element: ET.Element, link_name: str, source_label: str) -> RaySensorConfig:
    """Read ``<sensor type="ray"|"gpu_ray">`` from ``<gazebo reference="link_name">``.

    ``source_label`` names the document in error messages (e.g. "robot_description"). Bad values raise
    ``ConfigError`` naming the tag, the value and the sensor; unsupported plugins, plugin tags and noise
    types are logged once and ignored.
    """
    name = sensor_element.get("name")
    if not name:
        raise ConfigError(f"{source_label}: a <sensor> on link '{link_name}' has no name")
    where = f"{source_label}: lidar '{name}' on link '{link_name}'"
    sensor_type = sensor_element.get("type")
    if sensor_type not in LASER_PLUGINS.values():
        raise ConfigError(f"{where}: type '{sensor_type}' is not a ray sensor (expected 'ray' or 'gpu_ray')")

    ray = _block(sensor_element, "ray", where)
    horizontal = _block(ray, "scan/horizontal", where)
    vertical = ray.find("scan/vertical")
    range_ = _block(ray, "range", where)
    noise_mean, noise_stddev = _read_noise(ray, where)
    config = RaySensorConfig(
        sensor_name=name,
        link=link_name,
        pose=_read_pose(sensor_element, where),
        update_rate=_read(sensor_element, "update_rate", "<update_rate>", where, _non_negative, 0.0),
        samples=_read(horizontal, "samples", "<samples>", where, _positive_int),
        resolution=_read(horizontal, "resolution", "<resolution>", where, _positive, 1.0),
        min_angle=_read(horizontal, "min_angle", "<min_angle>", where, _finite),
        max_angle=_read(horizontal, "max_angle", "<max_angle>", where, _finite),
        range_min=_read(range_, "min", "<range><min>", where, _non_negative),
        range_max=_read(range_, "max", "<range><max>", where, _positive),
        range_resolution=_read(range_, "resolution", "<range><resolution>", where, _non_negative, 0.0),
        noise_mean=noise_mean,
        noise_stddev=noise_stddev,
        is_gpu=sensor_type == "gpu_ray",
        **_read_vertical(vertical, where),
        **_read_plugin(sensor_element, sensor_type, where),
    )
    _check_consistency(config, where)
    return config


def _read_vertical(vertical: Optional[ET.Element], where: str) -> dict:
    if vertical is None:
        return {}
    return {
        "vertical_samples": _read(vertical, "samples", "<vertical><samples>", where, _positive_int, 1),
        "vertical_resolution": _read(vertical, "resolution", "<vertical><resolution>", where, _positive, 1.0),
        "vertical_min_angle": _read(vertical, "min_angle", "<vertical><min_angle>", where, _finite, 0.0),
        "vertical_max_angle": _read(vertical, "max_angle", "<vertical><max_angle>", where, _finite, 0.0),
    }


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
    if config.range_count < 1:
        raise ConfigError(f"{where}: <samples> × <resolution> = {config.samples * config.resolution} "
                          f"leaves no ranges")
    if config.vertical_range_count < 1:
        raise ConfigError(f"{where}: <vertical><samples> × <vertical><resolution> = "
                          f"{config.vertical_samples * config.vertical_resolution} leaves no ranges")


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

    def scan(self, sensor_pose_world: Pose, collision_filter_mask: int = -1) -> Scan:
        """Scan from ``sensor_pose_world`` (link world pose ∘ ``config.pose``).

        A ray sees a collision object only if (object group & collision_filter_mask) != 0 and
        (object mask & 1) != 0: pybullet 3.2.7's ray test acts as collision group 1
        (btBroadphaseProxy::DefaultFilter) with this mask. PyBullet puts dynamic bodies in group 1 and
        mass-0 bodies in group 2, so to hide the robot that carries the sensor, give its links a group bit
        of their own (not 1 or 2), keep 1 set in their masks, and pass ``-1 & ~robot_bit`` here.
        """
        config = self._config
        rotation = np.asarray(rotation_matrix(sensor_pose_world.orientation))
        origin = np.asarray(sensor_pose_world.position)
        points = self._ray_points @ rotation.T + origin
        count = self._ray_count
        fractions = np.empty(count)
        for first in range(0, count, _MAX_RAYS_PER_BATCH):
            last = min(first + _MAX_RAYS_PER_BATCH, count)
            hits = self._client.rayTestBatch(points[first:last], points[count + first:count + last],
                                             collisionFilterMask=collision_filter_mask)
            fractions[first:last] = [hit[2] for hit in hits]

        # Rays are cast from range_min; a miss (fraction 1) is set to range_max exactly, because
        # min + 1·(max − min) can round to just below max.
        raw = np.where(fractions >= 1.0, config.range_max,
                       config.range_min + fractions * (config.range_max - config.range_min))
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
