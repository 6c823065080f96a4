"""``libgazebo_ros_block_laser.so``: a ray sensor's horizontal and vertical scan as sensor_msgs/PointCloud (the
points and one unnamed channel of intensities, as upstream fills it), published only while subscribed."""
import rospy
from geometry_msgs.msg import Point32
from sensor_msgs.msg import ChannelFloat32, PointCloud

from ..core.sensors.block_laser import BlockLaser
from ..core.names import resolve_frame, tf_prefix
from . import RosPlugin, resolve_in_namespace, ros_time


class GazeboRosBlockLaser(RosPlugin, BlockLaser):
    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        namespace = self.robot_namespace()
        self.frame_id = resolve_frame(self.params["frameName"], tf_prefix(context.simulation.parameters, namespace))
        self.publisher = self.topics.publisher(resolve_in_namespace(namespace, self.params["topicName"]), PointCloud)
        config = self.config
        rospy.loginfo(f"{self.label}: sensor '{config.sensor_name}' on link '{config.link}' -> "
                      f"{self.publisher.resolved_name} (frame {self.frame_id}), {config.vertical_range_count} rows "
                      f"of {config.range_count} points at {config.update_rate:g} Hz")

    def update(self, now: float):
        if self.nobody_listens(now, self.publisher):
            return
        cloud = self.cloud()
        message = PointCloud()
        message.header.stamp = ros_time(now)
        message.header.frame_id = self.frame_id
        message.points = [Point32(x, y, z) for x, y, z in cloud.xyz.tolist()]
        message.channels = [ChannelFloat32("", cloud.intensity.tolist())]
        self.publisher.publish(message)
