"""``libgazebo_ros_laser.so`` and ``libgazebo_ros_gpu_laser.so``: a ray sensor published as LaserScan."""
import rospy
from sensor_msgs.msg import LaserScan

from ..core.clock import UpdateTimer
from ..core.geometry import compose
from ..core.lidar import LaserScanner, parse_ray_sensor
from . import BridgePlugin, PluginContext, loop_publisher, resolve_frame, resolve_in_namespace


class GazeboRosLaser(BridgePlugin):
    def __init__(self, context: PluginContext, link_name: str, sensor, element, rng):
        self.context = context
        self.config = parse_ray_sensor(sensor, link_name, "model '%s'" % context.robot.name)
        self.scanner = LaserScanner(context.engine.client, self.config, rng)
        self.timer = UpdateTimer(self.config.update_rate, start=context.engine.sim_time)
        # Sensor namespace: absent means the simulator's own ("/"), empty means the model name.
        namespace = self.config.robot_namespace
        if namespace == "":
            namespace = context.robot.name
        self.publisher = loop_publisher(resolve_in_namespace(namespace, self.config.topic_name), LaserScan)
        # Everything but this robot's own bit: the scan never sees the robot that carries the sensor.
        self.collision_filter_mask = -1 & ~context.robot.collision_group
        self.message = LaserScan()
        self.message.header.frame_id = resolve_frame(self.config.frame_name)
        self.message.angle_min, self.message.angle_max = self.config.min_angle, self.config.max_angle
        self.message.angle_increment = self.config.angle_increment
        self.message.range_min, self.message.range_max = self.config.range_min, self.config.range_max
        rospy.loginfo("GazeboRosLaser: sensor '%s' on link '%s' -> %s (frame %s), %d ranges at %.1f Hz",
                      self.config.sensor_name, link_name, self.publisher.resolved_name,
                      self.message.header.frame_id, self.config.range_count * self.config.vertical_range_count,
                      self.config.update_rate)

    def update(self, now: float):
        # As in gazebo_ros, the sensor works only while someone listens.
        if self.publisher.get_num_connections() == 0:
            return
        robot = self.context.robot
        pose = compose(robot.link_world_pose(self.config.link), self.config.pose)
        scan = self.scanner.scan(pose, self.collision_filter_mask)
        self.message.header.stamp = self.context.stamp()
        self.message.ranges = scan.ranges.tolist()
        self.message.intensities = scan.intensities.tolist()
        self.publisher.publish(self.message)

    def close(self):
        self.publisher.unregister()
