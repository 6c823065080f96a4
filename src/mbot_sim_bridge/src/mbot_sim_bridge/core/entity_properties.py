"""get/set_link_properties and get/set_joint_properties (gazebo_ros's services) on what Bullet has.

A link's properties are its mass, its inertia about the centre of mass and the centre of mass, as Bullet holds
them (a robot's link after fixed-joint lumping, as Gazebo's): the centre of mass frame ``com`` in the link frame,
whose axes are the inertia's principal axes, and the inertia in that frame. Bullet fixes both when a body is
built, so set_link_properties changes the mass and the moments about those axes; a request that moves the centre
of mass or turns the axes is warned about once, and the rest set. gravity_mode false is a force cancelling the
link's weight before every step (Bullet has no per-link gravity).

A joint's: its type, damping, position and rate. set_joint_properties takes ODEJointProperties' first entries:
damping (a torque -damping·rate before every step: PyBullet's own joint damping made a 0.01 kg·m² plate spin at
its velocity cap), hiStop and loStop (Bullet's joint limits; a joint already beyond a new stop is held where it
is, not pushed back), and fmax with vel (a velocity motor, as ODE's; it stays until a plugin or reset_simulation
sets the joint's motor again); erp, cfm, stop_erp, stop_cfm and fudge_factor have no Bullet counterpart and are
warned about once.
"""
import math
from typing import List, NamedTuple, Optional, Sequence

import numpy as np

from .errors import ModelError
from .geometry import Pose, rotation_matrix

# kg and kg·m², as the URDF reader's bounds: far beyond any robot, and what Bullet's solver can integrate.
MAX_MASS = 1e9
MAX_INERTIA = 1e9
MAX_COM = 1e5  # m, as far as a model may be placed
# N·m·s/rad (or N·s/m), N·m (or N), rad (or m), rad/s (or m/s).
MAX_DAMPING = 1e6
MAX_FMAX = 1e6
MAX_STOP = 1e6
NO_STOP = 1e30  # a joint without a stop: beyond any position
MAX_VEL = 1e4
# The centre of mass and axes a request gives count as unchanged within this (m, and quaternion components).
SAME_FRAME = 1e-6
ODE_ONLY_FIELDS = ("erp", "cfm", "stop_erp", "stop_cfm", "fudge_factor")
JOINT_TYPES = {"revolute": 0, "continuous": 1, "prismatic": 2, "fixed": 3}  # GetJointProperties' constants


class LinkProperties(NamedTuple):
    com: Pose  # the centre of mass and the inertia's axes, in the link frame
    gravity_mode: bool
    mass: float
    ixx: float
    ixy: float
    ixz: float
    iyy: float
    iyz: float
    izz: float


class JointProperties(NamedTuple):
    type: int
    damping: List[float]
    position: List[float]
    rate: List[float]


def inertia_tensor(properties: LinkProperties) -> np.ndarray:
    p = properties
    return np.array([[p.ixx, p.ixy, p.ixz], [p.ixy, p.iyy, p.iyz], [p.ixz, p.iyz, p.izz]])


def checked_link_properties(link_name: str, requested: LinkProperties, current: LinkProperties):
    """(mass, principal moments about ``current``'s axes, whether the request moves the centre of mass or turns
    the axes) for a set_link_properties request; ModelError naming the value for one that is not finite, a mass
    not above 0 or beyond MAX_MASS, an inertia beyond MAX_INERTIA or with a moment not above 0."""
    what = f"SetLinkProperties: link '{link_name}'"
    if not (math.isfinite(requested.mass) and 0.0 < requested.mass <= MAX_MASS):
        raise ModelError(f"{what}: mass must be finite, above 0 and at most {MAX_MASS:g} kg; got {requested.mass}")
    tensor = inertia_tensor(requested)
    if not (np.all(np.isfinite(tensor)) and np.all(np.abs(tensor) <= MAX_INERTIA)):
        raise ModelError(f"{what}: inertia values must be finite and at most {MAX_INERTIA:g} kg·m² in size; got "
                         f"{tensor[np.triu_indices(3)].tolist()}")
    values = (*requested.com.position, *requested.com.orientation)
    if not all(math.isfinite(value) for value in values) or max(map(abs, requested.com.position)) > MAX_COM:
        raise ModelError(f"{what}: com must be finite, its position at most {MAX_COM:g} m from the link's origin; "
                         f"got {values}")
    # The inertia as given (about the requested com axes) seen along the axes Bullet keeps.
    to_current = np.array(rotation_matrix(current.com.orientation)).T @ np.array(rotation_matrix(
        requested.com.orientation))
    along = to_current @ tensor @ to_current.T
    moments = np.diag(along)
    if not np.all(moments > 0.0):
        raise ModelError(f"{what}: the inertia's moments must be above 0; got {moments.tolist()}")
    off_axes = np.max(np.abs(along - np.diag(moments))) > SAME_FRAME * max(1.0, float(np.max(moments)))
    moved = np.max(np.abs(np.subtract(requested.com.position, current.com.position))) > SAME_FRAME
    return float(requested.mass), tuple(moments.tolist()), bool(off_axes or moved)


class JointSettings(NamedTuple):
    """What a set_joint_properties request sets; None: not given."""
    damping: Optional[float]
    limits: Optional[tuple]  # (lower, upper)
    motor: Optional[tuple]  # (velocity, max force)
    ignored: List[str]  # ODEJointProperties fields without a Bullet counterpart, and entries beyond the first axis


def checked_joint_settings(joint_name: str, config, lower: float, upper: float) -> JointSettings:
    """A set_joint_properties request's ODEJointProperties ``config`` for a one-axis joint now limited to
    [``lower``, ``upper``]; ModelError naming the value for one that is not finite or out of range."""
    what = f"SetJointProperties: joint '{joint_name}'"

    def first(field: str, low: float, high: float) -> Optional[float]:
        values: Sequence[float] = getattr(config, field)
        if not values:
            return None
        if not (math.isfinite(values[0]) and low <= values[0] <= high):
            raise ModelError(f"{what}: {field} must be finite and in [{low:g}, {high:g}]; got {values[0]}")
        return float(values[0])
    damping = first("damping", 0.0, MAX_DAMPING)
    hi_stop, lo_stop = first("hiStop", -MAX_STOP, MAX_STOP), first("loStop", -MAX_STOP, MAX_STOP)
    fmax, vel = first("fmax", 0.0, MAX_FMAX), first("vel", -MAX_VEL, MAX_VEL)
    limits = None
    if hi_stop is not None or lo_stop is not None:
        limits = (lower if lo_stop is None else lo_stop, upper if hi_stop is None else hi_stop)
        if limits[0] > limits[1]:
            raise ModelError(f"{what}: loStop {limits[0]:g} is above hiStop {limits[1]:g}")
    motor = None if fmax is None and vel is None else (vel or 0.0, fmax or 0.0)
    ignored = [field for field in ODE_ONLY_FIELDS if getattr(config, field)]
    ignored += [f"{field}[1:]" for field in ("damping", "hiStop", "loStop", "fmax", "vel")
                if len(getattr(config, field)) > 1]
    return JointSettings(damping, limits, motor, ignored)
