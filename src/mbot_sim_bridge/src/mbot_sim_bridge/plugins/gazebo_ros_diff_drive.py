"""``libgazebo_ros_diff_drive.so``: cmd_vel in; odometry, odom TF and wheel joint states out."""
import rospy
from geometry_msgs.msg import TransformStamped, Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage

from ..core.drives.diff_drive import DiffDrive
from ..core.drives.twist_drive import ODOM_POSE_COVARIANCE
from ..core.names import resolve_frame, tf_prefix
from . import RosPlugin, resolve_in_namespace, ros_time
from .ground_truth_odometry import on_twist
from .messages import set_pose, set_quaternion, set_xyz


class GazeboRosDiffDrive(RosPlugin, DiffDrive):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        params = self.params
        prefix = tf_prefix(self.context.simulation.parameters, self.namespace)
        self.odom_frame = resolve_frame(params["odometryFrame"], prefix)
        self.base_frame = resolve_frame(params["robotBaseFrame"], prefix)
        self.publish_odom_tf = params["publishTf"] and params["publishOdomTF"]
        # publishTf=false means no odometry topic at all, not just no TF (gazebo_ros reads it that way).
        topics = self.topics
        self.odom_publisher = (topics.publisher(resolve_in_namespace(self.namespace, params["odometryTopic"]),
                                                Odometry) if params["publishTf"] else None)
        self.tf_publisher = topics.publisher("/tf", TFMessage) if self.publish_odom_tf else None
        self.joint_state_publisher = (topics.publisher(resolve_in_namespace(self.namespace, "joint_states"),
                                                       JointState) if self.joint_states_published else None)
        self._make_messages()
        self.command_topic = resolve_in_namespace(self.namespace, params["commandTopic"])
        topics.subscriber(self.command_topic, Twist, lambda message: on_twist(self, message))
        if params["publishWheelTF"]:
            rospy.loginfo(f"{self.label}: publishWheelTF: the wheel frames reach /tf through robot_state_publisher "
                          "from joint_states; they are not broadcast a second time (that duplicate is what makes "
                          "Gazebo's wheels jump in rviz, gazebo_ros_pkgs#1524)")
        odometry = self.odom_publisher.resolved_name if self.odom_publisher else "(none: publishTf false)"
        rospy.loginfo(f"{self.label}: {self.command_topic} -> wheels {self.joints[0]}/{self.joints[1]}, separation "
                      f"{self.geometry.wheel_separation:.3f} m, diameter {2 * self.geometry.wheel_radius:.3f} m, "
                      f"torque {self.torque:.1f} N·m, acceleration {self.ramp.acceleration:.2f} m/s², "
                      f"{params['odometrySource']} odometry on {odometry} at {params['updateRate']:.0f} Hz, legacyMode "
                      f"{self.geometry.legacy_mode}")

    def update(self, now: float):
        # Topics nobody listens to are skipped: the loop publishes synchronously, so each costs real time.
        stamp = ros_time(now)
        odometry_wanted = self.topics.listened(self.odom_publisher)
        tf_wanted = self.topics.listened(self.tf_publisher)
        if odometry_wanted or tf_wanted:
            odometry = self.odometry()
            if odometry_wanted:
                self._publish_odometry(stamp, odometry)
            if tf_wanted:
                self._publish_odom_tf(stamp, odometry)
        if self.topics.listened(self.joint_state_publisher):
            self._publish_wheel_joint_states(stamp)
        super().update(now)

    def _make_messages(self):
        """The messages, built once and refilled at each update: building a genpy message costs more than
        filling it."""
        self.odometry_message = Odometry()
        self.odometry_message.header.frame_id = self.odom_frame
        self.odometry_message.child_frame_id = self.base_frame
        self.odometry_message.pose.covariance = ODOM_POSE_COVARIANCE
        transform = TransformStamped()
        transform.header.frame_id = self.odom_frame
        transform.child_frame_id = self.base_frame
        self.tf_message = TFMessage([transform])
        # gazebo_ros lists the right wheel first and leaves velocity and effort empty.
        self.wheel_states = JointState()
        self.wheel_states.name = [self.joints[1], self.joints[0]]

    def _publish_odometry(self, stamp, odometry_values):
        (position, orientation), (vx, vy), wz = odometry_values
        odometry = self.odometry_message
        odometry.header.stamp = stamp
        set_pose(odometry.pose.pose, position, orientation)
        twist = odometry.twist.twist
        twist.linear.x, twist.linear.y, twist.angular.z = vx, vy, wz
        self.odom_publisher.publish(odometry)

    def _publish_odom_tf(self, stamp, odometry_values):
        (position, orientation), _, _ = odometry_values
        transform = self.tf_message.transforms[0]
        transform.header.stamp = stamp
        set_xyz(transform.transform.translation, position)
        set_quaternion(transform.transform.rotation, orientation)
        self.tf_publisher.publish(self.tf_message)

    def _publish_wheel_joint_states(self, stamp):
        self.wheel_states.header.stamp = stamp
        self.wheel_states.position = [state[0] for state in self.context.robot.joint_state(self.wheel_states.name)]
        self.joint_state_publisher.publish(self.wheel_states)
