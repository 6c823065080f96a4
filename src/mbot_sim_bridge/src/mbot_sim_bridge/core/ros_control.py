"""ros_control in the simulator, without ROS: transmissions, joint limits, the default robot hardware
simulation and the controller manager.

Follows ros_control 0.20 and gazebo_ros_control (gazebo_ros_pkgs 2.9, Noetic):
- ``parse_transmissions``: transmission_interface's TransmissionParser: ``<transmission>`` with ``<type>``,
  ``<joint>`` (with ``<hardwareInterface>``) and ``<actuator>`` (``<hardwareInterface>``, the old placement,
  and ``<mechanicalReduction>``);
- ``RobotHWSim``: gazebo_ros_control's DefaultRobotHWSim: one joint per transmission with its first hardware
  interface; joint limits from the URDF ``<limit>`` and the ``joint_limits/<joint>`` parameters, enforced as
  joint_limits_interface's saturation handles; ``gazebo_ros_control/pid_gains/<joint>`` turns position and
  velocity joints into PID-driven effort joints; the e-stop;
- ``ControllerManager``: controller_manager's load/unload/switch (with strictness and resource conflicts)/list,
  with upstream's log texts. Services call it from ROS threads; ``update`` runs in the loop thread.
The controllers themselves are in ``core/controllers.py``.
"""
import math
import threading
from dataclasses import dataclass, field
from typing import Callable, Dict, List, Optional, Sequence, Tuple
from xml.etree import ElementTree

from .errors import ConfigError
from .log import get_logger, info_once, warn_once
from .robot_model import Joint, RobotModel
from .xml_values import parse_float

_logger = get_logger(__name__)

SIMPLE_TRANSMISSION = "transmission_interface/SimpleTransmission"
EFFORT, POSITION, VELOCITY = "EffortJointInterface", "PositionJointInterface", "VelocityJointInterface"
JOINT_STATE = "JointStateInterface"
# Demangled C++ names, as controllers report their interface in list_controllers and in errors.
INTERFACE_TYPES = {name: "hardware_interface::" + name for name in (EFFORT, POSITION, VELOCITY, JOINT_STATE)}
# Gazebo gives a joint without an effort limit an unbounded motor (numeric_limits<double>::max()); Bullet needs
# a number, and this one is far beyond any wheel or arm joint's need while keeping the solver well scaled.
UNBOUNDED_EFFORT = 1.0e5


class HardwareInterfaceError(Exception):
    """hardware_interface::HardwareInterfaceException: a controller asked for a resource that is not there."""


# -- transmissions -------------------------------------------------------------------------------------------
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


# -- joint limits --------------------------------------------------------------------------------------------
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


