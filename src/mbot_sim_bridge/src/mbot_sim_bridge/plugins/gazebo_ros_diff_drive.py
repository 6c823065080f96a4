"""``libgazebo_ros_diff_drive.so``: cmd_vel in; odometry, odom TF and wheel joint states out."""
import logging
import math
import threading

import rospy
from geometry_msgs.msg import TransformStamped, Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState

from ..core.clock import UpdateTimer
from ..core.diff_drive import (DIFF_DRIVE_IGNORED_TAGS, DIFF_DRIVE_PARAMS, ODOM_POSE_COVARIANCE,
                               DiffDriveGeometry, EncoderOdometry, WheelSpeedRamp, yaw_rotated_velocity)
from ..core.errors import ConfigError
from ..core.geometry import yaw
from ..core.params import PluginParams
from . import BridgePlugin, PluginContext, loop_publisher, resolve_frame, resolve_in_namespace

_LOG_LEVELS = {"debug": logging.DEBUG, "info": logging.INFO, "warn": logging.WARNING, "error": logging.ERROR,
               "fatal": logging.CRITICAL}


def read_params(element, model_name: str):
    """The plugin's tags with Gazebo's defaults; the namespace falls back to the model name, as in gazebo_ros."""
    namespace_element = element.find("robotNamespace")
    namespace = (namespace_element.text or "").strip() if namespace_element is not None else ""
    label = "GazeboRosDiffDrive(ns = %s)" % (namespace or model_name)
    values = PluginParams(element, label, ignored=DIFF_DRIVE_IGNORED_TAGS).read(DIFF_DRIVE_PARAMS)
    values["robotNamespace"] = namespace or model_name
    return label, values


