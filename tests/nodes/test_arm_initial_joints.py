#!/usr/bin/env python3
"""spawn_model -J on the arm (arm_initial_joints.test), in a world started paused (paused:=true): once this
test is connected to /joint_states and -J has set the joints, it unpauses, and the first /joint_states carry
the -J positions within 1e-4 rad (m for the finger; its mimic follower is published by the simulator's own
10 Hz stream, by when the gripper, limp as upstream's until a goal, has moved); after a second of sim time
the trajectory controller still holds them (see HOLD_TOLERANCE). /gazebo/set_model_configuration answers bad
requests with upstream's message or one naming the value, and nothing moves; spawn_model -J into the running
simulation sets the joints and names a joint the model lacks in one line. get_model_properties and
get_link_state answer through ROS with upstream's messages. The pick world's link attacher attaches and detaches
through its services; names of no model or link answer false and move nothing."""
import math
import subprocess
import tempfile
import unittest

import rospy
import rostest
from control_msgs.msg import JointTrajectoryControllerState
from gazebo_msgs.srv import (GetJointProperties, GetLinkState, GetModelProperties, GetModelState,
                             SetModelConfiguration)
from gazebo_ros_link_attacher.srv import Attach
from sensor_msgs.msg import JointState
from std_srvs.srv import Empty

from sim_support import print_figures, wait_for, wait_for_running_controllers

INITIAL = {"shoulder_pan_joint": 4.0, "shoulder_lift_joint": -1.2, "elbow_joint": 1.5, "wrist_1_joint": -0.9,
           "wrist_2_joint": 0.7, "wrist_3_joint": 0.4, "left_finger_joint": 0.03}
TOLERANCE = 1e-4
# A controller started in the first steps after -J set the joints holds as upstream's setHoldPosition does over
# stop_trajectory_duration, from the joints' velocity then: up to 4e-4 rad/s from the one step of gravity before
# the motors holding the set joints act, which moves the hold by up to 1.2e-4 rad.
HOLD_TOLERANCE = 3e-4
# The effort PIDs' static error under gravity (arm_effort_controllers.yaml's gains), not the hold's.
ACTUAL_TOLERANCE = 5e-3


