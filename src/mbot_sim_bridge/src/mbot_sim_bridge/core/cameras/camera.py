"""Gazebo's camera (``type="camera"``) and depth camera (``type="depth"``), rendered by PyBullet.

``parse_camera_sensor`` reads the ``<sensor>``; ``Camera`` is the core of ``libgazebo_ros_camera.so`` and
``DepthCamera`` that of ``libgazebo_ros_openni_kinect.so`` (``libgazebo_ros_depth_camera.so`` is the same
without ``pointCloudCutoffMax``). What Gazebo does and the bridge copies (gazebo_plugins noetic-devel,
``gazebo_ros_camera_utils.cpp``, ``gazebo_ros_openni_kinect.cpp``, ``gazebo_ros_depth_camera.cpp``):

- The camera looks along its frame's +x, image up = +z (sensor frame = link frame ∘ ``<sensor><pose>``).
- CameraInfo: f = width / (2·tan(hfov/2)) for both axes (an explicit ``focalLength`` wins, with a warning),
  cx = (width + 1)/2, cy = (height + 1)/2 (1-based, so a point on the optical axis lands half a pixel
  from where K puts it), P[3] = −f·hackBaseline, D = [k1, k2, t1, t2, k3] from the plugin tags.
- ``<image><format>`` sets the encoding; an unknown format is published as bgr8 with one error.
- Depth is z along the optical axis in metres. Nothing rendered there (beyond ``<clip><far>``) reads +inf;
  the depth image and the cloud turn every value outside (pointCloudCutoff, pointCloudCutoffMax) into NaN.
- The cloud is organized, 32 bytes a point (x, y, z, pad, rgb, pad), in the optical frame:
  x = z·(i − (W−1)/2)/f, y = z·(j − (H−1)/2)/f, with f from hfov and a 0-based centre (unlike K).
- Sensor ``<update_rate>`` paces the frames; the plugin's ``updateRate`` throttles the camera plugin's image
  and camera_info, and only the camera_info topics of the depth plugins.

Where the bridge differs: the picture comes from PyBullet's TinyRenderer (see ``render_scene.choose_renderer``), so
colours are the models' flat material colours under PyBullet's light; pixels where nothing is drawn get
Gazebo's default background, 0.7 grey. World models are drawn from their collision shapes. Lens
``<distortion>`` is not rendered. A sensor ``<update_rate>`` of 0 (Gazebo: as fast as the renderer goes)
runs at the plugin's ``updateRate``, or at 30 Hz when that is 0 too.
"""
import xml.etree.ElementTree as ET
from typing import NamedTuple, Optional, Tuple

import numpy as np

from .. import names
from ..clock import UpdateTimer
from ..errors import ConfigError
from .image_formats import (FORMAT_ENCODINGS, add_image_noise, convert_image, depth_16uc1, depth_in_range,
                            image_encoding, point_cloud)
from ..geometry import Pose, compose
from ..log import get_logger, info_once, warn_once
from ..params import Param, PluginParams, non_negative, positive, rate
from ..plugin import Plugin
from ..sensors.sensor_elements import gaussian_noise, sensor_label, sensor_pose
from .render_scene import CameraConfig, CameraRenderer
from ..xml_values import XmlDocument

_log = get_logger(__name__)

# The rate a sensor with <update_rate> 0 and plugin updateRate 0 renders at (Gazebo: as fast as it can).
DEFAULT_FRAME_RATE = 30.0
# Pixels per frame at most: the loop waits for each frame, and a depth frame of 4096 x 2160 took 7.5 s (0.5 GB),
# one of 8192 x 8192 16 s and 3.4 GB; 1920 x 1080 takes about 1 s on a loaded machine.
MAX_CAMERA_PIXELS = 2048 * 2048
CAMERA_SENSOR_PARAMS = (
    rate("update_rate", 0.0, "frames per sim second; 0 = the plugin's updateRate, else 30",
         warn_if_missing=False),
    Param("camera/horizontal_fov", float, 1.047, "rad (SDF's minimum 0.1)", minimum=0.1, maximum=3.1416,
          warn_if_missing=False),
    Param("camera/image/width", int, 320, "pixels", minimum=1, maximum=8192, warn_if_missing=False),
    Param("camera/image/height", int, 240, "pixels", minimum=1, maximum=8192, warn_if_missing=False),
    Param("camera/image/format", str, "R8G8B8", "pixel format", warn_if_missing=False),
    # PyBullet's TinyRenderer never returns from a frame whose near plane is under about 1e-10 m.
    Param("camera/clip/near", float, 0.1, "m", minimum=1e-6, warn_if_missing=False),
    positive("camera/clip/far", float, 100.0, "m", warn_if_missing=False),
    Param("camera/noise/type", str, "none", "gaussian or none", warn_if_missing=False),
    Param("camera/noise/mean", float, 0.0, "in [0, 1] colour units", warn_if_missing=False),
    non_negative("camera/noise/stddev", float, 0.0, "in [0, 1] colour units", warn_if_missing=False),
)

