"""spawn_sdf_model's input -> a one-model SDF world the world loader reads.

gazebo_ros accepts ``<sdf><model>`` (spawn_model -file/-param) and ``<sdf><world><include>`` (what
spawn_model -database sends). The model is renamed to the requested name and placed at the requested pose
composed with its own, as spawn_sdf_model does; a ``robot_namespace`` goes into every plugin without a
``<robotNamespace>``, sensor plugins included, as gazebo_ros does for SDF and URDF alike.
"""
import tempfile
from typing import Optional, Sequence
from xml.etree import ElementTree

from ..errors import ModelError
from ..geometry import Pose, compose, rpy
from ..xml_values import parse_xml, read_pose
from .sdf_world import parse_world
from .world_description import WorldDescription


def _pose_text(pose: Pose) -> str:
    return " ".join(f"{value:.9g}" for value in tuple(pose.position) + tuple(rpy(pose.orientation)))


def _set_pose(element: ElementTree.Element, pose: Pose):
    existing = element.find("pose")
    if existing is None:
        existing = ElementTree.SubElement(element, "pose")
    existing.text = _pose_text(pose)


def spawn_world_xml(model_xml: str, name: str, pose: Pose, robot_namespace: str = "") -> str:
    where = f"model '{name}'"
    document = parse_xml(model_xml.encode(), where, ModelError)
    root = document.root
    if root.tag != "sdf":
        raise ModelError(f"{where} is not SDF: its root element is <{root.tag}>, not <sdf>")
    worlds = root.findall("world")
    if len(worlds) > 1:
        raise ModelError(f"{where}: {len(worlds)} <world> elements; one is read (gazebo_ros takes the first, however "
                         "empty)")
    world = root.find("world")
    entries = (world.findall("model") + world.findall("include")) if world is not None else root.findall("model")
    if len(entries) != 1:
        raise ModelError(f"{where}: expected exactly one <model> (or one <include> in a <world>), found {len(entries)}")
    entry = entries[0]
    if entry.tag == "model":
        entry.set("name", name)
    else:
        name_element = entry.find("name")
        if name_element is None:
            name_element = ElementTree.SubElement(entry, "name")
        name_element.text = name
    _set_pose(entry, compose(pose, read_pose(entry.find("pose"), document)))
    if robot_namespace:
        for plugin in entry.iter("plugin"):
            if plugin.find("robotNamespace") is None:
                ElementTree.SubElement(plugin, "robotNamespace").text = robot_namespace
    spawned = ElementTree.Element("sdf", version=root.get("version", "1.6"))
    ElementTree.SubElement(spawned, "world", name="spawn").append(entry)
    return ElementTree.tostring(spawned, encoding="unicode")


def read_spawned_model(model_xml: str, name: str, pose: Pose, robot_namespace: str = "",
                       model_path: Optional[Sequence[str]] = None) -> WorldDescription:
    """spawn_sdf_model's input read as the one-model world the simulation adds, without touching the simulation,
    so that a service thread reads it while the loop steps on. ModelError for a model with nothing to simulate,
    naming what was left out of it (a mesh or an <include> not found)."""
    # The world loader reads files (relative URIs resolve against them); a private temp file holds it.
    with tempfile.NamedTemporaryFile("w", prefix="mbot_spawn_", suffix=".world") as world_file:
        world_file.write(spawn_world_xml(model_xml, name, pose, robot_namespace))
        world_file.flush()
        description = parse_world(world_file.name, model_path)
    if not any(model.name == name and model.shapes for model in description.models) and not description.robots:
        reasons = "".join(f"; {reason}" for reason in description.left_out)
        raise ModelError(f"model '{name}' has no collision geometry; nothing to simulate{reasons}")
    return description


def spawned_pose(description: WorldDescription, name: str) -> Pose:
    """Where the model ``read_spawned_model`` read is placed: the request's pose composed with the model's own."""
    return next(model.pose for model in description.models + description.robots if model.name == name)
