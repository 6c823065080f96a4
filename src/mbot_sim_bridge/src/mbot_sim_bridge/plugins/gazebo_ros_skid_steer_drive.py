"""``libgazebo_ros_skid_steer_drive.so``: cmd_vel in; ground-truth odometry (and, with broadcastTF, the odom TF)
out."""
import rospy
from geometry_msgs.msg import Twist

from ..core.names import resolve_frame, tf_prefix
from ..core.drives.skid_steer_drive import SkidSteerDrive
from . import RosPlugin, resolve_in_namespace
from .messages import diagonal_covariance
from .ground_truth_odometry import OdometryOutput, on_twist


class GazeboRosSkidSteerDrive(RosPlugin, SkidSteerDrive):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        params = self.params
        namespace = self.robot_namespace()
        prefix = tf_prefix(context.simulation.parameters, namespace)
        covariance = diagonal_covariance((params["covariance_x"], params["covariance_y"], 1e12, 1e12, 1e12,
                                          params["covariance_yaw"]), 6)
        self.output = OdometryOutput(self.topics, resolve_in_namespace(namespace, params["odometryTopic"]),
                                     resolve_frame(params["odometryFrame"], prefix),
                                     resolve_frame(params["robotBaseFrame"], prefix), covariance,
                                     params["broadcastTF"], twist_covariance=covariance)
        self.command_topic = resolve_in_namespace(namespace, params["commandTopic"])
        self.topics.subscriber(self.command_topic, Twist, lambda message: on_twist(self, message))
        rospy.loginfo(f"{self.label}: {self.command_topic} -> wheels {', '.join(self.joints)}, separation "
                      f"{params['wheelSeparation']:.3f} m, diameter {params['wheelDiameter']:.3f} m, torque "
                      f"{params['torque']:.1f} N·m; odometry on {self.output.odom_publisher.resolved_name} at "
                      f"{params['updateRate']:g} Hz")

    def update(self, now: float):
        super().update(now)
        self.output.publish(now, *self.latest)
