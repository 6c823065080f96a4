"""transmission_interface's TransmissionParser: ``<transmission>`` with ``<type>``, ``<joint>`` (with
``<hardwareInterface>``) and ``<actuator>`` (``<hardwareInterface>``, the old placement, and
``<mechanicalReduction>``), read from ``RobotModel.transmissions``."""
from dataclasses import dataclass
from typing import Callable, List, Optional, Sequence, Tuple
from xml.etree import ElementTree

from ..errors import ConfigError
from ..log import get_logger, warn_once
from ..xml_values import parse_float

_logger = get_logger(__name__)


SIMPLE_TRANSMISSION = "transmission_interface/SimpleTransmission"


@dataclass
class Transmission:
    name: str
    type: str
    joints: List[Tuple[str, List[str]]]  # (joint name, its hardware interfaces)
    actuators: List[Tuple[str, List[str], Optional[float]]]  # (name, hardware interfaces, mechanicalReduction)


def _interfaces(element: ElementTree.Element) -> List[str]:
    return [(child.text or "").strip() for child in element.findall("hardwareInterface") if (child.text or "").strip()]


def parse_transmissions(elements: Sequence[ElementTree.Element],
                        where: Callable[[ElementTree.Element], str]) -> List[Transmission]:
    """A URDF's ``<transmission>`` elements (``RobotModel.transmissions``), as transmission_interface's parser
    reads them.

    Like upstream, a transmission without a name, type, joint or actuator is skipped with an error message;
    a bad ``mechanicalReduction`` is a ConfigError (the simple transmission loader would refuse it).
    """
    transmissions = []
    for element in elements:
        name = element.get("name")
        type_element = element.find("type")
        kind = (type_element.text or "").strip() if type_element is not None else ""
        joints = [(joint.get("name"), _interfaces(joint)) for joint in element.findall("joint")]
        actuators = []
        for actuator in element.findall("actuator"):
            reduction = actuator.find("mechanicalReduction")
            value = None
            if reduction is not None:
                try:
                    value = parse_float(reduction.text or "")
                except ValueError:
                    raise ConfigError(f"{where(reduction)}: transmission '{name}': <mechanicalReduction> "
                                      f"'{(reduction.text or '').strip()}' is not a number") from None
            actuators.append((actuator.get("name"), _interfaces(actuator), value))
        problem = ("has no name" if not name else "has no <type>" if not kind
                   else "has no <joint>" if not joints or not all(joint for joint, _ in joints)
                   else "has no <actuator>" if not actuators else None)
        if problem:
            _logger.error(f"{where(element)}: transmission '{name}' {problem}; skipped, as "
                          "transmission_interface's parser does")
            continue
        if kind != SIMPLE_TRANSMISSION:
            warn_once(_logger, f"{where(element)}: transmission '{name}' has type '{kind}'; the default robot hardware "
                               "simulation uses only its joint and hardware interface, as gazebo_ros_control does")
        transmissions.append(Transmission(name, kind, joints, actuators))
    return transmissions
