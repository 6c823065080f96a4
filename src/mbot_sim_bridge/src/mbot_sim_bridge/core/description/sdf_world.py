"""SDF worlds: ``.world`` file -> descriptions of models, links and collision shapes, read as Gazebo 11 reads them.

``parse_world`` is plain XML work (sdformat 1.4 to 1.7): physics, gravity, models inline or through
``<include>``, links, collisions, friction, poses composed world_T_model · model_T_link · link_T_collision.
The result is a ``world_description.WorldDescription``; ``world_bodies.load_world`` turns its rigid models into
PyBullet bodies; a model with joints, sensors or plugins is read as a robot instead (``sdf_model``), which the
simulation spawns as URDF robots are. Visuals, lights, scene and GUI are left out; physics-relevant elements
that are not simulated (unknown geometry) warn once each, naming file and line. The world's own plugins are
kept for the Simulation, which builds them.
"""
import dataclasses
import os
import xml.etree.ElementTree as ET
from typing import List, NamedTuple, Optional, Sequence, Tuple

import numpy as np

from ..errors import ModelError, WorldError
from ..geometry import IDENTITY, Pose, compose
from ..joints.model_configuration import requested_positions
from ..log import get_logger, warn_once
from ..physics_properties import MAX_GRAVITY, MAX_TIME_STEP, MAX_UPDATE_RATE, MIN_TIME_STEP
from .materials import sdf_material_rgba
from .mesh import TriangleMesh, load_mesh
from .model_path import MODEL_MANIFESTS, default_model_path, find_model_directory
from .sdf_model import ModelLevel, SdfToUrdf, is_articulated, state_joint_positions
from .world_description import (SHAPE_KINDS, ArticulatedModel, LinkDescription, ModelDescription, PhysicsConfig, Shape,
                                WorldDescription)
from ..xml_values import (MAX_SHAPE_SIZE, XmlDocument, check_range, parse_xml, read_bool, read_bool_attribute,
                          read_number, read_pose, read_text, read_vector, read_xml_file)

_log = get_logger(__name__)

SDF_VERSION = (1, 7)  # newest spec followed here; model.config picks the best model file up to it
NEWEST_SDF_VERSION = (1, 12)  # the newest there is (sdformat 15): a file of a later one is refused

# Gazebo ships these two, so worlds include them without shipping them; the model path still wins.
_BUILTIN_MODELS = {
    "ground_plane": """<sdf version="1.6"><model name="ground_plane"><static>true</static>
        <link name="link"><collision name="collision">
          <geometry><plane><normal>0 0 1</normal><size>100 100</size></plane></geometry>
          <surface><friction><ode><mu>100</mu><mu2>50</mu2></ode></friction></surface>
        </collision></link></model></sdf>""",
    "sun": """<sdf version="1.6"><light type="directional" name="sun"/></sdf>""",
}
BUILTIN_MODEL_NAMES = tuple(_BUILTIN_MODELS)

# <physics><ode><constraints> read, each with the largest value accepted: erp is a fraction; beyond these a
# correcting velocity would throw bodies and a surface layer sink them (in Gazebo, and in a saved world).
_CONSTRAINT_LIMITS = {"erp": 1.0, "contact_max_correcting_vel": 1.0e4, "contact_surface_layer": 0.1}
# Children read elsewhere or without effect on contacts pass silently; unsupported and unknown ones warn once.
# A world's <plugin>s are built by the Simulation (WorldDescription.plugins), which says which it lacks.
_WORLD_IGNORED = {"audio", "wind", "gravity", "magnetic_field", "atmosphere", "gui", "physics", "scene", "light",
                  "spherical_coordinates", "state", "frame", "road", "plugin"}
_WORLD_UNSUPPORTED = {"actor", "population"}
_MODEL_IGNORED = {"static", "pose", "self_collide", "allow_auto_disable", "enable_wind", "frame"}
_MODEL_UNSUPPORTED = {"gripper"}
_MODEL_ARTICULATION = {"joint", "plugin"}  # such a model is simulated as a robot (sdf_model)
_LINK_IGNORED = {"pose", "inertial", "visual", "sensor", "self_collide", "enable_wind", "must_be_base_link",
                 "velocity_decay", "frame", "projector", "audio_sink", "audio_source", "battery", "light",
                 "particle_emitter"}
