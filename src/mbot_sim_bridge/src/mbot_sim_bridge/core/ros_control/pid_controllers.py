"""The PID controllers of effort_controllers and velocity_controllers: JointPositionController,
JointVelocityController, JointGroupPositionController (control_toolbox's Pid from ``pid/p i d i_clamp``).

The single-joint ones put a sample of their state into the ``outbox`` every tenth update, the first included, as
upstream fills its control_msgs/JointControllerState (``state``) then; the ROS layer publishes it."""
from typing import NamedTuple, Optional

from ..description.robot_model import RobotModel
from .angles import position_error
from .control_toolbox import Pid
from .controller_manager import ControllerInitError
from .hardware_interface import EFFORT
from .controller_interface import Controller, param
from .forward_command_controller import ForwardJointGroupCommandController, joint_name_param


class _UrdfJointLimits:
    """The URDF joint a PID position controller needs: its type and position limits."""

    def __init__(self, urdf: Optional[RobotModel], joint: str):
        if urdf is None:
            raise ControllerInitError("Failed to parse urdf file")
        urdf_joint = urdf.joints.get(joint)
        if urdf_joint is None:
            raise ControllerInitError(f"Could not find joint '{joint}' in urdf")
        self.type = urdf_joint.type
        self.lower, self.upper = (urdf_joint.lower, urdf_joint.upper) if urdf_joint.has_limit else (0.0, 0.0)

    def enforce(self, command: float) -> float:
        if self.type in ("revolute", "prismatic"):
            if command > self.upper:
                return self.upper
            if command < self.lower:
                return self.lower
        return command


def _pid(params: dict, key: str, namespace: str) -> Pid:
    pid = Pid.from_params(param(params, key, None, dict), namespace + "/" + key)
    if pid is None:
        raise ControllerInitError("")  # Pid.from_params has said why
    return pid


STATE_EVERY_UPDATES = 10


class StateSample(NamedTuple):
    """control_msgs/JointControllerState's values."""
    set_point: float
    process_value: float
    process_value_dot: float
    error: float
    time_step: float
    command: float
    p: float
    i: float
    d: float
    i_clamp: float
    antiwindup: bool


class StateSampling:
    """Mixed into a single-joint PID controller: a StateSample into the ``outbox`` every STATE_EVERY_UPDATES
    updates."""

    def _sample(self, now: float, set_point: float, process_value: float, period: float):
        if self.updates % STATE_EVERY_UPDATES == 0:
            pid = self.pid
            self.outbox.append((now, StateSample(set_point, process_value, self.joint.velocity, self.error, period,
                                                 self.output, pid.p, pid.i, pid.d, pid.i_max, pid.antiwindup)))
        self.updates += 1


class PidPositionController(StateSampling, Controller):
    """effort_controllers/JointPositionController (INTERFACE EFFORT) and velocity_controllers/
    JointPositionController (INTERFACE VELOCITY): PID on the position error, output as the joint's command."""

    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context)
        self.namespace = context.namespace
        joint = joint_name_param(params, self.namespace)
        self.pid = _pid(params, "pid", self.namespace)
        self.joint = self.handle(joint)
        self.urdf = _UrdfJointLimits(context.urdf, joint)
        self.target = 0.0
        self.target_velocity = None
        self.error = self.output = 0.0
        self.updates = 0

    def set_command(self, position: float, velocity: Optional[float] = None):
        if self.finite_command([self.joint.name] * 2, [position, 0.0 if velocity is None else velocity]):
            self.target, self.target_velocity = position, velocity

    def starting(self, now):
        self.target, self.target_velocity = self.urdf.enforce(self.joint.position), None
        self.pid.reset()

    def update(self, now, period):
        target = self.urdf.enforce(self.target)
        self.error = position_error(self.urdf.type, self.joint.position, target, self.urdf.lower, self.urdf.upper)
        velocity_error = None if self.target_velocity is None else self.target_velocity - self.joint.velocity
        self.output = self.pid.compute(self.error, period, velocity_error)
        self.joint.command = self.output
        self._sample(now, target, self.joint.position, period)


class EffortVelocityController(StateSampling, Controller):
    """effort_controllers/JointVelocityController: PID on the velocity error, output as effort."""

    INTERFACE = EFFORT

    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context)
        self.namespace = context.namespace
        self.joint = self.handle(joint_name_param(params, self.namespace))
        self.pid = _pid(params, "pid", self.namespace)
        self.target = 0.0
        self.error = self.output = 0.0
        self.updates = 0

    def set_command(self, velocity: float):
        if self.finite_command([self.joint.name], [velocity]):
            self.target = velocity

    def starting(self, now):
        self.target = 0.0
        self.pid.reset()

    def update(self, now, period):
        self.error = self.target - self.joint.velocity
        self.output = self.pid.compute(self.error, period)
        self.joint.command = self.output
        self._sample(now, self.target, self.joint.velocity, period)


class EffortGroupPositionController(ForwardJointGroupCommandController):
    """effort_controllers/JointGroupPositionController: one PID per joint, from ``<joint>/pid``."""

    INTERFACE = EFFORT

    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context)
        self.urdf = [_UrdfJointLimits(context.urdf, joint) for joint in self.joint_names]
        self.pids = []
        for joint in self.joint_names:
            pid = Pid.from_params(param(params, joint + "/pid", None, dict), self.namespace + "/" + joint + "/pid")
            if pid is None:
                raise ControllerInitError(f"Failed to load PID parameters from {joint}/pid")
            self.pids.append(pid)

    def starting(self, now):
        self.commands = [limits.enforce(joint.position) for joint, limits in zip(self.joints, self.urdf)]
        for pid in self.pids:
            pid.reset()

    def update(self, now, period):
        for joint, command, limits, pid in zip(self.joints, self.commands, self.urdf, self.pids):
            target = limits.enforce(command)
            joint.command = pid.compute(position_error(limits.type, joint.position, target, limits.lower,
                                                        limits.upper), period)
