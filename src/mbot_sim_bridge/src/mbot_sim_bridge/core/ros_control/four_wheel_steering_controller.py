"""four_wheel_steering_controller/FourWheelSteeringController: four driven wheels (velocity) on four steering joints
(position), commanded by a Twist on ``cmd_vel`` (counter-phase steering: the rear wheels steer opposite to the
front) or by a four_wheel_steering_msgs/FourWheelSteering on ``cmd_four_wheel_steering`` (front and rear
steering angles of their own: equal ones crab, opposite ones turn in counter-phase), whichever came last. The
odometry is upstream's: the axles' speeds from the wheel velocities and steering angles, integrated in x, y and
heading, with the speed's acceleration and jerk and the steering velocities as rolling means. The geometry (track,
wheel base, wheel radius, the steering axis' offset from the wheel) comes from the parameters or, as
urdf_geometry_parser finds it, from the joints' positions in the base frame."""
import collections
import math
from typing import List, NamedTuple, Optional, Tuple

from ..description.robot_model import RobotModel
from ..log import get_logger, warn_once
from .controller_interface import param
from .controller_manager import ControllerInitError
from .diff_drive_controller import OdometryController, _wheel_names
from .hardware_interface import POSITION

_logger = get_logger(__name__)


class FourWheelOdometrySample(NamedTuple):
    """nav_msgs/Odometry's and odom_steer's (four_wheel_steering_msgs/FourWheelSteeringStamped) values."""
    x: float
    y: float
    heading: float
    linear_x: float
    linear_y: float
    angular: float
    speed: float
    acceleration: float
    jerk: float
    front_steering: float
    front_steering_velocity: float
    rear_steering: float
    rear_steering_velocity: float


class _RollingMean:
    """boost's rolling_mean over the last ``window`` values."""

    def __init__(self, window: int):
        self.values = collections.deque(maxlen=max(window, 1))

    def add(self, value: float) -> float:
        self.values.append(value)
        return self.mean

    @property
    def mean(self) -> float:
        return sum(self.values) / len(self.values) if self.values else 0.0


class FourWheelSteeringOdometry:
    """four_wheel_steering_controller::Odometry."""

    def __init__(self, window: int = 10):
        self.window = window
        self.x = self.y = self.heading = 0.0
        self.linear = self.linear_x = self.linear_y = self.angular = 0.0
        self.steering_track = self.wheel_steering_y_offset = self.wheel_radius = self.wheel_base = 0.0
        self.timestamp = 0.0
        self.reset_accumulators()

    def reset_accumulators(self):
        self.acceleration, self.jerk = _RollingMean(self.window), _RollingMean(self.window)
        self.front_steering_velocity = _RollingMean(self.window)
        self.rear_steering_velocity = _RollingMean(self.window)
        self.linear_previous = self.acceleration_previous = 0.0
        self.front_steering_previous = self.rear_steering_previous = 0.0

    def init(self, now: float):
        self.reset_accumulators()
        self.timestamp = now

    def set_wheel_params(self, steering_track, wheel_steering_y_offset, wheel_radius, wheel_base):
        self.steering_track, self.wheel_steering_y_offset = steering_track, wheel_steering_y_offset
        self.wheel_radius, self.wheel_base = wheel_radius, wheel_base

    def _axle_speed(self, left: float, right: float, steering: float, turn: float, squared) -> float:
        """An axle's linear speed from its wheels' speeds (rad/s); ``turn`` is upstream's front_tmp/rear_tmp."""
        track, offset = self.steering_track, self.wheel_steering_y_offset
        left_turn = turn / math.sqrt(1 - track * turn * math.cos(steering) + (track * turn / 2) ** 2)
        right_turn = turn / math.sqrt(1 + track * turn * math.cos(steering) + (track * turn / 2) ** 2)
        left_corrected = left / (1 - offset * left_turn)
        right_corrected = right / (1 - offset * right_turn)
        left_squared, right_squared = squared(left, left_corrected), squared(right, right_corrected)
        return (self.wheel_radius * math.copysign(1.0, left_corrected + right_corrected)
                * math.sqrt((left_squared + right_squared) / (2 + (track * turn) ** 2 / 2.0)))

    def update(self, front_left, front_right, rear_left, rear_right, front_steering, rear_steering,
               now: float) -> bool:
        tan_difference = math.tan(front_steering) - math.tan(rear_steering)
        front_turn = math.cos(front_steering) * tan_difference / self.wheel_base
        rear_turn = math.cos(rear_steering) * tan_difference / self.wheel_base
        # Upstream squares the raw front speeds but the offset-corrected rear ones; kept as it computes them.
        front_speed = self._axle_speed(front_left, front_right, front_steering, front_turn,
                                       lambda raw, corrected: raw * raw)
        rear_speed = self._axle_speed(rear_left, rear_right, rear_steering, rear_turn,
                                      lambda raw, corrected: corrected * corrected)
        self.angular = (front_speed * front_turn + rear_speed * rear_turn) / 2.0
        self.linear_x = (front_speed * math.cos(front_steering) + rear_speed * math.cos(rear_steering)) / 2.0
        self.linear_y = (front_speed * math.sin(front_steering) - self.wheel_base * self.angular / 2.0
                         + rear_speed * math.sin(rear_steering) + self.wheel_base * self.angular / 2.0) / 2.0
        self.linear = math.copysign(1.0, rear_speed) * math.hypot(self.linear_x, self.linear_y)
        dt = now - self.timestamp
        if dt < 0.0001:
            return False  # too short an interval to integrate with
        self.timestamp = now
        self.integrate_xy(self.linear_x * dt, self.linear_y * dt, self.angular * dt)
        self.acceleration.add((self.linear_previous - self.linear) / dt)
        self.linear_previous = self.linear
        self.jerk.add((self.acceleration_previous - self.acceleration.mean) / dt)
        self.acceleration_previous = self.acceleration.mean
        # upstream's signs: previous minus current, and the steering angle itself as the "previous" value
        self.front_steering_velocity.add((self.front_steering_previous - front_steering) / dt)
        self.front_steering_previous = front_steering
        self.rear_steering_velocity.add((self.rear_steering_previous - rear_steering) / dt)
        self.rear_steering_previous = rear_steering
        return True

    def integrate_xy(self, linear_x: float, linear_y: float, angular: float):
        cos, sin = math.cos(self.heading), math.sin(self.heading)
        self.x += linear_x * cos - linear_y * sin
        self.y += linear_x * sin + linear_y * cos
        self.heading += angular


