"""The Twist a marker pose asks for, as upstream's marker_server computes it (ros-visualization/
interactive_marker_twist_server, kinetic-devel): angular.z = angular_scale * yaw, linear.<axis> =
linear_scale[axis] * position.<axis> for the axes configured, each clamped to its limits. Without rospy."""
import math
from dataclasses import dataclass, field
from typing import Dict, Optional, Tuple

AXES = ("x", "y", "z")


@dataclass
class Scales:
    linear: Dict[str, float] = field(default_factory=lambda: {"x": 1.0})
    max_positive_linear: Dict[str, float] = field(default_factory=lambda: {"x": 1.0})
    max_negative_linear: Dict[str, float] = field(default_factory=lambda: {"x": -1.0})
    angular: float = 2.2
    max_angular: float = 2.2


def yaw(x: float, y: float, z: float, w: float) -> float:
    """tf::getYaw: the yaw of the ZYX Euler angles of the normalized quaternion."""
    norm = x * x + y * y + z * z + w * w
    return math.atan2(2.0 * (w * z + x * y) / norm, 1.0 - 2.0 * (y * y + z * z) / norm)


def _clamp(value: float, low: float, high: float) -> float:
    return max(min(value, high), low)


def twist_values(scales: Scales, position: Tuple[float, float, float],
                 orientation: Tuple[float, float, float, float]) -> Tuple[Dict[str, float], float]:
    """(linear values by axis, angular.z). Upstream clamps against the max first, then the min; so does this."""
    angular = _clamp(scales.angular * yaw(*orientation), -scales.max_angular, scales.max_angular)
    linear = {}
    for axis, value in zip(AXES, position):
        if axis in scales.linear:
            linear[axis] = max(min(scales.linear[axis] * value, scales.max_positive_linear[axis]),
                               scales.max_negative_linear[axis])
    return linear, angular


# Metres of marker offset beyond any drag in rviz: such a pose still gives the clamped Twist, as upstream's does, but
# is said once, as a sign of a client sending something else than a dragged marker.
HUGE_OFFSET = 1.0e4


def huge_offset(position) -> Optional[str]:
    """The first position value beyond HUGE_OFFSET in magnitude, described, else None."""
    for name, value in zip(("position.x", "position.y", "position.z"), position):
        if abs(value) > HUGE_OFFSET:
            return f"{name} is {value:g}, beyond {HUGE_OFFSET:g} m"
    return None


def pose_problem(position, orientation) -> Optional[str]:
    """Why a feedback pose cannot give a Twist (a NaN or infinite value, or a zero quaternion), else None."""
    names = ("position.x", "position.y", "position.z", "orientation.x", "orientation.y", "orientation.z",
             "orientation.w")
    for name, value in zip(names, tuple(position) + tuple(orientation)):
        if not math.isfinite(value):
            return f"{name} is {value}"
    norm = sum(float(value) * value for value in orientation)
    if not 0.0 < norm < math.inf:
        return f"the orientation's squared norm is {norm}"
    return None
