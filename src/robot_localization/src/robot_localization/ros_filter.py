"""ekf_localization_node's ROS side: parameters, subscribers, the periodic update on a timer, odometry/filtered,
accel/filtered, set_pose (topic and service) and the world_frame -> base_link transform. The filter and the
mapping of sensor data onto it live in the ROS-free ``estimator`` and ``ekf`` modules; this file converts
messages and looks transforms up in tf2."""
import threading

import numpy as np
import rospy
import tf2_ros
from geometry_msgs.msg import AccelWithCovarianceStamped, PoseWithCovarianceStamped, TransformStamped
from geometry_msgs.msg import TwistWithCovarianceStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu

from robot_localization.srv import SetPose, SetPoseResponse

from .ekf import AX, AZ, ROLL, VX, VYAW, YAW
from .estimator import Estimator, ImuInput, PoseInput, TwistInput
from .geometry import Transform, matrix_rpy, quaternion_matrix, rpy_quaternion
from .params import read_config


def vector(message):
    return np.array([message.x, message.y, message.z], dtype=float)


def quaternion(message):
    return np.array([message.x, message.y, message.z, message.w], dtype=float)


def matrix(values, size):
    return np.array(values, dtype=float).reshape(size, size)


def pose_input(header, pose):
    return PoseInput(header.stamp.to_sec(), header.frame_id, vector(pose.pose.position),
                     quaternion(pose.pose.orientation), matrix(pose.covariance, 6))


def twist_input(header, frame, twist):
    return TwistInput(header.stamp.to_sec(), frame, vector(twist.twist.linear), vector(twist.twist.angular),
                      matrix(twist.covariance, 6))


def transform_message(stamp, parent, child, transform):
    message = TransformStamped()
    message.header.stamp, message.header.frame_id, message.child_frame_id = stamp, parent, child
    t, q = message.transform.translation, message.transform.rotation
    t.x, t.y, t.z = transform.translation
    q.x, q.y, q.z, q.w = rpy_quaternion(*matrix_rpy(transform.rotation))
    return message


