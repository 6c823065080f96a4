"""core/ros_control/ and core/ros_control/gazebo_ros_control.py: transmissions, limits, the PID, the diff
drive's odometry and speed limiter, the controller manager's state machine and texts, and the mbot and a
two-joint arm driven through the controllers in the simulation, with no ROS master."""
import logging
import math
import os
import threading

import pytest

from mbot_sim_bridge.core.errors import ConfigError
from mbot_sim_bridge.core.ros_control.angles import normalize_angle, shortest_angular_distance_with_limits
from mbot_sim_bridge.core.ros_control.control_toolbox import Pid
from mbot_sim_bridge.core.ros_control.diff_drive_controller import (CommandSample, DiffDriveOdometry,
                                                                    OdometrySample, SpeedLimiter)
from mbot_sim_bridge.core.ros_control.joint_limits import JointLimits, apply_limit_params
from mbot_sim_bridge.core.ros_control.transmissions import parse_transmissions
from mbot_sim_bridge.core.simulation import MAX_BATCH_SIM_SECONDS
from mbot_sim_bridge.core.xml_values import parse_xml

from ros_control_fixtures import (MBOT_YAML, ROBOTS, arm, expand_xacro_arm, load_yaml, recording_batches, simulate,
                                  start_controllers, switch, switch_stepping)
from sensor_fixtures import course_urdf, measured_motion


@pytest.fixture(scope="module")
def mbot_ros_control_urdf():
    return course_urdf("mbot_ros_control_gazebo")


@pytest.fixture
def mbot(mbot_ros_control_urdf):
    sim, spawned, plugin = simulate(mbot_ros_control_urdf, load_yaml(MBOT_YAML), "mbot", namespace="/")
    manager = plugin.manager
    assert manager.load("joint_state_controller", plugin.urdf)
    assert manager.load("mobile_base_controller", plugin.urdf)
    assert switch(sim, manager, ["joint_state_controller", "mobile_base_controller"])
    yield sim, spawned, plugin, manager.find("mobile_base_controller").controller
    sim.close()


def test_a_switch_pending_when_its_model_is_deleted_is_answered_not_carried_out(mbot, caplog):
    """A STRICT switch with timeout 0 waits for the control loop for ever, as upstream's; paused, the loop does
    not come, and deleting the model must still answer the call (before, it never returned)."""
    sim, _, plugin, _ = mbot
    result = []
    thread = threading.Thread(target=lambda: result.append(plugin.manager.switch([], ["mobile_base_controller"], 2)),
                              daemon=True)
    thread.start()
    thread.join(0.3)
    assert thread.is_alive(), "the switch ran without a control update"
    sim.delete("mbot")
    thread.join(5.0)
    assert not thread.is_alive() and result == [False]
    assert "the model was deleted before the pending controller switch ran; nothing was switched" in caplog.text


# -- transmissions and limits ----------------------------------------------------------------------------------
TRANSMISSIONS = """<robot name="t">
  <transmission name="new_style"><type>transmission_interface/SimpleTransmission</type>
    <joint name="a"><hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface></joint>
    <actuator name="a_motor"><mechanicalReduction>50</mechanicalReduction></actuator></transmission>
  <transmission name="old_style"><type>transmission_interface/SimpleTransmission</type>
    <joint name="b"/>
    <actuator name="b_motor"><hardwareInterface>VelocityJointInterface</hardwareInterface></actuator></transmission>
  <transmission name="no_actuator"><type>transmission_interface/SimpleTransmission</type><joint name="c"/>
  </transmission>
</robot>"""


def test_transmissions_are_read_at_joint_and_old_actuator_level(caplog):
    document = parse_xml(TRANSMISSIONS.encode(), "test")
    transmissions = parse_transmissions(document.root.findall("transmission"), document.where)
    assert [t.name for t in transmissions] == ["new_style", "old_style"]
    assert transmissions[0].joints == [("a", ["hardware_interface/EffortJointInterface"])]
    assert transmissions[0].actuators == [("a_motor", [], 50.0)]
    assert transmissions[1].joints == [("b", [])] and transmissions[1].actuators[0][1] == ["VelocityJointInterface"]
    assert "transmission 'no_actuator' has no <actuator>" in caplog.text


