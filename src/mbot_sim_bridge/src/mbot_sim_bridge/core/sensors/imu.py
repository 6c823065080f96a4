"""Gazebo's two IMUs: the model plugin ``libgazebo_ros_imu.so`` and ``<sensor type="imu">`` with
``libgazebo_ros_imu_sensor.so`` (gazebo_plugins noetic-devel ``gazebo_ros_imu.cpp``,
``gazebo_ros_imu_sensor.cpp``; Gazebo ``sensors/ImuSensor.cc``, ``GaussianNoiseModel.cc``).

``ImuModelPlugin`` (GazeboRosIMU), as Gazebo computes it:
- orientation = rpyOffset ∘ the body's world orientation, without noise;
- angular_velocity = R·(ω_world + n) and linear_acceleration = R·(Δv_world/Δt + n), where R is the body's
  world rotation (Gazebo rotates the world vectors *by* the body orientation rather than into the body frame,
  which only matters once the body tilts or turns), n ~ N(0, gaussianNoise) per axis and Δv/Δt the change of
  the body's world linear velocity since the last message. **Gravity is not included**: a body at rest reads
  0 m/s². ``xyzOffset`` has no effect. ``<imu><noise>`` blocks (TurtleBot3 writes one) are never read.
- every covariance diagonal is gaussianNoise², frame_id = frameName (default bodyName);
- ``updateRate`` 0 = every physics step, as in Gazebo (TurtleBot3: 1000 messages a sim second); nothing is
  computed while nobody subscribes, and the bridge then looks only every IDLE_PERIOD. While read, the body's
  state is recorded after every step (one PyBullet query) and the readings of the recorded steps are
  computed together with numpy when the loop next stops (at most MAX_BATCH_SIM_SECONDS later), each stamped
  with its own step, so the plugin no longer makes the loop stop at every step.
- sdformat renames a ``bodyName``/``frameName`` that names a link lumped by a fixed joint to the surviving
  parent link (that is why TurtleBot3's /imu says frame_id base_footprint in Gazebo); the bridge does the same.

``ImuSensor`` (GazeboRosImuSensor over gazebo::sensors::ImuSensor):
- orientation = rpyOffset ∘ the sensor's world orientation (REP 145: the world is the reference);
- angular_velocity = the sensor-frame angular velocity; linear_acceleration = the sensor-frame
  (Δv/Δt − g) of the sensor point, so a sensor at rest reads +9.81 m/s² up; each axis gets the sensor's
  ``<imu><angular_velocity|linear_acceleration><x|y|z><noise>`` (mean, stddev and a bias drawn once from
  bias_mean/bias_stddev with a random sign);
- the plugin then adds N(0, gaussianNoise) to every field (orientation too, unnormalized), sets every
  covariance diagonal to gaussianNoise², frame_id = frameName (required), and publishes no faster than
  ``updateRateHZ`` (default 1 Hz).
- Δv/Δt is taken over the bridge's sensor period (the timer's), not one physics step: the same mean
  acceleration, without the step-to-step contact jitter.
"""
import xml.etree.ElementTree as ET
from typing import NamedTuple, Optional, Tuple

import numpy as np

from .. import names
from ..clock import EveryStopTimer, UpdateTimer
from ..errors import ConfigError
from ..geometry import IDENTITY, Pose, Vector, compose, pose_from_xyz_rpy, quaternion_products, rotation_matrix
from ..log import get_logger, warn_once
from ..params import ERROR_MODEL_LIMIT, Param, PluginParams, non_negative, rate
from ..plugin import Plugin
from .body_sensors import IDLE_PERIOD, gazebo_body, read_vector_param
from .sensor_elements import gaussian_noise, sensor_label, sensor_pose

_log = get_logger(__name__)


class ImuReading(NamedTuple):
    stamp: float
    orientation: Tuple[float, float, float, float]  # x, y, z, w
    angular_velocity: Vector
    linear_acceleration: Vector
    covariance: float  # the value on every covariance diagonal


class ImuReadings(NamedTuple):
    """Readings of consecutive steps, one row each."""
    stamps: np.ndarray  # (N,) sim seconds
    orientations: np.ndarray  # (N, 4) x, y, z, w
    angular_velocities: np.ndarray  # (N, 3)
    linear_accelerations: np.ndarray  # (N, 3)
    covariance: float

    def last(self) -> ImuReading:
        return ImuReading(float(self.stamps[-1]), tuple(self.orientations[-1]), tuple(self.angular_velocities[-1]),
                          tuple(self.linear_accelerations[-1]), self.covariance)


