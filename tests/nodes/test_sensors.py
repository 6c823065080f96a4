#!/usr/bin/env python3
"""The sensor set on its topics: the course's kinect (rgb, depth, cloud, camera_info; a wall at 1.5 m read
through the depth image and, after TF, through the cloud), the course's camera (image, camera_info, a red
plate where K says), and TurtleBot3-style IMUs with p3d ground truth."""
import math
import sys
import threading
import unittest
from types import SimpleNamespace

import numpy
import rospy
import rostest
import tf2_ros
from gazebo_msgs.srv import GetWorldProperties
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, Image, Imu, PointCloud2, Range

from sim_support import WALL_TIMEOUT, Simulator, model_state_service, wait_for, yaw_of

WALL_X = 1.65  # the wall's near face in the world (sensor_wall.world)
PLATE = (2.495, 4.4, 0.3)  # the red plate's near-face centre
SONAR_TO_WALL = 1.9 - 0.75  # sdf_wall's near face less the sonar's x (its model at 0.5, the sensor 0.25 ahead)
PENDULUM_HINGE = (0.0, -13.0, 2.1)  # model_1's link_1 frame, on its hinge; the model starts turned 30 degrees
# camera_link in base_footprint: base_link at z = 0.005/2 + 2 * 0.01975, camera 0.17 ahead, 0.10 above it.
CAMERA_IN_BASE = numpy.array([0.17, 0.0, 0.0025 + 0.0395 + 0.10])


class Collector:
    def __init__(self, topic, message_type):
        self.lock = threading.Lock()
        self.messages = []
        self.subscriber = rospy.Subscriber(topic, message_type, self.on_message, queue_size=5, buff_size=2 ** 26)

    def on_message(self, message):
        with self.lock:
            self.messages.append(message)
            del self.messages[:-40]

    def wait(self, count=1):
        wait_for(lambda: len(self.messages) >= count, what=f"{count} messages on {self.subscriber.name}")
        with self.lock:
            return list(self.messages)

    def read(self, count=1):
        """``wait``, then unsubscribe: a camera renders only while someone listens, and slows the tests after."""
        messages = self.wait(count)
        self.subscriber.unregister()
        return messages


class Kinect(unittest.TestCase):
    """kinect.test: the course's kinect robot alone, so that its TF tree is the odom one."""

    @classmethod
    def setUpClass(cls):
        rospy.init_node("kinect_test")
        cls.sim = Simulator()
        cls.tf = tf2_ros.Buffer()
        cls.tf_listener = tf2_ros.TransformListener(cls.tf)

    def test_kinect_topics_fields_and_rates(self):
        rgb, depth = Collector("/kinect/rgb/image_raw", Image), Collector("/kinect/depth/image_raw", Image)
        info = Collector("/kinect/rgb/camera_info", CameraInfo)
        images, depths, infos = rgb.wait(4), depth.wait(4), info.wait(4)
        image, info_message = images[-1], infos[-1]
        self.assertEqual((image.width, image.height, image.encoding), (640, 480, "rgb8"))
        self.assertEqual(image.header.frame_id, "kinect_frame_optical")
        self.assertEqual((depths[-1].encoding, depths[-1].step), ("32FC1", 640 * 4))
        self.assertAlmostEqual(info_message.K[0], 554.256, places=2)
        self.assertEqual((info_message.K[2], info_message.K[5]), (320.5, 240.5))
        depth_period = numpy.diff([m.header.stamp.to_sec() for m in depths]).min()
        info_period = numpy.diff([m.header.stamp.to_sec() for m in infos]).min()
        print(f"figure: kinect depth images every {depth_period:.3f} s of sim time, camera_info "
              f"every {info_period:.3f} s")
        self.assertAlmostEqual(depth_period, 0.05, places=3)
        self.assertAlmostEqual(info_period, 0.1, places=3)

    def test_wall_in_the_depth_image_and_in_the_cloud_through_tf(self):
        depth = Collector("/kinect/depth/image_raw", Image).wait(2)[-1]
        values = numpy.frombuffer(depth.data, dtype=numpy.float32).reshape(480, 640)
        centre = values[220:260, 300:340]
        cloud = Collector("/kinect/depth/points", PointCloud2).wait(2)[-1]
        points = numpy.frombuffer(cloud.data, dtype=numpy.float32).reshape(480, 640, 8)[..., :3]
        transform = self.tf.lookup_transform("odom", cloud.header.frame_id, cloud.header.stamp,
                                             rospy.Duration(WALL_TIMEOUT))
        t, q = transform.transform.translation, transform.transform.rotation
        rotation = quaternion_matrix((q.x, q.y, q.z, q.w))
        world = points[200:280:10, 280:360:10].reshape(-1, 3) @ rotation.T + (t.x, t.y, t.z)
        print(f"figure: kinect wall at 1.5 m: depth {numpy.nanmin(centre):.4f}..{numpy.nanmax(centre):.4f} m over the "
              f"centre; cloud points at x {world[:, 0].min():.4f}..{world[:, 0].max():.4f} m in "
              f"odom (wall at {WALL_X:.2f})")
        self.assertLess(numpy.nanmax(numpy.abs(centre - 1.5)), 0.01)
        self.assertLess(numpy.abs(world[:, 0] - WALL_X).max(), 0.01)
        self.assertEqual((cloud.point_step, cloud.width, cloud.height), (32, 640, 480))
        self.assertEqual([f.name for f in cloud.fields], ["x", "y", "z", "rgb"])