def test_a_bad_mechanical_reduction_is_refused():
    document = parse_xml(TRANSMISSIONS.replace(">50<", ">fifty<").encode(), "test")
    with pytest.raises(ConfigError, match="<mechanicalReduction> 'fifty' is not a number"):
        parse_transmissions(document.root.findall("transmission"), document.where)


def test_the_mbot_wheels_are_velocity_joints_without_limits(mbot):
    _, _, plugin, _ = mbot
    assert {name: joint.interface for name, joint in plugin.hw.joints.items()} == {
        "left_wheel_joint": "VelocityJointInterface", "right_wheel_joint": "VelocityJointInterface"}
    assert all(joint.limits is None for joint in plugin.hw.joints.values())
    assert plugin.driven_joints == ("left_wheel_joint", "right_wheel_joint")
    assert plugin.control_period == pytest.approx(0.001)


def test_the_mbot_xacro_argument_control_period_sets_how_often_the_controllers_update():
    urdf = course_urdf("mbot_ros_control_gazebo", control_period="0.01")
    sim, _, plugin = simulate(urdf, load_yaml(MBOT_YAML), "mbot", namespace="/")
    try:
        assert plugin.control_period == pytest.approx(0.01)
        updates = []
        update = plugin.manager.update
        plugin.manager.update = lambda now, period, reset=False: (updates.append(period), update(now, period, reset))
        sim.step(1000)
        assert len(updates) == 100 and all(period == pytest.approx(0.01) for period in updates[1:])
    finally:
        sim.close()


def test_joint_limit_parameters_override_the_urdf():
    limits = apply_limit_params(JointLimits(True, -1.0, 1.0, True, 2.0), {
        "has_velocity_limits": True, "max_velocity": 0.5, "has_effort_limits": True, "max_effort": 7}, "j")
    assert (limits.min_position, limits.max_velocity, limits.has_effort_limits, limits.max_effort) == (-1, 0.5, True, 7)


def test_shortest_angular_distance_with_limits_takes_the_way_within_them():
    assert shortest_angular_distance_with_limits(0.1, -0.1, -1.0, 1.0) == pytest.approx(-0.2)
    # From 3 to -3 the short way crosses pi, outside [-3.1, 3.1]: the long way round.
    assert shortest_angular_distance_with_limits(3.0, -3.0, -3.1, 3.1) == pytest.approx(-6.0)


# -- maths -------------------------------------------------------------------------------------------------------
def test_normalize_angle_is_upstreams_fmod_into_minus_pi_exclusive_to_pi():
    assert normalize_angle(math.pi) == normalize_angle(-math.pi) == normalize_angle(3 * math.pi) == math.pi
    assert normalize_angle(2 * math.pi) == 0.0 and normalize_angle(-2 * math.pi) == 0.0
    assert normalize_angle(7.0) == 7.0 - 2 * math.pi
    # Exact where atan2(sin, cos) is not: a wheel that has turned a million radians.
    assert normalize_angle(1e6) == math.fmod(1e6 + math.pi, 2 * math.pi) - math.pi


def test_pid_terms_clamp_and_antiwindup():
    pid = Pid(p=2.0, i=1.0, d=0.5, i_max=0.3, i_min=-0.3)
    # First call: upstream's reset leaves the last error at 0 and "valid", so d sees the whole step.
    assert pid.compute(1.0, 0.1) == pytest.approx(2.0 + 0.1 + 0.5 * 10.0)
    assert pid.compute(1.0, 0.1) == pytest.approx(2.0 + 0.2)
    for _ in range(100):
        pid.compute(1.0, 0.1)
    assert pid.compute(1.0, 0.1) == pytest.approx(2.0 + 0.3)  # the i term is clamped, the integral is not
    assert pid.i_error > 10
    windup_free = Pid(p=0.0, i=1.0, i_max=0.3, i_min=-0.3, antiwindup=True)
    for _ in range(100):
        windup_free.compute(1.0, 0.1)
    assert windup_free.i_error == pytest.approx(0.3)
    assert Pid.from_params({"i": 1.0}, "/ns/pid", quiet=True) is None
    gains = Pid.from_params({"p": 1, "i_clamp": -2.0, "i_clamp_max": 5.0}, "/ns/pid")
    assert (gains.i_min, gains.i_max) == (-2.0, 5.0)


