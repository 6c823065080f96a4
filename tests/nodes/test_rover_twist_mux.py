#!/usr/bin/env python3
"""The rover through twist_mux, as a Clearpath base is driven: /cmd_vel (priority 1) moves it at the commanded
speed; the joystick's topic (priority 10) overrides /cmd_vel and /cmd_vel takes over again 0.5 s after the
joystick stops; true on /e_stop (priority 255) stops it from 0.15 m/s within 0.1 s of sim time while /cmd_vel
keeps coming, and false lets /cmd_vel drive again; feedback of the rviz twist marker drives it through the
marker server."""
import math
import unittest

import rospy
import rostest
from gazebo_msgs.msg import ModelStates
from geometry_msgs.msg import Pose, Twist
from std_msgs.msg import Bool
from visualization_msgs.msg import InteractiveMarkerFeedback

from sim_support import print_figures, publish_for, twist, wait_for, wait_for_running_controllers, yaw_of

CONTROLLER = "rover_velocity_controller"
# The e-stop's limit, and what "stopped" means for the ground truth: the rover's speed (m/s).
STOP_WITHIN_SIM_SECONDS = 0.1
STOPPED_SPEED = 0.01
E_STOP_SPEED = 0.15


class RoverTwistMux(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("rover_twist_mux_test")
        cls.figures = []
        cls.truth = []  # (sim time, forward speed, yaw rate, height) from /gazebo/model_states
        cls.mux_out = []  # (sim time, Twist) that twist_mux sent the controller
        wait_for_running_controllers(["rover_joint_publisher", CONTROLLER])
        rospy.Subscriber("/gazebo/model_states", ModelStates, cls._on_states, queue_size=10)
        rospy.Subscriber(f"/{CONTROLLER}/cmd_vel", Twist, lambda message: cls.mux_out.append(
            (rospy.get_time(), message)), queue_size=100)
        cls.cmd_vel = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
        cls.joystick = rospy.Publisher("/joy_teleop/cmd_vel", Twist, queue_size=1)
        cls.e_stop = rospy.Publisher("/e_stop", Bool, queue_size=1, latch=True)
        cls.feedback = rospy.Publisher("/twist_marker_server/feedback", InteractiveMarkerFeedback, queue_size=1)
        for publisher in (cls.cmd_vel, cls.joystick, cls.e_stop, cls.feedback):
            wait_for(lambda: publisher.get_num_connections() > 0, what=f"a subscriber to {publisher.resolved_name}")
        # Spawned at z = 0 with its wheels in the ground, as Husky is: it lands first (rover.test's rest height).
        wait_for(lambda: cls.truth and abs(cls.truth[-1][3] - 0.132) < 0.01 and abs(cls.truth[-1][1]) < STOPPED_SPEED,
                 what="the rover to come to rest on its wheels")

    @classmethod
    def tearDownClass(cls):
        print_figures(cls.figures)

    @classmethod
    def _on_states(cls, states):
        if "rover" in states.name:
            index = states.name.index("rover")
            velocity, heading = states.twist[index], yaw_of(states.pose[index].orientation)
            forward = velocity.linear.x * math.cos(heading) + velocity.linear.y * math.sin(heading)
            cls.truth.append((rospy.get_time(), forward, velocity.angular.z, states.pose[index].position.z))

    def mean_truth(self, since):
        samples = [(forward, turn) for stamp, forward, turn, _ in self.truth if stamp >= since]
        self.assertTrue(samples, "no ground truth since the given time")
        return (sum(forward for forward, _ in samples) / len(samples),
                sum(turn for _, turn in samples) / len(samples))

    def test_1_cmd_vel_drives_it_through_twist_mux(self):
        publish_for(1.0, (self.cmd_vel, twist(0.3)))
        start = rospy.get_time()
        publish_for(1.0, (self.cmd_vel, twist(0.3)))
        forward, _ = self.mean_truth(start)
        self.figures.append(f"rover on /cmd_vel through twist_mux at 0.3 m/s: {forward:.3f} m/s")
        self.assertAlmostEqual(forward, 0.3, delta=0.015)
        self.assertEqual(self.mux_out[-1][1], twist(0.3))

    def test_2_joystick_overrides_cmd_vel(self):
        publish_for(0.5, (self.cmd_vel, twist(0.3)))
        publish_for(0.5, (self.cmd_vel, twist(0.3)), (self.joystick, twist(0.0, 0.6)))
        start = rospy.get_time()
        publish_for(1.0, (self.cmd_vel, twist(0.3)), (self.joystick, twist(0.0, 0.6)))
        forward, turn = self.mean_truth(start)
        passed = {(message.linear.x, message.angular.z) for stamp, message in self.mux_out if stamp >= start}
        self.figures.append(f"rover with the joystick (0.6 rad/s) over /cmd_vel (0.3 m/s): {forward:.3f} m/s, "
                            f"{turn:.3f} rad/s")
        self.assertEqual(passed, {(0.0, 0.6)}, "only the joystick's twist should reach the controller")
        self.assertLess(abs(forward), 0.05)
        self.assertGreater(turn, 0.3)
        # The joystick stops: its input times out after 0.5 s and /cmd_vel passes again.
        released = rospy.get_time()
        publish_for(1.0, (self.cmd_vel, twist(0.3)))
        back = next(stamp for stamp, message in self.mux_out if stamp >= released and message == twist(0.3))
        self.figures.append(f"/cmd_vel passed again {back - released:.2f} s of sim time after the joystick stopped")
        self.assertLess(back - released, 0.5 + 0.2)

    def test_3_e_stop_stops_it_within_0_1_s(self):
        # The controller's deceleration limit (3 m/s^2, Husky's) alone takes 0.05 s from this speed; the rest of
        # the 0.1 s is the way from this node through twist_mux to the simulator.
        publish_for(1.0, (self.cmd_vel, twist(E_STOP_SPEED)))
        self.assertGreater(self.truth[-1][1], 0.9 * E_STOP_SPEED)
        self.e_stop.publish(Bool(True))
        self.addCleanup(self.e_stop.publish, Bool(False))
        engaged = rospy.get_time()
        publish_for(0.5, (self.cmd_vel, twist(E_STOP_SPEED)))
        stopped = next(stamp for stamp, forward, _, _ in self.truth
                       if stamp >= engaged and abs(forward) < STOPPED_SPEED)
        # The body rocks a little on its tyres after a hard stop; it must not drive on while /cmd_vel comes.
        after = [forward for stamp, forward, _, _ in self.truth if stamp >= stopped]
        drift = sum(after) / len(after)
        self.figures.append(f"e-stop at {E_STOP_SPEED} m/s: below {STOPPED_SPEED} m/s after "
                            f"{stopped - engaged:.3f} s of sim time; then {drift:+.4f} m/s on average, "
                            f"{max(map(abs, after)):.4f} at most")
        self.assertLessEqual(stopped - engaged, STOP_WITHIN_SIM_SECONDS)
        self.assertLess(abs(drift), STOPPED_SPEED)
        self.e_stop.publish(Bool(False))
        released = rospy.get_time()
        publish_for(1.0, (self.cmd_vel, twist(E_STOP_SPEED)))
        self.assertGreater(self.mean_truth(released + 0.5)[0], 0.9 * E_STOP_SPEED,
                           "/cmd_vel should drive once e_stop is false")

    def test_4_marker_feedback_drives_it(self):
        feedback = InteractiveMarkerFeedback(client_id="/rviz/InteractiveMarkers", marker_name="robot_twist_marker",
                                             event_type=InteractiveMarkerFeedback.POSE_UPDATE, pose=Pose())
        feedback.pose.position.x, feedback.pose.orientation.w = 0.25, 1.0
        feedback.header.frame_id = "base_link"
        publish_for(1.0, (self.feedback, feedback))
        start = rospy.get_time()
        publish_for(1.0, (self.feedback, feedback))
        forward, _ = self.mean_truth(start)
        self.figures.append(f"rover on the twist marker's feedback (x 0.25 m, scale 1): {forward:.3f} m/s")
        self.assertAlmostEqual(forward, 0.25, delta=0.015)


if __name__ == "__main__":
    rostest.rosrun("mbot_tests", "rover_twist_mux", RoverTwistMux)