class RosFilter:
    def __init__(self):
        self.warned = set()
        self.config, problems = read_config(rospy.get_param("~", {}))
        for level, line in problems:
            (rospy.logerr if level == "error" else rospy.logwarn)(line)
        config = self.config
        if rospy.has_param("~print_diagnostics") and config.print_diagnostics:
            rospy.logwarn("~print_diagnostics: /diagnostics is not published; configuration and data problems are "
                          "logged instead")
        self.lock = threading.Lock()
        self.tf_buffer = tf2_ros.Buffer()
        self.tf_listener = tf2_ros.TransformListener(self.tf_buffer)
        self.tf_broadcaster = tf2_ros.TransformBroadcaster()
        self.estimator = Estimator(self.lookup, self.warn_once, config.frames, config.two_d_mode,
                                   config.gravitational_acceleration, config.predict_to_current_time,
                                   {sensor.name: rospy.resolve_name(sensor.topic) for sensor in config.sensors})
        ekf = self.estimator.filter
        ekf.process_noise = config.process_noise_covariance
        ekf.sensor_timeout = config.sensor_timeout
        ekf.dynamic_process_noise = config.dynamic_process_noise_covariance
        if config.initial_state is not None:
            ekf.state = config.initial_state.copy()
        if config.initial_estimate_covariance is not None:
            ekf.covariance = config.initial_estimate_covariance.copy()
        ekf.last_measurement_time = rospy.Time.now().to_sec()
        self.estimator.history_length = config.history_length
        self.last_published_stamp = None
        self.odometry_publisher = rospy.Publisher("odometry/filtered", Odometry, queue_size=20)
        self.accel_publisher = (rospy.Publisher("accel/filtered", AccelWithCovarianceStamped, queue_size=20)
                                if config.publish_acceleration else None)
        self.subscribers = [rospy.Subscriber("set_pose", PoseWithCovarianceStamped, self.set_pose, queue_size=1)]
        self.set_pose_service = rospy.Service("set_pose", SetPose, self.set_pose_service_call)
        for sensor in config.sensors:
            self.subscribe(sensor)
        self.timer = rospy.Timer(rospy.Duration(1.0 / config.frequency), self.periodic_update)

    def warn_once(self, key, line):
        if key not in self.warned:
            self.warned.add(key)
            rospy.logwarn(line)

    def lookup(self, target, source, stamp):
        """RosFilterUtilities::lookupTransformSafe: at the data's time, else the latest, else the identity if
        both frames are the same."""
        if target == source:
            return Transform()
        timeout = rospy.Duration(self.config.transform_timeout)
        try:
            message = self.tf_buffer.lookup_transform(target, source, rospy.Time.from_sec(stamp), timeout)
        except tf2_ros.TransformException:
            try:
                message = self.tf_buffer.lookup_transform(target, source, rospy.Time(0))
                rospy.logwarn_throttle(2.0, f"Transform from {source} to {target} was unavailable for the time "
                                       "requested. Using latest instead.")
            except tf2_ros.TransformException as error:
                rospy.logwarn_throttle(2.0, f"Could not obtain transform from {source} to {target}. Error was "
                                       f"{error}")
                return None
        transform = message.transform
        return Transform(quaternion_matrix(quaternion(transform.rotation)), vector(transform.translation))

    def subscribe(self, sensor):
        sources = sensor.sources
        options = dict(queue_size=sensor.queue_size, tcp_nodelay=sensor.nodelay)
        if not any(source.update.any() for source in sources.values()):
            return
        if sensor.kind == "odom":
            def callback(message):
                self.locked(self.estimator.odometry, pose_input(message.header, message.pose),
                            twist_input(message.header, message.child_frame_id, message.twist),
                            sources["pose"], sources["twist"])
            message_type = Odometry
        elif sensor.kind == "imu":
            def callback(message):
                imu = ImuInput(message.header.stamp.to_sec(), message.header.frame_id, quaternion(message.orientation),
                               matrix(message.orientation_covariance, 3), vector(message.angular_velocity),
                               matrix(message.angular_velocity_covariance, 3), vector(message.linear_acceleration),
                               matrix(message.linear_acceleration_covariance, 3))
                self.locked(self.estimator.imu, imu, sources["pose"], sources["twist"], sources["acceleration"])
            message_type = Imu
        elif sensor.kind == "pose":
            def callback(message):
                self.locked(self.estimator.pose, pose_input(message.header, message.pose), sources["pose"])
            message_type = PoseWithCovarianceStamped
        else:
            def callback(message):
                self.locked(self.estimator.twist, twist_input(message.header, message.header.frame_id,
                                                              message.twist), sources["twist"])
            message_type = TwistWithCovarianceStamped
        self.subscribers.append(rospy.Subscriber(sensor.topic, message_type, callback, **options))

    def locked(self, function, *args):
        """An input's callback under the lock, with the clock its stamp is checked against (none under sim time
        before the first /clock, when ROS time reads 0)."""
        now = rospy.Time.now().to_sec()
        with self.lock:
            function(*args, now=now if now > 0 else None)

    def set_pose(self, message):
        rospy.loginfo(f"Received set_pose request with value\n{message}")
        with self.lock:
            accepted = self.estimator.set_pose(pose_input(message.header, message.pose), rospy.Time.now().to_sec())
        if not accepted:
            self.warn_once("set_pose", "set_pose: a pose or covariance with NaN, inf or huge values was refused; "
                           "the estimate is unchanged")

    def set_pose_service_call(self, request):
        self.set_pose(request.pose)
        return SetPoseResponse()

    def periodic_update(self, event):
        now = rospy.Time.now()
        with self.lock:
            self.estimator.integrate(now.to_sec())
            self.estimator.differentiate(now.to_sec())
            for topic, reason in self.estimator.filter.take_rejections():
                if reason == "outlier":
                    rospy.logdebug(f"{topic}: a measurement beyond its rejection threshold was left out")
                    continue
                self.warn_once(f"{topic}_{reason}", REJECTIONS[reason].format(topic=topic))
            odometry = self.odometry_message()
            accel = self.accel_message() if self.accel_publisher else None
        if odometry is None:
            return
        stamp = odometry.header.stamp
        if self.last_published_stamp is not None and self.last_published_stamp >= stamp:
            return  # nothing new since the last publication (upstream's permit_corrected_publication false)
        self.last_published_stamp = stamp
        if self.config.publish_tf:
            self.publish_transform(odometry)
        self.odometry_publisher.publish(odometry)
        if accel is not None:
            self.accel_publisher.publish(accel)

    def publish_transform(self, odometry):
        frames = self.config.frames
        stamp = odometry.header.stamp + rospy.Duration(self.config.transform_time_offset)
        pose = odometry.pose.pose
        world_base = Transform(quaternion_matrix(quaternion(pose.orientation)), vector(pose.position))
        if self.config.invert_tf:
            self.tf_broadcaster.sendTransform(transform_message(stamp, frames.base_link_output, frames.world,
                                                                world_base.inverse()))
        elif frames.world == frames.odom:
            self.tf_broadcaster.sendTransform(transform_message(stamp, frames.world, frames.base_link_output,
                                                                world_base))
        else:
            # map -> base_link is estimated, odom -> base_link comes from elsewhere: publish map -> odom.
            base_odom = self.lookup(frames.base_link, frames.odom, odometry.header.stamp.to_sec())
            if base_odom is None:
                rospy.logerr_throttle(5.0, f"Could not obtain transform from {frames.odom}->{frames.base_link}")
                return
            self.tf_broadcaster.sendTransform(transform_message(stamp, frames.map, frames.odom,
                                                                world_base * base_odom))

    def odometry_message(self):
        ekf = self.estimator.filter
        if not ekf.initialized:
            return None
        state, covariance = ekf.state, ekf.covariance
        if not np.isfinite(state).all():
            rospy.logerr_throttle(5.0, "Critical Error, NaNs were detected in the output state of the filter.")
        message = Odometry()
        message.header.stamp = rospy.Time.from_sec(ekf.last_measurement_time)
        message.header.frame_id = self.config.frames.world
        message.child_frame_id = self.config.frames.base_link_output
        pose, twist = message.pose.pose, message.twist.twist
        pose.position.x, pose.position.y, pose.position.z = state[:3]
        q = pose.orientation
        q.x, q.y, q.z, q.w = rpy_quaternion(*state[ROLL:YAW + 1])
        twist.linear.x, twist.linear.y, twist.linear.z = state[VX:VX + 3]
        twist.angular.x, twist.angular.y, twist.angular.z = state[VX + 3:VYAW + 1]
        message.pose.covariance = covariance[:6, :6].ravel().tolist()
        message.twist.covariance = covariance[VX:VYAW + 1, VX:VYAW + 1].ravel().tolist()
        return message

    def accel_message(self):
        ekf = self.estimator.filter
        if not ekf.initialized:
            return None
        message = AccelWithCovarianceStamped()
        message.header.stamp = rospy.Time.from_sec(ekf.last_measurement_time)
        message.header.frame_id = self.config.frames.base_link_output
        accel = message.accel.accel
        accel.linear.x, accel.linear.y, accel.linear.z = ekf.state[AX:AZ + 1]
        accel.angular.x, accel.angular.y, accel.angular.z = self.estimator.angular_acceleration
        covariance = np.zeros((6, 6))
        covariance[:3, :3] = ekf.covariance[AX:AZ + 1, AX:AZ + 1]
        covariance[3:, 3:] = self.estimator.angular_acceleration_covariance
        message.accel.covariance = covariance.ravel().tolist()
        return message


REJECTIONS = {
    "invalid": "{topic}: a measurement with NaN, inf or huge values or covariances; those members are left out",
    "singular": "{topic}: a measurement whose innovation covariance cannot be inverted was left out",
    "diverged": "{topic}: a measurement that would make the estimate non-finite was left out",
}


def main():
    rospy.init_node("ekf_se")
    RosFilter()
    rospy.spin()
