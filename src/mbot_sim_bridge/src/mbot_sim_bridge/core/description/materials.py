"""Gazebo's material names -> RGBA, for the simulator window.

Diffuse colours of gazebo-classic's ``media/materials/scripts/gazebo.material``. Textured materials (wood,
bricks, grass ...) get the average colour of their texture, since the window draws flat colours.
"""
from typing import Optional, Tuple
from xml.etree import ElementTree

RGBA = Tuple[float, float, float, float]

GAZEBO_MATERIALS = {
    "Gazebo/Grey": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/Gray": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/DarkGrey": (0.175, 0.175, 0.175, 1.0),
    "Gazebo/DarkGray": (0.175, 0.175, 0.175, 1.0),
    "Gazebo/White": (1.0, 1.0, 1.0, 1.0),
    "Gazebo/FlatBlack": (0.1, 0.1, 0.1, 1.0),
    "Gazebo/Black": (0.0, 0.0, 0.0, 1.0),
    "Gazebo/Red": (1.0, 0.0, 0.0, 1.0),
    "Gazebo/RedBright": (0.87, 0.26, 0.07, 1.0),
    "Gazebo/Green": (0.0, 1.0, 0.0, 1.0),
    "Gazebo/Blue": (0.0, 0.0, 1.0, 1.0),
    "Gazebo/SkyBlue": (0.0, 0.0, 1.0, 1.0),
    "Gazebo/Yellow": (1.0, 1.0, 0.0, 1.0),
    "Gazebo/ZincYellow": (0.9725, 0.9529, 0.2078, 1.0),
    "Gazebo/DarkYellow": (0.7, 0.7, 0.0, 1.0),
    "Gazebo/Orange": (1.0, 0.5088, 0.0468, 1.0),
    "Gazebo/Purple": (1.0, 0.0, 1.0, 1.0),
    "Gazebo/Turquoise": (0.0, 1.0, 1.0, 1.0),
    "Gazebo/Indigo": (0.33, 0.0, 0.5, 1.0),
    "Gazebo/Gold": (0.8, 0.6487, 0.1208, 1.0),
    "Gazebo/Wood": (0.55, 0.38, 0.22, 1.0),
    "Gazebo/WoodFloor": (0.6, 0.45, 0.3, 1.0),
    "Gazebo/WoodPallet": (0.6, 0.5, 0.35, 1.0),
    "Gazebo/Bricks": (0.6, 0.3, 0.22, 1.0),
    "Gazebo/Grass": (0.3, 0.55, 0.2, 1.0),
    "Gazebo/Road": (0.25, 0.25, 0.25, 1.0),
    "Gazebo/Residential": (0.75, 0.7, 0.6, 1.0),
    "Gazebo/CeilingTiled": (0.85, 0.85, 0.85, 1.0),
    "Gazebo/PaintedWall": (0.9, 0.88, 0.8, 1.0),
}


def gazebo_material_rgba(name: str) -> Optional[RGBA]:
    return GAZEBO_MATERIALS.get(name.strip())


def sdf_material_rgba(material: Optional[ElementTree.Element]) -> Optional[RGBA]:
    """An SDF ``<material>``: its ``<script><name>`` if Gazebo knows it, else ``<diffuse>``, else ``<ambient>``."""
    if material is None:
        return None
    name = material.findtext("script/name")
    if name and gazebo_material_rgba(name):
        return gazebo_material_rgba(name)
    for tag in ("diffuse", "ambient"):
        text = material.findtext(tag)
        if text:
            try:
                values = [float(value) for value in text.split()]
            except ValueError:
                return None
            if len(values) in (3, 4):
                return tuple(values[:3]) + (values[3] if len(values) == 4 else 1.0,)
    return None


def colour_robot(robot):
    """Gazebo materials on a robot's links, as the simulator window shows them (the heaviest of lumped links
    decides, since PyBullet colours a link's visuals as a whole)."""
    colours = {}
    for link in robot.model.links.values():
        rgba = gazebo_material_rgba(link.gazebo_tag("material") or "")
        if rgba is None or link.name not in robot.model.lumped_into:
            continue
        index = robot.link_index[robot.model.lumped_into[link.name][0]]
        if index not in colours or link.mass > colours[index][0]:
            colours[index] = (link.mass, rgba)
    for index, (_, rgba) in colours.items():
        robot.client.changeVisualShape(robot.body, index, rgbaColor=rgba)
