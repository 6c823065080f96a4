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
