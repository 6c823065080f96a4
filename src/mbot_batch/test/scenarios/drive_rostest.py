#!/usr/bin/env python3
"""drive.py as a rostest test node: the same second of driving, and a test case that wants the mbot moved."""
import unittest

import rospy
import rostest
from drive import drive
from mbot_batch import scenario


class Drive(unittest.TestCase):
    def test_the_mbot_moves_forward(self):
        metrics = drive(scenario.parameters())
        for name, value in metrics.items():
            scenario.metric(name, value)
        self.assertGreater(metrics["x"], 0.05)


if __name__ == "__main__":
    rospy.init_node("drive_test", disable_signals=True)
    rostest.rosrun("mbot_batch", "drive", Drive)