# -- small maths shared with the controllers (the ``angles`` package) ---------------------------------------
def normalize_angle(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


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


def clamp(value: float, low: float, high: float) -> float:
    return min(max(value, low), high)


class Pid:
    """control_toolbox::Pid: p, i, d, i_clamp (or i_clamp_min/max), antiwindup; computeCommand as upstream."""

    def __init__(self, p=0.0, i=0.0, d=0.0, i_max=0.0, i_min=0.0, antiwindup=False):
        self.p, self.i, self.d, self.i_max, self.i_min, self.antiwindup = p, i, d, i_max, i_min, antiwindup
        self.reset()

    @classmethod
    def from_params(cls, params, namespace: str, quiet: bool = False) -> Optional["Pid"]:
        """Pid::init(nh): None (with upstream's error unless quiet) when there is no ``p``."""
        if not isinstance(params, dict) or "p" not in params:
            if not quiet:
                _logger.error(f"No p gain specified for pid.  Namespace: {namespace}")
            return None
        i_clamp = abs(float(params.get("i_clamp", 0.0)))
        i_max, i_min = i_clamp, -i_clamp
        if "i_clamp_min" in params:
            i_min = -abs(float(params["i_clamp_min"]))
        if "i_clamp_max" in params:
            i_max = abs(float(params["i_clamp_max"]))
        if params.get("publish_state"):
            warn_once(_logger, f"{namespace}/publish_state: the PID state topic needs control_msgs, which Debian does "
                               "not package; not published")
        return cls(float(params["p"]), float(params.get("i", 0.0)), float(params.get("d", 0.0)), i_max, i_min,
                   bool(params.get("antiwindup", False)))

    def reset(self):
        # Upstream's reset() leaves the last error "valid" at 0, so the first derivative sees the whole error.
        self.p_error_last = self.i_error = self.d_error = self.command = 0.0
        self.valid_p_error_last = True

    def compute(self, error: float, dt: float, error_dot: Optional[float] = None) -> float:
        if dt == 0.0 or not math.isfinite(error):
            return 0.0
        if error_dot is None:
            error_dot = self.d_error
            if dt > 0.0:
                if self.valid_p_error_last:
                    error_dot = (error - self.p_error_last) / dt
                self.p_error_last = error
                self.valid_p_error_last = True
        self.d_error = error_dot
        if not math.isfinite(error_dot):
            return 0.0
        self.i_error += dt * error
        if self.antiwindup and self.i != 0:
            bounds = sorted((self.i_min / self.i, self.i_max / self.i))
            self.i_error = clamp(self.i_error, bounds[0], bounds[1])
        i_term = self.i * self.i_error
        if not self.antiwindup:
            i_term = clamp(i_term, self.i_min, self.i_max)
        self.command = self.p * error + i_term + self.d * error_dot
        return self.command


# -- the default robot hardware simulation -------------------------------------------------------------------
@dataclass
class SimJoint:
    """One joint of the hardware simulation: the handle controllers read and command."""
    name: str
    interface: str  # EFFORT, POSITION or VELOCITY
    joint_type: str  # URDF type, or inferred from the limits; "" if unknown
    limits: Optional[JointLimits]
    pid: Optional[Pid] = None
    # gazebo_ros_control starts these at 1.0 (position, effort) until the first read.
    position: float = 1.0
    velocity: float = 0.0
    effort: float = 1.0
    command: float = 0.0
    previous_command: float = math.nan  # position saturation's memory
    previous_velocity_command: float = 0.0  # velocity saturation's memory
    sent: Optional[Tuple[str, float]] = field(default=None, repr=False)  # last motor setting given to the engine

    @property
    def lower(self) -> float:
        return self.limits.min_position if self.limits and self.limits.has_position_limits else -math.inf

    @property
    def upper(self) -> float:
        return self.limits.max_position if self.limits and self.limits.has_position_limits else math.inf

    @property
    def effort_limit(self) -> float:
        return self.limits.max_effort if self.limits and self.limits.has_effort_limits else math.inf


class RobotHWSim:
    """gazebo_ros_control::DefaultRobotHWSim over a SpawnedRobot (``robot``: joint_state, set_joint_*)."""

    def __init__(self, robot, transmissions: Sequence[Transmission], urdf: RobotModel, label: str,
                 limit_params: Optional[dict] = None, pid_params: Optional[dict] = None, pid_namespace: str = ""):
        self.robot = robot
        self.label = label
        self.joints: Dict[str, SimJoint] = {}
        self.e_stop_active = False
        self._last_e_stop_active = False
        self._held_positions: Dict[str, float] = {}
        limit_params, pid_params = limit_params or {}, pid_params or {}
        for transmission in transmissions:
            if len(transmission.joints) > 1:
                _logger.warning(f"{label}: Transmission {transmission.name} has more than one joint. Currently the "
                                "default robot hardware simulation  interface only supports one.")
                continue
            joint_name, interfaces = transmission.joints[0]
            if not interfaces and transmission.actuators and transmission.actuators[0][1]:
                interfaces = transmission.actuators[0][1]
                warn_once(_logger, f"{label}: The <hardware_interface> element of tranmission {transmission.name} "
                                   "should be nested inside the <joint> element, not <actuator>. The transmission "
                                   "will be properly loaded, but please update your robot model to remain compatible "
                                   "with future versions of the plugin.")
            if not interfaces:
                _logger.warning(f"{label}: Joint {joint_name} of transmission {transmission.name} does not specify any "
                                "hardware interface. Not adding it to the robot hardware simulation.")
                continue
            if len(interfaces) > 1:
                _logger.warning(f"{label}: Joint {joint_name} of transmission {transmission.name} specifies multiple "
                                "hardware interfaces. Currently the default robot hardware simulation interface only "
                                "supports one. Using the first entry")
            interface = interfaces[0].replace("hardware_interface/", "", 1)
            if interface not in (EFFORT, POSITION, VELOCITY):
                raise ConfigError(f"{label}: No matching hardware interface found for '{interfaces[0]}' while loading "
                                  f"interfaces for {joint_name}")
            if interface == interfaces[0]:
                warn_once(_logger, f"{label}: Deprecated syntax, please prepend 'hardware_interface/' to '{interface}' "
                                   f"within the <hardwareInterface> tag in joint '{joint_name}'.")
            if joint_name not in robot.joint_index:
                raise ConfigError(f'{label}: This robot has a joint named "{joint_name}" which is '
                                  'not in the gazebo model.')
            reductions = [value for _, _, value in transmission.actuators if value is not None and value != 1.0]
            if reductions:
                info_once(_logger, f"{label}: transmission {transmission.name}: mechanicalReduction {reductions[0]} is "
                                   "read but, as in gazebo_ros_control's default robot "
                                   "hardware simulation, not applied")
            urdf_joint = urdf.joints.get(joint_name)
            limits = apply_limit_params(urdf_joint_limits(urdf_joint), limit_params.get(joint_name), joint_name)
            joint_type = urdf_joint.type if urdf_joint is not None else ""
            if not joint_type and limits is not None:
                joint_type = ("revolute" if limits.has_position_limits
                              else "continuous" if limits.angle_wraparound else "prismatic")
            if urdf_joint is not None and urdf_joint.has_safety_controller:
                warn_once(_logger, f"{label}: joint '{joint_name}' has a <safety_controller>: soft joint limits are "
                                   "not simulated; its hard limits are enforced as saturation")
            self._check_limits(joint_name, interface, limits)
            pid = None
            if interface != EFFORT:
                # Upstream logs "No p gain specified" as an error for every joint without gains; that is the
                # normal case (the joint is driven directly), so it is said once at INFO here.
                pid = Pid.from_params(pid_params.get(joint_name), f"{pid_namespace}/{joint_name}", quiet=True)
                if pid is None:
                    drive = "position servo" if interface == POSITION else "velocity motor"
                    info_once(_logger, f"{label}: no {pid_namespace}/{joint_name}/p: joint '{joint_name}' is "
                                       f"driven directly ({drive})")
            self.joints[joint_name] = SimJoint(joint_name, interface, joint_type, limits, pid)
        self.names = list(self.joints)

    def _check_limits(self, joint: str, interface: str, limits: Optional[JointLimits]):
        """The saturation handles' constructors refuse limits they cannot enforce (JointLimitsInterfaceException)."""
        if limits is None:
            return
        if interface in (EFFORT, VELOCITY) and not limits.has_velocity_limits:
            raise ConfigError(f"{self.label}: Cannot enforce limits for joint '{joint}'. It has no "
                              "velocity limits specification.")
        if interface == EFFORT and not limits.has_effort_limits:
            raise ConfigError(f"{self.label}: Cannot enforce limits for joint '{joint}'. It has no "
                              "efforts limits specification.")

    def handle(self, name: str, interface: str) -> SimJoint:
        """A command handle (interface EFFORT/POSITION/VELOCITY) or a state handle (JOINT_STATE)."""
        joint = self.joints.get(name)
        if joint is None or (interface != JOINT_STATE and joint.interface != interface):
            raise HardwareInterfaceError(f"Could not find resource '{name}' in '{INTERFACE_TYPES[interface]}'.")
        return joint

    def names_with(self, interface: str) -> List[str]:
        return [name for name, joint in self.joints.items() if interface == JOINT_STATE or joint.interface == interface]

    def read(self):
        """readSim: positions (revolute and continuous unwrapped step by step, as upstream), velocities, efforts."""
        if not self.names:
            return
        for joint, (position, velocity, effort) in zip(self.joints.values(), self.robot.joint_state(self.names)):
            if joint.joint_type == "prismatic":
                joint.position = position
            else:
                joint.position += shortest_angular_distance(joint.position, position)
            joint.velocity = velocity
            joint.effort = effort

    def write(self, period: float):
        """writeSim: e-stop, limit saturation, then each joint's motor; the engine is told only of changes."""
        if self.e_stop_active:
            if not self._last_e_stop_active:
                self._held_positions = {name: joint.position for name, joint in self.joints.items()}
                self._last_e_stop_active = True
        else:
            self._last_e_stop_active = False
        for joint in self.joints.values():
            if joint.interface == POSITION and self.e_stop_active:
                joint.command = self._held_positions.get(joint.name, joint.position)
            if joint.limits is not None:
                self._saturate(joint, period)
            self._drive(joint, period)

    def _saturate(self, joint: SimJoint, period: float):
        limits = joint.limits
        if joint.interface == EFFORT:
            low, high = -limits.max_effort, limits.max_effort
            if limits.has_position_limits:
                if joint.position < limits.min_position:
                    low = 0.0
                elif joint.position > limits.max_position:
                    high = 0.0
            if joint.velocity < -limits.max_velocity:
                low = 0.0
            elif joint.velocity > limits.max_velocity:
                high = 0.0
            joint.command = clamp(joint.command, low, high)
        elif joint.interface == POSITION:
            if math.isnan(joint.previous_command):
                joint.previous_command = joint.position
            low, high = joint.lower, joint.upper
            if limits.has_velocity_limits:
                step = limits.max_velocity * period
                low, high = max(joint.previous_command - step, low), min(joint.previous_command + step, high)
            joint.command = clamp(joint.command, low, high)
            joint.previous_command = joint.command
        else:
            low, high = -limits.max_velocity, limits.max_velocity
            if limits.has_acceleration_limits:
                step = limits.max_acceleration * period
                low = max(joint.previous_velocity_command - step, low)
                high = min(joint.previous_velocity_command + step, high)
            joint.command = clamp(joint.command, low, high)
            joint.previous_velocity_command = joint.command

    def _drive(self, joint: SimJoint, period: float):
        e_stop = self.e_stop_active
        if joint.pid is not None:
            if joint.interface == POSITION:
                if joint.joint_type == "revolute":
                    error = shortest_angular_distance_with_limits(joint.position, joint.command, joint.lower,
                                                                  joint.upper)
                elif joint.joint_type == "continuous":
                    error = shortest_angular_distance(joint.position, joint.command)
                else:
                    error = joint.command - joint.position
            else:
                error = -joint.velocity if e_stop else joint.command - joint.velocity
            limit = joint.effort_limit
            self._send(joint, "effort", clamp(joint.pid.compute(error, period), -limit, limit))
        elif joint.interface == EFFORT:
            self._send(joint, "effort", 0.0 if e_stop else joint.command)
        elif joint.interface == POSITION:
            self._send(joint, "position", joint.command)
        else:
            self._send(joint, "velocity", 0.0 if e_stop else joint.command)

    def _send(self, joint: SimJoint, mode: str, value: float):
        # Bullet keeps a velocity or position motor's setting until it is changed, so an unchanged one is not
        # sent again; a torque it applies for one step only, so efforts go out every step (as Gazebo's SetForce).
        if mode != "effort" and joint.sent == (mode, value):
            return
        joint.sent = (mode, value)
        limit = joint.effort_limit if math.isfinite(joint.effort_limit) else UNBOUNDED_EFFORT
        if mode == "effort":
            self.robot.set_joint_effort(joint.name, value)
        elif mode == "position":
            # Gazebo teleports the joint (SetPosition) regardless of load; Bullet's position servo with an
            # unbounded force is the stable equivalent that still lets contacts act.
            self.robot.set_joint_position(joint.name, value, UNBOUNDED_EFFORT)
        else:
            self.robot.set_joint_velocity(joint.name, value, limit)

    def forget_motors(self):
        """After a reset the engine's motors may have changed; send every setting again."""
        for joint in self.joints.values():
            joint.sent = None


# -- the controller manager ----------------------------------------------------------------------------------
class ControllerInitError(Exception):
    """A controller's init failed; the message lines are what upstream logs before 'Initializing ... failed'."""


@dataclass
class LoadContext:
    """What a controller gets besides its parameters: the robot's URDF (None if it could not be read) and its
    parameter namespace (for messages)."""
    urdf: Optional[RobotModel]
    namespace: str
    clock: Callable[[], float]  # the sim time (s), readable from any thread


@dataclass
class LoadedController:
    name: str
    type: str
    controller: object  # a core.controllers.Controller
    claimed: List[Tuple[str, List[str]]]  # (hardware interface type, resources)

    @property
    def state(self) -> str:
        return self.controller.state


class ControllerManager:
    """controller_manager::ControllerManager over a RobotHWSim.

    ``factory(type)`` returns the controller class for a type string, or None; ``get_params(name)`` the
    controller's parameters as a dict (None when it has none). load/unload/switch/list are called from service
    threads; ``update`` from the loop thread. A switch is handed to the next ``update`` and waited for, as
    upstream's realtime switch is (so it waits while the simulation is paused).
    """

    def __init__(self, hw: RobotHWSim, factory: Callable[[str], Optional[type]], types: Sequence[str],
                 get_params: Callable[[str], Optional[dict]], namespace: str = "/",
                 clock: Callable[[], float] = lambda: 0.0):
        self.hw = hw
        self.clock = clock
        self.factory = factory
        self.types = list(types)
        self.get_params = get_params
        self.namespace = namespace
        self.controllers: List[LoadedController] = []  # replaced, never mutated: the loop reads it without lock
        self._lock = threading.RLock()
        self._switch_request: Optional[Tuple[list, list, threading.Event]] = None

    # -- service side ------------------------------------------------------------------------------------
    def find(self, name: str) -> Optional[LoadedController]:
        return next((loaded for loaded in self.controllers if loaded.name == name), None)

    def load(self, name: str, urdf=None) -> bool:
        with self._lock:
            if self.find(name) is not None:
                _logger.error(f"A controller named '{name}' was already loaded inside the controller manager")
                return False
            params = self.get_params(name)
            controller_type = params.get("type") if isinstance(params, dict) else None
            if not isinstance(controller_type, str):
                _logger.error(f"Could not load controller '{name}' because the type was not specified. Did you load "
                              "the controller configuration on the parameter server (namespace: "
                              f"'{_join(self.namespace, name)}')?")
                return False
            controller_class = self.factory(controller_type)
            if controller_class is None:
                _logger.error(f"Could not load controller '{name}' because controller type "
                              f"'{controller_type}' does not exist.")
                _logger.error("Use 'rosservice call controller_manager/list_controller_types' to get the available "
                              "types")
                return False
            context = LoadContext(urdf, _join(self.namespace, name), self.clock)
            try:
                controller = controller_class(name, self.hw, params, context)
            except ControllerInitError as error:
                for line in str(error).splitlines():
                    _logger.error(line)
                _logger.error("Failed to initialize the controller")
                _logger.error(f"Initializing controller '{name}' failed")
                return False
            except HardwareInterfaceError as error:
                _logger.error(f"Exception thrown while initializing controller '{name}'.\n{error}")
                _logger.error(f"Initializing controller '{name}' failed")
                return False
            claimed = [(INTERFACE_TYPES[controller.INTERFACE], list(controller.claimed))]
            self.controllers = self.controllers + [LoadedController(name, controller_type, controller, claimed)]
            _logger.debug(f"Successfully load controller '{name}'")
            return True

    def unload(self, name: str) -> bool:
        with self._lock:
            loaded = self.find(name)
            if loaded is None:
                _logger.error(f"Could not unload controller with name '{name}' because no "
                              "controller with this name exists")
                return False
            if loaded.state == "running":
                _logger.error(f"Could not unload controller with name '{name}' because it is still running")
                return False
            self.controllers = [other for other in self.controllers if other is not loaded]
            loaded.controller.close()
            return True

    def switch(self, start: Sequence[str], stop: Sequence[str], strictness: int, start_asap: bool = False,
               timeout: float = 0.0, wait: Optional[Callable[[threading.Event, float], bool]] = None) -> bool:
        """SwitchController: checks as upstream, then waits for the loop to do it. ``wait(event, timeout)``
        blocks until the event is set (returns False if it gave up)."""
        if strictness == 0:
            _logger.warning("Controller Manager: To switch controllers you need to specify a strictness level of "
                            "controller_manager_msgs::SwitchController::STRICT (2) or ::BEST_EFFORT (1). Defaulting "
                            "to ::BEST_EFFORT.")
            strictness = 1
        strict = strictness == 2
        with self._lock:
            stop_list, start_list = [], []
            for names, target, verb in ((stop, stop_list, "stop"), (start, start_list, "start")):
                for name in names:
                    loaded = self.find(name)
                    if loaded is None:
                        if strict:
                            _logger.error(f"Could not {verb} controller with name '{name}' because no "
                                          "controller with this name exists")
                            return False
                        _logger.debug(f"Could not {verb} controller with name '{name}' because no "
                                      "controller with this name exists")
                    else:
                        target.append(loaded)
            active = []
            for loaded in self.controllers:
                in_stop, in_start = loaded in stop_list, loaded in start_list
                running = loaded.state == "running"
                if not running and in_stop:
                    if strict:
                        _logger.error(f"Could not stop controller '{loaded.name}' since it is not running")
                        return False
                    in_stop = False
                    stop_list.remove(loaded)
                if running and not in_stop and in_start:
                    if strict:
                        _logger.error(f"Controller '{loaded.name}' is already running")
                        return False
                    in_start = False
                    start_list.remove(loaded)
                if in_stop and in_start:
                    _logger.error(f"Could no start or stop controller '{loaded.name}' because of "
                                  "conflicting switching command")
                    return False
                if in_start or (running and not in_stop):
                    active.append(loaded)
            if self._conflict(active):
                _logger.error("Could not switch controllers, due to resource conflict")
                return False
            done = threading.Event()
            self._switch_request = (stop_list, start_list, done)
        if wait is None:
            done.wait()
            return True
        if wait(done, timeout):
            return True
        self._switch_request = None
        return False

    @staticmethod
    def _conflict(active: Sequence[LoadedController]) -> bool:
        claims: Dict[str, List[str]] = {}
        for loaded in active:
            for _, resources in loaded.claimed:
                for resource in resources:
                    claims.setdefault(resource, []).append(loaded.name)
        conflict = False
        for resource, names in sorted(claims.items()):
            if len(names) > 1:
                listed = "".join(name + ", " for name in names)
                _logger.warning(f"Resource conflict on [{resource}].  Controllers = [{listed}]")
                conflict = True
        return conflict

    def list(self) -> List[LoadedController]:
        with self._lock:
            return list(self.controllers)

    def unload_all(self):
        """Stop and unload everything (the model is deleted or the simulator stops)."""
        with self._lock:
            for loaded in self.controllers:
                loaded.controller.close()
            self.controllers = []

    # -- loop side ---------------------------------------------------------------------------------------
    def update(self, now: float, period: float, reset_controllers: bool = False):
        """Every running controller's update, then a pending switch, as ControllerManager::update."""
        controllers = self.controllers
        if reset_controllers:
            for loaded in controllers:
                if loaded.state == "running":
                    loaded.controller.stop_request(now)
                    loaded.controller.start_request(now)
        for loaded in controllers:
            if loaded.controller.state == "running":
                loaded.controller.update(now, period)
        request = self._switch_request
        if request is not None:
            stop_list, start_list, done = request
            for loaded in stop_list:
                if loaded.state == "running":
                    loaded.controller.stop_request(now)
            for loaded in start_list:
                loaded.controller.start_request(now)
            self._switch_request = None
            done.set()


def _join(namespace: str, name: str) -> str:
    return namespace.rstrip("/") + "/" + name