_NAMESPACE = Param("robotNamespace", str, "", "absent: the simulator's namespace; empty: the model name",
                   warn_if_missing=False)
# GazeboRosCameraUtils::Load's tags (all read silently when absent).
CAMERA_PARAMS = (
    _NAMESPACE,
    Param("cameraName", str, "", "the topics' namespace below robotNamespace", warn_if_missing=False),
    Param("imageTopicName", str, "image_raw", "sensor_msgs/Image", warn_if_missing=False),
    Param("cameraInfoTopicName", str, "camera_info", "sensor_msgs/CameraInfo", warn_if_missing=False),
    Param("frameName", str, "", "frame_id of every message", warn_if_missing=False),
    rate("updateRate", 0.0, "Hz throttle on top of the sensor update_rate; 0 = every frame",
         warn_if_missing=False),
    Param("hackBaseline", float, 0.0, "P[3] = -f * hackBaseline", warn_if_missing=False),
    non_negative("focalLength", float, 0.0, "0 = width / (2 tan(hfov/2))", warn_if_missing=False),
    Param("Cx", float, 0.0, "0 = (width + 1) / 2", warn_if_missing=False),
    Param("Cy", float, 0.0, "0 = (height + 1) / 2", warn_if_missing=False),
    Param("CxPrime", float, 0.0, "read by Gazebo, unused in the messages", warn_if_missing=False),
    Param("distortionK1", float, 0.0, "copied into D", warn_if_missing=False),
    Param("distortionK2", float, 0.0, "copied into D", warn_if_missing=False),
    Param("distortionK3", float, 0.0, "copied into D", warn_if_missing=False),
    Param("distortionT1", float, 0.0, "copied into D", warn_if_missing=False),
    Param("distortionT2", float, 0.0, "copied into D", warn_if_missing=False),
    Param("borderCrop", bool, True, "reported only", warn_if_missing=False),
    Param("autoDistortion", bool, False, "reported only (no distortion is rendered)", warn_if_missing=False),
)
# Tags the camera plugins read without effect (or not at all); the snake_case distortion tags are a
# common slip (the course's kinect writes them) that Gazebo ignores too.
CAMERA_IGNORED_TAGS = ("alwaysOn", "baseline", "distortion_k1", "distortion_k2", "distortion_k3",
                       "distortion_t1", "distortion_t2", "imageTopicNameRaw", "triggerTopicName")
DEPTH_PARAMS = CAMERA_PARAMS + (
    Param("depthImageTopicName", str, "depth/image_raw", "32FC1 metres (16UC1 mm)", warn_if_missing=False),
    Param("depthImageCameraInfoTopicName", str, "depth/camera_info", "CameraInfo of the depth image",
          warn_if_missing=False),
    Param("pointCloudTopicName", str, "points", "sensor_msgs/PointCloud2", warn_if_missing=False),
    non_negative("pointCloudCutoff", float, 0.4, "m; nearer is NaN", warn_if_missing=False),
    non_negative("pointCloudCutoffMax", float, 5.0, "m; farther is NaN", warn_if_missing=False),
    Param("useDepth16UC1Format", bool, False, "16UC1 millimetres (0 = no reading) instead of 32FC1",
          warn_if_missing=False),
)
# libgazebo_ros_depth_camera.so: no cutoffMax; its reflectance and normals topics are not produced.
DEPTH_CAMERA_PARAMS = tuple(param for param in DEPTH_PARAMS if param.tag != "pointCloudCutoffMax")

