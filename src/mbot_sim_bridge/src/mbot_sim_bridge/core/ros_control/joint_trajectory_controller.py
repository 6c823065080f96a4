"""joint_trajectory_controller (ros_controllers, Noetic) for the position, velocity and effort interfaces.

Upstream's behaviour, piece by piece: quintic-spline segments that are linear, cubic or quintic by the
derivatives a point gives; a trajectory per joint kept in the controller's own time ("uptime", from 0 when it
starts); a new trajectory spliced onto the current one at its start time (the current one runs until then, a
bridge segment joins the two); points in the past dropped; hold (or, with ``stop_trajectory_duration``, a
smooth stop) on start, on cancel and on an empty trajectory; path and goal tolerances from ``constraints`` and
the goal; the goal's outcome with FollowJointTrajectory's error codes.

The ROS layer (``plugins/ros_controllers.py``) owns the topics, the action server and the query_state service;
it hands goals in as ``TrajectoryGoal`` and publishes what ``ended`` collects, and the state and feedback
that the update puts into the ``outbox`` at ``state_publish_rate`` and ``action_monitor_rate``. Goal callbacks
arrive in ROS threads, the update in the loop thread: ``lock`` serialises them.
"""
import copy
import math
import sys
import threading
from dataclasses import dataclass, field
from typing import List, NamedTuple, Optional, Sequence, Tuple

from ..log import get_logger, warn_once
from .angles import shortest_angular_distance
from .control_toolbox import Pid
from .controller_interface import Controller, param
from .controller_manager import ControllerInitError, ControllerInitException
from .hardware_interface import POSITION

_logger = get_logger(__name__)

# control_msgs/FollowJointTrajectoryResult error codes
SUCCESSFUL, INVALID_GOAL, INVALID_JOINTS = 0, -1, -2
PATH_TOLERANCE_VIOLATED, GOAL_TOLERANCE_VIOLATED = -4, -5
# what became of a goal, as actionlib's terminal states
SUCCEEDED, ABORTED, CANCELED = "succeeded", "aborted", "canceled"


@dataclass
class TrajectoryPoint:
    """trajectory_msgs/JointTrajectoryPoint: empty velocities/accelerations mean "not given"."""
    positions: Sequence[float]
    velocities: Sequence[float] = ()
    accelerations: Sequence[float] = ()
    time_from_start: float = 0.0


@dataclass
class JointTrajectory:
    """trajectory_msgs/JointTrajectory; ``start`` is header.stamp in sim seconds (0: start at once)."""
    joint_names: Sequence[str]
    points: Sequence[TrajectoryPoint]
    start: float = 0.0


@dataclass
class JointTolerance:
    """control_msgs/JointTolerance: > 0 sets, < 0 clears (0.0, unchecked), 0 keeps the default."""
    name: str
    position: float = 0.0
    velocity: float = 0.0
    acceleration: float = 0.0


@dataclass
class StateTolerances:
    position: float = 0.0
    velocity: float = 0.0
    acceleration: float = 0.0

    def update(self, tolerance: JointTolerance):
        for key in ("position", "velocity", "acceleration"):
            value = getattr(tolerance, key)
            if value > 0.0:
                setattr(self, key, value)
            elif value < 0.0:
                setattr(self, key, 0.0)

    def holds(self, error: Tuple[float, float, float]) -> bool:
        """checkStateTolerancePerJoint: a tolerance of 0 is not checked."""
        return all(not (limit > 0.0 and abs(value) > limit)
                   for limit, value in zip((self.position, self.velocity, self.acceleration), error))


@dataclass
class JointTolerances:
    """SegmentTolerancesPerJoint."""
    path: StateTolerances = field(default_factory=StateTolerances)
    goal: StateTolerances = field(default_factory=StateTolerances)
    goal_time: float = 0.0


@dataclass(eq=False)
class TrajectoryGoal:
    """A FollowJointTrajectory goal as the controller sees it; ``handle`` is the ROS layer's goal handle."""
    trajectory: JointTrajectory
    path_tolerance: Sequence[JointTolerance] = ()
    goal_tolerance: Sequence[JointTolerance] = ()
    goal_time_tolerance: float = 0.0
    handle: object = None


