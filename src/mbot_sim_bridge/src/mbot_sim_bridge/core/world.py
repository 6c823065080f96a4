"""SDF worlds: ``.world`` file -> collision shapes -> PyBullet bodies, read the way Gazebo 11 reads them.

``parse_world`` is plain XML work (sdformat 1.4 to 1.7): physics, gravity, models inline or through
``<include>``, links, collisions, friction, poses composed world_T_model · model_T_link · link_T_collision.
``load_world`` turns the result into bodies in one BulletClient. Visuals, lights, scene and GUI are left out;
physics-relevant elements that are not simulated (joints, plugins, unknown geometry) warn once each, naming
file and line.

Each model becomes one PyBullet multibody: a base that carries the model's mass and every collision as a
massless child on a fixed joint. A static model gets mass 0, which PyBullet treats as immovable. SDF
joints are not simulated, so the links of one model move as one rigid body.
"""
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, NamedTuple, Optional, Sequence, Tuple
from xml.parsers import expat

import numpy as np
import pybullet

from .errors import ModelError, WorldError
from .geometry import IDENTITY, Pose, compose, inverse, pose_from_xyz_rpy, rotation_matrix
from .log import get_logger, warn_once
from .materials import sdf_material_rgba
from .mesh import TriangleMesh, load_mesh

_log = get_logger(__name__)

SDF_VERSION = (1, 7)  # newest spec followed here; model.config picks the best model file up to it
SHAPE_KINDS = ("box", "cylinder", "sphere", "plane", "mesh")

# Gazebo ships these two, so worlds include them without shipping them; the model path still wins.
_BUILTIN_MODELS = {
    "ground_plane": """<sdf version="1.6"><model name="ground_plane"><static>true</static>
        <link name="link"><collision name="collision">
          <geometry><plane><normal>0 0 1</normal><size>100 100</size></plane></geometry>
          <surface><friction><ode><mu>100</mu><mu2>50</mu2></ode></friction></surface>
        </collision></link></model></sdf>""",
    "sun": """<sdf version="1.6"><light type="directional" name="sun"/></sdf>""",
}

# Children read elsewhere or without effect on contacts pass silently; unsupported and unknown ones warn once.
_WORLD_IGNORED = {"audio", "wind", "gravity", "magnetic_field", "atmosphere", "gui", "physics", "scene", "light",
                  "spherical_coordinates", "state", "frame", "road"}
_WORLD_UNSUPPORTED = {"actor", "population", "plugin"}
_MODEL_IGNORED = {"static", "pose", "self_collide", "allow_auto_disable", "enable_wind", "frame"}
_MODEL_UNSUPPORTED = {"joint", "plugin", "gripper"}
_LINK_IGNORED = {"pose", "inertial", "visual", "sensor", "self_collide", "enable_wind", "must_be_base_link",
                 "velocity_decay", "frame", "projector", "audio_sink", "audio_source", "battery", "light",
                 "particle_emitter"}
_LINK_DEFAULTS_REQUIRED = {"gravity": True, "kinematic": False}  # other values change the motion
_GEOMETRY_UNSUPPORTED = {"heightmap", "image", "polyline", "capsule", "ellipsoid"}

# PyBullet's createCollisionShape limits for mesh data passed as arrays.
_BULLET_MAX_MESH_VERTICES = 131072
_BULLET_MAX_MESH_INDICES = 524288


@dataclass(frozen=True)
class PhysicsConfig:
    """``<physics>`` and gravity with SDF defaults (reference sheet §8)."""
    max_step_size: float = 0.001
    real_time_factor: float = 1.0
    real_time_update_rate: float = 1000.0
    gravity: Tuple[float, float, float] = (0.0, 0.0, -9.8)


