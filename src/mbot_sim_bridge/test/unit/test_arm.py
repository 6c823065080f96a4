"""The six-joint arm (arm_description, arm_gazebo): a YAML-driven xacro with package:// STL meshes, mounted on the
world, its controllers from arm_gazebo's YAML as arm_bringup.launch loads them: the effort trajectory controller
takes it through a trajectory, the gripper closes on a box, the mimic finger follows its leader."""
import os

import pytest
from ros_control_fixtures import WORKSPACE_SRC, load_yaml, run_until_ended, simulate, start_controllers
from sensor_fixtures import expanded

from mbot_sim_bridge.core.ros_control.gripper_action_controller import GripperGoal
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.ros_control.joint_trajectory_controller import (
    ABORTED, SUCCEEDED, SUCCESSFUL, JointTrajectory, TrajectoryGoal, TrajectoryPoint)
from mbot_sim_bridge.package_uris import resolve_package_uris

ARM_XACRO = os.path.join(WORKSPACE_SRC, "arm_description", "urdf", "arm.urdf.xacro")
CONFIG = os.path.join(WORKSPACE_SRC, "arm_gazebo", "config", "arm_{}_controllers.yaml")


def arm(interface):
    urdf = expanded(ARM_XACRO,
                        transmission_hw_interface=f"hardware_interface/{interface.capitalize()}JointInterface")
    assert "package://arm_description/meshes/collision/upper_arm.stl" in urdf
    sim, spawned, plugin = simulate(urdf, load_yaml(CONFIG.format(interface)), "robot",
                                    package_uris=resolve_package_uris, namespace="/")
    arm_controller = start_controllers(sim, plugin, "arm_controller", "joint_state_controller", "gripper_controller")
    return sim, spawned, arm_controller, plugin.manager.find("gripper_controller").controller



@pytest.mark.parametrize("interface", ["effort", "position"])
def test_the_arm_stays_on_its_mount_and_follows_a_trajectory_to_its_goal(interface):
    sim, spawned, controller, _ = arm(interface)
    sim.step(500)
    assert spawned.robot.root_pose().position == pytest.approx((0.0, 0.0, 0.0), abs=1e-6)
    target = [0.8, 0.6, 0.9, -0.5, 0.4, 0.3]
    points = [TrajectoryPoint([0.4, 0.3, 0.45, -0.25, 0.2, 0.15], time_from_start=1.0),
              TrajectoryPoint(target, time_from_start=2.0)]
    assert controller.accept_goal(TrajectoryGoal(JointTrajectory(controller.joint_names, points)))[0]
    end = run_until_ended(sim, controller)
    assert (end.status, end.error_code) == (SUCCEEDED, SUCCESSFUL), end
    errors = [abs(joint.position - value) for joint, value in zip(controller.joints, target)]
    assert max(errors) < 0.01, errors
    assert spawned.robot.root_pose().position == pytest.approx((0.0, 0.0, 0.0), abs=1e-6)


def test_the_gripper_reaches_an_empty_goal_stalls_on_a_box_and_its_mimic_finger_follows(tmp_path):
    sim, spawned, _, gripper = arm("effort")
    leader, follower = "left_finger_joint", "right_finger_joint"
    assert gripper.accept_goal(GripperGoal(0.035, 30.0))
    end = run_until_ended(sim, gripper)
    assert (end.status, end.reached_goal, end.stalled) == (SUCCEEDED, True, False)
    (left, _, _), (right, _, _) = spawned.robot.joint_state([leader, follower])
    assert abs(left - right) < 0.001 and left == pytest.approx(0.035, abs=0.002)
    # A static 4 cm box between the open fingers: closing, they stop on it at 2 cm from the centre line.
    x, y, z = spawned.robot.link_world_pose("gripper_base_link").position
    world = tmp_path / "box.world"
    world.write_text(f"<sdf version='1.6'><world name='w'><model name='box'><static>true</static>"
                     f"<pose>{x} {y} {z + 0.06} 0 0 0</pose><link name='link'><collision name='collision'>"
                     f"<geometry><box><size>0.03 0.04 0.03</size></box></geometry></collision></link></model>"
                     f"</world></sdf>")
    sim.add_world(parse_world(str(world)))
    assert gripper.accept_goal(GripperGoal(0.0, 30.0))
    end = run_until_ended(sim, gripper)
    assert (end.status, end.reached_goal, end.stalled) == (ABORTED, False, True)
    assert end.position == pytest.approx(0.02, abs=0.002)
    (left, _, _), (right, _, _) = spawned.robot.joint_state([leader, follower])
    assert abs(left - right) < 0.001


@pytest.mark.parametrize("position", [0.05, -0.01, 1e300, -5.0])
def test_a_gripper_goal_past_the_fingers_travel_ends_stalled_on_the_stop(position):
    """Upstream's semantics: the finger rests on its limit (0 to 0.04 m) and the goal is aborted as stalled after
    stall_timeout; before, the effort gripper chattered at the limit (up to 0.4 m/s) and never ended (the position
    gripper's command is saturated to the limit, and it stalled already)."""
    sim, spawned, _, gripper = arm("effort")
    try:
        assert gripper.accept_goal(GripperGoal(position, 30.0))
        end = run_until_ended(sim, gripper, seconds=3.0)
        assert (end.status, end.reached_goal, end.stalled) == (ABORTED, False, True)
        assert end.position == pytest.approx(0.04 if position > 0 else 0.0, abs=2e-4)
        (_, speed, _), = spawned.robot.joint_state(["left_finger_joint"])
        assert abs(speed) < 1e-3
    finally:
        sim.close()
