"""``libgazebo_ros_planar_move.so``: cmd_vel in (x, y, yaw rate); ground-truth odometry and the odom TF out."""
import rospy
from geometry_msgs.msg import Twist

from ..core.names import resolve_frame, tf_prefix
from ..core.drives.planar_move import PlanarMove
from ..core.drives.twist_drive import ODOM_POSE_COVARIANCE
from . import RosPlugin, resolve_in_namespace
from .ground_truth_odometry import OdometryOutput, on_twist


class GazeboRosPlanarMove(RosPlugin, PlanarMove):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        params = self.params
        namespace = self.robot_namespace()
        prefix = tf_prefix(context.simulation.parameters, namespace)
        odom_frame = resolve_frame(params["odometryFrame"], prefix)
        base_frame = resolve_frame(params["robotBaseFrame"], prefix)
        self.output = OdometryOutput(self.topics, resolve_in_namespace(namespace, params["odometryTopic"]),
                                     odom_frame, base_frame, ODOM_POSE_COVARIANCE, broadcast_tf=True)
        self.command_topic = resolve_in_namespace(namespace, params["commandTopic"])
        self.topics.subscriber(self.command_topic, Twist, lambda message: on_twist(self, message))
        rospy.loginfo(f"{self.label}: {self.command_topic} sets the base's velocity; odometry on "
                      f"{self.output.odom_publisher.resolved_name} at {params['odometryRate']:g} Hz, TF {odom_frame} "
                      f"-> {base_frame}")

    def update(self, now: float):
        super().update(now)
        if self.params["odometryRate"] > 0:
            self.output.publish(now, *self.latest)
