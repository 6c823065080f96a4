#!/usr/bin/env python3
"""A third-party Gazebo robot package (tests/third_party, TurtleBot3's layout), launched unchanged: its world's
model comes through the package's gazebo_model_path export, /scan sees it, /odom and TF flow, /cmd_vel drives,
and TurtleBot3's IMU block gives /imu a message for every 1 ms step."""
import math
import threading
import unittest

import rospy
import rostest
import tf2_ros
from geometry_msgs.msg import Twist, Vector3
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu, LaserScan

from sim_support import Simulator, wait_for

SPAWN_X = -1.0  # minibot_world.launch's x_pos
# Range from the lidar to the pillars of model://minibot_pillars (tests/third_party/minibot_gazebo/models).
ROUND_PILLAR = (0.0, 0.9)  # (beam angle, range): a cylinder of radius 0.1 at the origin
SQUARE_PILLAR = (math.pi / 2, 1.1)  # a 0.2 m box at (-1.0, 1.2)


class ThirdPartyWorld(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("third_party_world_test")
        cls.sim = Simulator(model="minibot")
        cls.lock = threading.Lock()
        cls.scan, cls.odom = [None], [None]
        rospy.Subscriber("/scan", LaserScan, lambda message: cls.keep(cls.scan, message))
        rospy.Subscriber("/odom", Odometry, lambda message: cls.keep(cls.odom, message))

    @classmethod
    def keep(cls, slot, message):
        with cls.lock:
            slot[0] = message

    def latest(self, slot):
        with self.lock:
            return slot[0]

    def range_at(self, scan, angle):
        index = int(round((angle - scan.angle_min) / scan.angle_increment))
        return scan.ranges[index]

    def test_1_scan_sees_the_exported_model(self):
        scan = wait_for(lambda: self.latest(self.scan), what="/scan")
        for name, (angle, expected) in (("round pillar", ROUND_PILLAR), ("square pillar", SQUARE_PILLAR)):
            measured = self.range_at(scan, angle)
            print(f"figure: minibot lidar, {name} at {math.degrees(angle):.0f} deg: {measured:.3f} m "
                  f"(world: {expected:.2f} m)")
            self.assertAlmostEqual(measured, expected, delta=0.05, msg=name)
        self.assertEqual(self.range_at(scan, math.pi), float("inf"), "nothing behind the robot within 3.5 m")

    def test_2_odom_and_tf_flow_and_cmd_vel_drives(self):
        odom = wait_for(lambda: self.latest(self.odom), what="/odom")
        self.assertEqual((odom.header.frame_id, odom.child_frame_id), ("odom", "base_footprint"))
        self.assertAlmostEqual(odom.pose.pose.position.x, SPAWN_X, delta=0.02)
        buffer = tf2_ros.Buffer()
        listener = tf2_ros.TransformListener(buffer)
        wait_for(lambda: buffer.can_transform("odom", "base_footprint", rospy.Time(0)), what="TF odom -> base")
        del listener
        self.sim.cmd_vel.publish(Twist(linear=Vector3(x=0.2)))
        wait_for(lambda: self.latest(self.odom).pose.pose.position.x > SPAWN_X + 0.2, what="the robot to drive")
        self.sim.cmd_vel.publish(Twist())

    def test_3_imu_at_every_step(self):
        received = []
        subscriber = rospy.Subscriber("/imu", Imu, received.append)  # an unbounded queue: none dropped
        wait_for(lambda: len(received) >= 500, what="500 /imu messages")
        subscriber.unregister()
        stamps = [message.header.stamp.to_sec() for message in received[:500]]
        gaps = {round(b - a, 6) for a, b in zip(stamps, stamps[1:])}
        at_rest = received[-1]
        print(f"figure: minibot /imu (TurtleBot3's block, updateRate 0): 500 messages, gaps between stamps "
              f"{sorted(gaps)} s, frame {at_rest.header.frame_id}, linear_acceleration.z "
              f"{at_rest.linear_acceleration.z:.4f}")
        self.assertEqual(gaps, {0.001}, "a message for every 1 ms step, none missing")
        self.assertEqual(at_rest.header.frame_id, "base_footprint")  # sdformat renames the lumped imu_link
        self.assertLess(abs(at_rest.orientation.z), 0.01)  # spawned facing +x
        self.assertEqual([message.header.seq for message in received[:500]],
                         list(range(received[0].header.seq, received[0].header.seq + 500)))


if __name__ == "__main__":
    rostest.rosrun("mbot_tests", "third_party_world", ThirdPartyWorld)
