#!/usr/bin/env python3
"""spawn_model -J on the arm (arm_initial_joints.test): the first /joint_states carry the -J positions within
1e-4 rad (m for the fingers), the right finger follows its mimic leader, and after a second of sim time the
trajectory controller still holds them (its desired state within 1e-4 of them)."""
import unittest

import rospy
import rostest
from control_msgs.msg import JointTrajectoryControllerState
from sensor_msgs.msg import JointState

from sim_support import print_figures, wait_for, wait_for_running_controllers

INITIAL = {"shoulder_pan_joint": 4.0, "shoulder_lift_joint": -1.2, "elbow_joint": 1.5, "wrist_1_joint": -0.9,
           "wrist_2_joint": 0.7, "wrist_3_joint": 0.4, "left_finger_joint": 0.03, "right_finger_joint": 0.03}
TOLERANCE = 1e-4
# The effort PIDs' static error under gravity (arm_effort_controllers.yaml's gains), not the hold's.
ACTUAL_TOLERANCE = 5e-3


class ArmInitialJoints(unittest.TestCase):
    def test_first_joint_states_show_the_set_positions_and_the_controller_holds_them(self):
        positions = {}  # each joint's first position (the mimic finger comes in a message of its own)

        def on_joint_states(message):
            for name, position in zip(message.name, message.position):
                positions.setdefault(name, position)
        subscriber = rospy.Subscriber("/joint_states", JointState, on_joint_states)
        wait_for(lambda: set(INITIAL) <= set(positions), what="every joint on /joint_states")
        subscriber.unregister()
        errors = {name: abs(positions[name] - value) for name, value in INITIAL.items()}
        self.assertLess(max(errors.values()), TOLERANCE, errors)

        wait_for_running_controllers(["joint_state_controller", "arm_controller", "gripper_controller"])
        start = rospy.get_time()
        wait_for(lambda: rospy.get_time() > start + 1.0, what="a second of sim time")
        state = rospy.wait_for_message("/arm_controller/state", JointTrajectoryControllerState, timeout=30.0)
        desired = dict(zip(state.joint_names, state.desired.positions))
        actual = dict(zip(state.joint_names, state.actual.positions))
        hold_errors = [abs(desired[name] - INITIAL[name]) for name in state.joint_names]
        actual_errors = [abs(actual[name] - INITIAL[name]) for name in state.joint_names]
        self.assertLess(max(hold_errors), TOLERANCE, hold_errors)
        self.assertLess(max(actual_errors), ACTUAL_TOLERANCE, actual_errors)
        print_figures([f"-J: first /joint_states within {max(errors.values()):.1e} of the -J positions",
                       f"-J: trajectory hold within {max(hold_errors):.1e} after 1 s, actual within "
                       f"{max(actual_errors):.1e}"])


if __name__ == "__main__":
    rospy.init_node("arm_initial_joints_test")
    rostest.rosrun("mbot_tests", "arm_initial_joints", ArmInitialJoints)
