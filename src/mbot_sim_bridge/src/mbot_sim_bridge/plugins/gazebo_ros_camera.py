"""``libgazebo_ros_camera.so``: sensor_msgs/Image and CameraInfo of a camera sensor, rendered only while
someone subscribes to either."""
import rospy
from sensor_msgs.msg import CameraInfo, Image

from ..core.camera import Camera, Intrinsics
from ..core.names import resolve_frame
from . import loop_publisher, ros_time


def camera_namespace(plugin) -> str:
    """robotNamespace + "/" + cameraName, as GazeboRosCameraUtils builds its NodeHandle."""
    return rospy.names.ns_join(plugin.robot_namespace(), plugin.params["cameraName"].strip("/"))


def camera_info_message(intrinsics: Intrinsics, frame_id: str) -> CameraInfo:
    info = CameraInfo()
    info.header.frame_id = frame_id
    info.width, info.height = intrinsics.width, intrinsics.height
    info.distortion_model = intrinsics.distortion_model
    info.D = list(intrinsics.distortion)
    info.K, info.R, info.P = intrinsics.K, intrinsics.R, intrinsics.P
    return info


def image_message(frame_id: str, encoding: str, pixels) -> Image:
    """An Image holding ``pixels`` ((H, W, channels) C-contiguous), copied once into bytes."""
    image = Image()
    image.header.frame_id = frame_id
    image.height, image.width = pixels.shape[:2]
    image.encoding = encoding
    image.is_bigendian = 0
    image.step = pixels.strides[0]
    image.data = pixels.tobytes()
    return image


class GazeboRosCamera(Camera):
    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        namespace = camera_namespace(self)
        self.frame_id = resolve_frame(self.params["frameName"])
        self.image_publisher = loop_publisher(rospy.names.ns_join(namespace, self.params["imageTopicName"]), Image)
        self.info_publisher = loop_publisher(rospy.names.ns_join(namespace, self.params["cameraInfoTopicName"]),
                                             CameraInfo)
        self.info = camera_info_message(self.intrinsics, self.frame_id)
        config = self.config
        rospy.loginfo(f"{self.label}: sensor '{config.sensor_name}' on link '{config.link}' -> "
                      f"{self.image_publisher.resolved_name}, {self.info_publisher.resolved_name} (frame "
                      f"'{self.frame_id}'), {config.width}x{config.height} {self.encoding} at {self.frame_rate:g} Hz "
                      f"({self.renderer.renderer} renderer)")

    def update(self, now: float):
        # As in gazebo_ros, the sensor renders only while the image or camera_info has a subscriber.
        image_wanted = self.image_publisher.get_num_connections() > 0
        if not image_wanted and self.info_publisher.get_num_connections() == 0:
            return
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

    def close(self):
        self.image_publisher.unregister()
        self.info_publisher.unregister()
