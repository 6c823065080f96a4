"""NaN, inf and huge numbers through ros_control and the physics: the offending robot is refused, clamped or
frozen with one message, and every other model keeps its pose (before, a NaN wheel command sank them all)."""
import logging
import math
import os
from dataclasses import replace

import pytest

from mbot_sim_bridge.core.errors import BridgeError, ModelError
from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.description.sdf_spawn import spawn_world_xml
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.ros_control.controller_table import CORE_CONTROLLERS
from mbot_sim_bridge.core.ros_control.diff_drive_controller import TwistController
from mbot_sim_bridge.core.ros_control.four_wheel_steering_controller import FourWheelSteeringController
from mbot_sim_bridge.core.ros_control.gripper_action_controller import GripperActionController, GripperGoal
from mbot_sim_bridge.core.ros_control.joint_trajectory_controller import (JointTrajectory, JointTrajectoryController,
                                                                          TrajectoryPoint)

from ros_control_fixtures import (CAR_CONFIG, MBOT_YAML, ROBOTS, expand_xacro_arm, expand_xacro_car, load_yaml,
                                  simulate, start_controllers)
from sensor_fixtures import course_urdf

BYSTANDER_TOLERANCE = 1e-3  # m
BAD_VALUES = (math.nan, math.inf, -math.inf, 1e308, -1e308)


@pytest.fixture(scope="module")
def mbot_ros_control_urdf():
    return course_urdf("mbot_ros_control_gazebo")


def with_bystander(sim, urdf):
    """A second mbot without plugins two metres away, settled: the model nothing may disturb."""
    bystander = urdf.replace("libgazebo_ros_control.so", "libnot_simulated.so")
    sim.spawn_robot(parse_robot(bystander, "model 'bystander'"), "bystander", pose_from_xyz_rpy((2, 0, 0), (0, 0, 0)))
    sim.step(300)
    return sim.engine.model_pose("bystander").position


def messages(caplog, *texts):
    return [record for record in caplog.records if all(text in record.getMessage() for text in texts)]


ARM_PID = {"p": 100.0, "d": 5.0}
# Every controller type that takes a command: the robot it drives and its configuration.
COMMANDED = {
    "position_controllers/JointPositionController": ("Position", {"joint": "shoulder"}),
    "position_controllers/JointGroupPositionController": ("Position", {"joints": ["shoulder", "elbow"]}),
    "velocity_controllers/JointVelocityController": ("mbot", {"joint": "left_wheel_joint"}),
    "velocity_controllers/JointGroupVelocityController": ("mbot", {"joints": ["left_wheel_joint",
                                                                             "right_wheel_joint"]}),
    "velocity_controllers/JointPositionController": ("mbot", {"joint": "left_wheel_joint", "pid": {"p": 10.0}}),
    "effort_controllers/JointEffortController": ("Effort", {"joint": "shoulder"}),
    "effort_controllers/JointGroupEffortController": ("Effort", {"joints": ["shoulder", "elbow"]}),
    "effort_controllers/JointPositionController": ("Effort", {"joint": "shoulder", "pid": ARM_PID}),
    "effort_controllers/JointVelocityController": ("Effort", {"joint": "shoulder", "pid": ARM_PID}),
    "effort_controllers/JointGroupPositionController": ("Effort", {"joints": ["shoulder", "elbow"],
                                                                   "shoulder": {"pid": ARM_PID},
                                                                   "elbow": {"pid": ARM_PID}}),
    "diff_drive_controller/DiffDriveController": ("mbot", load_yaml(MBOT_YAML)["mobile_base_controller"]),
    "ackermann_steering_controller/AckermannSteeringController":
        ("ackermann", load_yaml(CAR_CONFIG.format("ackermann"))["car_controller"]),
    "four_wheel_steering_controller/FourWheelSteeringController":
        ("four_wheel", load_yaml(CAR_CONFIG.format("four_wheel"))["car_controller"]),
    "position_controllers/JointTrajectoryController": ("Position", {"joints": ["shoulder", "elbow"]}),
    "velocity_controllers/JointTrajectoryController": ("Velocity", {"joints": ["shoulder", "elbow"],
                                                                    "gains": {"shoulder": {"p": 20.0},
                                                                              "elbow": {"p": 20.0}}}),
    "effort_controllers/JointTrajectoryController": ("Effort", {"joints": ["shoulder", "elbow"],
                                                                "gains": {"shoulder": ARM_PID, "elbow": ARM_PID}}),
    "position_controllers/GripperActionController": ("Position", {"joint": "elbow"}),
    "effort_controllers/GripperActionController": ("Effort", {"joint": "elbow", "gains": {"elbow": ARM_PID}}),
}


