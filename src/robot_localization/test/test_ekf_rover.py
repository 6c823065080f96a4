#!/usr/bin/env python3
"""ekf_localization_node live (see ekf_rover.test)."""
import math
import os
import sys
import threading
import unittest

import rospkg
import rospy
import rostest
import tf2_ros
from geometry_msgs.msg import PoseWithCovarianceStamped, Twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Log
from sensor_msgs.msg import Imu

from robot_localization.srv import SetPose

# The workspace's rostest helpers (waiting on conditions, yaw of a quaternion) live in mbot_tests' nodes.
sys.path.insert(0, os.path.join(rospkg.RosPack().get_path("mbot_tests"), "nodes"))
from sim_support import WALL_TIMEOUT, model_state_service, wait_for, yaw_of  # noqa: E402

# The node runs Clearpath's configuration with smooth_lagged_data: on a loaded machine its callbacks run late,
# and without smoothing data arriving after sensor_timeout (1/frequency here) is fused after the prediction went
# past its stamp, as upstream does, losing the motion in between (up to 9.4 % of this drive seen live). With it,
# live runs ended 0.8 to 3.5 % of the distance from the ground truth under a load average of 17 to 19 on two
# cores. The 2 % acceptance, with Clearpath's configuration unchanged, is checked on the recorded 11 m drive
# (test/unit/test_rover_drive.py).
ACCEPTED_FRACTION = 0.06


def finite(odometry):
    pose, twist = odometry.pose.pose, odometry.twist.twist
    return all(math.isfinite(value) for value in (
        pose.position.x, pose.position.y, pose.orientation.z, pose.orientation.w, twist.linear.x, twist.angular.z,
        *odometry.pose.covariance))


class Latest:
    def __init__(self, topic, message_type):
        self.message, self.count = None, 0
        rospy.Subscriber(topic, message_type, self.store, queue_size=10)

    def store(self, message):
        self.message, self.count = message, self.count + 1


