"""``libgazebo_ros_f3d.so``: the wrench applied to a link from outside, as geometry_msgs/WrenchStamped at every
physics step while subscribed."""
import rospy

from ..core.sensors.f3d import F3D
from .wrench_topic import WrenchTopic


class GazeboRosF3D(WrenchTopic, F3D):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.advertise_wrench(context, self.params["frameName"])
        rospy.loginfo(f"{self.label}: link '{self.link}' -> {self.publisher.resolved_name} (frame "
                      f"'{self.message.header.frame_id}', world-frame values) at every physics step")
