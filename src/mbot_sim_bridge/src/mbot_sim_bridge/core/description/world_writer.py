"""The running world as an SDF 1.6 file: Gazebo's "File > Save world as", without ROS.

Every world model is written back the way it was read, at its pose now: an ``<include>`` stays an include of
the same ``<uri>`` with ``<name>`` and ``<pose>`` set; an inline ``<model>`` stays inline with its own links,
whose poses in the model frame do not change. A model with joints is written as read, and where its joints
stand now goes, as Gazebo saves it, into the world's ``<state>``: the world pose of each of its links (SDF has
no joint position in a model, and Gazebo's ModelState writes links only); reading the file sets the joints
from those poses.
Scene and the other non-model world elements are copied. Physics, gravity and lights are written as they
are now: set_physics_properties' settings, and each light as read unless set_light_properties changed it (then
a ``<light>`` with its values now, the sun's include too) or delete_light removed it. Robots spawned from URDF
are left out unless asked for; then each becomes an inline model converted the way Gazebo's URDF import does, at
its links' current poses, with its plugins kept as tags.
Model poses are written as world poses, so world ``<frame>``s are not needed and not written. The file is
SDF 1.6, or 1.7 when a model written back uses 1.7's ``relative_to``/``attached_to`` frames.
"""
import copy
import math
import os
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Dict, Iterable, List, Mapping, NamedTuple, Optional, Sequence, Union

from ..errors import WorldError
from ..geometry import Pose, compose, inverse, rpy
from ..lights import Light, light_name, read_light
from .robot_model import BALL_JOINT_TYPE, RobotModel
from .world_description import ArticulatedModel, ModelDescription, PhysicsConfig, WorldDescription

SDF_VERSION = "1.6"
# Frame semantics that came with 1.7; a copied model that uses them makes the file 1.7 (Gazebo 11 reads both).
_SDF_1_7_ATTRIBUTES = ("relative_to", "attached_to")
# sdformat's URDF import gives continuous joints these limits (SDF 1.6 has no "continuous" type).
_CONTINUOUS_LIMIT = 1e16
_GEOMETRY_SIZES = {"box": ("size",), "cylinder": ("radius", "length"), "sphere": ("radius",)}


@dataclass(frozen=True)
class SavedRobot:
    """A robot spawned from URDF, as it stands now: world pose of every URDF link the simulator kept."""
    name: str
    model: RobotModel
    link_poses: Mapping[str, Pose]


class WorldSnapshot(NamedTuple):
    # world models (the world file's and spawn_sdf_model's, those with joints too), in load order
    models: List[Union[ModelDescription, ArticulatedModel]]
    poses: Dict[str, Pose]  # model name -> world pose of its model frame now
    robots: List[SavedRobot]  # URDF robots, with the world pose of every URDF link now (when asked for)
    robot_names: List[str]  # every robot spawned from URDF, written or not
    link_states: Dict[str, Dict[str, Pose]]  # model with joints -> world pose of each of its links now
    physics: PhysicsConfig  # the settings in use
    lights: Dict[str, Light]  # the world's lights now, by name


def take_snapshot(simulation, with_robots: bool) -> WorldSnapshot:
    """What a save needs from a ``core.simulation.Simulation``, read in the thread that owns its engine."""
    engine = simulation.engine
    models = [model for name, model in simulation.world_models.items() if name in engine.model_names()]
    poses = {model.name: engine.model_pose(model.name) for model in models}
    # SDF models with joints run as robots; they are written back as read, at their model frame's pose now.
    link_states = {}
    for name, articulated in simulation.sdf_robots.items():
        models.append(articulated)
        poses[name] = compose(engine.model_pose(name), inverse(articulated.root_in_model))
        robot = simulation.models[name].robot
        link_states[name] = {link: robot.link_world_pose(link) for link in robot.model.lumped_into if link != "world"}
    urdf_robots = [name for name in simulation.models if name not in simulation.sdf_robots]
    robots = []
    if with_robots:
        for name in urdf_robots:
            spawned = simulation.models[name]
            robot = spawned.robot
            links = {link: robot.link_world_pose(link) for link in robot.model.lumped_into}
            robots.append(SavedRobot(name, robot.model, links))
    return WorldSnapshot(models, poses, robots, urdf_robots, link_states, engine.physics,
                         dict(simulation.lights.lights))