_LINK_DEFAULTS_REQUIRED = {"gravity": True, "kinematic": False}  # other values change the motion
# A dynamic link's mass (kg) and principal moments (kg m^2): the upper ends as the URDF checks' (robot_model.py).
_MASS_RANGE = (1e-6, 1e9)
_MOMENT_RANGE = (1e-12, 1e9)
_GEOMETRY_UNSUPPORTED = {"heightmap", "image", "polyline", "capsule", "ellipsoid"}


def parse_world(path: str, model_path: Optional[Sequence[str]] = None) -> WorldDescription:
    """Read a .world file; raise WorldError for a missing or malformed file, warn once for what is skipped."""
    return _WorldParser(default_model_path() if model_path is None else model_path).parse(str(path))


# --- SDF reading -------------------------------------------------------------------------------------------

class _ModelEntry(NamedTuple):
    """A model to build: inline, or from an <include> whose <name>, <pose> and <static> win."""
    element: ET.Element
    document: XmlDocument
    name: str
    pose: Optional[ET.Element]
    pose_document: XmlDocument
    static: Optional[bool]
    where: str  # the <model> or <include> in the including file, for messages
    source: ET.Element  # that <model> or <include>


def _inline_model(element: ET.Element, document: XmlDocument) -> _ModelEntry:
    return _ModelEntry(element, document, element.get("name", ""), element.find("pose"), document, None,
                       document.where(element), element)


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

    def add(self, name: str, pose: Optional[ET.Element], document: XmlDocument, default: str = "") -> None:
        self._entries[name] = (pose, document, default)

    def resolve(self, pose: Optional[ET.Element], document: XmlDocument, default: str = "") -> Pose:
        """World pose given by a <pose> element (None means identity) in this scope."""
        if pose is None:
            return self.frame(default, document, pose)
        frame = pose.get("relative_to") or pose.get("frame") or default
        return compose(self.frame(frame, document, pose), read_pose(pose, document))

    def frame(self, name: str, document: XmlDocument, referrer: Optional[ET.Element]) -> Pose:
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
        self._left_out = []

    def parse(self, path: str) -> WorldDescription:
        document = self._read(path)
        world = document.root.find("world")
        if document.root.tag != "sdf" or world is None:
            raise WorldError(f"{path}: not an SDF world: no <sdf><world> element")
        worlds = document.root.findall("world")
        if len(worlds) > 1:
            raise WorldError(f"{document.where(worlds[1])}: a second <world>; a file holds one (Gazebo would simulate "
                             "the first, however empty)")
        self._check_version(document)
        scope = _Frames(f"world '{world.get('name', 'default')}'", IDENTITY, ("", "world"))
        entries, others = [], []
        for child in world:
            if child.tag == "model":
                entries.append(_inline_model(child, document))
            elif child.tag == "include":
                included = self._include(child, document)
                entries.extend(included)
                if not included:  # a light such as model://sun, or a model not found here
                    others.append(child)
            elif child.tag == "frame":
                scope.add(child.get("name", ""), child.find("pose"), document, child.get("attached_to", ""))
            elif child.tag == "plugin":
                _check_plugin(child, document, f"world '{world.get('name', 'default')}'")
            elif child.tag in _WORLD_UNSUPPORTED:
                self._warn_unsupported(document, child)
            elif child.tag not in _WORLD_IGNORED:
                self._warn_unknown(document, child, "world")
            if child.tag not in ("model", "include", "frame", "physics", "gravity", "state"):
                others.append(child)
        unique = {}
        for entry in entries:
            if entry.name in unique:
                warn_once(_log, f"{entry.where}: a model named '{entry.name}' already exists; this one is skipped")
                continue
            unique[entry.name] = entry
            scope.add(entry.name, entry.pose, entry.pose_document)
        models = [self._model(entry, scope) for entry in unique.values()]
        state = world.find("state")
        if state is not None:
            models = [_with_state(model, state, document) if isinstance(model, ArticulatedModel) else model
                      for model in models]
        return WorldDescription(world.get("name", "default"), path, self._physics(document, world),
                                tuple(model for model in models if isinstance(model, ModelDescription)),
                                tuple(others),
                                tuple(model for model in models if isinstance(model, ArticulatedModel)),
                                tuple(self._left_out))

    # Files ---------------------------------------------------------------------------------------------

    def _read(self, path: str) -> XmlDocument:
        if path not in self._documents:
            self._documents[path] = read_xml_file(path, WorldError)
        return self._documents[path]

    def _check_version(self, document: XmlDocument) -> None:
        version = _version(document.root.get("version", ""))
        if document.root.get("version") is not None and not (1, 0) <= version <= NEWEST_SDF_VERSION:
            raise document.fail(document.root, f"<sdf version=\"{document.root.get('version', '')}\"> is not an SDF "
                                               f"version: they run from 1.0 to "
                                               f"{'.'.join(map(str, NEWEST_SDF_VERSION))}")
        if version > SDF_VERSION:
            warn_once(_log, f"{document.path}: SDF {document.root.get('version')} is newer than "
                            f"{'.'.join(map(str, SDF_VERSION))}, the newest read here")

    def _model_document(self, uri: str, document: XmlDocument) -> Optional[XmlDocument]:
        """The SDF document an <include><uri> names, or None when it cannot be found."""
        if uri.startswith("model://"):
            name = uri[len("model://"):].strip("/")
            directory = find_model_directory(name, self._model_path)
            if directory is None:
                if name not in _BUILTIN_MODELS:
                    return None
                key = f"<built-in model://{name}>"
                if key not in self._documents:
                    self._documents[key] = parse_xml(_BUILTIN_MODELS[name].encode(), key, WorldError)
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
        config_path = next((os.path.join(directory, manifest) for manifest in MODEL_MANIFESTS
                            if os.path.isfile(os.path.join(directory, manifest))),
                           os.path.join(directory, "model.config"))
        config = self._read(config_path)
        choices = [(_version(entry.get("version", "")), (entry.text or "").strip())
                   for entry in config.root.iter("sdf") if (entry.text or "").strip()]
        if not choices:
            raise WorldError(f"{config_path}: no <sdf> entry names a model file")
        supported = [choice for choice in choices if choice[0] <= SDF_VERSION]
        version, name = max(supported) if supported else min(choices)
        return os.path.join(directory, name)

    def _local_path(self, uri: str, document: XmlDocument) -> Optional[str]:
        """file:// or plain paths: absolute, else relative to the including file, else to GAZEBO_RESOURCE_PATH."""
        if "://" in uri and not uri.startswith("file://"):
            return None
        path = uri[len("file://"):] if uri.startswith("file://") else uri
        bases = [os.path.dirname(os.path.abspath(document.path))]
        bases += [entry for entry in os.environ.get("GAZEBO_RESOURCE_PATH", "").split(":") if entry]
        candidates = [path] if os.path.isabs(path) else [os.path.join(base, path) for base in bases]
        return next((candidate for candidate in candidates if os.path.exists(candidate)), None)

    def _mesh_path(self, uri: str, document: XmlDocument) -> Optional[str]:
        if uri.startswith("model://"):
            name, _, rest = uri[len("model://"):].partition("/")
            directory = find_model_directory(name, self._model_path)
            return os.path.join(directory, rest) if directory else None
        return self._local_path(uri, document)

    def _mesh(self, path: str) -> Optional[TriangleMesh]:
        if path not in self._meshes:
            try:
                self._meshes[path] = load_mesh(path)
            except ModelError as error:
                self._leave_out(f"{error}; collisions using it are skipped")
                self._meshes[path] = None
        return self._meshes[path]

    def _leave_out(self, message: str) -> None:
        """Warn once that a file the world names is not simulated, and keep the reason (WorldDescription.left_out)."""
        warn_once(_log, message)
        self._left_out.append(message)

    # Elements ------------------------------------------------------------------------------------------

    def _include(self, include: ET.Element, document: XmlDocument) -> List[_ModelEntry]:
        uri = read_text(include, "uri")
        if not uri:
            warn_once(_log, f"{document.where(include)}: <include> without <uri>; skipped")
            return []
        model_document = self._model_document(uri, document)
        if model_document is None:
            searched = ":".join(self._model_path) or "(empty)"
            self._leave_out(f"{document.where(include)}: cannot find '{uri}' (model path: {searched}); skipped")
            return []
        self._check_version(model_document)
        model = model_document.root.find("model")
        if model is None:
            if model_document.root.find("light") is None:
                warn_once(_log, f"{model_document.path}: no <model> to include for '{uri}'; skipped")
            return []
        static = include.find("static")
        pose = include.find("pose")
        return [_ModelEntry(model, model_document, read_text(include, "name") or model.get("name", ""),
                            pose if pose is not None else model.find("pose"),
                            document if pose is not None else model_document,
                            None if static is None else read_bool(static, document), document.where(include),
                            include)]

    def _model(self, entry: _ModelEntry, parent: _Frames):
        """A ModelDescription (a rigid model), or an ArticulatedModel for one with joints, sensors or plugins."""
        static = entry.static
        if static is None:
            static = read_bool(entry.element.find("static"), entry.document, default=False)
        scope = _Frames(f"model '{entry.name}'", parent.frame(entry.name, entry.document, entry.element),
                        ("", "__model__"))
        levels = self._levels(entry, scope, prefix="", expanding=(entry.element,))
        # SDF 1.6 lets an <include> add plugins to the model it includes.
        added_plugins = entry.source.findall("plugin") if entry.source.tag == "include" else []
        if is_articulated(levels) or added_plugins:
            converted = SdfToUrdf(entry.name, entry.where, scope.origin, static, levels, self._mesh_path,
                                  self._inertial, self._check_link, added_plugins).build()
            return ArticulatedModel(entry.name, static, scope.origin, converted.robot, converted.root_in_model,
                                    entry.source)
        links = [self._link(link, level.document, level.frames, static, entry.name, level.prefix)
                 for level in levels for link in level.element.findall("link")]
        return ModelDescription(entry.name, static, scope.origin, tuple(links), entry.source)

    def _levels(self, entry: _ModelEntry, scope: _Frames, prefix: str,
                expanding: Tuple[ET.Element, ...]) -> List[ModelLevel]:
        """A model and the models nested in it, with their frames; ``expanding`` are the <model>s on the way
        (an included file is read once, so including a model inside itself meets the same element again)."""
        element, document = entry.element, entry.document
        nested = []
        _check_link_names(element, document, entry.name)
        for plugin in element.findall("plugin") + element.findall("link/sensor/plugin"):
            _check_plugin(plugin, document, f"model '{entry.name}'")
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
            elif child.tag not in _MODEL_IGNORED and child.tag not in _MODEL_ARTICULATION:
                self._warn_unknown(document, child, "model")
        for inner in nested:
            scope.add(inner.name, inner.pose, inner.pose_document)
        levels = [ModelLevel(element, document, scope, prefix)]
        for inner in nested:
            if inner.element in expanding:
                raise WorldError(f"{inner.where}: {inner.document.path} includes itself")
            inner_scope = _Frames(f"model '{inner.name}'", scope.frame(inner.name, document, inner.element),
                                  ("", "__model__"))
            levels += self._levels(inner, inner_scope, f"{prefix}{inner.name}::", expanding + (inner.element,))
        return levels

    @classmethod
    def _check_link(cls, link: ET.Element, document: XmlDocument, model: str) -> None:
        """Warn once for what a link has that is not simulated (both for rigid models and those with joints)."""
        name = link.get("name", "")
        for tag, required in _LINK_DEFAULTS_REQUIRED.items():
            if read_bool(link.find(tag), document, default=required) != required:
                warn_once(_log, f"{document.where(link.find(tag))}: <{tag}>{str(not required).lower()}</{tag}> "
                                f"in link '{name}' of model '{model}' is not simulated")
        for child in link:
            if child.tag not in _LINK_IGNORED and child.tag not in _LINK_DEFAULTS_REQUIRED and child.tag != "collision":
                cls._warn_unknown(document, child, "link")

    def _link(self, link: ET.Element, document: XmlDocument, scope: _Frames, static: bool, model: str,
              prefix: str) -> LinkDescription:
        name = link.get("name", "")
        self._check_link(link, document, model)
        pose = scope.frame(name, document, link)
        mass, inertia, inertial_pose = self._inertial(link.find("inertial"), document, static,
                                                      f"link '{name}' of model '{model}'")
        visual_materials = (sdf_material_rgba(visual.find("material")) for visual in link.findall("visual"))
        rgba = next((colour for colour in visual_materials if colour is not None), None)
        collisions = (self._collision(collision, document, scope, name, static, model, prefix + name, rgba)
                      for collision in link.findall("collision"))
        return LinkDescription(prefix + name, pose, mass, inertia, inertial_pose,
                               tuple(shape for shape in collisions if shape is not None))

    @staticmethod
    def _inertial(inertial: Optional[ET.Element], document: XmlDocument, static: bool, label: str):
        """Mass, inertia and its pose; SDF defaults are mass 1 and unit moments, a static model weighs nothing.

        As sdformat's MassMatrix3::IsValid, a dynamic link needs a positive mass and principal moments that are
        positive and satisfy the triangle inequality; beyond that, Bullet's solver turned a mass or moment far
        from ``_MASS_RANGE``/``_MOMENT_RANGE`` NaN, so those are refused too."""
        if static:
            return 0.0, (0.0,) * 6, IDENTITY
        if inertial is None:
            return 1.0, (1.0, 0.0, 0.0, 1.0, 0.0, 1.0), IDENTITY

        def number(parent: ET.Element, tag: str, default: float, minimum: float, maximum: float) -> float:
            value = read_number(parent, tag, document, default)
            try:
                check_range(value, minimum, maximum)
            except ValueError as problem:
                raise document.fail(parent.find(tag), f"{label}: <{tag}>: {problem}") from None
            return value
        mass = number(inertial, "mass", 1.0, *_MASS_RANGE)
        tensor = inertial.find("inertia")
        defaults = {"ixx": 1.0, "ixy": 0.0, "ixz": 0.0, "iyy": 1.0, "iyz": 0.0, "izz": 1.0}
        inertia = tuple(number(tensor, key, value, -_MOMENT_RANGE[1], _MOMENT_RANGE[1])
                        if tensor is not None else value for key, value in defaults.items())
        ixx, ixy, ixz, iyy, iyz, izz = inertia
        moments = sorted(np.linalg.eigvalsh(np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])))
        if moments[0] < _MOMENT_RANGE[0] or moments[0] + moments[1] < moments[2] * (1.0 - 1e-6):
            raise document.fail(tensor, f"{label}: <inertia> has principal moments "
                                        f"{', '.join(f'{m:g}' for m in moments)}; they must be at least "
                                        f"{_MOMENT_RANGE[0]:g} kg m^2 and each at most the sum of the other two")
        pose = inertial.find("pose")
        return mass, inertia, IDENTITY if pose is None else read_pose(pose, document)

    def _collision(self, collision: ET.Element, document: XmlDocument, scope: _Frames, link: str, static: bool,
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
                      mu=read_number(friction, "mu", document, 1.0) if friction is not None else 1.0,
                      mu2=read_number(friction, "mu2", document, 1.0) if friction is not None else 1.0)
        if kind == "box":
            return Shape(size=read_vector(kind_element, "size", document, (1.0, 1.0, 1.0), positive=True,
                                          maximum=MAX_SHAPE_SIZE), **common)
        if kind == "sphere":
            radius = read_number(kind_element, "radius", document, 1.0, positive=True, maximum=MAX_SHAPE_SIZE)
            return Shape(size=(2.0 * radius,) * 3, radius=radius, **common)
        if kind == "cylinder":
            radius = read_number(kind_element, "radius", document, 1.0, positive=True, maximum=MAX_SHAPE_SIZE)
            length = read_number(kind_element, "length", document, 1.0, positive=True, maximum=MAX_SHAPE_SIZE)
            return Shape(size=(2.0 * radius, 2.0 * radius, length), radius=radius, length=length, **common)
        if kind == "plane":
            if not static:
                warn_once(_log, f"{document.where(kind_element)}: a plane only collides in a static model; "
                                f"{label} skipped")
                return None
            normal = np.asarray(read_vector(kind_element, "normal", document, (0.0, 0.0, 1.0)))
            if not np.linalg.norm(normal) > 0.0:
                raise WorldError(f"{document.where(kind_element)}: <plane><normal> must not be zero")
            width, height = read_vector(kind_element, "size", document, (1.0, 1.0), count=2)
            return Shape(size=(width, height, 0.0), normal=tuple(normal / np.linalg.norm(normal)), **common)
        return self._mesh_shape(kind_element, document, label, common)

    def _mesh_shape(self, mesh: ET.Element, document: XmlDocument, label: str, common: dict) -> Optional[Shape]:
        uri = read_text(mesh, "uri")
        path = self._mesh_path(uri, document) if uri else None
        if path is None:
            self._leave_out(f"{document.where(mesh)}: cannot find mesh '{uri}'; {label} skipped")
            return None
        if mesh.find("submesh") is not None:
            warn_once(_log, f"{document.where(mesh.find('submesh'))}: <submesh> is not supported; "
                            f"{label} uses the whole mesh")
        triangles = self._mesh(path)
        if triangles is None:
            return None
        scale = read_vector(mesh, "scale", document, (1.0, 1.0, 1.0))
        scaled = triangles.scaled(scale)
        size = tuple(float(v) for v in scaled.vertices.max(axis=0) - scaled.vertices.min(axis=0))
        return Shape(size=size, mesh_path=path, mesh=scaled, **common)

    def _physics(self, document: XmlDocument, world: ET.Element) -> PhysicsConfig:
        candidates = world.findall("physics")
        chosen = next((p for p in candidates if read_bool_attribute(p, "default")),
                      candidates[0] if candidates else None)
        defaults = PhysicsConfig()
        values = {}
        if chosen is not None:
            # The bounds set_physics_properties keeps to (physics_properties).
            values = dict(
                max_step_size=read_number(chosen, "max_step_size", document, defaults.max_step_size,
                                          minimum=MIN_TIME_STEP, maximum=MAX_TIME_STEP),
                real_time_factor=read_number(chosen, "real_time_factor", document, defaults.real_time_factor,
                                             minimum=0.0),
                real_time_update_rate=read_number(chosen, "real_time_update_rate", document,
                                                  defaults.real_time_update_rate, minimum=0.0,
                                                  maximum=MAX_UPDATE_RATE))
            constraints = chosen.find("ode/constraints")
            for tag, maximum in _CONSTRAINT_LIMITS.items():
                values[tag] = read_number(constraints, tag, document, getattr(defaults, tag), minimum=0.0,
                                          maximum=maximum)
            if read_number(constraints, "cfm", document, 0.0, minimum=0.0) != 0.0:
                warn_once(_log, f"{document.where(constraints.find('cfm'))}: <cfm> is not applied: Bullet's global "
                                "CFM softens contacts, where ODE's softens joints")
        # SDF 1.6 moved <gravity> from <physics> to <world>; files of either age are read.
        for parent in (world, chosen):
            if parent is not None and parent.find("gravity") is not None:
                values["gravity"] = read_vector(parent, "gravity", document, defaults.gravity)
                if max(abs(value) for value in values["gravity"]) > MAX_GRAVITY:
                    raise document.fail(parent.find("gravity"), f"<gravity>: {parent.findtext('gravity').strip()} "
                                                                f"is beyond ±{MAX_GRAVITY:g} m/s² on an axis")
                break
        return PhysicsConfig(**values)

    @staticmethod
    def _warn_unsupported(document: XmlDocument, element: ET.Element) -> None:
        what = f"<{element.tag}" + (f" name='{element.get('name')}'" if element.get("name") else "") + ">"
        if element.get("filename"):
            what += f" ({element.get('filename')})"
        warn_once(_log, f"{document.where(element)}: {what} is not simulated; ignored")

    @staticmethod
    def _warn_unknown(document: XmlDocument, element: ET.Element, parent: str) -> None:
        # Once per file and kind, at the first: a model of a million of them logged for minutes.
        warn_once(_log, f"{document.where(element)}: <{element.tag}> is not an SDF <{parent}> element; ignored, "
                        "here and wherever else this file has it",
                  key=("unknown element", document.path, parent, element.tag))