class _VelocityDifference:
    """Δv/Δt of a world velocity between calls, as the IMU sensor forms its acceleration."""

    def __init__(self):
        self.last_velocity: Optional[np.ndarray] = None
        self.last_time = 0.0

    def reset(self, velocity, now: float):
        self.last_velocity, self.last_time = np.asarray(velocity, dtype=float), now

    def __call__(self, velocity, now: float) -> np.ndarray:
        velocity = np.asarray(velocity, dtype=float)
        dt = now - self.last_time
        acceleration = (velocity - self.last_velocity) / dt if dt > 0 else np.zeros(3)
        self.reset(velocity, now)
        return acceleration


class ImuModelPlugin(Plugin):
    """Core of libgazebo_ros_imu.so (GazeboRosIMU)."""
    NAMESPACE_RULE = names.ROOT

    GAZEBO_CLASS = "GazeboRosIMU"
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the topic and service", warn_if_missing=False),
        Param("bodyName", str, None, "link whose motion is measured", required=True),
        # Gazebo reports these missing at INFO level, not as warnings.
        Param("topicName", str, "/default_imu", "sensor_msgs/Imu; empty = none", warn_if_missing=False),
        Param("serviceName", str, "/default_imu", "std_srvs/Empty calibrate service (does nothing)",
              warn_if_missing=False),
        non_negative("gaussianNoise", float, 0.0, "stddev on rates and accelerations; covariance diagonals",
                     warn_if_missing=False, maximum=ERROR_MODEL_LIMIT),
        Param("xyzOffset", str, "0 0 0", "read, no effect in Gazebo", warn_if_missing=False),
        Param("rpyOffset", str, "0 0 0", "rad; pre-multiplies the orientation", warn_if_missing=False),
        rate("updateRate", 0.0, "Hz of sim time; 0 = every physics step", warn_if_missing=False),
        Param("frameName", str, None, "frame_id (default: bodyName)", warn_if_missing=False),
    )
    IGNORED_TAGS = ("alwaysOn", "imu")

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.params = self.read_params()
        robot = context.robot
        where = context.where(element)
        body = self.params["bodyName"]
        if body not in robot.model.lumped_into:
            raise ConfigError(f"{where}: {self.label}: bodyName: {body} does not exist (links: "
                              f"{', '.join(sorted(robot.model.lumped_into))})")
        # sdformat renames a lumped bodyName (and a frameName equal to it) to the link that survives.
        self.link = gazebo_body(robot, body)[0]
        frame = self.params["frameName"] if self.params["frameName"] is not None else body
        self.frame_name = gazebo_body(robot, frame)[0] if frame in robot.model.lumped_into else frame
        read_vector_param(element, "xyzOffset", self.label, where)
        rpy = read_vector_param(element, "rpyOffset", self.label, where) or (0.0, 0.0, 0.0)
        self.offset = pose_from_xyz_rpy((0.0, 0.0, 0.0), rpy).orientation
        self._offset_rotation = np.array(rotation_matrix(self.offset))
        self.noise = self.params["gaussianNoise"]
        self.rng = context.random_stream(element.get("name") or "imu")
        simulation = context.simulation
        now = simulation.sim_time
        self.timer = UpdateTimer(self.params["updateRate"], start=now)
        self.period = self.timer.period
        # A rate at or above the physics rate reads every step, as updateRate 0 does.
        self.every_step = self.period <= simulation.step_size * (1.0 + 1e-9)
        self._stopping_timer, self._every_stop_timer = self.timer, EveryStopTimer()
        self._rows = []  # the body's recorded Bullet states since the last reading
        self._recording = False
        self._last_velocity = np.asarray(robot.link_world_velocity(self.link)[0], dtype=float)
        self._last_time = now
        self.readings: Optional[ImuReadings] = None

    @property
    def latest(self) -> Optional[ImuReading]:
        return None if self.readings is None else self.readings.last()

    def step_recorder(self, now: float):
        if not self._recording:
            return None
        return self.context.robot.link_state_recorder(self.link, self._rows)

    def reset(self, now: float):
        super().reset(now)
        self._stopping_timer.reset(now)  # also when recording: reset_simulation takes sim time back to 0
        self._rows.clear()
        self._last_velocity = np.asarray(self.context.robot.link_world_velocity(self.link)[0], dtype=float)
        self._last_time = now

    def idle(self, now: float):
        """While nothing reads the IMU, look again only every IDLE_PERIOD instead of every step; Gazebo keeps
        its last time and velocity meanwhile, and the next reading differences from them."""
        self._recording = False
        self._rows.clear()
        self.timer = self._stopping_timer
        self.timer.period = max(self.period, IDLE_PERIOD)

    def update(self, now: float):
        if not self._rows:  # the first reading after idle, or a rate below the physics rate: the state now
            self.context.robot.link_state_recorder(self.link, self._rows)()
        self.readings = self.read()
        self._rows.clear()
        if self.every_step:
            self._recording = True
            self.timer = self._every_stop_timer
        else:
            self.timer.period = self.period

    def read(self) -> ImuReadings:
        """The readings of the recorded rows, which end at the current step."""
        simulation = self.context.simulation
        count, step, last_step = len(self._rows), simulation.step_size, simulation.engine.steps
        stamps = np.arange(last_step - count + 1, last_step + 1) * step
        orientations, rotations, velocities, angular = self.context.robot.recorded_link_states(self.link, self._rows)
        if self.offset != IDENTITY.orientation:
            orientations = quaternion_products(self.offset, orientations)
            rotations = self._offset_rotation @ rotations
        # Δv/Δt from each step's velocity and the one before (the last reading's for the first row).
        accelerations = np.empty_like(velocities)
        first_interval = stamps[0] - self._last_time
        accelerations[0] = (velocities[0] - self._last_velocity) / first_interval if first_interval > 0 else 0.0
        np.subtract(velocities[1:], velocities[:-1], out=accelerations[1:])
        accelerations[1:] /= step
        self._last_velocity, self._last_time = velocities[-1], stamps[-1]
        if self.noise > 0:
            noise = self.rng.normal(0.0, self.noise, (count, 6))
            angular, accelerations = angular + noise[:, :3], accelerations + noise[:, 3:]
        return ImuReadings(stamps, orientations, (rotations @ angular[..., None])[..., 0],
                           (rotations @ accelerations[..., None])[..., 0], self.noise ** 2)


