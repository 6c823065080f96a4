"""robot_localization's RosFilter without ROS: sensor data mapped onto the 15-member state as upstream maps it
(ros_filter.cpp: odometry, IMU, pose and twist callbacks, preparePose/Twist/Acceleration, differential and
relative modes, two_d_mode), the measurement queue in time order and the periodic update. The node hands in
messages as the plain records below and a ``lookup(target, source, stamp)`` that returns a ``Transform`` or None.
"""
import collections
import heapq
import itertools
from dataclasses import dataclass

import numpy as np

from .ekf import (AX, AZ, MEASUREMENT_LIMIT, PITCH, ROLL, STATE_SIZE, VPITCH, VROLL, VX, VYAW, VZ, YAW, Z,
                  Ekf, Measurement, normalize_angle)
from .geometry import Transform, block_rotation, cross, matrix_rpy, quaternion_matrix, rpy_matrix, update_mask

# The members two_d_mode pins to zero, and the variance it gives them.
TWO_D_MEMBERS = [Z, ROLL, PITCH, VZ, VROLL, VPITCH, AZ]
TWO_D_VARIANCE = 1e-6
SET_POSE_VARIANCE = 1e-6
# How far (s) a message's stamp may be ahead of the node's clock. Upstream has no bound: data from the future
# waits in its queue, and while the queue holds any it does not predict, so a stamp 100 s ahead silences the
# output for 100 s, and the input's older data is refused meanwhile. Beyond this the message is refused, said
# once per input; within it (a sender's clock a little ahead, /clock arriving after the data) it waits.
FUTURE_LIMIT = 1.0


@dataclass
class PoseInput:
    stamp: float
    frame: str
    position: np.ndarray
    orientation: np.ndarray  # x y z w
    covariance: np.ndarray  # 6x6


@dataclass
class TwistInput:
    stamp: float
    frame: str
    linear: np.ndarray
    angular: np.ndarray
    covariance: np.ndarray  # 6x6


@dataclass
class ImuInput:
    stamp: float
    frame: str
    orientation: np.ndarray
    orientation_covariance: np.ndarray  # 3x3
    angular_velocity: np.ndarray
    angular_velocity_covariance: np.ndarray
    linear_acceleration: np.ndarray
    linear_acceleration_covariance: np.ndarray


@dataclass
class Source:
    """One stream into the filter (upstream's CallbackData): odom0_pose, imu0_twist, ... and its settings."""
    name: str
    update: np.ndarray  # 15 booleans
    differential: bool = False
    relative: bool = False
    threshold: float = float("inf")
    remove_gravity: bool = False


@dataclass
class Frames:
    map: str = "map"
    odom: str = "odom"
    base_link: str = "base_link"
    world: str = "odom"
    base_link_output: str = "base_link"


def ignored(covariance):
    """The sensor_msgs/Imu convention: -1 as the first element marks a quantity the IMU does not provide."""
    return abs(covariance[0, 0] + 1.0) < 1e-9


def six_by_six(block, offset):
    """A 6x6 covariance holding a 3x3 ``block`` at rows/columns ``offset``..``offset + 2``."""
    covariance = np.zeros((6, 6))
    covariance[offset:offset + 3, offset:offset + 3] = block
    return covariance