def test_speed_limiter_velocity_acceleration_and_jerk():
    limiter = SpeedLimiter.from_params({"linear": {"x": {"has_velocity_limits": True, "max_velocity": 1.0,
                                                         "has_acceleration_limits": True, "max_acceleration": 2,
                                                         "min_acceleration": -4.0}}}, "linear/x", "test")
    assert limiter.min_velocity == -1.0
    assert limiter.limit(5.0, 0.0, 0.0, 0.1) == pytest.approx(0.2)
    assert limiter.limit(-5.0, 0.0, 0.0, 0.1) == pytest.approx(-0.4)
    assert limiter.limit(5.0, 0.95, 0.9, 0.1) == pytest.approx(1.0)
    jerk = SpeedLimiter(has_jerk_limits=True, min_jerk=-1.0, max_jerk=1.0)
    # dv - dv0 limited to ±jerk·2·dt²: from a steady 0.5 the next step may change by at most 0.02.
    assert jerk.limit(1.0, 0.5, 0.5, 0.1) == pytest.approx(0.52)


def test_odometry_integrates_wheel_positions_exactly_on_an_arc():
    odometry = DiffDriveOdometry(window=10)
    odometry.set_wheel_params(0.4, 0.1, 0.1)
    odometry.init(0.0)
    # Both wheels on a circle of radius R about the centre: left R - 0.2, right R + 0.2, for 1 rad.
    radius, turn, steps = 1.0, 1.0, 100
    for k in range(1, steps + 1):
        arc = turn * k / steps
        odometry.update(arc * (radius - 0.2) / 0.1, arc * (radius + 0.2) / 0.1, k * 0.01)
    assert odometry.heading == pytest.approx(turn)
    assert (odometry.x, odometry.y) == pytest.approx((math.sin(turn), 1 - math.cos(turn)))
    assert odometry.linear == pytest.approx(radius * turn / 1.0)
    assert odometry.angular == pytest.approx(turn / 1.0)


# -- the controller manager --------------------------------------------------------------------------------------
def test_list_switch_and_unload_behave_as_upstream(mbot, caplog):
    sim, _, plugin, _ = mbot
    manager = plugin.manager
    assert [(c.name, c.state, c.claimed) for c in manager.list()] == [
        ("joint_state_controller", "running", [("hardware_interface::JointStateInterface", [])]),
        ("mobile_base_controller", "running",
         [("hardware_interface::VelocityJointInterface", ["right_wheel_joint", "left_wheel_joint"])])]
    assert not manager.load("mobile_base_controller", plugin.urdf)
    assert "A controller named 'mobile_base_controller' was already loaded" in caplog.text
    assert not manager.unload("mobile_base_controller")
    assert "because it is still running" in caplog.text
    assert not switch(sim, manager, start=["mobile_base_controller"])
    assert "Controller 'mobile_base_controller' is already running" in caplog.text
    assert not switch(sim, manager, stop=["nothing"])
    assert "Could not stop controller with name 'nothing' because no controller with this name exists" in caplog.text
    assert switch(sim, manager, start=["mobile_base_controller"], stop=["nothing"], strictness=1)
    assert switch(sim, manager, stop=["mobile_base_controller"])
    assert manager.find("mobile_base_controller").state == "stopped"
    assert all(joint.command == 0.0 for joint in plugin.hw.joints.values())  # stopping brakes
    assert not switch(sim, manager, stop=["mobile_base_controller"])
    assert "Could not stop controller 'mobile_base_controller' since it is not running" in caplog.text
    assert manager.unload("mobile_base_controller")
    assert [c.name for c in manager.list()] == ["joint_state_controller"]
    caplog.clear()  # the stop of 'nothing' above said "because no controller with this name exists" too
    assert not manager.unload("mobile_base_controller")
    assert ("Could not unload controller with name 'mobile_base_controller' because no controller with this name "
            "exists") in caplog.text


