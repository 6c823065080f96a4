"""The arm of arm_gazebo (effort controllers, as arm_bringup.launch starts it) picks a 0.2 kg, 4 cm box with
friction 1 from a table and sets it down 0.3 m to the side (mbot_gazebo's pick plan), with the slip measured
from ground truth: the box's pose in the gripper's frame, from the fingers' closing to their opening."""
import math
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
BOX_SIDE, BOX_MASS = 0.04, 0.2
TABLE_HEIGHT = 0.05
REACH, SIDEWAYS = 0.38, 0.3  # m: the box's distance from the arm's axis; how far it is carried along y
GRIPPER = "gripper_base_link"
WORLD = """<sdf version='1.6'><world name='pick'>
  <include><uri>model://ground_plane</uri></include>
  {plugins}
  <model name='table'><static>true</static><pose>{x} 0 {table_z} 0 0 0</pose><link name='link'>
    <collision name='collision'><geometry><box><size>0.2 0.8 {table_height}</size></box></geometry></collision>
  </link></model>
  <model name='box'><pose>{x} {y} {z} 0 0 {yaw}</pose><link name='link'>
    <inertial><mass>{mass}</mass><inertia><ixx>{inertia}</ixx><iyy>{inertia}</iyy><izz>{inertia}</izz></inertia>
    </inertial>
    <collision name='collision'><geometry><box><size>{side} {side} {side}</size></box></geometry>
      <surface><friction><ode><mu>1</mu><mu2>1</mu2></ode></friction></surface></collision>
  </link></model>
</world></sdf>"""


@dataclass
class PickRecord:
    outcomes: Dict[str, object] = field(default_factory=dict)
    slips: List[float] = field(default_factory=list)  # m, the box's offset in the gripper's frame, every 10 ms
    target: tuple = ()

    @property
    def slip(self) -> float:
        return max(self.slips)


def pick_world(tmp_path, x, y, plugins=""):
    """The table and the box at (x, y) on it, with the world's ``plugins`` (SDF <plugin> elements)."""
    path = os.path.join(str(tmp_path), "pick.world")
    side = BOX_SIDE
    with open(path, "w") as world:
        world.write(WORLD.format(x=x, y=y, z=TABLE_HEIGHT + side / 2, yaw=math.atan2(y, x), table_z=TABLE_HEIGHT / 2,
                                 table_height=TABLE_HEIGHT, mass=BOX_MASS, inertia=BOX_MASS * side * side / 6, side=side,
                                 plugins=plugins))
    return path


def arm_with_box(tmp_path, urdf_extra="", world_plugins=""):
    """The arm (``urdf_extra`` added inside its <robot>) with its controllers started, the table and box."""
    urdf = expand_xacro(ARM_XACRO).replace("</robot>", urdf_extra + "</robot>")
    pan = math.asin(SIDEWAYS / 2 / REACH)
    world = pick_world(tmp_path, REACH * math.cos(pan), -SIDEWAYS / 2, world_plugins)
    sim, spawned, plugin = simulate(urdf, load_yaml(CONFIG), "robot", package_uris=resolve_package_uris,
                                    namespace="/", world=world)
    arm = start_controllers(sim, plugin, "arm_controller", "joint_state_controller", "gripper_controller")
    return sim, spawned, arm, plugin.manager.find("gripper_controller").controller


def box_in_gripper(sim, spawned):
    return compose(inverse(spawned.robot.link_world_pose(GRIPPER)), sim.engine.model_pose("box"))


def pick(sim, spawned, arm, gripper, after_close: Callable[[], None] = lambda: None,
         before_release: Callable[[], None] = lambda: None) -> PickRecord:
    """Runs the pick plan; ``after_close`` and ``before_release`` are called around the carry (an attach and a
    detach)."""
    pan = math.asin(SIDEWAYS / 2 / REACH)
    box = (REACH * math.cos(pan), -SIDEWAYS / 2, TABLE_HEIGHT + BOX_SIDE / 2)
    record = PickRecord(target=(box[0], SIDEWAYS / 2, box[2]))
    held = None
    for step in pick_and_place(ArmGeometry.from_description(), box, record.target):
        if step.name == "release":
            before_release()
            held = None
        if step.gripper is not None:
            assert gripper.accept_goal(GripperGoal(step.gripper, step.max_effort))
            record.outcomes[step.name] = run_until_ended(sim, gripper)
        else:
            points = [TrajectoryPoint(list(positions), time_from_start=seconds) for seconds, positions in step.waypoints]
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
    return record


def placement_error(sim, record) -> float:
    return float(np.linalg.norm(np.subtract(sim.engine.model_pose("box").position, record.target)))
