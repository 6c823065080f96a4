#!/usr/bin/env python3
"""Driven at 0.5 m/s into the play ground's jersey barrier, the mbot stops at it: it neither passes
through nor flies off."""
import math
import sys
import unittest

import rospy
import rostest

from sim_support import Simulator, roll_pitch_of, wait_for

BARRIER_NEAR_FACE_X = 5.0
BASE_RADIUS = 0.16  # the mbot's disc: its front is this far ahead of base_footprint


class Barrier(unittest.TestCase):
    def test_robot_stops_at_the_barrier(self):
        rospy.init_node("barrier_test")
        sim = Simulator()
        sim.command(0.5, 0.0)
        track = []

        def stalled():
            track.append(sim.truth())
            recent = [t for t in track if t[0] >= track[-1][0] - 1.0]
            return track[-1][0] > 3.0 and recent[-1][0] - recent[0][0] > 0.9 and \
                abs(recent[-1][1].position.x - recent[0][1].position.x) < 0.005
        wait_for(stalled, what="the robot to stop moving forward")
        sim.command(0.0, 0.0)
        furthest = max(pose.position.x for _, pose, _ in track)
        highest = max(abs(pose.position.z) for _, pose, _ in track)
        tilt = max(abs(a) for _, pose, _ in track for a in roll_pitch_of(pose.orientation))
        print(f"figure: barrier face at x={BARRIER_NEAR_FACE_X:.2f}: robot front reached "
              f"x={furthest + BASE_RADIUS:.3f}, |z| <= {highest:.4f} m, tilt <= {math.degrees(tilt):.2f} deg",
              file=sys.stderr)
        self.assertGreater(furthest + BASE_RADIUS, BARRIER_NEAR_FACE_X - 0.3, "it should reach the barrier")
        self.assertLess(furthest + BASE_RADIUS, BARRIER_NEAR_FACE_X + 0.01, "it must not pass through")
        self.assertLess(highest, 0.05, "it must stay on the ground")
        self.assertLess(math.degrees(tilt), 10.0, "it must not flip")


if __name__ == "__main__":
    rostest.rosrun("mbot_tests", "barrier", Barrier)