def test_resource_conflicts_refuse_the_switch(mbot, caplog):
    sim, _, plugin, _ = mbot
    manager = plugin.manager
    manager.get_params = lambda name: {"type": "velocity_controllers/JointVelocityController",
                                       "joint": "left_wheel_joint"}
    assert manager.load("wheel_velocity", plugin.urdf)
    assert not switch(sim, manager, start=["wheel_velocity"])
    assert "Resource conflict on [left_wheel_joint].  Controllers = [mobile_base_controller, wheel_velocity, ]" \
        in caplog.text
    assert "Could not switch controllers, due to resource conflict" in caplog.text
    assert switch(sim, manager, start=["wheel_velocity"], stop=["mobile_base_controller"])
    assert manager.find("wheel_velocity").state == "running"


def test_unknown_type_missing_type_and_unknown_joint_fail_with_upstream_texts(mbot, caplog):
    sim, _, plugin, controller = mbot
    manager = plugin.manager
    configs = {
        "typo": {"type": "diff_drive_controller/DiffDriveControler"},
        "untyped": {"left_wheel": "x"},
        "ghost_wheels": {"type": "diff_drive_controller/DiffDriveController", "left_wheel": "ghost_joint",
                         "right_wheel": "left_wheel_joint"},
        "ghost_forward": {"type": "position_controllers/JointGroupPositionController", "joints": ["ghost_joint"]},
    }
    manager.get_params = configs.get
    for name in configs:
        assert not manager.load(name, plugin.urdf)
    assert ("Could not load controller 'typo' because controller type 'diff_drive_controller/DiffDriveControler' "
            "does not exist.") in caplog.text
    assert "Use 'rosservice call controller_manager/list_controller_types' to get the available types" in caplog.text
    assert ("Could not load controller 'untyped' because the type was not specified. Did you load the controller "
            "configuration on the parameter server (namespace: '/untyped')?") in caplog.text
    assert "ghost_joint couldn't be retrieved from model description" in caplog.text
    assert "Initializing controller 'ghost_wheels' failed" in caplog.text
    assert ("Exception thrown: Could not find resource 'ghost_joint' in "
            "'hardware_interface::PositionJointInterface'.") in caplog.text
    # The rest keeps running.
    assert [c.state for c in manager.list()] == ["running", "running"]
    controller.set_command(0.2, 0.0, sim.sim_time)
    sim.step(500)
    assert controller.odometry.linear == pytest.approx(0.2, rel=0.05)


# -- the mbot through diff_drive_controller ----------------------------------------------------------------------
@pytest.mark.parametrize("linear", [0.2, -0.2])
def test_the_mbot_tracks_linear_speed(mbot, linear):
    sim, spawned, _, controller = mbot
    speed, _ = measured_motion(sim, spawned, lambda: controller.set_command(linear, 0.0, sim.sim_time))
    assert speed == pytest.approx(linear, rel=0.05)


@pytest.mark.parametrize("angular", [0.5, -1.0])
def test_the_mbot_tracks_yaw_rate_and_turns_left_on_positive(mbot, angular):
    sim, spawned, _, controller = mbot
    _, yaw_rate = measured_motion(sim, spawned, lambda: controller.set_command(0.0, angular, sim.sim_time))
    assert yaw_rate == pytest.approx(angular, rel=0.05)


