"""SDF models with joints, sensors or plugins -> the URDF with ``<gazebo>`` blocks that URDF robots are read from.

A model of a world file, an ``<include>`` or spawn_sdf_model that has a ``<joint>``, a model ``<plugin>`` or a
link ``<sensor>`` is simulated as a robot: its links, joints, sensors and plugins are written as the URDF a Gazebo
user would write for the same model, and ``robot_model.parse_robot`` reads that, so joint states, plugins,
sensors, reset, NaN containment and saving are the URDF path's (only rigid models stay world bodies).

SDF to URDF, as sdformat 9 reads SDF 1.4 to 1.7:
- a link's frame is its pose in the model; a joint's frame is its ``<pose>`` in the child link's frame (or in
  ``relative_to``/``frame``). URDF puts the joint frame at the child link's frame, and so does PyBullet's
  multibody, so a child link's URDF frame is its joint's frame and its contents are moved into that frame; the
  SDF link frame, seen from there, is kept (``RobotModel.reported_frames``) and is what poses, velocities,
  sensors and saving report for the link, as Gazebo does (a link whose joint has no pose is not moved);
- the joint axis is in the joint frame, in the model frame for SDF 1.4 and for 1.5/1.6's
  ``<use_parent_model_frame>``, and in any frame ``<xyz expressed_in>`` names (1.7);
- a joint to ``world`` fixes the model to the world (URDF's ``world`` root); a ``<static>`` model is fixed there
  with every joint fixed; a link on no joint moves freely (a URDF floating joint, which is built that way);
  a link without ``<inertial>`` has SDF's mass of 1 kg and unit moments;
- revolute without limits (SDF's ±1e16) is continuous; ``<dynamics>`` damping and friction become URDF's;
- a ball joint is PyBullet's spherical joint (free, no motor; not in joint_states, as Gazebo's publisher
  reads one-axis joints); universal, revolute2, screw and gearbox joints are refused with one line naming the
  joint.
"""
import copy
import math
import xml.etree.ElementTree as ET
from typing import Callable, Dict, List, NamedTuple, Optional, Sequence, Tuple

from ..entity_properties import MAX_DAMPING
from ..errors import ModelError
from ..geometry import IDENTITY, Pose, compose, inverse, rotate, rpy
from ..log import get_logger, warn_once
from ..xml_values import MAX_SHAPE_SIZE, XmlDocument, read_bool, read_number, read_pose, read_text, read_vector
from .materials import sdf_material_rgba
from .robot_model import BALL_JOINT_TYPE, RobotModel, parse_robot, pybullet_text

_log = get_logger(__name__)

# SDF joint type -> URDF joint type.
JOINT_TYPES = {"revolute": "revolute", "continuous": "continuous", "prismatic": "prismatic", "fixed": "fixed",
               "ball": BALL_JOINT_TYPE}
_REFUSED_JOINT_TYPES = ("universal", "revolute2", "screw", "gearbox")
# SDF's default joint limits: beyond these a joint has none.
UNLIMITED = 1e16
# The SDF geometries URDF has; a collision or visual of another kind is left out with a warning.
_URDF_SHAPES = ("box", "cylinder", "sphere", "mesh")


class ModelLevel(NamedTuple):
    """A ``<model>`` of the model being read (itself or a nested one): links named ``prefix + name``."""
    element: ET.Element
    document: XmlDocument
    frames: object  # sdf_world's _Frames of this model: world poses of its named frames
    prefix: str


class SdfRobot(NamedTuple):
    robot: RobotModel
    root_in_model: Pose  # the URDF root link's frame in the model frame: where spawning puts the model


def is_articulated(levels: List[ModelLevel]) -> bool:
    """Whether a model needs the robot path: a joint, a model plugin or a sensor anywhere in it."""
    return any(level.element.find(tag) is not None for level in levels for tag in ("joint", "plugin", "link/sensor"))


def _version(document: XmlDocument) -> Tuple[int, ...]:
    try:
        return tuple(int(part) for part in document.root.get("version", "1.6").split("."))
    except ValueError:
        return (1, 6)


def _origin(parent: ET.Element, pose: Pose):
    ET.SubElement(parent, "origin", xyz=" ".join(repr(float(v)) for v in pose.position),
                  rpy=" ".join(repr(float(v)) for v in rpy(pose.orientation)))


