"""``libgazebo_ros_depth_camera.so``: the openni_kinect plugin's topics (gazebo_ros_openni_kinect.py)."""
import rospy

from ..core.cameras.camera import PlainDepthCamera
from .gazebo_ros_openni_kinect import GazeboRosOpenniKinect


class GazeboRosDepthCamera(GazeboRosOpenniKinect, PlainDepthCamera):
    """The same outputs without pointCloudCutoffMax."""

    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        rospy.loginfo(f"{self.label}: the reflectance and normals topics of libgazebo_ros_depth_camera.so are not "
                      "published")