class ArmInitialJoints(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.first_positions = {}  # each joint's first position

        def on_joint_states(message):
            for name, position in zip(message.name, message.position):
                cls.first_positions.setdefault(name, position)
        # Messages published before a subscriber's connection is up are lost: in a running simulation the
        # first ones would go by while this test connects.
        subscriber = rospy.Subscriber("/joint_states", JointState, on_joint_states)
        wait_for(lambda: subscriber.get_num_connections() > 0, what="a connection to /joint_states")
        rospy.wait_for_service("/gazebo/get_joint_properties", timeout=30.0)
        joint_properties = rospy.ServiceProxy("/gazebo/get_joint_properties", GetJointProperties)
        wait_for(lambda: joint_properties("elbow_joint").position == (INITIAL["elbow_joint"],),
                 what="spawn_model -J to set elbow_joint")
        assert not cls.first_positions, "joint states came while the simulation was paused"
        rospy.ServiceProxy("/gazebo/unpause_physics", Empty)()
        wait_for(lambda: set(INITIAL) <= set(cls.first_positions), what="every joint on /joint_states")
        subscriber.unregister()

    def test_first_joint_states_show_the_set_positions(self):
        errors = {name: abs(self.first_positions[name] - value) for name, value in INITIAL.items()}
        self.assertLess(max(errors.values()), TOLERANCE, errors)
        print_figures([f"-J: first /joint_states within {max(errors.values()):.1e} of the -J positions"])

    def test_the_trajectory_controller_holds_the_set_positions(self):
        wait_for_running_controllers(["joint_state_controller", "arm_controller", "gripper_controller"])
        start = rospy.get_time()
        wait_for(lambda: rospy.get_time() > start + 1.0, what="a second of sim time")
        desired, actual = self.arm_state()
        hold_errors = [abs(desired[name] - INITIAL[name]) for name in desired]
        actual_errors = [abs(actual[name] - INITIAL[name]) for name in actual]
        self.assertLess(max(hold_errors), HOLD_TOLERANCE, hold_errors)
        self.assertLess(max(actual_errors), ACTUAL_TOLERANCE, actual_errors)
        print_figures([f"-J: trajectory hold within {max(hold_errors):.1e} after 1 s, actual within "
                       f"{max(actual_errors):.1e}"])

    def test_bad_requests_are_answered_and_nothing_moves(self):
        wait_for_running_controllers(["joint_state_controller", "arm_controller", "gripper_controller"])
        rospy.wait_for_service("/gazebo/set_model_configuration", timeout=30.0)
        configure = rospy.ServiceProxy("/gazebo/set_model_configuration", SetModelConfiguration)
        answers = [configure("no_such_model", "", ["elbow_joint"], [0.5]),
                   configure("robot", "", ["elbow_joint"], [0.5, 0.6]),
                   configure("robot", "", ["elbow_joint"], [math.nan]),
                   configure("robot", "", ["elbow_joint"], [math.inf]),
                   configure("robot", "", ["elbow_joint"], [1e300])]
        self.assertEqual([answer.success for answer in answers], [False] * 5)
        self.assertEqual(answers[0].status_message, "SetModelConfiguration: model does not exist")
        self.assertEqual(answers[1].status_message,
                         "SetModelConfiguration: joint name and position list have different lengths")
        for answer, text in zip(answers[2:], ("position nan is not a finite number",
                                             "position inf is not a finite number",
                                             "position 1e+300 is outside its limits")):
            self.assertIn("joint 'elbow_joint': " + text, answer.status_message)
        # A refused request leaves the hold (which an accepted one would move) where -J put it.
        desired, actual = self.arm_state()
        self.assertLess(max(abs(desired[name] - INITIAL[name]) for name in desired), HOLD_TOLERANCE, desired)
        self.assertLess(max(abs(actual[name] - INITIAL[name]) for name in actual), ACTUAL_TOLERANCE, actual)
        answer = configure("robot", "", ["no_such_joint"], [1.0])
        self.assertTrue(answer.success)
        self.assertEqual(answer.status_message,
                         "SetModelConfiguration: success; model 'robot' has no movable joint 'no_such_joint' (ignored)")

    def test_spawn_model_names_a_joint_the_model_lacks_in_one_line(self):
        with tempfile.NamedTemporaryFile("w", suffix=".urdf") as urdf:
            urdf.write(PENDULUM_URDF)
            urdf.flush()
            run = subprocess.run(["rosrun", "gazebo_ros", "spawn_model", "-urdf", "-file", urdf.name, "-model",
                                  "pendulum", "-x", "2", "-J", "hinge", "0.5", "-J", "no_such_joint", "1.0"],
                                 capture_output=True, text=True, timeout=60)
        self.assertEqual(run.returncode, 0, run.stderr)
        hinge = rospy.ServiceProxy("/gazebo/get_joint_properties", GetJointProperties)("hinge")
        self.assertTrue(hinge.success)
        # Spawned hanging at rest, then set to 0.5 while spawn_model held the physics paused: the pendulum swings
        # with that amplitude (undamped; bob 0.2 kg 0.3 m below the hinge), whatever the moment of this reading.
        angle, rate = hinge.position[0], hinge.rate[0]
        amplitude = math.acos(math.cos(angle) - PENDULUM_INERTIA * rate ** 2 / (2 * BOB_MASS * GRAVITY * BOB_DEPTH))
        self.assertAlmostEqual(amplitude, 0.5, delta=0.02)
        lines = [line for line in run.stderr.splitlines() if "no_such_joint" in line]
        self.assertEqual(len(lines), 1, run.stderr)
        self.assertIn("model 'pendulum' has no movable joint 'no_such_joint'", lines[0])

    def test_model_properties_and_link_state(self):
        rospy.wait_for_service("/gazebo/get_link_state", timeout=30.0)
        properties = rospy.ServiceProxy("/gazebo/get_model_properties", GetModelProperties)
        link_state = rospy.ServiceProxy("/gazebo/get_link_state", GetLinkState)
        arm = properties("robot")
        self.assertTrue(arm.success)
        self.assertEqual(arm.status_message, "GetModelProperties: got properties")
        self.assertIn("wrist_3_link", arm.body_names)
        self.assertTrue(set(INITIAL) <= set(arm.joint_names), arm.joint_names)
        self.assertEqual(properties("no_such_model").status_message, "GetModelProperties: model does not exist")
        wrist = link_state("robot::wrist_3_link", "robot::wrist_3_link")
        self.assertTrue(wrist.success)
        self.assertEqual((wrist.status_message, wrist.link_state.reference_frame),
                         ("GetLinkState: got state", "robot::wrist_3_link"))
        self.assertLess(abs(wrist.link_state.pose.position.x) + abs(wrist.link_state.pose.position.z), 1e-6)
        self.assertEqual(link_state("wrist_3_link", "").status_message,
                         "GetLinkState: link not found, did you forget to scope the link by model name?")
        self.assertEqual(link_state("robot::wrist_3_link", "nowhere").status_message,
                         "GetLinkState: reference reference_frame not found, did you forget to scope the link by "
                         "model name?")

    def test_the_link_attacher_services(self):
        rospy.wait_for_service("/link_attacher_node/detach", timeout=30.0)
        attach = rospy.ServiceProxy("/link_attacher_node/attach", Attach)
        detach = rospy.ServiceProxy("/link_attacher_node/detach", Attach)
        model_state = rospy.ServiceProxy("/gazebo/get_model_state", GetModelState)
        before = model_state("box", "world").pose.position
        bad = [("no_such_model", "link", "table", "link"), ("box", "no_such_link", "table", "link"),
               ("box", "link", "box", "link"), ("nan", "inf", "1e308", ""), ("box" * 10000, "link", "table", "link")]
        self.assertEqual([attach(*names).ok for names in bad], [False] * len(bad))
        self.assertEqual([detach(*names).ok for names in bad], [False] * len(bad))
        pair = ("box", "link", "table", "link")
        self.assertEqual([attach(*pair).ok, attach(*pair).ok, detach(*pair).ok, detach(*pair).ok],
                         [True, True, True, False])
        after = model_state("box", "world").pose.position
        moved = math.dist((before.x, before.y, before.z), (after.x, after.y, after.z))
        self.assertLess(moved, 1e-4)

    @staticmethod
    def arm_state():
        """The trajectory controller's desired and actual positions by joint, from its next state message."""
        state = rospy.wait_for_message("/arm_controller/state", JointTrajectoryControllerState, timeout=30.0)
        return (dict(zip(state.joint_names, state.desired.positions)),
                dict(zip(state.joint_names, state.actual.positions)))


BOB_MASS, BOB_DEPTH, GRAVITY = 0.2, 0.3, 9.8  # PENDULUM_URDF's bob, its depth below the hinge; the pick world's g
PENDULUM_INERTIA = 0.001 + BOB_MASS * BOB_DEPTH ** 2  # about the hinge: the bob's own and its mass at its depth
PENDULUM_URDF = """<robot name="pendulum">
  <link name="world"/>
  <joint name="anchor" type="fixed"><parent link="world"/><child link="base"/><origin xyz="0 0 1"/></joint>
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>
    </inertial><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="bob"><inertial><origin xyz="0 0 -0.3"/><mass value="0.2"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="continuous"><parent link="base"/><child link="bob"/><axis xyz="1 0 0"/></joint>
</robot>"""


if __name__ == "__main__":
    rospy.init_node("arm_initial_joints_test")
    rostest.rosrun("mbot_tests", "arm_initial_joints", ArmInitialJoints)
