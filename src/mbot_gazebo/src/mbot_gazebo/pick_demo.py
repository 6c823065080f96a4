"""``./mbot demo --pick``: the arm (arm_gazebo's arm_bringup.launch in its pick world) picks the box from the table
and sets it down at the other end, 0.3 m away, through its FollowJointTrajectory and GripperCommand actions (the
plan: ``pick_plan``), held by friction alone. It prints each step's result and the box's final distance from the
target, from ground truth (/gazebo/get_model_state), and draws the box's path (/gazebo/model_states) and the
fingers' opening (/joint_states) over time to out/pick.png."""
import math
import os
import sys
import threading
import time

import actionlib
import numpy as np
import rospkg
import rospy
from control_msgs.msg import (FollowJointTrajectoryAction, FollowJointTrajectoryGoal, GripperCommand,
                              GripperCommandAction, GripperCommandGoal)
from gazebo_msgs.msg import ModelStates
from gazebo_msgs.srv import GetModelState
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from .arm_demo import ERROR_CODES, with_arm_bringup
from .pick_plan import JOINTS, ArmGeometry, pick_and_place

FINGERS = ("left_finger_joint", "right_finger_joint")
ACCEPTED_ERROR = 0.01  # m: the box's final distance from its target
WAIT = 120.0  # s of wall time for the simulator's actions and each step


class GroundTruth:
    """The box's positions (/gazebo/model_states) and the fingers' opening (/joint_states), by sim time."""

    def __init__(self):
        self.lock = threading.Lock()
        self.now = 0.0
        self.box, self.opening, self.steps = [], [], []  # (t, x, y, z), (t, m), (t, step name)
        self.fingers = {}  # each finger's latest position
        rospy.Subscriber("/clock", Clock, self._clock, queue_size=10)
        rospy.Subscriber("/gazebo/model_states", ModelStates, self._models, queue_size=10)
        rospy.Subscriber("/joint_states", JointState, self._joints, queue_size=100)

    def _clock(self, message):
        with self.lock:
            self.now = message.clock.to_sec()

    def _models(self, message):
        if "box" in message.name:
            position = message.pose[message.name.index("box")].position
            with self.lock:
                self.box.append((self.now, position.x, position.y, position.z))

    def _joints(self, message):
        # The mimic finger comes in a message of its own (the joint state publisher the simulator adds for it).
        with self.lock:
            self.fingers.update((name, position) for name, position in zip(message.name, message.position)
                                if name in FINGERS)
            if len(self.fingers) == len(FINGERS):
                self.opening.append((message.header.stamp.to_sec(), sum(self.fingers.values())))

    def mark(self, step: str):
        with self.lock:
            self.steps.append((self.now, step))

    def arrays(self):
        with self.lock:
            return np.array(self.box), np.array(self.opening), list(self.steps)


def run(out_path: str, gui: bool) -> int:
    world = os.path.join(rospkg.RosPack().get_path("arm_gazebo"), "worlds", "pick.world")
    return with_arm_bringup(out_path, gui, "pick", [f"world_name:={world}"], "pick world, friction grasp",
                            pick_and_draw)


