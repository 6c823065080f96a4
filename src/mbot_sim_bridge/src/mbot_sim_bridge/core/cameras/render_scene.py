"""What cameras see and how it is drawn: the renderer choice, the render scene of a Simulation, and one camera's
render of colour and depth from a sensor pose."""
import os
import pkgutil
import tempfile
import weakref
from dataclasses import dataclass
from typing import Dict, Optional, Tuple

import numpy as np
import pybullet

from ..geometry import IDENTITY, Pose, compose, inverse, rotation_matrix
from .image_formats import linear_depth
from ..log import get_logger, info_once, warn_once
from ..description.materials import colour_robot
from ..pybullet_shapes import DEFAULT_WORLD_RGBA, visual_shape, welded_body

_log = get_logger(__name__)

# Gazebo's default <scene><background>, for pixels where nothing is drawn.
BACKGROUND_RGB = (178, 178, 178)
# Environment choice of the renderer: "tiny" (default) or "egl" (the bench compares them).
RENDERER_ENV = "MBOT_CAMERA_RENDERER"

# Whether the EGL plugin loaded, per client object: PyBullet hands a disconnected client's number to the next
# client, which has no plugin (keyed by number, a later client rendered with TinyRenderer while called 'egl').
_egl_loaded: "weakref.WeakKeyDictionary[object, bool]" = weakref.WeakKeyDictionary()


def choose_renderer(client) -> str:
    """'tiny' (PyBullet's TinyRenderer, the default) or 'egl' when asked for with MBOT_CAMERA_RENDERER=egl.

    The EGL plugin (PyBullet's OpenGL renderer on the platform's GL, here Mesa's llvmpipe) puts things within a
    pixel of where CameraInfo says, as TinyRenderer does (test_camera), but it never sees bodies created before
    it was loaded into the client. The bench measures the speed of both.
    """
    wanted = os.environ.get(RENDERER_ENV, "tiny").strip().lower()
    if wanted not in ("egl", "tiny"):
        warn_once(_log, f"{RENDERER_ENV}='{wanted}' is not 'egl' or 'tiny'; using tiny")
        wanted = "tiny"
    if wanted == "tiny" or client.getConnectionInfo().get("connectionMethod") == pybullet.GUI:
        return "tiny"
    if client not in _egl_loaded:
        loader = pkgutil.get_loader("eglRenderer")
        plugin = client.loadPlugin(loader.get_filename(), "_eglRendererPlugin") if loader is not None else -1
        _egl_loaded[client] = plugin >= 0
        if plugin < 0:
            info_once(_log, "PyBullet's EGL renderer did not load; cameras use TinyRenderer")
    return "egl" if _egl_loaded[client] else "tiny"


class RenderScene:
    """What cameras see, kept beside the physics in the same PyBullet server.

    World models are collision-only bodies. TinyRenderer draws their boxes, cylinders, spheres and planes
    (the planes with its checkerboard texture, which is taken off here so they show their material colour)
    but not their meshes; the EGL renderer draws none of them. So each world model gets a visual-only twin
    (no collision: rays and contacts never meet it) of the shapes the renderer would miss, with their material
    colours, moved onto the model before every render. Robots keep their URDF visuals, recoloured with their
    links' Gazebo materials as the window does. The Simulation owns one, made when its first camera needs it; with the
    simulator window open, the window's colours are its own and only the mesh twins are added.
    """

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
        parts = []
        with tempfile.TemporaryDirectory(prefix="mbot_camera_") as folder:
            for shape in model.shapes:
                if meshes_only and shape.kind != "mesh":
                    continue
                visual = visual_shape(client, shape, folder)
                if visual is not None:
                    parts.append((visual, compose(world_to_model, shape.pose)))
            if not parts:
                return None
            body = welded_body(client, model.pose, parts, visual=True)
        for index in range(len(parts)):
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
