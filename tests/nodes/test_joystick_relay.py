#!/usr/bin/env python3
"""joystick_relay.py: a joystick Twist scaled by the turbo step (joystick.yaml: four steps, the second at
start), the turbo and priority actions, joy_priority and its text marker, and invalid input (out of range, NaN,
inf) answered with a zero Twist and one error per kind. Run by test_twist_mux.py, on twist_mux.test's launch."""
import math
import unittest

import actionlib
import rospy
from geometry_msgs.msg import Twist
from rosgraph_msgs.msg import Log
from std_msgs.msg import Bool
from twist_mux_msgs.msg import JoyPriorityAction, JoyPriorityGoal, JoyTurboAction, JoyTurboGoal
from visualization_msgs.msg import Marker

from sim_support import WALL_TIMEOUT, init_test_node, twist, wait_for


class JoystickRelay(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        init_test_node("joystick_relay_test")
        cls.out, cls.priority, cls.errors = [], [], []
        rospy.Subscriber("joy_vel_out", Twist, cls.out.append)
        rospy.Subscriber("joy_priority", Bool, lambda message: cls.priority.append(message.data))
        rospy.Subscriber("/rosout", Log, lambda log: cls.errors.append(log.msg) if log.level >= Log.ERROR else None)
        cls.joystick = rospy.Publisher("joy_vel_in", Twist, queue_size=10)
        wait_for(lambda: cls.joystick.get_num_connections() > 0, what="joystick_relay to subscribe joy_vel_in")
        wait_for(lambda: cls.priority, what="the latched joy_priority")

    def relay(self, message):
        count = len(self.out)
        self.joystick.publish(message)
        wait_for(lambda: len(self.out) > count, what="joy_vel_out")
        return self.out[-1]

    def action(self, name, action_type, goal):
        client = actionlib.SimpleActionClient(name, action_type)
        self.assertTrue(client.wait_for_server(rospy.Duration(WALL_TIMEOUT)))
        client.send_goal_and_wait(goal, rospy.Duration(WALL_TIMEOUT))

    def test_1_scaled_by_the_turbo_step(self):
        self.assertEqual(self.priority[-1], True)
        self.assertEqual(rospy.wait_for_message("text_marker", Marker, timeout=WALL_TIMEOUT).text, "Manual")
        out = self.relay(twist(1.0, 0.5))
        # Step 2 of 4: forward 0.5 + (1.0 - 0.5) / 3, turning 0.7 + (1.2 - 0.7) / 3.
        self.assertAlmostEqual(out.linear.x, 0.5 + 0.5 / 3)
        self.assertAlmostEqual(out.angular.z, 0.5 * (0.7 + 0.5 / 3))
        self.assertAlmostEqual(self.relay(twist(-1.0)).linear.x, -(0.25 + 0.25 / 3))  # backward's own range
        self.action("joy_turbo_increase", JoyTurboAction, JoyTurboGoal())
        self.assertAlmostEqual(self.relay(twist(1.0)).linear.x, 0.5 + 1.0 / 3)
        self.action("joy_turbo_reset", JoyTurboAction, JoyTurboGoal())
        self.assertAlmostEqual(self.relay(twist(1.0)).linear.x, 0.5 + 0.5 / 3)

    def test_2_invalid_input_gives_a_zero_twist_and_one_error_per_kind(self):
        for _ in range(3):
            for bad in (twist(2.0), twist(math.nan), twist(0.0, math.inf)):
                self.assertEqual(self.relay(bad), Twist())
        wait_for(lambda: len([text for text in self.errors if "Joystick provided" in text]) >= 2,
                 what="the errors")
        rospy.sleep(0.2)
        self.assertEqual(len([text for text in self.errors if "Joystick provided" in text]), 2, self.errors)

    def test_3_priority_toggles(self):
        count = len(self.priority)
        self.action("joy_priority_action", JoyPriorityAction, JoyPriorityGoal())
        wait_for(lambda: len(self.priority) > count and self.priority[-1] is False, what="joy_priority false")
        sent = len(self.out)
        self.joystick.publish(twist(1.0))
        rospy.sleep(0.3)
        self.assertEqual(len(self.out), sent, "the relay forwarded without priority")
        self.action("joy_priority_action", JoyPriorityAction, JoyPriorityGoal())
        wait_for(lambda: self.priority[-1] is True and self.out and self.out[-1] == Twist(),
                 what="joy_priority true and a zero Twist")

