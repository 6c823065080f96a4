#!/usr/bin/env python3
"""A Husky-style launch (rosparam load + spawner) runs unchanged: both controllers start, the skid-steer base
drives forward at the commanded speed and turns left on a positive angular.z at the rate skid steering gives;
/joint_states has all four wheels; the spawner's --stopped, YAML-file and shutdown paths are exercised on a second
controller."""
import math
import os
import subprocess
import unittest

import rospy
import rostest
from controller_manager_msgs.srv import ListControllers
from geometry_msgs.msg import Twist
from sensor_msgs.msg import JointState

from mbot_sim_bridge.processes import stop_process_group
from sim_support import (WALL_TIMEOUT, controller_states, model_state_service, print_figures, publish_for, twist,
                         wait_for, yaw_of)

CONTROLLER = "quad_velocity_controller"
# quad_base.urdf.xacro's default geometry and quad_control.yaml's multiplier (Husky's).
HALF_TRACK, HALF_WHEELBASE, SEPARATION_MULTIPLIER = 0.4 / 2, 0.36 / 2, 1.875


class RosControlQuad(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("ros_control_quad_test")
        cls.figures = []
        rospy.wait_for_service("/controller_manager/list_controllers", timeout=WALL_TIMEOUT)
        cls.list_controllers = rospy.ServiceProxy("/controller_manager/list_controllers", ListControllers)
        wait_for(lambda: cls.states() == {"quad_joint_publisher": "running", CONTROLLER: "running"},
                 what="the spawner to start both controllers")
        cls.get_model_state = model_state_service()
        cls.cmd_vel = rospy.Publisher(f"/{CONTROLLER}/cmd_vel", Twist, queue_size=1)
        wait_for(lambda: cls.cmd_vel.get_num_connections() > 0, what="the controller to subscribe cmd_vel")

    @classmethod
    def tearDownClass(cls):
        print_figures(cls.figures)

    @classmethod
    def states(cls):
        return controller_states(cls.list_controllers)

    def pose(self):
        return self.get_model_state("quad_base", "world").pose

    def drive(self, linear, angular, sim_seconds):
        publish_for(sim_seconds, (self.cmd_vel, twist(linear, angular)))

    def test_drives_forward_at_the_commanded_speed(self):
        self.drive(0.4, 0.0, 1.5)
        start, pose0 = rospy.get_time(), self.pose()
        self.drive(0.4, 0.0, 2.0)
        pose1, elapsed = self.pose(), rospy.get_time() - start
        speed = math.hypot(pose1.position.x - pose0.position.x, pose1.position.y - pose0.position.y) / elapsed
        self.figures.append(f"Husky-style quad base at 0.4 m/s: {speed:.4f} m/s")
        self.assertAlmostEqual(speed, 0.4, delta=0.02)

    def test_turns_left_at_the_rate_skid_steering_gives(self):
        # diff_drive_controller drives the wheels at ±angular·m·b (wheel separation 2b from the URDF's front wheels,
        # times wheel_separation_multiplier m); the base turns where Coulomb friction's torques at the four wheels
        # (±a, ±b) cancel, at angular·m·b²/(a² + b²) (the workspace README, "Skid steering"): 1.036 rad/s for this
        # base; measured 1.0349 in three runs. 5 %: the poses are stamped in sim time, so what varies is the turn.
        expected = 1.0 * SEPARATION_MULTIPLIER * HALF_TRACK ** 2 / (HALF_WHEELBASE ** 2 + HALF_TRACK ** 2)
        self.drive(0.0, 1.0, 0.5)  # past the controller's 6 rad/s² ramp and the wheels' spin-up
        start = self.get_model_state("quad_base", "world")
        self.drive(0.0, 1.0, 1.5)
        end = self.get_model_state("quad_base", "world")
        turned = math.remainder(yaw_of(end.pose.orientation) - yaw_of(start.pose.orientation), 2 * math.pi)
        rate = turned / (end.header.stamp - start.header.stamp).to_sec()
        self.figures.append(f"Husky-style quad base at +1.0 rad/s: {rate:+.4f} rad/s (Coulomb friction {expected:.4f})")
        self.assertAlmostEqual(rate, expected, delta=0.05 * expected)

    def test_joint_states_has_every_wheel(self):
        message = rospy.wait_for_message("/joint_states", JointState, timeout=WALL_TIMEOUT)
        wait_for(lambda: {"front_left_wheel", "rear_left_wheel", "front_right_wheel", "rear_right_wheel"} <=
                 set(rospy.wait_for_message("/joint_states", JointState, timeout=WALL_TIMEOUT).name),
                 what=f"the four wheels on /joint_states (last: {message.name})")

    def test_spawner_yaml_file_stopped_and_shutdown(self):
        path = os.path.join(os.environ.get("ROS_LOG_DIR", "/tmp"), "quad_extra_controller.yaml")
        with open(path, "w") as stream:
            stream.write("extra_joint_publisher:\n  type: joint_state_controller/JointStateController\n"
                         "  publish_rate: 10\n")
        spawner = subprocess.Popen(["rosrun", "controller_manager", "spawner", "--stopped", "--timeout", "20",
                                    path], start_new_session=True)
        try:
            wait_for(lambda: self.states().get("extra_joint_publisher") == "initialized",
                     what="the spawner to load extra_joint_publisher stopped")
        finally:
            exited = stop_process_group(spawner, WALL_TIMEOUT)
        self.assertTrue(exited, "the spawner did not exit on SIGINT")
        wait_for(lambda: "extra_joint_publisher" not in self.states(), what="the spawner to unload on exit")
        self.assertEqual(spawner.returncode, 0)

    def test_controller_manager_cli_lists_and_unspawner_inhibits(self):
        listing = subprocess.run(["rosrun", "controller_manager", "controller_manager", "list"], capture_output=True,
                                 text=True, timeout=WALL_TIMEOUT)
        self.assertIn(f"'{CONTROLLER}' - 'hardware_interface::VelocityJointInterface' ( running )", listing.stdout)
        unspawner = subprocess.Popen(["rosrun", "controller_manager", "unspawner", CONTROLLER],
                                     start_new_session=True)
        try:
            wait_for(lambda: self.states()[CONTROLLER] == "stopped", what="the unspawner to stop the controller")
        finally:
            exited = stop_process_group(unspawner, WALL_TIMEOUT)
        self.assertTrue(exited, "the unspawner did not exit on SIGINT")
        wait_for(lambda: self.states()[CONTROLLER] == "running", what="the unspawner to restart it on exit")


if __name__ == "__main__":
    rostest.rosrun("mbot_tests", "ros_control_quad", RosControlQuad)
