"""``libgazebo_ros_laser.so`` and ``libgazebo_ros_gpu_laser.so``: a ray sensor published as LaserScan."""
import rospy
from sensor_msgs.msg import LaserScan

from ..core.sensors.lidar import RaySensor
from ..core.names import resolve_frame, tf_prefix
from . import RosPlugin, resolve_in_namespace, ros_time


class GazeboRosLaser(RosPlugin, RaySensor):
    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        config = self.config
        namespace = self.robot_namespace()
        self.publisher = self.topics.publisher(resolve_in_namespace(namespace, self.params["topicName"]), LaserScan)
        self.message = LaserScan()
        prefix = tf_prefix(context.simulation.parameters, namespace)
        self.message.header.frame_id = resolve_frame(self.params["frameName"], prefix)
        self.message.angle_min, self.message.angle_max = config.min_angle, config.max_angle
        self.message.angle_increment = config.angle_increment
        self.message.range_min, self.message.range_max = config.range_min, config.range_max
        ranges = config.range_count * config.vertical_range_count
        rospy.loginfo(f"{self.label}: sensor '{config.sensor_name}' on link '{config.link}' -> "
                      f"{self.publisher.resolved_name} (frame {self.message.header.frame_id}), {ranges} ranges at "
                      f"{config.update_rate:.1f} Hz")

    def update(self, now: float):
        # As in gazebo_ros, the sensor works only while someone listens.
        if self.nobody_listens(now, self.publisher):
            return
        scan = self.scan()
        self.message.header.stamp = ros_time(now)
        self.message.ranges = scan.ranges.tolist()
        self.message.intensities = scan.intensities.tolist()
        self.publisher.publish(self.message)
