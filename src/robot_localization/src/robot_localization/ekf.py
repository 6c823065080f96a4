"""robot_localization's extended Kalman filter, without ROS: the 15-state omnidirectional model, its predict and
correct steps and their Jacobian, as upstream's FilterBase and Ekf compute them (filter_base.cpp, ekf.cpp).

The state is x y z roll pitch yaw, their velocities in the body frame (vx vy vz vroll vpitch vyaw) and the body
frame's linear acceleration (ax ay az). Times are seconds as floats. One thing differs from upstream: a
measurement's values whose number, variance or covariance is not finite or beyond ``MEASUREMENT_LIMIT`` are left
out of the update as upstream leaves out NaN and inf values, and an update that would leave the state or its
covariance non-finite is undone; ``Ekf.rejections`` says why, for the node to report.
"""
from dataclasses import dataclass

import numpy as np

STATE_SIZE = 15
X, Y, Z, ROLL, PITCH, YAW, VX, VY, VZ, VROLL, VPITCH, VYAW, AX, AY, AZ = range(STATE_SIZE)
STATE_NAMES = ("X", "Y", "Z", "ROLL", "PITCH", "YAW", "X_VELOCITY", "Y_VELOCITY", "Z_VELOCITY",
               "ROLL_VELOCITY", "PITCH_VELOCITY", "YAW_VELOCITY", "X_ACCELERATION", "Y_ACCELERATION",
               "Z_ACCELERATION")
ANGLES = (ROLL, PITCH, YAW)
# Beyond this magnitude a measured value or variance is no measurement (positions in UTM stay below 1e7 m).
MEASUREMENT_LIMIT = 1e9
# Upstream's floor on a measurement variance, without which the gain computation blows up.
MINIMUM_VARIANCE = 1e-9
# Upstream's guard against bag playback with sim time: a longer step is taken as 0.01 s.
LONGEST_DELTA = 100000.0

DEFAULT_PROCESS_NOISE = np.diag([0.05, 0.05, 0.06, 0.03, 0.03, 0.06, 0.025, 0.025, 0.04, 0.01, 0.01, 0.02,
                                 0.01, 0.01, 0.015])


def normalize_angle(angle):
    """angles::normalize_angle: into [-pi, pi)."""
    return (angle + np.pi) % (2.0 * np.pi) - np.pi


@dataclass
class Measurement:
    """One sensor reading mapped onto the state: ``values`` and ``covariance`` are full-sized, ``update`` says
    which members it measures; ``threshold`` is the Mahalanobis rejection threshold in sigmas."""
    topic: str
    time: float
    values: np.ndarray
    covariance: np.ndarray
    update: np.ndarray
    threshold: float = float("inf")


def valid_indices(measurement):
    """The measured members whose value, variance and covariances with the others are finite and bounded (NaN
    fails every comparison).
    Upstream drops NaN and inf values only; a NaN or huge covariance would poison the whole estimate."""
    values = measurement.values
    with np.errstate(invalid="ignore"):
        candidates = np.flatnonzero(measurement.update & (np.abs(values) <= MEASUREMENT_LIMIT))
        block = measurement.covariance[np.ix_(candidates, candidates)]
        good = (np.abs(block) <= MEASUREMENT_LIMIT).all(axis=1)
    return candidates[good]


