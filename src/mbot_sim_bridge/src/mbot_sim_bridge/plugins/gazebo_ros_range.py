"""``libgazebo_ros_range.so``: a ray sensor's nearest reading as sensor_msgs/Range."""
import rospy
from sensor_msgs.msg import Range

from ..core.names import resolve_frame, tf_prefix
from ..core.sensors.range_sensor import RangeSensor
from . import RosPlugin, resolve_in_namespace, ros_time


class RangePublisher(RosPlugin):
    """The Range topic of this plugin and of hector's sonar (hector_gazebo_ros_sonar.py): the message made once
    and refilled, published only while subscribed."""

    def advertise(self, topic: str, frame_id: str):
        config = self.config
        self.publisher = self.topics.publisher(resolve_in_namespace(self.robot_namespace(), topic), Range)
        self.message = Range(radiation_type=self.radiation_type, field_of_view=self.field_of_view,
                             min_range=config.range_min, max_range=config.range_max)
        self.message.header.frame_id = frame_id
        rospy.loginfo(f"{self.label}: sensor '{config.sensor_name}' on link '{config.link}' -> "
                      f"{self.publisher.resolved_name} (frame {frame_id})")

    def update(self, now: float):
        if self.nobody_listens(now, self.publisher):
            return
        super().update(now)
        self.message.header.stamp = ros_time(now)
        self.message.range = self.latest.range
        self.publisher.publish(self.message)


class GazeboRosRange(RangePublisher, RangeSensor):
    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        prefix = tf_prefix(context.simulation.parameters, self.robot_namespace())
        self.advertise(self.params["topicName"], resolve_frame(self.params["frameName"], prefix))
