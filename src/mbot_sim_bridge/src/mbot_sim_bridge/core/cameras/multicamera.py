"""``libgazebo_ros_multicamera.so`` on ``<sensor type="multicamera">`` without ROS (gazebo_plugins noetic-devel
``gazebo_ros_multicamera.cpp``, ``MultiCameraPlugin.cpp``, ``gazebo_ros_camera_utils.cpp``).

Each ``<camera name>`` of the sensor is read as a camera sensor's ``<camera>`` (``camera.py``), posed at the
sensor's ``<pose>`` then the camera's own ``<pose>``. As upstream, a camera whose name contains "left" publishes
under ``<cameraName>/left`` with Tx = 0 in its P, one containing "right" under ``<cameraName>/right`` with
P[3] = −f·``hackBaseline`` (the tag, not the cameras' distance apart); any other camera is not published (said
once). Every camera shares the sensor's ``<update_rate>`` and the plugin's tags; each is rendered once per frame,
and the ROS layer renders only the cameras someone subscribes to.
"""
import dataclasses
import xml.etree.ElementTree as ET
from typing import Dict, NamedTuple

from .. import names
from .camera import (CAMERA_IGNORED_TAGS, CAMERA_PARAMS, CAMERA_SENSOR_PARAMS, DEFAULT_FRAME_RATE, Frame, Intrinsics,
                     Throttle, camera_intrinsics, parse_camera_sensor)
from ..clock import UpdateTimer
from ..errors import ConfigError
from ..geometry import Pose, compose
from .image_formats import FORMAT_ENCODINGS, add_image_noise, convert_image, image_encoding
from ..log import get_logger, warn_once
from ..plugin import Plugin
from .render_scene import CameraConfig, CameraRenderer
from ..sensors.sensor_elements import sensor_label, sensor_pose

_log = get_logger(__name__)

SIDES = ("left", "right")
# The sensor's values; each <camera name> holds the camera sensor's camera/... values.
MULTICAMERA_SENSOR_PARAMS = CAMERA_SENSOR_PARAMS


class StereoCamera(NamedTuple):
    """One published camera of the sensor: its side ("left" or "right"), values, CameraInfo and renderer."""
    side: str
    config: CameraConfig
    encoding: str
    intrinsics: Intrinsics
    renderer: CameraRenderer
    throttle: Throttle


def _camera_as_sensor(sensor: ET.Element, camera: ET.Element, document) -> ET.Element:
    """A camera sensor element holding ``camera`` and the multicamera's update_rate, for parse_camera_sensor;
    errors inside it still name the camera's line."""
    as_sensor = ET.Element("sensor", {"name": f"{sensor.get('name')}/{camera.get('name')}", "type": "camera"})
    for element in (sensor.find("update_rate"), camera):
        if element is not None:
            as_sensor.append(element)
    document.lines[as_sensor] = document.lines.get(camera)
    return as_sensor


class MultiCamera(Plugin):
    """Core of libgazebo_ros_multicamera.so (GazeboRosMultiCamera): a stereo pair on one sensor."""
    NAMESPACE_RULE = names.SENSOR
    GAZEBO_CLASS = "GazeboRosMultiCamera"
    PARAMS = CAMERA_PARAMS
    IGNORED_TAGS = CAMERA_IGNORED_TAGS
    SENSOR_TYPES = ("multicamera",)
    SENSOR_PARAMS = MULTICAMERA_SENSOR_PARAMS

    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        robot = context.robot
        document = robot.model.document
        name, where, label = sensor_label(sensor, "multicamera", context.link, document)
        self.sensor_name = name
        self.params = self.read_params()
        base_pose = sensor_pose(sensor, document, where, label)
        now = context.simulation.sim_time
        self.cameras: Dict[str, StereoCamera] = {}
        for camera in sensor.findall("camera"):
            camera_name = camera.get("name") or ""
            side = next((side for side in SIDES if side in camera_name), None)
            if side is None or side in self.cameras:
                warn_once(_log, f"{document.where(camera)}: {label}: camera '{camera_name}' is not published: "
                                "the plugin publishes one camera named with 'left' and one with 'right'")
                continue
            config = parse_camera_sensor(_camera_as_sensor(sensor, camera, document), context.link, document)
            camera_pose = sensor_pose(camera, document, document.where(camera), f"{label} camera '{camera_name}'")
            config = dataclasses.replace(config, pose=compose(base_pose, camera_pose))
            params = dict(self.params, hackBaseline=self.params["hackBaseline"] if side == "right" else 0.0)
            encoding, _, known = image_encoding(config.image_format)
            if not known:
                warn_once(_log, f"{document.where(camera)}: {label}: Unsupported Gazebo ImageFormat "
                                f"'{config.image_format}'; published as bgr8 (known: {', '.join(FORMAT_ENCODINGS)})")
            self.cameras[side] = StereoCamera(side, config, encoding, camera_intrinsics(config, params, self.label),
                                              CameraRenderer(robot.client, config, context.simulation.render_scene),
                                              Throttle(self.params["updateRate"], now))
        if not self.cameras:
            raise ConfigError(f"{where}: {label}: no <camera> named with 'left' or 'right'; the plugin publishes "
                              "nothing else")
        first = next(iter(self.cameras.values())).config
        self.frame_rate = first.update_rate or self.params["updateRate"] or DEFAULT_FRAME_RATE
        self.timer = UpdateTimer(self.frame_rate, start=now)
        self.rng = context.random_stream(name)
        self.latest: Dict[str, Frame] = {}

    def camera_pose(self, side: str) -> Pose:
        camera = self.cameras[side]
        return compose(self.context.robot.link_world_pose(camera.config.link), camera.config.pose)

    def capture(self, side: str, now: float) -> Frame:
        camera = self.cameras[side]
        rgb, _ = camera.renderer.render(self.camera_pose(side))
        if camera.config.noise_stddev is not None:
            rgb = add_image_noise(rgb, camera.config.noise_mean, camera.config.noise_stddev, self.rng)
        return Frame(now, convert_image(rgb, camera.encoding), rgb, None)

    def reset(self, now: float):
        super().reset(now)
        for camera in self.cameras.values():
            camera.throttle.last = now

    def update(self, now: float):
        self.latest = {side: self.capture(side, now) for side, camera in self.cameras.items()
                       if camera.throttle.passes(now)}
