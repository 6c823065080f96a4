"""``libgazebo_ros_tricycle_drive.so`` without ROS (gazebo_plugins noetic-devel ``gazebo_ros_tricycle_drive.cpp``).

cmd_vel's linear.x is the speed of the actuated (front) wheel's rim and angular.z is the steering angle itself
(rad, clamped to ±π/2), as upstream reads them: not a yaw rate. Every update (more than 1/``updateRate`` after
the last, advanced by whole periods), as upstream:
- the odometry is published first, from the ground truth (``world``: the model's pose, its linear velocity
  rotated into the base by yaw, the world yaw rate) or from the encoder wheels (``encoder``), then
- the actuated wheel gets a velocity motor of at most ``wheelTorque`` towards speed / (diameter / 2); with
  ``wheelAcceleration`` > 0 its speed changes by at most wheelAcceleration·dt when slowing and
  wheelDeceleration·dt when speeding up (upstream's names are swapped so), and stays when within
  ``wheelSpeedTolerance``;
- the steering joint: with ``steeringSpeed`` 0 (the default) it is set to the angle (Gazebo's SetPosition;
  here a position servo of unbounded force, which reaches it within the step); with ``steeringSpeed`` > 0 it
  turns at ±steeringSpeed until within ``steeringAngleTolerance``, positive whenever the angle error (current
  − target) is below the wheel's target speed, as upstream compares them: so, driving forward, it only ever
  steers one way.
Encoder odometry integrates the encoder wheels' speeds every physics step, with upstream's heading change
(left − right) / separation: it turns the opposite way to the robot, as upstream's does.
"""
import math
from typing import Optional

from .. import names
from ..clock import UpdateTimer
from ..geometry import pose_from_xyz_rpy
from ..log import get_logger, warn_once
from ..params import Param, non_negative, rate
from ..plugin import Plugin
from ..ros_control.hardware_interface import UNBOUNDED_EFFORT
from .diff_drive import MINIMUM_WHEEL_SIZE
from .twist_drive import DriveOdometry, TwistCommand, ground_truth_odometry

_logger = get_logger(__name__)

JOINT_TAGS = ("steeringJoint", "actuatedWheelJoint", "encoderWheelLeftJoint", "encoderWheelRightJoint")
ODOMETRY_SOURCES = ("world", "encoder")
MAX_STEERING_ANGLE = math.pi / 2


