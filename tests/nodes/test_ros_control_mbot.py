#!/usr/bin/env python3
"""The mbot driven through gazebo_ros_control and diff_drive_controller, as started by the spawner.

Tracking and odometry are measured against ground truth (/gazebo/get_model_state) and printed as figures;
the controller manager's services are checked against upstream's behaviour and error texts.
"""
import math
import threading
import unittest

import rosgraph
import rospy
import rostest
from controller_manager_msgs.srv import (ListControllers, ListControllerTypes, LoadController, SwitchController,
                                         SwitchControllerRequest, UnloadController)
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Log

from sim_support import WALL_TIMEOUT, Simulator, controller_states, motion_between, print_figures, wait_for

CONTROLLER = "mobile_base_controller"
# diff_drive_controller's limits (mbot_ros_control.yaml: 1.8 m/s², 10 rad/s²) reach every commanded speed here
# within 0.12 s; a second settles the wheels' own loop behind them before the measurement.
SETTLE_SECONDS = 1.0
MEASURE_SECONDS = 1.0
STRICT, BEST_EFFORT = SwitchControllerRequest.STRICT, SwitchControllerRequest.BEST_EFFORT


class RosControlMbot(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("ros_control_mbot_test")
        cls.figures = []
        cls.logs = []
        cls.log_subscriber = rospy.Subscriber("/rosout", Log, lambda log: cls.logs.append(log.msg))
        cls.sim = Simulator(cmd_vel=None)  # the controller, not the simulator, subscribes its cmd_vel
        services = {"list_controllers": ListControllers, "list_controller_types": ListControllerTypes,
                    "load_controller": LoadController, "unload_controller": UnloadController,
                    "switch_controller": SwitchController}
        for name, service_type in services.items():
            rospy.wait_for_service("/controller_manager/" + name, timeout=WALL_TIMEOUT)
            setattr(cls, name, rospy.ServiceProxy("/controller_manager/" + name, service_type))
        wait_for(lambda: cls.states() == {"joint_state_controller": "running", CONTROLLER: "running"},
                 what="the spawner to start both controllers")
        cls.odometry = None
        cls.odom_subscriber = rospy.Subscriber(f"/{CONTROLLER}/odom", Odometry,
                                               lambda message: setattr(cls, "odometry", message))
        cls.cmd_vel = rospy.Publisher(f"/{CONTROLLER}/cmd_vel", Twist, queue_size=1)
        wait_for(lambda: cls.cmd_vel.get_num_connections() > 0, what="the controller to subscribe cmd_vel")
        cls.twist = None
        cls.repeater = threading.Thread(target=cls.repeat_command, daemon=True)
        cls.repeater.start()

    @classmethod
    def tearDownClass(cls):
        print_figures(cls.figures)

    @classmethod
    def states(cls):
        return controller_states(cls.list_controllers)

    @classmethod
    def repeat_command(cls):
        """Re-send the current command every 20 ms of wall time (cmd_vel_timeout is 0.5 s of sim time)."""
        while not rospy.is_shutdown():
            if cls.twist is not None:
                cls.cmd_vel.publish(cls.twist)
            rospy.rostime.wallsleep(0.02)

    def command(self, linear=None, angular=0.0):
        if linear is None:
            type(self).twist = None
            return
        twist = Twist()
        twist.linear.x, twist.angular.z = linear, angular
        type(self).twist = twist

    def steady_motion(self, linear, angular):
        self.sim.reset_world()
        self.command(linear, angular)
        start = self.sim.wait_sim_time(SETTLE_SECONDS)
        end = self.sim.wait_sim_time(MEASURE_SECONDS)
        self.command(0.0, 0.0)
        return motion_between(start, end)

    def test_0_the_spawner_stops_taking_the_clock_once_the_controllers_run(self):
        def nodes(kind, topic):
            publishers, subscribers, _ = rosgraph.Master(rospy.get_name()).getSystemState()
            return next((names for name, names in (publishers if kind == "pub" else subscribers) if name == topic), [])
        self.assertIn("/controller_spawner", nodes("pub", "/rosout"))  # it runs, waiting for its end
        wait_for(lambda: "/controller_spawner" not in nodes("sub", "/clock"), what="the spawner to unsubscribe /clock")
        self.assertIn(rospy.get_name(), nodes("sub", "/clock"))  # as every other node under /use_sim_time

    def test_1_tracks_linear_and_angular_speed(self):
        for linear, angular in ((0.2, 0.0), (-0.2, 0.0), (0.0, 0.5), (0.0, -1.0)):
            speed, yaw_rate = self.steady_motion(linear, angular)
            commanded, measured = (linear, speed) if linear else (angular, yaw_rate)
            self.figures.append(f"ros_control mbot v={linear:+.1f} w={angular:+.1f}: measured v {speed:+.4f} m/s, w "
                                f"{yaw_rate:+.4f} rad/s ({100 * (measured - commanded) / abs(commanded):+.2f}%)")
            self.assertAlmostEqual(measured, commanded, delta=0.05 * abs(commanded))

    def test_2_cmd_vel_timeout_stops_the_robot(self):
        self.sim.reset_world()
        self.command(0.3, 0.0)
        self.sim.wait_sim_time(SETTLE_SECONDS)
        self.command(None)  # silence: the controller brakes after cmd_vel_timeout (0.5 s)
        t0, pose0, _ = self.sim.wait_sim_time(1.0)
        t1, pose1, _ = self.sim.wait_sim_time(1.0)
        speed = math.hypot(pose1.position.x - pose0.position.x, pose1.position.y - pose0.position.y) / (t1 - t0)
        self.figures.append(f"ros_control mbot after cmd_vel_timeout: {speed:.5f} m/s")
        self.assertLess(speed, 0.005)

    def test_3_wheel_odometry_over_3_m(self):
        self.sim.reset_world()
        self.sim.wait_sim_time(0.5)
        odometry0, (_, truth0, _) = self.odometry.pose.pose.position, self.sim.truth()
        self.command(0.3, 0.0)
        wait_for(lambda: math.hypot(self.sim.truth()[1].position.x - truth0.position.x,
                                    self.sim.truth()[1].position.y - truth0.position.y) > 3.0,
                 timeout=120, what="a 3 m drive")
        self.command(0.0, 0.0)
        self.sim.wait_sim_time(1.0)
        odometry1, (_, truth1, _) = self.odometry.pose.pose.position, self.sim.truth()
        truth = math.hypot(truth1.position.x - truth0.position.x, truth1.position.y - truth0.position.y)
        odometry = math.hypot(odometry1.x - odometry0.x, odometry1.y - odometry0.y)
        self.figures.append(f"ros_control mbot odometry over {truth:.3f} m of ground truth: {odometry:.3f} m "
                            f"({100 * (odometry - truth) / truth:+.2f}%)")
        self.assertAlmostEqual(odometry, truth, delta=0.02 * truth)

    def test_4_switch_list_and_unload_as_upstream(self):
        self.assertFalse(self.unload_controller(CONTROLLER).ok, "a running controller must not unload")
        self.assertFalse(self.switch_controller([CONTROLLER], [], STRICT, False, 0.0).ok, "already running")
        self.assertFalse(self.switch_controller([], ["no_such_controller"], STRICT, False, 0.0).ok)
        self.assertTrue(self.switch_controller([], ["no_such_controller"], BEST_EFFORT, False, 0.0).ok)
        self.assertTrue(self.switch_controller([], [CONTROLLER], STRICT, False, 0.0).ok)
        self.assertEqual(self.states()[CONTROLLER], "stopped")
        self.sim.reset_world()
        self.command(0.3, 0.0)
        t0, pose0, _ = self.sim.wait_sim_time(1.0)
        t1, pose1, _ = self.sim.wait_sim_time(1.0)
        self.assertLess(math.hypot(pose1.position.x - pose0.position.x, pose1.position.y - pose0.position.y), 0.005,
                        "a stopped controller must not drive")
        self.command(0.0, 0.0)
        self.assertTrue(self.unload_controller(CONTROLLER).ok)
        self.assertEqual(list(self.states()), ["joint_state_controller"])
        self.assertTrue(self.load_controller(CONTROLLER).ok)
        self.assertEqual(self.states()[CONTROLLER], "initialized")
        self.assertTrue(self.switch_controller([CONTROLLER], [], STRICT, False, 0.0).ok)
        self.assertEqual(self.states()[CONTROLLER], "running")
        self.assertIn("diff_drive_controller/DiffDriveController", self.list_controller_types().types)
        claimed = {state.name: [(r.hardware_interface, sorted(r.resources)) for r in state.claimed_resources]
                   for state in self.list_controllers().controller}
        self.assertEqual(claimed[CONTROLLER], [("hardware_interface::VelocityJointInterface",
                                                ["left_wheel_joint", "right_wheel_joint"])])

    def test_5_bad_controllers_fail_with_upstream_texts_and_the_rest_runs(self):
        rospy.set_param("/typo_controller/type", "diff_drive_controller/DiffDriveControler")
        rospy.set_param("/ghost_controller", {"type": "diff_drive_controller/DiffDriveController",
                                              "left_wheel": "ghost_wheel_joint", "right_wheel": "left_wheel_joint"})
        self.assertFalse(self.load_controller("typo_controller").ok)
        self.assertFalse(self.load_controller("ghost_controller").ok)
        expected = ["Could not load controller 'typo_controller' because controller type "
                    "'diff_drive_controller/DiffDriveControler' does not exist.",
                    "ghost_wheel_joint couldn't be retrieved from model description",
                    "Initializing controller 'ghost_controller' failed"]
        for text in expected:
            wait_for(lambda: any(text in message for message in self.logs), what="the log line: " + text)
        self.figures.append("ros_control errors as upstream: " + " | ".join(expected))
        self.assertEqual(self.states(), {"joint_state_controller": "running", CONTROLLER: "running"})
        speed, _ = self.steady_motion(0.2, 0.0)
        self.assertAlmostEqual(speed, 0.2, delta=0.01)


if __name__ == "__main__":
    rostest.rosrun("mbot_tests", "ros_control_mbot", RosControlMbot)
