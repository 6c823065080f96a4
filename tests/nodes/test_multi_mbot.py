#!/usr/bin/env python3
"""Ten namespaced lidar mbots: their own topics and frames, their own cmd_vel, and scans that see the others."""
import math
import sys
import threading
import unittest

import rospy
import rostest
from gazebo_msgs.srv import GetWorldProperties
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan

from sim_support import WALL_TIMEOUT, model_state_service, wait_for, yaw_of

COUNT = 10
ROBOTS = [f"mbot_{index}" for index in range(1, COUNT + 1)]
LASER_X = 0.08  # laser_link ahead of base_footprint (mbot_with_laser_gazebo.xacro)
LIDAR_RADIUS = 0.05  # what another robot shows at the scan's height: its lidar's cylinder


class MultiMbot(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("multi_mbot_test")
        rospy.wait_for_service("/gazebo/get_world_properties", timeout=WALL_TIMEOUT)
        world = rospy.ServiceProxy("/gazebo/get_world_properties", GetWorldProperties)
        wait_for(lambda: set(ROBOTS) <= set(world().model_names), timeout=240, what=f"{COUNT} robots")
        cls.state = model_state_service()
        cls.lock = threading.Lock()
        cls.odom, cls.scans = {}, {}
        cls.subscribers = []
        for robot in ROBOTS:
            cls.subscribers.append(rospy.Subscriber(f"/{robot}/odom", Odometry, cls.keep(cls.odom, robot)))
            cls.subscribers.append(rospy.Subscriber(f"/{robot}/scan", LaserScan, cls.keep(cls.scans, robot)))
        wait_for(lambda: len(cls.odom) == COUNT and len(cls.scans) == COUNT, what="odom and scan of every robot")

    @classmethod
    def keep(cls, store, robot):
        def callback(message):
            with cls.lock:
                store[robot] = message
        return callback

    def test_topics_and_frames_are_per_robot(self):
        for robot in ROBOTS:
            with self.lock:
                odom, scan = self.odom[robot], self.scans[robot]
            self.assertEqual((odom.header.frame_id, odom.child_frame_id), (robot + "/odom", robot + "/base_footprint"))
            self.assertEqual(scan.header.frame_id, robot + "/laser_link")

    def at_rest(self, robot):
        with self.lock:
            twist = self.odom[robot].twist.twist
        return abs(twist.linear.x) < 1e-3 and abs(twist.angular.z) < 1e-3

    def test_each_scan_sees_its_nearest_neighbour(self):
        # The drive test leaves the robots turning down to rest: a scan taken while a robot still turned would not
        # match a pose read later. So compare poses with scans taken after every robot stands still.
        wait_for(lambda: all(self.at_rest(robot) for robot in ROBOTS), what="every robot at rest")
        settled = rospy.Time.now()
        wait_for(lambda: all(self.scans[robot].header.stamp > settled for robot in ROBOTS),
                 what="a scan of every robot taken at rest")
        poses = {robot: self.state(robot, "world").pose for robot in ROBOTS}
        lasers = {robot: (pose.position.x + LASER_X * math.cos(yaw_of(pose.orientation)),
                          pose.position.y + LASER_X * math.sin(yaw_of(pose.orientation)), yaw_of(pose.orientation))
                  for robot, pose in poses.items()}
        with self.lock:
            scans = dict(self.scans)
        worst, compared = 0.0, 0
        for robot in ROBOTS:
            x, y, heading = lasers[robot]
            scan = scans[robot]

            def bearing_of(other):
                dx, dy = lasers[other][0] - x, lasers[other][1] - y
                return math.atan2(math.sin(math.atan2(dy, dx) - heading), math.cos(math.atan2(dy, dx) - heading))
            # The nearest neighbour inside the course lidar's 6-rad fan: one in its 0.28 rad blind sector behind
            # cannot be seen, and any robot nearer along the beam would itself be the nearest in the fan.
            in_fan = [other for other in ROBOTS if other != robot
                      and scan.angle_min <= bearing_of(other) <= scan.angle_max]
            neighbour = min(in_fan, key=lambda other: math.hypot(lasers[other][0] - x, lasers[other][1] - y))
            bearing = bearing_of(neighbour)
            beam = int(round((bearing - scan.angle_min) / scan.angle_increment))
            measured = min(scan.ranges[max(0, beam - 2):beam + 3])
            error = measured - (math.hypot(lasers[neighbour][0] - x, lasers[neighbour][1] - y) - LIDAR_RADIUS)
            worst, compared = max(worst, abs(error)), compared + 1
            self.assertLess(abs(error), 0.06, f"{robot} sees {neighbour} at {measured:.3f} m along "
                                              f"{bearing:.2f} rad, {error:.3f} m off")
        print(f"figure: {COUNT} robots: {compared} scans find their nearest neighbour in the fan, "
              f"worst error {worst:.3f} m")
        self.assertEqual(compared, COUNT)

    def test_each_robot_drives_on_its_own_cmd_vel(self):
        rates = {robot: 0.1 * (index + 1) * (-1) ** index for index, robot in enumerate(ROBOTS)}
        publishers = {robot: rospy.Publisher(f"/{robot}/cmd_vel", Twist, queue_size=1, latch=True)
                      for robot in ROBOTS}
        try:
            for robot, publisher in publishers.items():
                wait_for(lambda: publisher.get_num_connections() > 0, what=f"/{robot}/cmd_vel subscribed")
                command = Twist()
                command.angular.z = rates[robot]
                publisher.publish(command)
            wait_for(lambda: all(abs(self.odom[robot].twist.twist.angular.z - rates[robot]) < 0.02
                                 for robot in ROBOTS), what="every robot turning at its own rate")
        finally:  # stopped whatever happened: the scan test waits for every robot at rest
            for publisher in publishers.values():
                publisher.publish(Twist())
        turning = ", ".join(f"{rate:.1f}" for rate in rates.values())
        print(f"figure: {COUNT} robots turning at {turning} rad/s on their own cmd_vel")


if __name__ == "__main__":
    rostest.rosrun("mbot_tests", "multi_mbot", MultiMbot, sys.argv)
