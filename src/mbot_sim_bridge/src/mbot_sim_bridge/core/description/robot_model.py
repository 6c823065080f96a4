"""robot_description (URDF after xacro) -> what the simulator needs, the way Gazebo's URDF import sees it.

Follows sdformat9's ``parser_urdf.cc`` where it matters for physics:
- fixed joints are lumped into their parent, so each URDF link maps to a simulated body link plus a fixed
  offset; the lumping is done here rather than by PyBullet's URDF_MERGE_FIXED_LINKS because sdformat keeps each
  lumped collision's own surface, and Bullet has one friction per link: a lumped part whose surface differs
  from its holder's (a frictionless caster under a chassis) stays a Bullet link of its own on a fixed joint;
- a link with no ``<inertial>`` that gets lumped adds no mass (PyBullet would give it 1 kg and unit inertia);
- a link with no ``<inertial>`` on a moving joint is not simulated, together with its subtree (with a warning);
- ``<gazebo reference="...">`` blocks are collected per link; model-level ``<gazebo>`` blocks carry plugins.
"""
import copy
import math
import os
import stat
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple
from xml.etree import ElementTree

import numpy as np

from ..entity_properties import MAX_DAMPING
from ..errors import ModelError
from ..geometry import IDENTITY, Pose, compose, rotate, rotation_matrix, rpy
from ..log import get_logger, warn_once
from ..xml_values import (MAX_SHAPE_SIZE, XmlDocument, check_range, parse_float, parse_floats, parse_xml,
                          read_attribute_numbers, read_origin)

_logger = get_logger(__name__)

MOVABLE_JOINT_TYPES = ("continuous", "revolute", "prismatic")
# sdformat's URDF import writes no joint for these: the child link moves freely in the model (planar too, not
# held to its plane), and no joint of that name exists for joint_states or -J. PyBullet's importer cannot
# load them into a multibody, so each becomes a chain that holds nothing (see _add_free_chain).
FREE_JOINT_TYPES = ("planar", "floating")
# PyBullet's own URDF type, for SDF ball joints (sdf_model): three free rotations, no joint_states entry.
BALL_JOINT_TYPE = "spherical"
SUPPORTED_JOINT_TYPES = MOVABLE_JOINT_TYPES + ("fixed",) + FREE_JOINT_TYPES + (BALL_JOINT_TYPE,)
# A free joint's chain: three prismatic joints along the parent's x, y and z, then a spherical joint, between
# links without mass. Their names: the joint's own for the spherical one, these suffixes for the others.
FREE_CHAIN_AXES = (("x", "1 0 0"), ("y", "0 1 0"), ("z", "0 0 1"))
# The chain's prismatic joints reach this far (m), beyond the farthest a model may be placed (engine.MAX_POSITION).
_FREE_CHAIN_REACH = 1e6

# <gazebo reference="link"> tags the bridge acts on.
LINK_TAGS_USED = ("material", "mu1", "mu2", "fdir1", "sensor")
# Tags whose Gazebo default is what Bullet does anyway: only another value is reported (value -> default).
LINK_TAGS_DEFAULT_ONLY = {"turnGravityOff": "false", "gravity": "true", "selfCollide": "false"}
# Tags read by Gazebo's URDF import that have no Bullet counterpart here: one warning per tag and model.
LINK_TAGS_NO_EFFECT = ("kp", "kd", "minDepth", "maxVel", "laserRetro", "maxContacts", "dampingFactor",
                       "maxVelocity", "provideFeedback", "implicitSpringDamper", "cfmDamping", "stopCfm",
                       "stopErp", "springStiffness", "springReference", "fudgeFactor", "visual", "collision",
                       "preserveFixedJoint", "disableFixedJointLumping")
# <gazebo reference="joint"> tags (sdformat's URDF import reads them onto the joint). provideFeedback asks Gazebo
# to compute the joint's wrench, which the ft sensor plugin here computes without it: accepted, nothing to do.
JOINT_TAGS_USED = ("provideFeedback",)
# Tags that set ODE's joint solver, its springs or Gazebo's fixed-joint lumping: no Bullet counterpart here (every
# fixed joint is lumped, as without preserveFixedJoint): one warning per tag and joint.
JOINT_TAGS_NO_EFFECT = ("implicitSpringDamper", "cfmDamping", "stopCfm", "stopErp", "stopKp", "stopKd",
                        "springStiffness", "springReference", "fudgeFactor", "preserveFixedJoint",
                        "disableFixedJointLumping")
# A wheel's tread (m) and how much narrower in radius its sides are (a fraction): see _with_treads. The sides
# stay off flat ground until the wheel leans by about 2 degrees.
TREAD_WIDTH = 0.002
SIDE_CLEARANCE = 0.01
# Gazebo's default friction coefficient for a surface that sets none (ODE mu = mu2 = 1).
DEFAULT_MU = 1.0
# A negligible inertial for a Bullet link without mass (a massless root, a separate surface): PyBullet would
# give it 1 kg and unit inertia.
_NEGLIGIBLE_MASS = 1e-9
_NEGLIGIBLE_INERTIA = 1e-12
_SHAPE_SIZES = {"box": (("size", 3),), "cylinder": (("radius", 1), ("length", 1)), "sphere": (("radius", 1),)}
# kg and kg·m²: far beyond any robot; larger values are typos that Bullet's solver cannot integrate.
_MAX_MASS = 1e9
_MAX_INERTIA = 1e9
# A link's mass, when it has one, and the principal moments of a Bullet link with mass: the least of SDF links'
# (sdf_world) too. Below them Bullet flung or froze what it moved: a 1e-7 kg base under a 1 kg arm flew 50 m, a
# 1e-300 kg one was dragged 0.2 m, and an arm with inertia 0 never swung (ODE says "inertia must be positive
# definite" and steps on). 0 keeps its URDF meaning: no mass, as a link without <inertial>.
_LEAST_MASS = 1e-6
_LEAST_MOMENT = 1e-12
# A joint axis shorter than this is taken for none (normalising it would lose all precision).
_MIN_AXIS_LENGTH = 1e-6


