"""The ``angles`` package's functions the controllers and the hardware simulation use."""
import math


def normalize_angle(angle: float) -> float:
    """Into (-pi, pi], with upstream's fmod (exact, where atan2(sin, cos) rounds)."""
    result = math.fmod(angle + math.pi, 2 * math.pi)
    return result + math.pi if result <= 0.0 else result - math.pi


def shortest_angular_distance(start: float, end: float) -> float:
    return normalize_angle(end - start)


def shortest_angular_distance_with_limits(start: float, end: float, lower: float, upper: float) -> float:
    """angles::shortest_angular_distance_with_large_limits: the way from start to end that stays within the
    limits (which may span more than a turn); the plain shortest distance when neither way is free."""
    if lower > upper:
        return shortest_angular_distance(start, end)
    delta = shortest_angular_distance(start, end)
    other = delta - math.copysign(2 * math.pi, delta) if delta != 0 else 0.0
    for candidate in sorted((delta, other), key=abs):
        if lower <= start + candidate <= upper:
            return candidate
    return delta


def position_error(joint_type: str, current: float, target: float, lower: float, upper: float) -> float:
    """How far a joint of URDF ``joint_type`` is from ``target``, as ros_controllers' position controllers and
    gazebo_ros_control's PID take it: within the limits for a revolute joint, the shortest way round for a
    continuous one, the plain difference otherwise."""
    if joint_type == "revolute":
        return shortest_angular_distance_with_limits(current, target, lower, upper)
    if joint_type == "continuous":
        return shortest_angular_distance(current, target)
    return target - current
