"""``libgazebo_ros_skid_steer_drive.so`` without ROS (gazebo_plugins noetic-devel
``gazebo_ros_skid_steer_drive.cpp``).

Every update (more than 1/``updateRate`` after the last, advanced by whole periods) the odometry is taken from
the ground truth (the model's world pose; the world twist, linear rotated into the base by yaw) and then the
four wheels get velocity motors of at most ``torque``: right wheels v + ω·s/2, left wheels v − ω·s/2, divided by
the wheel radius. ``broadcastTF`` (default false) adds the odom -> base TF. The last cmd_vel holds until
another comes or a reset; a NaN or infinite one is ignored.
"""
from typing import Optional

from .. import names
from ..clock import UpdateTimer
from ..params import Param, non_negative, rate
from ..plugin import Plugin
from .diff_drive import MINIMUM_WHEEL_SIZE
from .twist_drive import DriveOdometry, TwistCommand, ground_truth_odometry

WHEEL_TAGS = ("leftFrontJoint", "rightFrontJoint", "leftRearJoint", "rightRearJoint")


class SkidSteerDrive(TwistCommand, Plugin):
    """Core of libgazebo_ros_skid_steer_drive.so (GazeboRosSkidSteerDrive)."""
    NAMESPACE_RULE = names.ROOT
    GAZEBO_CLASS = "GazeboRosSkidSteerDrive Plugin"
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the topics", warn_if_missing=False),
        Param("broadcastTF", bool, False, "publish the odom -> base TF", warn_if_missing=False),
        Param("leftFrontJoint", str, "left_front_joint", "wheel joint"),
        Param("rightFrontJoint", str, "right_front_joint", "wheel joint"),
        Param("leftRearJoint", str, "left_rear_joint", "wheel joint"),
        Param("rightRearJoint", str, "right_rear_joint", "wheel joint"),
        Param("wheelSeparation", float, 0.4, "m between the left and right wheels", minimum=MINIMUM_WHEEL_SIZE),
        Param("wheelDiameter", float, 0.15, "m", minimum=MINIMUM_WHEEL_SIZE),
        non_negative("torque", float, 5.0, "N·m, the most each wheel motor gives"),
        Param("commandTopic", str, "cmd_vel", "geometry_msgs/Twist subscribed"),
        Param("odometryTopic", str, "odom", "nav_msgs/Odometry (ground truth)"),
        Param("odometryFrame", str, "odom", "frame_id of the odometry"),
        Param("robotBaseFrame", str, "base_footprint", "child_frame_id of the odometry"),
        rate("updateRate", 100.0, "Hz of sim time; <= 0 = every physics step", signed=True),
        non_negative("covariance_x", float, 0.0001, "pose and twist covariance of x"),
        non_negative("covariance_y", float, 0.0001, "pose and twist covariance of y"),
        non_negative("covariance_yaw", float, 0.01, "pose and twist covariance of yaw"),
    )

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.params = params = self.read_params()
        self.joints = self.named_joints(params, WHEEL_TAGS)
        self.driven_joints = self.joints
        self.timer = UpdateTimer(params["updateRate"], strict=True, start=context.simulation.sim_time)
        self.latest: Optional[DriveOdometry] = None

    def update(self, now: float):
        robot = self.context.robot
        self.latest = ground_truth_odometry(robot)
        speed, turn = self.command()
        half_track = turn * self.params["wheelSeparation"] / 2.0
        radius = self.params["wheelDiameter"] / 2.0
        left, right = speed - half_track, speed + half_track
        for joint, rim_speed in zip(self.joints, (left, right, left, right)):
            robot.set_joint_velocity(joint, rim_speed / radius, self.params["torque"])

    def reset(self, now: float):
        super().reset(now)
        self.stop()