def test_every_commanded_controller_type_is_fuzzed():
    assert set(COMMANDED) == set(CORE_CONTROLLERS) - {"joint_state_controller/JointStateController"}


def command(sim, controller, value):
    """``value`` for every joint, as the controller's command topic would carry it; the refusal, if any."""
    if isinstance(controller, TwistController):
        return controller.set_command(value, value, sim.sim_time)
    if isinstance(controller, FourWheelSteeringController):  # both its topics
        complaints = [controller.set_twist(value, value, value, sim.sim_time),
                      controller.set_steering(value, value, value, sim.sim_time)]
        return complaints[0] or complaints[1]
    if isinstance(controller, JointTrajectoryController):
        controller.command(JointTrajectory(controller.joint_names,
                                           [TrajectoryPoint([value] * len(controller.joints), time_from_start=0.5)]))
        return None
    if isinstance(controller, GripperActionController):
        controller.accept_goal(GripperGoal(value, 10.0))
        return None
    if hasattr(controller, "set_commands"):
        return controller.set_commands([value] * len(controller.joints))
    return controller.set_command(value)


@pytest.mark.parametrize("controller_type", sorted(COMMANDED))
def test_non_finite_and_huge_commands_disturb_no_other_model(mbot_ros_control_urdf, controller_type, caplog):
    robot, config = COMMANDED[controller_type]
    if robot == "mbot":
        urdf, name = mbot_ros_control_urdf, "mbot"
    elif robot in ("ackermann", "four_wheel"):
        urdf, name = expand_xacro_car(robot), "car"
    else:
        urdf, name = expand_xacro_arm(robot), "arm"
    sim, spawned, plugin = simulate(urdf, {"fuzzed": dict(config, type=controller_type)}, name,
                                    namespace=None if name == "arm" else "/")  # the others' robotNamespace
    try:
        resting = with_bystander(sim, mbot_ros_control_urdf)
        controller = start_controllers(sim, plugin, "fuzzed")
        for value in BAD_VALUES:
            complaint = command(sim, controller, value)
            if not math.isfinite(value):  # refused: said once by the controller, or answered as upstream does
                said = messages(caplog, "controller 'fuzzed'", f"command {value}", "not a finite number")
                assert len(said) == 1 or complaint.startswith("Received NaN in "), value
            sim.step(300)
            position = sim.engine.model_pose(name).position
            assert all(math.isfinite(v) for v in position), (value, position)
            assert all(math.isfinite(v) for state in spawned.robot.joint_state(spawned.robot.movable_joints)
                       for v in state), value
            assert math.dist(sim.engine.model_pose("bystander").position, resting) < BYSTANDER_TOLERANCE, value
        assert not messages(caplog, "frozen"), "a NaN reached the physics"
        clamped = [record.getMessage() for record in messages(caplog, "is beyond the engine's")]
        assert len(clamped) == len(set(clamped))  # once per joint and value
    finally:
        sim.close()


def effort_arm(shoulder_pid):
    """The effort-interface two-joint arm with these PID gains for its shoulder position controller."""
    controllers = load_yaml(os.path.join(ROBOTS, "config", "arm_effort.yaml"))
    controllers["shoulder_position_controller"]["pid"] = shoulder_pid
    return simulate(expand_xacro_arm("Effort"), controllers, "arm")


@pytest.mark.parametrize("gain, value", [("i", math.inf), ("p", math.nan), ("d", "fast"), ("i_clamp", math.nan)])
def test_pid_gains_that_are_not_finite_numbers_refuse_the_controller(gain, value, caplog):
    sim, _, plugin = effort_arm({"p": 1000.0, "i": 500.0, "d": 20.0, "i_clamp": 5.0, gain: value})
    try:
        assert not plugin.manager.load("shoulder_position_controller", plugin.urdf)
        assert messages(caplog, f"shoulder_position_controller/pid/{gain} is {value!r}", "finite number")
        assert plugin.manager.find("shoulder_position_controller") is None
    finally:
        sim.close()


def test_a_pid_output_that_overflows_holds_the_joint(caplog):
    """Finite but absurd gains (p 1e308) overflow the PID's output to inf; the hardware layer holds the joint."""
    sim, spawned, plugin = effort_arm({"p": 1e308, "d": 1e308})
    try:
        start_controllers(sim, plugin, "shoulder_position_controller").set_command(1.5)
        sim.step(500)
        assert all(math.isfinite(v) for state in spawned.robot.joint_state(["shoulder", "elbow"]) for v in state)
        assert all(math.isfinite(v) for v in sim.engine.model_pose("arm").position)
        held = [record.getMessage() for record in messages(caplog, "joint 'shoulder'", "not a finite number", "held")]
        assert held and len(set(held)) == len(held), held  # once for each of inf, -inf
    finally:
        sim.close()