@dataclass(frozen=True)
class Shape:
    """One collision geometry, posed in the world frame.

    ``size`` is the extent of the geometry along its own x, y, z axes: the box size, (2r, 2r, length) for a
    cylinder (axis along local z), 2r for a sphere, the visual ``<size>`` of a plane (its collision is
    infinite) and the scaled bounding box of a mesh (not necessarily centred on the pose).
    """
    model: str
    link: str  # nested models give scoped names, "inner::link"
    name: str
    kind: str  # one of SHAPE_KINDS
    pose: Pose
    size: Tuple[float, float, float]
    radius: float = 0.0
    length: float = 0.0
    normal: Tuple[float, float, float] = (0.0, 0.0, 1.0)
    mesh_path: Optional[str] = None
    mesh_scale: Tuple[float, float, float] = (1.0, 1.0, 1.0)
    mesh: Optional[TriangleMesh] = field(default=None, compare=False, repr=False)  # scaled, collision frame
    mu: float = 1.0
    mu2: float = 1.0
    rgba: Optional[Tuple[float, float, float, float]] = None  # the link's first visual material, for the window

    def world_points(self, segments: int = 32) -> np.ndarray:
        """(N, 3) world points whose convex hull encloses the shape; round parts are ``segments``-gons.

        Empty for a plane, which has no bounds.
        """
        angles = np.linspace(0.0, 2.0 * np.pi, segments, endpoint=False)
        circle = np.stack([np.cos(angles), np.sin(angles), np.zeros(segments)], axis=1)
        if self.kind == "sphere":  # rotation-invariant, so built straight in the world frame
            poles = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])
            return np.asarray(self.pose.position) + self.radius * np.concatenate([circle, poles])
        if self.kind == "box":
            signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
            local = signs * np.asarray(self.size) / 2.0
        elif self.kind == "cylinder":
            rim = self.radius * circle
            local = np.concatenate([rim + [0, 0, self.length / 2.0], rim - [0, 0, self.length / 2.0]])
        elif self.kind == "mesh":
            local = self.mesh.vertices
        else:
            return np.empty((0, 3))
        return local @ np.asarray(rotation_matrix(self.pose.orientation)).T + np.asarray(self.pose.position)

    def outline(self, segments: int = 32) -> Tuple[Tuple[float, float], ...]:
        """Top view: counter-clockwise convex polygon of the footprint in the world XY plane (() for a plane)."""
        return _convex_hull_2d(self.world_points(segments)[:, :2])

    def bounds(self) -> Tuple[Tuple[float, float, float], Tuple[float, float, float]]:
        """World axis-aligned bounding box (minimum corner, maximum corner); infinite for a plane."""
        points = self.world_points()
        if len(points) == 0:
            return (-np.inf,) * 3, (np.inf,) * 3
        return tuple(float(v) for v in points.min(axis=0)), tuple(float(v) for v in points.max(axis=0))


@dataclass(frozen=True)
class LinkDescription:
    name: str
    pose: Pose  # world frame
    mass: float  # 0 in a static model
    inertia: Tuple[float, float, float, float, float, float]  # ixx ixy ixz iyy iyz izz, inertial frame
    inertial_pose: Pose  # link frame
    collisions: Tuple[Shape, ...]


@dataclass(frozen=True)
class ModelDescription:
    name: str
    static: bool
    pose: Pose  # world frame
    links: Tuple[LinkDescription, ...]

    @property
    def shapes(self) -> Tuple[Shape, ...]:
        return tuple(shape for link in self.links for shape in link.collisions)


@dataclass(frozen=True)
class WorldDescription:
    name: str
    path: str
    physics: PhysicsConfig
    models: Tuple[ModelDescription, ...]

    @property
    def shapes(self) -> Tuple[Shape, ...]:
        """Every collision of every model, in the world frame."""
        return tuple(shape for model in self.models for shape in model.shapes)


@dataclass(frozen=True)
class LoadedWorld:
    physics: PhysicsConfig
    bodies: Dict[str, int]  # model name -> PyBullet body id
    shapes: Tuple[Shape, ...]  # the collisions that became PyBullet shapes
    # model name -> the body's centre-of-mass frame in the model frame; PyBullet reports base poses in it
    inertial_frames: Dict[str, Pose]

    def model_pose(self, client, name: str) -> Pose:
        """World pose of the model frame of ``name`` now."""
        position, orientation = client.getBasePositionAndOrientation(self.bodies[name])
        return compose(Pose(tuple(position), tuple(orientation)), inverse(self.inertial_frames[name]))


def world_lateral_friction(mu: float, mu2: float) -> float:
    """PyBullet ``lateralFriction`` for a world collision with SDF ``<ode><mu>``/``<mu2>``.

    ODE takes min(μa, μb) per contact; Bullet multiplies the two bodies' frictions. With the world side at
    min(μ, μ2, 1) the product equals ODE's value whenever the robot's μ is 1 (the SDF default) or the world's
    is at least 1 (the ground plane's 100) and the robot's at most 1. When both are below 1 the product is
    smaller than ODE's min. Bullet's friction is isotropic, so the smaller of μ and μ2 is used.
    """
    return min(mu, mu2, 1.0)


def default_model_path() -> List[str]:
    """Directories searched for ``model://NAME``: GAZEBO_MODEL_PATH, then this workspace's worlds/models."""
    directories = [entry for entry in os.environ.get("GAZEBO_MODEL_PATH", "").split(":") if entry]
    workspace_models = _workspace_models()
    if workspace_models:
        directories.append(workspace_models)
    return directories