class AxisNoise(NamedTuple):
    mean: np.ndarray
    stddev: np.ndarray
    bias: np.ndarray


_NOISE_PARAMS = (
    Param("type", str, "none", "gaussian or none", warn_if_missing=False),
    Param("mean", float, 0.0, "", warn_if_missing=False),
    non_negative("stddev", float, 0.0, "", warn_if_missing=False),
    Param("bias_mean", float, 0.0, "", warn_if_missing=False),
    non_negative("bias_stddev", float, 0.0, "", warn_if_missing=False),
)
_UNSUPPORTED_NOISE_TAGS = ("precision", "dynamic_bias_stddev", "dynamic_bias_correlation_time")


def read_imu_noise(sensor: ET.Element, quantity: str, rng: np.random.Generator, label: str,
                   where: str) -> AxisNoise:
    """Per-axis gaussian noise of ``<imu><quantity><x|y|z><noise>``; the bias is drawn once, as Gazebo does."""
    mean, stddev, bias = np.zeros(3), np.zeros(3), np.zeros(3)
    for axis, name in enumerate("xyz"):
        element = sensor.find(f"imu/{quantity}/{name}/noise")
        if element is None:
            continue
        values = PluginParams(element, f"{label} <{quantity}><{name}><noise>", where=where,
                              check_unknown=False).read(_NOISE_PARAMS)
        for tag in _UNSUPPORTED_NOISE_TAGS:
            if element.find(tag) is not None:
                warn_once(_log, f"{where}: {label}: <{quantity}><{name}><noise><{tag}> is not simulated")
        if not gaussian_noise(element, values["type"], f"{where}: {label}", f"<{quantity}><{name}>"):
            continue
        mean[axis], stddev[axis] = values["mean"], values["stddev"]
        if values["bias_mean"] or values["bias_stddev"]:
            drawn = rng.normal(values["bias_mean"], values["bias_stddev"])
            bias[axis] = -drawn if rng.uniform() < 0.5 else drawn
    return AxisNoise(mean, stddev, bias)


