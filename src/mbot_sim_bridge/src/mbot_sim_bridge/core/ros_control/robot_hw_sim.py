"""gazebo_ros_control's robot hardware simulations, each with upstream's RobotHWSim interface (``init_sim`` is
the constructor, ``read_sim``, ``write_sim``), by ``<robotSimType>`` in ``ROBOT_HW_SIMS``.

DefaultRobotHWSim: one joint per transmission with its first hardware interface; joint limits
from the URDF and the ``joint_limits/<joint>`` parameters, enforced as joint_limits_interface's saturation
handles, or as its soft-limits handles when the URDF joint has a <safety_controller>
handles; ``gazebo_ros_control/pid_gains/<joint>`` turns position and velocity joints into PID-driven effort
joints; the e-stop."""
import math
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence

from ..errors import ConfigError
from ..log import get_logger, info_once, warn_once
from ..description.robot_model import RobotModel
from .angles import normalize_angle, position_error
from .control_toolbox import Pid, clamp
from .hardware_interface import (EFFORT, INTERFACE_TYPES, JOINT_STATE, MAX_JOINT_SPEED, POSITION,
                                 UNBOUNDED_EFFORT, VELOCITY, HardwareInterfaceError)
from .joint_limits import (JointLimits, SoftJointLimits, apply_limit_params, urdf_joint_limits,
                           urdf_soft_joint_limits)
from .transmissions import Transmission

_logger = get_logger(__name__)

_COMMAND_KIND = {EFFORT: "effort", POSITION: "position", VELOCITY: "velocity"}
# What the engine can carry out, by motor mode (a joint's own limits apply before).
_ENGINE_BOUND = {"velocity": MAX_JOINT_SPEED, "effort": UNBOUNDED_EFFORT, "position": math.inf}
# How near its position limit (m or rad) an effort joint pushed outwards counts as resting on the stop.
STOP_MARGIN = 1e-4


@dataclass
class SimJoint:
    """One joint of the hardware simulation: the handle controllers read and command."""
    name: str
    interface: str  # EFFORT, POSITION or VELOCITY
    joint_type: str  # URDF type, or inferred from the limits; "" if unknown
    limits: Optional[JointLimits]
    pid: Optional[Pid] = None
    soft_limits: Optional[SoftJointLimits] = None
    # gazebo_ros_control starts these at 1.0 (position, effort) until the first read.
    position: float = 1.0
    velocity: float = 0.0
    effort: float = 1.0
    command: float = 0.0
    previous_command: float = math.nan  # position saturation's memory
    previous_velocity_command: float = 0.0  # velocity saturation's memory
    # The last motor setting given to the engine: the body's load count (0: none since the last reset) and value.
    sent_loads: int = field(default=0, repr=False)
    sent_value: float = field(default=0.0, repr=False)
    on_stop: bool = field(default=False, repr=False)  # pressed against a position limit, held there (write_sim)

    @property
    def motor(self) -> str:
        """The engine's motor mode: a PID turns a position or velocity joint into an effort one."""
        return "effort" if self.pid is not None else _COMMAND_KIND[self.interface]

    @property
    def lower(self) -> float:
        return self.limits.min_position if self.limits and self.limits.has_position_limits else -math.inf

    @property
    def upper(self) -> float:
        return self.limits.max_position if self.limits and self.limits.has_position_limits else math.inf

    @property
    def effort_limit(self) -> float:
        return self.limits.max_effort if self.limits and self.limits.has_effort_limits else math.inf


