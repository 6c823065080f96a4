"""``libgazebo_ros_openni_kinect.so``: rgb image, depth image, point cloud and the two camera_info topics of a
depth sensor, from one render per sensor frame, only while something is subscribed."""
import rospy
from sensor_msgs.msg import CameraInfo, Image, PointCloud2, PointField

from ..core.cameras.camera import DepthCamera
from ..core.cameras.image_formats import POINT_FIELDS, POINT_STEP
from ..core.names import resolve_frame
from . import RosPlugin, ros_time
from .gazebo_ros_camera import camera_namespace
from .messages import camera_info_message, image_message


class GazeboRosOpenniKinect(RosPlugin, DepthCamera):
    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        namespace = camera_namespace(self)
        params = self.params

        def publisher(tag, message_type):
            return self.topics.publisher(rospy.names.ns_join(namespace, params[tag]), message_type)

        self.frame_id = resolve_frame(params["frameName"])
        self.image_publisher = publisher("imageTopicName", Image)
        self.info_publisher = publisher("cameraInfoTopicName", CameraInfo)
        self.depth_publisher = publisher("depthImageTopicName", Image)
        self.depth_info_publisher = publisher("depthImageCameraInfoTopicName", CameraInfo)
        self.cloud_publisher = publisher("pointCloudTopicName", PointCloud2)
        self.info = camera_info_message(self.intrinsics, self.frame_id)
        self.depth_encoding = "16UC1" if params["useDepth16UC1Format"] else "32FC1"
        self.cloud = PointCloud2()
        self.cloud.header.frame_id = self.frame_id
        self.cloud.height, self.cloud.width = self.config.height, self.config.width
        self.cloud.fields = [PointField(name, offset, PointField.FLOAT32, 1) for name, offset in POINT_FIELDS]
        self.cloud.is_bigendian = False
        self.cloud.point_step = POINT_STEP
        self.cloud.row_step = POINT_STEP * self.config.width
        config = self.config
        info_rate = f"{params['updateRate']:g} Hz" if params["updateRate"] else "every frame"
        rospy.loginfo(f"{self.label}: sensor '{config.sensor_name}' on link '{config.link}' -> "
                      f"{self.image_publisher.resolved_name}, {self.depth_publisher.resolved_name}, "
                      f"{self.cloud_publisher.resolved_name} (frame '{self.frame_id}'), {config.width}x{config.height} "
                      f"at {self.frame_rate:g} Hz, camera_info at {info_rate}, cloud within ({self.cutoff:g}, "
                      f"{self.cutoff_max:g}) m ({self.renderer.renderer} renderer)")

    def update(self, now: float):
        image_wanted, depth_wanted, cloud_wanted = (self.topics.listened(publisher) for publisher in (
            self.image_publisher, self.depth_publisher, self.cloud_publisher))
        stamp = ros_time(now)
        if image_wanted or depth_wanted or cloud_wanted:
            frame = self.capture(now)
            self.latest = frame
            if image_wanted:
                message = image_message(self.frame_id, self.encoding, frame.image)
                message.header.stamp = stamp
                self.image_publisher.publish(message)
            if depth_wanted:
                depth = self.depth_image(frame)
                message = image_message(self.frame_id, self.depth_encoding, depth.reshape(depth.shape + (1,)))
                message.header.stamp = stamp
                self.depth_publisher.publish(message)
            if cloud_wanted:
                self.cloud.data, self.cloud.is_dense = self.cloud_data(frame)
                self.cloud.header.stamp = stamp
                self.cloud_publisher.publish(self.cloud)
        # The camera_info topics follow the plugin's updateRate, each while it has subscribers.
        info_wanted = [publisher for publisher in (self.info_publisher, self.depth_info_publisher)
                       if self.topics.listened(publisher)]
        if info_wanted and self.throttle.passes(now):
            self.info.header.stamp = stamp
            for publisher in info_wanted:
                publisher.publish(self.info)