def test_cmd_vel_timeout_stops_the_mbot(mbot):
    sim, spawned, _, controller = mbot
    measured_motion(sim, spawned, lambda: controller.set_command(0.3, 0.0, sim.sim_time))
    sim.step(int(controller.cmd_vel_timeout * 1000) + 500)  # no command for timeout + 0.5 s
    linear, _ = spawned.robot.root_velocity()
    assert math.hypot(linear[0], linear[1]) < 0.005


def test_wheel_odometry_over_3_m_stays_within_2_percent(mbot):
    sim, spawned, _, controller = mbot
    start = spawned.robot.root_pose().position
    for _ in range(220):  # 11 s at 0.3 m/s, with the acceleration ramp
        controller.set_command(0.3, 0.0, sim.sim_time)
        sim.step(50)
    end = spawned.robot.root_pose().position
    truth = math.hypot(end[0] - start[0], end[1] - start[1])
    odometry = math.hypot(controller.odometry.x, controller.odometry.y)
    assert truth > 3.0
    assert odometry == pytest.approx(truth, rel=0.02)


# -- the two-joint arm -------------------------------------------------------------------------------------------
SETPOINTS = ((0.5, -0.8), (-1.0, 1.2), (1.5, 0.3))


@pytest.mark.parametrize("interface, controllers", [
    ("Effort", ("shoulder_position_controller", "elbow_position_controller")),
    ("Position", ("arm_controller",))])
def test_the_arm_reaches_setpoints_within_a_degree(interface, controllers):
    sim, spawned, plugin = arm(interface)
    try:
        manager = plugin.manager
        for name in controllers:
            assert manager.load(name, plugin.urdf)
        assert switch(sim, manager, controllers)
        for setpoint in SETPOINTS:
            if interface == "Effort":
                for name, value in zip(controllers, setpoint):
                    manager.find(name).controller.set_command(value)
            else:
                assert manager.find("arm_controller").controller.set_commands(list(setpoint)) is None
            sim.step(2000)
            reached = [state[0] for state in spawned.robot.joint_state(["shoulder", "elbow"])]
            errors = [math.degrees(abs(a - b)) for a, b in zip(reached, setpoint)]
            assert max(errors) < 1.0, f"setpoint {setpoint}: errors {errors} degrees"
    finally:
        sim.close()


def test_the_integral_term_takes_out_the_static_error_of_a_constant_load():
    """The shoulder held level with the elbow straight: gravity's 3.7 N m on it, which the proportional term alone
    holds 3.7 mrad off. The integral (500 against p 1000: a 2 s time constant) must take that error out within
    10 s (0.07 mrad left); with its sign wrong 1.3 mrad remain."""
    sim, spawned, plugin = arm("Effort")
    try:
        start_controllers(sim, plugin, "shoulder_position_controller", "elbow_position_controller")
        plugin.manager.find("shoulder_position_controller").controller.set_command(math.pi / 2)
        plugin.manager.find("elbow_position_controller").controller.set_command(0.0)
        sim.step(10000)
        (position, velocity, _), = spawned.robot.joint_state(["shoulder"])
        print(f"figure: shoulder level under its load: static error {position - math.pi / 2:+.2e} rad")
        assert abs(velocity) < 1e-3
        assert position == pytest.approx(math.pi / 2, abs=2e-4)
    finally:
        sim.close()


def test_effort_limits_saturate_the_pid_output(caplog):
    caplog.set_level(logging.INFO)
    sim, _, plugin = arm("Effort")
    try:
        start_controllers(sim, plugin, "shoulder_position_controller").set_command(1.9)
        sim.step(2)
        assert plugin.hw.joints["shoulder"].command == pytest.approx(40.0)  # the URDF's effort limit
        assert "mechanicalReduction" not in caplog.text  # a reduction of 1 needs no remark
    finally:
        sim.close()


