"""``libgazebo_ros_vacuum_gripper.so``: the ``on`` and ``off`` services and the ``grasping`` topic."""
import rospy
from std_msgs.msg import Bool
from std_srvs.srv import Empty, EmptyResponse

from ..core.manipulation.vacuum_gripper import VacuumGripper
from . import RosPlugin, resolve_in_namespace


class GazeboRosVacuumGripper(RosPlugin, VacuumGripper):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        namespace = self.robot_namespace()
        self.publisher = self.topics.publisher(resolve_in_namespace(namespace, self.params["topicName"]), Bool)
        self.services = [self.topics.service(resolve_in_namespace(namespace, name), Empty,
                                             lambda request, on=on: self._on_switch(on))
                         for name, on in (("on", True), ("off", False))]
        rospy.loginfo(f"{self.label}: link '{self.link}' pulls while on ({self.services[0].resolved_name}, "
                      f"{self.services[1].resolved_name}); {self.publisher.resolved_name} says whether it grasps")

    def _on_switch(self, on: bool):
        said = self.switch(on)
        (rospy.logwarn if "already" in said else rospy.loginfo)(said)
        return EmptyResponse()

    def update(self, now: float):
        if self.nobody_listens(now, self.publisher):
            return
        super().update(now)
        self.publisher.publish(Bool(self.grasping))
