"""What the drives' ROS sides share: cmd_vel into the core's TwistCommand, and the odometry topic and odom TF of
the drive plugins that report the ground truth (planar move, skid steer, tricycle): messages made once and
refilled, each published only while someone listens."""
import math
from operator import attrgetter
from typing import Optional

import rospy
from geometry_msgs.msg import TransformStamped, Twist
from nav_msgs.msg import Odometry
from tf2_msgs.msg import TFMessage

from . import PluginTopics, ros_time
from .messages import set_pose, set_quaternion, set_xyz


def on_twist(plugin, message: Twist):
    """cmd_vel to a TwistCommand drive (the axes it reads); one that is not finite or beyond the drive's
    COMMAND_LIMIT is refused with a throttled warning."""
    values = [attrgetter(axis)(message) for axis in plugin.COMMAND_AXES]
    if not plugin.set_command(*values):
        given = ", ".join(f"{axis} {value}" for axis, value in zip(plugin.COMMAND_AXES, values))
        beyond = f" or one beyond {plugin.COMMAND_LIMIT:g}" if math.isfinite(plugin.COMMAND_LIMIT) else ""
        rospy.logwarn_throttle(5.0, f"{plugin.label}: ignored a {plugin.command_topic} with a non-finite "
                                    f"value{beyond} ({given}); keeping the last valid command")


class OdometryOutput:
    def __init__(self, topics: PluginTopics, topic: str, odom_frame: str, base_frame: str, covariance,
                 broadcast_tf: bool, twist_covariance: Optional[list] = None):
        self.topics = topics
        self.odom_publisher = topics.publisher(topic, Odometry)
        self.tf_publisher = topics.publisher("/tf", TFMessage) if broadcast_tf else None
        self.odometry = Odometry()
        self.odometry.header.frame_id, self.odometry.child_frame_id = odom_frame, base_frame
        self.odometry.pose.covariance = covariance
        if twist_covariance is not None:
            self.odometry.twist.covariance = twist_covariance
        transform = TransformStamped()
        transform.header.frame_id, transform.child_frame_id = odom_frame, base_frame
        self.tf_message = TFMessage([transform])

    def publish(self, now: float, pose, linear, angular: float):
        """``linear``: (x, y) in the base frame."""
        stamp = ros_time(now)
        if self.topics.listened(self.odom_publisher):
            message = self.odometry
            message.header.stamp = stamp
            set_pose(message.pose.pose, pose.position, pose.orientation)
            twist = message.twist.twist
            twist.linear.x, twist.linear.y = linear
            twist.angular.z = angular
            self.odom_publisher.publish(message)
        if self.topics.listened(self.tf_publisher):
            transform = self.tf_message.transforms[0]
            transform.header.stamp = stamp
            set_xyz(transform.transform.translation, pose.position)
            set_quaternion(transform.transform.rotation, pose.orientation)
            self.tf_publisher.publish(self.tf_message)