@dataclass
class GoalEnd:
    goal: TrajectoryGoal
    status: str  # SUCCEEDED, ABORTED or CANCELED
    error_code: int = SUCCESSFUL
    error_string: str = ""


class StatePoints(NamedTuple):
    """What the ``state`` topic and the action's feedback carry, as one update left it: the desired
    (positions, velocities, accelerations), actual (positions, velocities) and error points, their times from
    the segment's start; ``goal`` is the goal a feedback is for (None: the state topic)."""
    desired: Tuple[List[float], List[float], List[float]]
    actual: Tuple[List[float], List[float]]
    error: Tuple[List[float], List[float], List[float]]
    times_from_start: Tuple[float, float, float]  # desired, actual, error
    goal: Optional[TrajectoryGoal]


def _spline_coefficients(start: Tuple[float, Optional[float], Optional[float]],
                         end: Tuple[float, Optional[float], Optional[float]], duration: float) -> List[float]:
    """QuinticSplineSegment's coefficients: linear without velocities, cubic with them, quintic with
    accelerations too (on both ends)."""
    (p0, v0, a0), (p1, v1, a1) = start, end
    T = duration
    if v0 is None or v1 is None:
        return [p0, 0.0 if T == 0.0 else (p1 - p0) / T, 0.0, 0.0, 0.0, 0.0]
    if a0 is None or a1 is None:
        if T == 0.0:
            return [p0, v0, 0.0, 0.0, 0.0, 0.0]
        return [p0, v0, (-3.0 * p0 + 3.0 * p1 - 2.0 * v0 * T - v1 * T) / T ** 2,
                (2.0 * p0 - 2.0 * p1 + v0 * T + v1 * T) / T ** 3, 0.0, 0.0]
    if T == 0.0:
        return [p0, v0, 0.5 * a0, 0.0, 0.0, 0.0]
    return [p0, v0, 0.5 * a0,
            (-20.0 * p0 + 20.0 * p1 - 3.0 * a0 * T ** 2 + a1 * T ** 2 - 12.0 * v0 * T - 8.0 * v1 * T) / (2.0 * T ** 3),
            (30.0 * p0 - 30.0 * p1 + 3.0 * a0 * T ** 2 - 2.0 * a1 * T ** 2 + 16.0 * v0 * T + 14.0 * v1 * T)
            / (2.0 * T ** 4),
            (-12.0 * p0 + 12.0 * p1 - a0 * T ** 2 + a1 * T ** 2 - 6.0 * v0 * T - 6.0 * v1 * T) / (2.0 * T ** 5)]


def _polynomial(c: Sequence[float], t: float) -> Tuple[float, float, float]:
    position = c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * (c[4] + t * c[5]))))
    velocity = c[1] + t * (2.0 * c[2] + t * (3.0 * c[3] + t * (4.0 * c[4] + t * 5.0 * c[5])))
    acceleration = 2.0 * c[2] + t * (6.0 * c[3] + t * (12.0 * c[4] + t * 20.0 * c[5]))
    return position, velocity, acceleration


class Segment:
    """One joint's JointTrajectorySegment<QuinticSplineSegment>: states are (position, velocity or None,
    acceleration or None); outside its time span it holds its end position with zero velocity."""

    def __init__(self, start_time: float, start_state, end_time: float, end_state, time_from_start: float = 0.0,
                 goal: Optional[TrajectoryGoal] = None, tolerances: Optional[JointTolerances] = None):
        if end_time < start_time:
            raise ValueError("Quintic spline segment can't be constructed: end_time < start_time.")
        self.start_time, self.duration = start_time, end_time - start_time
        self.time_from_start = time_from_start
        self.coefficients = _spline_coefficients(start_state, end_state, self.duration)
        self.goal = goal
        self.tolerances = tolerances or JointTolerances()

    @property
    def end_time(self) -> float:
        return self.start_time + self.duration

    def sample(self, time: float) -> Tuple[float, float, float]:
        t = time - self.start_time
        if t < 0.0:
            return _polynomial(self.coefficients, 0.0)[0], 0.0, 0.0
        if t > self.duration:
            return _polynomial(self.coefficients, self.duration)[0], 0.0, 0.0
        return _polynomial(self.coefficients, t)

    def with_goal(self, goal: Optional[TrajectoryGoal]) -> "Segment":
        other = copy.copy(self)
        other.goal = goal
        return other