def _check_link_names(model: ET.Element, document: XmlDocument, model_name: str) -> None:
    """sdformat's rules for link names: given, unique in their model, and without '::', which scopes nested
    models' names."""
    seen = set()
    for link in model.findall("link"):
        name = link.get("name", "")
        problem = ("has no name" if not name else f"'{name}' is defined twice" if name in seen
                   else f"'{name}' holds '::', which SDF keeps for nested models' names" if "::" in name else None)
        if problem:
            raise document.fail(link, f"model '{model_name}': a <link> {problem}")
        seen.add(name)


def _check_plugin(plugin: ET.Element, document: XmlDocument, owner: str) -> None:
    if not plugin.get("filename", "").strip():
        raise document.fail(plugin, f"{owner}: <plugin name='{plugin.get('name', '')}'> has no filename, which "
                                    "sdformat requires")


# --- Values -------------------------------------------------------------------------------------------------

def _with_state(model: ArticulatedModel, state: ET.Element, document: XmlDocument) -> ArticulatedModel:
    """A model with joints whose joints start where the world's <state> (a saved world) puts its links; a state
    that cannot be reached (beyond a limit, a bad pose) is said once and the model starts as its file has it."""
    found = next((element for element in state.findall("model") if element.get("name") == model.name), None)
    if found is None:
        return model
    try:
        positions = state_joint_positions(found, document, model.pose, model.robot)
        requested_positions(model.robot.joints, [joint.name for joint in model.robot.movable_joints()],
                            list(positions), list(positions.values()))
    except (ModelError, WorldError) as error:
        warn_once(_log, f"{document.where(found)}: <state> of model '{model.name}' left out ({error}); its joints "
                        "start where its model puts them")
        return model
    return dataclasses.replace(model, joint_positions=positions)


def _version(text: str) -> Tuple[int, ...]:
    try:
        return tuple(int(part) for part in text.split("."))
    except ValueError:
        return (0,)
