"""gripper_action_controller (ros_controllers, Noetic): one joint behind a control_msgs/GripperCommand action.

A goal sets the position and the effort bound; the goal succeeds (reached_goal) once the joint is within
``goal_tolerance``, and is aborted as stalled once the joint has moved slower than
``stall_velocity_threshold`` for ``stall_timeout`` seconds short of it, as upstream (a gripper holding an object
ends ABORTED with stalled true). The effort type drives the joint with a PID from ``gains/<joint>`` clamped
to the goal's max_effort (0 clamps it to nothing, as upstream); the position type commands the position.
The ROS layer owns the action server and publishes what ``ended`` collects.
"""
import sys
import threading
from dataclasses import dataclass
from typing import List, Optional

from ..log import get_logger
from .control_toolbox import Pid, clamp
from .controller_interface import Controller, param
from .controller_manager import ControllerInitError
from .hardware_interface import EFFORT
from .joint_trajectory_controller import ABORTED, CANCELED, SUCCEEDED

_logger = get_logger(__name__)


@dataclass(eq=False)
class GripperGoal:
    """control_msgs/GripperCommand as a goal; ``handle`` is the ROS layer's goal handle."""
    position: float
    max_effort: float
    handle: object = None


@dataclass
class GripperEnd:
    """What became of a goal, with control_msgs/GripperCommandResult's values."""
    goal: GripperGoal
    status: str
    position: float = 0.0
    effort: float = 0.0
    stalled: bool = False
    reached_goal: bool = False


class GripperActionController(Controller):
    """``position_controllers/`` and ``effort_controllers/GripperActionController``; INTERFACE set per type."""

    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context)
        namespace = context.namespace
        joint = params.get("joint")
        if not isinstance(joint, str) or not joint:
            raise ControllerInitError("Could not find joint name on param server")
        if context.urdf is None:
            raise ControllerInitError("Failed to parse URDF contained in 'robot_description' parameter")
        if joint not in context.urdf.joints:
            raise ControllerInitError(f"Could not find joint '{joint}' in URDF model.")
        try:
            self.joint = self.handle(joint)
        except Exception:
            raise ControllerInitError(f"Could not find joint '{joint}' in "
                                      f"'hardware_interface::{self.INTERFACE}'.") from None
        self.goal_tolerance = abs(param(params, "goal_tolerance", 0.01, float, namespace))
        self.default_max_effort = abs(param(params, "max_effort", 0.0, float, namespace))
        self.stall_velocity_threshold = param(params, "stall_velocity_threshold", 0.001, float, namespace)
        self.stall_timeout = param(params, "stall_timeout", 1.0, float, namespace)
        self.pid: Optional[Pid] = None
        if self.INTERFACE == EFFORT:
            self.pid = Pid.from_params(param(params, "gains/" + joint, None, dict), f"{namespace}/gains/{joint}")
            if self.pid is None:
                # Upstream goes on with a PID of zero gains: the gripper never moves.
                _logger.warning("Failed to initialize PID gains from ROS parameter server.")
                self.pid = Pid()
        self.lock = threading.RLock()
        self.position, self.max_effort = self.joint.position, self.default_max_effort
        self.active_goal: Optional[GripperGoal] = None
        self.ended: List[GripperEnd] = []
        self.computed_command = 0.0
        self.time = self.last_movement_time = 0.0

    def starting(self, now):
        with self.lock:
            self.position, self.max_effort = self.joint.position, self.default_max_effort
            if self.pid is not None:
                self.pid.reset()
                self.joint.command = 0.0
            self.time = self.last_movement_time = now

    def stopping(self, now):
        with self.lock:
            self._preempt()

    def restart_clock(self, now):
        self.time = self.last_movement_time = now

    def _preempt(self):
        if self.active_goal is not None:
            self.ended.append(GripperEnd(self.active_goal, CANCELED))
            self.active_goal = None

    def accept_goal(self, goal: GripperGoal) -> bool:
        """goalCB: False when the controller is not running or the goal is not finite numbers (upstream takes
        those); else the goal replaces the active one."""
        with self.lock:
            if self.state != "running":
                _logger.error(f"{self.name}: Can't accept new action goals. Controller is not running.")
                return False
            if not self.finite_command([self.joint.name] * 2, [goal.position, goal.max_effort]):
                return False
            self._preempt()
            self.position, self.max_effort = goal.position, goal.max_effort
            self.last_movement_time = self.time
            self.active_goal = goal
            return True

    def cancel_goal(self, goal: GripperGoal):
        with self.lock:
            if goal is self.active_goal:
                self.active_goal = None
                self.position, self.max_effort = self.joint.position, self.default_max_effort
                self.ended.append(GripperEnd(goal, CANCELED))

    def update(self, now, period):
        with self.lock:
            self.time = now
            position, velocity = self.joint.position, self.joint.velocity
            error = self.position - position
            self._check_for_success(now, error, position, velocity)
            if self.pid is None:
                self.joint.command = self.position
                self.computed_command = self.max_effort
            else:
                bound = abs(self.max_effort)
                self.computed_command = clamp(self.pid.compute(error, period, -velocity), -bound, bound)
                self.joint.command = self.computed_command

    def _check_for_success(self, now: float, error: float, position: float, velocity: float):
        goal = self.active_goal
        if goal is None:
            return
        if abs(error) < self.goal_tolerance:
            self.ended.append(GripperEnd(goal, SUCCEEDED, position, self.computed_command, False, True))
            self.active_goal = None
        elif abs(velocity) > self.stall_velocity_threshold:
            self.last_movement_time = now
        elif now - self.last_movement_time > self.stall_timeout:
            self.ended.append(GripperEnd(goal, ABORTED, position, self.computed_command, True, False))
            self.active_goal = None

    def publish_due(self, now):
        return bool(self.ended)

    def steps_until_publish(self, now, step_size):
        # A goal's end waits for the next stop of the loop, as upstream's waits for its action monitor timer.
        return 1 if self.ended else sys.maxsize
