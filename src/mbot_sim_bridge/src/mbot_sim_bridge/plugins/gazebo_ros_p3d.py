"""``libgazebo_ros_p3d.so``: ground-truth nav_msgs/Odometry of a link."""
import rospy
from nav_msgs.msg import Odometry

from ..core.sensors.p3d import P3D
from . import RosPlugin, resolve_in_namespace, ros_time
from .messages import diagonal_covariance, set_pose, set_xyz


class GazeboRosP3D(RosPlugin, P3D):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        namespace = self.robot_namespace()
        self.publisher = self.topics.publisher(resolve_in_namespace(namespace, self.params["topicName"]), Odometry)
        rate = f"at {self.params['updateRate']:g} Hz" if self.params["updateRate"] else "at every physics step"
        rospy.loginfo(f"{self.label}: link '{self.body}' -> {self.publisher.resolved_name} in frame "
                      f"'{self.frame_name}' {rate}")

    def update(self, now: float):
        if self.nobody_listens(now, self.publisher):
            return
        super().update(now)
        truth = self.latest
        message = Odometry()
        message.header.stamp = ros_time(now)
        message.header.frame_id = self.frame_name
        message.child_frame_id = self.child_frame
        set_pose(message.pose.pose, truth.pose.position, truth.pose.orientation)
        set_xyz(message.twist.twist.linear, truth.linear)
        set_xyz(message.twist.twist.angular, truth.angular)
        message.pose.covariance = message.twist.covariance = diagonal_covariance(truth.covariance, 6)
        self.publisher.publish(message)
