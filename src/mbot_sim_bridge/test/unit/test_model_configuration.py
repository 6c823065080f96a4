"""set_model_configuration (and spawn_model -J) on the six-joint arm: joints set exactly before the next step,
controllers starting from (or, running, holding) the set positions, and every bad request refused with nothing
moved."""
import math
import os

import pytest
from ros_control_fixtures import WORKSPACE_SRC, load_yaml, simulate, start_controllers, switch_stepping
from sensor_fixtures import expanded

from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.errors import ModelError
from mbot_sim_bridge.package_uris import resolve_package_uris

ARM_XACRO = os.path.join(WORKSPACE_SRC, "arm_description", "urdf", "arm.urdf.xacro")
CONFIG = os.path.join(WORKSPACE_SRC, "arm_gazebo", "config", "arm_{}_controllers.yaml")
ARM_JOINTS = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
              "wrist_3_joint"]
# shoulder_pan beyond pi: the hardware's step-by-step unwrapping alone would read it 2 pi lower.
POSE = [4.0, -1.2, 1.5, -0.9, 0.7, 0.4]


@pytest.fixture(params=["effort", "position"])
def arm(request):
    interface = request.param
    urdf = expanded(ARM_XACRO,
                        transmission_hw_interface=f"hardware_interface/{interface.capitalize()}JointInterface")
    sim, spawned, plugin = simulate(urdf, load_yaml(CONFIG.format(interface)), "robot",
                                    package_uris=resolve_package_uris, namespace="/")
    with sim:
        yield sim, spawned, plugin


def positions(spawned, names=ARM_JOINTS):
    return [position for position, _, _ in spawned.robot.joint_state(names)]


def test_joints_are_set_exactly_and_controllers_started_afterwards_hold_them(arm):
    sim, spawned, plugin = arm
    assert sim.set_model_configuration("robot", ARM_JOINTS + ["left_finger_joint"], POSE + [0.03]) == []
    assert positions(spawned) == pytest.approx(POSE, abs=1e-12)
    # The mimic finger follows its leader at once.
    assert positions(spawned, ["right_finger_joint"]) == pytest.approx([0.03], abs=1e-12)
    for name in ("joint_state_controller", "arm_controller"):
        assert plugin.manager.load(name, plugin.urdf)
    switch_stepping(sim, plugin.manager, ["joint_state_controller", "arm_controller"])
    hw_positions = [plugin.hw.joints[name].position for name in ARM_JOINTS]
    assert hw_positions == pytest.approx(POSE, abs=1e-6)  # one step later, held by a motor
    controller = plugin.manager.find("arm_controller").controller
    sim.step(1000)
    assert controller.desired[0] == pytest.approx(POSE, abs=2e-4)
    assert positions(spawned) == pytest.approx(POSE, abs=5e-3)


def test_running_controllers_hold_the_new_positions_instead_of_pulling_back(arm):
    sim, spawned, plugin = arm
    controller = start_controllers(sim, plugin, "arm_controller", "joint_state_controller")
    sim.step(200)
    sim.set_model_configuration("robot", ARM_JOINTS, POSE)
    sim.step(1000)
    assert controller.desired[0] == pytest.approx(POSE, abs=2e-4)
    assert positions(spawned) == pytest.approx(POSE, abs=5e-3)


def test_a_joint_without_a_controller_stays_where_it_was_set_under_gravity(arm):
    """The shoulder set to -1.2 rad, where gravity pulls the arm down: a position joint's command is its new
    position, and an effort joint no controller drives is held there too (unheld, it falls to -1.94 rad in 0.5 s)."""
    sim, spawned, _ = arm
    sim.set_model_configuration("robot", ["shoulder_lift_joint"], [-1.2])
    sim.step(500)
    assert positions(spawned, ["shoulder_lift_joint"]) == pytest.approx([-1.2], abs=1e-3)


@pytest.mark.parametrize("names, values, message", [
    (["elbow_joint"], [0.1, 0.2], "SetModelConfiguration: joint name and position list have different lengths"),
    (["elbow_joint"], [math.nan], "joint 'elbow_joint': position nan is not a finite number"),
    (["elbow_joint"], [math.inf], "joint 'elbow_joint': position inf is not a finite number"),
    (["elbow_joint"], [-1e300], "joint 'elbow_joint': position -1e+300 is outside its limits"),
    (["shoulder_lift_joint", "elbow_joint"], [0.5, 3.0], "joint 'elbow_joint': position 3 is outside its limits"),
])
def test_bad_values_are_refused_and_nothing_moves(arm, names, values, message):
    sim, spawned, _ = arm
    sim.step(10)
    before = positions(spawned)
    with pytest.raises(ModelError, match=message.replace("+", r"\+")):
        sim.set_model_configuration("robot", names, values)
    assert positions(spawned) == before


def test_unknown_model_gets_upstreams_answer_and_unknown_joints_are_named_and_skipped(arm):
    sim, spawned, _ = arm
    with pytest.raises(ModelError, match="^SetModelConfiguration: model does not exist$"):
        sim.set_model_configuration("no_such_model", ["elbow_joint"], [0.5])
    missing = sim.set_model_configuration("robot", ["elbow_joint", "no_such_joint", "gripper_mount_joint"],
                                          [0.5, 1.0, 1.0])
    assert missing == ["no_such_joint", "gripper_mount_joint"]  # a fixed joint does not move: none to set
    assert positions(spawned, ["elbow_joint"]) == pytest.approx([0.5], abs=1e-12)


def test_a_world_model_has_no_joints_to_set(arm, tmp_path):
    sim, _, _ = arm
    world = tmp_path / "box.world"
    world.write_text("<sdf version='1.6'><world name='w'><model name='box'><pose>2 0 0.5 0 0 0</pose><link "
                     "name='link'><collision name='c'><geometry><box><size>1 1 1</size></box></geometry></collision>"
                     "</link></model></world></sdf>")
    sim.add_world(parse_world(str(world), []))
    assert sim.set_model_configuration("box", ["hinge"], [0.3]) == ["hinge"]


def test_reset_world_returns_the_joints_to_their_spawn_positions(arm):
    sim, spawned, _ = arm
    sim.set_model_configuration("robot", ARM_JOINTS, POSE)
    sim.reset(simulation=False)
    assert positions(spawned) == pytest.approx([0.0] * 6, abs=1e-12)
