"""``libhector_gazebo_ros_imu.so`` without ROS (hector_gazebo_plugins melodic-devel ``gazebo_ros_imu.cpp``).

On each update, with ``dt`` the sim time since the last one (0 on the first after load or reset, which then
keeps the previous values):
- ``rot`` = rpyOffset ∘ the body's world orientation;
- acceleration = rot⁻¹·(Δv/dt − g), so a body at rest reads +9.81 m/s² up; angular rate = rpyOffset⁻¹ applied
  to the rotation between the last and this orientation, as angle·axis/dt;
- each goes through its SensorModel (``accel*``, ``rate*`` tags; ``gaussianNoise`` overrides both noises when
  non-zero), and the yaw model (``yaw*``) advances;
- the orientation gets the heading error (the yaw bias about z) and the roll/pitch error that the
  accelerometer bias implies (its world-frame x and y over g);
- covariances: angular velocity and linear acceleration diagonals are the noises squared; orientation's are
  accel noise²/g² for roll and pitch and the yaw noise² for yaw;
- the bias topic (``biasTopicName``, default ``<topicName>/bias``) carries the orientation error and the
  rate and acceleration biases.
``updateRate`` (Hz) or ``updatePeriod`` (s) pace it; 0 updates on every physics step. ``xyzOffset`` is read
and, as upstream, not applied.
"""
from typing import NamedTuple, Optional, Tuple

import numpy as np
import pybullet

from .. import names
from ..geometry import IDENTITY, Pose, Vector, compose, inverse, pose_from_xyz_rpy, rotation_matrix
from .hector_plugin import HECTOR_UPDATE_PARAMS, HectorUpdates, body_link, update_timer
from .hector_sensor_model import SensorModel, sensor_model_params
from ..sensors.body_sensors import read_vector_param
from ..params import ERROR_MODEL_LIMIT, Param, non_negative, rate
from ..plugin import Plugin

Quaternion = Tuple[float, float, float, float]


class HectorImuReading(NamedTuple):
    stamp: float
    orientation: Quaternion
    angular_velocity: Vector
    linear_acceleration: Vector
    orientation_covariance: Tuple[float, float, float]  # diagonal
    angular_velocity_covariance: Tuple[float, float, float]
    linear_acceleration_covariance: Tuple[float, float, float]
    # The bias message: orientation error, rate bias, acceleration bias.
    orientation_error: Quaternion
    rate_bias: Vector
    accel_bias: Vector


def _quaternion(w: float, x: float, y: float, z: float) -> Quaternion:
    norm = np.sqrt(w * w + x * x + y * y + z * z)
    return (x / norm, y / norm, z / norm, w / norm)


def _rotate_back(orientation: Quaternion, vector) -> np.ndarray:
    """``vector`` expressed in the frame ``orientation`` rotates to (RotateVectorReverse)."""
    return np.asarray(rotation_matrix(orientation)).T @ np.asarray(vector, dtype=float)


