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

Where the bridge differs: the picture comes from PyBullet's TinyRenderer (see ``choose_renderer``), so
colours are the models' flat material colours under PyBullet's light; pixels where nothing is drawn get
Gazebo's default background, 0.7 grey. World models are drawn from their collision shapes. Lens
``<distortion>`` is not rendered. A sensor ``<update_rate>`` of 0 (Gazebo: as fast as the renderer goes)
runs at the plugin's ``updateRate``, or at 30 Hz when that is 0 too.
"""
import os
import pkgutil
import tempfile
import weakref
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Dict, NamedTuple, Optional, Tuple

import numpy as np
import pybullet

from . import names
from .clock import UpdateTimer
from .errors import BridgeError, ConfigError
from .geometry import IDENTITY, Pose, compose, inverse, rotation_matrix
from .log import get_logger, info_once, warn_once
from .materials import colour_robot
from .params import Param, PluginParams, non_negative, positive
from .plugin import Plugin
from .xml_values import XmlDocument, read_pose

_log = get_logger(__name__)

# The rate a sensor with <update_rate> 0 and plugin updateRate 0 renders at (Gazebo: as fast as it can).
DEFAULT_FRAME_RATE = 30.0
# Gazebo's default <scene><background>, for pixels where nothing is drawn.
BACKGROUND_RGB = (178, 178, 178)
# Environment choice of the renderer: "tiny" (default) or "egl" (the bench compares them).
RENDERER_ENV = "MBOT_CAMERA_RENDERER"

# <image><format> -> (ROS encoding, bytes per pixel), as GazeboRosCameraUtils::Init.
FORMAT_ENCODINGS: Dict[str, Tuple[str, int]] = {
    "L8": ("mono8", 1), "L_INT8": ("mono8", 1),
    "L16": ("mono16", 2), "L_INT16": ("mono16", 2),
    "R8G8B8": ("rgb8", 3), "RGB_INT8": ("rgb8", 3),
    "B8G8R8": ("bgr8", 3), "BGR_INT8": ("bgr8", 3),
    "R16G16B16": ("rgb16", 6), "RGB_INT16": ("rgb16", 6),
    "BAYER_RGGB8": ("bayer_rggb8", 1), "BAYER_BGGR8": ("bayer_bggr8", 1),
    "BAYER_GBRG8": ("bayer_gbrg8", 1), "BAYER_GRBG8": ("bayer_grbg8", 1),
}
# Channel (0 R, 1 G, 2 B) of each pixel of a 2x2 Bayer tile, row-major.
_BAYER_TILES = {"bayer_rggb8": (0, 1, 1, 2), "bayer_bggr8": (2, 1, 1, 0),
                "bayer_gbrg8": (1, 2, 0, 1), "bayer_grbg8": (1, 0, 2, 1)}

CAMERA_SENSOR_PARAMS = (
    non_negative("update_rate", float, 0.0, "frames per sim second; 0 = the plugin's updateRate, else 30",
                 warn_if_missing=False),
    Param("camera/horizontal_fov", float, 1.047, "rad", minimum=0, exclusive_minimum=True, maximum=3.1416,
          warn_if_missing=False),
    Param("camera/image/width", int, 320, "pixels", minimum=1, maximum=8192, warn_if_missing=False),
    Param("camera/image/height", int, 240, "pixels", minimum=1, maximum=8192, warn_if_missing=False),
    Param("camera/image/format", str, "R8G8B8", "pixel format", warn_if_missing=False),
    positive("camera/clip/near", float, 0.1, "m", warn_if_missing=False),
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
    non_negative("updateRate", float, 0.0, "Hz throttle on top of the sensor update_rate; 0 = every frame",
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

# PointCloud2 layout Gazebo builds with setPointCloud2FieldsByString(2, "xyz", "rgb").
POINT_STEP = 32
POINT_FIELDS = (("x", 0), ("y", 4), ("z", 8), ("rgb", 16))  # all FLOAT32, count 1


@dataclass(frozen=True)
class CameraConfig:
    """One camera sensor's SDF values; lengths in m, angles in rad."""

    sensor_name: str
    link: str
    width: int = 320
    height: int = 240
    hfov: float = 1.047
    image_format: str = "R8G8B8"
    near: float = 0.1
    far: float = 100.0
    pose: Pose = IDENTITY  # of the sensor in the link frame
    update_rate: float = 0.0
    noise_mean: float = 0.0
    noise_stddev: Optional[float] = None  # None: no noise

    @property
    def focal_length(self) -> float:
        return self.width / (2.0 * np.tan(self.hfov / 2.0))


