#!/usr/bin/env python3
"""car_bringup.launch runs unchanged: the spawner starts both controllers, the car drives a steered arc from
/car_controller/cmd_vel at the speed and yaw rate the Ackermann geometry gives (angular.z the steering angle),
and /car_controller/odom reports it in the YAML's frames."""
import math
import unittest

import rospy
import rostest
from controller_manager_msgs.srv import ListControllers
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

from sim_support import (WALL_TIMEOUT, controller_states, model_state_service, print_figures, publish_for, twist,
                         wait_for, yaw_of)

WHEELBASE = 0.4


class Car(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("car_test")
        cls.figures = []
        rospy.wait_for_service("/controller_manager/list_controllers", timeout=WALL_TIMEOUT)
        list_controllers = rospy.ServiceProxy("/controller_manager/list_controllers", ListControllers)
        wait_for(lambda: controller_states(list_controllers) == {"joint_state_controller": "running",
                                                                  "car_controller": "running"},
                 what="the spawner to start both controllers")
        cls.get_model_state = model_state_service()
        cls.cmd_vel = rospy.Publisher("/car_controller/cmd_vel", Twist, queue_size=1)
        wait_for(lambda: cls.cmd_vel.get_num_connections() > 0, what="the controller to subscribe cmd_vel")

    @classmethod
    def tearDownClass(cls):
        print_figures(cls.figures)

    def drive(self, linear, steering, sim_seconds):
        publish_for(sim_seconds, (self.cmd_vel, twist(linear, steering)))

    def test_drives_a_steered_arc_and_reports_it_on_odom(self):
        linear, steering = 0.5, 0.3
        self.drive(linear, steering, 2.0)
        pose0, start = self.get_model_state("car", "world").pose, rospy.get_time()
        self.drive(linear, steering, 2.0)
        pose1, elapsed = self.get_model_state("car", "world").pose, rospy.get_time() - start
        yaw_rate = math.remainder(yaw_of(pose1.orientation) - yaw_of(pose0.orientation), 2 * math.pi) / elapsed
        expected = linear * math.tan(steering) / WHEELBASE
        self.figures.append(f"car at 0.5 m/s, steering 0.3 rad: yaw rate {yaw_rate:.4f} rad/s "
                            f"(geometry: {expected:.4f})")
        self.assertAlmostEqual(yaw_rate, expected, delta=0.05 * expected)
        odometry = rospy.wait_for_message("/car_controller/odom", Odometry, timeout=WALL_TIMEOUT)
        self.assertEqual((odometry.header.frame_id, odometry.child_frame_id), ("odom", "base_footprint"))
        self.assertAlmostEqual(odometry.twist.twist.linear.x, linear, delta=0.05 * linear)
        self.assertAlmostEqual(odometry.twist.twist.angular.z, expected, delta=0.05 * expected)


if __name__ == "__main__":
    rostest.rosrun("mbot_tests", "car", Car)
