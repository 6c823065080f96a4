"""``libgazebo_ros_planar_move.so``: cmd_vel in (x, y, yaw rate); ground-truth odometry and the odom TF out."""
import rospy
from geometry_msgs.msg import TransformStamped, Twist
from nav_msgs.msg import Odometry
from tf2_msgs.msg import TFMessage

from ..core.diff_drive import ODOM_POSE_COVARIANCE
from ..core.names import resolve_frame, tf_prefix
from ..core.planar_move import PlanarMove
from ..subscriptions import TrackedSubscriber
from . import RosPlugin, resolve_in_namespace, ros_time
from .messages import set_pose, set_quaternion, set_xyz


class GazeboRosPlanarMove(RosPlugin, PlanarMove):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        params = self.params
        namespace = self.robot_namespace()
        prefix = tf_prefix(context.simulation.parameters, namespace)
        odom_frame = resolve_frame(params["odometryFrame"], prefix)
        base_frame = resolve_frame(params["robotBaseFrame"], prefix)
        self.odom_publisher = self.topics.publisher(resolve_in_namespace(namespace, params["odometryTopic"]),
                                                    Odometry)
        self.tf_publisher = self.topics.publisher("/tf", TFMessage)
        self.command_topic = resolve_in_namespace(namespace, params["commandTopic"])
        self.topics.own(TrackedSubscriber(self.command_topic, Twist, self._on_command))
        self.odometry = Odometry()
        self.odometry.header.frame_id, self.odometry.child_frame_id = odom_frame, base_frame
        self.odometry.pose.covariance = ODOM_POSE_COVARIANCE
        transform = TransformStamped()
        transform.header.frame_id, transform.child_frame_id = odom_frame, base_frame
        self.tf_message = TFMessage([transform])
        rospy.loginfo(f"{self.label}: {self.command_topic} sets the base's velocity; odometry on "
                      f"{self.odom_publisher.resolved_name} at {params['odometryRate']:g} Hz, TF {odom_frame} -> "
                      f"{base_frame}")

    def _on_command(self, message: Twist):
        x, y, rotation = message.linear.x, message.linear.y, message.angular.z
        if not self.set_command(x, y, rotation):
            rospy.logwarn_throttle(5.0, f"{self.label}: ignored a {self.command_topic} with a non-finite value "
                                        f"(linear {x}, {y}, angular.z {rotation}); keeping the last valid command")

    def update(self, now: float):
        super().update(now)
        if self.params["odometryRate"] <= 0:
            return
        stamp = ros_time(now)
        odometry = self.latest
        if self.topics.listened(self.odom_publisher):
            message = self.odometry
            message.header.stamp = stamp
            set_pose(message.pose.pose, odometry.pose.position, odometry.pose.orientation)
            twist = message.twist.twist
            twist.linear.x, twist.linear.y = odometry.linear
            twist.angular.z = odometry.angular
            self.odom_publisher.publish(message)
        if self.topics.listened(self.tf_publisher):
            transform = self.tf_message.transforms[0]
            transform.header.stamp = stamp
            set_xyz(transform.transform.translation, odometry.pose.position)
            set_quaternion(transform.transform.rotation, odometry.pose.orientation)
            self.tf_publisher.publish(self.tf_message)