def _workspace_models() -> Optional[str]:
    # The real path leads back to the source tree from a source checkout and from catkin's devel space
    # (its generated package __init__ extends __path__ to the sources). An install space has no repo root,
    # so ROS_PACKAGE_PATH is tried for mbot_gazebo, whose worlds/ links to the same folder.
    module = Path(os.path.realpath(__file__))  # <repo>/src/mbot_sim_bridge/src/mbot_sim_bridge/core/world.py
    candidates = [module.parents[5] / "worlds" / "models"] if len(module.parents) > 5 else []
    candidates += [Path(entry) / "mbot_gazebo" / "worlds" / "models"
                   for entry in os.environ.get("ROS_PACKAGE_PATH", "").split(":") if entry]
    return next((str(candidate) for candidate in candidates if candidate.is_dir()), None)


def parse_world(path: str, model_path: Optional[Sequence[str]] = None) -> WorldDescription:
    """Read a .world file; raise WorldError for a missing or malformed file, warn once for what is skipped."""
    return _WorldParser(default_model_path() if model_path is None else model_path).parse(str(path))


def load_world(client, description: WorldDescription) -> LoadedWorld:
    """Build one body per model of ``description`` in ``client`` (a BulletClient).

    Gravity and time step stay with the caller (the Engine applies ``description.physics``).
    """
    bodies, shapes, inertial_frames = {}, [], {}
    for model in description.models:
        collision_shapes = [(shape, _collision_shape(client, shape, concave=model.static)) for shape in model.shapes]
        collision_shapes = [(shape, index) for shape, index in collision_shapes if index is not None]
        if not collision_shapes:
            _log.debug("model '%s' has no collision shape; no body created", model.name)
            continue
        bodies[model.name], inertial_frames[model.name] = _create_body(client, model, collision_shapes)
        for index, (shape, _) in enumerate(collision_shapes):
            if shape.rgba is not None:  # only the simulator window shows it
                client.changeVisualShape(bodies[model.name], index, rgbaColor=shape.rgba)
        shapes.extend(shape for shape, _ in collision_shapes)
    return LoadedWorld(description.physics, bodies, tuple(shapes), inertial_frames)


def _collision_shape(client, shape: Shape, concave: bool) -> Optional[int]:
    if shape.kind == "box":
        return client.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[s / 2.0 for s in shape.size])
    if shape.kind == "cylinder":
        return client.createCollisionShape(pybullet.GEOM_CYLINDER, radius=shape.radius, height=shape.length)
    if shape.kind == "sphere":
        return client.createCollisionShape(pybullet.GEOM_SPHERE, radius=shape.radius)
    if shape.kind == "plane":
        return client.createCollisionShape(pybullet.GEOM_PLANE, planeNormal=shape.normal)
    vertices, triangles = shape.mesh.vertices, shape.mesh.triangles
    if len(vertices) > _BULLET_MAX_MESH_VERTICES or (concave and triangles.size > _BULLET_MAX_MESH_INDICES):
        warn_once(_log, f"{shape.mesh_path}: {len(vertices)} vertices and {len(triangles)} triangles exceed "
                        f"PyBullet's mesh limits ({_BULLET_MAX_MESH_VERTICES}, {_BULLET_MAX_MESH_INDICES // 3}); "
                        f"collision '{shape.name}' of model '{shape.model}' skipped")
        return None
    if concave:  # a triangle mesh, as ODE collides it, works in Bullet only for bodies that never move
        return client.createCollisionShape(pybullet.GEOM_MESH, vertices=vertices.tolist(),
                                           indices=triangles.ravel().tolist())
    return client.createCollisionShape(pybullet.GEOM_MESH, vertices=vertices.tolist())  # convex hull


def _create_body(client, model: ModelDescription, collision_shapes) -> Tuple[int, Pose]:
    world_to_model = inverse(model.pose)
    child_frames = [compose(world_to_model, shape.pose) for shape, _ in collision_shapes]
    mass, inertial_frame, moments = (0.0, IDENTITY, None) if model.static else _mass_properties(model)
    if not model.static and mass == 0.0:
        warn_once(_log, f"model '{model.name}' is not static but has no mass; PyBullet keeps it fixed")
    count = len(collision_shapes)
    body = client.createMultiBody(
        baseMass=mass, baseCollisionShapeIndex=-1, basePosition=model.pose.position,
        baseOrientation=model.pose.orientation, baseInertialFramePosition=inertial_frame.position,
        baseInertialFrameOrientation=inertial_frame.orientation,
        linkMasses=[0.0] * count, linkCollisionShapeIndices=[index for _, index in collision_shapes],
        linkVisualShapeIndices=[-1] * count, linkPositions=[frame.position for frame in child_frames],
        linkOrientations=[frame.orientation for frame in child_frames],
        linkInertialFramePositions=[IDENTITY.position] * count,
        linkInertialFrameOrientations=[IDENTITY.orientation] * count,
        linkParentIndices=[0] * count, linkJointTypes=[pybullet.JOINT_FIXED] * count,
        linkJointAxis=[(0.0, 0.0, 1.0)] * count)
    if moments is not None:
        client.changeDynamics(body, -1, localInertiaDiagonal=moments)
    for link_index, (shape, _) in enumerate(collision_shapes):
        client.changeDynamics(body, link_index, lateralFriction=world_lateral_friction(shape.mu, shape.mu2),
                              restitution=0.0)
    return body, inertial_frame


