"""What the plugins that sense one body share (the two IMUs, hector's IMU, p3d, f3d and the force-torque sensor):
the link Gazebo keeps for a lumped body, the offset tags, and how seldom an every-step one looks while idle."""
import xml.etree.ElementTree as ET
from typing import Optional, Tuple

from ..errors import ConfigError
from ..geometry import Pose, Vector
from ..xml_values import parse_floats

# Sim seconds between looks at an every-step plugin (updateRate 0) while nothing subscribes: Gazebo computes
# nothing then either, and a timer due on every step would keep the loop at one physics step per pass.
IDLE_PERIOD = 0.05


def read_vector_param(element: ET.Element, tag: str, label: str, where: str) -> Optional[Vector]:
    """A three-number tag (xyzOffset, rpyOffset) or None when absent; ConfigError naming it when bad."""
    child = element.find(tag)
    if child is None or not (child.text or "").strip():
        return None
    try:
        return parse_floats(child.text, 3)
    except ValueError as error:
        raise ConfigError(f"{where}: {label}: <{tag}> has bad value '{child.text.strip()}': {error}") from None


def gazebo_body(robot, name: str) -> Tuple[str, Pose]:
    """The link Gazebo keeps for URDF link ``name`` (fixed joints lumped) and ``name``'s pose in it."""
    return robot.model.lumped_into[name]