def wheel_commands(linear_x: float, angular: float, track: float, offset: float, wheel_base: float,
                   radius: float) -> Tuple[List[float], List[float]]:
    """A Twist's wheel speeds (front left, front right, rear left, rear right; rad/s) and steering angles in the
    same order, the rear steering opposite to the front, as upstream computes them."""
    steering_track = track - 2 * offset
    speeds = [0.0] * 4
    if abs(linear_x) > 0.001:
        steering_offset = angular * offset / radius
        sign = math.copysign(1.0, linear_x)
        left = sign * math.hypot(linear_x - angular * steering_track / 2, wheel_base * angular / 2.0) / radius
        right = sign * math.hypot(linear_x + angular * steering_track / 2, wheel_base * angular / 2.0) / radius
        speeds = [left - steering_offset, right + steering_offset, left - steering_offset, right + steering_offset]
    front_left = front_right = 0.0
    if abs(2.0 * linear_x) > abs(angular * steering_track):
        front_left = math.atan(angular * wheel_base / (2.0 * linear_x - angular * steering_track))
        front_right = math.atan(angular * wheel_base / (2.0 * linear_x + angular * steering_track))
    elif abs(linear_x) > 0.001:
        front_left = front_right = math.copysign(math.pi / 2, angular)
    return speeds, [front_left, front_right, -front_left, -front_right]


def steering_commands(speed: float, front: float, rear: float, track: float, offset: float, wheel_base: float,
                      radius: float) -> Tuple[List[float], List[float]]:
    """A FourWheelSteering command's wheel speeds and steering angles (same order as ``wheel_commands``)."""
    steering_track = track - 2 * offset
    front, rear = min(max(front, -math.pi / 2), math.pi / 2), min(max(rear, -math.pi / 2), math.pi / 2)
    tan_front, tan_rear = math.tan(front), math.tan(rear)
    steering_difference = steering_track * (tan_front - tan_rear) / 2.0
    angles = [0.0] * 4
    if abs(wheel_base - abs(steering_difference)) > 0.001:
        angles = [math.atan(wheel_base * tan_front / (wheel_base - steering_difference)),
                  math.atan(wheel_base * tan_front / (wheel_base + steering_difference)),
                  math.atan(wheel_base * tan_rear / (wheel_base - steering_difference)),
                  math.atan(wheel_base * tan_rear / (wheel_base + steering_difference))]
    speeds = [0.0] * 4
    if abs(speed) > 0.001:
        def virtual_base(left, right):
            """The distance from the axle to the projection of the turn's centre on the wheel base."""
            tan_left, tan_right = math.tan(left), math.tan(right)
            if abs(tan_left - tan_right) > 0.01:
                return tan_right * tan_left * steering_track / (tan_left - tan_right)
            return 0.0
        front_base, rear_base = virtual_base(angles[0], angles[1]), virtual_base(angles[2], angles[3])
        angular = speed * (tan_front - tan_rear) / wheel_base
        steering_offset = angular * offset / radius
        sign = math.copysign(1.0, speed)

        def wheel(side, base):
            return sign * math.hypot(speed + side * angular * steering_track / 2, base * angular) / radius
        speeds = [wheel(-1, front_base) - steering_offset, wheel(1, front_base) + steering_offset,
                  wheel(-1, rear_base) - steering_offset, wheel(1, rear_base) + steering_offset]
    return speeds, angles


