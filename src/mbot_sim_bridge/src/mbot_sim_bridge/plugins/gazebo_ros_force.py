"""``libgazebo_ros_force.so``: a geometry_msgs/Wrench topic pushing a link."""
import rospy
from geometry_msgs.msg import Wrench

from ..core.manipulation.force import Force
from . import RosPlugin, resolve_in_namespace


class GazeboRosForce(RosPlugin, Force):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        topic = resolve_in_namespace(self.robot_namespace(), self.params["topicName"])
        self.topics.subscriber(topic, Wrench, self._on_wrench)
        rospy.loginfo(f"{self.label}: {topic} pushes link '{self.link}' (world frame, at its centre of mass)")

    def _on_wrench(self, message: Wrench):
        force, torque = message.force, message.torque
        self.set_wrench((force.x, force.y, force.z), (torque.x, torque.y, torque.z))
