"""Wheel-ground friction computed by the bridge: Coulomb friction in the wheel's own frame, at its mid-plane.

A multibody's friction in Bullet acts along two directions fixed by the contact normal alone (btPlaneSpace1), so
on flat ground along world x and y, each limited by mu*N: a wheel sliding diagonally gets up to 1.41 times the
grip, and a skid-steer base turning in place speeds up and slows down with its heading (every 90 degrees). ODE
does the same unless the wheel sets ``fdir1``, which turns the friction directions with the wheel. So a wheel (a
link whose collisions are cylinders about its joint's axis; ``RobotModel.wheels``) that carries ``fdir1`` gets
no Bullet friction: before every step each of its contacts gets the force computed here, from the normal force
Bullet found at the last step, at the contact moved along the axle to the wheel's mid-plane (where Bullet's
tread touches, see robot_model._with_treads). Along ``fdir1`` (in the wheel's frame, seen in the contact plane)
the limit is mu1*N and across it mu2*N, on an ellipse (Coulomb's circle when mu1 = mu2; ODE's is a box).
Below the limit the force opposes the slip in proportion, with a gain that takes a quarter of the slip away per
step: a stiff but explicit stand-in for static friction, which Bullet's solver would give exactly. The gain
follows the mass the force moves: across the wheel, the wheel's share of the robot; along it, for a wheel no
plugin drives, the wheel's own spin (a driven wheel's velocity motor holds its spin, so there the share of the
robot again).
"""
import math
from typing import NamedTuple, Optional, Sequence, Tuple

import pybullet


# Fraction of the slip velocity one step's friction takes away below the limit (see the module docstring).
STICK_FRACTION = 0.25
# Below this a direction (fdir1 seen edge-on) is not used, m/s or unit length.
_TINY = 1e-9


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _unit(a) -> Optional[Tuple[float, float, float]]:
    length = math.sqrt(_dot(a, a))
    return None if length < _TINY else (a[0] / length, a[1] / length, a[2] / length)


def _rotate(q, v) -> Tuple[float, float, float]:
    """``v`` rotated by the unit quaternion ``q`` (x, y, z, w), written out: a PyBullet call per vector would cost
    more than the arithmetic, and this runs for every wheel at every step."""
    x, y, z, w = q
    tx, ty, tz = 2.0 * (y * v[2] - z * v[1]), 2.0 * (z * v[0] - x * v[2]), 2.0 * (x * v[1] - y * v[0])
    return (v[0] + w * tx + y * tz - z * ty, v[1] + w * ty + z * tx - x * tz, v[2] + w * tz + x * ty - y * tx)


class Wheel(NamedTuple):
    """One wheel link (Bullet link ``index``); vectors in its link frame."""
    index: int
    centre: Tuple[float, float, float]
    axis: Tuple[float, float, float]
    fdir1: Optional[Tuple[float, float, float]]
    mu1: float
    mu2: float
    gains: Tuple[float, float]  # N per m/s of slip along the rolling direction and across it


def wheel(index: int, centre, axis, fdir1, mu1: float, mu2: float, masses: Tuple[float, float],
          step_size: float) -> Wheel:
    """``masses``: what a force at the tread moves along the rolling direction and across it (kg)."""
    return Wheel(index, tuple(centre), tuple(axis), fdir1, mu1, mu2,
                 tuple(STICK_FRACTION * mass / step_size for mass in masses))


