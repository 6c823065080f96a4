"""diff_drive_controller/DiffDriveController: wheels as names or lists, geometry from the parameters or the
URDF, multipliers, ``cmd_vel_timeout``, the speed limiter, odometry integrated from the wheel positions (exact arc /
Runge-Kutta 2 with a rolling mean of the speeds), ``open_loop``; the odometry (at ``publish_rate``) and
``cmd_vel_out`` (with ``publish_cmd``, every cycle) filled into the ``outbox``."""
import collections
import math
import operator
from typing import List, NamedTuple, Optional

from ..log import get_logger, warn_once
from ..description.robot_model import RobotModel
from .controller_manager import ControllerInitError
from .hardware_interface import VELOCITY
from .controller_interface import Controller, param

_logger = get_logger(__name__)
_position = operator.attrgetter("position")  # of a joint handle


class OdometrySample(NamedTuple):
    """nav_msgs/Odometry's (and the odom TF's) values at a publish time of the odometry."""
    x: float
    y: float
    heading: float
    linear: float
    angular: float


class CommandSample(NamedTuple):
    """cmd_vel_out's values: the command after the speed limiter."""
    linear: float
    angular: float


class SpeedLimiter:
    """diff_drive_controller::SpeedLimiter: jerk, then acceleration, then velocity."""

    def __init__(self, has_velocity_limits=False, has_acceleration_limits=False, has_jerk_limits=False,
                 min_velocity=0.0, max_velocity=0.0, min_acceleration=0.0, max_acceleration=0.0,
                 min_jerk=0.0, max_jerk=0.0):
        self.has_velocity_limits, self.has_acceleration_limits = has_velocity_limits, has_acceleration_limits
        self.has_jerk_limits = has_jerk_limits
        self.min_velocity, self.max_velocity = min_velocity, max_velocity
        self.min_acceleration, self.max_acceleration = min_acceleration, max_acceleration
        self.min_jerk, self.max_jerk = min_jerk, max_jerk

    @classmethod
    def from_params(cls, params: dict, prefix: str, where: str) -> "SpeedLimiter":
        """``linear/x/...`` or ``angular/z/...``; the minimums default to minus the maximums, as upstream."""
        def get(key, default, kind=float):
            return param(params, prefix + "/" + key, default, kind, where)
        limiter = cls(get("has_velocity_limits", False, bool), get("has_acceleration_limits", False, bool),
                      get("has_jerk_limits", False, bool))
        for quantity in ("velocity", "acceleration", "jerk"):
            maximum = get("max_" + quantity, 0.0)
            setattr(limiter, "max_" + quantity, maximum)
            setattr(limiter, "min_" + quantity, get("min_" + quantity, -maximum))
        return limiter

    def limit(self, v: float, v0: float, v1: float, dt: float) -> float:
        """The limited command, given the last two commands v0 (previous) and v1 (before that); clamps written
        out (min of max), as this runs twice on every control cycle."""
        if self.has_jerk_limits:
            dv, dv0, dt2 = v - v0, v0 - v1, 2.0 * dt * dt
            v = v0 + dv0 + min(max(dv - dv0, self.min_jerk * dt2), self.max_jerk * dt2)
        if self.has_acceleration_limits:
            v = v0 + min(max(v - v0, self.min_acceleration * dt), self.max_acceleration * dt)
        if self.has_velocity_limits:
            v = min(max(v, self.min_velocity), self.max_velocity)
        return v


class DiffDriveOdometry:
    """diff_drive_controller::Odometry: pose from wheel positions; speeds as a rolling mean over a window."""

    def __init__(self, window: int = 10):
        self.window = window
        self.x = self.y = self.heading = 0.0
        self.linear = self.angular = 0.0
        self.wheel_separation = self.left_radius = self.right_radius = 0.0
        self.left_old = self.right_old = 0.0
        self.timestamp = 0.0
        self.reset_accumulators()

    def reset_accumulators(self):
        self._speeds = collections.deque()  # (linear, angular) of the last ``window`` updates
        self._linear_sum = self._angular_sum = 0.0

    def init(self, now: float):
        self.reset_accumulators()
        self.timestamp = now

    def set_wheel_params(self, separation: float, left_radius: float, right_radius: float):
        self.wheel_separation, self.left_radius, self.right_radius = separation, left_radius, right_radius

    def update(self, left_position: float, right_position: float, now: float) -> bool:
        left, right = left_position * self.left_radius, right_position * self.right_radius
        left_delta, right_delta = left - self.left_old, right - self.right_old
        self.left_old, self.right_old = left, right
        linear = (right_delta + left_delta) * 0.5
        angular = (right_delta - left_delta) / self.wheel_separation
        self.integrate(linear, angular)
        dt = now - self.timestamp
        if dt < 0.0001:
            return False  # too short an interval to estimate speeds
        self.timestamp = now
        # boost's rolling_mean of each speed over the last ``window`` updates, kept as running sums
        linear, angular = linear / dt, angular / dt
        speeds = self._speeds
        speeds.append((linear, angular))
        self._linear_sum += linear
        self._angular_sum += angular
        if len(speeds) > self.window:
            old_linear, old_angular = speeds.popleft()
            self._linear_sum -= old_linear
            self._angular_sum -= old_angular
        count = len(speeds)
        self.linear, self.angular = self._linear_sum / count, self._angular_sum / count
        return True

    def update_open_loop(self, linear: float, angular: float, now: float):
        self.linear, self.angular = linear, angular
        dt = now - self.timestamp
        self.timestamp = now
        self.integrate(linear * dt, angular * dt)

    def integrate(self, linear: float, angular: float):
        """Exact arc integration, or second-order Runge-Kutta when the turn is negligible."""
        if abs(angular) < 1e-6:
            direction = self.heading + angular * 0.5
            self.x += linear * math.cos(direction)
            self.y += linear * math.sin(direction)
            self.heading += angular
        else:
            heading_old = self.heading
            radius = linear / angular
            self.heading += angular
            self.x += radius * (math.sin(self.heading) - math.sin(heading_old))
            self.y += -radius * (math.cos(self.heading) - math.cos(heading_old))


