"""``libgazebo_ros_f3d.so``: the wrench applied to a link from outside, as geometry_msgs/WrenchStamped at every
physics step while subscribed."""
import rospy
from geometry_msgs.msg import WrenchStamped

from ..core.f3d import F3D
from ..core.names import resolve_frame, tf_prefix
from . import RosPlugin, resolve_in_namespace
from .messages import set_wrench_stamped


class GazeboRosF3D(RosPlugin, F3D):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        namespace = self.robot_namespace()
        self.message = WrenchStamped()
        self.message.header.frame_id = resolve_frame(self.params["frameName"],
                                                     tf_prefix(context.simulation.parameters, namespace))
        self.publisher = self.topics.publisher(resolve_in_namespace(namespace, self.params["topicName"]),
                                               WrenchStamped)
        rospy.loginfo(f"{self.label}: link '{self.link}' -> {self.publisher.resolved_name} (frame "
                      f"'{self.message.header.frame_id}', world-frame values) at every physics step")

    def update(self, now: float):
        if not self.topics.listened(self.publisher):
            self.idle(now)
            return
        super().update(now)
        set_wrench_stamped(self.message, now, self.latest.force, self.latest.torque)
        self.publisher.publish(self.message)