class HectorImu(HectorUpdates, Plugin):
    """Core of libhector_gazebo_ros_imu.so (hector's GazeboRosIMU)."""
    NAMESPACE_RULE = names.ROOT
    GAZEBO_CLASS = "GazeboRosIMU"
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the topics", warn_if_missing=False),
        Param("bodyName", str, None, "link measured; absent: the model's root link", warn_if_missing=False),
        Param("frameId", str, None, "frame_id (default: bodyName)", warn_if_missing=False),
        Param("topicName", str, "imu", "sensor_msgs/Imu; empty = none", warn_if_missing=False),
        Param("biasTopicName", str, None, "sensor_msgs/Imu of the biases (default: topicName/bias)",
              warn_if_missing=False),
        Param("serviceName", str, None, "std_srvs/Empty calibrate service, zeroes the rate drift (default: "
              "topicName/calibrate)", warn_if_missing=False),
        non_negative("gaussianNoise", float, 0.0, "when not 0: the accel and rate noise on every axis",
                     warn_if_missing=False, maximum=ERROR_MODEL_LIMIT),
        Param("xyzOffset", str, "0 0 0", "read, no effect (as upstream)", warn_if_missing=False),
        Param("rpyOffset", str, "0 0 0", "rad; pre-multiplies the orientation", warn_if_missing=False),
        rate("updateRate", 0.0, "Hz of sim time; 0 = every physics step", warn_if_missing=False),
        *HECTOR_UPDATE_PARAMS,
        *sensor_model_params("accel", 3, "acceleration (m/s²)"),
        *sensor_model_params("rate", 3, "angular rate (rad/s)"),
        *sensor_model_params("yaw", 1, "heading (rad)"),
    )

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.params = params = self.read_params()
        where = f"{context.where(element)}: {self.label}"
        self.link = body_link(context, element, self.label, params["bodyName"])
        self.frame_id = params["frameId"] if params["frameId"] is not None else (params["bodyName"] or self.link)
        read_vector_param(element, "xyzOffset", self.label, context.where(element))
        rpy = read_vector_param(element, "rpyOffset", self.label, context.where(element)) or (0.0, 0.0, 0.0)
        self.offset = pose_from_xyz_rpy((0.0, 0.0, 0.0), rpy).orientation
        rng = context.random_stream(element.get("name") or "hector_imu")
        self.accel_model = SensorModel.from_params(params, "accel", 3, rng, where)
        self.rate_model = SensorModel.from_params(params, "rate", 3, rng, where)
        self.yaw_model = SensorModel.from_params(params, "yaw", 1, rng, where)
        if params["gaussianNoise"]:
            self.accel_model.gaussian_noise = self.rate_model.gaussian_noise = np.full(3, params["gaussianNoise"])
        self.gravity = np.asarray(context.simulation.engine.physics.gravity, dtype=float)
        self.timer = update_timer(params, context.simulation.sim_time)
        self.latest: Optional[HectorImuReading] = None
        self.calibration_pending = False
        self.sensor_models = (self.accel_model, self.rate_model, self.yaw_model)
        self._rest()

    def _rest(self):
        """GazeboRosIMU::Reset's motion state: orientation identity, velocity and acceleration zero."""
        self.orientation: Quaternion = IDENTITY.orientation
        self.velocity = np.zeros(3)
        self.accel = np.zeros(3)
        self.rate = np.zeros(3)

    def reset(self, now: float):
        super().reset(now)  # fresh drifts
        self._rest()

    def calibrate(self):
        """The calibrate service (from another thread): the next update starts with the rate drift at zero."""
        self.calibration_pending = True

    def update(self, now: float):
        if self.calibration_pending:
            self.calibration_pending = False
            self.rate_model.reset(np.zeros(3))
        dt = self.elapsed(now)
        robot = self.context.robot
        pose = robot.link_world_pose(self.link)
        rot = compose(Pose((0.0, 0.0, 0.0), self.offset), Pose((0.0, 0.0, 0.0), pose.orientation)).orientation
        velocity = np.asarray(robot.link_world_velocity(self.link)[0], dtype=float)
        if dt > 0.0:
            self.accel = _rotate_back(rot, (velocity - self.velocity) / dt - self.gravity)
        self.velocity = velocity
        delta = compose(inverse(Pose((0.0, 0.0, 0.0), self.orientation)), Pose((0.0, 0.0, 0.0), rot)).orientation
        self.orientation = rot
        if dt > 0.0:
            axis, angle = pybullet.getAxisAngleFromQuaternion(delta)
            self.rate = _rotate_back(self.offset, np.asarray(axis) * angle / dt)
        accel = self.accel_model(self.accel, dt)
        rate = self.rate_model(self.rate, dt)
        self.yaw_model.update(dt)

        g = float(np.linalg.norm(self.gravity))
        accel_drift = np.asarray(rotation_matrix(pose.orientation)) @ self.accel_model.bias
        yaw_error = float(self.yaw_model.bias)
        tilt = (_quaternion(1.0, 0.5 * accel_drift[1] / g, -0.5 * accel_drift[0] / g, 0.0) if g > 0
                else IDENTITY.orientation)
        error = compose(Pose((0.0, 0.0, 0.0), _quaternion(np.cos(yaw_error / 2), 0.0, 0.0, np.sin(yaw_error / 2))),
                        Pose((0.0, 0.0, 0.0), tilt)).orientation
        orientation = compose(Pose((0.0, 0.0, 0.0), error), Pose((0.0, 0.0, 0.0), rot)).orientation
        accel_noise, rate_noise = self.accel_model.gaussian_noise, self.rate_model.gaussian_noise
        tilt_variance = tuple(accel_noise[:2] ** 2 / g ** 2) if g > 0 else (-1.0, -1.0)
        self.latest = HectorImuReading(
            now, tuple(orientation), tuple(rate), tuple(accel),
            (*tilt_variance, float(self.yaw_model.gaussian_noise) ** 2), tuple(rate_noise ** 2),
            tuple(accel_noise ** 2), tuple(error), tuple(self.rate_model.bias), tuple(self.accel_model.bias))
