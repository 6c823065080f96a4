#!/usr/bin/env python3
"""The rover as its own launch file brings it up: both controllers start; the base, whose collision meshes are
package:// STL and COLLADA files, drives at the commanded speed (ground truth); the hector IMU reads gravity up
at rest; the hector GPS fix moves north by the distance driven (x is north at referenceHeading 0); the
VLP-16-style lidar publishes 16 rings. A holonomic base beside it (planar move) moves sideways at the
commanded speed and its odometry says so; its front sonar reads a crate spawned 1 m ahead, and its bumper
reports the crate by Gazebo's collision names once driven into it, with the normal towards the base, and
nothing before; a skid-steer base (skid steer plugin) drives forward at the commanded speed; a tricycle (tricycle
plugin) drives and steers as its kinematics say, publishes its joints, and its block laser's points lie on the
ground ahead; a stereo head publishes its left and right images with the baseline in the right CameraInfo, and
its f3d reports a wrench /gazebo/apply_body_wrench puts on its base and its pan joint's ft sensor the head's
weight."""
import math
import unittest

import rospy
import rostest
from gazebo_msgs.msg import ContactsState
from gazebo_msgs.srv import ApplyBodyWrench, DeleteModel, SpawnModel
from geometry_msgs.msg import Pose, Twist, Wrench, WrenchStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, Image, Imu, JointState, NavSatFix, PointCloud, PointCloud2, Range
from sensor_msgs import point_cloud2

from sim_support import (WALL_TIMEOUT, model_state_service, print_figures, publish_for, wait_for,
                         wait_for_running_controllers)

CONTROLLER = "rover_velocity_controller"
# WGS84, as hector's GPS converts: metres per radian of latitude at the reference latitude (49.9 deg).
EQUATORIAL_RADIUS, EXCENTRICITY2 = 6378137.0, 0.00669437999013
REFERENCE_LATITUDE = math.radians(49.9)
# The tricycle: wheelbase, and its block laser's height above the ground (axle 0.08 m, mast 0.3 m).
TRICYCLE_WHEELBASE, BLOCK_LASER_HEIGHT = 0.5, 0.38
# A crate as tall as the holonomic base's sonars, 1 m ahead of its front sonar (at x = +0.26 on the base).
CRATE_SIZE = (0.4, 1.0, 0.5)
CRATE_GAP = 1.0
CRATE_SDF = f"""<sdf version="1.6"><model name="crate"><link name="link">
  <inertial><mass>20</mass></inertial>
  <collision name="collision"><geometry><box><size>{' '.join(map(str, CRATE_SIZE))}</size></box></geometry></collision>
  <visual name="visual"><geometry><box><size>{' '.join(map(str, CRATE_SIZE))}</size></box></geometry></visual>
</link></model></sdf>"""


def north_radius():
    sin2 = math.sin(REFERENCE_LATITUDE) ** 2
    return EQUATORIAL_RADIUS * (1 - EXCENTRICITY2) / (1 - EXCENTRICITY2 * sin2) ** 1.5


def east_radius():
    """hector's radius_east: the prime vertical radius times cos(latitude)."""
    return EQUATORIAL_RADIUS / math.sqrt(1 - EXCENTRICITY2 * math.sin(REFERENCE_LATITUDE) ** 2) * math.cos(
        REFERENCE_LATITUDE)


class Latest:
    """The messages of a topic, the last one first at hand."""

    def __init__(self, topic, message_type):
        self.message, self.messages = None, []
        self.subscriber = rospy.Subscriber(topic, message_type, self.store, queue_size=100)

    def store(self, message):
        self.message = message
        self.messages.append(message)

    def since(self, stamp):
        return [message for message in self.messages if message.header.stamp >= stamp]