def find_segment(segments: Sequence[Segment], time: float) -> Optional[int]:
    """The index of the segment active at ``time`` (the last that starts at or before it); None before all."""
    found = None
    for index, segment in enumerate(segments):
        if time < segment.start_time:
            break
        found = index
    return found


def sample(segments: Sequence[Segment], time: float) -> Tuple[Optional[int], Tuple[float, float, float]]:
    """trajectory_interface::sample: before the first segment it samples that one (and says none is active)."""
    index = find_segment(segments, time)
    return index, segments[0 if index is None else index].sample(time)


def wraparound_offset(previous: float, following: float, wraps: bool) -> float:
    """wraparoundJointOffset: a continuous joint's new trajectory is shifted by whole turns to start nearest
    to where the current one is."""
    if not wraps:
        return 0.0
    distance = shortest_angular_distance(previous, following)
    if abs(abs(distance) - math.pi) < 1e-9:
        distance = abs(distance) if following > previous else -abs(distance)
    return previous + distance - following


def _point_state(point: TrajectoryPoint, index: int, offset: float):
    return (point.positions[index] + offset,
            point.velocities[index] if point.velocities else None,
            point.accelerations[index] if point.accelerations else None)


def _point_valid(point: TrajectoryPoint, joints: int) -> bool:
    return all(not values or len(values) == joints for values in (point.velocities, point.accelerations))


def _period(rate: float, name: str, namespace: str) -> float:
    """Upstream's ros::Duration(1.0 / rate): a rate of 0 (or NaN, or one below 2^-31 Hz) makes that throw and the
    load fail; a negative rate gives a negative period, which upstream's checks pass at every update (said once
    here, as upstream says nothing); inf gives 0."""
    period = 1.0 / rate if rate != 0.0 else math.inf
    if not abs(period) < 2.0 ** 31:
        raise ControllerInitException(f"Duration is out of dual 32-bit range ({namespace}/{name} is {rate:g}, a period "
                                      f"of 1/{rate:g} s)")
    if period < 0.0:
        warn_once(_logger, f"{namespace}/{name} is {rate:g}: a negative period, so at every update, as upstream")
    return period


class TrajectoryError(Exception):
    """A trajectory that cannot be followed; the message is upstream's error string."""


class _ClosedLoopAdapter:
    """HardwareInterfaceAdapter for the velocity and effort interfaces: a PID per joint from ``gains/<joint>``
    on the position error (and the velocity error as its derivative), plus ``velocity_ff/<joint>`` times the
    desired velocity."""

    def __init__(self, joints, params: dict, namespace: str):
        self.joints = joints
        self.pids: List[Pid] = []
        for joint in joints:
            pid = Pid.from_params(param(params, "gains/" + joint.name, None, dict),
                                  f"{namespace}/gains/{joint.name}")
            if pid is None:
                # Upstream warns and goes on with null PIDs for the remaining joints, which crashes in update.
                raise ControllerInitError("Failed to initialize PID gains from ROS parameter server.")
            self.pids.append(pid)
        self.velocity_ff = [param(params, "velocity_ff/" + joint.name, 0.0, float, namespace) for joint in joints]

    def starting(self):
        for joint, pid in zip(self.joints, self.pids):
            pid.reset()
            joint.command = 0.0

    def command(self, period: float, desired, error):
        for i, (joint, pid) in enumerate(zip(self.joints, self.pids)):
            joint.command = desired[1][i] * self.velocity_ff[i] + pid.compute(error[0][i], period, error[1][i])


class _PositionAdapter:
    def __init__(self, joints, params, namespace):
        self.joints = joints

    def starting(self):
        for joint in self.joints:
            joint.command = joint.position

    def command(self, period, desired, error):
        for joint, position in zip(self.joints, desired[0]):
            joint.command = position


