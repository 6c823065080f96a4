"""``libgazebo_ros_ft_sensor.so``: a joint's wrench on its child link as geometry_msgs/WrenchStamped, while
subscribed."""
import rospy
from geometry_msgs.msg import WrenchStamped

from ..core.ft_sensor import FTSensor
from ..core.names import resolve_frame, tf_prefix
from . import RosPlugin, resolve_in_namespace
from .messages import set_wrench_stamped


class GazeboRosFT(RosPlugin, FTSensor):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        namespace = self.robot_namespace()
        self.message = WrenchStamped()
        self.message.header.frame_id = resolve_frame(self.child_link,
                                                     tf_prefix(context.simulation.parameters, namespace))
        self.publisher = self.topics.publisher(resolve_in_namespace(namespace, self.params["topicName"]),
                                               WrenchStamped)
        rate = self.params["updateRate"]
        rospy.loginfo(f"{self.label}: joint '{self.joint}' -> {self.publisher.resolved_name} (frame "
                      f"'{self.message.header.frame_id}') {f'at {rate:g} Hz' if rate else 'at every physics step'}")

    def update(self, now: float):
        if not self.topics.listened(self.publisher):
            self.idle(now)
            return
        super().update(now)
        set_wrench_stamped(self.message, now, self.latest.force, self.latest.torque)
        self.publisher.publish(self.message)
