"""``libhector_gazebo_ros_gps.so``: sensor_msgs/NavSatFix and the velocity as geometry_msgs/Vector3Stamped.

hector's ``set_reference_geopose`` service and dynamic_reconfigure server need hector_gazebo_plugins' own
types, which the workspace does not build: they are left out, with one INFO line.
"""
import rospy
from geometry_msgs.msg import Vector3Stamped
from sensor_msgs.msg import NavSatFix

from ..core.hector.hector_gps import HectorGps
from ..core.log import get_logger, info_once
from . import RosPlugin, resolve_in_namespace, ros_time
from .messages import diagonal_covariance, set_xyz

_logger = get_logger(__name__)


class HectorGazeboRosGps(RosPlugin, HectorGps):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        namespace = self.robot_namespace()
        self.fix_publisher = self.topics.publisher(resolve_in_namespace(namespace, self.params["topicName"]),
                                                   NavSatFix)
        self.velocity_publisher = self.topics.publisher(
            resolve_in_namespace(namespace, self.params["velocityTopicName"]), Vector3Stamped)
        info_once(_logger, f"{self.label}: the set_reference_geopose service and dynamic_reconfigure need "
                                    "hector_gazebo_plugins' own types and are not provided")
        rospy.loginfo(f"{self.label}: link '{self.link}' -> {self.fix_publisher.resolved_name}, "
                      f"{self.velocity_publisher.resolved_name} (frame '{self.frame_id}')")

    def update(self, now: float):
        if self.nobody_listens(now, self.fix_publisher, self.velocity_publisher):
            return
        super().update(now)
        reading = self.latest
        fix = NavSatFix()
        fix.header.stamp = ros_time(now)
        fix.header.frame_id = self.frame_id
        fix.status.status, fix.status.service = self.params["status"], self.params["service"]
        fix.latitude, fix.longitude, fix.altitude = reading.latitude, reading.longitude, reading.altitude
        fix.position_covariance = diagonal_covariance(reading.position_covariance, 3)
        fix.position_covariance_type = NavSatFix.COVARIANCE_TYPE_DIAGONAL_KNOWN
        self.fix_publisher.publish(fix)
        velocity = Vector3Stamped()
        velocity.header = fix.header
        set_xyz(velocity.vector, reading.velocity)
        self.velocity_publisher.publish(velocity)
