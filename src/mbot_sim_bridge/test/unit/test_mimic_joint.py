"""Mimic joints (core/joints/mimic_joint.py): a gripper finger with a URDF <mimic> follows its leader within 1 mm while
the leader moves at a gripper's pace, and so does one set up with roboticsgroup's plugin (position or PID effort);
bad mimics are refused with the joint named."""
import numpy as np
import pytest
from plugin_robots import MIMIC_GRIPPER, MIMIC_PLUGIN_BLOCK
from sensor_fixtures import world_simulation

from mbot_sim_bridge.core.errors import ConfigError, ModelError
from mbot_sim_bridge.core.joints.mimic_joint import MimicJoint
from mbot_sim_bridge.core.parameters import Parameters
from mbot_sim_bridge.core.description.robot_model import parse_robot

URDF_MIMIC = '<mimic joint="left_finger_joint" multiplier="-1" offset="0.002"/>'


def pid_gains(gains) -> Parameters:
    return Parameters({"gazebo_ros_control": {"pid_gains": {"right_finger_joint": gains}}})


def gripper(tmp_path, mimic="", plugin="", parameters=None):
    sim = world_simulation(tmp_path)
    if parameters is not None:
        sim.parameters = parameters
    urdf = MIMIC_GRIPPER.format(mimic=mimic, plugin=plugin)
    spawned = sim.spawn_robot(parse_robot(urdf, "model 'gripper'"), "gripper")
    return sim, spawned


def worst_follow_error(sim, spawned):
    """Drive the leader out and back at 5 cm/s, as a gripper moves (0.6 s each way): the worst
    |follower − (−leader + 0.002)| and where the leader ends."""
    sim.step(100)  # the follower, spawned at 0, reaches the offset first
    worst = 0.0
    for speed in (0.05, -0.05):
        spawned.robot.set_joint_velocity("left_finger_joint", speed, 20.0)
        for _ in range(120):
            sim.step(5)
            (leader, _, _), (follower, _, _) = spawned.robot.joint_state(["left_finger_joint", "right_finger_joint"])
            worst = max(worst, abs(follower - (-leader + 0.002)))
    return worst, leader


@pytest.mark.parametrize("how", ["urdf mimic", "plugin", "plugin with PID"])
def test_the_mimic_finger_follows_its_leader_within_a_millimetre(tmp_path, how):
    gains = pid_gains({"p": 2000.0, "i": 0.0, "d": 20.0})
    arguments = {"urdf mimic": dict(mimic=URDF_MIMIC),
                 "plugin": dict(plugin=MIMIC_PLUGIN_BLOCK.format(extra="")),
                 "plugin with PID": dict(plugin=MIMIC_PLUGIN_BLOCK.format(extra="<hasPID/>"), parameters=gains)}[how]
    sim, spawned = gripper(tmp_path, **arguments)
    assert [plugin.follower for plugin in spawned.plugins if isinstance(plugin, MimicJoint)] == ["right_finger_joint"]
    assert sim.steps_to_next_event() > 1  # the servo runs between the steps of the loop's batches
    worst, leader = worst_follow_error(sim, spawned)
    print(f"figure: mimic finger ({how}): worst |follower - (-leader + 0.002)| {worst * 1000:.3f} mm while the "
          f"leader goes 3 cm out and back at 5 cm/s")
    assert abs(leader) < 0.002  # out and back
    assert worst < 0.001
    sim.close()


def test_bad_mimics_are_refused_with_the_joint_named(tmp_path):
    with pytest.raises(ModelError, match="joint 'right_finger_joint': <mimic joint='thumb_joint'> needs a movable"):
        gripper(tmp_path, mimic='<mimic joint="thumb_joint"/>')
    with pytest.raises(ConfigError, match="<multiplier>"):
        gripper(tmp_path, mimic='<mimic joint="left_finger_joint" multiplier="1e300"/>')
    with pytest.raises(ConfigError, match="hasPID: no usable gains under /gazebo_ros_control/pid_gains/right_finger"):
        gripper(tmp_path, plugin=MIMIC_PLUGIN_BLOCK.format(extra="<hasPID/>"))


def test_pid_effort_is_clamped_to_max_effort(tmp_path):
    gains = pid_gains({"p": 1e6})
    sim, spawned = gripper(tmp_path, plugin=MIMIC_PLUGIN_BLOCK.format(extra="<hasPID/><maxEffort>0.5</maxEffort>"),
                           parameters=gains)
    spawned.robot.set_joint_velocity("left_finger_joint", 0.05, 20.0)
    sim.step(20)
    (_, _, effort), = spawned.robot.joint_state(["right_finger_joint"])
    assert abs(effort) <= 0.5 + 1e-9
    assert np.isfinite(effort)
    sim.close()


@pytest.mark.parametrize("multiplier", [1e6, -1e6])
def test_a_huge_multiplier_keeps_the_follower_within_its_travel_and_reset_world_settles_it(tmp_path, multiplier):
    """The follower's target is held to its limits: with a multiplier of 1e6 the gripper flew 11.7 m up, and
    jumped again after reset_world."""
    mimic = f'<mimic joint="left_finger_joint" multiplier="{multiplier:g}" offset="0"/>'
    sim, spawned = gripper(tmp_path, mimic=mimic)
    try:
        for _ in range(2):
            spawned.robot.set_joint_velocity("left_finger_joint", 0.05, 20.0)
            sim.step(300)
            (follower, _, _), = spawned.robot.joint_state(["right_finger_joint"])
            assert abs(follower) <= 0.04 + 1e-3
            assert np.linalg.norm(spawned.robot.root_pose().position) < 0.05
            sim.reset(simulation=False)
            sim.step(300)
            assert np.linalg.norm(spawned.robot.root_pose().position) < 0.05
    finally:
        sim.close()
