"""``libgazebo_ros_multicamera.so``: each side's sensor_msgs/Image and CameraInfo under ``<cameraName>/left`` and
``<cameraName>/right``, each camera rendered only while someone subscribes to its image or camera_info."""
import rospy
from sensor_msgs.msg import CameraInfo, Image

from ..core.cameras.multicamera import MultiCamera
from ..core.names import resolve_frame
from . import RosPlugin, ros_time
from .gazebo_ros_camera import camera_namespace
from .messages import camera_info_message, image_message


class GazeboRosMultiCamera(RosPlugin, MultiCamera):
    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        self.frame_id = resolve_frame(self.params["frameName"])
        self.publishers = {}
        for side, camera in self.cameras.items():
            namespace = rospy.names.ns_join(camera_namespace(self), side)
            image, info = (self.topics.publisher(rospy.names.ns_join(namespace, self.params[tag]), message_type)
                           for tag, message_type in (("imageTopicName", Image), ("cameraInfoTopicName", CameraInfo)))
            self.publishers[side] = (image, info, camera_info_message(camera.intrinsics, self.frame_id))
            config = camera.config
            rospy.loginfo(f"{self.label}: camera '{side}' of sensor '{self.sensor_name}' on link '{config.link}' -> "
                          f"{image.resolved_name}, {info.resolved_name} (frame '{self.frame_id}'), "
                          f"{config.width}x{config.height} {camera.encoding} at {self.frame_rate:g} Hz, "
                          f"P[3] {camera.intrinsics.P[3]:g}")

    def update(self, now: float):
        stamp = ros_time(now)
        for side, (image, info, info_message) in self.publishers.items():
            image_wanted = self.topics.listened(image)
            if not (image_wanted or self.topics.listened(info)) or not self.cameras[side].throttle.passes(now):
                continue
            if image_wanted:
                frame = self.capture(side, now)
                self.latest[side] = frame
                message = image_message(self.frame_id, self.cameras[side].encoding, frame.image)
                message.header.stamp = stamp
                image.publish(message)
            info_message.header.stamp = stamp
            info.publish(info_message)