@dataclass
class Link:
    name: str
    has_inertial: bool
    mass: float
    collision_kinds: List[str]
    # Radius of each collision shape that has one (cylinder, sphere), else None; in collision_kinds' order.
    collision_radii: List[Optional[float]] = field(default_factory=list)
    gazebo: List[ElementTree.Element] = field(default_factory=list)

    def gazebo_tag(self, tag: str) -> Optional[str]:
        """Value of the last ``<gazebo reference>`` child with this tag (later blocks win, as in sdformat), its
        text or, as sdformat's URDF import also reads it, its ``value`` attribute (Clearpath's ``<mu1 value=""/>``)."""
        text = None
        for block in self.gazebo:
            child = block.find(tag)
            if child is None:
                continue
            value = child.get("value") if child.get("value") is not None else child.text
            if value is not None:
                text = value.strip()
        return text

    def surface(self, source: str) -> Tuple[float, float]:
        """(mu1, mu2) of the link's collisions, each 1 when not given, as in SDF's <ode> friction."""
        return tuple(_friction(self.gazebo_tag(tag), source, self.name, tag) for tag in ("mu1", "mu2"))


@dataclass
class Joint:
    name: str
    type: str
    parent: str
    child: str
    origin: Pose
    axis: Tuple[float, float, float]
    # URDF <limit>: lower/upper (rad or m; -inf/inf when absent or continuous), effort and velocity (0 = none given)
    lower: float = -math.inf
    upper: float = math.inf
    effort: float = 0.0
    velocity: float = 0.0
    has_limit: bool = False  # a <limit> element was given
    # <safety_controller>: (soft_lower_limit, soft_upper_limit, k_position, k_velocity)
    safety: Optional[Tuple[float, float, float, float]] = None
    mimic: Optional[Tuple[str, float, float]] = None  # <mimic>: (leader joint, multiplier, offset)

    @property
    def movable(self) -> bool:
        return self.type in MOVABLE_JOINT_TYPES

    @property
    def free(self) -> bool:
        return self.type in FREE_JOINT_TYPES

    @property
    def spherical(self) -> bool:
        """Whether its Bullet joint is spherical (a ball joint, and a free joint's last)."""
        return self.free or self.type == BALL_JOINT_TYPE

    def free_chain(self) -> List[Tuple[str, str]]:
        """(Bullet link, prismatic joint) names of a free joint's chain, the links' first."""
        return [(f"{self.name}__free_{axis}", f"{self.name}__free_{axis}_joint") for axis, _ in FREE_CHAIN_AXES]