class GazeboRosDiffDrive(BridgePlugin):
    def __init__(self, context: PluginContext, element):
        self.context = context
        robot = context.robot
        self.label, params = read_params(element, robot.name)
        for tag in ("leftJoint", "rightJoint"):
            if params[tag] not in robot.joint_index:
                raise ConfigError("%s: <%s> names joint '%s', which the robot does not have; movable joints: %s"
                                  % (self.label, tag, params[tag], ", ".join(robot.movable_joints) or "none"))
        level = _LOG_LEVELS.get(params["rosDebugLevel"].lower())
        if level is not None:
            # Gazebo sets the whole server's roscpp level from this tag; the bridge sets its own loggers'
            # level, leaving rospy's internals (which log broken pipes at DEBUG) at their default.
            logging.getLogger("rosout.mbot_sim_bridge").setLevel(level)
        self.joints = (params["leftJoint"], params["rightJoint"])
        self.geometry = DiffDriveGeometry(params["wheelSeparation"], params["wheelDiameter"] / 2.0,
                                          params["legacyMode"])
        self.torque = params["wheelTorque"]
        self.ramp = WheelSpeedRamp(params["wheelAcceleration"])
        self.encoder = EncoderOdometry(self.geometry) if params["odometrySource"] == "encoder" else None
        self.needs_every_step = self.encoder is not None
        self.odom_frame = resolve_frame(params["odometryFrame"])
        self.base_frame = resolve_frame(params["robotBaseFrame"])
        self.publish_odom_tf = params["publishTf"] and params["publishOdomTF"]
        self.timer = UpdateTimer(params["updateRate"], strict=True, start=context.engine.sim_time)
        self.last_update = context.engine.sim_time
        namespace = params["robotNamespace"]

        self._lock = threading.Lock()
        self._command = (0.0, 0.0)
        # publishTf=false means no odometry topic at all, not just no TF (gazebo_ros reads it that way).
        self.odom_publisher = (loop_publisher(resolve_in_namespace(namespace, params["odometryTopic"]), Odometry)
                               if params["publishTf"] else None)
        self.joint_state_publisher = (loop_publisher(resolve_in_namespace(namespace, "joint_states"), JointState)
                                      if params["publishWheelJointState"] else None)
        self.command_topic = resolve_in_namespace(namespace, params["commandTopic"])
        self.subscriber = rospy.Subscriber(self.command_topic, Twist, self._on_command, queue_size=1)
        if params["publishWheelTF"]:
            rospy.loginfo("%s: publishWheelTF: the wheel frames reach /tf through robot_state_publisher from "
                          "joint_states; they are not broadcast a second time (that duplicate is what makes "
                          "Gazebo's wheels jump in rviz, gazebo_ros_pkgs#1524)", self.label)
        rospy.loginfo("%s: %s -> wheels %s/%s, separation %.3f m, diameter %.3f m, torque %.1f N·m, "
                      "acceleration %.2f m/s², %s odometry on %s at %.0f Hz, legacyMode %s",
                      self.label, self.command_topic, self.joints[0], self.joints[1],
                      self.geometry.wheel_separation, 2 * self.geometry.wheel_radius, self.torque,
                      self.ramp.acceleration, params["odometrySource"],
                      self.odom_publisher.resolved_name if self.odom_publisher else "(none: publishTf false)",
                      params["updateRate"], self.geometry.legacy_mode)

    @property
    def joint_states_published(self):
        return self.joints if self.joint_state_publisher is not None else ()

    def _on_command(self, message: Twist):
        linear, angular = message.linear.x, message.angular.z
        if not (math.isfinite(linear) and math.isfinite(angular)):
            rospy.logwarn_throttle(5.0, "%s: ignored a %s with a non-finite value (linear.x %s, angular.z %s); "
                                   "keeping the last valid command" % (self.label, self.command_topic, linear, angular))
            return
        with self._lock:
            self._command = (linear, angular)

    def on_step(self, step_size: float):
        (_, left_rate, _), (_, right_rate, _) = self.context.robot.joint_state(self.joints)
        self.encoder.integrate(left_rate, right_rate, step_size)

    def update(self, now: float):
        stamp = self.context.stamp()
        if self.odom_publisher is not None:
            self._publish_odometry(stamp)
        if self.joint_state_publisher is not None:
            self._publish_wheel_joint_states(stamp)
        with self._lock:
            linear, angular = self._command
        targets = self.geometry.wheel_rim_speeds(linear, angular)
        radius = self.geometry.wheel_radius
        measured = tuple(rate * radius for _, rate, _ in self.context.robot.joint_state(self.joints))
        speeds = self.ramp.step(targets, measured, now - self.last_update)
        for joint, speed in zip(self.joints, speeds):
            self.context.robot.set_joint_velocity(joint, speed / radius, self.torque)
        self.last_update = now

    def _publish_odometry(self, stamp):
        robot = self.context.robot
        odometry = Odometry()
        odometry.header.stamp = stamp
        odometry.header.frame_id = self.odom_frame
        odometry.child_frame_id = self.base_frame
        pose, twist = odometry.pose.pose, odometry.twist.twist
        if self.encoder is None:
            root = robot.root_pose()
            pose.position.x, pose.position.y, pose.position.z = root.position
            (pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w) = root.orientation
            linear, angular = robot.root_velocity()
            twist.linear.x, twist.linear.y = yaw_rotated_velocity(linear, yaw(root.orientation))
            twist.angular.z = angular[2]
        else:
            pose.position.x, pose.position.y = self.encoder.x, self.encoder.y
            pose.orientation.z, pose.orientation.w = math.sin(self.encoder.theta / 2), math.cos(self.encoder.theta / 2)
            twist.linear.x, twist.angular.z = self.encoder.linear, self.encoder.angular
        odometry.pose.covariance = ODOM_POSE_COVARIANCE
        self.odom_publisher.publish(odometry)
        if self.publish_odom_tf:
            transform = TransformStamped()
            transform.header = odometry.header
            transform.child_frame_id = self.base_frame
            transform.transform.translation.x = pose.position.x
            transform.transform.translation.y = pose.position.y
            transform.transform.translation.z = pose.position.z
            transform.transform.rotation = pose.orientation
            self.context.tf_broadcaster.send_transform(transform)

    def _publish_wheel_joint_states(self, stamp):
        # gazebo_ros lists the right wheel first and leaves velocity and effort empty.
        message = JointState()
        message.header.stamp = stamp
        message.name = [self.joints[1], self.joints[0]]
        message.position = [state[0] for state in self.context.robot.joint_state(message.name)]
        self.joint_state_publisher.publish(message)

    def reset(self, now: float):
        super().reset(now)
        self.last_update = now
        self.ramp.reset()
        if self.encoder is not None:
            self.encoder.reset()
        with self._lock:
            self._command = (0.0, 0.0)

    def close(self):
        self.subscriber.unregister()
        for publisher in (self.odom_publisher, self.joint_state_publisher):
            if publisher is not None:
                publisher.unregister()