class CameraAndImu(unittest.TestCase):
    """sensors.test: the course's camera robot and an IMU robot, each in its own namespace, and the world
    file's own models with sensors and plugins (sensor_wall.world)."""

    @classmethod
    def setUpClass(cls):
        rospy.init_node("sensors_test")
        # No Simulator(): it drives /cmd_vel, and these robots listen in their own namespaces.
        cls.sim = SimpleNamespace(get_model_state=model_state_service())
        # The bridge offers its services one by one: get_model_state up does not mean get_world_properties is.
        rospy.wait_for_service("/gazebo/get_world_properties", timeout=WALL_TIMEOUT)
        properties = rospy.ServiceProxy("/gazebo/get_world_properties", GetWorldProperties)
        for model in ("camera_bot", "imu_bot"):
            wait_for(lambda: model in properties().model_names, what="model " + model)

    def test_camera_image_and_the_red_plate_where_k_says(self):
        # spawn_model's robot namespace comes first: NodeHandle("camera_bot" + "/" + "/camera"), as in Gazebo.
        image = Collector("/camera_bot/camera/image_raw", Image).read(1)[-1]
        info = Collector("/camera_bot/camera/camera_info", CameraInfo).read(1)[-1]
        self.assertEqual((image.width, image.height, image.encoding, image.header.frame_id),
                         (1280, 720, "rgb8", "camera_link"))
        self.assertAlmostEqual(info.K[0], 762.72, places=2)
        self.assertAlmostEqual(info.P[3], -762.72 * 0.07, places=2)
        pixels = numpy.frombuffer(image.data, dtype=numpy.uint8).reshape(720, 1280, 3).astype(int)
        red = (pixels[..., 0] > 150) & (pixels[..., 1] < 80) & (pixels[..., 2] < 80)
        rows, cols = numpy.nonzero(red)
        x, y, z = self.plate_in_camera()
        predicted = (info.K[0] * x / z + info.K[2], info.K[4] * y / z + info.K[5])
        error = math.hypot(cols.mean() - predicted[0], rows.mean() - predicted[1])
        print(f"figure: camera red plate predicted at ({predicted[0]:.1f}, {predicted[1]:.1f}) px, seen at "
              f"({cols.mean():.1f}, {rows.mean():.1f}) px: {error:.2f} px apart")
        self.assertGreater(red.sum(), 50)
        self.assertLess(error, 2.0)

    def plate_in_camera(self):
        """The plate's near-face centre in camera_link's optical convention (x right, y down, z forward)."""
        pose = self.sim.get_model_state("camera_bot", "world").pose
        q = pose.orientation
        rotation = quaternion_matrix((q.x, q.y, q.z, q.w))
        camera = numpy.array([pose.position.x, pose.position.y, pose.position.z]) + rotation @ CAMERA_IN_BASE
        local = rotation.T @ (numpy.asarray(PLATE) - camera)
        return -local[1], -local[2], local[0]

    def test_imus_and_ground_truth(self):
        imu = Collector("/imu_bot/imu", Imu).wait(20)
        sensor = Collector("/imu_bot/imu_sensor", Imu).wait(20)
        truth = Collector("/imu_bot/ground_truth", Odometry).wait(5)[-1]
        state = self.sim.get_model_state("imu_bot", "world")
        imu_period = numpy.diff([m.header.stamp.to_sec() for m in imu]).min()
        accel_z = numpy.mean([m.linear_acceleration.z for m in sensor])
        print(f"figure: imu_bot: libgazebo_ros_imu every {imu_period:.3f} s, frame {imu[-1].header.frame_id}, "
              f"acceleration z {imu[-1].linear_acceleration.z:.3f}; imu sensor acceleration z {accel_z:.3f} m/s^2, yaw "
              f"{yaw_of(sensor[-1].orientation):.4f} (truth {yaw_of(state.pose.orientation):.4f}); p3d x "
              f"{truth.pose.pose.position.x:.4f} (model state {state.pose.position.x:.4f})")
        self.assertAlmostEqual(imu_period, 0.01, places=3)
        self.assertEqual(imu[-1].header.frame_id, "base_footprint")  # sdformat renames the lumped imu_link
        self.assertEqual(sensor[-1].header.frame_id, "imu_link")
        self.assertLess(abs(imu[-1].linear_acceleration.z), 0.05)
        self.assertLess(abs(accel_z - 9.8), 3 * 0.017)
        self.assertLess(abs(yaw_of(sensor[-1].orientation) - 0.7), 0.01)
        self.assertEqual((truth.header.frame_id, truth.child_frame_id), ("world", "base_footprint"))
        self.assertAlmostEqual(truth.pose.pose.position.y, state.pose.position.y, places=3)

    def test_range_camera_and_p3d_of_the_world_files_own_models(self):
        """Models of the world file whose sensors and plugins run as a Gazebo user's would."""
        # Their plugins have no <robotNamespace>, so no model name is put in front: /sonar, /camera1/...
        sonar = Collector("/sonar", Range).read(3)
        image = Collector("/camera1/image_raw", Image).read(1)[-1]
        info = Collector("/camera1/camera_info", CameraInfo).read(1)[-1]
        poses = Collector("/model_1/link_1/pose", Odometry).read(40)
        ranges = [message.range for message in sonar]
        rolls = [2.0 * math.atan2(m.pose.pose.orientation.x, m.pose.pose.orientation.w) for m in poses]
        print(f"figure: sdf sonar {numpy.mean(ranges):.3f} m to the wall (geometry {SONAR_TO_WALL:.3f} m); camera1 "
              f"{image.width}x{image.height} {image.header.frame_id}; p3d link_1 roll from {min(rolls):.3f} to "
              f"{max(rolls):.3f} rad over {poses[-1].header.stamp.to_sec() - poses[0].header.stamp.to_sec():.2f} s")
        self.assertEqual((sonar[-1].header.frame_id, sonar[-1].radiation_type), ("sonar_link", Range.ULTRASOUND))
        self.assertLess(abs(numpy.mean(ranges) - SONAR_TO_WALL), 0.02)
        self.assertEqual((image.width, image.height, image.encoding, image.header.frame_id),
                         (320, 240, "rgb8", "camera_link"))
        self.assertAlmostEqual(info.K[0], 160.0 / math.tan(1.3962634 / 2.0), places=2)
        # The hinge stays put while the link swings through the upright, within its 30 degrees each way.
        for message in poses:
            position = message.pose.pose.position
            self.assertLess(math.dist((position.x, position.y, position.z), PENDULUM_HINGE), 1e-3)
        self.assertEqual(poses[-1].header.frame_id, "world")
        self.assertLess(max(abs(roll) for roll in rolls), 0.5236 + 0.01)
        self.assertGreater(max(rolls) - min(rolls), 0.05)


def quaternion_matrix(q):
    x, y, z, w = q
    return numpy.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


if __name__ == "__main__":
    case = Kinect if "Kinect" in sys.argv else CameraAndImu
    rostest.rosrun("mbot_tests", case.__name__.lower(), case, sys.argv)
