"""``libgazebo_ros_diff_drive.so`` without ROS: the tags, the wheel motors and the odometry.

Mirrors gazebo_plugins' GazeboRosDiffDrive: the command -> wheel-speed split (with Kinetic's legacyMode),
the wheelAcceleration ramp, and the encoder odometry integration. ``DiffDrive`` drives the robot's wheel
joints from the last command; the ROS plugin feeds it cmd_vel and publishes what ``odometry()`` returns.
"""
import logging
import math
from dataclasses import dataclass
from typing import Tuple

from .. import names
from ..clock import UpdateTimer
from ..geometry import Pose
from ..params import Param, non_negative, rate
from ..plugin import Plugin
from .twist_drive import DriveOdometry, TwistCommand, ground_truth_odometry

# Below a millimetre a wheel or a track width is a typo (0, 1e-300) that makes the wheel speeds explode.
MINIMUM_WHEEL_SIZE = 0.001

DIFF_DRIVE_PARAMS = (
    Param("commandTopic", str, "cmd_vel", "geometry_msgs/Twist subscribed, relative to robotNamespace"),
    Param("odometryTopic", str, "odom", "nav_msgs/Odometry published"),
    Param("odometryFrame", str, "odom", "frame_id of the odometry and parent of the odom TF"),
    Param("robotBaseFrame", str, "base_footprint", "child_frame_id of the odometry and child of the odom TF"),
    Param("publishTf", bool, True, "false: no odometry topic and no odom TF at all (as in gazebo_ros)"),
    Param("publishOdomTF", bool, True, "gates only the odom -> base TF", warn_if_missing=False),
    Param("publishWheelTF", bool, False, "wheel frames on /tf (through robot_state_publisher, see README)"),
    Param("publishWheelJointState", bool, False, "wheel joints on joint_states"),
    Param("wheelSeparation", float, 0.34, "distance between the wheels (m)", minimum=MINIMUM_WHEEL_SIZE),
    Param("wheelDiameter", float, 0.15, "wheel diameter (m)", minimum=MINIMUM_WHEEL_SIZE),
    non_negative("wheelTorque", float, 5.0, "maximum torque of each wheel motor (N·m)"),
    non_negative("wheelAcceleration", float, 0.0, "rim acceleration limit (m/s²); 0 = none"),
    rate("updateRate", 100.0, "odometry and command rate (Hz, sim time); ≤ 0 = every physics step", signed=True),
    Param("odometrySource", str, "world", "world: ground truth; encoder: integrated wheel odometry",
          choices=("world", "encoder")),
    Param("leftJoint", str, "left_joint", "joint named 'left' by the plugin"),
    Param("rightJoint", str, "right_joint", "joint named 'right' by the plugin"),
    Param("legacyMode", bool, False, "Kinetic's wheel swap: true gives leftJoint v + ω·s/2 (see README)",
          warn_if_missing=False),
    Param("robotNamespace", str, "", "namespace of the topics; spawn_model sets it", warn_if_missing=False),
    Param("rosDebugLevel", str, "na", "Debug/Info/Warn/Error/Fatal: the bridge's log level",
          warn_if_missing=False),
)
# Read by Gazebo's Noetic plugin without effect; the bridge accepts them with one INFO line.
DIFF_DRIVE_IGNORED_TAGS = ("alwaysOn", "broadcastTF", "torque")

# Gazebo applies both targets at once when either wheel is this close to its target (m/s).
_ACCELERATION_DEADBAND = 0.01


@dataclass(frozen=True)
class DiffDriveGeometry:
    wheel_separation: float
    wheel_radius: float
    legacy_mode: bool

    def wheel_rim_speeds(self, linear: float, angular: float) -> Tuple[float, float]:
        """(leftJoint, rightJoint) rim speeds in m/s for a body twist.

        Without legacyMode (Melodic and later) leftJoint gets v − ω·s/2. Kinetic's legacyMode swapped the
        signs; the course's robot relies on that because its 'left' wheel sits at negative y.
        """
        half_difference = angular * self.wheel_separation / 2.0
        if self.legacy_mode:
            return linear + half_difference, linear - half_difference
        return linear - half_difference, linear + half_difference


class WheelSpeedRamp:
    """wheelAcceleration as gazebo_ros applies it: an integrator per wheel, bypassed near the target."""

    def __init__(self, acceleration: float):
        self.acceleration = acceleration
        self.commanded = [0.0, 0.0]

    def reset(self):
        self.commanded = [0.0, 0.0]

    def step(self, targets: Tuple[float, float], measured: Tuple[float, float], dt: float) -> Tuple[float, float]:
        """Rim speeds to apply, given the targets and the measured rim speeds (all m/s)."""
        if self.acceleration == 0.0 or any(abs(t - m) < _ACCELERATION_DEADBAND for t, m in zip(targets, measured)):
            return tuple(targets)
        limit = self.acceleration * dt
        for index, (target, measured_speed) in enumerate(zip(targets, measured)):
            self.commanded[index] += max(-limit, min(limit, target - measured_speed))
        return tuple(self.commanded)


