"""``libhector_gazebo_ros_imu.so``: sensor_msgs/Imu with gravity, its bias topic and the calibrate service.

hector's ``set_accel_bias``/``set_rate_bias`` services and its dynamic_reconfigure servers need
hector_gazebo_plugins' own types, which the workspace does not build: they are left out, with one INFO line.
"""
import rospy
from sensor_msgs.msg import Imu
from std_srvs.srv import Empty, EmptyResponse

from ..core.hector.hector_imu import HectorImu
from ..core.log import get_logger, info_once
from . import RosPlugin, resolve_in_namespace, ros_time
from .messages import diagonal_covariance, set_quaternion, set_xyz

_logger = get_logger(__name__)


def _imu(stamp, frame_id, orientation, angular_velocity, linear_acceleration) -> Imu:
    message = Imu()
    message.header.stamp = ros_time(stamp)
    message.header.frame_id = frame_id
    set_quaternion(message.orientation, orientation)
    set_xyz(message.angular_velocity, angular_velocity)
    set_xyz(message.linear_acceleration, linear_acceleration)
    return message


class HectorGazeboRosImu(RosPlugin, HectorImu):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        namespace = self.robot_namespace()
        topic = self.params["topicName"]
        bias_topic = self.params["biasTopicName"] if self.params["biasTopicName"] is not None else (
            topic + "/bias" if topic else "")
        service = self.params["serviceName"] if self.params["serviceName"] is not None else topic + "/calibrate"
        self.publisher = self.topics.publisher(resolve_in_namespace(namespace, topic), Imu) if topic else None
        self.bias_publisher = (self.topics.publisher(resolve_in_namespace(namespace, bias_topic), Imu)
                               if bias_topic else None)
        if service:
            self.topics.service(resolve_in_namespace(namespace, service), Empty, self._calibrate)
        info_once(_logger, f"{self.label}: the set_accel_bias/set_rate_bias services and dynamic_reconfigure "
                                    "need hector_gazebo_plugins' own types and are not provided")
        shown = self.publisher.resolved_name if self.publisher else "(no topicName: nothing)"
        rate = f"at {1.0 / self.timer.period:g} Hz" if self.timer.period else "at every physics step"
        rospy.loginfo(f"{self.label}: link '{self.link}' -> {shown} (frame '{self.frame_id}') {rate}")

    def _calibrate(self, request):
        self.calibrate()
        return EmptyResponse()

    def update(self, now: float):
        if self.nobody_listens(now, self.publisher, self.bias_publisher):
            return
        super().update(now)
        reading = self.latest
        if self.topics.listened(self.publisher):
            message = _imu(now, self.frame_id, reading.orientation, reading.angular_velocity,
                           reading.linear_acceleration)
            message.orientation_covariance = diagonal_covariance(reading.orientation_covariance, 3)
            message.angular_velocity_covariance = diagonal_covariance(reading.angular_velocity_covariance, 3)
            message.linear_acceleration_covariance = diagonal_covariance(reading.linear_acceleration_covariance, 3)
            self.publisher.publish(message)
        if self.topics.listened(self.bias_publisher):
            self.bias_publisher.publish(_imu(now, self.frame_id, reading.orientation_error, reading.rate_bias,
                                             reading.accel_bias))
