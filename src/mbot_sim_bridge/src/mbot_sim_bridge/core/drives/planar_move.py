"""``libgazebo_ros_planar_move.so`` without ROS (gazebo_plugins noetic-devel ``gazebo_ros_planar_move.cpp``).

A holonomic base: before every physics step the model's velocity is set outright from the last ``cmd_vel``
(linear.x and linear.y in the robot frame, rotated by the base's yaw; z velocity 0; angular.z about the world
z), so the base moves exactly as commanded whatever its wheels do. ``cmdTimeout`` ≥ 0 zeroes the command when
no new one came for that long (sim time); negative, the default, keeps it for ever. Odometry is the ground
truth pose, published when more than 1/``odometryRate`` has passed, with the twist from the pose difference
since the last one (the commanded angular.z when it exceeds π per period), rotated into the base frame by yaw,
and the odom -> base TF.
"""
import math
from typing import Optional

from .. import names
from ..clock import UpdateTimer
from ..engine import MAX_SPEED
from ..geometry import yaw
from ..params import Param, rate
from ..plugin import Plugin
from .twist_drive import DriveOdometry, TwistCommand, yaw_rotated_velocity


class PlanarMove(TwistCommand, Plugin):
    """Core of libgazebo_ros_planar_move.so (GazeboRosPlanarMove)."""
    NAMESPACE_RULE = names.ROOT
    GAZEBO_CLASS = "PlanarMovePlugin"
    COMMAND_AXES = ("linear.x", "linear.y", "angular.z")
    COMMAND_LIMIT = MAX_SPEED  # set_model_state's cap: 1e10 m/s sent the base 50 m backwards in one step
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the topics", warn_if_missing=False),
        Param("commandTopic", str, "cmd_vel", "geometry_msgs/Twist: linear.x, linear.y (robot frame), angular.z"),
        Param("odometryTopic", str, "odom", "nav_msgs/Odometry (ground truth)"),
        Param("odometryFrame", str, "odom", "frame_id of the odometry and parent of the TF"),
        Param("robotBaseFrame", str, "base_footprint", "child frame of the odometry and the TF"),
        rate("odometryRate", 20.0, "Hz of sim time; <= 0 = no odometry", signed=True),
        Param("cmdTimeout", float, -1.0, "s without a command before it is zeroed; < 0 = never"),
    )
    needs_every_step = True

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.params = params = self.read_params()
        now = context.simulation.sim_time
        rate = params["odometryRate"]
        # Disabled odometry: a timer that never comes due within any run.
        self.timer = UpdateTimer(rate if rate > 0 else 1e-12, strict=True, start=now)
        self.command_timeout = params["cmdTimeout"]
        self.last_pose = context.robot.root_pose()
        self.last_odometry_time = now
        self.latest: Optional[DriveOdometry] = None

    def on_step(self, step_size: float):
        x, y, rotation = self.command(self.context.simulation.sim_time)
        robot = self.context.robot
        heading = yaw(robot.root_pose().orientation)
        cos_h, sin_h = math.cos(heading), math.sin(heading)
        robot.set_root_velocity((x * cos_h - y * sin_h, y * cos_h + x * sin_h, 0.0), (0.0, 0.0, rotation))

    def update(self, now: float):
        """The odometry of the time since the last one."""
        period = now - self.last_odometry_time
        pose = self.context.robot.root_pose()
        linear = ((pose.position[0] - self.last_pose.position[0]) / period,
                  (pose.position[1] - self.last_pose.position[1]) / period)
        rotation = self.command()[2]
        if rotation > math.pi / period:
            angular = rotation
        else:
            angular = math.remainder(yaw(pose.orientation) - yaw(self.last_pose.orientation), 2 * math.pi) / period
        self.last_pose, self.last_odometry_time = pose, now
        self.latest = DriveOdometry(pose, yaw_rotated_velocity(linear, yaw(pose.orientation)), angular)

    def reset(self, now: float):
        super().reset(now)
        self.stop()
        self.last_pose, self.last_odometry_time = self.context.robot.root_pose(), now