class EncoderOdometry:
    """odometrySource=encoder: planar pose integrated from wheel angles every physics step."""

    def __init__(self, geometry: DiffDriveGeometry):
        self.geometry = geometry
        self.reset()

    def reset(self):
        self.x = self.y = self.theta = 0.0
        self.linear = self.angular = 0.0

    def integrate(self, left_rate: float, right_rate: float, dt: float):
        """Advance by one step from the joint rates (rad/s) of leftJoint and rightJoint."""
        radius = self.geometry.wheel_radius
        left, right = left_rate * radius * dt, right_rate * radius * dt
        # legacyMode mirrors the turn direction exactly as in the command split.
        turn = (left - right) if self.geometry.legacy_mode else (right - left)
        delta_theta = turn / self.geometry.wheel_separation
        distance = (left + right) / 2.0
        dx = distance * math.cos(self.theta + delta_theta / 2.0)
        dy = distance * math.sin(self.theta + delta_theta / 2.0)
        self.x += dx
        self.y += dy
        self.theta += delta_theta
        if dt > 0:
            # Gazebo reports the speed as a magnitude, so it is never negative, even when reversing.
            self.linear = math.hypot(dx, dy) / dt
            self.angular = delta_theta / dt


_LOG_LEVELS = {"debug": logging.DEBUG, "info": logging.INFO, "warn": logging.WARNING, "error": logging.ERROR,
               "fatal": logging.CRITICAL}


class DiffDrive(TwistCommand, Plugin):
    """The plugin's physics: wheel motors from the last command, every ``updateRate``; odometry on demand."""
    NAMESPACE_RULE = names.MODEL

    GAZEBO_CLASS = "GazeboRosDiffDrive"
    PARAMS = DIFF_DRIVE_PARAMS
    IGNORED_TAGS = DIFF_DRIVE_IGNORED_TAGS

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.params = params = self.read_params()
        self.namespace = self.robot_namespace()
        self.joints = self.named_joints(params, ("leftJoint", "rightJoint"))
        level = _LOG_LEVELS.get(params["rosDebugLevel"].lower())
        if level is not None:
            # Gazebo sets the whole server's roscpp level from this tag; the bridge sets its own loggers'
            # level, leaving rospy's internals (which log broken pipes at DEBUG) at their default.
            logging.getLogger("rosout.mbot_sim_bridge").setLevel(level)
        self.driven_joints = self.joints
        if params["publishWheelJointState"]:
            self.joint_states_published = self.joints
        self.geometry = DiffDriveGeometry(params["wheelSeparation"], params["wheelDiameter"] / 2.0,
                                          params["legacyMode"])
        self.torque = params["wheelTorque"]
        self.ramp = WheelSpeedRamp(params["wheelAcceleration"])
        self.encoder = EncoderOdometry(self.geometry) if params["odometrySource"] == "encoder" else None
        self.needs_every_step = self.encoder is not None
        self.timer = UpdateTimer(params["updateRate"], strict=True, start=context.simulation.sim_time)
        self.last_update = context.simulation.sim_time

    def on_step(self, step_size: float):
        (_, left_rate, _), (_, right_rate, _) = self.context.robot.joint_state(self.joints)
        self.encoder.integrate(left_rate, right_rate, step_size)

    def update(self, now: float):
        linear, angular = self.command()
        robot = self.context.robot
        targets = self.geometry.wheel_rim_speeds(linear, angular)
        radius = self.geometry.wheel_radius
        measured = tuple(rate * radius for _, rate, _ in robot.joint_state(self.joints))
        speeds = self.ramp.step(targets, measured, now - self.last_update)
        for joint, speed in zip(self.joints, speeds):
            robot.set_joint_velocity(joint, speed / radius, self.torque)
        self.last_update = now

    def odometry(self) -> DriveOdometry:
        """The odometry the plugin reports for its odometrySource."""
        if self.encoder is None:
            return ground_truth_odometry(self.context.robot)
        encoder = self.encoder
        pose = Pose((encoder.x, encoder.y, 0.0), (0.0, 0.0, math.sin(encoder.theta / 2), math.cos(encoder.theta / 2)))
        return DriveOdometry(pose, (encoder.linear, 0.0), encoder.angular)

    def reset(self, now: float):
        super().reset(now)
        self.last_update = now
        self.ramp.reset()
        if self.encoder is not None:
            self.encoder.reset()
        self.stop()
