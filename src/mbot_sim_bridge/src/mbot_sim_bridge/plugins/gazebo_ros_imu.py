"""``libgazebo_ros_imu.so``: sensor_msgs/Imu of a link, and the (empty) calibrate service."""
import rospy
from sensor_msgs.msg import Imu
from std_srvs.srv import Empty, EmptyResponse

from ..core.sensors.imu import ImuModelPlugin
from . import RosPlugin, resolve_in_namespace
from .messages import imu_records


class GazeboRosImu(RosPlugin, ImuModelPlugin):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        namespace = self.robot_namespace()
        self.publisher = None
        if self.params["topicName"]:
            self.publisher = self.topics.publisher(resolve_in_namespace(namespace, self.params["topicName"]), Imu)
            self.topics.service(resolve_in_namespace(namespace, self.params["serviceName"]), Empty,
                                lambda request: EmptyResponse())
        topic = self.publisher.resolved_name if self.publisher else "(no topicName: nothing)"
        rate = f"at {self.params['updateRate']:g} Hz" if self.params["updateRate"] else "at every physics step"
        rospy.loginfo(f"{self.label}: link '{self.link}' -> {topic} (frame '{self.frame_name}') {rate}")

    def update(self, now: float):
        if self.nobody_listens(now, self.publisher):
            return
        super().update(now)
        self.publisher.publish_records(imu_records(self.readings, self.frame_name))