class Ekf:
    def __init__(self):
        self.process_noise = DEFAULT_PROCESS_NOISE.copy()
        self.sensor_timeout = 1.0 / 30.0
        self.dynamic_process_noise = False
        self.rejections = []
        self.reset()

    def reset(self):
        self.initialized = False
        self.state = np.zeros(STATE_SIZE)
        self.covariance = np.eye(STATE_SIZE) * 1e-9
        self.last_measurement_time = 0.0

    def transfer_function(self, delta):
        """The state transition (body-frame velocities and accelerations rotated into the world frame by the
        current roll, pitch and yaw) and its Jacobian, as in Ekf::predict."""
        roll, pitch, yaw = self.state[ROLL], self.state[PITCH], self.state[YAW]
        vx, vy, vz = self.state[VX:VZ + 1]
        vpitch, vyaw = self.state[VPITCH], self.state[VYAW]
        ax, ay, az = self.state[AX:AZ + 1]
        sp, cp = np.sin(pitch), np.cos(pitch)
        cpi = 1.0 / cp
        tp = sp * cpi
        sr, cr = np.sin(roll), np.cos(roll)
        sy, cy = np.sin(yaw), np.cos(yaw)
        # Body-to-world rotation, rows for x y z.
        rotation = np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                             [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                             [-sp, cp * sr, cp * cr]])
        f = np.eye(STATE_SIZE)
        f[X:Z + 1, VX:VZ + 1] = rotation * delta
        f[X:Z + 1, AX:AZ + 1] = 0.5 * rotation * delta * delta
        f[ROLL, VROLL] = delta
        f[ROLL, VPITCH] = sr * tp * delta
        f[ROLL, VYAW] = cr * tp * delta
        f[PITCH, VPITCH] = cr * delta
        f[PITCH, VYAW] = -sr * delta
        f[YAW, VPITCH] = sr * cpi * delta
        f[YAW, VYAW] = cr * cpi * delta
        f[VX:VZ + 1, AX:AZ + 1] = np.eye(3) * delta

        velocity, acceleration = np.array([vx, vy, vz]), np.array([ax, ay, az])
        half_t2 = 0.5 * delta * delta

        def position_derivative(coefficients):
            coefficients = np.asarray(coefficients)
            return coefficients @ velocity * delta + coefficients @ acceleration * half_t2

        jacobian = f.copy()
        jacobian[X, ROLL] = position_derivative([0.0, cy * sp * cr + sy * sr, -cy * sp * sr + sy * cr])
        jacobian[X, PITCH] = position_derivative([-cy * sp, cy * cp * sr, cy * cp * cr])
        jacobian[X, YAW] = position_derivative([-sy * cp, -sy * sp * sr - cy * cr, -sy * sp * cr + cy * sr])
        jacobian[Y, ROLL] = position_derivative([0.0, sy * sp * cr - cy * sr, -sy * sp * sr - cy * cr])
        jacobian[Y, PITCH] = position_derivative([-sy * sp, sy * cp * sr, sy * cp * cr])
        jacobian[Y, YAW] = position_derivative([cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr])
        jacobian[Z, ROLL] = position_derivative([0.0, cp * cr, -cp * sr])
        jacobian[Z, PITCH] = position_derivative([-cp, -sp * sr, -sp * cr])
        jacobian[ROLL, ROLL] = 1.0 + (cr * tp * vpitch - sr * tp * vyaw) * delta
        jacobian[ROLL, PITCH] = (cpi * cpi * sr * vpitch + cpi * cpi * cr * vyaw) * delta
        jacobian[PITCH, ROLL] = (-sr * vpitch - cr * vyaw) * delta
        jacobian[YAW, ROLL] = (cr * cpi * vpitch - sr * cpi * vyaw) * delta
        jacobian[YAW, PITCH] = (sr * tp * cpi * vpitch + cr * tp * cpi * vyaw) * delta
        return f, jacobian

    def current_process_noise(self):
        """The process noise, scaled on its pose block by the speed when dynamic (computeDynamicProcessNoise)."""
        if not self.dynamic_process_noise:
            return self.process_noise
        noise = self.process_noise.copy()
        speed = np.linalg.norm(self.state[VX:VYAW + 1])
        noise[:6, :6] = self.process_noise[:6, :6] * speed * speed
        return noise

    def predict(self, delta):
        f, jacobian = self.transfer_function(delta)
        noise = self.current_process_noise()
        self.state = f @ self.state
        self.wrap_angles()
        self.covariance = jacobian @ self.covariance @ jacobian.T + delta * noise

    def correct(self, measurement):
        indices = valid_indices(measurement)
        if len(indices) < np.count_nonzero(measurement.update):
            self.rejections.append((measurement.topic, "invalid"))
        if not len(indices):
            return
        size = len(indices)
        h = np.zeros((size, STATE_SIZE))
        h[np.arange(size), indices] = 1.0
        r = measurement.covariance[np.ix_(indices, indices)].copy()
        diagonal = np.abs(np.diag(r))
        np.fill_diagonal(r, np.maximum(diagonal, MINIMUM_VARIANCE))

        pht = self.covariance @ h.T
        with np.errstate(all="ignore"):
            try:
                hphr_inverse = np.linalg.inv(h @ pht + r)
            except np.linalg.LinAlgError:
                self.rejections.append((measurement.topic, "singular"))
                return
            gain = pht @ hphr_inverse
            innovation = measurement.values[indices] - self.state[indices]
            angles = np.isin(indices, ANGLES)
            innovation[angles] = normalize_angle(innovation[angles])
            squared_mahalanobis = innovation @ hphr_inverse @ innovation
            # Upstream's test, with its default threshold (max double) squared to inf: only an overflow fails it.
            if not squared_mahalanobis < measurement.threshold * measurement.threshold:
                self.rejections.append((measurement.topic, "outlier"))
                return
            state = self.state + gain @ innovation
            residual = np.eye(STATE_SIZE) - gain @ h
            covariance = residual @ self.covariance @ residual.T + gain @ r @ gain.T
        if not (np.isfinite(state).all() and np.isfinite(covariance).all()):
            self.rejections.append((measurement.topic, "diverged"))
            return
        self.state, self.covariance = state, covariance
        self.wrap_angles()

    def process_measurement(self, measurement):
        """FilterBase::processMeasurement: predict up to the measurement's time, then correct; the first one
        initializes the measured members (and their covariance) instead."""
        delta = 0.0
        if self.initialized:
            delta = measurement.time - self.last_measurement_time
            if delta > 0:
                self.predict(self.validate_delta(delta))
            self.correct(measurement)
        else:
            indices = valid_indices(measurement)
            if not len(indices):
                self.rejections.append((measurement.topic, "invalid"))
                return
            self.state[indices] = measurement.values[indices]
            self.covariance[np.ix_(indices, indices)] = measurement.covariance[np.ix_(indices, indices)]
            self.initialized = True
        if delta >= 0.0:
            self.last_measurement_time = measurement.time

    def predict_to(self, time):
        """The periodic update's prediction to ``time`` when no measurement came (RosFilter::integrateMeasurements
        with predict_to_current_time, or after sensor_timeout)."""
        delta = self.validate_delta(time - self.last_measurement_time)
        self.predict(delta)
        self.last_measurement_time += delta

    @staticmethod
    def validate_delta(delta):
        return 0.01 if delta > LONGEST_DELTA else delta

    def wrap_angles(self):
        self.state[[ROLL, PITCH, YAW]] = normalize_angle(self.state[[ROLL, PITCH, YAW]])

    def take_rejections(self):
        rejections, self.rejections = self.rejections, []
        return rejections