def _mass_properties(model: ModelDescription) -> Tuple[float, Pose, Optional[Tuple[float, float, float]]]:
    """Total mass, principal centre-of-mass frame (in the model frame) and principal moments of the welded links."""
    world_to_model = inverse(model.pose)
    frames = [compose(world_to_model, compose(link.pose, link.inertial_pose)) for link in model.links]
    masses = np.array([link.mass for link in model.links])
    total = float(masses.sum())
    if total <= 0.0:
        return 0.0, IDENTITY, None
    centres = np.array([frame.position for frame in frames])
    centre = masses @ centres / total
    inertia = np.zeros((3, 3))
    for link, frame, offset in zip(model.links, frames, centres - centre):
        ixx, ixy, ixz, iyy, iyz, izz = link.inertia
        rotation = np.array(rotation_matrix(frame.orientation))
        local = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        # Rotate into the model frame, then move to the common centre (parallel-axis theorem).
        inertia += rotation @ local @ rotation.T + link.mass * (offset @ offset * np.eye(3) - np.outer(offset, offset))
    moments, axes = np.linalg.eigh(inertia)
    if np.linalg.det(axes) < 0.0:
        axes[:, 2] = -axes[:, 2]
    return total, Pose(tuple(centre), _quaternion_from_matrix(axes)), tuple(float(m) for m in moments)


