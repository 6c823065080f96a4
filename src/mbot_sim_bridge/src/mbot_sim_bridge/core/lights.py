"""The world's lights, as gazebo_ros's get/set_light_properties and delete_light see them: every ``<light>`` of the
world file and the sun of an ``<include>`` of model://sun, kept and editable by name.

Nothing renders them: the camera images are lit by the camera's own light (README), so an edited or deleted light
changes what the services answer, nothing else. Gazebo keeps lights across reset_world and reset_simulation, and
so do these.
"""
import math
from typing import Dict, NamedTuple, Optional, Sequence, Tuple
from xml.etree import ElementTree

from .engine import check_state
from .errors import ModelError
from .geometry import IDENTITY, Pose, Vector, pose_from_xyz_rpy
from .log import get_logger, warn_once
from .xml_values import parse_bool, parse_floats

_logger = get_logger(__name__)

# A colour component, attenuation factor or direction component beyond this is a typo, not a light.
MAX_LIGHT_VALUE = 1e6

Colour = Tuple[float, float, float, float]


class Light(NamedTuple):
    type: str  # point, directional or spot
    cast_shadows: bool
    diffuse: Colour
    specular: Colour
    attenuation: Tuple[float, float, float]  # constant, linear, quadratic
    range: float
    direction: Vector
    pose: Pose  # in the world


# SDF's <light> defaults, and Gazebo's model://sun (its model database's sun/model.sdf).
SDF_LIGHT = Light("point", False, (1.0, 1.0, 1.0, 1.0), (0.1, 0.1, 0.1, 1.0), (1.0, 1.0, 0.0), 10.0,
                  (0.0, 0.0, -1.0), IDENTITY)
SUN = Light("directional", True, (0.8, 0.8, 0.8, 1.0), (0.2, 0.2, 0.2, 1.0), (0.9, 0.01, 0.001), 1000.0,
            (-0.5, 0.1, -0.9), Pose((0.0, 0.0, 10.0), IDENTITY.orientation))


def world_lights(elements: Sequence[ElementTree.Element]) -> Dict[str, Light]:
    """The lights among a world's other children (WorldDescription.others), by name."""
    return {name: read_light(element) for element in elements for name in [light_name(element)] if name is not None}


def light_name(element: ElementTree.Element) -> Optional[str]:
    """The name of the light a world's child is (a <light>, or an <include> of model://sun), else None."""
    if element.tag == "light":
        return element.get("name", "")
    if element.tag == "include" and (element.findtext("uri") or "").strip().rstrip("/") == "model://sun":
        return (element.findtext("name") or "sun").strip()
    return None


def read_light(element: ElementTree.Element) -> Light:
    """The light a <light> or model://sun <include> describes, with SDF's or the sun's defaults for what it leaves
    out; a bad value is said once and the default kept."""
    light = SUN if element.tag == "include" else SDF_LIGHT._replace(type=element.get("type", "point"))
    def read(path: str, parse, default, what: str):
        text = element.findtext(path)
        if text is None:
            return default
        try:
            return parse(text)
        except ValueError:
            warn_once(_logger, f"light '{element.get('name', element.findtext('name'))}': <{path}> '{text.strip()}' "
                               f"is not {what}; the default {default} is kept")
            return default

    def values(path: str, count: int, default):
        return read(path, lambda text: parse_floats(text, count)[0 if count == 1 else slice(None)], default,
                    f"{count} numbers")
    pose = values("pose", 6, None)
    return light._replace(
        cast_shadows=read("cast_shadows", parse_bool, light.cast_shadows, "true or false"),
        diffuse=values("diffuse", 4, light.diffuse), specular=values("specular", 4, light.specular),
        attenuation=(values("attenuation/constant", 1, light.attenuation[0]),
                     values("attenuation/linear", 1, light.attenuation[1]),
                     values("attenuation/quadratic", 1, light.attenuation[2])),
        range=values("attenuation/range", 1, light.range), direction=values("direction", 3, light.direction),
        pose=light.pose if pose is None else pose_from_xyz_rpy(pose[:3], pose[3:]))


class Lights:
    def __init__(self, lights: Dict[str, Light]):
        self.lights = dict(lights)

    def get(self, name: str) -> Light:
        return self._named(name, "getLightProperties")

    def set(self, name: str, cast_shadows: bool, diffuse: Colour, specular: Colour,
            attenuation: Tuple[float, float, float], direction: Vector, pose: Pose):
        """set_light_properties: what upstream's request replaces (its type and range stay); ModelError naming the
        value for one that is not finite or beyond MAX_LIGHT_VALUE, or a pose Bullet's world could not hold."""
        light = self._named(name, "setLightProperties")
        for field, numbers in (("diffuse", diffuse), ("specular", specular), ("attenuation", attenuation),
                               ("direction", direction)):
            if not all(math.isfinite(value) and abs(value) <= MAX_LIGHT_VALUE for value in numbers):
                raise ModelError(f"setLightProperties: light '{name}': {field} must be finite and at most "
                                 f"{MAX_LIGHT_VALUE:g} in size; got {tuple(numbers)}")
        check_state(f"setLightProperties: light '{name}'", pose)
        self.lights[name] = light._replace(cast_shadows=bool(cast_shadows), diffuse=tuple(diffuse),
                                           specular=tuple(specular), attenuation=tuple(attenuation),
                                           direction=tuple(direction), pose=pose)

    def delete(self, name: str):
        if self.lights.pop(name, None) is None:
            raise ModelError(f"DeleteLight: Requested light {name} not found!")

    def _named(self, name: str, service: str) -> Light:
        light: Optional[Light] = self.lights.get(name)
        if light is None:
            raise ModelError(f"{service}: Requested light {name} not found!")
        return light
