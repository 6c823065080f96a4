"""The arm of arm_gazebo (effort controllers, as arm_bringup.launch starts it) in arm_gazebo's pick world picks
the 0.2 kg, 4 cm box with friction 1 from the table and sets it down 0.3 m to the side (mbot_gazebo's pick plan),
with the slip measured from ground truth: the box's offset in the gripper's frame, from the fingers' closing to
their opening."""
import os
from dataclasses import dataclass, field
from typing import Callable, Dict, List

import numpy as np
from ros_control_fixtures import WORKSPACE_SRC, load_yaml, run_until_ended, simulate, start_controllers

from mbot_gazebo.pick_plan import ArmGeometry, pick_and_place
from mbot_sim_bridge.core.geometry import compose, inverse
from mbot_sim_bridge.core.ros_control.gripper_action_controller import GripperGoal
from mbot_sim_bridge.core.ros_control.joint_trajectory_controller import (
    SUCCEEDED, JointTrajectory, TrajectoryGoal, TrajectoryPoint)
from mbot_sim_bridge.package_uris import resolve_package_uris
from mbot_sim_bridge.robot_description import expand_xacro

ARM_XACRO = os.path.join(WORKSPACE_SRC, "arm_description", "urdf", "arm.urdf.xacro")
CONFIG = os.path.join(WORKSPACE_SRC, "arm_gazebo", "config", "arm_effort_controllers.yaml")
PICK_WORLD = os.path.join(WORKSPACE_SRC, "arm_gazebo", "worlds", "pick.world")
GRIPPER = "gripper_base_link"


@dataclass
class PickRecord:
    outcomes: Dict[str, object] = field(default_factory=dict)
    slips: List[float] = field(default_factory=list)  # m, the box's offset in the gripper's frame, every 10 ms
    target: tuple = ()

    @property
    def slip(self) -> float:
        return max(self.slips)


def arm_with_box(urdf_extra=""):
    """The arm (``urdf_extra`` added inside its <robot>) with its controllers started, in arm_gazebo's pick world
    (the table, the box, the link attacher)."""
    urdf = expand_xacro(ARM_XACRO).replace("</robot>", urdf_extra + "</robot>")
    sim, spawned, plugin = simulate(urdf, load_yaml(CONFIG), "robot", package_uris=resolve_package_uris,
                                    namespace="/", world=PICK_WORLD)
    arm = start_controllers(sim, plugin, "arm_controller", "joint_state_controller", "gripper_controller")
    return sim, spawned, arm, plugin.manager.find("gripper_controller").controller


def box_in_gripper(sim, spawned):
    return compose(inverse(spawned.robot.link_world_pose(GRIPPER)), sim.engine.model_pose("box"))


def pick(sim, spawned, arm, gripper, after_close: Callable[[], None] = lambda: None,
         before_release: Callable[[], None] = lambda: None, after_release: Callable[[], None] = lambda: None,
         max_effort: float = 20.0) -> PickRecord:
    """Runs the pick plan, the fingers closing with ``max_effort`` (N); ``after_close``, ``before_release`` and
    ``after_release`` are called around the carry (an attach and a detach, or waits for them)."""
    box = sim.engine.model_pose("box").position
    record = PickRecord(target=(box[0], -box[1], box[2]))  # the other end of the table
    held = None
    for step in pick_and_place(ArmGeometry.from_description(), box, record.target, max_effort=max_effort):
        if step.name == "release":
            before_release()
            held = None
        if step.gripper is not None:
            assert gripper.accept_goal(GripperGoal(step.gripper, step.max_effort))
            record.outcomes[step.name] = run_until_ended(sim, gripper)
        else:
            points = [TrajectoryPoint(list(positions), time_from_start=seconds)
                      for seconds, positions in step.waypoints]
            assert arm.accept_goal(TrajectoryGoal(JointTrajectory(arm.joint_names, points)))[0]
            while True:
                sim.step(10)
                if held is not None:
                    record.slips.append(float(np.linalg.norm(np.subtract(box_in_gripper(sim, spawned).position,
                                                                           held))))
                if arm.ended:
                    record.outcomes[step.name] = arm.ended.pop(0)
                    break
            assert record.outcomes[step.name].status == SUCCEEDED, (step.name, record.outcomes[step.name])
        if step.name == "close":
            after_close()
            held = box_in_gripper(sim, spawned).position
        if step.name == "release":
            after_release()
    return record


def placement_error(sim, record) -> float:
    return float(np.linalg.norm(np.subtract(sim.engine.model_pose("box").position, record.target)))


def step_until(sim, condition, seconds: float, what: str):
    """Step 10 ms at a time until ``condition()``, at most ``seconds`` of sim time."""
    for _ in range(int(seconds / 0.01)):
        if condition():
            return
        sim.step(10)
    raise AssertionError(f"{what} not within {seconds} s")