@dataclass
class RobotModel:
    name: str
    root: str
    links: Dict[str, Link]
    joints: Dict[str, Joint]
    plugins: List[ElementTree.Element]
    # For every URDF link: (the simulated link it is lumped into, its pose in that link's frame).
    lumped_into: Dict[str, Tuple[str, Pose]]
    pybullet_urdf: str
    transmissions: List[ElementTree.Element]
    document: XmlDocument  # the parsed robot_description: line numbers for messages
    # Lumped links simulated as a Bullet link of their own (on a fixed joint, massless) for their own surface.
    separate_surfaces: Tuple[str, ...] = ()
    # Links that roll (see _wheels): link -> (the first cylinder's centre, the unit axle), in the link frame.
    wheels: Dict[str, Tuple[Tuple[float, float, float], Tuple[float, float, float]]] = field(default_factory=dict)
    # The URDF text parsed: a plugin that reads the same text from a parameter reuses this model (and its warnings
    # are said once, not once per reading).
    xml: str = ""
    # Where a link's frame as Gazebo reports it is not its URDF frame (an SDF link whose joint has a <pose>: URDF
    # and PyBullet put a link's frame at its joint): that frame, seen from the URDF frame.
    reported_frames: Dict[str, Pose] = field(default_factory=dict)

    @property
    def anchored(self) -> bool:
        """Whether the root link is URDF's ``world``: Gazebo fixes the model to the world there, as arm
        descriptions mount their base with a fixed ``world_joint``."""
        return self.root == "world"

    def reported_frame(self, link_name: str) -> Tuple[str, Pose]:
        """The simulated link holding ``link_name`` and, in that link's URDF frame, the frame Gazebo reports for
        ``link_name`` (poses, velocities, sensors, saving)."""
        holder, offset = self.lumped_into[link_name]
        own = self.reported_frames.get(link_name)
        return holder, offset if own is None else compose(offset, own)

    def movable_joints(self) -> List[Joint]:
        return [joint for joint in self.joints.values() if joint.movable]

    def free_chain_links(self) -> List[str]:
        """The Bullet links of the free joints' chains: no links Gazebo has."""
        return [link for joint in self.joints.values() if joint.free for link, _ in joint.free_chain()]

    def free_chain_joints(self) -> List[str]:
        """The prismatic Bullet joints of the free joints' chains, to be left without a motor."""
        return [name for joint in self.joints.values() if joint.free for _, name in joint.free_chain()]

    def collision_names(self) -> Dict[str, List[str]]:
        """Simulated link -> the names sdformat gives the collisions it holds: "L_collision" (then
        "L_collision_1", ...) for link L's own, "P_fixed_joint_lump__L_collision" for those lumped into P."""
        return {holder: [name for name, _, _ in boxes] for holder, boxes in self.collision_boxes().items()}

    def collision_boxes(self) -> Dict[str, List[Tuple[str, Pose, Tuple[float, float, float]]]]:
        """Simulated link -> (sdformat's name, pose in that link's frame, half extents) of each collision it
        holds; a mesh's extents are unknown here and taken as zero (its origin stands for it)."""
        boxes: Dict[str, List[Tuple[str, Pose, Tuple[float, float, float]]]] = {}
        for holder, _, name, pose, extents in self._collisions():
            boxes.setdefault(holder, []).append((name, pose, extents))
        return boxes

    def bullet_collision_names(self) -> Dict[str, List[str]]:
        """As ``collision_names``, by Bullet link: a separate surface's collisions are held by its own."""
        names: Dict[str, List[str]] = {}
        for holder, part, name, _, _ in self._collisions():
            names.setdefault(part if part in self.separate_surfaces else holder, []).append(name)
        return names

    def bullet_surface(self, bullet_link: str, source: str) -> Tuple[float, float]:
        """(mu1, mu2) of a Bullet link: a separate surface's own, else that of the collisions its holder keeps."""
        if bullet_link in self.separate_surfaces:
            return self.links[bullet_link].surface(source)
        return _held_surface(bullet_link, self.links, self.lumped_into, source)

    def _collisions(self):
        """(holder, URDF link, sdformat's name, pose in the holder's frame, half extents) of every collision."""
        elements = {element.get("name"): element for element in self.document.root.findall("link")}
        for link in self.links.values():
            if link.name not in self.lumped_into or link.name not in elements:
                continue
            holder, offset = self.lumped_into[link.name]
            prefix = link.name if holder == link.name else f"{holder}_fixed_joint_lump__{link.name}"
            for index, collision in enumerate(elements[link.name].findall("collision")):
                name = f"{prefix}_collision" + (f"_{index}" if index else "")
                pose = compose(offset, read_origin(collision, self.document))
                yield holder, link.name, name, pose, _half_extents(collision.find("geometry"))

    def fdir1(self, link_name: str, source: str) -> Optional[Tuple[float, float, float]]:
        """Gazebo's first friction direction of a link, in its frame, or None when absent or zero."""
        text = self.links[link_name].gazebo_tag("fdir1")
        if text is None:
            return None
        try:
            direction = parse_floats(text, 3)
        except ValueError as error:
            raise ModelError(f"{source}: <gazebo reference='{link_name}'> <fdir1> '{text}': {error}") from None
        largest = max(abs(value) for value in direction)
        if largest == 0.0:
            return None
        # Scaled before it is squared, so that 1e308 stays finite.
        length = math.sqrt(sum((value / largest) ** 2 for value in direction))
        return tuple(value / largest / length for value in direction)

    def sensors(self) -> List[Tuple[str, ElementTree.Element]]:
        """(URDF link name, <sensor> element) for every sensor in the ``<gazebo reference>`` blocks."""
        return [(link.name, sensor) for link in self.links.values()
                for block in link.gazebo for sensor in block.findall("sensor")]

    def caster_links(self, driven_joints) -> List[str]:
        """Links that act as ball casters: every collision a sphere, on a joint nothing drives.

        Gazebo users rely on ODE letting such a sphere slide sideways. In Bullet, a sphere on a one-axis
        joint (the course's back caster) rolls only forwards and its sideways friction pins the robot when
        it turns in place, so these links get frictionless contacts unless their <gazebo> block sets mu1/mu2.
        """
        casters = []
        for joint in self.joints.values():
            link = self.links[joint.child]
            if (joint.name not in driven_joints and link.collision_kinds
                    and all(kind == "sphere" for kind in link.collision_kinds)
                    and link.gazebo_tag("mu1") is None and link.gazebo_tag("mu2") is None):
                casters.append(link.name)
        return casters


def _parse_document(urdf_xml: str, source: str) -> XmlDocument:
    if not urdf_xml or not urdf_xml.strip():
        raise ModelError(f"{source} is empty")
    document = parse_xml(urdf_xml.encode(), source, ModelError)
    if document.root.tag != "robot":
        raise ModelError(f"{source} is not URDF: its root element is <{document.root.tag}>, not <robot>")
    return document


def _safety_controller(element: ElementTree.Element, where: str,
                       document: XmlDocument) -> Optional[Tuple[float, float, float, float]]:
    """URDF <safety_controller> (urdfdom: k_velocity required, the others 0 when absent), or None."""
    safety = element.find("safety_controller")
    if safety is None:
        return None
    if safety.get("k_velocity") is None:
        raise ModelError(f"{where}: <safety_controller> needs k_velocity")
    return tuple(read_attribute_numbers(safety, name, document, (0.0,), 1)[0]
                 for name in ("soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity"))


def _mimic(element: ElementTree.Element, where: str, document: XmlDocument) -> Optional[Tuple[str, float, float]]:
    """URDF <mimic joint= multiplier= offset=> (multiplier 1 and offset 0 when absent), or None."""
    mimic = element.find("mimic")
    if mimic is None:
        return None
    if not mimic.get("joint"):
        raise ModelError(f"{where}: <mimic> needs a joint")
    multiplier = read_attribute_numbers(mimic, "multiplier", document, (1.0,), 1)[0]
    offset = read_attribute_numbers(mimic, "offset", document, (0.0,), 1)[0]
    return mimic.get("joint"), multiplier, offset


def _check_dynamics(dynamics: Optional[ElementTree.Element], document: XmlDocument, joint_name: str):
    """<dynamics damping friction> within set_joint_properties' bounds: Bullet turned a damping of 1e308 NaN."""
    for name in ("damping", "friction") if dynamics is not None else ():
        try:
            check_range(read_attribute_numbers(dynamics, name, document, (0.0,), 1)[0], 0.0, MAX_DAMPING)
        except ValueError as error:
            raise ModelError(f"{document.where(dynamics)}: joint '{joint_name}': <dynamics {name}>: {error}") from None