def test_a_robot_the_physics_turns_nan_is_frozen_and_the_others_keep_their_poses(mbot_ros_control_urdf, caplog):
    """A NaN that reaches the engine anyway (here a motor set directly, past every guard) is caught at the step."""
    sim, spawned, plugin = simulate(mbot_ros_control_urdf, load_yaml(MBOT_YAML), "mbot", namespace="/")
    try:
        resting = with_bystander(sim, mbot_ros_control_urdf)
        controller = start_controllers(sim, plugin, "mobile_base_controller")
        spawned.robot.set_joint_velocity("left_wheel_joint", math.nan, 10.0)
        sim.step(500)
        assert all(math.isfinite(v) for v in sim.engine.model_pose("mbot").position)
        assert math.dist(sim.engine.model_pose("mbot").position, (0, 0, 0)) < 0.01, "not put back at its spawn pose"
        assert math.dist(sim.engine.model_pose("bystander").position, resting) < BYSTANDER_TOLERANCE
        assert len(messages(caplog, "model 'mbot'", "NaN", "frozen")) == 1
        # Frozen: its controllers no longer run, so a command does not move it.
        controller.set_command(0.3, 0.0, sim.sim_time)
        sim.step(500)
        assert math.dist(sim.engine.model_pose("mbot").position, (0, 0, 0)) < 0.01
        # reset_world lifts the freeze: the same command drives it.
        sim.reset(simulation=False)
        for _ in range(10):
            controller.set_command(0.3, 0.0, sim.sim_time)
            sim.step(100)
        assert sim.engine.model_pose("mbot").position[0] > 0.1
        assert math.dist(sim.engine.model_pose("bystander").position, resting) < BYSTANDER_TOLERANCE
    finally:
        sim.close()


def test_a_healthy_run_freezes_nothing(mbot_ros_control_urdf, caplog):
    """The check after every step finds nothing and says nothing in a healthy run."""
    caplog.set_level(logging.INFO)
    sim, _, _ = simulate(mbot_ros_control_urdf, load_yaml(MBOT_YAML), "mbot", namespace="/")
    try:
        sim.step(1000)
        assert sim.engine.models_not_finite() == []
        assert not messages(caplog, "frozen")
    finally:
        sim.close()


CRATE = """<sdf version="1.6"><model name="crate"><pose>0 0 0.25 0 0 0</pose><link name="link">
  <inertial><mass>{mass}</mass><inertia><ixx>{ixx}</ixx><iyy>{iyy}</iyy><izz>{izz}</izz></inertia></inertial>
  <collision name="c"><geometry><box><size>0.5 0.5 0.5</size></box></geometry></collision></link></model></sdf>"""


def spawned_crate(tmp_path, name, position, mass=1.0, ixx=0.04, iyy=0.04, izz=0.04):
    path = tmp_path / f"{name}.world"
    path.write_text(spawn_world_xml(CRATE.format(mass=mass, ixx=ixx, iyy=iyy, izz=izz), name,
                                    pose_from_xyz_rpy(position, (0, 0, 0))))
    return parse_world(str(path))


@pytest.mark.parametrize("inertial, message", [
    ({"mass": 1e300}, r"<mass>: 1e\+300 is outside the valid range >= 1e-06 and <= 1e\+09"),
    ({"mass": 1e-300}, r"<mass>: 1e-300 is outside the valid range >= 1e-06 and <= 1e\+09"),
    ({"mass": -1}, r"<mass>: -1 is outside the valid range"),
    ({"ixx": 0}, r"<inertia> has principal moments 0, 0.04, 0.04; they must be at least 1e-12"),
    ({"ixx": 1e300}, r"<ixx>: 1e\+300 is outside the valid range >= -1e\+09 and <= 1e\+09"),
    ({"ixx": 1, "iyy": 1, "izz": 3}, r"<inertia> has principal moments 1, 1, 3; .* at most the sum of the other two"),
])
def test_sdf_inertials_that_would_turn_the_model_nan_are_refused_naming_model_link_and_tag(tmp_path, inertial,
                                                                                         message):
    with pytest.raises(BridgeError, match=r"\.world:\d+: link 'link' of model 'crate': " + message):
        spawned_crate(tmp_path, "crate", (0, 0, 0), **inertial)