def _same_pose(first: Pose, second: Pose, tolerance: float = 1e-12) -> bool:
    relative = compose(inverse(first), second)
    return max(abs(value) for value in tuple(relative.position) + tuple(relative.orientation[:3])) <= tolerance


def _pose_text(pose: Pose) -> str:
    return " ".join(repr(float(v)) for v in tuple(pose.position) + tuple(rpy(pose.orientation)))


class _Link(NamedTuple):
    element: ET.Element
    level: ModelLevel
    local_name: str
    world: Pose  # the SDF link frame, world


class _Joint(NamedTuple):
    name: str
    element: ET.Element
    level: ModelLevel
    kind: str
    parent: str
    child: str
    world: Pose  # the SDF joint frame, world


class SdfToUrdf:
    """One model's URDF. ``mesh_path(uri, document)`` finds a mesh file; ``inertial(element, document, static,
    label)`` reads and checks an ``<inertial>`` as world models' are (mass, inertia tuple, pose in the link);
    ``check_link(element, document, model)`` warns for what a link has that is not simulated, as for those;
    ``added_plugins`` are the model's plugins given beside it (in its <include>)."""

    def __init__(self, name: str, where: str, model_pose: Pose, static: bool, levels: List[ModelLevel],
                 mesh_path: Callable[[str, XmlDocument], Optional[str]], inertial: Callable, check_link: Callable,
                 added_plugins: Sequence[ET.Element] = ()):
        self.name, self.where, self.model_pose, self.static, self.levels = name, where, model_pose, static, levels
        self._mesh_path, self._inertial, self._check_link = mesh_path, inertial, check_link
        self._added_plugins = added_plugins
        self.label = f"{where}: model '{name}'"

    def build(self) -> SdfRobot:
        links = self._links()
        joints = self._joints(links)
        children = {joint.child: joint for joint in joints}
        anchored = self.static or any(joint.parent == "world" for joint in joints)
        free = [name for name in links if name not in children]
        if not free and not anchored:
            raise ModelError(f"{self.label}: joints {', '.join(repr(joint.name) for joint in joints)} form a loop: "
                             "every link is a joint's child, so none is the model's root")
        root = "world" if anchored else free[0]
        unjointed = [name for name in free if name != root]
        frames = {name: links[name].world for name in free}
        frames.update({joint.child: joint.world for joint in joints})
        frames["world"] = self.model_pose
        robot = ET.Element("robot", name=self.name)
        if anchored:
            ET.SubElement(robot, "link", name="world")
        for name, link in links.items():
            self._link(robot, name, link, frames[name])
        # A link on no joint moves freely in its model, as in Gazebo: URDF's floating joint is built that way.
        for name in unjointed:
            self._simple_joint(robot, f"{name}_free", root, name, inverse(frames[root]), frames[name],
                              "fixed" if self.static else "floating")
        for joint in joints:
            self._joint(robot, joint, inverse(frames[joint.parent]), frames[joint.child])
        plugins = [plugin for level in self.levels for plugin in level.element.findall("plugin")]
        for plugin in plugins + list(self._added_plugins):
            ET.SubElement(robot, "gazebo").append(copy.deepcopy(plugin))
        model = parse_robot(pybullet_text(robot), self.label)
        for name, link in links.items():
            if not _same_pose(frames[name], link.world):
                model.reported_frames[name] = compose(inverse(frames[name]), link.world)
        return SdfRobot(model, compose(inverse(self.model_pose), frames[root]))

    # -- links --------------------------------------------------------------------------------------------------
    def _links(self) -> Dict[str, _Link]:
        links: Dict[str, _Link] = {}
        for level in self.levels:
            for element in level.element.findall("link"):
                local = element.get("name", "")
                name = level.prefix + local
                problem = ("has no name" if not local else f"'{name}' is defined twice" if name in links
                           else "is named 'world', which joints use for the world" if name == "world" else None)
                if problem:
                    raise ModelError(f"{level.document.where(element)}: model '{self.name}': a <link> {problem}")
                links[name] = _Link(element, level, local, level.frames.frame(local, level.document, element))
        if not links:
            raise ModelError(f"{self.label} has no <link>")
        return links

    def _link(self, robot: ET.Element, name: str, link: _Link, frame: Pose):
        element, document, frames = link.element, link.level.document, link.level.frames
        to_urdf = inverse(frame)
        urdf_link = ET.SubElement(robot, "link", name=name)
        label = f"link '{name}' of model '{self.name}'"
        self._check_link(element, document, self.name)
        if read_bool(element.find("self_collide"), document):
            warn_once(_log, f"{document.where(element.find('self_collide'))}: <self_collide> in {label} is not "
                            "simulated: links of one model do not collide with each other")
        mass, inertia, inertial_pose = self._inertial(element.find("inertial"), document, self.static, label)
        if mass > 0.0:
            inertial = ET.SubElement(urdf_link, "inertial")
            _origin(inertial, compose(to_urdf, compose(link.world, inertial_pose)))
            ET.SubElement(inertial, "mass", value=repr(mass))
            ET.SubElement(inertial, "inertia", **{key: repr(value) for key, value in zip(
                ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), inertia)})
        gazebo = ET.Element("gazebo", reference=name)
        for kind in ("collision", "visual"):
            for part in element.findall(kind):
                pose = compose(to_urdf, frames.resolve(part.find("pose"), document, default=link.local_name))
                geometry = self._geometry(part, document, f"{kind} '{part.get('name', '')}' of {label}")
                if geometry is None:
                    continue
                urdf_part = ET.SubElement(urdf_link, kind, name=part.get("name", ""))
                _origin(urdf_part, pose)
                urdf_part.append(geometry)
                rgba = sdf_material_rgba(part.find("material")) if kind == "visual" else None
                if rgba is not None:
                    material = ET.SubElement(urdf_part, "material", name=f"{name}_{part.get('name', '')}")
                    ET.SubElement(material, "color", rgba=" ".join(repr(float(v)) for v in rgba))
        self._surface(gazebo, element, document, label)
        for sensor in element.findall("sensor"):
            placed = copy.deepcopy(sensor)
            for stale in placed.findall("pose"):
                placed.remove(stale)
            # In the SDF link frame: the frame sensors' links are reported in (RobotModel.reported_frames).
            pose = compose(inverse(link.world), frames.resolve(sensor.find("pose"), document, default=link.local_name))
            ET.SubElement(placed, "pose").text = _pose_text(pose)
            gazebo.append(placed)
        if len(gazebo):
            robot.append(gazebo)

    @staticmethod
    def _surface(gazebo: ET.Element, link: ET.Element, document: XmlDocument, label: str):
        """The first collision's ODE friction as the link's ``<mu1>``/``<mu2>``/``<fdir1>``: a URDF link has one
        surface (see robot_model), Gazebo's URDF import writes these to every collision of the link."""
        frictions = [found for found in (c.find("surface/friction/ode") for c in link.findall("collision"))
                     if found is not None]
        if not frictions:
            return
        friction = frictions[0]
        texts = {tuple((found.findtext(tag) or "").strip() for tag in ("mu", "mu2", "fdir1")) for found in frictions}
        if len(texts) > 1 or len(frictions) < len(link.findall("collision")):
            warn_once(_log, f"{document.where(friction)}: the collisions of {label} have different friction; "
                            "all take the first one's (one surface per link, as in a URDF)")
        for tag, urdf_tag in (("mu", "mu1"), ("mu2", "mu2")):
            if friction.find(tag) is not None:
                ET.SubElement(gazebo, urdf_tag).text = repr(read_number(friction, tag, document, 1.0, minimum=0.0))
        if friction.find("fdir1") is not None:
            ET.SubElement(gazebo, "fdir1").text = " ".join(
                repr(v) for v in read_vector(friction, "fdir1", document, (0.0, 0.0, 0.0)))

    def _geometry(self, part: ET.Element, document: XmlDocument, label: str) -> Optional[ET.Element]:
        geometry = part.find("geometry")
        shape = next(iter(geometry), None) if geometry is not None else None
        if shape is None or shape.tag == "empty":
            return None
        urdf = ET.Element("geometry")
        if shape.tag not in _URDF_SHAPES:
            warn_once(_log, f"{document.where(shape)}: <{shape.tag}> is not simulated in a model with joints, "
                            f"sensors or plugins; {label} left out")
            return None
        if shape.tag == "box":
            size = read_vector(shape, "size", document, (1.0, 1.0, 1.0), positive=True, maximum=MAX_SHAPE_SIZE)
            ET.SubElement(urdf, "box", size=" ".join(repr(v) for v in size))
        elif shape.tag == "mesh":
            uri = read_text(shape, "uri")
            path = self._mesh_path(uri, document) if uri else None
            if path is None:
                warn_once(_log, f"{document.where(shape)}: cannot find mesh '{uri}'; {label} left out")
                return None
            scale = read_vector(shape, "scale", document, (1.0, 1.0, 1.0))
            ET.SubElement(urdf, "mesh", filename=path, scale=" ".join(repr(v) for v in scale))
        else:
            attributes = {"radius": repr(read_number(shape, "radius", document, 1.0, positive=True,
                                                     maximum=MAX_SHAPE_SIZE))}
            if shape.tag == "cylinder":
                attributes["length"] = repr(read_number(shape, "length", document, 1.0, positive=True,
                                                        maximum=MAX_SHAPE_SIZE))
            ET.SubElement(urdf, shape.tag, **attributes)
        return urdf

    # -- joints -------------------------------------------------------------------------------------------------
    def _joints(self, links: Dict[str, _Link]) -> List[_Joint]:
        joints = []
        for level in self.levels:
            document = level.document
            for element in level.element.findall("joint"):
                name = level.prefix + element.get("name", "")
                where = f"{document.where(element)}: model '{self.name}': joint '{name}'"
                kind = element.get("type", "")
                if kind in _REFUSED_JOINT_TYPES:
                    raise ModelError(f"{where}: type '{kind}' is not simulated (PyBullet's multibody is built here "
                                     f"from one-axis joints); use one of {', '.join(JOINT_TYPES)}")
                if kind not in JOINT_TYPES:
                    raise ModelError(f"{where}: type '{kind}' is not an SDF joint type; use one of "
                                     f"{', '.join(JOINT_TYPES)}")
                ends = {}
                for role in ("parent", "child"):
                    given = read_text(element, role)
                    ends[role] = next((candidate for candidate in (level.prefix + given, given)
                                       if candidate in links or (candidate == "world" and role == "parent")), None)
                    if ends[role] is None:
                        raise ModelError(f"{where}: <{role}> '{given}' is not a link of the model")
                pose = element.find("pose")
                child = links[ends["child"]]
                if pose is not None and (pose.get("relative_to") or pose.get("frame")):
                    world = level.frames.resolve(pose, document)
                else:
                    world = compose(child.world, read_pose(pose, document))
                joints.append(_Joint(name, element, level, kind, ends["parent"], ends["child"], world))
        seen = {}
        for joint in joints:
            if joint.child in seen:
                raise ModelError(f"{self.label}: link '{joint.child}' is the child of two joints, "
                                 f"'{seen[joint.child]}' and '{joint.name}'")
            seen[joint.child] = joint.name
        return joints

    @staticmethod
    def _simple_joint(robot: ET.Element, name: str, parent: str, child: str, to_parent: Pose, frame: Pose,
                     kind: str = "fixed"):
        joint = ET.SubElement(robot, "joint", name=name, type=kind)
        ET.SubElement(joint, "parent", link=parent)
        ET.SubElement(joint, "child", link=child)
        _origin(joint, compose(to_parent, frame))

    def _joint(self, robot: ET.Element, joint: _Joint, to_parent: Pose, frame: Pose):
        if self.static or joint.kind in ("fixed", "ball"):
            self._simple_joint(robot, joint.name, joint.parent, joint.child, to_parent, frame,
                               "fixed" if self.static else JOINT_TYPES[joint.kind])
            return
        document = joint.level.document
        axis = joint.element.find("axis")
        limit = axis.find("limit") if axis is not None else None
        lower = read_number(limit, "lower", document, -UNLIMITED)
        upper = read_number(limit, "upper", document, UNLIMITED)
        kind = JOINT_TYPES[joint.kind]
        if kind == "revolute" and lower <= -UNLIMITED and upper >= UNLIMITED:
            kind = "continuous"
        element = ET.SubElement(robot, "joint", name=joint.name, type=kind)
        ET.SubElement(element, "parent", link=joint.parent)
        ET.SubElement(element, "child", link=joint.child)
        _origin(element, compose(to_parent, frame))
        ET.SubElement(element, "axis", xyz=" ".join(repr(v) for v in self._axis(joint, axis, frame)))
        # SDF's -1 (no limit) for effort and velocity is URDF's 0 (none given).
        effort = max(0.0, read_number(limit, "effort", document, -1.0))
        velocity = max(0.0, read_number(limit, "velocity", document, -1.0))
        attributes = {"effort": repr(effort), "velocity": repr(velocity)}
        if kind != "continuous":
            attributes.update(lower=repr(max(lower, -UNLIMITED)), upper=repr(min(upper, UNLIMITED)))
        ET.SubElement(element, "limit", **attributes)
        dynamics = axis.find("dynamics") if axis is not None else None
        if dynamics is not None:
            ET.SubElement(element, "dynamics", **{tag: repr(read_number(dynamics, tag, document, 0.0, minimum=0.0,
                                                                        maximum=MAX_DAMPING))
                                                  for tag in ("damping", "friction")})
            for tag in ("spring_stiffness", "spring_reference"):
                if read_number(dynamics, tag, document, 0.0) != 0.0:
                    warn_once(_log, f"{document.where(dynamics.find(tag))}: joint '{joint.name}' of model "
                                    f"'{self.name}': <{tag}> is not simulated")

    def _axis(self, joint: _Joint, axis: Optional[ET.Element], frame: Pose) -> Tuple[float, float, float]:
        """The joint axis in the joint frame (URDF's)."""
        document = joint.level.document
        vector = read_vector(axis, "xyz", document, (0.0, 0.0, 1.0))
        xyz = axis.find("xyz") if axis is not None else None
        version = _version(document)
        if version >= (1, 7):
            expressed_in = xyz.get("expressed_in", "") if xyz is not None else ""
            if not expressed_in:
                return vector
            orientation = (joint.level.frames.origin if expressed_in == "__model__"
                           else joint.level.frames.frame(expressed_in, document, xyz)).orientation
        elif version < (1, 5) or read_bool(axis.find("use_parent_model_frame") if axis is not None else None,
                                           document):
            orientation = joint.level.frames.origin.orientation
        else:
            return vector
        # Seen from the joint frame, whose world orientation is the child's URDF frame's.
        world = rotate(orientation, vector)
        return rotate(inverse(frame).orientation, world)