class TricycleDrive(TwistCommand, Plugin):
    """Core of libgazebo_ros_tricycle_drive.so (GazeboRosTricycleDrive)."""
    NAMESPACE_RULE = names.MODEL
    GAZEBO_CLASS = "TricycleDrive"
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the topics", warn_if_missing=False),
        Param("steeringJoint", str, "front_steering_joint", "the steering joint"),
        Param("actuatedWheelJoint", str, "front_wheel_joint", "the driven wheel's joint"),
        Param("encoderWheelLeftJoint", str, "left_wheel_joint", "left encoder wheel's joint"),
        Param("encoderWheelRightJoint", str, "right_wheel_joint", "right encoder wheel's joint"),
        Param("actuatedWheelDiameter", float, 0.15, "m", minimum=MINIMUM_WHEEL_SIZE),
        Param("encoderWheelDiameter", float, 0.15, "m", minimum=MINIMUM_WHEEL_SIZE),
        Param("encoderWheelSeparation", float, 0.5, "m between the encoder wheels", minimum=MINIMUM_WHEEL_SIZE),
        non_negative("wheelTorque", float, 5.0, "N·m, the most the wheel and the steering motors give"),
        Param("commandTopic", str, "cmd_vel", "geometry_msgs/Twist: linear.x wheel speed, angular.z steering angle"),
        Param("odometryTopic", str, "odom", "nav_msgs/Odometry"),
        Param("odometryFrame", str, "odom", "frame_id of the odometry and parent of the TF"),
        Param("robotBaseFrame", str, "base_link", "child frame of the odometry and the TF"),
        Param("odometrySource", str, "world", "world (ground truth) or encoder", choices=ODOMETRY_SOURCES),
        rate("updateRate", 100.0, "Hz of sim time; <= 0 = every physics step", signed=True),
        non_negative("wheelAcceleration", float, 0.0, "rad/s² when slowing; 0 = no limit"),
        non_negative("wheelDeceleration", float, None, "rad/s² when speeding up; absent: wheelAcceleration",
                     warn_if_missing=False),
        non_negative("wheelSpeedTolerance", float, 0.01, "rad/s within which the wheel keeps its speed"),
        non_negative("steeringSpeed", float, 0.0, "rad/s; 0 = the steering is set to the angle"),
        non_negative("steeringAngleTolerance", float, 0.01, "rad within which the steering stops"),
        Param("publishWheelTF", bool, False, "the joints' frames (through joint_states here)"),
        Param("publishWheelJointState", bool, False, "joint_states of the four joints"),
    )

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.params = params = self.read_params()
        if params["wheelDeceleration"] is None:
            params["wheelDeceleration"] = params["wheelAcceleration"]
        self.joints = self.named_joints(params, JOINT_TAGS)
        self.steering_joint, self.wheel_joint = self.joints[:2]
        self.driven_joints = self.joints[:2]
        if params["publishWheelJointState"]:
            self.joint_states_published = self.joints
        self.encoder = params["odometrySource"] == "encoder"
        self.needs_every_step = self.encoder
        now = context.simulation.sim_time
        self.timer = UpdateTimer(params["updateRate"], strict=True, start=now)
        self.last_update = now
        self._reset_encoder(now)
        self.latest: Optional[DriveOdometry] = None

    def _reset_encoder(self, now: float):
        self.encoder_pose = (0.0, 0.0, 0.0)  # x, y, heading
        self.encoder_twist = ((0.0, 0.0), 0.0)
        self.last_encoder_time = now

    def on_step(self, step_size: float):
        now = self.context.simulation.sim_time
        dt = now - self.last_encoder_time
        self.last_encoder_time = now
        if dt <= 0:
            return
        (_, left, _), (_, right, _) = self.context.robot.joint_state(self.joints[2:])
        radius = self.params["encoderWheelDiameter"] / 2.0
        separation = self.params["encoderWheelSeparation"]
        left_distance, right_distance = left * radius * dt, right * radius * dt
        x, y, heading = self.encoder_pose
        mean = (left_distance + right_distance) / 2.0
        turn = (left_distance - right_distance) / separation
        if not all(math.isfinite(value) for value in (x + mean, y + mean, heading + turn)):
            warn_once(_logger, f"{self.label}: the encoder odometry overflows (encoderWheelDiameter "
                               f"{self.params['encoderWheelDiameter']:g}, encoderWheelSeparation {separation:g}); "
                               "it stays at its last finite pose")
            return
        dx = mean * math.cos(heading + turn / 2.0)
        dy = mean * math.sin(heading + turn / 2.0)
        self.encoder_pose = (x + dx, y + dy, heading + turn)
        self.encoder_twist = ((dx / dt, dy / dt), turn / dt)

    def odometry(self) -> DriveOdometry:
        if self.encoder:
            x, y, heading = self.encoder_pose
            linear, angular = self.encoder_twist
            return DriveOdometry(pose_from_xyz_rpy((x, y, 0.0), (0.0, 0.0, heading)), linear, angular)
        return ground_truth_odometry(self.context.robot)

    def update(self, now: float):
        dt = now - self.last_update
        self.last_update = now
        self.latest = self.odometry()
        speed, angle = self.command()
        wheel_speed = speed / (self.params["actuatedWheelDiameter"] / 2.0)
        self._drive_wheel(wheel_speed, dt)
        self._steer(max(-MAX_STEERING_ANGLE, min(MAX_STEERING_ANGLE, angle)), wheel_speed)

    def _drive_wheel(self, target: float, dt: float):
        params, robot = self.params, self.context.robot
        applied = target
        if params["wheelAcceleration"] > 0:
            (_, current, _), = robot.joint_state([self.wheel_joint])
            difference = current - target
            if abs(difference) < params["wheelSpeedTolerance"]:
                applied = current
            elif abs(difference) > params["wheelAcceleration"] * dt:
                applied = (current - params["wheelAcceleration"] * dt if difference > 0
                           else current + params["wheelDeceleration"] * dt)
        robot.set_joint_velocity(self.wheel_joint, applied, params["wheelTorque"])

    def _steer(self, target: float, wheel_speed: float):
        params, robot = self.params, self.context.robot
        steering_speed = params["steeringSpeed"]
        if steering_speed == 0:
            robot.set_joint_position(self.steering_joint, target, UNBOUNDED_EFFORT)
            return
        (current, _, _), = robot.joint_state([self.steering_joint])
        difference = current - target
        if abs(difference) < params["steeringAngleTolerance"]:
            velocity = 0.0
        else:
            # Upstream compares the error with the wheel's target speed, not with 0.
            velocity = steering_speed if difference < wheel_speed else -steering_speed
        robot.set_joint_velocity(self.steering_joint, velocity, params["wheelTorque"])

    def reset(self, now: float):
        super().reset(now)
        self.stop()
        self.last_update = now
        self._reset_encoder(now)