class JointTrajectoryController(Controller):
    """``<interface>_controllers/JointTrajectoryController``; INTERFACE is set per type."""

    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context)
        namespace = context.namespace
        self.namespace = namespace
        self.state_publish_period = _period(param(params, "state_publish_rate", 50.0, float, namespace),
                                            "state_publish_rate", namespace)
        self.action_monitor_period = _period(param(params, "action_monitor_rate", 20.0, float, namespace),
                                             "action_monitor_rate", namespace)
        self.stop_trajectory_duration = param(params, "stop_trajectory_duration", 0.0, float, namespace)
        if not 0.0 <= self.stop_trajectory_duration < math.inf:
            warn_once(_logger, f"{namespace}/stop_trajectory_duration is {self.stop_trajectory_duration}, not a "
                               "duration; stopping by holding where the joints are (0)")
            self.stop_trajectory_duration = 0.0
        self.allow_partial_joints_goal = param(params, "allow_partial_joints_goal", False, bool, namespace)
        joints = params.get("joints")
        if not isinstance(joints, list):
            raise ControllerInitError(f"Could not find 'joints' parameter (namespace: {namespace})." if joints is None
                                      else f"The 'joints' parameter is not an array (namespace: {namespace}).")
        if not all(isinstance(joint, str) for joint in joints):
            raise ControllerInitError(f"The 'joints' parameter contains a non-string element (namespace: {namespace}).")
        if not joints:
            raise ControllerInitError(f"Could not find 'joints' parameter (namespace: {namespace}).")
        if context.urdf is None:
            raise ControllerInitError("Failed to parse URDF contained in 'robot_description' parameter")
        self.joint_names = list(joints)
        self.wraps = []
        for joint in self.joint_names:
            urdf_joint = context.urdf.joints.get(joint)
            if urdf_joint is None:
                raise ControllerInitError(f"Could not find joint '{joint}' in URDF model.")
            self.wraps.append(urdf_joint.type == "continuous")
        self.joints = []
        for joint in self.joint_names:
            try:
                self.joints.append(self.handle(joint))
            except Exception:
                raise ControllerInitError(f"Could not find joint '{joint}' in "
                                          f"'hardware_interface::{self.INTERFACE}'.") from None
        self.default_tolerances = self._tolerances_from_params(param(params, "constraints", {}, dict, namespace))
        adapter = _PositionAdapter if self.INTERFACE == POSITION else _ClosedLoopAdapter
        self.adapter = adapter(self.joints, params, namespace)
        self.lock = threading.RLock()
        count = len(self.joint_names)
        self.time = self.uptime = self.period = 0.0
        self.trajectory: List[List[Segment]] = []
        self.active_goal: Optional[TrajectoryGoal] = None
        self.successful: List[bool] = [False] * count
        self.desired = ([0.0] * count, [0.0] * count, [0.0] * count)
        self.actual = ([0.0] * count, [0.0] * count)
        self.error = ([0.0] * count, [0.0] * count, [0.0] * count)
        self.times_from_start = (0.0, 0.0, 0.0)  # desired, actual, error
        self.ended: List[GoalEnd] = []
        self._last_state_publish = 0.0
        self._last_feedback = -math.inf

    def _tolerances_from_params(self, constraints: dict) -> List[JointTolerances]:
        """getSegmentTolerances: ``<joint>/trajectory`` and ``<joint>/goal`` positions, the shared
        ``stopped_velocity_tolerance`` (0.01) for the goal velocity, ``goal_time``."""
        where = self.namespace + "/constraints"
        stopped = param(constraints, "stopped_velocity_tolerance", 0.01, float, where)
        goal_time = param(constraints, "goal_time", 0.0, float, where)
        return [JointTolerances(StateTolerances(param(constraints, joint + "/trajectory", 0.0, float, where)),
                                StateTolerances(param(constraints, joint + "/goal", 0.0, float, where), stopped),
                                goal_time)
                for joint in self.joint_names]

    # -- controller life ---------------------------------------------------------------------------------
    def starting(self, now):
        with self.lock:
            self.time, self.uptime = now, 0.0
            self.desired = ([joint.position for joint in self.joints], [joint.velocity for joint in self.joints],
                            [0.0] * len(self.joints))
            self._hold(self.uptime)
            self._last_state_publish = self.uptime
            self.adapter.starting()

    def stopping(self, now):
        with self.lock:
            self._preempt()

    def restart_clock(self, now):
        self.time = now
        self._last_feedback = -math.inf

    def _hold(self, uptime: float, goal: Optional[TrajectoryGoal] = None):
        """setHoldPosition: hold where the joints are, or stop smoothly over stop_trajectory_duration from the
        desired state (a segment to the velocity-reversed state over twice the time, sampled at its middle)."""
        trajectory = []
        for i, joint in enumerate(self.joints):
            if self.stop_trajectory_duration == 0.0:
                state = (joint.position, 0.0, 0.0)
                segment = Segment(uptime, state, uptime, state, goal=goal)
            else:
                end, end_2x = uptime + self.stop_trajectory_duration, uptime + 2.0 * self.stop_trajectory_duration
                start = (self.desired[0][i], self.desired[1][i], 0.0)
                turned = Segment(uptime, start, end_2x, (start[0], -start[1], 0.0)).sample(end)
                segment = Segment(uptime, start, end, turned, goal=goal)
            trajectory.append([segment])
        self.trajectory = trajectory

    def _preempt(self):
        if self.active_goal is not None:
            self.ended.append(GoalEnd(self.active_goal, CANCELED))
            self.active_goal = None

    # -- commands ----------------------------------------------------------------------------------------
    def command(self, trajectory: JointTrajectory) -> Tuple[bool, str]:
        """The ``command`` topic: a trajectory without a goal; replaces (and so cancels) an active goal."""
        with self.lock:
            ok, error = self._update_trajectory(trajectory, None)
            if ok:
                self._preempt()
            return ok, error

    def accept_goal(self, goal: TrajectoryGoal) -> Tuple[bool, int, str]:
        """goalCB: (accepted, error code, error string); an accepted goal preempts the active one."""
        with self.lock:
            if self.state != "running":
                _logger.error(f"{self.name}: Can't accept new action goals. Controller is not running.")
                return False, INVALID_GOAL, ""
            names = list(goal.trajectory.joint_names)
            if ((not self.allow_partial_joints_goal and len(names) != len(self.joint_names))
                    or not self._mapping(names)):
                # Upstream's words; upstream leaves the error_string empty, the log alone says why.
                error = (f"Joints on incoming goal don't match the controller joints: got [{', '.join(names)}], "
                         f"the controller has [{', '.join(self.joint_names)}]")
                _logger.error(f"{self.name}: {error}")
                return False, INVALID_JOINTS, error
            ok, error = self._update_trajectory(goal.trajectory, goal)
            if not ok:
                return False, INVALID_GOAL, error
            self._preempt()
            self.active_goal = goal
            self.successful = [False] * len(self.joints)
            return True, SUCCESSFUL, ""

    def cancel_goal(self, goal: TrajectoryGoal):
        """cancelCB: the active goal stops where the joints are."""
        with self.lock:
            if goal is self.active_goal:
                self.active_goal = None
                self._hold(self.uptime)
                self.ended.append(GoalEnd(goal, CANCELED))

    def _mapping(self, names: Sequence[str]) -> Optional[List[int]]:
        """internal::mapping: where each of ``names`` is among the controller's joints; None if one is not, or
        (unlike upstream, which moved the one joint as the last of them said) if one is named twice."""
        if (len(names) > len(self.joint_names) or any(name not in self.joint_names for name in names)
                or len(set(names)) < len(names)):
            return None
        return [self.joint_names.index(name) for name in names]

    def _update_trajectory(self, trajectory: JointTrajectory, goal: Optional[TrajectoryGoal]) -> Tuple[bool, str]:
        if self.state != "running":
            error = "Can't accept new commands. Controller is not running."
            _logger.error(f"{self.name}: {error}")
            return False, error
        next_update_time, next_update_uptime = self.time + self.period, self.uptime + self.period
        if not trajectory.points:
            self._hold(self.uptime, goal)
            return True, ""
        try:
            result = self._init_trajectory(trajectory, next_update_time, next_update_uptime, goal)
        except (TrajectoryError, ValueError) as error:
            _logger.error(f"{self.name}: {error}")
            return False, str(error)
        self.trajectory = result
        return True, ""

    def _init_trajectory(self, message: JointTrajectory, time: float, uptime: float,
                         goal: Optional[TrajectoryGoal]) -> List[List[Segment]]:
        """initJointTrajectory: the current trajectory up to the new one's first future point, a bridge segment
        to that point, then the new points' segments; joints the message leaves out keep their trajectory."""
        points = list(message.points)
        start = message.start if message.start != 0.0 else time
        names = list(message.joint_names)
        times = [message.start] + [point.time_from_start for point in points]
        # NaN or inf would reach the joints: refused, said once per joint and value.
        if not (all(math.isfinite(value) for value in times) and all(
                self.finite_command(names, values) for point in points
                for values in (point.positions, point.velocities, point.accelerations))):
            raise TrajectoryError("Trajectory message contains a value that is not a finite number.")
        for earlier, later in zip(points, points[1:]):
            if earlier.time_from_start >= later.time_from_start:
                raise TrajectoryError("Trajectory message contains waypoints that are not strictly increasing in time.")
        if not self.allow_partial_joints_goal and len(names) != len(self.joint_names):
            raise TrajectoryError("Cannot create trajectory from message. It does not contain the expected joints.")
        mapping = self._mapping(names)
        if not mapping:
            raise TrajectoryError("Cannot create trajectory from message. It does not contain the expected joints.")
        tolerances = copy.deepcopy(self.default_tolerances)
        if goal is not None:
            for i, joint in enumerate(self.joint_names):
                for tolerance in goal.path_tolerance:
                    if tolerance.name == joint:
                        tolerances[i].path.update(tolerance)
                for tolerance in goal.goal_tolerance:
                    if tolerance.name == joint:
                        tolerances[i].goal.update(tolerance)
            if goal.goal_time_tolerance > 0.0 or goal.goal_time_tolerance < 0.0:  # NaN keeps the default
                for joint_tolerances in tolerances:
                    joint_tolerances.goal_time = max(goal.goal_time_tolerance, 0.0)
        # The first point still to come (points at or before now are dropped; a first point at 0 silently).
        first = next((i for i, point in enumerate(points) if time < start + point.time_from_start), None)
        if first is None:
            raise TrajectoryError(f"Dropping all {len(points)} trajectory point(s), as they occur before the current "
                                  f"time.\nLast point is {time - (start + points[-1].time_from_start):f}s in the past.")
        if first > 0 and not (first == 1 and points[0].time_from_start == 0.0 and message.start == 0.0):
            _logger.warning(f"{self.name}: Dropping first {first} trajectory point(s) out of {len(points)}, as they "
                            f"occur before the current time.\nFirst valid point will be reached in "
                            f"{start + points[first].time_from_start - time:.3f}s.")
        start_uptime = uptime + (start - time)
        result = []
        for joint_index, segments in enumerate(self.trajectory):
            active = find_segment(segments, uptime)
            result.append([segment if active is None or index < active else segment.with_goal(goal)
                           for index, segment in enumerate(segments)])
        for point in points[first:]:
            if len(point.positions) != len(names) or not _point_valid(point, len(names)):
                raise TrajectoryError("Size mismatch in trajectory point position, velocity or acceleration data.")
        for message_index, joint_index in enumerate(mapping):
            current = self.trajectory[joint_index]
            bridge_start = max(start_uptime, uptime)
            _, bridge_state = sample(current, bridge_start)
            point = points[first]
            offset = wraparound_offset(bridge_state[0], point.positions[message_index], self.wraps[joint_index])
            first_active, bridge_active = find_segment(current, uptime), find_segment(current, bridge_start)
            if first_active is None or bridge_active is None:
                raise TrajectoryError("Unexpected error: Could not find segments in current trajectory. Please contact "
                                      "the package maintainer.")
            joint_tolerances = tolerances[joint_index] if goal is not None else None
            joint_trajectory = current[first_active:bridge_active + 1]
            joint_trajectory.append(Segment(bridge_start, bridge_state, start_uptime + point.time_from_start,
                                            _point_state(point, message_index, offset), 0.0, goal,
                                            joint_tolerances))
            for earlier, later in zip(points[first:], points[first + 1:]):
                joint_trajectory.append(Segment(start_uptime + earlier.time_from_start,
                                                _point_state(earlier, message_index, offset),
                                                start_uptime + later.time_from_start,
                                                _point_state(later, message_index, offset),
                                                earlier.time_from_start, goal, joint_tolerances))
            result[joint_index] = joint_trajectory
        return result

    # -- loop ----------------------------------------------------------------------------------------------
    def update(self, now, period):
        with self.lock:
            self.time, self.period, self.uptime = now, period, self.uptime + period
            active_segments = self._update_states()
            goal = self.active_goal
            for i, (segments, index) in enumerate(zip(self.trajectory, active_segments)):
                segment = segments[index]
                if goal is None or segment.goal is not goal:
                    continue
                error = (self.error[0][i], self.error[1][i], self.error[2][i])
                if self.uptime < segment.end_time:
                    if not segment.tolerances.path.holds(error):
                        self._abort(PATH_TOLERANCE_VIOLATED, f"{self.joint_names[i]} path error {error[0]:f}")
                        goal = None
                elif index == len(segments) - 1:
                    if segment.tolerances.goal.holds(error):
                        self.successful[i] = True
                    elif self.uptime >= segment.end_time + segment.tolerances.goal_time:
                        self._abort(GOAL_TOLERANCE_VIOLATED, f"{self.joint_names[i]} goal error {error[0]:f}")
                        goal = None
            if self.active_goal is not None and all(self.successful):
                self.ended.append(GoalEnd(self.active_goal, SUCCEEDED))
                self.active_goal = None
            self.adapter.command(period, self.desired, self.error)
            # As upstream's publishState: a period of 0 never publishes, a negative one at every update.
            if self.state_publish_period != 0.0 and self._last_state_publish + self.state_publish_period < self.uptime:
                self._last_state_publish += self.state_publish_period
                self.outbox.append((now, self._points(None)))
            if (self.active_goal is not None
                    and self.time - self._last_feedback >= self.action_monitor_period - 1e-9):
                self._last_feedback = self.time
                self.outbox.append((now, self._points(self.active_goal)))

    def _points(self, goal: Optional[TrajectoryGoal]) -> StatePoints:
        # _update_states makes new lists at every update, so these are not changed afterwards.
        return StatePoints(self.desired, self.actual, self.error, self.times_from_start, goal)

    def _abort(self, error_code: int, error_string: str):
        self.ended.append(GoalEnd(self.active_goal, ABORTED, error_code, error_string))
        self.active_goal = None
        self.successful = [False] * len(self.joints)

    def _update_states(self) -> List[int]:
        """updateStates: desired from the trajectory, actual from the joints, the error between them (Noetic takes
        the shortest angular distance for every joint, prismatic ones included). Returns each joint's active
        segment (the first one if the time came before all, which the trajectories' construction rules out)."""
        desired, actual, error = ([], [], []), ([], []), ([], [], [])
        active_segments = []
        for i, (joint, segments) in enumerate(zip(self.joints, self.trajectory)):
            index, (position, velocity, acceleration) = sample(segments, self.uptime)
            index = 0 if index is None else index
            active_segments.append(index)
            for values, value in zip(desired, (position, velocity, acceleration)):
                values.append(value)
            actual[0].append(joint.position)
            actual[1].append(joint.velocity)
            error[0].append(shortest_angular_distance(joint.position, position))
            error[1].append(velocity - joint.velocity)
            error[2].append(0.0)
            if i == 0:
                segment = segments[index]
                actual_from_start = self.uptime - segment.start_time + segment.time_from_start
                self.times_from_start = (segment.time_from_start, actual_from_start,
                                         segment.time_from_start - actual_from_start)
        self.desired, self.actual, self.error = desired, actual, error
        return active_segments

    def query_state(self, time: float) -> Optional[Tuple[List[float], List[float], List[float]]]:
        """query_state: the trajectory sampled at a sim time; None (with upstream's error) when it cannot be."""
        with self.lock:
            if self.state != "running":
                _logger.error(f"{self.name}: Can't sample trajectory. Controller is not running.")
                return None
            sample_time = self.uptime + (time - self.time)
            if not math.isfinite(sample_time):
                _logger.error(f"{self.name}: query_state: time {time} is not a finite number")
                return None
            states = []
            for segments in self.trajectory:
                index, state = sample(segments, sample_time)
                if index is None:
                    _logger.error(f"{self.name}: Requested sample time precedes trajectory start time.")
                    return None
                states.append(state)
            return [state[0] for state in states], [state[1] for state in states], [state[2] for state in states]

    def publish_due(self, now):
        return bool(self.ended)

    def steps_until_publish(self, now, step_size):
        # The state and the feedback go into the outbox at their step; a goal's end waits for the next stop, as
        # upstream's waits for its action monitor timer.
        return 1 if self.ended else sys.maxsize
