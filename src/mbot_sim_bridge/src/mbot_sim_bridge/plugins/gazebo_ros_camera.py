"""``libgazebo_ros_camera.so``: sensor_msgs/Image and CameraInfo of a camera sensor, rendered only while
someone subscribes to either."""
import rospy
from sensor_msgs.msg import CameraInfo, Image

from ..core.cameras.camera import Camera
from ..core.names import resolve_frame
from . import RosPlugin, ros_time
from .messages import camera_info_message, image_message


def camera_namespace(plugin) -> str:
    """robotNamespace + "/" + cameraName, as GazeboRosCameraUtils builds its NodeHandle."""
    return rospy.names.ns_join(plugin.robot_namespace(), plugin.params["cameraName"].strip("/"))


class GazeboRosCamera(RosPlugin, Camera):
    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        namespace = camera_namespace(self)
        self.frame_id = resolve_frame(self.params["frameName"])
        image_topic, info_topic = (rospy.names.ns_join(namespace, self.params[tag])
                                   for tag in ("imageTopicName", "cameraInfoTopicName"))
        self.image_publisher = self.topics.publisher(image_topic, Image)
        self.info_publisher = self.topics.publisher(info_topic, CameraInfo)
        self.info = camera_info_message(self.intrinsics, self.frame_id)
        config = self.config
        rospy.loginfo(f"{self.label}: sensor '{config.sensor_name}' on link '{config.link}' -> "
                      f"{self.image_publisher.resolved_name}, {self.info_publisher.resolved_name} (frame "
                      f"'{self.frame_id}'), {config.width}x{config.height} {self.encoding} at {self.frame_rate:g} Hz "
                      f"({self.renderer.renderer} renderer)")

    def update(self, now: float):
        # As in gazebo_ros, the sensor renders only while the image or camera_info has a subscriber.
        if self.nobody_listens(now, self.image_publisher, self.info_publisher):
            return
        image_wanted = self.topics.listened(self.image_publisher)
        if not self.throttle.passes(now):
            return
        stamp = ros_time(now)
        if image_wanted:
            frame = self.capture(now)
            self.latest = frame
            message = image_message(self.frame_id, self.encoding, frame.image)
            message.header.stamp = stamp
            self.image_publisher.publish(message)
        self.info.header.stamp = stamp
        self.info_publisher.publish(self.info)
