"""gazebo_ros's physics dynamic_reconfigure server on /gazebo: upstream's parameters (gazebo_ros/cfg/Physics.cfg:
names, types, defaults, bounds, all at level 1), first filled from the running world as upstream's first callback
does, then each change sent as one set_physics_properties request; the answer and parameter_updates hold the
physics in effect (a refused change leaves them as they were and is logged with the reason)."""
import rospy
from dynamic_reconfigure.server import ALL_LEVELS, Parameter, Server

from .core.errors import BridgeError
from .core.physics_properties import OdeConfig

PHYSICS_PARAMETERS = [
    Parameter("time_step", "double", 0.001, 0.0, 10.0, "Physics step, s: smaller is slower and more stable.", 1),
    Parameter("max_update_rate", "double", 60.0, 0.0, 1000.0, "Steps per wall second at most; 0: as fast as "
              "possible.", 1),
    Parameter("gravity_x", "double", 0.0, -100.0, 100.0, "Gravity along x, m/s².", 1),
    Parameter("gravity_y", "double", 0.0, -100.0, 100.0, "Gravity along y, m/s².", 1),
    Parameter("gravity_z", "double", -9.8, -100.0, 100.0, "Gravity along z, m/s².", 1),
    Parameter("auto_disable_bodies", "bool", False, False, True, "ODE: disable bodies at rest (not in Bullet).", 1),
    Parameter("sor_pgs_precon_iters", "int", 0, 0, 10000, "ODE: preconditioning iterations (not in Bullet).", 1),
    Parameter("sor_pgs_iters", "int", 20, 0, 10000, "Solver iterations per step (Bullet's).", 1),
    Parameter("sor_pgs_w", "double", 1.3, 0.0, 5.0, "ODE: SOR relaxation (not in Bullet).", 1),
    Parameter("sor_pgs_rms_error_tol", "double", -1.0, -1.0, 10000.0, "ODE: solver error tolerance (not in "
              "Bullet).", 1),
    Parameter("cfm", "double", 0.0, 0.0, 10.0, "ODE: constraint force mixing (not in Bullet).", 1),
    Parameter("erp", "double", 0.2, 0.0, 10.0, "Joint error reduction per step.", 1),
    Parameter("contact_surface_layer", "double", 0.001, 0.0, 10.0, "Penetration left uncorrected, m (kept, not "
              "applied).", 1),
    Parameter("contact_max_correcting_vel", "double", 100.0, 0.0, 10000000.0, "Fastest penetration correction, "
              "m/s.", 1),
    Parameter("max_contacts", "int", 100, 0, 10000000, "ODE: contacts between two bodies at most (not in Bullet).",
              1),
]
_ODE_FIELDS = OdeConfig._fields


class PhysicsReconfigure:
    def __init__(self, node):
        self.node = node
        self.server = Server(PHYSICS_PARAMETERS, self._reconfigure, "~")

    def _current(self):
        physics, ode = self.node.sim.engine.physics, self.node.sim.ode_config()
        values = {"time_step": physics.max_step_size, "max_update_rate": physics.real_time_update_rate,
                  **dict(zip(("gravity_x", "gravity_y", "gravity_z"), physics.gravity)), **ode._asdict()}
        return {parameter.name: type(parameter.default)(values[parameter.name]) for parameter in PHYSICS_PARAMETERS}

    def _reconfigure(self, config, level):
        if level == ALL_LEVELS:  # built with the node, before its loop runs
            return self._current()

        def apply():
            current = self._current()
            if config != current:
                gravity = (config["gravity_x"], config["gravity_y"], config["gravity_z"])
                ode = OdeConfig(**{field: config[field] for field in _ODE_FIELDS})
                self.node.sim.set_physics(config["time_step"], config["max_update_rate"], gravity, ode)
                self.node.physics_changed()
            return self._current()
        try:
            return self.node.call_in_loop(apply)
        except BridgeError as error:
            rospy.logerr(f"/gazebo physics reconfigure: {error}")
            return self.node.call_in_loop(self._current)
