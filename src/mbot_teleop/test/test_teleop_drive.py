#!/usr/bin/env python3
"""Keys typed into mbot_teleop.py drive the simulated mbot; run by teleop_drive.test.

Holding ``i`` moves the robot along +x in /odom, holding ``j`` turns it
counter-clockwise, and CTRL-C leaves it standing still. Durations are sim time.
"""

import math
import os
import threading
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry

from teleop_harness import PtyProcess, TwistRecorder, source_env, teleop_command, wait_until

SIM_TIMEOUT = 90.0  # wall s for the simulator to publish /odom
STEP_TIMEOUT = 30.0  # wall s
KEY_REPEAT = 1.0 / 30  # s: a held key repeats at about this period on a typical keyboard
STILL = 0.01  # m/s and rad/s
# The teleop's default speeds (the course's 0.2 m/s and 1.0 rad/s). Holding a key reaches them after ten key repeats
# of ramp (1/3 s) plus the diff drive's wheelAcceleration (1.8 m/s^2: 0.11 s to 0.2 m/s): RAMP_ALLOWANCE of sim
# time covers both with room for a loaded machine that delivers keys late.
SPEED = 0.2
TURN = 1.0
RAMP_ALLOWANCE = 0.6  # s


def _yaw(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


class TestTeleopDrive(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        rospy.init_node('teleop_drive_test')
        cls._odom = None
        cls._lock = threading.Lock()
        cls._odom_sub = rospy.Subscriber('/odom', Odometry, cls._store_odom)
        if not wait_until(cls._latest, SIM_TIMEOUT):
            raise AssertionError(f'no /odom within {SIM_TIMEOUT} s')
        cls.commands = TwistRecorder('/cmd_vel', os.environ)
        cls.teleop = PtyProcess(teleop_command(), source_env())
        if not wait_until(lambda: len(cls.commands), STEP_TIMEOUT):
            cls.tearDownClass()
            raise AssertionError('mbot_teleop published nothing on /cmd_vel')

    @classmethod
    def tearDownClass(cls):
        cls.teleop.close()
        cls.commands.close()
        cls._odom_sub.unregister()

    @classmethod
    def _store_odom(cls, msg):
        with cls._lock:
            cls._odom = msg

    @classmethod
    def _latest(cls):
        with cls._lock:
            return cls._odom

    def pose(self):
        odom = self._latest()
        position = odom.pose.pose.position
        return position.x, position.y, _yaw(odom.pose.pose.orientation)

    def hold(self, key, sim_seconds):
        """Repeat key as a held key does, for sim_seconds of sim time; the odometry's twist at the end."""
        start = rospy.get_time()
        while rospy.get_time() - start < sim_seconds:
            self.teleop.send(key)
            time.sleep(KEY_REPEAT)  # the keyboard's repeat rate, not a wait for anything
        return self._latest().twist.twist

    def wait_still(self):
        def still():
            twist = self._latest().twist.twist
            return abs(twist.linear.x) < STILL and abs(twist.angular.z) < STILL
        self.assertTrue(wait_until(still, STEP_TIMEOUT), 'the robot did not come to rest')

    def test_1_holding_i_drives_forward(self):
        x0, y0, yaw0 = self.pose()
        start = rospy.get_time()
        twist = self.hold('i', 3.0)
        self.teleop.send(' ')
        self.wait_still()
        x, y, yaw = self.pose()
        elapsed = rospy.get_time() - start
        print(f'figure: holding i for 3 s: {twist.linear.x:.3f} m/s at the end, {x - x0:.3f} m in {elapsed:.2f} s')
        # A diff drive on flat ground reaches its command: the held speed is the teleop's.
        self.assertAlmostEqual(twist.linear.x, SPEED, delta=0.01)
        # 0.2 m/s for 3 s less the ramp; never faster than 0.2 m/s over the whole time it moved.
        self.assertGreater(x - x0, SPEED * (3.0 - RAMP_ALLOWANCE))
        self.assertLess(x - x0, SPEED * elapsed)
        self.assertLess(abs(y - y0), 0.1)
        self.assertLess(abs(math.remainder(yaw - yaw0, math.tau)), 0.1)

    def test_2_holding_j_turns_counter_clockwise(self):
        x0, y0, yaw0 = self.pose()
        start = rospy.get_time()
        # At 1 rad/s, 1.5 s stays below half a turn, so the yaw change cannot wrap.
        twist = self.hold('j', 1.5)
        self.teleop.send(' ')
        self.wait_still()
        x, y, yaw = self.pose()
        elapsed, turned = rospy.get_time() - start, math.remainder(yaw - yaw0, math.tau)
        print(f'figure: holding j for 1.5 s: {twist.angular.z:.3f} rad/s at the end, {turned:.3f} rad in '
              f'{elapsed:.2f} s')
        self.assertAlmostEqual(twist.angular.z, TURN, delta=0.05)
        self.assertGreater(turned, TURN * (1.5 - RAMP_ALLOWANCE))
        self.assertLess(turned, TURN * elapsed)
        # The wheels sit 0.09 m ahead of base_footprint, so turning on the spot swings the
        # footprint along a circle of that radius: it stays within its diameter.
        self.assertLess(math.hypot(x - x0, y - y0), 0.2)

    def test_3_ctrl_c_leaves_the_robot_standing(self):
        self.hold('i', 1.0)
        self.teleop.send('\x03')
        self.assertEqual(self.teleop.proc.wait(timeout=STEP_TIMEOUT), 0)
        last_is_zero = wait_until(lambda: self.commands.commands()[-1:] == [(0.0, 0.0)],
                                  STEP_TIMEOUT)
        self.assertTrue(last_is_zero, 'no zero Twist after CTRL-C')
        # The diff drive keeps its last command, so this needs the teleop's zero Twist.
        self.wait_still()
        self.assertEqual(self.teleop.mode(), self.teleop.initial_mode)


if __name__ == '__main__':
    rostest.rosrun('mbot_teleop', 'teleop_drive', TestTeleopDrive)
