"""joint_limits_interface: limits from the URDF joint (``RobotModel``, read and checked there) and from the
``joint_limits/<joint>`` parameters, which override them; soft limits from the URDF's <safety_controller>."""
import math
from dataclasses import dataclass
from typing import Optional

from ..log import get_logger, warn_once
from ..description.robot_model import Joint

_logger = get_logger(__name__)


@dataclass
class JointLimits:
    """joint_limits_interface::JointLimits."""
    has_position_limits: bool = False
    min_position: float = -math.inf
    max_position: float = math.inf
    has_velocity_limits: bool = False
    max_velocity: float = 0.0
    has_acceleration_limits: bool = False
    max_acceleration: float = 0.0
    has_jerk_limits: bool = False
    max_jerk: float = 0.0
    has_effort_limits: bool = False
    max_effort: float = 0.0
    angle_wraparound: bool = False


@dataclass
class SoftJointLimits:
    """joint_limits_interface::SoftJointLimits."""
    min_position: float
    max_position: float
    k_position: float
    k_velocity: float


def urdf_soft_joint_limits(joint: Optional[Joint]) -> Optional[SoftJointLimits]:
    """joint_limits_interface::getSoftJointLimits(urdf joint): None without a <safety_controller>."""
    return SoftJointLimits(*joint.safety) if joint is not None and joint.safety is not None else None


def urdf_joint_limits(joint: Optional[Joint]) -> Optional[JointLimits]:
    """joint_limits_interface::getJointLimits(urdf joint): None when the joint has no <limit>."""
    if joint is None or not joint.has_limit:
        return None
    limits = JointLimits()
    limits.has_position_limits = joint.type in ("revolute", "prismatic")
    if limits.has_position_limits:
        limits.min_position, limits.max_position = joint.lower, joint.upper
    elif joint.type == "continuous":
        limits.angle_wraparound = True
    limits.has_velocity_limits, limits.max_velocity = True, joint.velocity
    limits.has_effort_limits, limits.max_effort = True, joint.effort
    return limits


_LIMIT_PAIRS = (("has_position_limits", ("min_position", "max_position")), ("has_velocity_limits", ("max_velocity",)),
                ("has_acceleration_limits", ("max_acceleration",)), ("has_jerk_limits", ("max_jerk",)),
                ("has_effort_limits", ("max_effort",)))


def apply_limit_params(limits: Optional[JointLimits], params: Optional[dict], joint: str) -> Optional[JointLimits]:
    """joint_limits_interface::getJointLimits(name, nh): ``joint_limits/<joint>/...`` parameters override."""
    if not params:
        return limits
    if not isinstance(params, dict):
        warn_once(_logger, f"joint_limits/{joint} is not a dictionary; ignored")
        return limits
    limits = limits or JointLimits()
    for flag, values in _LIMIT_PAIRS:
        if flag in params:
            setattr(limits, flag, bool(params[flag]))
            if params[flag]:
                for name in values:
                    if name in params:
                        setattr(limits, name, float(params[name]))
    if "angle_wraparound" in params and not limits.has_position_limits:
        limits.angle_wraparound = bool(params["angle_wraparound"])
    return limits
