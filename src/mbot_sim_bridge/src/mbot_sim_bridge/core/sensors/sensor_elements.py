"""What every Gazebo ``<sensor>`` has, read one way for the lidar, the cameras and the IMU: its name, its
``<pose>`` on the link, and whether a ``<noise>`` block is one the bridge simulates (gaussian)."""
import xml.etree.ElementTree as ET
from typing import Tuple

from ..errors import BridgeError, ConfigError
from ..geometry import Pose
from ..log import get_logger, warn_once
from ..xml_values import XmlDocument, read_pose

_log = get_logger(__name__)


def sensor_label(sensor: ET.Element, kind: str, link: str, document: XmlDocument) -> Tuple[str, str, str]:
    """(name, where, label) of a ``<sensor>``: "lidar 'scan' on link 'laser_link'"; a nameless one is refused."""
    name = sensor.get("name")
    where = document.where(sensor)
    if not name:
        raise ConfigError(f"{where}: a <sensor> on link '{link}' has no name")
    return name, where, f"{kind} '{name}' on link '{link}'"


def sensor_pose(sensor: ET.Element, document: XmlDocument, where: str, label: str) -> Pose:
    """The sensor's ``<pose>`` in its link's frame (identity when absent); a bad one names the sensor."""
    try:
        return read_pose(sensor.find("pose"), document)
    except BridgeError as error:
        raise ConfigError(f"{where}: {label}: {str(error).split(': ', 1)[1]}") from None


def gaussian_noise(noise: ET.Element, noise_type: str, where: str, what: str) -> bool:
    """Whether a ``<noise>`` element (None: absent) of ``noise_type`` is simulated: gaussian is, none is
    nothing to do, and any other type warns once that ``what`` stays noise-free."""
    if noise is None or noise_type == "none":
        return False
    if noise_type != "gaussian":
        warn_once(_log, f"{where}: <noise><type> '{noise_type}' is not supported (only gaussian is); {what} is "
                        "noise-free")
        return False
    return True