def _planar_distance(urdf: RobotModel, base: str, first: str, second: str) -> float:
    """urdf_geometry_parser's getDistanceBetweenJoints: the x-y distance of two joints, each placed by summing its
    chain's joint origins up to ``base``."""
    def position(joint_name):
        joint = urdf.joints.get(joint_name)
        if joint is None:
            raise ControllerInitError(f"{joint_name} couldn't be retrieved from model description")
        total = [0.0, 0.0, 0.0]
        while True:
            total = [a + b for a, b in zip(total, joint.origin.position)]
            if joint.parent == base:
                return total
            joint = next((j for j in urdf.joints.values() if j.child == joint.parent), None)
            if joint is None:
                raise ControllerInitError(f"Couldn't find the chain from {joint_name} to {base}")
    a, b = position(first), position(second)
    return math.hypot(a[0] - b[0], a[1] - b[1])


def _joint_radius(urdf: RobotModel, joint_name: str) -> float:
    joint = urdf.joints.get(joint_name)
    if joint is None:
        raise ControllerInitError(f"{joint_name} couldn't be retrieved from model description")
    link = urdf.links[joint.child]
    if not link.collision_kinds or link.collision_kinds[0] not in ("cylinder", "sphere"):
        raise ControllerInitError(f"Wheel link {joint.child} is NOT modeled as a cylinder or sphere!")
    return link.collision_radii[0]


