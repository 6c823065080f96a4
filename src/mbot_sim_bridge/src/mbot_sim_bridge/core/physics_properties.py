"""set_physics_properties and get_physics_properties' ODE fields on Bullet.

Changed at run time, between two steps: the time step (sim time goes on from where it is), the update rate (the
pacing's real-time factor is step × rate, as Gazebo's), gravity, and of the ODE solver fields those with a Bullet
counterpart: erp (Bullet's joint error reduction, as the world file's), sor_pgs_iters (Bullet's solver
iterations), contact_max_correcting_vel (the cap on the speed penetration is undone at) and
contact_surface_layer (kept and reported, not applied, as from the world file). The others (cfm,
sor_pgs_precon_iters, sor_pgs_w, sor_pgs_rms_error_tol, max_contacts, auto_disable_bodies) have no Bullet
counterpart: they are reported as Bullet behaves, and a request for another value is warned about once.
"""
import math
from dataclasses import replace
from typing import List, NamedTuple, Tuple

from .description.world_description import PhysicsConfig
from .errors import ModelError

# Also the bounds of a world file's <physics> and <gravity> (sdf_world). A step beyond 0.1 s makes every robot's
# contacts explode; below 10 µs a second of sim time takes 100,000 steps (1e-9 s gave no /clock in 120 s).
MIN_TIME_STEP, MAX_TIME_STEP = 1e-5, 0.1
MAX_UPDATE_RATE = 1e6  # Hz; 0 runs as fast as the machine goes
MAX_GRAVITY = 1e3  # m/s² per axis
MAX_SOLVER_ITERATIONS = 10000
MAX_CORRECTING_VEL = 1e7  # m/s, the top of gazebo_ros' reconfigure range
MAX_SURFACE_LAYER = 10.0  # m, likewise
# What the fields without a Bullet counterpart are reported as: how Bullet behaves in ODE's terms.
BULLET_AS_ODE = {"auto_disable_bodies": False, "sor_pgs_precon_iters": 0, "sor_pgs_w": 1.3,
                 "sor_pgs_rms_error_tol": 0.0, "cfm": 0.0, "max_contacts": 20}


class OdeConfig(NamedTuple):
    """gazebo_msgs/ODEPhysics' fields."""
    auto_disable_bodies: bool
    sor_pgs_precon_iters: int
    sor_pgs_iters: int
    sor_pgs_w: float
    sor_pgs_rms_error_tol: float
    contact_surface_layer: float
    contact_max_correcting_vel: float
    cfm: float
    erp: float
    max_contacts: int


def ode_config(physics: PhysicsConfig, solver_iterations: int) -> OdeConfig:
    return OdeConfig(**BULLET_AS_ODE, sor_pgs_iters=solver_iterations,
                     contact_surface_layer=physics.contact_surface_layer,
                     contact_max_correcting_vel=physics.contact_max_correcting_vel, erp=physics.erp)


def requested_physics(physics: PhysicsConfig, time_step: float, max_update_rate: float,
                      gravity: Tuple[float, float, float], ode: OdeConfig) -> Tuple[PhysicsConfig, int, List[str]]:
    """(the new physics, the solver iterations, the fields asked for another value that Bullet has no counterpart
    for) of a set_physics_properties request; ModelError naming the field for a value that is not finite or out of
    its range (nothing is changed then)."""
    def check(name: str, value: float, low: float, high: float):
        if not (math.isfinite(value) and low <= value <= high):
            raise ModelError(f"SetPhysicsProperties: {name} must be finite and in [{low:g}, {high:g}]; got {value}; "
                             "nothing was changed")
    check("time_step", time_step, MIN_TIME_STEP, MAX_TIME_STEP)
    check("max_update_rate", max_update_rate, 0.0, MAX_UPDATE_RATE)
    for axis, value in zip("xyz", gravity):
        check(f"gravity.{axis}", value, -MAX_GRAVITY, MAX_GRAVITY)
    check("ode_config.erp", ode.erp, 0.0, 1.0)
    check("ode_config.sor_pgs_iters", ode.sor_pgs_iters, 1, MAX_SOLVER_ITERATIONS)
    check("ode_config.contact_max_correcting_vel", ode.contact_max_correcting_vel, 0.0, MAX_CORRECTING_VEL)
    check("ode_config.contact_surface_layer", ode.contact_surface_layer, 0.0, MAX_SURFACE_LAYER)
    for name in ("sor_pgs_w", "sor_pgs_rms_error_tol", "cfm"):
        if not math.isfinite(getattr(ode, name)):
            raise ModelError(f"SetPhysicsProperties: ode_config.{name} must be finite; got {getattr(ode, name)}; "
                             "nothing was changed")
    ignored = [f"{name} {getattr(ode, name)}" for name, value in BULLET_AS_ODE.items() if getattr(ode, name) != value]
    new = replace(physics, max_step_size=float(time_step), real_time_update_rate=float(max_update_rate),
                  gravity=tuple(float(value) for value in gravity), erp=float(ode.erp),
                  contact_max_correcting_vel=float(ode.contact_max_correcting_vel),
                  contact_surface_layer=float(ode.contact_surface_layer))
    return new, int(ode.sor_pgs_iters), ignored