def pose_text(pose: Pose) -> str:
    """``x y z roll pitch yaw`` to the micrometre and microradian: PyBullet keeps poses in single precision,
    so more digits would only be its rounding (5.30000019 for 5.3)."""
    values = tuple(pose.position) + tuple(rpy(pose.orientation))
    return " ".join(_number(round(value, 6)) for value in values)


def _number(value: float) -> str:
    text = f"{value:.9g}"
    return "0" if text == "-0" else text


def world_sdf(world: WorldDescription, models: Sequence[Union[ModelDescription, ArticulatedModel]],
              poses: Mapping[str, Pose], robots: Sequence[SavedRobot] = (),
              link_states: Optional[Mapping[str, Mapping[str, Pose]]] = None,
              physics: Optional[PhysicsConfig] = None, lights: Optional[Mapping[str, Light]] = None) -> str:
    """The SDF text of ``world``'s settings with ``models`` at ``poses`` (model frames, world), ``robots``,
    ``link_states`` (world link poses of models with joints) as a ``<state>``, and ``physics`` and ``lights`` as
    they are now (None: as ``world`` has them)."""
    root = ET.Element("sdf", version=SDF_VERSION)
    element = ET.SubElement(root, "world", name=world.name)
    for other in world.others:
        name = light_name(other)
        if lights is None or name is None:
            element.append(copy.deepcopy(other))
        elif name in lights:  # a deleted light is left out
            light = lights[name]
            element.append(copy.deepcopy(other) if light == read_light(other) else _light(name, light))
    _physics(element, world.physics if physics is None else physics)
    base = os.path.dirname(os.path.abspath(world.path))
    main_models = {id(model) for model in world.models + world.robots}
    for model in models:
        if model.name not in poses:
            raise WorldError(f"no current pose for model '{model.name}'")
        # Relative file URIs of the loaded world pointed next to it; the saved file may live elsewhere.
        element.append(_model_element(model, poses[model.name], base if id(model) in main_models else None))
    for robot in robots:
        element.append(robot_model_element(robot))
    if link_states:
        element.append(_state(world.name, poses, link_states))
    if any(item.get(attribute) is not None for item in root.iter() for attribute in _SDF_1_7_ATTRIBUTES):
        root.set("version", "1.7")
    ET.indent(root, space="  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _state(world_name: str, poses: Mapping[str, Pose], link_states: Mapping[str, Mapping[str, Pose]]) -> ET.Element:
    """Gazebo's ``<state>`` (SDF state.sdf) of the models with joints: model and link world poses; a nested
    model's links ("inner::link") in a ``<model>`` of their own, as Gazebo's ModelState nests them."""
    state = ET.Element("state", world_name=world_name)
    for name, links in link_states.items():
        model = ET.SubElement(state, "model", name=name)
        ET.SubElement(model, "pose").text = pose_text(poses[name])
        for link, pose in links.items():
            parent = model
            *scopes, local = link.split("::")
            for scope in scopes:
                nested = parent.find(f"model[@name='{scope}']")
                parent = nested if nested is not None else ET.SubElement(parent, "model", name=scope)
            ET.SubElement(ET.SubElement(parent, "link", name=local), "pose").text = pose_text(pose)
    return state


def _light(name: str, light: Light) -> ET.Element:
    """A <light> with every value ``light`` has, so that reading it back gives ``light`` whatever the defaults."""
    element = ET.Element("light", name=name, type=light.type)
    ET.SubElement(element, "cast_shadows").text = "true" if light.cast_shadows else "false"
    ET.SubElement(element, "pose").text = pose_text(light.pose)
    ET.SubElement(element, "diffuse").text = " ".join(_number(value) for value in light.diffuse)
    ET.SubElement(element, "specular").text = " ".join(_number(value) for value in light.specular)
    attenuation = ET.SubElement(element, "attenuation")
    for tag, value in zip(("range", "constant", "linear", "quadratic"), (light.range, *light.attenuation)):
        ET.SubElement(attenuation, tag).text = _number(value)
    ET.SubElement(element, "direction").text = " ".join(_number(value) for value in light.direction)
    return element


def _physics(world: ET.Element, physics: PhysicsConfig):
    ET.SubElement(world, "gravity").text = " ".join(_number(value) for value in physics.gravity)
    element = ET.SubElement(world, "physics", name="default_physics", default="true", type="ode")
    ET.SubElement(element, "max_step_size").text = _number(physics.max_step_size)
    ET.SubElement(element, "real_time_factor").text = _number(physics.real_time_factor)
    ET.SubElement(element, "real_time_update_rate").text = _number(physics.real_time_update_rate)
    constraints = ET.SubElement(ET.SubElement(element, "ode"), "constraints")
    for tag in ("erp", "contact_max_correcting_vel", "contact_surface_layer"):
        ET.SubElement(constraints, tag).text = _number(getattr(physics, tag))


def _model_element(model: Union[ModelDescription, ArticulatedModel], pose: Pose, base: Optional[str]) -> ET.Element:
    if model.source is None:
        raise WorldError(f"model '{model.name}' was not read from SDF; it cannot be saved")
    element = copy.deepcopy(model.source)
    if element.tag == "include":
        _set_child(element, "name", model.name)
    else:
        element.set("name", model.name)
        if base is not None:
            _absolute_file_uris(element.iter("uri"), base)
    _set_child(element, "pose", pose_text(pose))
    return element


def _set_child(parent: ET.Element, tag: str, text: str):
    """Replace the text of ``parent``'s child ``tag`` (its attributes dropped), or add the child."""
    child = parent.find(tag)
    if child is None:
        child = ET.SubElement(parent, tag)
    child.attrib.clear()
    child.text = text


def _absolute_file_uris(uris: Iterable[ET.Element], base: str):
    for uri in uris:
        text = (uri.text or "").strip()
        path = text[len("file://"):] if text.startswith("file://") else text
        if path and "://" not in path and not os.path.isabs(path):
            candidate = os.path.normpath(os.path.join(base, path))
            # file://media/... names Gazebo's own resources, which are not next to the world file.
            if os.path.exists(candidate):
                uri.text = candidate


# --- URDF robots -------------------------------------------------------------------------------------------

def robot_model_element(robot: SavedRobot) -> ET.Element:
    """An inline SDF model of a URDF robot at its current link poses; its Gazebo plugins are copied as tags.

    Links keep their URDF names (no fixed-joint lumping: SDF has fixed joints), joints their types, axes and
    limits, links their ``<gazebo reference>`` sensors, friction and material.
    """
    model = robot.model
    urdf = model.document.root
    root_pose = robot.link_poses[model.root]
    element = ET.Element("model", name=robot.name)
    ET.SubElement(element, "pose").text = pose_text(root_pose)
    from_model = inverse(root_pose)
    for link in urdf.findall("link"):
        name = link.get("name", "")
        if name in robot.link_poses:
            element.append(_link(link, model, compose(from_model, robot.link_poses[name])))
    for joint in model.joints.values():
        # A planar or floating joint is none in Gazebo: its child is a free link of the model.
        if joint.parent in robot.link_poses and joint.child in robot.link_poses and not joint.free:
            element.append(_joint(joint))
    for plugin in model.plugins:
        element.append(copy.deepcopy(plugin))
    return element


def _link(urdf_link: ET.Element, model: RobotModel, pose: Pose) -> ET.Element:
    name = urdf_link.get("name", "")
    link = ET.Element("link", name=name)
    ET.SubElement(link, "pose").text = pose_text(pose)
    inertial = urdf_link.find("inertial")
    if inertial is not None:
        link.append(_inertial(inertial))
    known = model.links.get(name)
    gazebo = known.gazebo if known is not None else []
    mu = {tag: known.gazebo_tag(tag) if known is not None else None for tag in ("mu1", "mu2")}
    material = known.gazebo_tag("material") if known is not None else None
    for kind in ("collision", "visual"):
        for index, urdf_shape in enumerate(urdf_link.findall(kind)):
            shape = _shape(kind, urdf_shape, f"{name}_{kind}_{index}")
            if shape is None:
                continue
            if kind == "collision" and (mu["mu1"] or mu["mu2"]):
                ode = ET.SubElement(ET.SubElement(ET.SubElement(shape, "surface"), "friction"), "ode")
                ET.SubElement(ode, "mu").text = mu["mu1"] or mu["mu2"]
                ET.SubElement(ode, "mu2").text = mu["mu2"] or mu["mu1"]
            if kind == "visual":
                _visual_material(shape, urdf_shape.find("material"), material)
            link.append(shape)
    for block in gazebo:
        for sensor in block.findall("sensor"):
            link.append(copy.deepcopy(sensor))
    return link


def _origin_text(element: ET.Element) -> str:
    origin = element.find("origin")
    xyz = origin.get("xyz", "0 0 0") if origin is not None else "0 0 0"
    rpy_text = origin.get("rpy", "0 0 0") if origin is not None else "0 0 0"
    return " ".join(xyz.split() + rpy_text.split())


def _inertial(urdf: ET.Element) -> ET.Element:
    inertial = ET.Element("inertial")
    ET.SubElement(inertial, "pose").text = _origin_text(urdf)
    mass = urdf.find("mass")
    ET.SubElement(inertial, "mass").text = mass.get("value", "1") if mass is not None else "1"
    tensor = urdf.find("inertia")
    inertia = ET.SubElement(inertial, "inertia")
    for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
        ET.SubElement(inertia, key).text = tensor.get(key, "0") if tensor is not None else "0"
    return inertial


def _shape(kind: str, urdf: ET.Element, default_name: str) -> Optional[ET.Element]:
    geometry = urdf.find("geometry")
    shape_element = next(iter(geometry), None) if geometry is not None else None
    if shape_element is None:
        return None
    shape = ET.Element(kind, name=urdf.get("name") or default_name)
    ET.SubElement(shape, "pose").text = _origin_text(urdf)
    sdf_geometry = ET.SubElement(ET.SubElement(shape, "geometry"), shape_element.tag)
    if shape_element.tag == "mesh":
        filename = shape_element.get("filename", "")
        ET.SubElement(sdf_geometry, "uri").text = "file://" + filename if filename.startswith("/") else filename
        if shape_element.get("scale"):
            ET.SubElement(sdf_geometry, "scale").text = shape_element.get("scale")
    else:
        for attribute in _GEOMETRY_SIZES.get(shape_element.tag, ()):
            ET.SubElement(sdf_geometry, attribute).text = shape_element.get(attribute, "1")
    return shape


def _visual_material(visual: ET.Element, urdf_material: Optional[ET.Element], gazebo_material: Optional[str]):
    """A Gazebo material script (the <gazebo reference> one wins, as in Gazebo) or the URDF colour."""
    if gazebo_material:
        script = ET.SubElement(ET.SubElement(visual, "material"), "script")
        ET.SubElement(script, "uri").text = "file://media/materials/scripts/gazebo.material"
        ET.SubElement(script, "name").text = gazebo_material
        return
    colour = urdf_material.find("color") if urdf_material is not None else None
    if colour is not None and colour.get("rgba"):
        material = ET.SubElement(visual, "material")
        ET.SubElement(material, "ambient").text = colour.get("rgba")
        ET.SubElement(material, "diffuse").text = colour.get("rgba")


def _joint(joint) -> ET.Element:
    kind = {"continuous": "revolute", BALL_JOINT_TYPE: "ball"}.get(joint.type, joint.type)
    element = ET.Element("joint", name=joint.name, type=kind)
    ET.SubElement(element, "parent").text = joint.parent
    ET.SubElement(element, "child").text = joint.child
    if joint.type == "fixed":
        return element
    axis = ET.SubElement(element, "axis")
    # URDF's axis is in the joint frame, which is the child link frame: SDF 1.6's default for <xyz>.
    ET.SubElement(axis, "xyz").text = " ".join(_number(value) for value in joint.axis)
    limit = ET.SubElement(axis, "limit")
    lower = -_CONTINUOUS_LIMIT if joint.type == "continuous" or math.isinf(joint.lower) else joint.lower
    upper = _CONTINUOUS_LIMIT if joint.type == "continuous" or math.isinf(joint.upper) else joint.upper
    ET.SubElement(limit, "lower").text = _number(lower)
    ET.SubElement(limit, "upper").text = _number(upper)
    if joint.effort > 0.0:
        ET.SubElement(limit, "effort").text = _number(joint.effort)
    if joint.velocity > 0.0:
        ET.SubElement(limit, "velocity").text = _number(joint.velocity)
    return element


# --- Writing -----------------------------------------------------------------------------------------------

def write_world_file(path: str, text: str):
    """Write ``text`` to ``path`` all at once: a temp file in the same directory, renamed over ``path``.

    Raises WorldError with one line when the directory cannot be written; no partial file is left.
    """
    path = os.path.abspath(path)
    directory = os.path.dirname(path)
    temporary = None
    try:
        handle, temporary = tempfile.mkstemp(prefix=f".{os.path.basename(path)}.", suffix=".tmp", dir=directory)
        with os.fdopen(handle, "w") as output:
            output.write(text)
        os.chmod(temporary, 0o644)
        os.replace(temporary, path)
    except OSError as error:
        if temporary is not None and os.path.exists(temporary):
            os.unlink(temporary)
        raise WorldError(f"cannot write {path}: {error.strerror or error}") from None