def _quaternion_from_matrix(matrix: np.ndarray) -> Tuple[float, float, float, float]:
    """Rotation matrix -> quaternion (x, y, z, w), branching on the largest component for accuracy."""
    m = matrix
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        s = 2.0 * np.sqrt(trace + 1.0)
        q = ((m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4.0)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = (s / 4.0, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s)
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = ((m[0, 1] + m[1, 0]) / s, s / 4.0, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s)
    else:
        s = 2.0 * np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = ((m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, s / 4.0, (m[1, 0] - m[0, 1]) / s)
    return tuple(float(v) for v in q)


def _convex_hull_2d(points: np.ndarray) -> Tuple[Tuple[float, float], ...]:
    """Andrew's monotone chain; counter-clockwise, no repeated first point."""
    # Micrometres: below that, PyBullet's single-precision transforms make straight edges look bent.
    unique = sorted({(float(x) + 0.0, float(y) + 0.0) for x, y in np.round(points, 6)})
    if len(unique) < 3:
        return tuple(unique)

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    def half(sequence):
        chain = []
        for point in sequence:
            while len(chain) >= 2 and cross(chain[-2], chain[-1], point) <= 0.0:
                chain.pop()
            chain.append(point)
        return chain[:-1]

    return tuple(half(unique) + half(reversed(unique)))


# --- SDF reading -------------------------------------------------------------------------------------------

class _Document(NamedTuple):
    path: str
    root: ET.Element
    lines: Dict[ET.Element, int]

    def where(self, element: Optional[ET.Element]) -> str:
        line = self.lines.get(element) if element is not None else None
        return f"{self.path}:{line}" if line else self.path


def _parse_xml(path: str, data: bytes) -> _Document:
    """ElementTree built through expat so that every element keeps its line number for messages."""
    builder = ET.TreeBuilder()
    parser = expat.ParserCreate()
    lines = {}

    def start(tag, attributes):
        lines[builder.start(tag, attributes)] = parser.CurrentLineNumber

    parser.StartElementHandler = start
    parser.EndElementHandler = builder.end
    parser.CharacterDataHandler = builder.data
    try:
        parser.Parse(data, True)
    except expat.ExpatError as error:
        raise WorldError(f"{path}:{error.lineno}: {expat.ErrorString(error.code)}") from None
    return _Document(path, builder.close(), lines)


class _ModelEntry(NamedTuple):
    """A model to build: inline, or from an <include> whose <name>, <pose> and <static> win."""
    element: ET.Element
    document: _Document
    name: str
    pose: Optional[ET.Element]
    pose_document: _Document
    static: Optional[bool]
    where: str  # the <model> or <include> in the including file, for messages


def _inline_model(element: ET.Element, document: _Document) -> _ModelEntry:
    return _ModelEntry(element, document, element.get("name", ""), element.find("pose"), document, None,
                       document.where(element))


class _Frames:
    """Named frames of one scope (the world or a model) for the SDF 1.7 ``relative_to`` (and 1.5 ``frame``)
    attribute, resolved on first use.

    A pose without the attribute is relative to a default frame: the scope itself for links, models and frames,
    the link for collisions. Unknown names and cycles warn and fall back to the scope frame.
    """

    def __init__(self, label: str, origin: Pose, own_names: Tuple[str, ...]):
        self.label = label
        self.origin = origin  # world pose of the scope frame
        self._own_names = own_names
        self._entries = {}  # name -> (pose element, document, default frame)
        self._poses = {}
        self._resolving = set()

    def add(self, name: str, pose: Optional[ET.Element], document: _Document, default: str = "") -> None:
        self._entries[name] = (pose, document, default)

    def resolve(self, pose: Optional[ET.Element], document: _Document, default: str = "") -> Pose:
        """World pose given by a <pose> element (None means identity) in this scope."""
        if pose is None:
            return self.frame(default, document, pose)
        frame = pose.get("relative_to") or pose.get("frame") or default
        return compose(self.frame(frame, document, pose), _pose(pose, document))

    def frame(self, name: str, document: _Document, referrer: Optional[ET.Element]) -> Pose:
        if name in self._own_names:
            return self.origin
        if name not in self._poses:
            if name not in self._entries or name in self._resolving:
                problem = "is part of a cycle" if name in self._resolving else "does not exist"
                warn_once(_log, f"{document.where(referrer)}: frame '{name}' {problem} in {self.label}; "
                                f"using the {self.label} frame")
                return self.origin
            self._resolving.add(name)
            self._poses[name] = self.resolve(*self._entries[name])
            self._resolving.discard(name)
        return self._poses[name]


class _WorldParser:
    def __init__(self, model_path: Sequence[str]):
        self._model_path = [str(directory) for directory in model_path]
        self._documents = {}
        self._meshes = {}

    def parse(self, path: str) -> WorldDescription:
        document = self._read(path)
        world = document.root.find("world")
        if document.root.tag != "sdf" or world is None:
            raise WorldError(f"{path}: not an SDF world: no <sdf><world> element")
        self._check_version(document)
        scope = _Frames(f"world '{world.get('name', 'default')}'", IDENTITY, ("", "world"))
        entries = []
        for child in world:
            if child.tag == "model":
                entries.append(_inline_model(child, document))
            elif child.tag == "include":
                entries.extend(self._include(child, document))
            elif child.tag == "frame":
                scope.add(child.get("name", ""), child.find("pose"), document, child.get("attached_to", ""))
            elif child.tag in _WORLD_UNSUPPORTED:
                self._warn_unsupported(document, child)
            elif child.tag not in _WORLD_IGNORED:
                self._warn_unknown(document, child, "world")
        unique = {}
        for entry in entries:
            if entry.name in unique:
                warn_once(_log, f"{entry.where}: a model named '{entry.name}' already exists; this one is skipped")
                continue
            unique[entry.name] = entry
            scope.add(entry.name, entry.pose, entry.pose_document)
        models = tuple(self._model(entry, scope) for entry in unique.values())
        return WorldDescription(world.get("name", "default"), path, self._physics(document, world), models)

    # Files ---------------------------------------------------------------------------------------------

    def _read(self, path: str) -> _Document:
        if path not in self._documents:
            try:
                with open(path, "rb") as stream:
                    data = stream.read()
            except OSError as error:
                raise WorldError(f"{path}: cannot read: {error.strerror or error}") from None
            self._documents[path] = _parse_xml(path, data)
        return self._documents[path]

    def _check_version(self, document: _Document) -> None:
        version = _version(document.root.get("version", ""))
        if version > SDF_VERSION:
            warn_once(_log, f"{document.path}: SDF {document.root.get('version')} is newer than "
                            f"{'.'.join(map(str, SDF_VERSION))}, the newest read here")

    def _find_model_directory(self, name: str) -> Optional[str]:
        for directory in self._model_path:
            candidate = os.path.join(directory, name)
            if any(os.path.isfile(os.path.join(candidate, manifest)) for manifest in ("model.config", "manifest.xml")):
                return candidate
        return None

    def _model_document(self, uri: str, document: _Document) -> Optional[_Document]:
        """The SDF document an <include><uri> names, or None when it cannot be found."""
        if uri.startswith("model://"):
            name = uri[len("model://"):].strip("/")
            directory = self._find_model_directory(name)
            if directory is None:
                if name not in _BUILTIN_MODELS:
                    return None
                key = f"<built-in model://{name}>"
                if key not in self._documents:
                    self._documents[key] = _parse_xml(key, _BUILTIN_MODELS[name].encode())
                return self._documents[key]
        else:
            directory = self._local_path(uri, document)
            if directory is None:
                return None
            if os.path.isfile(directory):
                return self._read(directory)
        return self._read(self._best_model_file(directory))

    def _best_model_file(self, directory: str) -> str:
        """model.config lists one model file per SDF version: take the newest this reader follows."""
        config_path = os.path.join(directory, "model.config")
        if not os.path.isfile(config_path):
            config_path = os.path.join(directory, "manifest.xml")
        config = self._read(config_path)
        choices = [(_version(entry.get("version", "")), (entry.text or "").strip())
                   for entry in config.root.iter("sdf") if (entry.text or "").strip()]
        if not choices:
            raise WorldError(f"{config_path}: no <sdf> entry names a model file")
        supported = [choice for choice in choices if choice[0] <= SDF_VERSION]
        version, name = max(supported) if supported else min(choices)
        return os.path.join(directory, name)

    def _local_path(self, uri: str, document: _Document) -> Optional[str]:
        """file:// or plain paths: absolute, else relative to the including file, else to GAZEBO_RESOURCE_PATH."""
        if "://" in uri and not uri.startswith("file://"):
            return None
        path = uri[len("file://"):] if uri.startswith("file://") else uri
        bases = [os.path.dirname(os.path.abspath(document.path))]
        bases += [entry for entry in os.environ.get("GAZEBO_RESOURCE_PATH", "").split(":") if entry]
        candidates = [path] if os.path.isabs(path) else [os.path.join(base, path) for base in bases]
        return next((candidate for candidate in candidates if os.path.exists(candidate)), None)

    def _mesh_path(self, uri: str, document: _Document) -> Optional[str]:
        if uri.startswith("model://"):
            name, _, rest = uri[len("model://"):].partition("/")
            directory = self._find_model_directory(name)
            return os.path.join(directory, rest) if directory else None
        return self._local_path(uri, document)

    def _mesh(self, path: str) -> Optional[TriangleMesh]:
        if path not in self._meshes:
            try:
                self._meshes[path] = load_mesh(path)
            except ModelError as error:
                warn_once(_log, f"{error}; collisions using it are skipped")
                self._meshes[path] = None
        return self._meshes[path]

    # Elements ------------------------------------------------------------------------------------------

    def _include(self, include: ET.Element, document: _Document) -> List[_ModelEntry]:
        uri = _text(include, "uri")
        if not uri:
            warn_once(_log, f"{document.where(include)}: <include> without <uri>; skipped")
            return []
        model_document = self._model_document(uri, document)
        if model_document is None:
            searched = ":".join(self._model_path) or "(empty)"
            warn_once(_log, f"{document.where(include)}: cannot find '{uri}' (model path: {searched}); skipped")
            return []
        self._check_version(model_document)
        model = model_document.root.find("model")
        if model is None:
            if model_document.root.find("light") is None:
                warn_once(_log, f"{model_document.path}: no <model> to include for '{uri}'; skipped")
            return []
        static = include.find("static")
        pose = include.find("pose")
        return [_ModelEntry(model, model_document, _text(include, "name") or model.get("name", ""),
                            pose if pose is not None else model.find("pose"),
                            document if pose is not None else model_document,
                            None if static is None else _bool(static, document), document.where(include))]

    def _model(self, entry: _ModelEntry, parent: _Frames) -> ModelDescription:
        static = entry.static
        if static is None:
            static = _bool(entry.element.find("static"), entry.document, default=False)
        scope = _Frames(f"model '{entry.name}'", parent.frame(entry.name, entry.document, entry.element),
                        ("", "__model__"))
        links = self._links(entry, scope, static, entry.name, prefix="", expanding=(entry.element,))
        return ModelDescription(entry.name, static, scope.origin, tuple(links))

    def _links(self, entry: _ModelEntry, scope: _Frames, static: bool, model: str, prefix: str,
               expanding: Tuple[ET.Element, ...]) -> List[LinkDescription]:
        """Links of a model and of the models nested in it, flattened; ``expanding`` are the <model>s on the way
        (an included file is read once, so including a model inside itself meets the same element again)."""
        element, document = entry.element, entry.document
        nested = []
        for child in element:
            if child.tag in ("link", "frame"):
                default = child.get("attached_to", "") if child.tag == "frame" else ""
                scope.add(child.get("name", ""), child.find("pose"), document, default)
            elif child.tag == "model":
                nested.append(_inline_model(child, document))
            elif child.tag == "include":
                nested.extend(self._include(child, document))
            elif child.tag in _MODEL_UNSUPPORTED:
                self._warn_unsupported(document, child)
            elif child.tag not in _MODEL_IGNORED:
                self._warn_unknown(document, child, "model")
        for inner in nested:
            scope.add(inner.name, inner.pose, inner.pose_document)
        links = [self._link(link, document, scope, static, model, prefix) for link in element.findall("link")]
        for inner in nested:
            if inner.element in expanding:
                raise WorldError(f"{inner.where}: {inner.document.path} includes itself")
            inner_scope = _Frames(f"model '{inner.name}'", scope.frame(inner.name, document, inner.element),
                                  ("", "__model__"))
            links += self._links(inner, inner_scope, static, model, f"{prefix}{inner.name}::",
                                 expanding + (inner.element,))
        return links

    def _link(self, link: ET.Element, document: _Document, scope: _Frames, static: bool, model: str,
              prefix: str) -> LinkDescription:
        name = link.get("name", "")
        for tag, required in _LINK_DEFAULTS_REQUIRED.items():
            if _bool(link.find(tag), document, default=required) != required:
                warn_once(_log, f"{document.where(link.find(tag))}: <{tag}>{str(not required).lower()}</{tag}> "
                                f"in link '{name}' of model '{model}' is not simulated")
        for child in link:
            if child.tag not in _LINK_IGNORED and child.tag not in _LINK_DEFAULTS_REQUIRED and child.tag != "collision":
                self._warn_unknown(document, child, "link")
        pose = scope.frame(name, document, link)
        mass, inertia, inertial_pose = self._inertial(link.find("inertial"), document, static)
        visual_materials = (sdf_material_rgba(visual.find("material")) for visual in link.findall("visual"))
        rgba = next((colour for colour in visual_materials if colour is not None), None)
        collisions = (self._collision(collision, document, scope, name, static, model, prefix + name, rgba)
                      for collision in link.findall("collision"))
        return LinkDescription(prefix + name, pose, mass, inertia, inertial_pose,
                               tuple(shape for shape in collisions if shape is not None))

    @staticmethod
    def _inertial(inertial: Optional[ET.Element], document: _Document, static: bool):
        """Mass, inertia and its pose; SDF defaults are mass 1 and unit moments, a static model weighs nothing."""
        if static:
            return 0.0, (0.0,) * 6, IDENTITY
        if inertial is None:
            return 1.0, (1.0, 0.0, 0.0, 1.0, 0.0, 1.0), IDENTITY
        mass = _number(inertial, "mass", document, 1.0)
        tensor = inertial.find("inertia")
        defaults = {"ixx": 1.0, "ixy": 0.0, "ixz": 0.0, "iyy": 1.0, "iyz": 0.0, "izz": 1.0}
        inertia = tuple(_number(tensor, key, document, value) if tensor is not None else value
                        for key, value in defaults.items())
        pose = inertial.find("pose")
        return mass, inertia, IDENTITY if pose is None else _pose(pose, document)

    def _collision(self, collision: ET.Element, document: _Document, scope: _Frames, link: str, static: bool,
                   model: str, scoped_link: str, rgba) -> Optional[Shape]:
        name = collision.get("name", "")
        label = f"collision '{name}' of model '{model}'"
        geometry = collision.find("geometry")
        kind_element = next(iter(geometry), None) if geometry is not None else None
        if kind_element is None or kind_element.tag == "empty":
            return None
        kind = kind_element.tag
        if kind not in SHAPE_KINDS:
            why = "is not supported" if kind in _GEOMETRY_UNSUPPORTED else "is not an SDF geometry"
            warn_once(_log, f"{document.where(kind_element)}: <{kind}> {why}; {label} skipped")
            return None
        pose = scope.resolve(collision.find("pose"), document, default=link)
        friction = collision.find("surface/friction/ode")
        common = dict(model=model, link=scoped_link, name=name, kind=kind, pose=pose, rgba=rgba,
                      mu=_number(friction, "mu", document, 1.0) if friction is not None else 1.0,
                      mu2=_number(friction, "mu2", document, 1.0) if friction is not None else 1.0)
        if kind == "box":
            return Shape(size=_vector(kind_element, "size", document, (1.0, 1.0, 1.0), positive=True), **common)
        if kind == "sphere":
            radius = _number(kind_element, "radius", document, 1.0, positive=True)
            return Shape(size=(2.0 * radius,) * 3, radius=radius, **common)
        if kind == "cylinder":
            radius = _number(kind_element, "radius", document, 1.0, positive=True)
            length = _number(kind_element, "length", document, 1.0, positive=True)
            return Shape(size=(2.0 * radius, 2.0 * radius, length), radius=radius, length=length, **common)
        if kind == "plane":
            if not static:
                warn_once(_log, f"{document.where(kind_element)}: a plane only collides in a static model; "
                                f"{label} skipped")
                return None
            normal = np.asarray(_vector(kind_element, "normal", document, (0.0, 0.0, 1.0)))
            if not np.linalg.norm(normal) > 0.0:
                raise WorldError(f"{document.where(kind_element)}: <plane><normal> must not be zero")
            width, height = _vector(kind_element, "size", document, (1.0, 1.0), count=2)
            return Shape(size=(width, height, 0.0), normal=tuple(normal / np.linalg.norm(normal)), **common)
        return self._mesh_shape(kind_element, document, label, common)

    def _mesh_shape(self, mesh: ET.Element, document: _Document, label: str, common: dict) -> Optional[Shape]:
        uri = _text(mesh, "uri")
        path = self._mesh_path(uri, document) if uri else None
        if path is None:
            warn_once(_log, f"{document.where(mesh)}: cannot find mesh '{uri}'; {label} skipped")
            return None
        if mesh.find("submesh") is not None:
            warn_once(_log, f"{document.where(mesh.find('submesh'))}: <submesh> is not supported; "
                            f"{label} uses the whole mesh")
        triangles = self._mesh(path)
        if triangles is None:
            return None
        scale = _vector(mesh, "scale", document, (1.0, 1.0, 1.0))
        scaled = triangles.scaled(scale)
        size = tuple(float(v) for v in scaled.vertices.max(axis=0) - scaled.vertices.min(axis=0))
        return Shape(size=size, mesh_path=path, mesh_scale=scale, mesh=scaled, **common)

    def _physics(self, document: _Document, world: ET.Element) -> PhysicsConfig:
        candidates = world.findall("physics")
        chosen = next((p for p in candidates if _bool_attribute(p, "default")), candidates[0] if candidates else None)
        defaults = PhysicsConfig()
        values = {}
        if chosen is not None:
            values = dict(
                max_step_size=_number(chosen, "max_step_size", document, defaults.max_step_size, positive=True),
                real_time_factor=_number(chosen, "real_time_factor", document, defaults.real_time_factor),
                real_time_update_rate=_number(chosen, "real_time_update_rate", document,
                                              defaults.real_time_update_rate))
        # SDF 1.6 moved <gravity> from <physics> to <world>; files of either age are read.
        for parent in (world, chosen):
            if parent is not None and parent.find("gravity") is not None:
                values["gravity"] = _vector(parent, "gravity", document, defaults.gravity)
                break
        return PhysicsConfig(**values)

    @staticmethod
    def _warn_unsupported(document: _Document, element: ET.Element) -> None:
        what = f"<{element.tag}" + (f" name='{element.get('name')}'" if element.get("name") else "") + ">"
        if element.get("filename"):
            what += f" ({element.get('filename')})"
        effect = "the model's links move as one rigid body" if element.tag == "joint" else "ignored"
        warn_once(_log, f"{document.where(element)}: {what} is not simulated; {effect}")

    @staticmethod
    def _warn_unknown(document: _Document, element: ET.Element, parent: str) -> None:
        warn_once(_log, f"{document.where(element)}: <{element.tag}> is not an SDF <{parent}> element; ignored")


# --- Values -------------------------------------------------------------------------------------------------

def _version(text: str) -> Tuple[int, ...]:
    try:
        return tuple(int(part) for part in text.split("."))
    except ValueError:
        return (0,)


def _text(parent: ET.Element, tag: str) -> str:
    element = parent.find(tag)
    return (element.text or "").strip() if element is not None else ""


def _floats(element: ET.Element, document: _Document, count: int) -> Tuple[float, ...]:
    words = (element.text or "").split()
    try:
        values = tuple(float(word) for word in words)
    except ValueError:
        values = ()
    if len(values) != count or not all(np.isfinite(values)):
        raise WorldError(f"{document.where(element)}: <{element.tag}> needs {count} numbers, "
                         f"got '{(element.text or '').strip()}'")
    return values


def _number(parent: ET.Element, tag: str, document: _Document, default: float, positive: bool = False) -> float:
    element = parent.find(tag)
    if element is None:
        return default
    value = _floats(element, document, 1)[0]
    if positive and value <= 0.0:
        raise WorldError(f"{document.where(element)}: <{tag}> must be positive, got {value:g}")
    return value


def _vector(parent: ET.Element, tag: str, document: _Document, default: Tuple[float, ...], count: int = 3,
            positive: bool = False) -> Tuple[float, ...]:
    element = parent.find(tag)
    if element is None:
        return default
    values = _floats(element, document, count)
    if positive and min(values) <= 0.0:
        raise WorldError(f"{document.where(element)}: <{tag}> must be positive, got '{element.text.strip()}'")
    return values


def _pose(element: ET.Element, document: _Document) -> Pose:
    """``x y z roll pitch yaw``, rotation Rz·Ry·Rx like URDF; empty text is the identity."""
    if not (element.text or "").strip():
        return IDENTITY
    values = _floats(element, document, 6)
    return pose_from_xyz_rpy(values[:3], values[3:])


def _bool(element: Optional[ET.Element], document: _Document, default: bool = False) -> bool:
    if element is None:
        return default
    text = (element.text or "").strip().lower()
    if text not in ("true", "false", "1", "0"):
        raise WorldError(f"{document.where(element)}: <{element.tag}> must be true, false, 1 or 0, got '{text}'")
    return text in ("true", "1")


def _bool_attribute(element: ET.Element, name: str) -> bool:
    return element.get(name, "").strip().lower() in ("true", "1")