class FourWheelSteeringController(OdometryController):
    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context, FourWheelSteeringOdometry())
        front_wheels, rear_wheels = _wheel_names(params, "front_wheel"), _wheel_names(params, "rear_wheel")
        if len(front_wheels) != len(rear_wheels):
            raise ControllerInitError(f"#front wheels ({len(front_wheels)}) != #rear wheels ({len(rear_wheels)}).")
        if len(front_wheels) != 2:
            raise ControllerInitError(f"#two wheels by axle (left and right) is needed; now : {len(front_wheels)} .")
        front_steering = _wheel_names(params, "front_steering")
        rear_steering = _wheel_names(params, "rear_steering")
        if len(front_steering) != len(rear_steering):
            raise ControllerInitError(f"#left steerings ({len(front_steering)}) != #right steerings "
                                      f"({len(rear_steering)}).")
        if len(front_steering) != 2:
            raise ControllerInitError("#two steering by axle (left and right) is needed; now : "
                                      f"{len(front_steering)} .")

        def get(key, default, kind=float):
            return param(params, key, default, kind, name)
        if get("open_loop", False, bool):
            warn_once(_logger, f"{name}: open_loop is read but not used by four_wheel_steering_controller; the "
                               "odometry comes from the joints")
        self.odom_frame_id = "odom"  # fixed in upstream
        self.limiter_linear.has_jerk_limits = self.limiter_angular.has_jerk_limits = False  # upstream reads none
        self.track, self.wheel_radius, self.wheel_base = get("track", None), get("wheel_radius", None), \
            get("wheel_base", None)
        self._geometry_from_urdf(context.urdf, front_wheels, rear_wheels, front_steering)
        self.odometry.set_wheel_params(self.track - 2 * self.wheel_steering_y_offset, self.wheel_steering_y_offset,
                                       self.wheel_radius, self.wheel_base)
        _logger.info(f"{name}: Odometry params : track {self.track}, wheel radius {self.wheel_radius}, wheel base "
                     f"{self.wheel_base}, wheel steering offset {self.wheel_steering_y_offset}")
        # front left, front right, rear left, rear right
        self.wheels = [self.handle(joint) for joint in front_wheels + rear_wheels]
        self.steerings = [self.handle(joint, POSITION) for joint in front_steering + rear_steering]
        # (linear x, linear y, angular, stamp) and (speed, front steering, rear steering, stamp): each one tuple,
        # replaced whole by the ROS thread; the later stamp wins, as upstream.
        self._twist = (0.0, 0.0, 0.0, 0.0)
        self._steering = (0.0, 0.0, 0.0, 0.0)

    def _geometry_from_urdf(self, urdf: Optional[RobotModel], front_wheels, rear_wheels, front_steering):
        if urdf is None:
            raise ControllerInitError("Robot description couldn't be retrieved from param server.")
        base = self.base_frame_id
        if self.track is None:
            self.track = _planar_distance(urdf, base, front_wheels[0], front_wheels[1])
        self.wheel_steering_y_offset = _planar_distance(urdf, base, front_steering[0], front_wheels[0])
        if self.wheel_radius is None:
            self.wheel_radius = _joint_radius(urdf, front_wheels[0])
        if self.wheel_base is None:
            self.wheel_base = _planar_distance(urdf, base, front_wheels[0], rear_wheels[0])
        if not (self.wheel_radius > 0 and self.wheel_base > 0 and self.track > 2 * self.wheel_steering_y_offset):
            # upstream would divide by zero in the odometry and the wheel commands
            raise ControllerInitError(f"wheel_radius {self.wheel_radius} and wheel_base {self.wheel_base} must be "
                                      f"positive and track {self.track} more than twice the steering offset "
                                      f"{self.wheel_steering_y_offset}")

    def set_twist(self, linear_x: float, linear_y: float, angular: float, stamp: float) -> Optional[str]:
        """cmdVelCallback: None when taken, else upstream's complaint."""
        if self.state != "running":
            return "Can't accept new commands. Controller is not running."
        if not all(map(math.isfinite, (linear_x, linear_y, angular))):
            return "Received NaN in geometry_msgs::Twist. Ignoring command."
        self._twist = (linear_x, linear_y, angular, stamp)
        return None

    def set_steering(self, speed: float, front: float, rear: float, stamp: float) -> Optional[str]:
        """cmdFourWheelSteeringCallback: None when taken, else upstream's complaint."""
        if self.state != "running":
            return "Can't accept new commands. Controller is not running."
        if not all(map(math.isfinite, (speed, front, rear))):
            return "Received NaN in four_wheel_steering_msgs::FourWheelSteering. Ignoring command."
        self._steering = (speed, front, rear, stamp)
        return None

    def set_command(self, linear: float, angular: float, stamp: float) -> Optional[str]:
        """A Twist of linear.x and angular.z, as the other cmd_vel controllers take it."""
        return self.set_twist(linear, 0.0, angular, stamp)

    def brake(self):
        for joint in self.wheels + self.steerings:
            joint.command = 0.0

    def forget_commands(self):
        self._twist = self._steering = (0.0, 0.0, 0.0, -math.inf)

    @staticmethod
    def _axle_steering(left: float, right: float) -> float:
        """The virtual middle wheel's angle of an axle's two steering angles."""
        if abs(left) > 0.001 or abs(right) > 0.001:
            return math.atan(2 * math.tan(left) * math.tan(right) / (math.tan(left) + math.tan(right)))
        return 0.0

    def update(self, now, period):
        self._update_odometry(now)
        self._update_command(now, period)

    def _update_odometry(self, now):
        speeds = [joint.velocity for joint in self.wheels]
        angles = [joint.position for joint in self.steerings]
        if any(math.isnan(value) for value in speeds + angles):
            return
        front = self._axle_steering(angles[0], angles[1])
        rear = self._axle_steering(angles[2], angles[3])
        odometry = self.odometry
        odometry.update(*speeds, front, rear, now)
        if self.odometry_due(now):
            self.outbox.append((now, FourWheelOdometrySample(
                odometry.x, odometry.y, odometry.heading, odometry.linear_x, odometry.linear_y, odometry.angular,
                odometry.linear, odometry.acceleration.mean, odometry.jerk.mean, front,
                odometry.front_steering_velocity.mean, rear, odometry.rear_steering_velocity.mean)))

    def _update_command(self, now, period):
        linear_x, _, angular, twist_stamp = self._twist
        speed, front, rear, steering_stamp = self._steering
        steering_mode = steering_stamp >= twist_stamp
        if now - (steering_stamp if steering_mode else twist_stamp) > self.cmd_vel_timeout:
            linear_x = angular = speed = front = rear = 0.0
        geometry = (self.track, self.wheel_steering_y_offset, self.wheel_base, self.wheel_radius)
        if steering_mode:
            speed = self.limiter_linear.limit(speed, self.last0[0], self.last1[0], period)
            self.last1, self.last0 = self.last0, (speed, self.last0[1])
            speeds, angles = steering_commands(speed, front, rear, *geometry)
        else:
            linear_x = self.limiter_linear.limit(linear_x, self.last0[0], self.last1[0], period)
            angular = self.limiter_angular.limit(angular, self.last0[1], self.last1[1], period)
            self.last1, self.last0 = self.last0, (linear_x, angular)
            speeds, angles = wheel_commands(linear_x, angular, *geometry)
        for joint, value in zip(self.wheels, speeds):
            joint.command = value
        for joint, value in zip(self.steerings, angles):
            joint.command = value
