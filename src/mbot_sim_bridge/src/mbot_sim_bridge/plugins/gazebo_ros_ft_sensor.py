"""``libgazebo_ros_ft_sensor.so``: a joint's wrench on its child link as geometry_msgs/WrenchStamped, while
subscribed."""
import rospy

from ..core.sensors.ft_sensor import FTSensor
from .wrench_topic import WrenchTopic


class GazeboRosFT(WrenchTopic, FTSensor):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.advertise_wrench(context, self.child_link)
        rate = self.params["updateRate"]
        rospy.loginfo(f"{self.label}: joint '{self.joint}' -> {self.publisher.resolved_name} (frame "
                      f"'{self.message.header.frame_id}') {f'at {rate:g} Hz' if rate else 'at every physics step'}")
