"""The steady state of a four-wheel skid-steer base on flat ground, from a force and moment balance over its wheel
contacts, apart from the simulator: what the wheel contact model (core/wheel_contact.py) predicts, to hold the
simulator's turns and arcs against.

The body moves in the plane at (vx, vy) (its reference point, between the wheels) and turns at yaw rate w; each
wheel touches the ground at its mid-plane, (x, y) in the body's frame, with its rim moving backwards at the
speed ``rim`` the velocity motor holds. The contact slips at (vx - w y - rim, vy + w x), and friction opposes the
slip with mu N (Coulomb friction on a circle: Husky's mu1 = mu2). In a skid-steer turn every contact slides (the
slowest at 0.13 m/s in Husky's), so the wheel contact model's stand-in for static friction, which acts below
0.03 m/s, does not enter. The normal loads N are those of a rigid body on four equal stiff contacts: the weight
shared so that the loads' moments put it at the centre of mass (a plane over the contacts), moved by the turn's
inertia acting at the centre of mass's height. The balance is quasi-static: the friction forces sum to the mass
times the centripetal acceleration of the steady turn, and their moment about the centre of mass is zero."""
from typing import NamedTuple, Sequence, Tuple

import numpy as np
from scipy.optimize import least_squares

GRAVITY = 9.80665  # m/s^2, as the worlds' <gravity>
_SMOOTH = 1e-9  # m/s: a slip below this counts as none (keeps pure Coulomb friction differentiable)


class SkidBase(NamedTuple):
    wheelbase: float  # m, front to rear axle
    track: float  # m, left to right wheel mid-planes
    mass: float  # kg, the whole robot
    centre_of_mass: Tuple[float, float, float]  # (x, y) in the body's frame and height above the ground, m
    mu: float = 1.0

    def contacts(self) -> np.ndarray:
        """(x, y) of the front left, front right, rear left and rear right contacts."""
        a, b = self.wheelbase / 2, self.track / 2
        return np.array([(a, b), (a, -b), (-a, b), (-a, -b)])

    def normal_loads(self, acceleration: Sequence[float] = (0.0, 0.0)) -> np.ndarray:
        """The loads while the centre of mass accelerates at ``acceleration`` (x, y): its inertia, at its height,
        moves the loads as a shift of the centre of mass against the acceleration would."""
        x, y, height = self.centre_of_mass
        x, y = x - acceleration[0] * height / GRAVITY, y - acceleration[1] * height / GRAVITY
        signs = self.contacts() / (self.wheelbase / 2, self.track / 2)
        return self.mass * GRAVITY / 4 * (1 + signs[:, 0] * x / (self.wheelbase / 2) + signs[:, 1] * y / (
            self.track / 2))

    def acceleration(self, twist: Sequence[float]) -> np.ndarray:
        """The centre of mass's centripetal acceleration in the steady turn (vx, vy, w), in the body's frame."""
        vx, vy, w = twist
        x, y, _ = self.centre_of_mass
        return w * np.array([-(vy + w * x), vx - w * y])


def wheel_rim_speeds(base: SkidBase, linear: float, angular: float, separation_multiplier: float) -> np.ndarray:
    """The rim speeds diff_drive_controller commands for (linear, angular), for the four contacts' order."""
    half = separation_multiplier * base.track / 2
    left, right = linear - angular * half, linear + angular * half
    return np.array([left, right, left, right])


def slips(base: SkidBase, twist: Sequence[float], rims: np.ndarray) -> np.ndarray:
    """Each contact's slip velocity (x, y) in the body's frame."""
    vx, vy, w = twist
    points = base.contacts()
    return np.column_stack([vx - w * points[:, 1] - rims, vy + w * points[:, 0]])


def friction_forces(base: SkidBase, twist: Sequence[float], rims: np.ndarray) -> np.ndarray:
    slip = slips(base, twist, rims)
    speeds = np.sqrt(np.sum(slip ** 2, axis=1) + _SMOOTH ** 2)
    return -slip * (base.mu * base.normal_loads(base.acceleration(twist)) / speeds)[:, None]


def residuals(base: SkidBase, twist: Sequence[float], rims: np.ndarray) -> np.ndarray:
    """The net force less mass times the steady turn's centripetal acceleration, and the moment about the centre
    of mass, scaled by the weight (so N and N·m weigh alike)."""
    forces = friction_forces(base, twist, rims)
    arms = base.contacts() - np.asarray(base.centre_of_mass[:2])
    inertial = base.mass * base.acceleration(twist)
    moment = np.sum(arms[:, 0] * forces[:, 1] - arms[:, 1] * forces[:, 0])
    return np.append(forces.sum(axis=0) - inertial, moment) / (base.mass * GRAVITY)


def steady_twist(base: SkidBase, linear: float, angular: float, separation_multiplier: float) -> np.ndarray:
    """(vx, vy, w) of the body's reference point in its own frame at which the contacts' forces balance."""
    rims = wheel_rim_speeds(base, linear, angular, separation_multiplier)
    guess = (linear, 0.0, angular)
    solution = least_squares(lambda twist: residuals(base, twist, rims), guess, xtol=1e-12, ftol=1e-12,
                             gtol=1e-12)
    assert np.max(np.abs(solution.fun)) < 1e-8, f"no balance for ({linear}, {angular}): {solution.fun}"
    return solution.x