class WheelContacts:
    """The friction of a robot's wheels against whatever they touch: ``apply`` before every step."""

    def __init__(self, client, body: int, wheels: Sequence[Wheel]):
        self.client, self.body = client, body
        self.wheels = {wheel.index: wheel for wheel in wheels}
        self.indices = list(self.wheels)
        self._surfaces = {}  # (body, link) -> (lateral friction, static)

    def _surface(self, body: int, link: int) -> Tuple[float, bool]:
        key = (body, link)
        if key not in self._surfaces:
            info = self.client.getDynamicsInfo(body, link)
            self._surfaces[key] = (info[1], info[0] == 0.0)
        return self._surfaces[key]

    def _velocity_of(self, body: int, link: int, point) -> Tuple[float, float, float]:
        if link == -1:
            com, _ = self.client.getBasePositionAndOrientation(body)
            linear, angular = self.client.getBaseVelocity(body)
        else:
            state = self.client.getLinkState(body, link, computeLinkVelocity=1)
            com, linear, angular = state[0], state[6], state[7]
        arm = (point[0] - com[0], point[1] - com[1], point[2] - com[2])
        spin = _cross(angular, arm)
        return (linear[0] + spin[0], linear[1] + spin[1], linear[2] + spin[2])

    def apply(self):
        client, body, wheels = self.client, self.body, self.wheels
        touching = {}
        for point in client.getContactPoints(bodyA=body):
            if point[3] in wheels and point[2] != body and point[9] > 0.0:
                touching.setdefault(point[3], []).append(point)
        if not touching:
            return
        indices = list(touching)
        for index, state in zip(indices, client.getLinkStates(body, indices, computeLinkVelocity=1)):
            self._apply(wheels[index], touching[index], state)

    def _apply(self, wheel: Wheel, points, state):
        com, frame, orientation, linear, angular = state[0], state[4], state[5], state[6], state[7]
        offset = _rotate(orientation, wheel.centre)
        centre = (frame[0] + offset[0], frame[1] + offset[1], frame[2] + offset[2])
        axis = _rotate(orientation, wheel.axis)
        fdir1 = _rotate(orientation, wheel.fdir1) if wheel.fdir1 is not None else None
        gain_along, gain_across = (gain / len(points) for gain in wheel.gains)
        for point in points:
            other, other_link, normal, normal_force = point[2], point[4], point[7], point[9]
            friction, static = self._surface(other, other_link)
            mu1, mu2 = wheel.mu1 * friction, wheel.mu2 * friction
            if mu1 <= 0.0 and mu2 <= 0.0:
                continue
            arm = (point[5][0] - centre[0], point[5][1] - centre[1], point[5][2] - centre[2])
            along = _dot(arm, axis)
            at = (point[5][0] - along * axis[0], point[5][1] - along * axis[1], point[5][2] - along * axis[2])
            spin = _cross(angular, (at[0] - com[0], at[1] - com[1], at[2] - com[2]))
            velocity = (linear[0] + spin[0], linear[1] + spin[1], linear[2] + spin[2])
            if not static:
                moving = self._velocity_of(other, other_link, at)
                velocity = (velocity[0] - moving[0], velocity[1] - moving[1], velocity[2] - moving[2])
            rolling = _unit(_cross(axis, normal))
            first = _first_direction(fdir1, rolling, normal)
            if rolling is None or first is None:
                continue
            second = _cross(normal, first)
            across = _cross(normal, rolling)
            along_slip, across_slip = _dot(velocity, rolling), _dot(velocity, across)
            stick = tuple(-gain_along * along_slip * rolling[i] - gain_across * across_slip * across[i]
                          for i in range(3))
            slip1, slip2 = _dot(velocity, first), _dot(velocity, second)
            # A direction without friction (mu 0) takes no force; the other still sticks below its limit.
            force1 = _dot(stick, first) if mu1 > 0.0 else 0.0
            force2 = _dot(stick, second) if mu2 > 0.0 else 0.0
            if _outside(force1, force2, mu1 * normal_force, mu2 * normal_force):
                # Sliding: the force on the ellipse that dissipates most (opposite the slip when mu1 = mu2).
                weighted = math.hypot(mu1 * slip1, mu2 * slip2)
                if weighted < _TINY:
                    continue
                force1 = -normal_force * mu1 * mu1 * slip1 / weighted
                force2 = -normal_force * mu2 * mu2 * slip2 / weighted
            force = tuple(force1 * first[i] + force2 * second[i] for i in range(3))
            self.client.applyExternalForce(self.body, wheel.index, force, at, pybullet.WORLD_FRAME)


def _first_direction(fdir1, rolling, normal) -> Optional[Tuple[float, float, float]]:
    """fdir1 in the contact plane, or the rolling direction when fdir1 is absent or edge-on."""
    if fdir1 is None:
        return rolling
    for direction in (fdir1, rolling or (0.0, 0.0, 0.0)):
        along = _dot(direction, normal)
        unit = _unit((direction[0] - along * normal[0], direction[1] - along * normal[1],
                      direction[2] - along * normal[2]))
        if unit is not None:
            return unit
    return None


def _outside(force1: float, force2: float, limit1: float, limit2: float) -> bool:
    """Whether (force1, force2) lies beyond the ellipse with these semi-axes (a zero limit admits no force)."""
    ratio = 0.0
    for force, limit in ((force1, limit1), (force2, limit2)):
        if abs(force) > limit:  # beyond one semi-axis (or any force on a zero one); also keeps the ratio finite
            return True
        if limit > 0.0:
            ratio += (force / limit) ** 2
    return ratio > 1.0