class EkfRover(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("ekf_rover_test")
        cls.filtered, cls.bad_filtered = Latest("/odometry/filtered", Odometry), Latest("/bad/odometry/filtered",
                                                                                       Odometry)
        cls.logs = []
        rospy.Subscriber("/rosout", Log, cls.logs.append, queue_size=100)
        cls.get_model_state = model_state_service()
        cls.tf_buffer = tf2_ros.Buffer()
        cls.tf_listener = tf2_ros.TransformListener(cls.tf_buffer)
        cls.cmd_vel = rospy.Publisher("/rover_velocity_controller/cmd_vel", Twist, queue_size=1)
        wait_for(lambda: cls.cmd_vel.get_num_connections() > 0, what="the controller to subscribe cmd_vel")
        wait_for(lambda: cls.filtered.message, what="odometry/filtered")
        # Spawned with its wheels in the ground, as Husky is: wait until it has landed and stopped.
        wait_for(cls.at_rest, what="the rover to come to rest on its wheels")

    @classmethod
    def at_rest(cls):
        state = cls.get_model_state("rover", "world")
        speed = math.hypot(state.twist.linear.x, state.twist.linear.y, state.twist.linear.z)
        return abs(state.pose.position.z - 0.132) < 0.01 and speed < 0.01

    def truth(self):
        pose = self.get_model_state("rover", "world").pose
        return pose.position.x, pose.position.y, yaw_of(pose.orientation)

    def keep_commanding(self, twist, stop):
        """Publish ``twist`` every 20 ms of wall time until ``stop`` is set, whatever the main thread waits on
        (the controller stops the rover after 0.25 s without a command)."""
        while not stop.is_set():
            self.cmd_vel.publish(twist)
            rospy.rostime.wallsleep(0.02)

    def test_01_filtered_odometry_and_its_transform(self):
        message = self.filtered.message
        self.assertEqual((message.header.frame_id, message.child_frame_id), ("odom", "base_link"))
        self.assertTrue(finite(message))
        stamp = message.header.stamp
        transform = wait_for(lambda: self.tf_buffer.can_transform("odom", "base_link", stamp) and
                             self.tf_buffer.lookup_transform("odom", "base_link", stamp), what="odom -> base_link")
        self.assertEqual(transform.header.stamp, stamp)
        self.assertAlmostEqual(transform.transform.translation.x, message.pose.pose.position.x, places=6)
        self.assertAlmostEqual(transform.transform.rotation.z, message.pose.pose.orientation.z, places=6)

    def test_02_follows_the_ground_truth_over_a_drive_with_a_turn(self):
        # The filter's odom frame is where the rover started: compare displacements from here.
        start_truth, start = self.truth(), self.filtered.message.pose.pose
        start_yaw = yaw_of(start.orientation)
        path, last = 0.0, start_truth[:2]
        twist, stop = Twist(), threading.Event()
        commander = threading.Thread(target=self.keep_commanding, args=(twist, stop))
        commander.start()
        try:
            for linear, angular, seconds in ((0.5, 0.0, 3.0), (0.5, 0.5, 3.0), (0.5, 0.0, 2.0), (0.0, 0.0, 1.5)):
                twist.linear.x, twist.angular.z = linear, angular
                end = rospy.get_time() + seconds
                while rospy.get_time() < end:
                    rospy.sleep(0.1)
                    x, y, _ = self.truth()
                    path, last = path + math.hypot(x - last[0], y - last[1]), (x, y)
        finally:
            stop.set()
            commander.join()
        stopped, end_truth = rospy.Time.now(), self.truth()
        final = wait_for(lambda: self.filtered.message.header.stamp >= stopped and self.filtered.message,
                         what="the filter to catch up with the stop").pose.pose
        # Ground truth displacement, turned into the frame the filter started in.
        dx, dy = end_truth[0] - start_truth[0], end_truth[1] - start_truth[1]
        turn = start_yaw - start_truth[2]
        expected = (start.position.x + dx * math.cos(turn) - dy * math.sin(turn),
                    start.position.y + dx * math.sin(turn) + dy * math.cos(turn))
        error = math.hypot(final.position.x - expected[0], final.position.y - expected[1])
        yaw_error = math.remainder(yaw_of(final.orientation) - (end_truth[2] + turn), math.tau)
        print(f"\nfigure: live rover drive {path:.2f} m: filtered pose {error:.3f} m ({100 * error / path:.2f} %) "
              f"from ground truth, yaw {yaw_error:+.4f} rad")
        self.assertGreater(path, 3.0)
        self.assertLess(error, ACCEPTED_FRACTION * path)

    def test_03_set_pose_service_and_topic(self):
        request = PoseWithCovarianceStamped()
        request.header.frame_id = "odom"
        request.header.stamp = rospy.Time.now()
        request.pose.pose.position.x, request.pose.pose.position.y = 5.0, -2.0
        request.pose.pose.orientation.z, request.pose.pose.orientation.w = math.sin(0.5), math.cos(0.5)
        rospy.wait_for_service("/set_pose", timeout=WALL_TIMEOUT)
        rospy.ServiceProxy("/set_pose", SetPose)(request)
        # The latest message may still be one the filter built before the call.
        moved = wait_for(lambda: abs(self.filtered.message.pose.pose.position.x - 5.0) < 0.05 and
                         self.filtered.message, what="odometry/filtered at the pose set")
        self.assertAlmostEqual(moved.pose.pose.position.y, -2.0, delta=0.05)
        self.assertAlmostEqual(yaw_of(moved.pose.pose.orientation), 1.0, delta=0.02)

    def test_04_nan_inf_and_huge_inputs_keep_the_node_running(self):
        odometry = rospy.Publisher("/bad/odom", Odometry, queue_size=10)
        imu = rospy.Publisher("/bad/imu", Imu, queue_size=10)
        set_pose = rospy.Publisher("/bad/set_pose", PoseWithCovarianceStamped, queue_size=10)
        wait_for(lambda: odometry.get_num_connections() and imu.get_num_connections() and
                 set_pose.get_num_connections(), what="the second node to subscribe")
        for round, bad in enumerate([0.0, 0.0, math.nan, math.inf, -math.inf, 1e300, math.nan, 1e300] * 2):
            stamp = rospy.Time.now()
            odom = Odometry()
            odom.header.stamp, odom.header.frame_id, odom.child_frame_id = stamp, "bad_odom", "bad_base_link"
            odom.pose.pose.orientation.w = 1.0
            odom.twist.twist.linear.x, odom.twist.twist.angular.z = (0.5, 0.1) if bad == 0.0 else (bad, 0.1)
            odom.twist.covariance = [0.01 if i % 7 == 0 else 0.0 for i in range(36)]
            if round % 2:
                odom.twist.covariance[35] = bad
            reading = Imu()
            reading.header.stamp, reading.header.frame_id = stamp, "bad_base_link"
            reading.orientation.w = 1.0 if bad == 0.0 else bad
            reading.angular_velocity.z = 0.1
            reading.orientation_covariance = [bad if bad != 0.0 else 1e-3, 0, 0, 0, 1e-3, 0, 0, 0, 1e-3]
            reading.angular_velocity_covariance = [1e-3, 0, 0, 0, 1e-3, 0, 0, 0, 1e-3 if bad == 0.0 else bad]
            odometry.publish(odom)
            imu.publish(reading)
            rospy.rostime.wallsleep(0.05)
            wait_for(lambda: rospy.Time.now() > stamp, what="sim time to advance")
        bad_pose = PoseWithCovarianceStamped()
        bad_pose.header.stamp = rospy.Time.now()
        bad_pose.pose.pose.position.x, bad_pose.pose.pose.orientation.w = math.nan, 1.0
        set_pose.publish(bad_pose)
        count = self.bad_filtered.count
        wait_for(lambda: self.bad_filtered.count > count + 5, what="the second node to keep publishing")
        self.assertTrue(finite(self.bad_filtered.message))
        lines = [log.msg for log in self.logs if log.name == "/bad/ekf_bad_input" and log.level >= Log.WARN]
        for topic in ("odom0_twist", "imu0_twist", "set_pose"):
            said = [line for line in lines if line.startswith(topic + ":")]
            self.assertEqual(len(said), 1, f"{topic}: {lines}")

    def test_05_odometry_stamped_far_ahead_is_said_once_and_the_node_keeps_publishing(self):
        """Upstream queues such data and stops predicting until the clock reaches it (100 s here)."""
        odometry = rospy.Publisher("/bad/odom", Odometry, queue_size=10)
        wait_for(lambda: odometry.get_num_connections(), what="the second node to subscribe")
        for _ in range(20):
            odom = Odometry()
            odom.header.stamp = rospy.Time.now() + rospy.Duration(100.0)
            odom.header.frame_id, odom.child_frame_id = "bad_odom", "bad_base_link"
            odom.pose.pose.orientation.w = 1.0
            odom.twist.covariance = [0.01 if i % 7 == 0 else 0.0 for i in range(36)]
            odometry.publish(odom)
            rospy.rostime.wallsleep(0.05)
        count = self.bad_filtered.count
        wait_for(lambda: self.bad_filtered.count > count + 5, what="the second node to keep publishing")
        self.assertLess(abs((rospy.Time.now() - self.bad_filtered.message.header.stamp).to_sec()), 1.0)
        lines = [log.msg for log in self.logs if log.name == "/bad/ekf_bad_input" and "s ahead" in log.msg]
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("odom0 (/bad/odom)", lines[0])


if __name__ == "__main__":
    rostest.rosrun("robot_localization", "ekf_rover", EkfRover)
