"""``libhector_gazebo_ros_magnetic.so``: the earth's field in the body frame, as geometry_msgs/Vector3Stamped or
sensor_msgs/MagneticField. hector's dynamic_reconfigure server is not provided."""
import rospy
from geometry_msgs.msg import Vector3Stamped
from sensor_msgs.msg import MagneticField

from ..core.hector.hector_magnetic import HectorMagnetic
from . import RosPlugin, resolve_in_namespace, ros_time
from .messages import set_xyz


class HectorGazeboRosMagnetic(RosPlugin, HectorMagnetic):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.as_magnetic_field = self.params["useMagneticFieldMsgs"]
        self.publisher = self.topics.publisher(
            resolve_in_namespace(self.robot_namespace(), self.params["topicName"]),
            MagneticField if self.as_magnetic_field else Vector3Stamped)
        rospy.loginfo(f"{self.label}: link '{self.link}' -> {self.publisher.resolved_name} (frame '{self.frame_id}')")

    def update(self, now: float):
        if self.nobody_listens(now, self.publisher):
            return
        super().update(now)
        message = MagneticField() if self.as_magnetic_field else Vector3Stamped()
        message.header.stamp = ros_time(now)
        message.header.frame_id = self.frame_id
        set_xyz(message.magnetic_field if self.as_magnetic_field else message.vector, self.latest.field)
        self.publisher.publish(message)