def parse_camera_sensor(sensor: ET.Element, link: str, document: XmlDocument) -> CameraConfig:
    """Read ``<sensor type="camera"|"depth">``; bad values raise ConfigError naming where and what."""
    name = sensor.get("name")
    where = document.where(sensor)
    if not name:
        raise ConfigError(f"{where}: a <sensor> on link '{link}' has no name")
    label = f"camera '{name}' on link '{link}'"
    values = PluginParams(sensor, label, where=where, check_unknown=False).read(CAMERA_SENSOR_PARAMS)
    try:
        pose = read_pose(sensor.find("pose"), document)
    except BridgeError as error:
        raise ConfigError(f"{where}: {label}: {str(error).split(': ', 1)[1]}") from None
    if values["camera/clip/far"] <= values["camera/clip/near"]:
        raise ConfigError(f"{where}: {label}: <clip><far> ({values['camera/clip/far']}) must exceed <clip><near> "
                          f"({values['camera/clip/near']})")
    stddev = None
    noise_type = values["camera/noise/type"]
    if sensor.find("camera/noise") is not None and noise_type != "none":
        if noise_type == "gaussian":
            stddev = values["camera/noise/stddev"]
        else:
            warn_once(_log, f"{where}: {label}: <noise><type> '{noise_type}' is not supported (only gaussian is); "
                            f"the image is noise-free")
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


def image_encoding(image_format: str) -> Tuple[str, int, bool]:
    """(encoding, bytes per pixel, known); Gazebo publishes an unknown format as bgr8."""
    if image_format in FORMAT_ENCODINGS:
        return FORMAT_ENCODINGS[image_format] + (True,)
    return "bgr8", 3, False


def convert_image(rgb: np.ndarray, encoding: str) -> np.ndarray:
    """An (H, W, 3) uint8 RGB picture as the bytes of ``encoding``: (H, W, channels), C-contiguous."""
    if encoding == "rgb8":
        return np.ascontiguousarray(rgb)
    if encoding == "bgr8":
        return np.ascontiguousarray(rgb[..., ::-1])
    if encoding == "rgb16":
        return rgb.astype("<u2") * 257
    grey = (rgb @ np.array([0.299, 0.587, 0.114], dtype=np.float32)).round().astype(np.uint8)[..., np.newaxis]
    if encoding == "mono8":
        return grey
    if encoding == "mono16":
        return grey.astype("<u2") * 257
    tile = _BAYER_TILES[encoding]
    height, width = rgb.shape[:2]
    rows, cols = np.ogrid[:height, :width]
    channel = np.asarray(tile, dtype=np.intp).reshape(2, 2)[rows % 2, cols % 2]
    return np.take_along_axis(rgb, channel[..., np.newaxis], axis=2)


def linear_depth(buffer: np.ndarray, near: float, far: float) -> np.ndarray:
    """OpenGL depth-buffer values in [0, 1] as z-depth in metres; +inf where nothing was drawn."""
    buffer = np.asarray(buffer, dtype=np.float32)
    with np.errstate(divide="ignore"):
        depth = (far * near) / (far - (far - near) * buffer)
    depth[buffer >= 1.0] = np.inf
    return depth


def depth_in_range(depth: np.ndarray, cutoff: float, cutoff_max: float = np.inf) -> np.ndarray:
    """The depth image: NaN outside the open interval (cutoff, cutoff_max)."""
    valid = (depth > cutoff) & (depth < cutoff_max)
    return np.where(valid, depth, np.float32(np.nan)).astype(np.float32)


