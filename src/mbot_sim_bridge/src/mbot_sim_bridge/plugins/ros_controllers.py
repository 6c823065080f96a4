"""The ROS side of the ros_controllers (``core/ros_control/``): their topics, under the controller's namespace
(``<robot namespace>/<controller name>``) as upstream's controller NodeHandle puts them.

Subscribers only store values; ``publish(stamp)`` runs in the loop thread after /clock, at the stop of the loop
where the controller is due, and sends what its updates filled into the ``outbox``, each with its own update's
stamp (the joint states, the odometry, ``cmd_vel_out``; the single-joint PID controllers' control_msgs/
JointControllerState on ``state`` every tenth update, as upstream). The trajectory and gripper controllers
serve their actions with actionlib's ActionServer: a goal's outcome found by the update goes out with the next
publish, one decided in a ROS callback (preemption, cancel) at once.
"""
import math

import actionlib
import rospy
from actionlib_msgs.msg import GoalStatus
from control_msgs.msg import (FollowJointTrajectoryAction, FollowJointTrajectoryFeedback, FollowJointTrajectoryResult,
                              GripperCommandAction, GripperCommandResult, JointControllerState,
                              JointTrajectoryControllerState)
from control_msgs.srv import QueryTrajectoryState, QueryTrajectoryStateResponse
from four_wheel_steering_msgs.msg import FourWheelSteering, FourWheelSteeringStamped
from geometry_msgs.msg import TransformStamped, Twist, TwistStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64, Float64MultiArray
from tf2_msgs.msg import TFMessage
from trajectory_msgs.msg import JointTrajectory as JointTrajectoryMessage

from ..core.ros_control.controller_table import CORE_CONTROLLERS
from ..core.ros_control.diff_drive_controller import CommandSample, TwistController
from ..core.ros_control.four_wheel_steering_controller import FourWheelSteeringController
from ..core.ros_control.gripper_action_controller import GripperActionController, GripperGoal
from ..core.ros_control.joint_state_controller import JointStateController
from ..core.ros_control.joint_trajectory_controller import (ABORTED, SUCCEEDED, JointTolerance, JointTrajectory,
                                                            JointTrajectoryController, StatePoints, TrajectoryGoal,
                                                            TrajectoryPoint)
from ..core.ros_control.pid_controllers import StateSampling
from ..subscriptions import TrackedSubscriber
from ..core.names import resolve_frame
from . import loop_publisher, resolve_in_namespace, ros_time
from .messages import diagonal_covariance

# A goal's statuses while feedback for it means something.
_GOING = (GoalStatus.ACTIVE, GoalStatus.PREEMPTING)


class RosJointStateController(JointStateController):
    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context)
        root = context.namespace.rsplit("/", 1)[0] or "/"
        self.publisher = loop_publisher(resolve_in_namespace(root, "joint_states"), JointState)

    def publish(self, stamp):
        for time, states in self.outbox:
            message = JointState()
            message.header.stamp = ros_time(time)
            message.name, message.position, message.velocity, message.effort = states
            self.publisher.publish(message)

    def close(self):
        self.publisher.unregister()


def advertise_odometry(controller, context) -> str:
    """A base controller's clock, frames, ``odom`` and /tf publishers; its namespace."""
    controller.clock = context.clock
    controller.odom_frame = resolve_frame(controller.odom_frame_id)
    controller.base_frame = resolve_frame(controller.base_frame_id)
    controller.odom_publisher = loop_publisher(context.namespace + "/odom", Odometry)
    controller.tf_publisher = loop_publisher("/tf", TFMessage)
    return context.namespace


def publish_odometry(controller, stamp, odometry, linear_x: float, linear_y: float):
    """A base controller's nav_msgs/Odometry on ``odom`` and, with ``enable_odom_tf``, the odom TF."""
    message = Odometry()
    message.header.stamp = stamp
    message.header.frame_id = controller.odom_frame
    message.child_frame_id = controller.base_frame
    pose = message.pose.pose
    pose.position.x, pose.position.y = odometry.x, odometry.y
    pose.orientation.z, pose.orientation.w = math.sin(odometry.heading / 2), math.cos(odometry.heading / 2)
    message.pose.covariance = diagonal_covariance(controller.pose_covariance, 6)
    twist = message.twist.twist
    twist.linear.x, twist.linear.y, twist.angular.z = linear_x, linear_y, odometry.angular
    message.twist.covariance = diagonal_covariance(controller.twist_covariance, 6)
    controller.odom_publisher.publish(message)
    if controller.enable_odom_tf:
        transform = TransformStamped()
        transform.header = message.header
        transform.child_frame_id = controller.base_frame
        transform.transform.translation.x, transform.transform.translation.y = odometry.x, odometry.y
        transform.transform.rotation = pose.orientation
        controller.tf_publisher.publish(TFMessage([transform]))