def _joint_limits(element: ElementTree.Element, joint_type: str, document: XmlDocument) -> dict:
    limit = element.find("limit")
    if limit is None:
        return {}
    lower, upper, effort, velocity = (read_attribute_numbers(limit, name, document, (default,), 1)[0]
                                      for name, default in (("lower", 0.0), ("upper", 0.0), ("effort", 0.0),
                                                            ("velocity", 0.0)))
    for name, value in (("effort", effort), ("velocity", velocity)):
        if value < 0.0:
            # ros_control's saturation would clamp every command to this negative bound.
            raise document.fail(limit, f"joint '{element.get('name')}': <limit {name}=\"{value:g}\"> is negative; "
                                       "it is at least 0 (0 or none: no limit)")
    values = {"effort": effort, "velocity": velocity, "has_limit": True}
    if joint_type != "continuous":
        values.update(lower=lower, upper=upper)
    return values


def parse_robot(urdf_xml: str, source: str = "robot_description") -> RobotModel:
    """Parse and check a URDF string; ``source`` names it in every error ("robot_description", a file)."""
    document = _parse_document(urdf_xml, source)
    root = document.root
    name = root.get("name") or "robot"
    links: Dict[str, Link] = {}
    for element in root.findall("link"):
        link_name = element.get("name")
        if not link_name:
            raise ModelError(f"{source}: a <link> has no name")
        if link_name in links:
            raise ModelError(f"{source}: link '{link_name}' is defined twice")
        inertial = element.find("inertial")
        mass = 0.0
        if inertial is not None and (inertial.find("mass") is None or inertial.find("mass").get("value") is None):
            # urdfdom's rules; read as no <inertial>, a chain of 1,000 such links was cut to its root.
            where = document.where(inertial if inertial.find("mass") is None else inertial.find("mass"))
            raise ModelError(f"{where}: link '{link_name}': " + ("<inertial> has no <mass>" if inertial.find("mass")
                             is None else "<mass> has no value attribute (<mass value=\"1.0\"/>)"))
        if inertial is not None:
            mass = read_attribute_numbers(inertial.find("mass"), "value", document, (0.0,), 1)[0]
            try:
                check_range(mass, 0.0, _MAX_MASS, least_positive=_LEAST_MASS)
            except ValueError as error:
                raise ModelError(f"{source}: link '{link_name}': <mass value>: {error}") from None
        kinds = [geometry[0].tag for geometry in (c.find("geometry") for c in element.findall("collision"))
                 if geometry is not None and len(geometry)]
        links[link_name] = Link(link_name, inertial is not None and mass > 0, mass, kinds)
    if not links:
        raise ModelError(f"{source}: the robot has no <link>")

    joints: Dict[str, Joint] = {}
    for element in root.findall("joint"):
        joint_name = element.get("name")
        if not joint_name:
            raise ModelError(f"{source}: a <joint> has no name")
        where = f"{source} joint '{joint_name}'"
        if joint_name in joints:
            raise ModelError(f"{where}: defined twice")
        joint_type = element.get("type")
        if joint_type not in SUPPORTED_JOINT_TYPES:
            raise ModelError(f"{where}: type '{joint_type}' is not supported; use one of "
                             f"{', '.join(SUPPORTED_JOINT_TYPES)}")
        parent, child = element.find("parent"), element.find("child")
        if parent is None or child is None:
            raise ModelError(f"{where}: needs <parent link> and <child link>")
        for role, link_name in (("parent", parent.get("link")), ("child", child.get("link"))):
            if link_name not in links:
                raise ModelError(f"{where}: {role} link '{link_name}' is not defined")
        # URDF allows one parent; PyBullet would keep one of two silently (and crash on a duplicate joint).
        other = next((j.name for j in joints.values() if j.child == child.get("link")), None)
        if other is not None:
            raise ModelError(f"{where}: child link '{child.get('link')}' already has a parent joint, '{other}'")
        axis_element = element.find("axis")
        axis = (read_attribute_numbers(axis_element, "xyz", document, (0.0, 0.0, 0.0))
                if axis_element is not None else (1.0, 0.0, 0.0))
        # ODE refuses to normalise a zero axis (dNormalize3); Bullet divides by it and the robot turns NaN.
        if joint_type in MOVABLE_JOINT_TYPES and not math.hypot(*axis) >= _MIN_AXIS_LENGTH:
            raise ModelError(f"{document.where(axis_element)}: joint '{joint_name}': "
                             f"<axis xyz=\"{axis_element.get('xyz')}\"> has no direction; "
                             f"a {joint_type} joint needs an axis of length at least {_MIN_AXIS_LENGTH:g}")
        _check_dynamics(element.find("dynamics"), document, joint_name)
        limit = element.find("limit")
        if limit is None and joint_type in ("revolute", "prismatic"):
            # urdfdom's own rule; PyBullet said only "Cannot load URDF file", naming the robot.
            raise ModelError(f"{document.where(element)}: joint '{joint_name}' is of type {joint_type} but it does not "
                             f"specify limits (<limit lower upper effort velocity>)")
        joints[joint_name] = joint = Joint(joint_name, joint_type, parent.get("link"), child.get("link"),
                                           read_origin(element, document), axis,
                                           safety=_safety_controller(element, where, document),
                                           mimic=_mimic(element, where, document),
                                           **_joint_limits(element, joint_type, document))
        if joint.lower > joint.upper:
            raise ModelError(f"{document.where(limit)}: joint '{joint_name}': <limit lower=\"{joint.lower:g}\"> is "
                             f"above upper=\"{joint.upper:g}\"")

    for joint in joints.values():
        if joint.mimic is not None and (joint.mimic[0] not in joints or not joints[joint.mimic[0]].movable
                                        or not joint.movable):
            raise ModelError(f"{source} joint '{joint.name}': <mimic joint='{joint.mimic[0]}'> needs a movable joint "
                             f"mimicking a movable joint of the robot")
        followed = [joint.name]
        while joints[followed[-1]].mimic is not None:
            followed.append(joints[followed[-1]].mimic[0])
            if followed[-1] in followed[:-1]:
                raise ModelError(f"{source} joint '{joint.name}': <mimic> joints follow each other in a circle: "
                                 f"{' -> '.join(followed)}; one of them must follow a joint that is driven")
    children = {joint.child for joint in joints.values()}
    roots = [link_name for link_name in links if link_name not in children]
    if len(roots) != 1:
        raise ModelError(f"{source}: expected one root link, found {', '.join(roots) or 'none (a loop)'}")
    unreachable = set(links) - set(_subtree(roots[0], joints))
    if unreachable:
        raise ModelError(f"{source}: links {', '.join(sorted(unreachable))} form a loop, not reachable "
                         f"from root link '{roots[0]}'")

    plugins = _collect_gazebo_blocks(root, links, joints, source)
    transmissions = root.findall("transmission")
    dropped = _drop_massless_moving_links(links, joints, source)
    lumped_into = _lump_fixed_links(roots[0], links, joints)
    separate = _separate_surfaces(links, lumped_into, source)
    pybullet_urdf = _pybullet_urdf(root, links, joints, dropped, lumped_into, separate, document, source)
    _read_collision_radii(root, links, document)
    wheels = _wheels(root, links, joints, document)
    return RobotModel(name, roots[0], links, joints, plugins, lumped_into, _with_treads(pybullet_urdf, wheels),
                      transmissions, document, separate, wheels, urdf_xml)