def _wheel_names(params: dict, key: str) -> List[str]:
    value = params.get(key)
    if value is None:
        raise ControllerInitError(f"Couldn't retrieve wheel param '{key}'.")
    if isinstance(value, str):
        return [value]
    if isinstance(value, list):
        if not value:
            raise ControllerInitError(f"Wheel param '{key}' is an empty list")
        for index, item in enumerate(value):
            if not isinstance(item, str):
                raise ControllerInitError(f"Wheel param '{key}' #{index} isn't a string.")
        return list(value)
    raise ControllerInitError(f"Wheel param '{key}' is neither a list of strings nor a string.")


def _covariance_diagonal(params: dict, key: str, name: str) -> List[float]:
    value = params.get(key)
    if value is None:
        return [0.0] * 6  # upstream reads an unset list as zeros
    if (not isinstance(value, list) or len(value) != 6
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)):
        raise ControllerInitError(f"{name}: '{key}' must be a list of 6 numbers, got {value!r}")
    return [float(v) for v in value]


class DiffDriveController(Controller):
    INTERFACE = VELOCITY

    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context)
        left, right = _wheel_names(params, "left_wheel"), _wheel_names(params, "right_wheel")
        if len(left) != len(right):
            raise ControllerInitError(f"#left wheels ({len(left)}) != #right wheels ({len(right)}).")
        self.left_names, self.right_names = left, right

        def get(key, default, kind=float):
            return param(params, key, default, kind, name)
        self.publish_rate = get("publish_rate", 50.0)
        if math.isnan(self.publish_rate) or self.publish_rate == 0:  # upstream's Duration(1 / rate) throws
            raise ControllerInitError(f"publish_rate {self.publish_rate} gives no publish period; it must be a "
                                      "number other than 0")
        self.open_loop = get("open_loop", False, bool)
        self.wheel_separation_multiplier = get("wheel_separation_multiplier", 1.0)
        if "wheel_radius_multiplier" in params:
            self.left_radius_multiplier = self.right_radius_multiplier = get("wheel_radius_multiplier", 1.0)
        else:
            self.left_radius_multiplier = get("left_wheel_radius_multiplier", 1.0)
            self.right_radius_multiplier = get("right_wheel_radius_multiplier", 1.0)
        self.odometry = DiffDriveOdometry(get("velocity_rolling_window_size", 10, int))
        self.cmd_vel_timeout = get("cmd_vel_timeout", 0.5)
        self.allow_multiple_publishers = get("allow_multiple_cmd_vel_publishers", True, bool)
        self.base_frame_id = get("base_frame_id", "base_link", str)
        self.odom_frame_id = get("odom_frame_id", "odom", str)
        self.enable_odom_tf = get("enable_odom_tf", True, bool)
        self.limiter_linear = SpeedLimiter.from_params(params, "linear/x", name)
        self.limiter_angular = SpeedLimiter.from_params(params, "angular/z", name)
        self.publish_cmd = get("publish_cmd", False, bool)
        if get("publish_wheel_joint_controller_state", False, bool):
            warn_once(_logger, f"{name}: publish_wheel_joint_controller_state is not supported; the wheels' "
                               "JointTrajectoryControllerState is not published")
        self.wheel_separation = get("wheel_separation", None)
        self.wheel_radius = get("wheel_radius", None)
        self._geometry_from_urdf(context.urdf, left[0], right[0])
        self.pose_covariance = _covariance_diagonal(params, "pose_covariance_diagonal", name)
        self.twist_covariance = _covariance_diagonal(params, "twist_covariance_diagonal", name)
        self._apply_wheel_params()
        separation, left_radius, right_radius = self.wheel_params()
        _logger.info(f"{name}: Odometry params : wheel separation {separation}, left wheel radius {left_radius}, "
                     f"right wheel radius {right_radius}")
        self.left = [self.handle(joint) for joint in left]
        self.right = [self.handle(joint) for joint in right]
        # linear, angular, stamp (sim s): one tuple, replaced whole by the ROS thread, read whole by the loop
        self._command = (0.0, 0.0, -math.inf)
        self.last0 = self.last1 = (0.0, 0.0)
        self.last_publish = 0.0

    def _geometry_from_urdf(self, urdf: Optional[RobotModel], left: str, right: str):
        if self.wheel_separation is not None and self.wheel_radius is not None:
            return
        if urdf is None:
            raise ControllerInitError("Robot description couldn't be retrieved from param server.")
        left_joint, right_joint = urdf.joints.get(left), urdf.joints.get(right)
        for joint, joint_name in ((left_joint, left), (right_joint, right)):
            if joint is None:
                raise ControllerInitError(f"{joint_name} couldn't be retrieved from model description")
        if self.wheel_separation is None:
            self.wheel_separation = math.dist(left_joint.origin.position, right_joint.origin.position)
        if self.wheel_radius is None:
            wheel = urdf.links[left_joint.child]
            if not wheel.collision_kinds:
                raise ControllerInitError(f"Link {left_joint.child} does not have collision description. Add collision "
                                          f"description for link to urdf.\nCouldn't retrieve {left} wheel radius")
            if wheel.collision_kinds[0] not in ("cylinder", "sphere") or wheel.collision_radii[0] is None:
                raise ControllerInitError(f"Wheel link {left_joint.child} is NOT modeled as a cylinder or "
                                          f"sphere!\nCouldn't retrieve {left} wheel radius")
            self.wheel_radius = wheel.collision_radii[0]

    def wheel_params(self):
        return (self.wheel_separation_multiplier * self.wheel_separation,
                self.left_radius_multiplier * self.wheel_radius, self.right_radius_multiplier * self.wheel_radius)

    def _apply_wheel_params(self):
        self.wheel_params_applied = self.wheel_params()
        self.odometry.set_wheel_params(*self.wheel_params_applied)

    def set_command(self, linear: float, angular: float, stamp: float, publishers: int = 1) -> Optional[str]:
        """cmdVelCallback: None when taken, else upstream's complaint (the ROS layer logs it, throttled)."""
        if self.state != "running":
            return "Can't accept new commands. Controller is not running."
        if not self.allow_multiple_publishers and publishers > 1:
            self.brake()
            return f"Detected {publishers} publishers. Only 1 publisher is allowed. Going to brake."
        if not (math.isfinite(linear) and math.isfinite(angular)):
            return "Received NaN in velocity command. Ignoring."
        self._command = (linear, angular, stamp)
        return None

    def brake(self):
        for joint in self.left + self.right:
            joint.command = 0.0

    def starting(self, now):
        self.brake()
        self.last_publish = now
        self.odometry.init(now)

    def stopping(self, now):
        self.brake()

    def restart_clock(self, now):
        self.last_publish = now
        self.odometry.timestamp = now
        self._command = (0.0, 0.0, -math.inf)

    def update(self, now, period):
        # Upstream re-applies the multipliers every cycle for dynamic_reconfigure, which is not served here:
        # they are applied once, at init.
        odometry = self.odometry
        if self.open_loop:
            odometry.update_open_loop(self.last0[0], self.last0[1], now)
        else:
            count = len(self.left)
            left = sum(map(_position, self.left)) / count
            right = sum(map(_position, self.right)) / count
            if math.isnan(left) or math.isnan(right):
                return
            odometry.update(left, right, now)
        if self.last_publish + 1.0 / self.publish_rate < now:
            self.last_publish += 1.0 / self.publish_rate
            self.outbox.append((now, OdometrySample(odometry.x, odometry.y, odometry.heading, odometry.linear,
                                                    odometry.angular)))
        linear, angular, stamp = self._command
        if now - stamp > self.cmd_vel_timeout:
            linear = angular = 0.0
        linear = self.limiter_linear.limit(linear, self.last0[0], self.last1[0], period)
        angular = self.limiter_angular.limit(angular, self.last0[1], self.last1[1], period)
        self.last1 = self.last0
        self.last0 = (linear, angular)
        if self.publish_cmd:  # cmd_vel_out: every control cycle, as upstream
            self.outbox.append((now, CommandSample(linear, angular)))
        separation, left_radius, right_radius = self.wheel_params_applied
        left_speed = (linear - angular * separation / 2.0) / left_radius
        right_speed = (linear + angular * separation / 2.0) / right_radius
        for joint in self.left:
            joint.command = left_speed
        for joint in self.right:
            joint.command = right_speed
