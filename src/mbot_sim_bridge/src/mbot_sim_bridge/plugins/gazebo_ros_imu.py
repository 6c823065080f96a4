"""``libgazebo_ros_imu.so``: sensor_msgs/Imu of a link, and the (empty) calibrate service."""
import rospy
from sensor_msgs.msg import Imu
from std_srvs.srv import Empty, EmptyResponse

from ..core.imu import ImuModelPlugin, ImuReading
from . import loop_publisher, resolve_in_namespace, ros_time


def imu_message(reading: ImuReading, frame_id: str) -> Imu:
    message = Imu()
    message.header.stamp = ros_time(reading.stamp)
    message.header.frame_id = frame_id
    o, w, a = message.orientation, message.angular_velocity, message.linear_acceleration
    o.x, o.y, o.z, o.w = reading.orientation
    w.x, w.y, w.z = reading.angular_velocity
    a.x, a.y, a.z = reading.linear_acceleration
    diagonal = (reading.covariance, 0.0, 0.0, 0.0, reading.covariance, 0.0, 0.0, 0.0, reading.covariance)
    message.orientation_covariance = message.angular_velocity_covariance = diagonal
    message.linear_acceleration_covariance = diagonal
    return message


class GazeboRosImu(ImuModelPlugin):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        namespace = self.robot_namespace()
        self.publisher = self.service = None
        if self.params["topicName"]:
            self.publisher = loop_publisher(resolve_in_namespace(namespace, self.params["topicName"]), Imu)
            self.service = rospy.Service(resolve_in_namespace(namespace, self.params["serviceName"]), Empty,
                                         lambda request: EmptyResponse())
        topic = self.publisher.resolved_name if self.publisher else "(no topicName: nothing)"
        rate = f"at {self.params['updateRate']:g} Hz" if self.params["updateRate"] else "at every physics step"
        rospy.loginfo(f"{self.label}: link '{self.link}' -> {topic} (frame '{self.frame_name}') {rate}")

    def update(self, now: float):
        listened = self.publisher is not None and self.publisher.get_num_connections() > 0
        self.idle(not listened)
        if not listened:
            # Gazebo keeps its last time and velocity when nobody listens; the next reading differences from it.
            return
        super().update(now)
        self.publisher.publish(imu_message(self.latest, self.frame_name))

    def close(self):
        if self.publisher is not None:
            self.publisher.unregister()
            self.service.shutdown()
