"""``libgazebo_ros_imu_sensor.so``: sensor_msgs/Imu of a ``<sensor type="imu">``."""
import rospy
from sensor_msgs.msg import Imu

from ..core.sensors.imu import ImuSensor
from . import RosPlugin, resolve_in_namespace
from .messages import imu_message


class GazeboRosImuSensor(RosPlugin, ImuSensor):
    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        namespace = self.robot_namespace()
        self.publisher = self.topics.publisher(resolve_in_namespace(namespace, self.params["topicName"]), Imu)
        rate = "every physics step" if self.timer.period == 0 else f"{1.0 / self.timer.period:g} Hz"
        rospy.loginfo(f"{self.label}: sensor '{sensor.get('name')}' on link '{self.link}' -> "
                      f"{self.publisher.resolved_name} (frame '{self.params['frameName']}') at {rate}")

    def update(self, now: float):
        if self.nobody_listens(now, self.publisher):
            return
        super().update(now)
        self.publisher.publish(imu_message(self.latest, self.params["frameName"]))
