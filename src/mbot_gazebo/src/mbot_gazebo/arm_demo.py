"""``./mbot demo --arm``: the six-joint arm (arm_gazebo's arm_bringup.launch) follows a trajectory sent to its
FollowJointTrajectory action; the commanded (desired) and actual joint positions from the controller's state
topic are drawn to out/arm.png, with the result and the tracking errors printed."""
import os
import subprocess
import sys
import threading
import time
from typing import Callable, List

import actionlib
import numpy as np
import rospy
from control_msgs.msg import FollowJointTrajectoryAction, FollowJointTrajectoryGoal, JointTrajectoryControllerState
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from mbot_sim_bridge.processes import PrivateMaster, stop_process_group
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

# A reach forward and down, a turn of the wrist, and back: (seconds from start, positions).
WAYPOINTS = ((1.5, (0.8, 0.6, 0.9, -0.5, 0.4, 0.3)), (3.0, (-0.6, 0.9, 0.6, 0.8, -0.8, -0.5)),
             (4.5, (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)))
ERROR_CODES = {0: "SUCCESSFUL", -1: "INVALID_GOAL", -2: "INVALID_JOINTS", -3: "OLD_HEADER_TIMESTAMP",
               -4: "PATH_TOLERANCE_VIOLATED", -5: "GOAL_TOLERANCE_VIOLATED"}


class StateRecorder:
    """The controller's state messages: sim time, desired and actual positions."""

    def __init__(self):
        self.lock = threading.Lock()
        self.times, self.desired, self.actual, self.joint_names = [], [], [], []
        rospy.Subscriber("/arm_controller/state", JointTrajectoryControllerState, self._store, queue_size=100)

    def _store(self, message):
        with self.lock:
            self.joint_names = list(message.joint_names)
            self.times.append(message.header.stamp.to_sec())
            self.desired.append(message.desired.positions)
            self.actual.append(message.actual.positions)

    def arrays(self):
        with self.lock:
            return np.array(self.times), np.array(self.desired), np.array(self.actual), list(self.joint_names)


def draw(times, desired, actual, names, out_path, title):
    figure = Figure(figsize=(12, 7), dpi=100)
    FigureCanvasAgg(figure)
    for index, name in enumerate(names):
        axes = figure.add_subplot(2, 3, index + 1)
        axes.plot(times, desired[:, index], color="tab:blue", linewidth=2.0, label="commanded (desired)")
        axes.plot(times, actual[:, index], color="tab:orange", linewidth=1.2, linestyle="--", label="actual")
        axes.set_title(name, fontsize=10)
        axes.set_xlabel("sim time (s)")
        axes.set_ylabel("position (rad)")
        axes.grid(True, alpha=0.3)
        if index == 0:
            axes.legend(fontsize=8)
    figure.suptitle(title)
    figure.tight_layout()
    figure.savefig(out_path)


def run(out_path: str, gui: bool) -> int:
    return with_arm_bringup(out_path, gui, "arm", [], "effort trajectory controller", follow_and_draw)


def with_arm_bringup(out_path: str, gui: bool, demo: str, launch_args: List[str], what: str,
                     body: Callable[[str], int]) -> int:
    """arm_bringup.launch (with ``launch_args``) on a private master, ``body(out_path)`` run against it, the
    launch stopped after; the launch's log beside the picture."""
    log_dir = os.path.join(os.path.dirname(os.path.abspath(out_path)), f"{demo}_demo_logs")
    os.makedirs(log_dir, exist_ok=True)
    with PrivateMaster() as master:
        os.environ.update(ROS_MASTER_URI=master.uri, ROS_LOG_DIR=log_dir)
        with open(os.path.join(log_dir, "roslaunch.log"), "w") as launch_log:
            simulation = subprocess.Popen(
                ["roslaunch", "arm_gazebo", "arm_bringup.launch", f"gui:={str(gui).lower()}"] + launch_args,
                env=os.environ, stdout=launch_log, stderr=subprocess.STDOUT, start_new_session=True)
        try:
            print(f"mbot demo --{demo}: arm_bringup.launch, {what} (log: {os.path.relpath(log_dir)})",
                  file=sys.stderr, flush=True)
            return body(out_path)
        finally:
            stop_process_group(simulation)


def follow_and_draw(out_path: str) -> int:
    rospy.init_node("mbot_arm_demo", disable_signals=True)
    recorder = StateRecorder()
    client = actionlib.SimpleActionClient("/arm_controller/follow_joint_trajectory", FollowJointTrajectoryAction)
    if not client.wait_for_server(rospy.Duration(120.0)):
        print("mbot demo --arm: no follow_joint_trajectory action within 120 s (see the log)", file=sys.stderr)
        return 1
    deadline = time.monotonic() + 60.0
    while not recorder.arrays()[3]:
        if time.monotonic() > deadline:
            print("mbot demo --arm: no /arm_controller/state within 60 s", file=sys.stderr)
            return 1
        time.sleep(0.05)
    names = recorder.arrays()[3]
    trajectory = JointTrajectory(joint_names=names)
    for seconds, positions in WAYPOINTS:
        trajectory.points.append(JointTrajectoryPoint(positions=positions,
                                                      time_from_start=rospy.Duration.from_sec(seconds)))
    # Times come from the state's stamps (sim time): this node may have started before use_sim_time was set.
    first = len(recorder.arrays()[0])
    client.send_goal(FollowJointTrajectoryGoal(trajectory=trajectory))
    if not client.wait_for_result(rospy.Duration(120.0)):
        print("mbot demo --arm: no result within 120 s", file=sys.stderr)
        return 1
    result = client.get_result()
    ended, deadline = recorder.arrays()[0][-1], time.monotonic() + 30.0
    while recorder.arrays()[0][-1] < ended + 0.5 and time.monotonic() < deadline:  # half a second to settle
        time.sleep(0.02)
    times, desired, actual, _ = recorder.arrays()
    times, desired, actual = times[first:] - times[first], desired[first:], actual[first:]
    errors = np.abs(desired - actual)
    outcome = ERROR_CODES.get(result.error_code, str(result.error_code))
    summary = [f"result: {outcome} {result.error_string}".rstrip(),
               "largest tracking error per joint (rad): " + ", ".join(f"{e:.4f}" for e in errors.max(axis=0)),
               "final error per joint (rad): " + ", ".join(f"{e:.4f}" for e in errors[-1])]
    os.makedirs(os.path.dirname(os.path.abspath(out_path)), exist_ok=True)
    draw(times, desired, actual, names, out_path, f"arm: commanded and actual joint positions ({outcome})")
    for line in summary + [f"picture: {os.path.relpath(out_path)}"]:
        print(line)
    return 0 if result.error_code == 0 else 1