def parse_camera_sensor(sensor: ET.Element, link: str, document: XmlDocument) -> CameraConfig:
    """Read ``<sensor type="camera"|"depth">``; bad values raise ConfigError naming where and what."""
    name, where, label = sensor_label(sensor, "camera", link, document)
    values = PluginParams(sensor, label, where=where, check_unknown=False).read(CAMERA_SENSOR_PARAMS)
    pose = sensor_pose(sensor, document, where, label)
    if values["camera/clip/far"] <= values["camera/clip/near"]:
        raise ConfigError(f"{where}: {label}: <clip><far> ({values['camera/clip/far']}) must exceed <clip><near> "
                          f"({values['camera/clip/near']})")
    width, height = values["camera/image/width"], values["camera/image/height"]
    if width * height > MAX_CAMERA_PIXELS:
        raise ConfigError(f"{where}: {label}: <image> {width} x {height} is {width * height:,} pixels; a camera "
                          f"renders at most {MAX_CAMERA_PIXELS:,} (2048 x 2048) per frame, with the simulation "
                          "waiting for it")
    noisy = gaussian_noise(sensor.find("camera/noise"), values["camera/noise/type"], f"{where}: {label}", "the image")
    stddev = values["camera/noise/stddev"] if noisy else None
    if sensor.find("camera/distortion") is not None:
        info_once(_log, f"{where}: {label}: <distortion> is not rendered; the image is undistorted")
    return CameraConfig(name, link, values["camera/image/width"], values["camera/image/height"],
                        values["camera/horizontal_fov"], values["camera/image/format"], values["camera/clip/near"],
                        values["camera/clip/far"], pose, values["update_rate"], values["camera/noise/mean"], stddev)


class Intrinsics(NamedTuple):
    """What CameraInfo carries, as GazeboRosCameraUtils fills it."""

    width: int
    height: int
    f: float
    cx: float
    cy: float
    baseline: float  # hackBaseline
    distortion: Tuple[float, float, float, float, float]  # k1, k2, t1, t2, k3

    @property
    def K(self) -> Tuple[float, ...]:  # noqa: N802 (ROS's name)
        return (self.f, 0.0, self.cx, 0.0, self.f, self.cy, 0.0, 0.0, 1.0)

    @property
    def P(self) -> Tuple[float, ...]:  # noqa: N802 (ROS's name)
        return (self.f, 0.0, self.cx, -self.f * self.baseline, 0.0, self.f, self.cy, 0.0, 0.0, 0.0, 1.0, 0.0)

    R = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
    distortion_model = "plumb_bob"


def camera_intrinsics(config: CameraConfig, params: dict, label: str = "camera") -> Intrinsics:
    computed = config.focal_length
    f = params.get("focalLength", 0.0) or computed
    if not np.isclose(f, computed):
        warn_once(_log, f"{label}: <focalLength> {f} is inconsistent with width {config.width} and hfov "
                        f"{config.hfov} (expected {computed:.6g}); CameraInfo uses {f}, the picture follows hfov")
    cx = params.get("Cx", 0.0) or (config.width + 1.0) / 2.0
    cy = params.get("Cy", 0.0) or (config.height + 1.0) / 2.0
    distortion = tuple(params.get(tag, 0.0) for tag in ("distortionK1", "distortionK2", "distortionT1",
                                                        "distortionT2", "distortionK3"))
    return Intrinsics(config.width, config.height, f, cx, cy, params.get("hackBaseline", 0.0), distortion)


class Frame(NamedTuple):
    """One sensor frame: the image in the plugin's encoding and (depth sensors) the z-depth in metres."""

    stamp: float
    image: np.ndarray
    rgb: np.ndarray
    depth: Optional[np.ndarray]


class Throttle:
    """The plugins' own ``updateRate``: ``now − last ≥ period`` on sensor frame times (0 = every frame)."""

    def __init__(self, rate: float, start: float):
        self.period = 1.0 / rate if rate > 0 else 0.0
        self.last = start

    def passes(self, now: float) -> bool:
        if now < self.last:  # the clock went back (reset_simulation)
            self.last = now
        if now - self.last >= self.period - 1e-9:
            self.last = now
            return True
        return False