def state_joint_positions(state: ET.Element, document: XmlDocument, model_pose: Pose,
                          robot: RobotModel) -> Dict[str, float]:
    """The positions of a model's one-axis joints that put its links where a world's ``<state><model>`` has them
    (Gazebo saves the world poses of links, no joint positions): the turn about, or the shift along, the joint's
    axis from its origin to the child link's frame seen from the parent's. ``model_pose``: where the URDF's
    ``world`` link is (the model frame), for joints to the world."""
    links = {"world": model_pose}

    def read_links(element: ET.Element, prefix: str):
        for link in element.findall("link"):
            links[prefix + link.get("name", "")] = read_pose(link.find("pose"), document)
        for nested in element.findall("model"):
            read_links(nested, f"{prefix}{nested.get('name', '')}::")

    read_links(state, "")
    positions = {}
    for joint in robot.movable_joints():
        if joint.parent not in links or joint.child not in links:
            continue
        parent, child = (compose(links[name], inverse(robot.reported_frames.get(name, IDENTITY)))
                         for name in (joint.parent, joint.child))
        motion = compose(inverse(joint.origin), compose(inverse(parent), child))
        norm = math.sqrt(sum(value * value for value in joint.axis))
        axis = [value / norm for value in joint.axis]
        if joint.type == "prismatic":
            positions[joint.name] = sum(a * b for a, b in zip(axis, motion.position))
        else:
            turn = 2.0 * math.atan2(sum(a * b for a, b in zip(axis, motion.orientation[:3])), motion.orientation[3])
            positions[joint.name] = math.remainder(turn, 2.0 * math.pi)
    return positions