def depth_16uc1(depth: np.ndarray) -> np.ndarray:
    """16UC1 millimetres as Gazebo converts (truncating); NaN becomes 0, beyond 65.535 m saturates."""
    millimetres = np.nan_to_num(depth * 1000.0, nan=0.0, posinf=0.0)
    return np.clip(millimetres, 0, 65535).astype("<u2")


def point_cloud(depth: np.ndarray, hfov: float, rgb: Optional[np.ndarray]) -> Tuple[bytes, bool]:
    """Gazebo's organized cloud of an in-range depth image (NaN = no point): (data, is_dense).

    Points are x = z·(i − (W−1)/2)/f, y = z·(j − (H−1)/2)/f, z in the optical frame, f = W/(2·tan(hfov/2));
    rgb bytes 0..2 are the image's first three channels (R, G, B for rgb8), as Gazebo copies them.
    """
    height, width = depth.shape
    f = width / (2.0 * np.tan(hfov / 2.0))
    u = ((np.arange(width, dtype=np.float32) - 0.5 * (width - 1)) / f) if width > 1 else np.zeros(1, np.float32)
    v = ((np.arange(height, dtype=np.float32) - 0.5 * (height - 1)) / f) if height > 1 else np.zeros(1, np.float32)
    points = np.zeros((height, width, POINT_STEP // 4), dtype=np.float32)
    points[..., 0] = depth * u[np.newaxis, :]
    points[..., 1] = depth * v[:, np.newaxis]
    points[..., 2] = depth
    if rgb is not None and rgb.dtype == np.uint8 and rgb.shape[2] in (1, 3):
        colour = points.view(np.uint8).reshape(height, width, POINT_STEP)
        colour[..., 16:19] = rgb if rgb.shape[2] == 3 else rgb[..., :1]
    return points.tobytes(), bool(np.isfinite(depth).all())


# --- rendering -------------------------------------------------------------------------------------------

_egl_loaded: Dict[int, bool] = {}


def choose_renderer(client) -> str:
    """'tiny' (PyBullet's TinyRenderer, the default) or 'egl' when asked for with MBOT_CAMERA_RENDERER=egl.

    The EGL plugin (PyBullet's OpenGL renderer on the platform's GL, here Mesa's llvmpipe) is faster on an
    idle machine at 640x480 and above, but it does not draw the same picture: PyBullet resamples its
    framebuffer to the requested size, which moves things by up to 2 px at 640x480 and 5 px at 1280x720 from
    where CameraInfo puts them, and it never sees bodies created before it was loaded. The bench measures both.
    """
    wanted = os.environ.get(RENDERER_ENV, "tiny").strip().lower()
    if wanted not in ("egl", "tiny"):
        warn_once(_log, f"{RENDERER_ENV}='{wanted}' is not 'egl' or 'tiny'; using tiny")
        wanted = "tiny"
    if wanted == "tiny" or client.getConnectionInfo().get("connectionMethod") == pybullet.GUI:
        return "tiny"
    key = client._client
    if key not in _egl_loaded:
        loader = pkgutil.get_loader("eglRenderer")
        plugin = client.loadPlugin(loader.get_filename(), "_eglRendererPlugin") if loader is not None else -1
        _egl_loaded[key] = plugin >= 0
        if plugin < 0:
            info_once(_log, "PyBullet's EGL renderer did not load; cameras use TinyRenderer")
    return "egl" if _egl_loaded[key] else "tiny"


# Colour of world collisions whose link has no material (Gazebo draws those white-grey).
DEFAULT_WORLD_RGBA = (0.7, 0.7, 0.7, 1.0)


def _write_obj(path: str, vertices: np.ndarray, triangles: np.ndarray):
    """A Wavefront OBJ of a triangle mesh: the EGL renderer reads meshes only from files."""
    with open(path, "w") as obj:
        np.savetxt(obj, vertices, fmt="v %.6f %.6f %.6f")
        np.savetxt(obj, triangles + 1, fmt="f %d %d %d")


class RenderScene:
    """What cameras see, kept beside the physics in the same PyBullet server.

    World models are collision-only bodies. TinyRenderer draws their boxes, cylinders, spheres and planes
    (the planes with its checkerboard texture, which is taken off here so they show their material colour)
    but not their meshes; the EGL renderer draws none of them. So each world model gets a visual-only twin
    (no collision: rays and contacts never meet it) of the shapes the renderer would miss, with their material
    colours, moved onto the model before every render. Robots keep their URDF visuals, recoloured with their
    links' Gazebo materials as the window does. One scene per Simulation, shared by its cameras; with the
    simulator window open, the window's colours are its own and only the mesh twins are added.
    """

    _scenes: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()

    @classmethod
    def of(cls, simulation) -> "RenderScene":
        if simulation not in cls._scenes:
            cls._scenes[simulation] = cls(simulation)
        return cls._scenes[simulation]

    def __init__(self, simulation):
        self.simulation = simulation
        client = simulation.engine.client
        self.renderer = choose_renderer(client)
        self.window = client.getConnectionInfo().get("connectionMethod") == pybullet.GUI
        self.twins: Dict[str, Tuple[Optional[int], bool]] = {}  # world model name -> (twin body, static)
        self.coloured: Dict[str, int] = {}  # robot name -> body coloured

    def sync(self):
        engine = self.simulation.engine
        client = engine.client
        for name in [name for name in self.twins if name not in engine.world_bodies]:
            body = self.twins.pop(name)[0]
            if body is not None:
                client.removeBody(body)
        for name in engine.world_bodies:
            if name not in self.twins and name in self.simulation.world_models:
                model = self.simulation.world_models[name]
                if self.renderer == "tiny" and not self.window:
                    _plain_colours(client, engine.world_bodies[name], model)
                self.twins[name] = (self._build_twin(client, model, meshes_only=self.renderer == "tiny"),
                                    model.static)
        for name, (body, static) in self.twins.items():
            if body is not None and not static:
                pose = engine.model_pose(name)
                client.resetBasePositionAndOrientation(body, pose.position, pose.orientation)
        for name, robot in engine.robots.items():
            if not self.window and self.coloured.get(name) != robot.body:
                self.coloured[name] = robot.body
                colour_robot(robot)

    @staticmethod
    def _build_twin(client, model, meshes_only: bool) -> Optional[int]:
        world_to_model = inverse(model.pose)
        visuals, frames = [], []
        with tempfile.TemporaryDirectory(prefix="mbot_camera_") as folder:
            for index, shape in enumerate(model.shapes):
                if meshes_only and shape.kind != "mesh":
                    continue
                visual = _visual_shape(client, shape, os.path.join(folder, f"{index}.obj"))
                if visual is not None:
                    visuals.append(visual)
                    frames.append(compose(world_to_model, shape.pose))
            count = len(visuals)
            if not count:
                return None
            body = client.createMultiBody(
                baseMass=0.0, baseCollisionShapeIndex=-1, baseVisualShapeIndex=-1,
                basePosition=model.pose.position, baseOrientation=model.pose.orientation,
                linkMasses=[0.0] * count, linkCollisionShapeIndices=[-1] * count, linkVisualShapeIndices=visuals,
                linkPositions=[frame.position for frame in frames],
                linkOrientations=[frame.orientation for frame in frames],
                linkInertialFramePositions=[IDENTITY.position] * count,
                linkInertialFrameOrientations=[IDENTITY.orientation] * count,
                linkParentIndices=[0] * count, linkJointTypes=[pybullet.JOINT_FIXED] * count,
                linkJointAxis=[(0.0, 0.0, 1.0)] * count)
        for index in range(count):
            client.changeVisualShape(body, index, textureUniqueId=-1)
        return body


def _plain_colours(client, body: int, model):
    """TinyRenderer's drawing of a collision-only body: no checkerboard, the material colour or grey."""
    # A static model of one collision is a single object (link -1, see world_bodies); others have a link each.
    links = list(range(client.getNumJoints(body))) or [-1]
    shapes = model.shapes if len(model.shapes) == len(links) else [None] * len(links)
    for index, shape in zip(links, shapes):
        rgba = shape.rgba if shape is not None and shape.rgba is not None else DEFAULT_WORLD_RGBA
        client.changeVisualShape(body, index, textureUniqueId=-1, rgbaColor=list(rgba))


def _visual_shape(client, shape, obj_path: str) -> Optional[int]:
    rgba = list(shape.rgba or DEFAULT_WORLD_RGBA)
    if shape.kind == "box":
        return client.createVisualShape(pybullet.GEOM_BOX, halfExtents=[s / 2.0 for s in shape.size], rgbaColor=rgba)
    if shape.kind == "cylinder":
        return client.createVisualShape(pybullet.GEOM_CYLINDER, radius=shape.radius, length=shape.length,
                                        rgbaColor=rgba)
    if shape.kind == "sphere":
        return client.createVisualShape(pybullet.GEOM_SPHERE, radius=shape.radius, rgbaColor=rgba)
    if shape.kind == "plane":
        # A thin box of the plane's visual size, its top face on the plane.
        normal = np.asarray(shape.normal, dtype=float) / np.linalg.norm(shape.normal)
        axis = np.cross((0.0, 0.0, 1.0), normal)
        angle = np.arctan2(np.linalg.norm(axis), normal[2])
        rotation = (tuple(np.append(axis / np.linalg.norm(axis) * np.sin(angle / 2), np.cos(angle / 2)))
                    if np.linalg.norm(axis) > 1e-9 else IDENTITY.orientation)
        sx, sy = (size if size > 0 else 100.0 for size in shape.size[:2])
        return client.createVisualShape(pybullet.GEOM_BOX, halfExtents=[sx / 2, sy / 2, 0.0005], rgbaColor=rgba,
                                        visualFramePosition=tuple(-0.0005 * normal),
                                        visualFrameOrientation=rotation)
    if shape.mesh is None:
        return None
    _write_obj(obj_path, shape.mesh.vertices, shape.mesh.triangles)
    return client.createVisualShape(pybullet.GEOM_MESH, fileName=obj_path, rgbaColor=rgba)


class CameraRenderer:
    """Renders one camera's colour and depth in one call, from a sensor pose in the world."""

    def __init__(self, client, config: CameraConfig, scene: Optional[RenderScene] = None):
        self._client = client
        self._config = config
        self._scene = scene
        self.renderer = scene.renderer if scene is not None else choose_renderer(client)
        self._flags = pybullet.ER_NO_SEGMENTATION_MASK
        # PyBullet's FOV is vertical: the one the square-pixel hfov implies.
        vfov = 2.0 * np.degrees(np.arctan(config.height / (2.0 * config.focal_length)))
        self._projection = client.computeProjectionMatrixFOV(vfov, config.width / config.height, config.near,
                                                             config.far)

    def render(self, pose: Pose) -> Tuple[np.ndarray, np.ndarray]:
        """(rgb (H, W, 3) uint8 with Gazebo's background where nothing is drawn, z-depth (H, W) float32 m)."""
        config = self._config
        if self._scene is not None:
            self._scene.sync()
        rotation = np.asarray(rotation_matrix(pose.orientation))
        eye = np.asarray(pose.position)
        view = self._client.computeViewMatrix(eye, eye + rotation[:, 0], rotation[:, 2])
        _, _, rgba, buffer, _ = self._client.getCameraImage(
            config.width, config.height, view, self._projection, shadow=0, flags=self._flags,
            renderer=pybullet.ER_BULLET_HARDWARE_OPENGL if self.renderer == "egl" else pybullet.ER_TINY_RENDERER)
        rgba = np.asarray(rgba, dtype=np.uint8).reshape(config.height, config.width, 4)
        buffer = np.asarray(buffer, dtype=np.float32).reshape(config.height, config.width)
        rgb = rgba[..., :3].copy()
        rgb[buffer >= 1.0] = BACKGROUND_RGB
        return rgb, linear_depth(buffer, config.near, config.far)


def add_image_noise(rgb: np.ndarray, mean: float, stddev: float, rng: np.random.Generator) -> np.ndarray:
    """Gazebo's image noise: N(mean, stddev) in [0, 1] colour units on every channel, clamped."""
    noise = rng.normal(mean * 255.0, stddev * 255.0, rgb.shape).astype(np.float32)
    return np.clip(rgb + noise, 0, 255).astype(np.uint8)


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
        self.renderer = CameraRenderer(robot.client, self.config, RenderScene.of(context.simulation))
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