def _wheels(root: ElementTree.Element, links, joints, document: XmlDocument):
    """Links that roll: every collision a cylinder whose axis is the axis of the link's revolute or continuous
    joint. Link -> (the first cylinder's centre, the unit axle), in the link frame."""
    elements = {element.get("name"): element for element in root.findall("link")}
    found = {}
    for joint in joints.values():
        collisions = elements[joint.child].findall("collision") if joint.child in elements else []
        length = math.sqrt(sum(value * value for value in joint.axis))
        if joint.type not in ("continuous", "revolute") or not collisions or length == 0.0:
            continue
        axle = tuple(value / length for value in joint.axis)
        poses = [read_origin(collision, document) for collision in collisions]
        if all(kind == "cylinder" and abs(sum(a * b for a, b in zip(rotate(pose.orientation, (0.0, 0.0, 1.0)), axle)))
               > 0.999 for kind, pose in zip(links[joint.child].collision_kinds, poses)):
            found[joint.child] = (poses[0].position, axle)
    return found


def _with_treads(urdf: str, wheels) -> str:
    """Each wheel cylinder as Bullet gets it: a thin tread of its radius at its mid-plane, and the cylinder a
    little narrower in radius for what the wheel's sides touch. Bullet lets a cylinder lying on a plane touch it
    at one rim point, which jumps between the rims as rounding tilts the wheel; that shifted the load and the
    track of a wheeled base by half the wheel's width (see wheel_contact)."""
    if not wheels:
        return urdf
    robot = ElementTree.fromstring(urdf)
    for link in robot.findall("link"):
        if link.get("name") not in wheels:
            continue
        for collision in link.findall("collision"):
            cylinder = collision.find("geometry/cylinder")
            radius, length = float(cylinder.get("radius")), float(cylinder.get("length"))
            if length <= TREAD_WIDTH:
                continue
            tread = copy.deepcopy(collision)
            tread.find("geometry/cylinder").set("length", repr(TREAD_WIDTH))
            link.insert(list(link).index(collision), tread)
            cylinder.set("radius", repr(radius * (1.0 - SIDE_CLEARANCE)))
    return pybullet_text(robot)


def _friction(text: Optional[str], source: str, link: str, tag: str) -> float:
    if text is None:
        return DEFAULT_MU
    try:
        value = parse_float(text)
        check_range(value, minimum=0.0)
    except ValueError as error:
        raise ModelError(f"{source}: <gazebo reference='{link}'> <{tag}> '{text}': {error}") from None
    return value


def _held_surface(holder: str, links, lumped_into, source: str) -> Tuple[float, float]:
    """The surface a simulated link keeps: its own if it has collisions, else that of the first lumped link with
    collisions (a base_link lumped into a collision-free base_footprint root keeps its mu)."""
    parts = [name for name, (body, _) in lumped_into.items() if body == holder and links[name].collision_kinds]
    first = holder if holder in parts or not parts else parts[0]
    return links[first].surface(source)


def _separate_surfaces(links, lumped_into, source: str) -> Tuple[str, ...]:
    """Lumped links with collisions whose surface differs from the one their holder keeps."""
    return tuple(name for name, (holder, _) in lumped_into.items()
                 if holder != name and links[name].collision_kinds
                 and links[name].surface(source) != _held_surface(holder, links, lumped_into, source))


def _read_collision_radii(root: ElementTree.Element, links: Dict[str, Link], document: XmlDocument):
    """Each link's collision radii (a wheel's, for diff_drive_controller), once the shapes have been checked."""
    for element in root.findall("link"):
        link = links.get(element.get("name"))
        if link is None:  # dropped as a massless moving link
            continue
        shapes = [geometry[0] for geometry in (c.find("geometry") for c in element.findall("collision"))
                  if geometry is not None and len(geometry)]
        link.collision_radii = [
            read_attribute_numbers(shape, "radius", document, (0.0,), 1)[0] if shape.get("radius") is not None
            else None for shape in shapes]