def test_e_stop_stops_the_wheels_and_restarts_the_controllers_on_release(mbot):
    sim, spawned, plugin, controller = mbot
    measured_motion(sim, spawned, lambda: controller.set_command(0.3, 0.0, sim.sim_time), settle=1.0,
                    window=0.1)
    plugin.e_stop = True
    for _ in range(20):
        controller.set_command(0.3, 0.0, sim.sim_time)
        sim.step(50)
    linear, _ = spawned.robot.root_velocity()
    assert math.hypot(linear[0], linear[1]) < 0.005
    plugin.e_stop = False
    speed, _ = measured_motion(sim, spawned, lambda: controller.set_command(0.3, 0.0, sim.sim_time), settle=1.0,
                               window=0.5)
    assert speed == pytest.approx(0.3, rel=0.05)


@pytest.mark.parametrize("legacy", [False, True])
def test_pid_gains_turn_position_joints_into_pid_driven_effort_joints(legacy):
    urdf = expand_xacro_arm("Position")
    if legacy:
        plugin_element = '<plugin filename="libgazebo_ros_control.so" name="gazebo_ros_control"/>'
        assert plugin_element in urdf
        urdf = urdf.replace(plugin_element, plugin_element.replace("/>", "><legacyModeNS>true</legacyModeNS></plugin>"))
    gains = {"shoulder": {"p": 1000.0, "i": 500.0, "d": 20.0, "i_clamp": 5.0, "antiwindup": True},
             "elbow": {"p": 500.0, "i": 250.0, "d": 5.0, "i_clamp": 2.0, "antiwindup": True}}
    # Noetic reads the gains under the robot namespace (here the model name); legacyModeNS at the root.
    gains_name = "/gazebo_ros_control/pid_gains" if legacy else "/arm/gazebo_ros_control/pid_gains"
    sim, spawned, plugin = simulate(urdf, load_yaml(os.path.join(ROBOTS, "config", "arm_position.yaml")), "arm",
                                    {gains_name: gains})
    try:
        assert all(joint.pid is not None for joint in plugin.hw.joints.values())
        manager = plugin.manager
        assert manager.load("arm_controller", plugin.urdf)
        assert switch(sim, manager, ["arm_controller"])
        manager.find("arm_controller").controller.set_commands([0.7, -0.4])
        sim.step(2000)
        reached = [state[0] for state in spawned.robot.joint_state(["shoulder", "elbow"])]
        assert max(math.degrees(abs(a - b)) for a, b in zip(reached, (0.7, -0.4))) < 1.0
    finally:
        sim.close()


SOFT_UPPER = 1.0
SAFETY = f'<safety_controller soft_lower_limit="-1.0" soft_upper_limit="{SOFT_UPPER}" k_position="20" k_velocity="50"/>'


@pytest.mark.parametrize("interface, controller", [("Position", "shoulder_controller"),
                                                   ("Effort", "shoulder_position_controller")])
def test_a_joint_commanded_past_its_soft_limit_stops_at_it(interface, controller):
    """joint_limits_interface's soft limits from <safety_controller>: the shoulder (hard limit 2.0 rad) is
    commanded to 1.9 rad and stops at its soft upper limit of 1.0 (the effort one short of it by what holding
    the arm up against gravity takes, 1/(k_position k_velocity) rad per N·m)."""
    urdf = expand_xacro_arm(interface).replace('<joint name="shoulder" type="revolute">',
                                               f'<joint name="shoulder" type="revolute">{SAFETY}', 1)
    sim, spawned, plugin = simulate(urdf, load_yaml(os.path.join(ROBOTS, "config", f"arm_{interface.lower()}.yaml")),
                                    "arm")
    try:
        assert plugin.hw.joints["shoulder"].soft_limits is not None
        start_controllers(sim, plugin, controller).set_command(1.9)
        highest = 0.0
        for _ in range(30):
            sim.step(100)
            highest = max(highest, spawned.robot.joint_state(["shoulder"])[0][0])
        final = spawned.robot.joint_state(["shoulder"])[0][0]
        print(f"figure: soft limit {SOFT_UPPER} rad ({interface.lower()} interface), commanded 1.9: the shoulder "
              f"stops at {final:.4f} rad (highest {highest:.4f})")
        assert highest < SOFT_UPPER + 0.005
        assert final == pytest.approx(SOFT_UPPER, abs=0.005 if interface == "Position" else 0.05)
    finally:
        sim.close()


