"""``libgazebo_ros_velodyne_laser.so`` and ``libgazebo_ros_velodyne_gpu_laser.so``: sensor_msgs/PointCloud2 with
velodyne_pointcloud's layout (x y z intensity float32, ring uint16, time float32; 22 bytes a point)."""
import numpy as np
import rospy
from sensor_msgs.msg import PointCloud2, PointField

from ..core.names import resolve_frame, tf_prefix
from ..core.sensors.velodyne_laser import VelodyneLaser
from . import RosPlugin, resolve_in_namespace, ros_time

POINT = np.dtype({"names": ["x", "y", "z", "intensity", "ring", "time"],
                  "formats": ["<f4", "<f4", "<f4", "<f4", "<u2", "<f4"],
                  "offsets": [0, 4, 8, 12, 16, 18], "itemsize": 22})
FIELDS = [PointField(name, POINT.fields[name][1], PointField.UINT16 if name == "ring" else PointField.FLOAT32, 1)
          for name in POINT.names]


class GazeboRosVelodyneLaser(RosPlugin, VelodyneLaser):
    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        namespace = self.robot_namespace()
        # Upstream's prefix: the tf_prefix parameter, replaced by robotNamespace when that is not "/".
        prefix = tf_prefix(context.simulation.parameters, namespace)
        if namespace.strip("/"):
            prefix = namespace
        self.frame_id = resolve_frame(self.params["frameName"], prefix)
        self.publisher = self.topics.publisher(resolve_in_namespace(namespace, self.params["topicName"]),
                                               PointCloud2)
        config = self.config
        rospy.loginfo(f"{self.label}: sensor '{config.sensor_name}' on link '{config.link}' -> "
                      f"{self.publisher.resolved_name} (frame {self.frame_id}), {config.vertical_range_count} rings "
                      f"of {config.range_count} at {config.update_rate:g} Hz")

    def update(self, now: float):
        if self.nobody_listens(now, self.publisher):
            return
        cloud = self.cloud()
        points = np.zeros(len(cloud.ring), dtype=POINT)
        points["x"], points["y"], points["z"] = cloud.xyz.T
        points["intensity"], points["ring"] = cloud.intensity, cloud.ring
        message = PointCloud2()
        message.header.stamp = ros_time(now)
        message.header.frame_id = self.frame_id
        message.fields = FIELDS
        message.point_step = POINT.itemsize
        message.is_bigendian = False
        if cloud.organized:
            message.width = self.config.vertical_range_count
            message.height = cloud.rows
            message.is_dense = False
        else:
            message.width, message.height, message.is_dense = len(points), 1, True
        message.row_step = message.point_step * message.width
        message.data = points.tobytes()
        self.publisher.publish(message)