def _collect_gazebo_blocks(root, links, joints, source) -> List[ElementTree.Element]:
    plugins = []
    for block in root.findall("gazebo"):
        reference = block.get("reference")
        if reference is None:
            for child in block:
                if child.tag == "plugin":
                    plugins.append(child)
                elif child.tag != "static":
                    warn_once(_logger, f"{source}: model-level <gazebo> tag <{child.tag}> is not supported; ignored")
            continue
        if reference in links:
            links[reference].gazebo.append(block)
            for child in block:
                _check_link_tag(child, reference, source)
        elif reference in joints:
            for child in block:
                _check_joint_tag(child, reference, source)
        else:
            warn_once(_logger, f"{source}: <gazebo reference='{reference}'> names no link or joint; ignored")
    return plugins


def _check_joint_tag(child: ElementTree.Element, reference: str, source: str):
    """Say once per tag and model that a <gazebo reference="JOINT"> tag is left out, and why."""
    where = f"{source}: <gazebo reference='{reference}'> (a joint) <{child.tag}>"
    if child.tag in JOINT_TAGS_USED:
        return
    if child.tag in JOINT_TAGS_NO_EFFECT:
        warn_once(_logger, f"{where} has no Bullet counterpart; ignored")
    else:
        warn_once(_logger, f"{where} is not supported on a joint; ignored")


def _check_link_tag(child: ElementTree.Element, reference: str, source: str):
    """Say once per tag and model what a <gazebo reference> tag that the bridge does not act on means."""
    where = f"{source}: <gazebo reference='{reference}'> <{child.tag}>"
    if child.tag in LINK_TAGS_USED:
        return
    if child.tag in LINK_TAGS_DEFAULT_ONLY:
        if (child.text or "").strip().lower() not in (LINK_TAGS_DEFAULT_ONLY[child.tag],
                                                      "0" if LINK_TAGS_DEFAULT_ONLY[child.tag] == "false" else "1"):
            warn_once(_logger, f"{where}{(child.text or '').strip()}</{child.tag}> is not simulated; "
                               "Gazebo's default applies")
    elif child.tag in LINK_TAGS_NO_EFFECT:
        warn_once(_logger, f"{where} has no Bullet counterpart; ignored")
    else:
        warn_once(_logger, f"{where} is not supported; ignored")


def _subtree(link_name, joints) -> List[str]:
    """``link_name`` and every link below it. It ends on any input: with one parent per link (checked by
    parse_robot) a loop cannot hang below the root."""
    names = [link_name]
    pending = [link_name]
    while pending:
        parent = pending.pop()
        children = [joint.child for joint in joints.values() if joint.parent == parent]
        names.extend(children)
        pending.extend(children)
    return names


def _drop_massless_moving_links(links, joints, source) -> List[str]:
    """Gazebo does not model a massless link on a moving joint; it drops it with its whole subtree."""
    dropped: List[str] = []
    for joint in list(joints.values()):
        if joint.name not in joints or joint.type == "fixed" or links[joint.child].has_inertial:
            continue
        subtree = _subtree(joint.child, joints)
        warn_once(_logger, f"{source}: link '{joint.child}' has no <inertial> but moves on joint '{joint.name}'; like "
                           f"Gazebo, the simulation leaves out it and its subtree ({', '.join(subtree)})")
        dropped.extend(subtree)
        for name in subtree:
            del links[name]
        for other in [j for j in joints.values() if j.child in subtree]:
            del joints[other.name]
    return dropped


def _lump_fixed_links(root_name, links, joints) -> Dict[str, Tuple[str, Pose]]:
    lumped = {root_name: (root_name, IDENTITY)}
    pending = [root_name]
    while pending:
        parent = pending.pop()
        body, offset = lumped[parent]
        for joint in joints.values():
            if joint.parent != parent:
                continue
            if joint.type == "fixed":
                lumped[joint.child] = (body, compose(offset, joint.origin))
            else:
                lumped[joint.child] = (joint.child, IDENTITY)
            pending.append(joint.child)
    return lumped


def _mesh_problem(filename: str) -> Optional[str]:
    """Why PyBullet could not read a URDF mesh file, or None. Nothing is opened: a FIFO would block the loader."""
    path = filename[len("file://"):] if filename.startswith("file://") else filename
    if "://" in path:
        return "only absolute paths, file:// and package:// (resolved by spawn_urdf_model) can be read"
    if not os.path.isabs(path):
        return "a relative path has nothing to be relative to in robot_description; use package:// or an absolute path"
    try:
        mode = os.stat(path).st_mode
    except OSError as error:
        return error.strerror or str(error)
    if not stat.S_ISREG(mode):
        return "not a regular file"
    if not os.access(path, os.R_OK):
        return "not readable"
    return None


def _shape_problem(element: ElementTree.Element) -> Optional[str]:
    """Why PyBullet could not build the shape of a <visual> or <collision>, or None. PyBullet refuses the whole
    URDF for it without saying where ("Cannot load URDF file"), or builds a shape from NaN."""
    geometry = element.find("geometry")
    shapes = [] if geometry is None else list(geometry)
    if len(shapes) != 1:
        found = ", ".join(f"<{shape.tag}>" for shape in shapes) or "none"
        return f"<geometry> needs one shape (box, cylinder, sphere or mesh), found {found}"
    shape = shapes[0]
    if shape.tag == "mesh":
        problem = _mesh_problem(shape.get("filename", ""))
        if problem is not None:
            return f"mesh '{shape.get('filename', '')}': {problem}"
        return _numbers_problem(shape, "scale", 3, optional=True, minimum=None)
    if shape.tag not in _SHAPE_SIZES:
        return f"<{shape.tag}> is not a URDF shape (box, cylinder, sphere or mesh)"
    for attribute, count in _SHAPE_SIZES[shape.tag]:
        problem = _numbers_problem(shape, attribute, count, optional=False, minimum=0.0)
        if problem is not None:
            return problem
    return None