class Estimator:
    def __init__(self, lookup, warn, frames=None, two_d_mode=False, gravity=9.80665, predict_to_current_time=False,
                 topics=None):
        self.lookup, self.warn = lookup, warn
        self.topics = topics or {}  # input name (odom0, ...) -> its topic, for the warnings
        self.frames = frames or Frames()
        self.two_d_mode, self.gravity = two_d_mode, gravity
        self.predict_to_current_time = predict_to_current_time
        self.filter = Ekf()
        self.queue, self.sequence = [], itertools.count()
        self.last_message_times, self.previous_measurements, self.initial_measurements = {}, {}, {}
        self.last_set_pose_time = 0.0
        self.angular_acceleration = np.zeros(3)
        self.angular_acceleration_covariance = np.zeros((3, 3))
        self.last_angular_velocity, self.last_differentiation_time = np.zeros(3), 0.0
        # smooth_lagged_data: filter states and measurements of the last history_length seconds, oldest first.
        self.history_length = None
        self.state_history, self.measurement_history = collections.deque(), collections.deque()

    # Inputs, as upstream's callbacks; ``now`` is the node's clock when the message came (None: not checked).
    def odometry(self, pose, twist, pose_source, twist_source, now=None):
        """nav_msgs/Odometry: its pose in the world frame, its twist (``twist.frame`` is the child frame)."""
        if not self.timely(pose_source.name.rsplit("_", 1)[0], pose.stamp, now):
            return
        if pose_source.update.any():
            self.ordered(pose_source, pose, self.prepare_pose_source, target=self.frames.world, imu=False)
        if twist_source.update.any():
            self.ordered(twist_source, twist, self.prepare_twist_source, target=self.frames.base_link)

    def imu(self, message, pose_source, twist_source, acceleration_source, now=None):
        if not self.timely(pose_source.name.rsplit("_", 1)[0], message.stamp, now):
            return
        base_link = self.frames.base_link
        if pose_source.update.any() and not ignored(message.orientation_covariance):
            pose = PoseInput(message.stamp, message.frame, np.zeros(3), message.orientation,
                             six_by_six(message.orientation_covariance, 3))
            self.ordered(pose_source, pose, self.prepare_pose_source, target=base_link, imu=True)
        if twist_source.update.any() and not ignored(message.angular_velocity_covariance):
            twist = TwistInput(message.stamp, message.frame, np.zeros(3), message.angular_velocity,
                               six_by_six(message.angular_velocity_covariance, 3))
            self.ordered(twist_source, twist, self.prepare_twist_source, target=base_link)
        if acceleration_source.update.any() and not ignored(message.linear_acceleration_covariance):
            self.ordered(acceleration_source, message, self.prepare_acceleration, target=base_link)

    def pose(self, message, source, now=None):
        if self.timely(source.name, message.stamp, now):
            self.ordered(source, message, self.prepare_pose_source, target=self.frames.world, imu=False)

    def twist(self, message, source, now=None):
        if self.timely(source.name, message.stamp, now):
            self.ordered(source, message, self.prepare_twist_source, target=self.frames.base_link)

    def timely(self, name, stamp, now=None):
        """False, said once per input, for a message stamped at or before the last set_pose, or more than
        FUTURE_LIMIT ahead of ``now``."""
        if stamp <= self.last_set_pose_time:
            self.warn(f"{name}_timestamp", f"The {name} message has a timestamp equal to or before the last filter "
                      f"reset, this message will be ignored (message time: {stamp:.3f})")
            return False
        if now is not None and stamp - now > FUTURE_LIMIT:
            label = f"{name} ({self.topics[name]})" if name in self.topics else name
            self.warn(f"{name}_future", f"The {label} message is stamped {stamp - now:.3f} s ahead of the current "
                      f"time ({now:.3f}); messages more than {FUTURE_LIMIT:g} s ahead are ignored (message time: "
                      f"{stamp:.3f}, said once per input)")
            return False
        return True

    def ordered(self, source, message, prepare, **options):
        """Upstream's per-stream checks: nothing from before the last set_pose, nothing older than the stream's
        last message; then the prepared measurement goes into the queue."""
        if not self.timely(source.name, message.stamp):
            return
        previous_stamp = self.last_message_times.setdefault(source.name, message.stamp)
        if message.stamp < previous_stamp:
            self.warn(f"{source.name}_timestamp", f"The {source.name} message has a timestamp before that of the "
                      f"previous message received, this message will be ignored (message time: "
                      f"{message.stamp:.3f})")
            return
        with np.errstate(all="ignore"):  # NaN and inf are found and reported when the filter takes the data
            prepared = prepare(message, source, previous_stamp=previous_stamp, **options)
        if prepared is not None:
            values, covariance, update = prepared
            heapq.heappush(self.queue, (message.stamp, next(self.sequence), Measurement(
                source.name, message.stamp, values, covariance, update, source.threshold)))
        self.last_message_times[source.name] = message.stamp

    # Measurement preparation (preparePose, prepareTwist, prepareAcceleration).
    def prepare_pose_source(self, message, source, previous_stamp, target, imu):
        return self.prepare_pose(message, source.name, target, source.differential, source.relative, imu,
                                 source.update.copy(), previous_stamp)

    def prepare_pose(self, message, name, target, differential, relative, imu, update, previous_stamp=None):
        pose_frame = target if differential and not imu else message.frame
        if not np.any(message.orientation):
            orientation = np.eye(3)
            if update[ROLL:YAW + 1].any():
                self.warn(f"{name}_orientation", f"The {name} message contains an invalid orientation quaternion "
                          "(all zeros), taken as the identity")
        else:
            orientation = self.attitude(message.orientation, name)
        pose = Transform(orientation, np.asarray(message.position, dtype=float))
        target_transform = self.lookup(target, pose_frame or target, message.stamp)
        if target_transform is None:
            return None
        # An IMU's frame is where it is mounted, not the frame its orientation is reported in: only the mounting
        # yaw turns the mask and covariance, and the mounting offsets come off the measured angles.
        yaw_offset = matrix_rpy(target_transform.rotation)[2]
        rotation = rpy_matrix(0.0, 0.0, yaw_offset) if imu else target_transform.rotation
        update[:3] = update_mask(rotation, update[:3])
        update[ROLL:YAW + 1] = update_mask(rotation, update[ROLL:YAW + 1])
        covariance = np.asarray(message.covariance, dtype=float)
        rotation6 = block_rotation(rotation)
        covariance_rotated = rotation6 @ covariance @ rotation6.T
        if imu:
            offsets = np.array(matrix_rpy(target_transform.rotation))
            angles = normalize_angle(np.array(matrix_rpy(pose.rotation)) - offsets)
            pose.rotation = rpy_matrix(*(rpy_matrix(0.0, 0.0, offsets[2]) @ angles))
            target_transform = Transform()
        values, full_covariance = np.zeros(STATE_SIZE), np.zeros((STATE_SIZE, STATE_SIZE))
        if differential:
            previous = self.previous_measurements.get(name)
            self.previous_measurements[name] = (pose, covariance)
            if previous is None:
                return None
            previous_pose, previous_covariance = previous
            delta = Transform(target_transform.rotation) * previous_pose.inverse_times(pose)
            dt = message.stamp - previous_stamp
            with np.errstate(all="ignore"):
                linear = delta.translation / dt
                angular = np.array(matrix_rpy(delta.rotation)) / dt
                twist_covariance = (covariance_rotated + rotation6 @ previous_covariance @ rotation6.T) * dt
            twist_update = np.zeros(STATE_SIZE, dtype=bool)
            twist_update[VX:VYAW + 1] = update[:6]
            twist = TwistInput(message.stamp, self.frames.base_link, linear, angular, twist_covariance)
            return self.prepare_twist(twist, self.frames.base_link, twist_update)
        if relative:
            initial = self.initial_measurements.setdefault(name, pose)
            pose = initial.inverse_times(pose)
        pose = target_transform * pose
        values[:3] = pose.translation
        values[ROLL:YAW + 1] = matrix_rpy(pose.rotation)
        full_covariance[:6, :6] = covariance_rotated
        return self.force_two_d(values, full_covariance, update)

    def prepare_twist_source(self, message, source, previous_stamp, target):
        return self.prepare_twist(message, target, source.update.copy())

    def prepare_twist(self, message, target, update):
        transform = self.lookup(target, message.frame or target, message.stamp)
        if transform is None:
            return None
        rotation, offset = transform.rotation, transform.translation
        state_angular = self.filter.state[VROLL:VYAW + 1]
        values, covariance = np.zeros(STATE_SIZE), np.zeros((STATE_SIZE, STATE_SIZE))
        values[VROLL:VYAW + 1] = rotation @ message.angular
        # A sensor away from the origin sees the body's turning as linear velocity.
        values[VX:VZ + 1] = rotation @ message.linear + cross(offset, state_angular)
        update[VX:VZ + 1] = update_mask(rotation, update[VX:VZ + 1])
        update[VROLL:VYAW + 1] = update_mask(rotation, update[VROLL:VYAW + 1])
        rotation6 = block_rotation(rotation)
        covariance[VX:VYAW + 1, VX:VYAW + 1] = rotation6 @ np.asarray(message.covariance, dtype=float) @ rotation6.T
        return self.force_two_d(values, covariance, update)

    def prepare_acceleration(self, message, source, previous_stamp, target):
        transform = self.lookup(target, message.frame or self.frames.base_link, message.stamp)
        if transform is None:
            return None
        rotation, offset = transform.rotation, transform.translation
        acceleration = np.asarray(message.linear_acceleration, dtype=float)
        if source.remove_gravity:
            gravity = np.array([0.0, 0.0, self.gravity])
            if ignored(message.orientation_covariance):
                attitude = rpy_matrix(*self.filter.state[ROLL:YAW + 1]) @ rotation
                acceleration = acceleration - attitude.T @ gravity
            else:
                attitude = self.attitude(message.orientation, source.name)
                in_sensor = attitude.T @ gravity
                acceleration = acceleration - (rotation.T @ in_sensor if source.relative else in_sensor)
        state_angular = self.filter.state[VROLL:VYAW + 1]
        update = source.update.copy()
        values, covariance = np.zeros(STATE_SIZE), np.zeros((STATE_SIZE, STATE_SIZE))
        values[AX:AZ + 1] = (rotation @ acceleration + cross(offset, self.angular_acceleration)
                             - cross(cross(offset, state_angular), state_angular))
        update[AX:AZ + 1] = update_mask(rotation, update[AX:AZ + 1])
        covariance[AX:AZ + 1, AX:AZ + 1] = rotation @ message.linear_acceleration_covariance @ rotation.T
        return self.force_two_d(values, covariance, update)

    def attitude(self, quaternion, name):
        with np.errstate(all="ignore"):
            norm = np.linalg.norm(quaternion)
        if abs(norm - 1.0) > 0.01:
            self.warn(f"{name}_normalization", f"{name}: an orientation was not normalized, this should NOT "
                      "happen, but will normalize.")
        return quaternion_matrix(quaternion)

    def force_two_d(self, values, covariance, update):
        if self.two_d_mode:
            values[TWO_D_MEMBERS] = 0.0
            covariance[TWO_D_MEMBERS, TWO_D_MEMBERS] = TWO_D_VARIANCE
            update[TWO_D_MEMBERS] = True
        return values, covariance, update

    # The periodic update.
    def integrate(self, now):
        """RosFilter::integrateMeasurements: every queued measurement up to ``now`` in time order; with none
        fused for sensor_timeout (or with predict_to_current_time) a prediction up to ``now``. Upstream predicts
        only when the queue is empty, so data waiting for a later time stops the output; here it predicts as
        without data. With smooth_lagged_data (``history_length`` set), a measurement older than the estimate
        first takes the filter back to the state before it, and the measurements since are fused again."""
        predict = self.predict_to_current_time
        smoothing = self.history_length is not None
        fused = False
        if self.queue:
            if smoothing and self.queue[0][0] < self.filter.last_measurement_time:
                self.revert_to(self.queue[0][0] - 1e-9)
            while self.queue and self.queue[0][0] <= now:
                measurement = heapq.heappop(self.queue)[2]
                self.filter.process_measurement(measurement)
                fused = True
                if smoothing:
                    self.measurement_history.append(measurement)
                    # One saved state per distinct time.
                    if not self.queue or abs(self.queue[0][0] - self.filter.last_measurement_time) > 1e-9:
                        self.state_history.append((self.filter.last_measurement_time, self.filter.state.copy(),
                                                   self.filter.covariance.copy()))
        if (not fused and self.filter.initialized
                and now - self.filter.last_measurement_time >= self.filter.sensor_timeout):
            predict = True
        if self.filter.initialized and predict:
            self.filter.predict_to(now)
        if smoothing:
            self.forget_before(self.filter.last_measurement_time - self.history_length)

    def revert_to(self, time):
        """RosFilter::revertTo: the last saved state at or before ``time`` (the oldest one if the history is too
        short, with a warning), and the measurements after it back into the queue."""
        popped = None
        while self.state_history and self.state_history[-1][0] > time:
            popped = self.state_history.pop()
        restored = self.state_history[-1] if self.state_history else popped
        if not self.state_history and popped is not None:
            self.warn("history_length", f"Could not revert to state with time {time:.3f}: the history "
                      f"(history_length {self.history_length} s) is too short; reverted to {popped[0]:.3f}")
        if restored is None:
            return
        self.filter.last_measurement_time, state, covariance = restored
        self.filter.state, self.filter.covariance = state.copy(), covariance.copy()
        while self.measurement_history and self.measurement_history[-1].time > time:
            measurement = self.measurement_history.pop()
            if restored[0] <= measurement.time:
                heapq.heappush(self.queue, (measurement.time, next(self.sequence), measurement))

    def forget_before(self, cutoff):
        while self.measurement_history and self.measurement_history[0].time < cutoff:
            self.measurement_history.popleft()
        while self.state_history and self.state_history[0][0] < cutoff:
            self.state_history.popleft()

    def differentiate(self, now):
        """The angular acceleration accel/filtered reports, differentiated from the estimated angular velocity."""
        dt = now - self.last_differentiation_time
        if not self.filter.initialized or dt <= 0:
            return
        angular_velocity = self.filter.state[VROLL:VYAW + 1].copy()
        self.angular_acceleration = (angular_velocity - self.last_angular_velocity) / dt
        self.angular_acceleration_covariance = self.filter.covariance[VROLL:VYAW + 1, VROLL:VYAW + 1] * 2.0 / dt ** 2
        self.last_angular_velocity, self.last_differentiation_time = angular_velocity, now

    def set_pose(self, message, now):
        """set_pose (topic and service): the state becomes the given pose, at rest; data stamped before it is
        ignored. A pose or covariance with NaN, inf or huge values is refused (False): it would leave the filter
        nowhere."""
        values = np.concatenate([message.position, message.orientation, np.ravel(message.covariance)])
        if not (np.isfinite(values).all() and (np.abs(values) <= MEASUREMENT_LIMIT).all()):
            return False
        self.initial_measurements.clear()
        self.previous_measurements.clear()
        self.queue.clear()
        self.state_history.clear()
        self.measurement_history.clear()
        self.last_set_pose_time = message.stamp
        covariance = np.eye(STATE_SIZE) * SET_POSE_VARIANCE
        update = np.ones(STATE_SIZE, dtype=bool)
        prepared = self.prepare_pose(message, "set_pose", self.frames.world, False, False, False, update)
        values = np.zeros(STATE_SIZE)
        if prepared is not None:
            values, pose_covariance, _ = prepared
            covariance[:6, :6] = pose_covariance[:6, :6]
            if self.two_d_mode:
                covariance[TWO_D_MEMBERS, TWO_D_MEMBERS] = TWO_D_VARIANCE
        self.filter.state, self.filter.covariance = values, covariance
        self.filter.last_measurement_time = now
        return True