ARM_ON_BASE = """<robot name="r"><link name="base"><inertial><mass value="{base_mass}"/>
  <inertia ixx="{base_ixx}" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><mass value="1"/>
  <inertia ixx="{arm_i}" iyy="{arm_i}" izz="{arm_i}" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="{joint}"><parent link="base"/><child link="arm"/><axis xyz="1 0 0"/>
  <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"""


MASS_RANGE = r"the valid range 0 or >= 1e-06 and <= 1e\+09"


@pytest.mark.parametrize("values, message", [
    ({"base_mass": 1e-300}, r"link 'base': <mass value>: 1e-300 is outside " + MASS_RANGE),
    ({"base_mass": 1e300}, r"link 'base': <mass value>: 1e\+300 is outside " + MASS_RANGE),
    ({"base_ixx": 1e300}, r"link 'base': <inertia ixx>: 1e\+300 is outside the valid range >= 0 and <= 1e\+09"),
    ({"arm_i": 0}, r"link 'arm': <inertia> has principal moments 0, 0, 0 kg m\^2 for a mass of 1 kg; each must be at "
                   r"least 1e-12"),
])
def test_urdf_masses_and_inertias_bullet_cannot_step_are_refused_naming_model_link_and_tag(values, message):
    """Bullet flung a 1e-7 kg base 50 m and never swung an arm of inertia 0; masses of 0 (none) stay accepted, and a
    link without inertia is fine once lumped into another by a fixed joint."""
    urdf = {"base_mass": 1, "base_ixx": 0.01, "arm_i": 0.01, "joint": "revolute", **values}
    with pytest.raises(ModelError, match=r"^model 'r': " + message + "$"):
        parse_robot(ARM_ON_BASE.format(**urdf), "model 'r'")
    parse_robot(ARM_ON_BASE.format(base_mass=0, base_ixx=0, arm_i=0.01, joint="revolute"), "model 'r'")
    parse_robot(ARM_ON_BASE.format(base_mass=1, base_ixx=0.01, arm_i=0, joint="fixed"), "model 'r'")


def test_a_movable_joint_without_an_axis_direction_is_refused():
    urdf = ('<robot name="r"><link name="a"/><link name="b"/><joint name="spin" type="continuous">'
            '<parent link="a"/><child link="b"/>\n<axis xyz="0 0 0"/></joint></robot>')
    with pytest.raises(ModelError, match=r"^model 'r':2: joint 'spin': <axis xyz=\"0 0 0\"> has no direction; "
                                         r"a continuous joint needs an axis of length at least 1e-06$"):
        parse_robot(urdf, "model 'r'")


def test_a_world_model_that_turns_nan_by_itself_is_put_back_once_then_deleted(tmp_path, mbot_ros_control_urdf,
                                                                             caplog):
    """Past the checks at the door (a mass of 1e300 set here on the parsed description), an SDF model the physics
    turns NaN on every step is caught like a robot, put back once, deleted the second time; the others stay put
    and reset_world leaves them as spawned."""
    sim, _, _ = simulate(mbot_ros_control_urdf, load_yaml(MBOT_YAML), "mbot", namespace="/")
    try:
        resting = with_bystander(sim, mbot_ros_control_urdf)
        sim.add_world(spawned_crate(tmp_path, "steady", (-2, 0, 0)))
        sim.step(300)
        steady = sim.engine.model_pose("steady").position
        world = spawned_crate(tmp_path, "heavy", (0, 2, 0))
        heavy = replace(world.models[0], links=tuple(replace(link, mass=1e300) for link in world.models[0].links))
        with caplog.at_level(logging.ERROR):
            sim.add_world(replace(world, models=(heavy,)))
            sim.step(500)
        assert "heavy" not in sim.model_names()
        assert len(messages(caplog, "model 'heavy'", "NaN; it is put back")) == 1
        assert len(messages(caplog, "model 'heavy'", "NaN again", "deleted")) == 1
        assert math.dist(sim.engine.model_pose("bystander").position, resting) < 1e-4
        assert math.dist(sim.engine.model_pose("steady").position, steady) < 1e-4
        assert sim.engine.models_not_finite() == []
        sim.reset(simulation=False)
        assert math.dist(sim.engine.model_pose("mbot").position, (0, 0, 0)) < 1e-6
        assert math.dist(sim.engine.model_pose("bystander").position, (2, 0, 0)) < 1e-6
        assert math.dist(sim.engine.model_pose("steady").position, (-2, 0, 0.25)) < 1e-6
    finally:
        sim.close()
