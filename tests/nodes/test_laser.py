#!/usr/bin/env python3
"""/scan from the course's rplidar: message fields, rate and stamps in sim time, range to a known wall,
and the beam direction convention (a 90 degree turn moves the wall 90 degrees across the beams)."""
import math
import sys
import threading
import unittest

import numpy
import rospy
import rostest
from gazebo_msgs.msg import ModelState
from gazebo_msgs.srv import SetModelState
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan

from sim_support import Simulator, wait_for

WALL_DISTANCE = 2.0  # from laser_link to the wall's near face, laser_wall.world
SCAN_RATE = 5.5


class Laser(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("laser_test")
        cls.sim = Simulator()
        cls.lock = threading.Lock()
        cls.scans, cls.clock = [], [0.0]
        rospy.Subscriber("/clock", Clock, cls.on_clock)
        rospy.Subscriber("/scan", LaserScan, cls.on_scan)

    @classmethod
    def on_clock(cls, message):
        with cls.lock:
            cls.clock[0] = max(cls.clock[0], message.clock.to_sec())

    @classmethod
    def on_scan(cls, message):
        with cls.lock:
            cls.scans.append(message)

    def scans_after(self, count, start=0.0):
        wait_for(lambda: len([s for s in self.scans if s.header.stamp.to_sec() > start]) >= count,
                 what=f"{count} scans")
        with self.lock:
            return [s for s in self.scans if s.header.stamp.to_sec() > start]

    def test_fields_are_as_gazebo_fills_them(self):
        scan = self.scans_after(1)[-1]
        self.assertEqual(scan.header.frame_id, "laser_link")
        self.assertEqual(len(scan.ranges), 360)
        self.assertAlmostEqual(scan.angle_min, -3.0, places=6)
        self.assertAlmostEqual(scan.angle_max, 3.0, places=6)
        self.assertAlmostEqual(scan.angle_increment, 6.0 / 359, places=6)
        self.assertEqual((scan.time_increment, scan.scan_time), (0.0, 0.0))
        self.assertAlmostEqual(scan.range_min, 0.1, places=6)
        self.assertAlmostEqual(scan.range_max, 6.0, places=6)
        # Nothing behind the robot in this world: those beams read +inf, Gazebo's no-hit value.
        self.assertTrue(math.isinf(scan.ranges[0]) and scan.ranges[0] > 0)

    def test_rate_in_sim_time_and_stamps_follow_clock(self):
        scans = self.scans_after(23)
        stamps = numpy.array([s.header.stamp.to_sec() for s in scans])
        rate = (len(stamps) - 1) / (stamps[-1] - stamps[0])
        print(f"figure: scan rate {rate:.4f} Hz in sim time over {len(stamps)} scans (expected {SCAN_RATE:.1f})",
              file=sys.stderr)
        self.assertAlmostEqual(rate, SCAN_RATE, delta=0.02 * SCAN_RATE)
        self.assertTrue(numpy.all(numpy.diff(stamps) > 0), "stamps must advance")
        # Stamps are sim time: /clock has been there (topics arrive on separate connections, so only the
        # latest clock is compared), and each stamp falls on the 1 ms physics step.
        wait_for(lambda: self.clock[0] >= stamps[-1], what="/clock to reach the last scan stamp")
        self.assertTrue(numpy.allclose(numpy.round(stamps * 1000.0), stamps * 1000.0, atol=1e-6))

    def test_range_to_a_flat_wall(self):
        scan = self.scans_after(1)[-1]
        angles = scan.angle_min + numpy.arange(len(scan.ranges)) * scan.angle_increment
        ahead = numpy.abs(angles) < 0.3
        # The hit distance along a beam at angle a to the wall's normal is d / cos(a).
        errors = numpy.array(scan.ranges)[ahead] - WALL_DISTANCE / numpy.cos(angles[ahead])
        print(f"figure: wall at {WALL_DISTANCE:.2f} m: mean error {errors.mean():.4f} m, std {errors.std(ddof=1):.4f} "
              f"m over {ahead.sum()} beams", file=sys.stderr)
        self.assertLess(abs(errors.mean()), 0.005)
        self.assertLess(errors.std(ddof=1), 0.02)

    def test_turning_ninety_degrees_moves_the_wall_ninety_degrees_clockwise_in_the_scan(self):
        set_state = rospy.ServiceProxy("/gazebo/set_model_state", SetModelState)
        state = ModelState(model_name="mbot", reference_frame="world")
        state.pose.orientation.z, state.pose.orientation.w = math.sin(math.pi / 4), math.cos(math.pi / 4)
        try:
            self.assertTrue(set_state(state).success)
            turned_at = self.sim.truth()[0]
            scan = self.scans_after(2, start=turned_at)[-1]
            ranges = numpy.array(scan.ranges)
            angles = scan.angle_min + numpy.arange(len(ranges)) * scan.angle_increment
            # The 10 m wall is seen over a span of beams symmetric about its normal; the span's middle is the
            # wall's direction, which noise cannot move the way it moves a single nearest beam.
            angle = angles[numpy.isfinite(ranges)].mean()
            print(f"figure: after a +90 degree turn the wall is centred at {math.degrees(angle):.1f} degrees",
                  file=sys.stderr)
            # Beams count counter-clockwise from angle_min, so the wall, now on the robot's right, is at -90 degrees.
            self.assertAlmostEqual(angle, -math.pi / 2, delta=2.5 * scan.angle_increment)
        finally:  # the other tests expect the mbot facing the wall, whichever order they run in
            state.pose.orientation.z, state.pose.orientation.w = 0.0, 1.0
            self.assertTrue(set_state(state).success)


if __name__ == "__main__":
    rostest.rosrun("mbot_tests", "laser", Laser)