class ImuSensor(Plugin):
    """Core of libgazebo_ros_imu_sensor.so (GazeboRosImuSensor) over Gazebo's ImuSensor."""
    NAMESPACE_RULE = names.IMU_SENSOR

    GAZEBO_CLASS = "GazeboRosImuSensor"
    PARAMS = (
        Param("robotNamespace", str, None, "absent: /MODEL_NAME/", warn_if_missing=False),
        Param("topicName", str, "imu_data", "sensor_msgs/Imu, relative to the namespace"),
        Param("frameName", str, None, "frame_id", required=True),
        rate("updateRateHZ", 1.0, "Hz; publishes no faster than this; 0 = every sensor update"),
        non_negative("gaussianNoise", float, 0.0, "stddev on every field; covariance diagonals",
                     maximum=ERROR_MODEL_LIMIT),
        Param("xyzOffset", str, "0 0 0", "read, unused by Gazebo"),
        Param("rpyOffset", str, "0 0 0", "rad; pre-multiplies the orientation"),
        Param("initialOrientationAsReference", bool, False, "true is deprecated and not emulated",
              warn_if_missing=False),
    )
    IGNORED_TAGS = ("alwaysOn",)
    SENSOR_TYPES = ("imu",)
    SENSOR_PARAMS = (
        rate("update_rate", 0.0, "Hz; 0 = every physics step", warn_if_missing=False),
    )

    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        self.params = self.read_params()
        robot = context.robot
        where = context.where(element)
        name, sensor_where, label = sensor_label(sensor, "imu", context.link, robot.model.document)
        sensor_rate = PluginParams(sensor, label, where=sensor_where, check_unknown=False).read(
            self.SENSOR_PARAMS)["update_rate"]
        if self.params["initialOrientationAsReference"]:
            warn_once(_log, f"{self.label}: <initialOrientationAsReference> true is deprecated (REP 145) and not "
                            f"emulated; the world is the orientation reference")
        self.sensor_pose = sensor_pose(sensor, robot.model.document, sensor_where, label)
        self.link = context.link
        rpy = read_vector_param(element, "rpyOffset", self.label, where) or (0.0, 0.0, 0.0)
        read_vector_param(element, "xyzOffset", self.label, where)
        self.offset = pose_from_xyz_rpy((0.0, 0.0, 0.0), rpy)
        self.noise = self.params["gaussianNoise"]
        self.rng = context.random_stream(name)
        self.gyro_noise = read_imu_noise(sensor, "angular_velocity", self.rng, label, where)
        self.accel_noise = read_imu_noise(sensor, "linear_acceleration", self.rng, label, where)
        self.gravity = np.asarray(context.simulation.engine.physics.gravity, dtype=float)
        # The plugin publishes at most every 1/updateRateHZ of sensor time; the sensor updates at its
        # <update_rate>. The bridge reads the sensor only when the plugin would publish: the slower rate.
        plugin_rate = self.params["updateRateHZ"]
        rates = [rate for rate in (sensor_rate, plugin_rate) if rate > 0]
        now = context.simulation.sim_time
        self.timer = UpdateTimer(min(rates) if rates else 0.0, start=now)
        self.difference = _VelocityDifference()
        self.difference.reset(self._point_velocity(), now)
        self.latest: Optional[ImuReading] = None

    def _world_pose(self) -> Pose:
        return compose(self.context.robot.link_world_pose(self.link), self.sensor_pose)

    def _point_velocity(self):
        # The sensor origin's world velocity: the link frame's plus ω × (sensor offset in the world).
        robot = self.context.robot
        linear, angular = robot.link_world_velocity(self.link)
        if self.sensor_pose == IDENTITY:
            return linear
        link_pose = robot.link_world_pose(self.link)
        arm = np.asarray(rotation_matrix(link_pose.orientation)) @ np.asarray(self.sensor_pose.position)
        return np.asarray(linear) + np.cross(angular, arm)

    def reset(self, now: float):
        super().reset(now)
        self.difference.reset(self._point_velocity(), now)

    def idle(self, now: float):
        """While nothing reads the sensor, the next reading differences from the velocity now."""
        self.difference.reset(self._point_velocity(), now)

    def read(self, now: float) -> ImuReading:
        pose = self._world_pose()
        rotation = np.asarray(rotation_matrix(pose.orientation))
        _, angular = self.context.robot.link_world_velocity(self.link)
        acceleration = self.difference(self._point_velocity(), now)
        gyro = rotation.T @ np.asarray(angular)
        accel = rotation.T @ (acceleration - self.gravity)
        for values, noise in ((gyro, self.gyro_noise), (accel, self.accel_noise)):
            if noise.stddev.any() or noise.mean.any() or noise.bias.any():
                values += self.rng.normal(noise.mean, noise.stddev) + noise.bias
        orientation = np.asarray(compose(self.offset, Pose((0.0, 0.0, 0.0), pose.orientation)).orientation)
        if self.noise > 0:
            extra = self.rng.normal(0.0, self.noise, 10)
            orientation, gyro, accel = orientation + extra[:4], gyro + extra[4:7], accel + extra[7:]
        return ImuReading(now, tuple(orientation), tuple(gyro), tuple(accel), self.noise ** 2)

    def update(self, now: float):
        self.latest = self.read(now)