def pick_and_draw(out_path: str) -> int:
    rospy.init_node("mbot_pick_demo", disable_signals=True)
    truth = GroundTruth()
    arm = actionlib.SimpleActionClient("/arm_controller/follow_joint_trajectory", FollowJointTrajectoryAction)
    gripper = actionlib.SimpleActionClient("/gripper_controller/gripper_cmd", GripperCommandAction)
    for client in (arm, gripper):
        if not client.wait_for_server(rospy.Duration(WAIT)):
            print(f"mbot demo --pick: no {client.action_client.ns} action within {WAIT:g} s (see the log)",
                  file=sys.stderr)
            return 1
    deadline = time.monotonic() + WAIT
    while not all(len(samples) for samples in truth.arrays()[:2]):
        if time.monotonic() > deadline:
            print(f"mbot demo --pick: no /gazebo/model_states or /joint_states within {WAIT:g} s", file=sys.stderr)
            return 1
        time.sleep(0.05)
    rospy.wait_for_service("/gazebo/get_model_state", timeout=WAIT)
    model_state = rospy.ServiceProxy("/gazebo/get_model_state", GetModelState)
    start = model_state("box", "world").pose.position
    box = (start.x, start.y, start.z)
    target = (start.x, -start.y, start.z)  # the other end of the table
    lines, failed = [f"box at ({box[0]:.3f}, {box[1]:.3f}, {box[2]:.3f}), target ({target[0]:.3f}, "
                     f"{target[1]:.3f}, {target[2]:.3f})"], False
    for step in pick_and_place(ArmGeometry.from_description(), box, target):
        truth.mark(step.name)
        if step.gripper is not None:
            gripper.send_goal(GripperCommandGoal(command=GripperCommand(step.gripper, step.max_effort)))
            if not gripper.wait_for_result(rospy.Duration(WAIT)):
                print(f"mbot demo --pick: no result for '{step.name}' within {WAIT:g} s", file=sys.stderr)
                return 1
            result = gripper.get_result()
            how = "stalled" if result.stalled else "reached" if result.reached_goal else "ended"
            lines.append(f"{step.name}: gripper {how} at {2 * result.position * 100:.1f} cm open")
        else:
            trajectory = JointTrajectory(joint_names=list(JOINTS), points=[
                JointTrajectoryPoint(positions=positions, time_from_start=rospy.Duration.from_sec(seconds))
                for seconds, positions in step.waypoints])
            arm.send_goal(FollowJointTrajectoryGoal(trajectory=trajectory))
            if not arm.wait_for_result(rospy.Duration(WAIT)):
                print(f"mbot demo --pick: no result for '{step.name}' within {WAIT:g} s", file=sys.stderr)
                return 1
            result = arm.get_result()
            failed |= result.error_code != 0
            lines.append(f"{step.name}: {ERROR_CODES.get(result.error_code, str(result.error_code))} "
                         f"{result.error_string}".rstrip())
    truth.mark("end")
    settled, deadline = truth.arrays()[2][-1][0] + 0.5, time.monotonic() + 30.0
    while truth.arrays()[0][-1][0] < settled and time.monotonic() < deadline:  # half a second to settle
        time.sleep(0.02)
    final = model_state("box", "world").pose.position
    error = math.dist((final.x, final.y, final.z), target)
    verdict = "within" if error < ACCEPTED_ERROR else "beyond"
    lines.append(f"box's final error: {error * 1000:.1f} mm from the target ({verdict} {ACCEPTED_ERROR * 100:g} cm)")
    os.makedirs(os.path.dirname(os.path.abspath(out_path)), exist_ok=True)
    draw(*truth.arrays(), target, out_path, f"pick and place: the box {error * 1000:.1f} mm from its target")
    for line in lines + [f"picture: {os.path.relpath(out_path)}"]:
        print(line)
    return 0 if not failed and error < ACCEPTED_ERROR else 1


def draw(box, opening, steps, target, out_path: str, title: str):
    """The box's path seen from above and its height, and the fingers' opening, over sim time from the first step."""
    origin = steps[0][0]
    figure = Figure(figsize=(13, 4.5), dpi=100)
    FigureCanvasAgg(figure)
    top, height, fingers = (figure.add_subplot(1, 3, index) for index in (1, 2, 3))
    top.plot(box[:, 2], box[:, 1], color="tab:red", linewidth=2.0, label="box (ground truth)")
    top.plot([box[0, 2]], [box[0, 1]], "o", color="tab:red", label="start")
    top.plot([target[1]], [target[0]], "x", color="black", markersize=10, label="target")
    top.set_xlabel("y (m)")
    top.set_ylabel("x (m), toward the arm's front")
    top.set_title("the box seen from above", fontsize=10)
    top.set_aspect("equal", adjustable="datalim")
    top.invert_xaxis()  # y to the left, as seen from above facing +x
    top.legend(fontsize=8)
    height.plot(box[:, 0] - origin, box[:, 3], color="tab:red", linewidth=1.5)
    height.set_xlabel("sim time (s)")
    height.set_ylabel("box height z (m)")
    height.set_title("the box's height", fontsize=10)
    fingers.plot(opening[:, 0] - origin, opening[:, 1] * 100, color="tab:blue", linewidth=1.5)
    fingers.set_xlabel("sim time (s)")
    fingers.set_ylabel("opening between the fingers (cm)")
    fingers.set_title("the fingers' opening", fontsize=10)
    for axes in (height, fingers):
        axes.grid(True, alpha=0.3)
        for (start, name), (end, _) in zip(steps, steps[1:]):
            axes.axvline(start - origin, color="grey", linewidth=0.6, alpha=0.6)
            axes.text((start + end) / 2 - origin, 0.5, name, transform=axes.get_xaxis_transform(), fontsize=7,
                      ha="center", va="center", rotation=90, color="dimgrey")
    top.grid(True, alpha=0.3)
    figure.suptitle(title)
    figure.tight_layout()
    figure.savefig(out_path)