class DefaultRobotHWSim:
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
            # As upstream, soft limits apply only to a joint with limits.
            soft_limits = urdf_soft_joint_limits(urdf_joint) if limits is not None else None
            self._check_limits(joint_name, interface, limits, soft_limits)
            pid = None
            if interface != EFFORT:
                # Upstream logs "No p gain specified" as an error for every joint without gains; that is the
                # normal case (the joint is driven directly), so it is said once at INFO here.
                gains = pid_params.get(joint_name)
                pid = Pid.from_params(gains, f"{pid_namespace}/{joint_name}", quiet=True)
                if pid is None:
                    drive = "position servo" if interface == POSITION else "velocity motor"
                    why = ("its PID gains are refused" if isinstance(gains, dict) and "p" in gains
                           else f"no {pid_namespace}/{joint_name}/p")
                    info_once(_logger, f"{label}: {why}: joint '{joint_name}' is driven directly ({drive})")
            self.joints[joint_name] = SimJoint(joint_name, interface, joint_type, limits, pid, soft_limits)
        self.names = list(self.joints)
        # (joint, motor mode, what the engine can carry out in that mode) for write_sim, after every step
        self._motors = [(joint, joint.motor, _ENGINE_BOUND[joint.motor]) for joint in self.joints.values()]
        self._indices = [robot.joint_index[name] for name in self.names]

    def _check_limits(self, joint: str, interface: str, limits: Optional[JointLimits],
                      soft_limits: Optional[SoftJointLimits]):
        """The limit handles' constructors refuse limits they cannot enforce (JointLimitsInterfaceException); the
        soft velocity handle needs none, the soft position handle needs velocity limits."""
        if limits is None:
            return
        needs_velocity = (EFFORT, POSITION) if soft_limits is not None else (EFFORT, VELOCITY)
        if interface in needs_velocity and not limits.has_velocity_limits:
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

    def read_sim(self) -> bool:
        """readSim: positions (revolute and continuous unwrapped step by step, as upstream), velocities, efforts.
        False, with nothing read, when the physics made the model's state NaN: the Simulation freezes the model
        once the batch of steps ends, and the controllers must not carry the NaN past a reset."""
        if not self.names:
            return True
        rows = self.robot.joint_rows(self._indices)
        # One sum instead of a test per value: finite states cannot overflow it (efforts and speeds are
        # bounded far below the float range), so a non-finite sum means a NaN or inf in the state.
        if not math.isfinite(sum([row[0] + row[1] + row[3] for row in rows])):
            return False
        for joint, row in zip(self.joints.values(), rows):
            if joint.joint_type == "prismatic":
                joint.position = row[0]
            else:
                # shortest_angular_distance(joint.position, row[0]) without its extra call (every step)
                joint.position += normalize_angle(row[0] - joint.position)
            joint.velocity = row[1]
            joint.effort = row[3]
        return True

    def write_sim(self, period: float):
        """writeSim: e-stop, limit saturation, then each joint's motor; the engine is told only of changes.
        Written as one pass over the joints with the motor settings inline: it runs after every physics step."""
        e_stop = self.e_stop_active
        if e_stop:
            if not self._last_e_stop_active:
                self._held_positions = {name: joint.position for name, joint in self.joints.items()}
                self._last_e_stop_active = True
        else:
            self._last_e_stop_active = False
        loads = self.robot.loads
        for joint, motor, bound in self._motors:
            if e_stop and joint.interface == POSITION:
                joint.command = self._held_positions.get(joint.name, joint.position)
            if not math.isfinite(joint.command):
                joint.command = self._finite(joint, _COMMAND_KIND[joint.interface], joint.command)
            if joint.limits is not None:
                self._saturate(joint, period)
            if joint.pid is not None:
                value = self._pid_effort(joint, period)
            elif e_stop and motor != "position":
                value = 0.0
            else:
                value = joint.command
            if not -bound <= value <= bound:  # value is finite: the checks above have seen to that
                value = self._clamped_to_engine(joint, motor, value)
            # Bullet keeps a velocity or position motor's setting until it is changed, so an unchanged one is
            # not sent again; a torque it applies for one step only, so efforts go out every step (as Gazebo's
            # SetForce).
            if motor == "effort":
                self._set_effort(joint, value)
            elif value != joint.sent_value or loads != joint.sent_loads:
                joint.sent_loads, joint.sent_value = loads, value
                self._set_motor(joint, motor, value)

    def _set_effort(self, joint: SimJoint, value: float):
        """The effort for the next step. A joint pushed against its position limit rests on it, as on ODE's
        stops in Gazebo: Bullet's limit takes hold only once the joint is past it, so the push and the saturation
        (no outward effort past the limit) made it chatter there at up to 0.4 m/s, and a gripper's stall check
        never fired. There a zero-velocity motor of that effort holds it instead."""
        if (value > 0.0 and joint.position >= joint.upper - STOP_MARGIN
                or value < 0.0 and joint.position <= joint.lower + STOP_MARGIN):
            joint.on_stop = True
            self.robot.set_joint_velocity(joint.name, 0.0, abs(value))
            return
        if joint.on_stop:
            joint.on_stop = False
            self.robot.release_joint(joint.name)
        self.robot.set_joint_effort(joint.name, value)

    def _set_motor(self, joint: SimJoint, motor: str, value: float):
        """A new setting of a position or velocity motor."""
        if motor == "position":
            # Gazebo teleports the joint (SetPosition) regardless of load; Bullet's position servo with an
            # unbounded force is the stable equivalent that still lets contacts act.
            self.robot.set_joint_position(joint.name, value, UNBOUNDED_EFFORT)
        else:
            limit = joint.effort_limit
            self.robot.set_joint_velocity(joint.name, value, limit if math.isfinite(limit) else UNBOUNDED_EFFORT)

    def _saturate(self, joint: SimJoint, period: float):
        if joint.soft_limits is not None:
            self._soft_saturate(joint, period)
            return
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

    def _soft_saturate(self, joint: SimJoint, period: float):
        """joint_limits_interface's soft-limits handles: the allowed velocity shrinks towards each soft limit at
        k_position per unit of distance (within the velocity limit), and an effort is bounded by k_velocity times
        how far the joint's velocity is from that allowed one (within the effort limit)."""
        limits, soft = joint.limits, joint.soft_limits
        max_velocity = limits.max_velocity if limits.has_velocity_limits else math.inf
        position = joint.position
        if joint.interface == POSITION:
            if math.isnan(joint.previous_command):
                joint.previous_command = joint.position
            position = joint.previous_command  # upstream bounds each step from the last command
        if limits.has_position_limits:
            low_velocity = clamp(-soft.k_position * (position - soft.min_position), -max_velocity, max_velocity)
            high_velocity = clamp(-soft.k_position * (position - soft.max_position), -max_velocity, max_velocity)
        else:
            low_velocity, high_velocity = -max_velocity, max_velocity
        if joint.interface == EFFORT:
            low = clamp(-soft.k_velocity * (joint.velocity - low_velocity), -limits.max_effort, limits.max_effort)
            high = clamp(-soft.k_velocity * (joint.velocity - high_velocity), -limits.max_effort, limits.max_effort)
        elif joint.interface == POSITION:
            low, high = position + low_velocity * period, position + high_velocity * period
            if limits.has_position_limits:
                low, high = max(low, limits.min_position), min(high, limits.max_position)
        else:
            low, high = low_velocity, high_velocity
            if limits.has_acceleration_limits:
                low = max(joint.velocity - limits.max_acceleration * period, low)
                high = min(joint.velocity + limits.max_acceleration * period, high)
        joint.command = clamp(joint.command, low, high)
        if joint.interface == POSITION:
            joint.previous_command = joint.command

    def _pid_effort(self, joint: SimJoint, period: float) -> float:
        """The effort a PID-driven position or velocity joint gets (on e-stop: towards the held position or zero
        speed), within the joint's effort limit."""
        if joint.interface == POSITION:
            error = position_error(joint.joint_type, joint.position, joint.command, joint.lower, joint.upper)
        else:
            error = -joint.velocity if self.e_stop_active else joint.command - joint.velocity
        limit = joint.effort_limit
        # The one value not checked by write_sim: gains like 1e308 overflow it, past an unbounded limit.
        effort = self._finite(joint, "effort", joint.pid.compute(error, period))
        return clamp(effort, -limit, limit)

    def _finite(self, joint: SimJoint, what: str, value: float) -> float:
        """``value``, or the joint held (at its position, or at zero speed or effort) when it is NaN or inf:
        the engine would make the model's state NaN and disturb every other model."""
        if math.isfinite(value):
            return value
        hold = joint.position if what == "position" else 0.0
        warn_once(_logger, f"{self.label}: joint '{joint.name}': {what} command {value} is not a finite number; "
                           f"the joint is held ({hold:g}) until a finite command arrives")
        return hold

    def _clamped_to_engine(self, joint: SimJoint, mode: str, value: float) -> float:
        """A ``value`` beyond ``_ENGINE_BOUND`` at its bound (joint speeds at MAX_JOINT_SPEED, efforts at
        UNBOUNDED_EFFORT); said once per joint."""
        bound = _ENGINE_BOUND[mode]
        warn_once(_logger, f"{self.label}: joint '{joint.name}': {mode} command {value:g} is beyond the engine's "
                           f"{bound:g}; clamped")
        return math.copysign(bound, value)

    def joints_set(self, positions: Dict[str, float]):
        """set_model_configuration put joints at positions, at rest: read them as they are, and a position
        joint's command is its new position, from the next step on, until a controller commands it (else it
        would return to 0)."""
        for name, position in positions.items():
            joint = self.joints.get(name)
            if joint is not None:
                joint.position, joint.velocity = position, 0.0
                if joint.interface == POSITION:
                    joint.command = joint.previous_command = position
                    if joint.motor == "position":
                        joint.sent_loads, joint.sent_value = self.robot.loads, position
                        self._set_motor(joint, "position", position)

    def forget_motors(self):
        """After a reset the engine's motors may have changed; send every setting again."""
        for joint in self.joints.values():
            joint.sent_loads = 0


# <robotSimType> -> class; a robot's own hardware simulation is a class with the same interface and a line here.
ROBOT_HW_SIMS = {"gazebo_ros_control/DefaultRobotHWSim": DefaultRobotHWSim}
