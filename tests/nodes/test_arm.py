#!/usr/bin/env python3
"""The arm as arm_bringup.launch brings it up: a two-point FollowJointTrajectory goal succeeds with every joint
within 0.01 rad (joint_states); a path tolerance the arm cannot keep aborts with PATH_TOLERANCE_VIOLATED; a second
goal preempts the first; unknown or repeated joints are rejected with INVALID_JOINTS and a reason; the command
topic moves the arm without the action; state and query_state report the trajectory; an elbow commanded past its
limit stops at it; the gripper opens to its goal (reached_goal), closes on a box and stalls there, its mimic finger
within 0.001 of the leader; goals past the finger's travel each get a result; a switch_controller pending while
physics is paused is answered when the arm is deleted, and /clock runs on."""
import math
import threading
import unittest

import actionlib
import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from control_msgs.msg import (FollowJointTrajectoryAction, FollowJointTrajectoryGoal, FollowJointTrajectoryResult,
                              GripperCommand, GripperCommandAction, GripperCommandGoal, JointTolerance,
                              JointTrajectoryControllerState)
from control_msgs.srv import QueryTrajectoryState
from controller_manager_msgs.srv import SwitchController, SwitchControllerRequest
from gazebo_msgs.srv import DeleteModel, SpawnModel
from geometry_msgs.msg import Pose
from sensor_msgs.msg import JointState
from std_srvs.srv import Empty
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from sim_support import WALL_TIMEOUT, print_figures, wait_for, wait_for_running_controllers

JOINTS = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
          "wrist_3_joint"]
GOAL_TOLERANCE = 0.01
ELBOW_LIMIT = math.radians(160.0)
# Upright (all joints 0), the gripper base sits 0.85 m up on the mount's axis and the fingers reach 0.03 to
# 0.09 m above it.
FINGERS_CENTRE_Z = 0.85 + 0.06
BOX_SDF = """<sdf version="1.6"><model name="box"><static>true</static><link name="link">
  <collision name="collision"><geometry><box><size>0.03 0.04 0.03</size></box></geometry></collision>
  <visual name="visual"><geometry><box><size>0.03 0.04 0.03</size></box></geometry></visual>
</link></model></sdf>"""


def trajectory(points):
    """A JointTrajectory for every joint from (seconds, positions[, velocities]) tuples; stamp 0 (start now)."""
    message = JointTrajectory(joint_names=list(JOINTS))
    for seconds, positions, *velocities in points:
        message.points.append(JointTrajectoryPoint(positions=positions, velocities=velocities[0] if velocities else [],
                                                   time_from_start=rospy.Duration.from_sec(seconds)))
    return message