class RosTwistController(TwistController):
    """cmd_vel in, odom and the odom TF out (and cmd_vel_out for the diff drive's ``publish_cmd``)."""

    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context)
        namespace = advertise_odometry(self, context)
        self.cmd_publisher = loop_publisher(namespace + "/cmd_vel_out", TwistStamped) if self.publish_cmd else None
        self.subscriber = TrackedSubscriber(namespace + "/cmd_vel", Twist, self._on_command)

    def _on_command(self, message: Twist):
        complaint = self.set_command(message.linear.x, message.angular.z, self.clock(),
                                     self.subscriber.get_num_connections())
        if complaint:
            rospy.logerr_throttle(1.0, f"{self.name}: {complaint}")

    def publish(self, stamp):
        for time, sample in self.outbox:
            if isinstance(sample, CommandSample):
                message = TwistStamped()
                message.header.stamp = ros_time(time)
                message.twist.linear.x, message.twist.angular.z = sample.linear, sample.angular
                self.cmd_publisher.publish(message)
            else:
                publish_odometry(self, ros_time(time), sample, sample.linear, 0.0)

    def close(self):
        self.subscriber.unregister()
        for publisher in (self.odom_publisher, self.tf_publisher, self.cmd_publisher):
            if publisher is not None:
                publisher.unregister()


class RosFourWheelSteeringController(FourWheelSteeringController):
    """cmd_vel and cmd_four_wheel_steering in; odom, odom_steer and the odom TF out."""

    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context)
        namespace = advertise_odometry(self, context)
        self.steering_publisher = loop_publisher(namespace + "/odom_steer", FourWheelSteeringStamped)
        self.subscribers = [TrackedSubscriber(namespace + "/cmd_vel", Twist, self._on_twist),
                            TrackedSubscriber(namespace + "/cmd_four_wheel_steering", FourWheelSteering,
                                              self._on_steering)]

    def _on_twist(self, message: Twist):
        self._complain(self.set_twist(message.linear.x, message.linear.y, message.angular.z, self.clock()))

    def _on_steering(self, message: FourWheelSteering):
        self._complain(self.set_steering(message.speed, message.front_steering_angle, message.rear_steering_angle,
                                         self.clock()))

    def _complain(self, complaint):
        if complaint:
            rospy.logwarn_throttle(1.0, f"{self.name}: {complaint}")

    def publish(self, stamp):
        for time, sample in self.outbox:
            publish_odometry(self, ros_time(time), sample, sample.linear_x, sample.linear_y)
            message = FourWheelSteeringStamped()
            message.header.stamp = ros_time(time)
            message.header.frame_id = self.odom_frame
            data = message.data
            data.speed, data.acceleration, data.jerk = sample.speed, sample.acceleration, sample.jerk
            data.front_steering_angle = sample.front_steering
            data.front_steering_angle_velocity = sample.front_steering_velocity
            data.rear_steering_angle = sample.rear_steering
            data.rear_steering_angle_velocity = sample.rear_steering_velocity
            self.steering_publisher.publish(message)

    def close(self):
        for subscriber in self.subscribers:
            subscriber.unregister()
        for publisher in (self.odom_publisher, self.steering_publisher, self.tf_publisher):
            publisher.unregister()


class _CommandTopic:
    """A ``command`` subscriber: Float64 for single-joint controllers, Float64MultiArray for groups."""

    def _subscribe(self, namespace, group):
        self.state_publisher = (loop_publisher(namespace + "/state", JointControllerState)
                                if isinstance(self, StateSampling) else None)
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
        for time, sample in self.outbox:
            message = JointControllerState(**sample._asdict())
            message.header.stamp = ros_time(time)
            self.state_publisher.publish(message)

    def close(self):
        self.subscriber.unregister()
        if self.state_publisher is not None:
            self.state_publisher.unregister()


def _trajectory(message: JointTrajectoryMessage) -> JointTrajectory:
    return JointTrajectory(list(message.joint_names), [
        TrajectoryPoint(list(point.positions), list(point.velocities), list(point.accelerations),
                        point.time_from_start.to_sec()) for point in message.points], message.header.stamp.to_sec())


def _tolerances(tolerances) -> list:
    return [JointTolerance(tolerance.name, tolerance.position, tolerance.velocity, tolerance.acceleration)
            for tolerance in tolerances]


class _ActionController:
    """The action side shared by the trajectory and gripper controllers: an actionlib ActionServer on
    ``<controller>/<action>`` whose goals' outcomes (the core's ``ended``) are sent by ``_send_ended``."""

    def _serve(self, namespace: str, action: str, action_type):
        self.server = actionlib.ActionServer(namespace + "/" + action, action_type, self._on_goal, self._on_cancel,
                                             auto_start=False)
        self.server.start()

    def _send_ended(self):
        with self.lock:
            ended, self.ended = self.ended, []
        for end in ended:
            handle = end.goal.handle
            if end.status == SUCCEEDED:
                handle.set_succeeded(self._result(end))
            elif end.status == ABORTED:
                handle.set_aborted(self._result(end))
            else:
                handle.set_canceled()

    def _on_cancel(self, handle):
        with self.lock:
            active = self.active_goal
            if active is not None and active.handle == handle:
                self.cancel_goal(active)
        self._send_ended()

    def stopping(self, now):
        super().stopping(now)
        self._send_ended()

    def close(self):
        self.server.stop()