def _numbers_problem(shape: ElementTree.Element, attribute: str, count: int, optional: bool,
                     minimum: Optional[float]) -> Optional[str]:
    text = shape.get(attribute)
    if text is None:
        return None if optional else f"<{shape.tag}> needs {attribute}"
    try:
        for value in parse_floats(text, count):
            check_range(abs(value) if minimum is None else value, minimum or 0.0, MAX_SHAPE_SIZE,
                        exclusive_minimum=True)
    except ValueError as error:
        return f"<{shape.tag} {attribute}>: {error}"
    return None


def _check_links(root: ElementTree.Element, copied: ElementTree.Element, document: XmlDocument, source: str):
    """Shapes, origins and inertials PyBullet could not load or that would make NaN. A bad collision refuses the
    model; a bad visual is left out of ``copied`` (the URDF PyBullet gets) with a warning: the simulation does
    not need it, and PyBullet would refuse the whole URDF for it."""
    for link, copied_link in zip(root.findall("link"), copied.findall("link")):
        _check_inertial(link.find("inertial"), document, f"{source}: link '{link.get('name')}'")
        for kind in ("collision", "visual"):
            for element, copied_element in zip(link.findall(kind), copied_link.findall(kind)):
                read_origin(element, document)
                problem = _shape_problem(element)
                if problem is None:
                    continue
                message = f"{source}: link '{link.get('name')}' {kind} {problem}"
                if kind == "collision":
                    raise ModelError(message)
                warn_once(_logger, message + "; the visual is left out")
                copied_link.remove(copied_element)


def _check_inertial(inertial: Optional[ElementTree.Element], document: XmlDocument, where: str):
    if inertial is None:
        return
    read_origin(inertial, document)
    inertia = inertial.find("inertia")
    if inertia is None:
        return
    for name in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz"):
        value = read_attribute_numbers(inertia, name, document, (0.0,), 1)[0]
        try:
            check_range(value if name in ("ixx", "iyy", "izz") else abs(value), 0.0, _MAX_INERTIA)
        except ValueError as error:
            raise ModelError(f"{where}: <inertia {name}>: {error}") from None


def _pybullet_urdf(root: ElementTree.Element, links, joints, dropped: List[str], lumped_into, separate,
                   document: XmlDocument, source: str) -> str:
    """The URDF handed to PyBullet: fixed joints lumped as Gazebo does (masses, visuals and collisions moved into
    the holder, a separate surface kept on a massless link of its own), no <gazebo>/<transmission>, dropped
    links removed, shapes, origins and inertials checked."""
    # Copied without the blocks PyBullet does not read: a description of 700,000 <gazebo> blocks is mostly them.
    checked = ElementTree.Element(root.tag, root.attrib)
    checked.extend(copy.deepcopy(element) for element in root if element.tag not in ("gazebo", "transmission"))
    _check_links(root, checked, document, source)
    elements = {element.get("name"): element for element in checked.findall("link")}
    robot = ElementTree.Element("robot", name=root.get("name") or "robot")
    robot.extend(checked.findall("material"))  # the named colours visuals refer to
    holders = {}
    for name, (holder, _) in lumped_into.items():
        if holder == name and name in links:
            holders[name] = ElementTree.SubElement(robot, "link", name=name)
    masses = {holder: [] for holder in holders}
    for name, (holder, offset) in lumped_into.items():
        if name not in links:
            continue
        element = elements[name]
        for visual in element.findall("visual"):
            _move(visual, offset, document)
            holders[holder].append(visual)
        if name in separate:
            # Its fixed joint's origin is the offset: the collisions keep their own origins.
            own = ElementTree.SubElement(robot, "link", name=name)
            _add_inertial(own, [])
            parent_joint = next(joint for joint in joints.values() if joint.child == name)
            _add_joint(robot, parent_joint.name, "fixed", holder, name, offset)
            own.extend(element.findall("collision"))
        else:
            for collision in element.findall("collision"):
                _move(collision, offset, document)
                holders[holder].append(collision)
        inertial = element.find("inertial")
        if links[name].has_inertial and inertial is not None:
            masses[holder].append((inertial, offset))
    for holder, parts in masses.items():
        _add_inertial(holders[holder], parts, document, f"{source}: link '{holder}'")
    for joint in joints.values():
        if joint.type == "fixed" or joint.child in dropped:
            continue
        holder, offset = lumped_into[joint.parent]
        if joint.free:
            _add_free_chain(robot, joint, holder, compose(offset, joint.origin))
            continue
        element = copy.deepcopy(next(e for e in checked.findall("joint") if e.get("name") == joint.name))
        element.find("parent").set("link", holder)
        _move(element, offset, document)
        robot.append(element)
    return pybullet_text(robot)


def pybullet_text(robot: ElementTree.Element) -> str:
    """``robot`` as text with one element per line. PyBullet's URDF reader misreads long lines: one-line chains of
    24 to 127 links were refused ("Cannot load URDF file", naming garbled elements such as ``inertia60``)."""
    ElementTree.indent(robot, space="")
    return ElementTree.tostring(robot, encoding="unicode")