class Arm(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("arm_test")
        cls.figures = []
        wait_for_running_controllers(["joint_state_controller", "arm_controller", "gripper_controller"])
        # joint_states comes in parts: the controller's joints, and the mimic finger from the simulator.
        cls.joint_positions = {}
        rospy.Subscriber("/joint_states", JointState,
                         lambda message: cls.joint_positions.update(zip(message.name, message.position)))
        cls.controller_state = None
        rospy.Subscriber("/arm_controller/state", JointTrajectoryControllerState,
                         lambda message: setattr(cls, "controller_state", message))
        cls.trajectory_clients = [actionlib.SimpleActionClient("/arm_controller/follow_joint_trajectory",
                                                               FollowJointTrajectoryAction) for _ in range(2)]
        cls.gripper = actionlib.SimpleActionClient("/gripper_controller/gripper_cmd", GripperCommandAction)
        for client in cls.trajectory_clients + [cls.gripper]:
            assert client.wait_for_server(rospy.Duration(WALL_TIMEOUT)), "action server not up"
        cls.command = rospy.Publisher("/arm_controller/command", JointTrajectory, queue_size=1)
        wait_for(lambda: set(JOINTS + ["right_finger_joint"]) <= set(cls.joint_positions)
                 and cls.controller_state is not None,
                 what="joint_states and the controller's state")

    @classmethod
    def tearDownClass(cls):
        print_figures(cls.figures)

    def positions(self, names=JOINTS):
        return [self.joint_positions[name] for name in names]

    def follow(self, points, client=0, feedback_cb=None, **goal_fields):
        goal = FollowJointTrajectoryGoal(trajectory=trajectory(points), **goal_fields)
        self.trajectory_clients[client].send_goal(goal, feedback_cb=feedback_cb)

    def result(self, client=0):
        action = self.trajectory_clients[client]
        self.assertTrue(action.wait_for_result(rospy.Duration(WALL_TIMEOUT)), "no result")
        return action.get_state(), action.get_result()

    def settle(self, seconds=0.5):
        start = rospy.get_time()
        wait_for(lambda: rospy.get_time() > start + seconds, what=f"{seconds} s of sim time")

    def home(self):
        """Upright, through the command topic (a goal from beyond a limit would start where the trajectory was,
        not where the joint stopped, and break its path tolerance at once, as upstream)."""
        self.command.publish(trajectory([(1.5, [0.0] * 6, [0.0] * 6)]))
        wait_for(lambda: max(map(abs, self.positions())) < GOAL_TOLERANCE, what="the arm upright")

    def test_01_a_two_point_goal_succeeds_with_every_joint_at_its_goal(self):
        target = [0.8, 0.6, 0.9, -0.5, 0.4, 0.3]
        feedback = []
        self.follow([(1.0, [0.4, 0.3, 0.45, -0.25, 0.2, 0.15]), (2.0, target)], feedback_cb=feedback.append)
        state, result = self.result()
        self.assertEqual((state, result.error_code), (GoalStatus.SUCCEEDED, FollowJointTrajectoryResult.SUCCESSFUL))
        # Feedback at the YAML's action_monitor_rate (10 Hz) while the 2 s goal ran, each stamped with its step.
        stamps = [message.header.stamp.to_sec() for message in feedback]
        self.assertGreaterEqual(len(stamps), 19, stamps)
        self.assertTrue(all(abs(later - earlier - 0.1) < 1e-6 for earlier, later in zip(stamps, stamps[1:])), stamps)
        self.assertEqual(list(feedback[-1].joint_names), JOINTS)
        self.assertLess(max(abs(a - b) for a, b in zip(feedback[-1].desired.positions, target)), 0.1)
        self.figures.append(f"arm goal feedback: {len(stamps)} messages over {stamps[-1] - stamps[0]:.3f} s of sim "
                            "time, 0.1 s apart")
        self.settle()
        errors = [abs(a - b) for a, b in zip(self.positions(), target)]
        self.assertLess(max(errors), GOAL_TOLERANCE, errors)
        self.figures.append("arm (effort_controllers/JointTrajectoryController): two-point goal SUCCESSFUL, joint "
                            "errors " + ", ".join(f"{e:.4f}" for e in errors) + " rad 0.5 s after")
        # The state topic and query_state report the trajectory held at its end.
        state = self.controller_state
        self.assertEqual(list(state.joint_names), JOINTS)
        for desired, goal in zip(state.desired.positions, target):
            self.assertAlmostEqual(desired, goal, places=9)
        sampled = rospy.ServiceProxy("/arm_controller/query_state", QueryTrajectoryState)(rospy.Time.now())
        self.assertEqual(list(sampled.name), JOINTS)
        for position, goal in zip(sampled.position, target):
            self.assertAlmostEqual(position, goal, places=9)

    def test_02_a_path_tolerance_the_arm_cannot_keep_aborts(self):
        tight = [JointTolerance(name=name, position=1e-4) for name in JOINTS]
        self.follow([(0.3, [0.0, 0.0, 0.0, 0.0, 0.0, 0.0])], path_tolerance=tight)
        state, result = self.result()
        self.assertEqual((state, result.error_code),
                         (GoalStatus.ABORTED, FollowJointTrajectoryResult.PATH_TOLERANCE_VIOLATED))
        self.figures.append(f"path tolerance 1e-4 rad on a 0.3 s move: ABORTED, '{result.error_string}'")

    def test_03_a_second_goal_preempts_the_first(self):
        self.follow([(3.0, [0.5, 0.0, 0.0, 0.0, 0.0, 0.0])], client=0)
        wait_for(lambda: self.trajectory_clients[0].get_state() == GoalStatus.ACTIVE, what="the first goal active")
        self.follow([(1.0, [-0.5, 0.0, 0.0, 0.0, 0.0, 0.0])], client=1)
        self.assertEqual(self.result(0)[0], GoalStatus.PREEMPTED)
        self.assertEqual(self.result(1)[0], GoalStatus.SUCCEEDED)

    def test_04_unknown_joints_are_rejected(self):
        goal = FollowJointTrajectoryGoal(trajectory=trajectory([(1.0, [0.0] * 6)]))
        goal.trajectory.joint_names[5] = "wrist_4_joint"
        self.trajectory_clients[0].send_goal(goal)
        state, result = self.result()
        self.assertEqual((state, result.error_code), (GoalStatus.REJECTED, FollowJointTrajectoryResult.INVALID_JOINTS))
        self.assertIn("wrist_4_joint", result.error_string)
        # One joint named six times: rejected too (upstream's mapping would accept it and move one joint).
        goal.trajectory.joint_names = [JOINTS[0]] * 6
        self.trajectory_clients[0].send_goal(goal)
        state, result = self.result()
        self.assertEqual((state, result.error_code), (GoalStatus.REJECTED, FollowJointTrajectoryResult.INVALID_JOINTS))
        self.figures.append(f"a goal naming {JOINTS[0]} six times: REJECTED INVALID_JOINTS, '{result.error_string}'")

    def test_05_the_command_topic_moves_the_arm_without_the_action(self):
        target = [-0.3, 0.4, 0.5, 0.2, -0.3, 0.1]
        wait_for(lambda: self.command.get_num_connections() > 0, what="the controller on the command topic")
        self.command.publish(trajectory([(1.0, target)]))
        wait_for(lambda: max(abs(a - b) for a, b in zip(self.positions(), target)) < GOAL_TOLERANCE,
                 what="the arm at the commanded point")

    def test_06_an_elbow_commanded_past_its_limit_stops_at_it(self):
        self.command.publish(trajectory([(1.0, [0.0, 0.0, 3.0, 0.0, 0.0, 0.0])]))
        start = rospy.get_time()
        wait_for(lambda: rospy.get_time() > start + 2.0, what="2 s of sim time")
        elbow = self.positions(["elbow_joint"])[0]
        self.assertLess(elbow, ELBOW_LIMIT + 0.01)
        self.assertGreater(elbow, ELBOW_LIMIT - 0.05)
        self.figures.append(f"elbow commanded to 3.000 rad stops at {elbow:.4f} (limit {ELBOW_LIMIT:.4f})")
        self.home()

    def test_07_the_gripper_opens_then_closes_on_a_box_and_stalls(self):
        self.home()
        self.gripper.send_goal(GripperCommandGoal(GripperCommand(0.035, 30.0)))
        self.assertTrue(self.gripper.wait_for_result(rospy.Duration(WALL_TIMEOUT)))
        opened = self.gripper.get_result()
        self.assertEqual((self.gripper.get_state(), opened.reached_goal, opened.stalled),
                         (GoalStatus.SUCCEEDED, True, False))
        rospy.wait_for_service("/gazebo/spawn_sdf_model", timeout=WALL_TIMEOUT)
        pose = Pose()
        pose.position.z, pose.orientation.w = FINGERS_CENTRE_Z, 1.0
        spawned = rospy.ServiceProxy("/gazebo/spawn_sdf_model", SpawnModel)("box", BOX_SDF, "", pose, "world")
        self.assertTrue(spawned.success, spawned.status_message)
        self.gripper.send_goal(GripperCommandGoal(GripperCommand(0.0, 30.0)))
        self.assertTrue(self.gripper.wait_for_result(rospy.Duration(WALL_TIMEOUT)))
        closed = self.gripper.get_result()
        self.assertEqual((self.gripper.get_state(), closed.reached_goal, closed.stalled),
                         (GoalStatus.ABORTED, False, True))
        self.assertAlmostEqual(closed.position, 0.02, delta=0.002)
        leader, follower = self.positions(["left_finger_joint", "right_finger_joint"])
        self.assertLess(abs(leader - follower), 0.001)
        self.figures.append(f"gripper: opened to {opened.position:.4f} m (reached_goal); closed on a 4 cm box, "
                            f"stalled at {closed.position:.4f} m, effort {closed.effort:.1f} N; mimic finger "
                            f"{abs(leader - follower) * 1000:.3f} mm from its leader")

    def test_08_goals_past_the_fingers_travel_each_get_a_result(self):
        """The finger travels 0 to 0.04 m: each goal beyond ends (stalled at the limit) within 3 s of sim time."""
        self.assertTrue(rospy.ServiceProxy("/gazebo/delete_model", DeleteModel)("box").success)
        for position in (0.05, -0.01, 1e300, -5.0):
            start = rospy.get_time()
            self.gripper.send_goal(GripperCommandGoal(GripperCommand(position, 30.0)))
            self.assertTrue(self.gripper.wait_for_result(rospy.Duration(WALL_TIMEOUT)), f"no result for {position}")
            took, result = rospy.get_time() - start, self.gripper.get_result()
            self.assertLess(took, 3.0, position)
            self.assertIn(self.gripper.get_state(), (GoalStatus.SUCCEEDED, GoalStatus.ABORTED), position)
            self.assertTrue(-0.001 < result.position < 0.041, (position, result.position))
            self.figures.append(f"gripper goal {position:g} m: {GoalStatus.to_string(self.gripper.get_state())} "
                                f"(stalled {result.stalled}) at {result.position:.4f} m after {took:.2f} s of sim time")

    def test_09_a_switch_pending_when_the_arm_is_deleted_is_answered(self):
        """Physics paused, a STRICT switch with timeout 0 waits for the next update for ever; deleting the arm
        answers it (false, nothing switched), and /clock runs on after the unpause."""
        rospy.ServiceProxy("/gazebo/pause_physics", Empty)()
        # Persistent: its transport is set once connected, just before the request is written, so the delete
        # below comes after the switch reached the simulator.
        switch = rospy.ServiceProxy("/controller_manager/switch_controller", SwitchController, persistent=True)
        answers = []

        def call():
            try:
                answers.append(switch(start_controllers=[], stop_controllers=["gripper_controller"],
                                      strictness=SwitchControllerRequest.STRICT, start_asap=False, timeout=0.0).ok)
            except rospy.ServiceException as error:
                answers.append(error)
        caller = threading.Thread(target=call, daemon=True)
        caller.start()
        wait_for(lambda: switch.transport is not None, what="the switch call connected")
        self.assertTrue(caller.is_alive(), answers)
        self.assertTrue(rospy.ServiceProxy("/gazebo/delete_model", DeleteModel)("robot").success)
        caller.join(WALL_TIMEOUT)
        self.assertFalse(caller.is_alive(), "the switch call was never answered")
        self.assertEqual(answers, [False])
        rospy.ServiceProxy("/gazebo/unpause_physics", Empty)()
        start = rospy.get_time()
        wait_for(lambda: rospy.get_time() > start + 0.5, what="/clock running after the delete")
        self.figures.append("switch_controller pending (paused, STRICT, timeout 0) when the arm was deleted: "
                            "answered ok=False")

if __name__ == "__main__":
    rostest.rosrun("mbot_tests", "arm", Arm)