class RosJointTrajectoryController(_ActionController, JointTrajectoryController):
    """``command`` (trajectory_msgs/JointTrajectory), ``state`` (control_msgs/JointTrajectoryControllerState),
    ``query_state`` and the ``follow_joint_trajectory`` action, with feedback at action_monitor_rate."""

    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context)
        namespace = context.namespace
        self.state_publisher = loop_publisher(namespace + "/state", JointTrajectoryControllerState)
        self.subscriber = TrackedSubscriber(namespace + "/command", JointTrajectoryMessage, self._on_command)
        self.query_service = rospy.Service(namespace + "/query_state", QueryTrajectoryState, self._on_query)
        self._serve(namespace, "follow_joint_trajectory", FollowJointTrajectoryAction)

    def _on_command(self, message):
        self.command(_trajectory(message))
        self._send_ended()

    def _on_goal(self, handle):
        goal = handle.get_goal()
        accepted, error_code, error_string = self.accept_goal(TrajectoryGoal(
            _trajectory(goal.trajectory), _tolerances(goal.path_tolerance), _tolerances(goal.goal_tolerance),
            goal.goal_time_tolerance.to_sec(), handle))
        if not accepted:
            handle.set_rejected(FollowJointTrajectoryResult(error_code=error_code, error_string=error_string))
            return
        self._send_ended()  # the goal it preempted, first
        handle.set_accepted()

    @staticmethod
    def _result(end):
        return FollowJointTrajectoryResult(error_code=end.error_code, error_string=end.error_string)

    def _on_query(self, request):
        sampled = self.query_state(request.time.to_sec())
        if sampled is None:
            raise rospy.ServiceException("the trajectory cannot be sampled at that time (see the simulator's log)")
        return QueryTrajectoryStateResponse(list(self.joint_names), *sampled)

    def _fill(self, message, stamp, points: StatePoints):
        """The header and the desired, actual and error points of a state or feedback message."""
        message.header.stamp = stamp
        message.joint_names = list(self.joint_names)
        desired_from_start, actual_from_start, error_from_start = points.times_from_start
        message.desired.positions, message.desired.velocities, message.desired.accelerations = points.desired
        message.desired.time_from_start = rospy.Duration.from_sec(desired_from_start)
        message.actual.positions, message.actual.velocities = points.actual
        message.actual.time_from_start = rospy.Duration.from_sec(actual_from_start)
        message.error.positions, message.error.velocities = points.error[:2]
        message.error.time_from_start = rospy.Duration.from_sec(error_from_start)
        return message

    def publish(self, stamp):
        for time, points in self.outbox:
            if points.goal is None:
                self.state_publisher.publish(self._fill(JointTrajectoryControllerState(), ros_time(time), points))
            elif points.goal.handle.get_goal_status().status in _GOING:  # its result may have gone out since
                points.goal.handle.publish_feedback(self._fill(FollowJointTrajectoryFeedback(), ros_time(time),
                                                               points))
        self._send_ended()

    def close(self):
        super().close()
        self.subscriber.unregister()
        self.state_publisher.unregister()
        self.query_service.shutdown()


class RosGripperActionController(_ActionController, GripperActionController):
    """The ``gripper_cmd`` action (control_msgs/GripperCommand)."""

    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context)
        self._serve(context.namespace, "gripper_cmd", GripperCommandAction)

    def _on_goal(self, handle):
        command = handle.get_goal().command
        goal = GripperGoal(command.position, command.max_effort, handle)
        if not self.accept_goal(goal):
            handle.set_rejected(GripperCommandResult())
            return
        self._send_ended()
        handle.set_accepted()

    @staticmethod
    def _result(end):
        return GripperCommandResult(position=end.position, effort=end.effort, stalled=end.stalled,
                                    reached_goal=end.reached_goal)

    def publish(self, stamp):
        self._send_ended()


def _ros_class(core_class: type) -> type:
    """The ROS class of a command controller: the core class plus its ``command`` subscriber."""
    def __init__(self, name, hw, params, context):
        core_class.__init__(self, name, hw, params, context)
        self._subscribe(context.namespace, hasattr(self, "set_commands"))
    return type("Ros" + core_class.__name__, (_CommandTopic, core_class), {"__init__": __init__})


def _ros_controller(core_class: type) -> type:
    for core_base, ros_class in ((JointStateController, RosJointStateController),
                                 (TwistController, RosTwistController),
                                 (FourWheelSteeringController, RosFourWheelSteeringController),
                                 (JointTrajectoryController, RosJointTrajectoryController),
                                 (GripperActionController, RosGripperActionController)):
        if core_class is core_base:
            return ros_class
        if issubclass(core_class, core_base):  # a per-interface core class: its INTERFACE under the ROS class
            return type("Ros" + core_class.__name__, (ros_class, core_class), {})
    return _ros_class(core_class)


ROS_CONTROLLERS = {controller_type: _ros_controller(core_class)
                   for controller_type, core_class in CORE_CONTROLLERS.items()}