class Camera(Plugin):
    """Core of libgazebo_ros_camera.so: a camera sensor rendered on demand from its link."""
    NAMESPACE_RULE = names.SENSOR

    GAZEBO_CLASS = "GazeboRosCamera"
    PARAMS = CAMERA_PARAMS
    IGNORED_TAGS = CAMERA_IGNORED_TAGS
    SENSOR_TYPES = ("camera", "depth")  # a depth sensor is a camera sensor too
    SENSOR_PARAMS = CAMERA_SENSOR_PARAMS
    WITH_DEPTH = False

    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        robot = context.robot
        self.config = parse_camera_sensor(sensor, context.link, robot.model.document)
        self.params = self.read_params()
        self.intrinsics = camera_intrinsics(self.config, self.params, self.label)
        encoding, self.bytes_per_pixel, known = image_encoding(self.config.image_format)
        if not known:
            warn_once(_log, f"{context.where(sensor)}: {self.label}: Unsupported Gazebo ImageFormat "
                            f"'{self.config.image_format}'; published as bgr8 (known: "
                            f"{', '.join(FORMAT_ENCODINGS)})")
        self.encoding = encoding
        self.renderer = CameraRenderer(robot.client, self.config, context.simulation.render_scene)
        self.rng = context.random_stream(self.config.sensor_name)
        now = context.simulation.sim_time
        self.frame_rate = self.config.update_rate or self.params["updateRate"] or DEFAULT_FRAME_RATE
        if not self.config.update_rate:
            info_once(_log, f"{self.label}: sensor '{self.config.sensor_name}' has <update_rate> 0 (Gazebo: as "
                            f"fast as it renders); the bridge renders it at {self.frame_rate:g} Hz")
        self.timer = UpdateTimer(self.frame_rate, start=now)
        self.throttle = Throttle(self.params["updateRate"], now)
        self.latest: Optional[Frame] = None

    def sensor_pose(self) -> Pose:
        return compose(self.context.robot.link_world_pose(self.config.link), self.config.pose)

    def capture(self, now: float) -> Frame:
        """Render one frame (colour and, for depth sensors, depth from the same render)."""
        rgb, depth = self.renderer.render(self.sensor_pose())
        if self.config.noise_stddev is not None:
            rgb = add_image_noise(rgb, self.config.noise_mean, self.config.noise_stddev, self.rng)
        return Frame(now, convert_image(rgb, self.encoding), rgb, depth if self.WITH_DEPTH else None)

    def reset(self, now: float):
        super().reset(now)
        self.throttle.last = now

    def update(self, now: float):
        if self.throttle.passes(now):
            self.latest = self.capture(now)


class DepthCamera(Camera):
    """Core of libgazebo_ros_openni_kinect.so: colour, depth and cloud from one render per sensor frame."""

    GAZEBO_CLASS = "GazeboRosOpenniKinect"
    PARAMS = DEPTH_PARAMS
    SENSOR_TYPES = ("depth",)
    WITH_DEPTH = True

    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        self.cutoff = self.params["pointCloudCutoff"]
        self.cutoff_max = self.params.get("pointCloudCutoffMax", np.inf)

    def depth_image(self, frame: Frame) -> np.ndarray:
        """The depth image values: float32 metres with NaN outside the cutoffs (or 16UC1 mm, 0 outside)."""
        depth = depth_in_range(frame.depth, self.cutoff, self.cutoff_max)
        return depth_16uc1(depth) if self.params["useDepth16UC1Format"] else depth

    def cloud_data(self, frame: Frame) -> Tuple[bytes, bool]:
        return point_cloud(depth_in_range(frame.depth, self.cutoff, self.cutoff_max), self.config.hfov,
                           frame.image if frame.image.dtype == np.uint8 else None)

    def update(self, now: float):
        # Images and cloud go out every sensor frame; updateRate throttles only the camera_info topics.
        self.latest = self.capture(now)


class PlainDepthCamera(DepthCamera):
    """Core of libgazebo_ros_depth_camera.so: the kinect's outputs without pointCloudCutoffMax."""

    GAZEBO_CLASS = "GazeboRosDepthCamera"
    PARAMS = DEPTH_CAMERA_PARAMS
