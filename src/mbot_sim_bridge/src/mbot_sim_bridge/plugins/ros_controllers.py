"""The ROS side of the ros_controllers (``core/controllers.py``): their topics, under the controller's namespace
(``<robot namespace>/<controller name>``) as upstream's controller NodeHandle puts them.

Subscribers only store values; ``publish(stamp)`` runs in the loop thread after /clock. The single-joint PID
controllers publish control_msgs/JointControllerState on ``state`` every tenth update, as upstream.
"""
import math

import rospy
from control_msgs.msg import JointControllerState
from geometry_msgs.msg import TransformStamped, Twist, TwistStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64, Float64MultiArray
from tf2_msgs.msg import TFMessage

from ..core.ros_control import CORE_CONTROLLERS
from ..core.ros_control.diff_drive_controller import DiffDriveController
from ..core.ros_control.joint_state_controller import JointStateController
from ..subscriptions import TrackedSubscriber
from ..core.names import resolve_frame
from . import loop_publisher, resolve_in_namespace
from .messages import diagonal_covariance


class RosJointStateController(JointStateController):
    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context)
        root = context.namespace.rsplit("/", 1)[0] or "/"
        self.publisher = loop_publisher(resolve_in_namespace(root, "joint_states"), JointState)

    def publish(self, stamp):
        message = JointState()
        message.header.stamp = stamp
        message.name, message.position, message.velocity, message.effort = self.states()
        self.publisher.publish(message)

    def close(self):
        self.publisher.unregister()


class RosDiffDriveController(DiffDriveController):
    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context)
        self.clock = context.clock
        namespace = context.namespace
        self.odom_frame, self.base_frame = resolve_frame(self.odom_frame_id), resolve_frame(self.base_frame_id)
        self.odom_publisher = loop_publisher(namespace + "/odom", Odometry)
        self.tf_publisher = loop_publisher("/tf", TFMessage)
        self.cmd_publisher = loop_publisher(namespace + "/cmd_vel_out", TwistStamped) if self.publish_cmd else None
        self._cmd_pending = self._odometry_due = False
        self.subscriber = TrackedSubscriber(namespace + "/cmd_vel", Twist, self._on_command)

    def _on_command(self, message: Twist):
        complaint = self.set_command(message.linear.x, message.angular.z, self.clock(),
                                     self.subscriber.get_num_connections())
        if complaint:
            rospy.logerr_throttle(1.0, f"{self.name}: {complaint}")

    def update(self, now, period):
        super().update(now, period)
        self._cmd_pending = self.cmd_publisher is not None

    def publish_due(self, now):
        # cmd_vel_out goes out on every control cycle, as upstream; the odometry at publish_rate.
        odometry_due = super().publish_due(now)
        self._odometry_due = odometry_due
        return odometry_due or self._cmd_pending

    def publish(self, stamp):
        if self._cmd_pending:
            self._cmd_pending = False
            message = TwistStamped()
            message.header.stamp = stamp
            message.twist.linear.x, message.twist.angular.z = self.limited
            self.cmd_publisher.publish(message)
        if not self._odometry_due:
            return
        odometry = self.odometry
        message = Odometry()
        message.header.stamp = stamp
        message.header.frame_id = self.odom_frame
        message.child_frame_id = self.base_frame
        pose = message.pose.pose
        pose.position.x, pose.position.y = odometry.x, odometry.y
        pose.orientation.z, pose.orientation.w = math.sin(odometry.heading / 2), math.cos(odometry.heading / 2)
        message.pose.covariance = diagonal_covariance(self.pose_covariance, 6)
        message.twist.twist.linear.x, message.twist.twist.angular.z = odometry.linear, odometry.angular
        message.twist.covariance = diagonal_covariance(self.twist_covariance, 6)
        self.odom_publisher.publish(message)
        if self.enable_odom_tf:
            transform = TransformStamped()
            transform.header = message.header
            transform.child_frame_id = self.base_frame
            transform.transform.translation.x, transform.transform.translation.y = odometry.x, odometry.y
            transform.transform.rotation = pose.orientation
            self.tf_publisher.publish(TFMessage([transform]))

    def close(self):
        self.subscriber.unregister()
        for publisher in (self.odom_publisher, self.tf_publisher, self.cmd_publisher):
            if publisher is not None:
                publisher.unregister()


class _CommandTopic:
    """A ``command`` subscriber: Float64 for single-joint controllers, Float64MultiArray for groups."""

    def _subscribe(self, namespace, group):
        self.state_publisher = (loop_publisher(namespace + "/state", JointControllerState)
                                if hasattr(self, "state_sample") else None)
        message_type = Float64MultiArray if group else Float64
        self.subscriber = TrackedSubscriber(namespace + "/command", message_type, self._on_command)

    def _on_command(self, message):
        if isinstance(message, Float64):
            self.set_command(message.data)
            return
        complaint = self.set_commands(list(message.data))
        if complaint:
            rospy.logerr(complaint)

    def publish(self, stamp):
        message = JointControllerState(**self.state_sample._asdict())
        message.header.stamp = stamp
        self.state_sample = None
        self.state_publisher.publish(message)

    def close(self):
        self.subscriber.unregister()
        if self.state_publisher is not None:
            self.state_publisher.unregister()


def _ros_class(core_class: type) -> type:
    """The ROS class of a command controller: the core class plus its ``command`` subscriber."""
    def __init__(self, name, hw, params, context):
        core_class.__init__(self, name, hw, params, context)
        self._subscribe(context.namespace, hasattr(self, "set_commands"))
    return type("Ros" + core_class.__name__, (_CommandTopic, core_class), {"__init__": __init__})


ROS_CONTROLLERS = {
    controller_type: {JointStateController: RosJointStateController,
                      DiffDriveController: RosDiffDriveController}.get(core_class) or _ros_class(core_class)
    for controller_type, core_class in CORE_CONTROLLERS.items()
}
