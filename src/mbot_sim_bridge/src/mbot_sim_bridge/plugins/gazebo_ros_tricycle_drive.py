"""``libgazebo_ros_tricycle_drive.so``: cmd_vel in (linear.x wheel speed, angular.z steering angle); odometry and the
odom TF out, and with publishWheelJointState the four joints' joint_states."""
import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import JointState

from ..core.names import resolve_frame, tf_prefix
from ..core.drives.tricycle_drive import TricycleDrive
from ..core.drives.twist_drive import ODOM_POSE_COVARIANCE
from . import RosPlugin, resolve_in_namespace, ros_time
from .ground_truth_odometry import OdometryOutput, on_twist


class GazeboRosTricycleDrive(RosPlugin, TricycleDrive):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        params = self.params
        namespace = self.robot_namespace()
        prefix = tf_prefix(context.simulation.parameters, namespace)
        self.output = OdometryOutput(self.topics, resolve_in_namespace(namespace, params["odometryTopic"]),
                                     resolve_frame(params["odometryFrame"], prefix),
                                     resolve_frame(params["robotBaseFrame"], prefix), ODOM_POSE_COVARIANCE,
                                     broadcast_tf=True)
        self.joint_state_publisher = (self.topics.publisher(resolve_in_namespace(namespace, "joint_states"),
                                                            JointState)
                                      if params["publishWheelJointState"] else None)
        self.command_topic = resolve_in_namespace(namespace, params["commandTopic"])
        self.topics.subscriber(self.command_topic, Twist, lambda message: on_twist(self, message))
        if params["publishWheelTF"]:
            rospy.loginfo(f"{self.label}: publishWheelTF: the joints' frames reach /tf through robot_state_publisher "
                          "from joint_states; they are not broadcast a second time")
        rospy.loginfo(f"{self.label}: {self.command_topic} -> wheel {self.wheel_joint} (linear.x), steering "
                      f"{self.steering_joint} (angular.z as the angle); {params['odometrySource']} odometry on "
                      f"{self.output.odom_publisher.resolved_name} at {params['updateRate']:g} Hz")

    def update(self, now: float):
        super().update(now)
        self.output.publish(now, *self.latest)
        if self.topics.listened(self.joint_state_publisher):
            message = JointState()
            message.header.stamp = ros_time(now)
            message.name = list(self.joints)
            message.position, message.velocity, message.effort = (
                list(values) for values in zip(*self.context.robot.joint_state(self.joints)))
            self.joint_state_publisher.publish(message)