# -- the loop's batches ------------------------------------------------------------------------------------------
def driven_mbot(urdf, controllers=None):
    """The mbot with both controllers (``controllers``, by default mbot_ros_control.yaml's) started at its first
    step (the switch waits by stepping), driving a circle."""
    sim, spawned, plugin = simulate(urdf, controllers or load_yaml(MBOT_YAML), "mbot", namespace="/")
    manager = plugin.manager
    names = ["joint_state_controller", "mobile_base_controller"]
    for name in names:
        assert manager.load(name, plugin.urdf)
    switch_stepping(sim, manager, names)
    drive = manager.find("mobile_base_controller").controller
    drive.set_command(0.3, 0.5, sim.sim_time)
    return sim, spawned, plugin, drive


def test_controllers_update_between_the_steps_of_a_batch_as_single_steps_would(mbot_ros_control_urdf):
    """The controllers run on every step inside the loop's batches and fill their outboxes there, so the loop
    does not stop for them: 1,000 steps in one call send the same samples, stamped at the same steps, and end
    bit for bit where 1,000 single steps do; each sample goes out at most MAX_BATCH_SIM_SECONDS after its step."""
    runs = []
    for batch in (1, 1000):
        sim, spawned, plugin, drive = driven_mbot(mbot_ros_control_urdf)
        try:
            sent, delays, batches, update = [], [], recording_batches(sim), plugin.update

            def record_update(now, update=update, plugin=plugin, sent=sent):
                for loaded in plugin.publish_now:
                    sent.extend((stamp, loaded.name, sample) for stamp, sample in loaded.controller.outbox)
                    delays.extend(now - stamp for stamp, _ in loaded.controller.outbox)
                update(now)
            plugin.update = record_update
            for _ in range(1000 // batch):
                sim.step(batch)
            runs.append((sent, batches, sim.engine.model_pose("mbot"),
                         (drive.odometry.x, drive.odometry.y, drive.odometry.heading)))
            assert all(0.0 <= delay <= MAX_BATCH_SIM_SECONDS + 1e-9 for delay in delays), max(delays)
            assert not any(loaded.controller.outbox for loaded in plugin.manager.controllers)
        finally:
            sim.close()
    (single_sent, single_batches, single_pose, single_odometry), (sent, batches, pose, odometry) = runs
    assert sum(batches) == sum(single_batches) == 1000
    # Batches of the loop's longest (10 ms, 10 steps): the controllers end none.
    assert len(single_batches) == 1000 and len(batches) <= 101, batches
    assert sent == single_sent
    for name in ("joint_state_controller", "mobile_base_controller"):  # 50 Hz each
        assert 49 <= sum(entry[1] == name for entry in sent) <= 51
    assert pose == single_pose and odometry == single_odometry
    assert odometry[2] > 0.2  # it turned (0.5 rad/s until cmd_vel_timeout, 0.5 s)


def sent_samples(plugin):
    """(stamp, controller name, sample) of everything the controllers' outboxes send from now on."""
    sent, update = [], plugin.update

    def record_update(now):
        for loaded in plugin.publish_now:
            sent.extend((stamp, loaded.name, sample) for stamp, sample in loaded.controller.outbox)
        update(now)
    plugin.update = record_update
    return sent


def test_cmd_vel_out_is_filled_on_every_control_cycle_without_stopping_the_loop(mbot_ros_control_urdf):
    """publish_cmd: the limited command of each cycle (here ramping at max_acceleration 1.8 m/s²), stamped at its
    step; the loop still steps in its longest batches."""
    controllers = load_yaml(MBOT_YAML)
    controllers["mobile_base_controller"]["publish_cmd"] = True
    sim, spawned, plugin, drive = driven_mbot(mbot_ros_control_urdf, controllers)
    try:
        drive.set_command(1.0, 0.0, sim.sim_time)
        start, sent, batches = sim.sim_time, sent_samples(plugin), recording_batches(sim)
        sim.step(100)
        commands = [(stamp, sample) for stamp, _, sample in sent if isinstance(sample, CommandSample)]
        assert [stamp for stamp, _ in commands] == pytest.approx([start + 0.001 * (k + 1) for k in range(100)])
        ramp = [sample.linear - before.linear for (_, before), (_, sample) in zip(commands, commands[1:])]
        assert ramp == pytest.approx([1.8 * 0.001] * 99)
        assert 4 <= sum(isinstance(sample, OdometrySample) for _, _, sample in sent) <= 5  # 50 Hz over 0.1 s
        assert len(batches) <= 11, batches
    finally:
        sim.close()


def test_the_pid_controllers_state_is_sampled_every_tenth_update_at_its_own_step():
    sim, _, plugin = simulate(expand_xacro_arm("Effort"), load_yaml(os.path.join(ROBOTS, "config", "arm_effort.yaml")),
                              "arm")
    try:
        manager = plugin.manager
        assert manager.load("elbow_position_controller", plugin.urdf)
        switch_stepping(sim, manager, ["elbow_position_controller"])
        manager.find("elbow_position_controller").controller.set_command(0.5)
        start, sent, batches = sim.sim_time, sent_samples(plugin), recording_batches(sim)
        sim.step(200)
        stamps = [stamp for stamp, _, _ in sent]
        assert len(stamps) == 20 and [b - a for a, b in zip(stamps, stamps[1:])] == pytest.approx([0.01] * 19)
        assert start < stamps[0] <= start + 0.01
        last = sent[-1][2]
        assert last.set_point == 0.5 and last.error == pytest.approx(last.set_point - last.process_value)
        assert len(batches) <= 21, batches
    finally:
        sim.close()


def test_a_controller_plugin_failing_within_a_batch_is_disabled_for_the_rest_of_it(mbot_ros_control_urdf, caplog):
    sim, spawned, plugin, drive = driven_mbot(mbot_ros_control_urdf)
    try:
        calls = []

        def fail(step_size):
            calls.append(sim.sim_time)
            raise RuntimeError("broken")
        plugin.on_step = fail
        with caplog.at_level(logging.ERROR):
            sim.step(500)
        assert len(calls) == 1 and plugin not in spawned.plugins
        assert caplog.text.count("plugin GazeboRosControlPlugin(ns = /) failed and is disabled") == 1
        assert sim.sim_time == pytest.approx(0.501)
    finally:
        sim.close()


@pytest.mark.parametrize("rate", [0, math.nan])
def test_a_publish_rate_without_a_period_refuses_the_diff_drive_controller(mbot_ros_control_urdf, rate, caplog):
    params = load_yaml(MBOT_YAML)
    params["mobile_base_controller"]["publish_rate"] = rate
    sim, _, plugin = simulate(mbot_ros_control_urdf, params, "mbot", namespace="/")
    try:
        assert not plugin.manager.load("mobile_base_controller", plugin.urdf)
        assert f"publish_rate {float(rate)} gives no publish period" in caplog.text
        assert start_controllers(sim, plugin, "joint_state_controller")
        sim.step(100)
    finally:
        sim.close()


def test_the_robot_param_holding_the_spawned_urdf_is_not_parsed_again():
    """spawn_model -param sends the parameter's URDF parsed and written again (no declaration, no comments);
    gazebo_ros_control recognises it and reuses the spawned model, so its warnings are said once."""
    from mbot_sim_bridge.core.ros_control.gazebo_ros_control import _same_description
    parameter = '<?xml version="1.0"?>\n<!-- the course -->\n<robot name="r"><link name="a"/></robot>'
    assert _same_description(parameter, '<robot name="r"><link name="a" /></robot>')
    assert not _same_description(parameter, '<robot name="r"><link name="b" /></robot>')
    assert not _same_description("<robot", '<robot name="r" />')
