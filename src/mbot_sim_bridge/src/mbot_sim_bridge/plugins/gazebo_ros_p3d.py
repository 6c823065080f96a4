"""``libgazebo_ros_p3d.so``: ground-truth nav_msgs/Odometry of a link."""
import rospy
from nav_msgs.msg import Odometry

from ..core.p3d import P3D
from . import loop_publisher, resolve_in_namespace, ros_time


class GazeboRosP3D(P3D):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        namespace = self.robot_namespace()
        self.publisher = loop_publisher(resolve_in_namespace(namespace, self.params["topicName"]), Odometry)
        rate = f"at {self.params['updateRate']:g} Hz" if self.params["updateRate"] else "at every physics step"
        rospy.loginfo(f"{self.label}: link '{self.body}' -> {self.publisher.resolved_name} in frame "
                      f"'{self.frame_name}' {rate}")

    def update(self, now: float):
        listened = self.publisher.get_num_connections() > 0
        self.idle(not listened)
        if not listened:
            return
        super().update(now)
        truth = self.latest
        message = Odometry()
        message.header.stamp = ros_time(now)
        message.header.frame_id = self.frame_name
        message.child_frame_id = self.child_frame
        pose, twist = message.pose.pose, message.twist.twist
        pose.position.x, pose.position.y, pose.position.z = truth.pose.position
        o = pose.orientation
        o.x, o.y, o.z, o.w = truth.pose.orientation
        twist.linear.x, twist.linear.y, twist.linear.z = truth.linear
        twist.angular.x, twist.angular.y, twist.angular.z = truth.angular
        covariance = [0.0] * 36
        covariance[0::7] = [truth.covariance] * 6
        message.pose.covariance = message.twist.covariance = covariance
        self.publisher.publish(message)

    def close(self):
        self.publisher.unregister()