class Rover(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("rover_test")
        cls.figures = []
        wait_for_running_controllers(["rover_joint_publisher", CONTROLLER])
        cls.get_model_state = model_state_service()
        cls.imu, cls.fix = Latest("/imu/data", Imu), Latest("/navsat/fix", NavSatFix)
        cls.cmd_vel = rospy.Publisher(f"/{CONTROLLER}/cmd_vel", Twist, queue_size=1)
        wait_for(lambda: cls.cmd_vel.get_num_connections() > 0, what="the controller to subscribe cmd_vel")
        # Spawned at z = 0 with the wheels in the ground, as Husky is: wait until it has landed and stopped.
        wait_for(lambda: cls.at_rest(), what="the rover to come to rest on its wheels")

    @classmethod
    def tearDownClass(cls):
        print_figures(cls.figures)

    @classmethod
    def at_rest(cls):
        state = cls.get_model_state("rover", "world")
        speed = math.hypot(state.twist.linear.x, state.twist.linear.y, state.twist.linear.z)
        return abs(state.pose.position.z - 0.132) < 0.01 and speed < 0.01

    def drive(self, linear, sim_seconds, publisher=None, lateral=0.0):
        """The command on the rover's cmd_vel or on ``publisher`` for ``sim_seconds`` of sim time."""
        command = Twist()
        command.linear.x, command.linear.y = linear, lateral
        publish_for(sim_seconds, (publisher or self.cmd_vel, command))

    def test_01_imu_reads_gravity_up_at_rest(self):
        # Half a second of readings (50 Hz) once the rover stands still (after its landing, or a drive).
        wait_for(lambda: self.at_rest(), what="the rover at rest")
        start = rospy.Time.now() + rospy.Duration(0.2)
        readings = wait_for(lambda: len(self.imu.since(start)) >= 25 and self.imu.since(start),
                            what="25 /imu/data messages at rest")
        mean = [sum(getattr(m.linear_acceleration, axis) for m in readings) / len(readings) for axis in "xyz"]
        self.figures.append(f"rover hector IMU at rest: mean a = ({mean[0]:.3f}, {mean[1]:.3f}, {mean[2]:.3f}) m/s² "
                            f"over {len(readings)} messages")
        self.assertAlmostEqual(mean[2], 9.8, delta=0.05)
        self.assertLess(math.hypot(mean[0], mean[1]), 0.05)
        self.assertEqual(readings[-1].header.frame_id, "imu_link")

    def test_02_drives_at_the_commanded_speed_and_the_fix_follows_north(self):
        wait_for(lambda: self.fix.message, what="/navsat/fix")
        self.drive(0.5, 1.0)
        start, pose0, fix0 = rospy.get_time(), self.get_model_state("rover", "world").pose, self.fix.message
        self.drive(0.5, 3.0)
        pose1, elapsed, fix1 = self.get_model_state("rover", "world").pose, rospy.get_time() - start, self.fix.message
        driven = pose1.position.x - pose0.position.x
        speed = driven / elapsed
        north = math.radians(fix1.latitude - fix0.latitude) * north_radius()
        self.figures.append(f"rover (package:// meshes) through ros_control at 0.5 m/s: {speed:.4f} m/s")
        self.figures.append(f"rover hector GPS: {north:.3f} m north for {driven:.3f} m driven along x")
        self.assertAlmostEqual(speed, 0.5, delta=0.025)
        # The fix and the pose are read at slightly different sim times (40 Hz fix): 1 % plus one fix period.
        self.assertAlmostEqual(north, driven, delta=0.01 * driven + 0.5 / 40)
        # East is -y at reference heading 0. The rover lands from its spawn jump turned by a degree or two, so
        # the fix follows its ground truth rather than the x axis.
        east = math.radians(fix1.longitude - fix0.longitude) * east_radius()
        self.assertAlmostEqual(east, -(pose1.position.y - pose0.position.y), delta=0.01 * driven + 0.5 / 40)

    def test_03_lidar_publishes_sixteen_rings(self):
        cloud = rospy.wait_for_message("/velodyne_points", PointCloud2, timeout=WALL_TIMEOUT)
        fields = [field.name for field in cloud.fields]
        self.assertEqual(fields, ["x", "y", "z", "intensity", "ring", "time"])
        rings = {int(point[0]) for point in point_cloud2.read_points(cloud, field_names=("ring",))}
        self.figures.append(f"rover VLP-16: {cloud.width * cloud.height} points, rings {sorted(rings)}")
        # In the empty world only the eight rings below the horizon (0 to 7, lowest first) reach the ground.
        self.assertEqual(rings, set(range(8)))
        self.assertEqual(cloud.header.frame_id, "velodyne")

    def test_04_holonomic_base_moves_sideways(self):
        command = rospy.Publisher("/holonomic/cmd_vel", Twist, queue_size=1)
        odometry = Latest("/holonomic/odom", Odometry)
        wait_for(lambda: command.get_num_connections() > 0 and odometry.message, what="the planar move plugin")
        start = self.get_model_state("holonomic_base", "world").pose.position
        self.drive(0.0, 1.0, command, lateral=0.4)
        end = self.get_model_state("holonomic_base", "world").pose.position
        reported = odometry.message.twist.twist.linear
        self.figures.append(f"holonomic base at 0.4 m/s sideways: moved ({end.x - start.x:.3f}, {end.y - start.y:.3f}) "
                            f"m in 1 s; odometry ({reported.x:.3f}, {reported.y:.3f}) m/s")
        self.assertAlmostEqual(end.x - start.x, 0.0, delta=0.01)
        self.assertGreater(end.y - start.y, 0.35)
        self.assertAlmostEqual(reported.y, 0.4, delta=0.004)  # within 1 %
        self.assertEqual(odometry.message.header.frame_id, "odom")

    def test_05_holonomic_base_sonars(self):
        front = rospy.wait_for_message("/holonomic/sonar_front", Range, timeout=WALL_TIMEOUT)
        rear = rospy.wait_for_message("/holonomic/sonar_rear", Range, timeout=WALL_TIMEOUT)
        self.figures.append(f"holonomic base sonars in the open: front {front.range:.3f} m (fov "
                            f"{front.field_of_view:.2f}), rear {rear.range:.3f} m (fov {rear.field_of_view:.2f})")
        self.assertEqual((front.radiation_type, front.max_range), (Range.ULTRASOUND, 3.0))
        self.assertAlmostEqual(front.field_of_view, 0.26, places=6)
        self.assertEqual((rear.header.frame_id, rear.max_range), ("sonar_rear_link", 3.0))
        self.assertAlmostEqual(rear.field_of_view, 0.1, places=6)
        # Nothing within 3 m (the ground is farther for their lowest rays): both read max_range.
        self.assertEqual((front.range, rear.range), (3.0, 3.0))

    def test_06_holonomic_base_reads_a_crate_ahead_and_bumps_into_it(self):
        bumper = Latest("/holonomic/bumper", ContactsState)
        start = self.get_model_state("holonomic_base", "world").pose.position
        wait_for(lambda: bumper.since(rospy.Time.now()), what="a bumper message")
        self.assertEqual(bumper.message.states, [])  # nothing touches it yet
        crate = Pose()
        crate.position.x, crate.position.y = start.x + 0.26 + CRATE_GAP + CRATE_SIZE[0] / 2, start.y
        crate.position.z, crate.orientation.w = CRATE_SIZE[2] / 2, 1.0
        spawn = rospy.ServiceProxy("/gazebo/spawn_sdf_model", SpawnModel)
        self.assertTrue(spawn("crate", CRATE_SDF, "", crate, "world").success)
        # Whatever happens, the crate goes again (the sonar test reads max_range in the open), after the base
        # has stopped (cleanups run last first).
        self.addCleanup(rospy.ServiceProxy("/gazebo/delete_model", DeleteModel), "crate")
        spawned = rospy.Time.now()
        front = Latest("/holonomic/sonar_front", Range)
        wait_for(lambda: len(front.since(spawned)) >= 5, what="five sonar readings of the crate")
        readings = sorted(message.range for message in front.since(spawned))
        median = readings[len(readings) // 2]
        self.figures.append(f"holonomic front sonar, crate {CRATE_GAP} m ahead: median {median:.4f} m of "
                            f"{len(readings)} readings (noise sigma 0.005)")
        self.assertAlmostEqual(median, CRATE_GAP, delta=0.01)

        command = rospy.Publisher("/holonomic/cmd_vel", Twist, queue_size=1)
        self.addCleanup(self.drive, 0.0, 0.3, command)
        twist = Twist()
        twist.linear.x = 0.5

        def touching():
            command.publish(twist)
            return next((state for message in bumper.since(spawned) for state in message.states), None)
        state = wait_for(touching, what="the bumper to touch the crate")
        collisions = (state.collision1_name, state.collision2_name)
        normal = state.contact_normals[0]
        self.figures.append(f"holonomic bumper: {collisions[0]} against {collisions[1]}, {len(state.contact_normals)} "
                            f"points, normal ({normal.x:.3f}, {normal.y:.3f}, {normal.z:.3f})")
        plate = "holonomic_base::base_footprint::base_footprint_fixed_joint_lump__bumper_link_collision"
        self.assertEqual(collisions, (plate, "crate::link::collision"))
        self.assertLess(normal.x, -0.99)  # from the crate back towards the base
        self.assertEqual(bumper.message.header.frame_id, "bumper_link")

    def test_07_skid_steer_base_drives_forward(self):
        command = rospy.Publisher("/skid/cmd_vel", Twist, queue_size=1)
        odometry = Latest("/skid/odom", Odometry)
        wait_for(lambda: command.get_num_connections() > 0 and odometry.message, what="the skid steer plugin")
        # The plugin keeps its last command (no timeout, as upstream's): stopped again whatever happens, so it
        # does not drive on into the other robots during the later tests.
        self.addCleanup(self.drive, 0.0, 0.3, command)
        self.drive(0.5, 1.5, command)
        state = self.get_model_state("skid_steer_base", "world")
        reported = odometry.message.twist.twist.linear.x
        self.figures.append(f"skid steer base at 0.5 m/s: {state.twist.linear.x:.3f} m/s, odometry {reported:.3f} m/s")
        self.assertAlmostEqual(state.twist.linear.x, 0.5, delta=0.025)
        self.assertAlmostEqual(reported, 0.5, delta=0.025)
        header = odometry.message.header
        self.assertEqual((header.frame_id, odometry.message.child_frame_id), ("odom", "base_footprint"))

    def test_08_tricycle_steers_as_its_kinematics_say(self):
        command = rospy.Publisher("/tricycle/cmd_vel", Twist, queue_size=1)
        odometry = Latest("/tricycle/odom", Odometry)
        wait_for(lambda: command.get_num_connections() > 0 and odometry.message, what="the tricycle plugin")
        self.addCleanup(self.drive, 0.0, 0.3, command)  # it too keeps its last command
        twist = Twist()
        twist.linear.x, twist.angular.z = 0.4, 0.3  # wheel speed, steering angle
        start = rospy.get_time()
        # The plugin keeps the last command; it is sent until 1.5 s of sim time have passed.
        wait_for(lambda: command.publish(twist) or rospy.get_time() > start + 1.5, what="1.5 s of sim time")
        reported = odometry.message.twist.twist
        expected_forward, expected_yaw_rate = 0.4 * math.cos(0.3), 0.4 * math.sin(0.3) / TRICYCLE_WHEELBASE
        self.figures.append(f"tricycle (0.4 m/s, steering 0.3 rad): odometry {reported.linear.x:.3f} m/s for "
                            f"{expected_forward:.3f}, {reported.angular.z:.3f} rad/s for {expected_yaw_rate:.3f}")
        self.assertAlmostEqual(reported.linear.x, expected_forward, delta=0.05 * expected_forward)
        self.assertAlmostEqual(reported.angular.z, expected_yaw_rate, delta=0.05 * expected_yaw_rate)
        header = odometry.message.header
        self.assertEqual((header.frame_id, odometry.message.child_frame_id), ("odom", "base_footprint"))
        joints = rospy.wait_for_message("/tricycle/joint_states", JointState, timeout=WALL_TIMEOUT)
        self.assertEqual(joints.name, ["front_steering_joint", "front_wheel_joint", "left_wheel_joint",
                                       "right_wheel_joint"])
        self.assertAlmostEqual(joints.position[0], 0.3, delta=0.005)

    def test_09_tricycle_block_laser_sees_the_ground(self):
        cloud = rospy.wait_for_message("/tricycle/block_cloud", PointCloud, timeout=WALL_TIMEOUT)
        # The lowest row's rays point 0.2 rad down: each meets the ground h / sin(0.2) away, whatever its yaw
        # (upstream places the point at the mid-angle of two rows, so the distance, not z, is the check).
        ground = BLOCK_LASER_HEIGHT / math.sin(0.2)
        lowest = [math.sqrt(point.x ** 2 + point.y ** 2 + point.z ** 2) for point in cloud.points[:64]]
        self.figures.append(f"tricycle block laser: {len(cloud.points)} points in 8 rows, the lowest row "
                            f"{min(lowest):.3f} to {max(lowest):.3f} m away (the ground {ground:.3f} m along it)")
        self.assertEqual((len(cloud.points), len(cloud.channels), cloud.header.frame_id), (512, 1, "laser_link"))
        self.assertEqual(len(cloud.channels[0].values), 512)
        for distance in lowest:
            self.assertAlmostEqual(distance, ground, delta=0.03)

    def test_10_stereo_head_publishes_both_cameras(self):
        infos = {side: rospy.wait_for_message(f"/stereo_head/stereo/{side}/camera_info", CameraInfo,
                                              timeout=WALL_TIMEOUT) for side in ("left", "right")}
        images = {side: rospy.wait_for_message(f"/stereo_head/stereo/{side}/image_raw", Image, timeout=WALL_TIMEOUT)
                  for side in ("left", "right")}
        fx = infos["right"].P[0]
        self.figures.append(f"stereo head: {images['left'].width}x{images['left'].height} {images['left'].encoding} "
                            f"pair, right P[3] {infos['right'].P[3]:.3f} (fx {fx:.1f})")
        self.assertEqual(infos["left"].P[3], 0.0)
        self.assertAlmostEqual(infos["right"].P[3], -fx * 0.07, places=6)
        for image in images.values():
            self.assertEqual((image.width, image.height, image.encoding, image.header.frame_id),
                             (320, 240, "rgb8", "left_camera_optical_frame"))

    def test_11_f3d_reports_an_applied_wrench(self):
        wrenches = Latest("/stereo_head/base_wrench", WrenchStamped)
        wait_for(lambda: wrenches.message, what="the f3d plugin")
        self.assertEqual(wrenches.message.wrench.force.z, 0.0)
        wrench = Wrench()
        wrench.force.z, wrench.torque.z = 50.0, 2.0
        apply = rospy.ServiceProxy("/gazebo/apply_body_wrench", ApplyBodyWrench)
        start = rospy.Time.now()
        response = apply(body_name="stereo_head::base_footprint", reference_frame="world", wrench=wrench,
                         duration=rospy.Duration(0.5))
        self.assertTrue(response.success, response.status_message)
        during = wait_for(lambda: next((message for message in wrenches.since(start) if message.wrench.force.z), None),
                          what="the applied wrench on the f3d topic")
        self.figures.append(f"f3d under a 50 N, 2 N·m apply_body_wrench: force z {during.wrench.force.z:.1f} N, "
                            f"torque z {during.wrench.torque.z:.2f} N·m")
        self.assertEqual((during.wrench.force.z, during.wrench.torque.z, during.header.frame_id), (50.0, 2.0, "world"))
        wait_for(lambda: rospy.Time.now() > start + rospy.Duration(0.6) and not wrenches.message.wrench.force.z,
                 what="the wrench to end after its 0.5 s")
        refused = apply(body_name="stereo_head::nowhere", wrench=wrench, duration=rospy.Duration(0.5))
        self.assertFalse(refused.success)
        self.assertIn("ApplyBodyWrench: body does not exist", refused.status_message)

    def test_12_ft_sensor_reads_the_head_weight(self):
        def head_at_rest():  # an applied wrench (test_11) sets the head moving for a while
            twist = self.get_model_state("stereo_head", "world").twist
            return math.hypot(twist.linear.x, twist.linear.y, twist.linear.z, twist.angular.x, twist.angular.y,
                              twist.angular.z) < 1e-3
        wait_for(head_at_rest, what="the stereo head at rest")
        reading = rospy.wait_for_message("/stereo_head/pan_wrench", WrenchStamped, timeout=WALL_TIMEOUT)
        force = reading.wrench.force
        self.figures.append(f"stereo head pan ft sensor: force ({force.x:.3f}, {force.y:.3f}, {force.z:.3f}) N for the "
                            f"0.5 kg head ({-0.5 * 9.8:.2f} N along z)")
        self.assertEqual(reading.header.frame_id, "head_link")
        self.assertAlmostEqual(force.z, -0.5 * 9.8, delta=0.02 * 0.5 * 9.8)
        self.assertAlmostEqual(math.hypot(force.x, force.y), 0.0, delta=0.02 * 0.5 * 9.8)


if __name__ == "__main__":
    rostest.rosrun("mbot_tests", "rover", Rover)