def _add_free_chain(robot: ElementTree.Element, joint: Joint, holder: str, origin: Pose):
    """A planar or floating joint as a chain that holds nothing: prismatic x, y, z (no motor, see the engine)
    and a spherical joint between massless links, so the child moves as the free link sdformat makes it."""
    parent = holder
    for (link, prismatic), (_, axis) in zip(joint.free_chain(), FREE_CHAIN_AXES):
        _add_inertial(ElementTree.SubElement(robot, "link", name=link), [])
        element = _add_joint(robot, prismatic, "prismatic", parent, link, origin if parent == holder else IDENTITY)
        ElementTree.SubElement(element, "axis", xyz=axis)
        ElementTree.SubElement(element, "limit", lower=repr(-_FREE_CHAIN_REACH), upper=repr(_FREE_CHAIN_REACH),
                               effort="0", velocity="0")
        parent = link
    _add_joint(robot, joint.name, "spherical", parent, joint.child, IDENTITY)


def _move(element: ElementTree.Element, offset: Pose, document: XmlDocument):
    """``element``'s <origin> seen from ``offset``'s parent frame; left as written for the identity (PyBullet's
    transforms round to single precision)."""
    if offset != IDENTITY:
        _set_origin(element, compose(offset, read_origin(element, document)))


def _set_origin(element: ElementTree.Element, pose: Pose):
    for stale in element.findall("origin"):
        element.remove(stale)
    origin = ElementTree.Element("origin", xyz=" ".join(repr(v) for v in pose.position),
                                 rpy=" ".join(repr(v) for v in rpy(pose.orientation)))
    element.insert(0, origin)


def _add_joint(robot: ElementTree.Element, name: str, kind: str, parent: str, child: str,
               origin: Pose) -> ElementTree.Element:
    joint = ElementTree.SubElement(robot, "joint", name=name, type=kind)
    ElementTree.SubElement(joint, "parent", link=parent)
    ElementTree.SubElement(joint, "child", link=child)
    _set_origin(joint, origin)
    return joint


def _add_inertial(link: ElementTree.Element, parts, document: Optional[XmlDocument] = None, where: str = ""):
    """The combined inertial of ``parts`` ((<inertial>, pose of its link in ``link``'s frame)) about their common
    centre of mass, as sdformat lumps fixed joints; a negligible one when there is no mass (PyBullet would give
    1 kg and unit inertia). With mass, its principal moments must be at least _LEAST_MOMENT (``where`` names the
    link in the ModelError): checked after lumping, as a massive link without inertia fixed to another is fine."""
    total, centre, tensor = 0.0, np.zeros(3), np.zeros((3, 3))
    placed = []
    for inertial, offset in parts:
        mass = read_attribute_numbers(inertial.find("mass"), "value", document, (0.0,), 1)[0]
        pose = compose(offset, read_origin(inertial, document))
        values = {name: 0.0 for name in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")}
        if inertial.find("inertia") is not None:
            values = {name: read_attribute_numbers(inertial.find("inertia"), name, document, (0.0,), 1)[0]
                      for name in values}
        local = np.array([[values["ixx"], values["ixy"], values["ixz"]], [values["ixy"], values["iyy"], values["iyz"]],
                          [values["ixz"], values["iyz"], values["izz"]]])
        rotation = np.array(rotation_matrix(pose.orientation))
        placed.append((mass, np.array(pose.position), rotation @ local @ rotation.T))
        total += mass
        centre += mass * np.array(pose.position)
    element = ElementTree.SubElement(link, "inertial")
    if total <= 0.0:
        ElementTree.SubElement(element, "mass", value=repr(_NEGLIGIBLE_MASS))
        ElementTree.SubElement(element, "inertia", ixx=repr(_NEGLIGIBLE_INERTIA), iyy=repr(_NEGLIGIBLE_INERTIA),
                               izz=repr(_NEGLIGIBLE_INERTIA), ixy="0", ixz="0", iyz="0")
        return
    centre /= total
    for mass, position, rotated in placed:
        arm = position - centre
        tensor += rotated + mass * (arm @ arm * np.eye(3) - np.outer(arm, arm))
    moments = np.linalg.eigvalsh(tensor)
    if moments[0] < _LEAST_MOMENT:
        lumped = " with the links fixed to it" if len(parts) > 1 else ""
        raise ModelError(f"{where}{lumped}: <inertia> has principal moments {', '.join(f'{m:g}' for m in moments)} "
                         f"kg m^2 for a mass of {total:g} kg; each must be at least {_LEAST_MOMENT:g}")
    # Products far below the moments are rounding; PyBullet would turn them into a tiny rotation of the frame.
    tensor[np.abs(tensor) < 1e-12 * max(np.trace(tensor), _NEGLIGIBLE_INERTIA)] = 0.0
    ElementTree.SubElement(element, "origin", xyz=" ".join(repr(float(v)) for v in centre), rpy="0 0 0")
    ElementTree.SubElement(element, "mass", value=repr(total))
    ElementTree.SubElement(element, "inertia", **{name: repr(float(tensor[i, j])) for name, (i, j) in (
        ("ixx", (0, 0)), ("iyy", (1, 1)), ("izz", (2, 2)), ("ixy", (0, 1)), ("ixz", (0, 2)), ("iyz", (1, 2)))})


def _half_extents(geometry: Optional[ElementTree.Element]) -> Tuple[float, float, float]:
    """Half the size of a checked URDF shape along its own axes (a mesh: zero, its size is not read here)."""
    shape = geometry[0] if geometry is not None and len(geometry) else None
    if shape is None or shape.tag == "mesh":
        return (0.0, 0.0, 0.0)
    if shape.tag == "box":
        return tuple(value / 2.0 for value in parse_floats(shape.get("size", "0 0 0"), 3))
    radius = float(shape.get("radius", "0"))
    if shape.tag == "cylinder":
        return (radius, radius, float(shape.get("length", "0")) / 2.0)
    return (radius, radius, radius)
