#!/usr/bin/env python3
"""marker_server: its marker (name, frame, controls for x, y and the turn), feedback to Twist with upstream's
scales and limits, the marker snapped back after each feedback, and bad poses (NaN, inf, a zero quaternion)
refused with one warning each while the node keeps serving. Run by test_twist_mux.py, on twist_mux.test's launch."""
import math
import time
import unittest

import rospy
from geometry_msgs.msg import Pose, Twist
from rosgraph_msgs.msg import Log
from visualization_msgs.msg import InteractiveMarkerFeedback, InteractiveMarkerInit, InteractiveMarkerUpdate

from sim_support import WALL_TIMEOUT, init_test_node, wait_for




def feedback(x=0.0, y=0.0, yaw=0.0, orientation=None):
    message = InteractiveMarkerFeedback(client_id="/rviz/InteractiveMarkers", marker_name="rover_twist_marker",
                                        event_type=InteractiveMarkerFeedback.POSE_UPDATE, pose=Pose())
    message.header.frame_id = "base_footprint"
    message.pose.position.x, message.pose.position.y = x, y
    q = message.pose.orientation
    q.x, q.y, q.z, q.w = orientation or (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))
    return message


class MarkerServer(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        init_test_node("marker_server_test")
        cls.twists, cls.updates, cls.warnings = [], [], []
        rospy.Subscriber("/twist_marker_server/cmd_vel", Twist, cls.twists.append)
        rospy.Subscriber("/twist_marker_server/update", InteractiveMarkerUpdate, cls.updates.append)
        rospy.Subscriber("/rosout", Log, lambda log: cls.warnings.append(log.msg) if log.level >= Log.WARN else None)
        cls.init = rospy.wait_for_message("/twist_marker_server/update_full", InteractiveMarkerInit,
                                          timeout=WALL_TIMEOUT)
        cls.feedback = rospy.Publisher("/twist_marker_server/feedback", InteractiveMarkerFeedback, queue_size=10)
        wait_for(lambda: cls.feedback.get_num_connections() > 0, what="marker_server to subscribe its feedback")
        # The server takes no feedback from a new client for a second after the marker's creation (the
        # interactive_markers rule against two clients dragging one marker): knock until it answers.
        wait_for(lambda: cls.feedback.publish(feedback()) or time.sleep(0.05) or cls.twists,
                 what="marker_server to take feedback")

    def send(self, message):
        count = len(self.twists)
        self.feedback.publish(message)
        return count

    def test_marker_as_upstream_builds_it(self):
        marker, = self.init.markers
        self.assertEqual((marker.name, marker.header.frame_id, marker.description),
                         ("rover_twist_marker", "base_footprint", "twist controller for rover"))
        self.assertEqual([control.name for control in marker.controls], ["move_x", "move_y", "rotate_z"])

    def test_feedback_becomes_a_clamped_twist_and_the_marker_snaps_back(self):
        updates = len(self.updates)
        count = self.send(feedback(x=0.4, y=-3.0, yaw=0.5))
        wait_for(lambda: len(self.twists) > count, what="the Twist for a feedback")
        twist = self.twists[-1]
        self.assertAlmostEqual(twist.linear.x, 0.4)
        self.assertAlmostEqual(twist.linear.y, -1.0)  # scale 1, clamped at max_negative -1
        self.assertAlmostEqual(twist.angular.z, 1.1)  # 2.2 per radian
        count = self.send(feedback(yaw=-1.0))
        wait_for(lambda: len(self.twists) > count, what="the Twist for a turn")
        self.assertAlmostEqual(self.twists[-1].angular.z, -1.5)  # max_angular_velocity
        wait_for(lambda: any(update.poses and update.poses[-1].pose.orientation.w == 1.0
                             for update in self.updates[updates:]), what="the marker's pose set back to the robot")

    def test_bad_poses_are_refused_once_each_and_the_server_keeps_serving(self):
        bad = [feedback(x=math.nan), feedback(x=math.inf), feedback(orientation=(0.0, 0.0, 0.0, 0.0)),
               feedback(orientation=(0.0, 0.0, 1e200, 1e200))]
        count = len(self.twists)
        for _ in range(3):
            for message in bad:
                self.feedback.publish(message)
        self.send(feedback(x=1e308))
        wait_for(lambda: len(self.twists) > count, what="the Twist of a huge but finite pose")
        self.assertEqual([twist.linear.x for twist in self.twists[count:]], [1.0])
        wait_for(lambda: len([text for text in self.warnings if "no Twist sent" in text]) >= 4,
                 what="a warning for each kind of bad pose")
        time.sleep(0.2)
        complaints = [text for text in self.warnings if "no Twist sent" in text]
        self.assertEqual(len(complaints), 4, complaints)
        count = self.send(feedback(x=-1e308))
        wait_for(lambda: len(self.twists) > count, what="the clamped Twist of a second huge pose")
        self.assertEqual(self.twists[-1].linear.x, -1.0)
        wait_for(lambda: [text for text in self.warnings if "clamped" in text], what="the huge offset said")
        self.assertEqual(len([text for text in self.warnings if "clamped" in text]), 1)

