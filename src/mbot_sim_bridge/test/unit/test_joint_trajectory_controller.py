"""joint_trajectory_controller and gripper_action_controller in the simulator, without ROS: the two-joint arm
(ros_control_test_robots) with the trajectory controller on its position or effort interface."""
import logging
import math

import pytest
from ros_control_fixtures import (expand_xacro_arm, recording_batches, run_until_ended, simulate, start_controllers,
                                  switch, switch_stepping)

from mbot_sim_bridge.core.ros_control.gazebo_ros_control import GazeboRosControlPlugin
from mbot_sim_bridge.core.ros_control.gripper_action_controller import GripperGoal
from mbot_sim_bridge.core.ros_control.joint_trajectory_controller import (
    ABORTED, CANCELED, GOAL_TOLERANCE_VIOLATED, INVALID_GOAL, INVALID_JOINTS, PATH_TOLERANCE_VIOLATED, SUCCEEDED,
    SUCCESSFUL, JointTolerance, JointTrajectory, Segment, TrajectoryGoal, TrajectoryPoint)

JOINTS = ["shoulder", "elbow"]
# Gains in the range published arm configurations give their effort trajectory controllers.
EFFORT_GAINS = {"shoulder": {"p": 1000.0, "i": 50.0, "d": 30.0, "i_clamp": 5.0},
                "elbow": {"p": 500.0, "i": 20.0, "d": 10.0, "i_clamp": 2.0}}


def trajectory_arm(interface, **extra):
    config = {"type": f"{interface.lower()}_controllers/JointTrajectoryController", "joints": JOINTS,
              "constraints": {"goal_time": 0.5, "stopped_velocity_tolerance": 0.05,
                              "shoulder": {"goal": 0.01}, "elbow": {"goal": 0.01}}}
    if interface == "Effort":
        config["gains"] = EFFORT_GAINS
    if interface == "Velocity":  # a velocity per radian of error, plus the desired velocity fed forward
        config["gains"] = {joint: {"p": 20.0} for joint in JOINTS}
        config["velocity_ff"] = {joint: 1.0 for joint in JOINTS}
    config.update(extra)
    sim, spawned, plugin = simulate(expand_xacro_arm(interface), {"arm_controller": config}, "arm")
    controller = start_controllers(sim, plugin, "arm_controller")
    sim.step(100)
    return sim, controller


def goal(points, **tolerances):
    return TrajectoryGoal(JointTrajectory(JOINTS, [TrajectoryPoint(p, time_from_start=t) for t, p in points]),
                          **tolerances)



def test_segments_are_linear_cubic_or_quintic_by_the_derivatives_given_and_hold_outside():
    linear = Segment(1.0, (0.0, None, None), 3.0, (2.0, None, None))
    assert linear.sample(2.0) == pytest.approx((1.0, 1.0, 0.0))
    cubic = Segment(0.0, (0.0, 0.0, None), 2.0, (1.0, 0.0, None))
    assert cubic.sample(1.0) == pytest.approx((0.5, 0.75, 0.0))
    assert cubic.sample(2.0) == pytest.approx((1.0, 0.0, -1.5))
    quintic = Segment(0.0, (0.0, 1.0, 0.5), 1.0, (2.0, -1.0, 0.25))
    assert quintic.sample(0.0) == pytest.approx((0.0, 1.0, 0.5))
    assert quintic.sample(1.0) == pytest.approx((2.0, -1.0, 0.25))
    assert quintic.sample(5.0) == pytest.approx((2.0, 0.0, 0.0))
    assert quintic.sample(-1.0) == pytest.approx((0.0, 0.0, 0.0))


@pytest.mark.parametrize("interface", ["Position", "Velocity", "Effort"])
def test_a_two_point_goal_succeeds_with_every_joint_within_a_hundredth_of_a_radian(interface):
    sim, controller = trajectory_arm(interface)
    target = [0.6, -0.9]
    accepted, code, _ = controller.accept_goal(goal([(1.0, [0.3, -0.4]), (2.0, target)]))
    assert accepted and code == SUCCESSFUL
    end = run_until_ended(sim, controller)
    assert (end.status, end.error_code) == (SUCCEEDED, SUCCESSFUL)
    errors = [abs(joint.position - value) for joint, value in zip(controller.joints, target)]
    assert max(errors) < 0.01, errors


def test_a_path_tolerance_the_arm_cannot_keep_aborts_the_goal():
    sim, controller = trajectory_arm("Effort")
    tight = [JointTolerance("shoulder", position=1e-4), JointTolerance("elbow", position=1e-4)]
    assert controller.accept_goal(goal([(0.3, [1.5, -1.5])], path_tolerance=tight))[0]
    end = run_until_ended(sim, controller)
    assert (end.status, end.error_code) == (ABORTED, PATH_TOLERANCE_VIOLATED)
    assert end.error_string.split()[1:3] == ["path", "error"]


def test_a_goal_tolerance_missed_after_goal_time_aborts():
    sim, controller = trajectory_arm("Effort", gains={joint: {"p": 5.0} for joint in JOINTS})
    assert controller.accept_goal(goal([(0.5, [1.0, -1.0])], goal_time_tolerance=0.2))[0]
    end = run_until_ended(sim, controller)
    assert (end.status, end.error_code) == (ABORTED, GOAL_TOLERANCE_VIOLATED)


def test_a_second_goal_preempts_the_first_and_unknown_joints_are_refused():
    sim, controller = trajectory_arm("Position")
    first, second = goal([(2.0, [0.5, 0.5])]), goal([(1.0, [-0.5, 0.2])])
    assert controller.accept_goal(first)[0]
    sim.step(200)
    assert controller.accept_goal(second)[0]
    assert controller.ended.pop(0).goal is first and not controller.ended
    assert controller.accept_goal(TrajectoryGoal(JointTrajectory(["shoulder", "wrist"], [
        TrajectoryPoint([0.0, 0.0], time_from_start=1.0)]))) == (False, INVALID_JOINTS, (
            "Joints on incoming goal don't match the controller joints: got [shoulder, wrist], the controller has "
            "[shoulder, elbow]"))
    # One joint named twice is refused too (upstream moved it as the last of its entries said and SUCCEEDED).
    twice = controller.accept_goal(TrajectoryGoal(JointTrajectory(["shoulder", "shoulder"], [
        TrajectoryPoint([0.0, 0.3], time_from_start=1.0)])))
    assert twice[:2] == (False, INVALID_JOINTS) and "got [shoulder, shoulder]" in twice[2]
    refused = controller.accept_goal(goal([(1.0, [0.0, 0.0]), (1.0, [0.1, 0.1])]))
    assert refused[:2] == (False, INVALID_GOAL) and "strictly increasing" in refused[2]
    assert controller.accept_goal(goal([(1.0, [math.nan, 0.0])]))[:2] == (False, INVALID_GOAL)
    end = run_until_ended(sim, controller)
    assert end.goal is second and end.status == SUCCEEDED


def test_the_command_topic_moves_the_arm_and_cancels_an_active_goal():
    sim, controller = trajectory_arm("Position")
    active = goal([(3.0, [1.0, 1.0])])
    controller.accept_goal(active)
    ok, _ = controller.command(JointTrajectory(JOINTS, [TrajectoryPoint([-0.4, 0.7], time_from_start=0.5)]))
    assert ok and controller.ended.pop(0).status == CANCELED
    sim.step(1000)
    assert [joint.position for joint in controller.joints] == pytest.approx([-0.4, 0.7], abs=0.01)


def test_a_trajectory_starting_later_is_spliced_and_query_state_samples_it():
    sim, controller = trajectory_arm("Position")
    controller.command(JointTrajectory(JOINTS, [TrajectoryPoint([1.0, 0.0], time_from_start=2.0)]))
    sim.step(500)
    now = sim.sim_time
    old_at_half = controller.query_state(now + 0.5)
    assert old_at_half[1][0] == pytest.approx(0.5, rel=0.01)  # 1 rad in 2 s, linearly
    # The new trajectory starts 1 s from now: until then the old one runs on, a bridge joins the two.
    later = JointTrajectory(JOINTS, [TrajectoryPoint([0.0, 0.5], time_from_start=0.5)], start=now + 1.0)
    assert controller.command(later)[0]
    assert controller.query_state(now + 0.5) == old_at_half
    assert controller.query_state(now + 1.5)[0] == pytest.approx([0.0, 0.5])
    assert controller.query_state(now - 10.0) is None  # before the trajectory's start
    sim.step(2000)
    assert [joint.position for joint in controller.joints] == pytest.approx([0.0, 0.5], abs=0.01)


def test_points_in_the_past_are_dropped():
    sim, controller = trajectory_arm("Position")
    past = JointTrajectory(JOINTS, [TrajectoryPoint([0.2, 0.2], time_from_start=0.1)], start=sim.sim_time - 1.0)
    ok, error = controller.command(past)
    assert not ok and error.startswith("Dropping all 1 trajectory point(s)")


def test_cancel_holds_and_stop_trajectory_duration_stops_smoothly():
    sim, controller = trajectory_arm("Position", stop_trajectory_duration=0.5)
    active = goal([(2.0, [1.5, 0.0])])
    controller.accept_goal(active)
    sim.step(1000)
    moving = controller.desired[1][0]
    assert moving > 0.5
    controller.cancel_goal(active)
    assert controller.ended.pop(0).status == CANCELED
    sim.step(250)
    assert 0.0 < controller.desired[1][0] < moving
    sim.step(500)
    assert controller.desired[1][0] == 0.0
    assert controller.joints[0].position < 1.2


def test_an_effort_trajectory_controller_without_gains_does_not_load(caplog):
    urdf = expand_xacro_arm("Effort")
    sim, _, plugin = simulate(urdf, {"arm_controller": {"type": "effort_controllers/JointTrajectoryController",
                                                        "joints": JOINTS}}, "arm")
    assert not plugin.manager.load("arm_controller", plugin.urdf)
    assert "No p gain specified for pid.  Namespace: /arm/arm_controller/gains/shoulder" in caplog.text
    assert "Failed to initialize PID gains from ROS parameter server." in caplog.text


def gripper_arm(interface, **extra):
    config = {"type": f"{interface.lower()}_controllers/GripperActionController", "joint": "elbow",
              "stall_timeout": 0.5, **extra}
    sim, spawned, plugin = simulate(expand_xacro_arm(interface), {"gripper": config}, "arm")
    return sim, start_controllers(sim, plugin, "gripper")


def test_the_gripper_reaches_a_free_goal_and_stalls_when_its_effort_cannot_move_it():
    sim, gripper = gripper_arm("Effort", gains={"elbow": {"p": 200.0, "d": 5.0}})
    assert gripper.accept_goal(GripperGoal(0.8, 20.0))
    end = run_until_ended(sim, gripper)
    assert (end.status, end.reached_goal, end.stalled) == (SUCCEEDED, True, False)
    assert end.position == pytest.approx(0.8, abs=0.01)
    # 0.001 N m cannot lift the forearm: it stays short of the goal and the goal ends stalled.
    assert gripper.accept_goal(GripperGoal(0.0, 0.001))
    end = run_until_ended(sim, gripper)
    assert (end.status, end.reached_goal, end.stalled) == (ABORTED, False, True)
    assert abs(end.effort) <= 0.001


# Each bad parameter with what the controller manager logs: a refusal (upstream's error), or a warning naming the
# value and what is used instead, after which the controller works; None where the value is taken as given.
BAD_PARAMETERS = [
    ({"joints": "shoulder"}, True, "The 'joints' parameter is not an array (namespace: /arm/arm_controller)."),
    ({"joints": [1, 2]}, True, "The 'joints' parameter contains a non-string element"),
    ({"joints": []}, True, "Could not find 'joints' parameter (namespace: /arm/arm_controller)."),
    ({"joints": ["shoulder", "wrist"]}, True, "Could not find joint 'wrist' in URDF model."),
    # Upstream's ros::Duration(1.0 / rate) throws for 1/0 and 1/NaN; a negative period passes its checks every update.
    ({"state_publish_rate": 0.0}, True, "Exception thrown while initializing controller 'arm_controller'.\nDuration is "
                                        "out of dual 32-bit range (/arm/arm_controller/state_publish_rate is 0"),
    ({"action_monitor_rate": math.nan}, True, "Duration is out of dual 32-bit range"),
    ({"action_monitor_rate": -1.0}, False, "action_monitor_rate is -1: a negative period, so at every update"),
    ({"state_publish_rate": "fast"}, False, "parameter 'state_publish_rate' is 'fast', not a float; using 50.0"),
    ({"constraints": {"goal_time": "soon", "shoulder": {"goal": math.nan}}}, False,
     "parameter 'goal_time' is 'soon', not a float; using 0.0"),
    ({"stop_trajectory_duration": math.inf}, False, "stop_trajectory_duration is inf, not a duration"),
    ({"gains": {"shoulder": {"p": "high"}, "elbow": {"p": 1.0}}}, True,
     "/arm/arm_controller/gains/shoulder/p is 'high': a PID gain must be a finite number"),
]


@pytest.mark.parametrize("bad, refused, said", BAD_PARAMETERS)
def test_bad_parameters_refuse_the_controller_or_leave_it_working(bad, refused, said, caplog):
    config = {"type": "effort_controllers/JointTrajectoryController", "joints": JOINTS, "gains": EFFORT_GAINS,
              **bad}
    sim, _, plugin = simulate(expand_xacro_arm("Effort"), {"arm_controller": config}, "arm")
    caplog.set_level(logging.WARNING)
    assert plugin.manager.load("arm_controller", plugin.urdf) is not refused
    if said is not None:
        assert said in caplog.text
    if refused:
        assert "Initializing controller 'arm_controller' failed" in caplog.text
        return
    controller = plugin.manager.find("arm_controller").controller
    assert switch(sim, plugin.manager, ["arm_controller"])
    controller.command(JointTrajectory(JOINTS, [TrajectoryPoint([0.3, 0.3], time_from_start=0.5)]))
    sim.step(1000)
    assert [joint.position for joint in controller.joints] == pytest.approx([0.3, 0.3], abs=0.02)


def test_a_negative_state_publish_rate_publishes_at_every_update_as_upstream():
    """Upstream's publishState compares last + period < time: a negative period passes at every update."""
    sim, controller = trajectory_arm("Position", state_publish_rate=-1.0)
    ros_control = next(plugin for plugin in sim.models["arm"].plugins if isinstance(plugin, GazeboRosControlPlugin))
    published = []

    def publish(now, update=ros_control.update):
        published.extend(controller.outbox)
        update(now)
    ros_control.update = publish
    sim.step(100)
    assert len(published) == round(100 * sim.step_size / ros_control.control_period)


def test_a_partial_goal_moves_its_joints_only_when_allowed():
    sim, controller = trajectory_arm("Position")
    partial = TrajectoryGoal(JointTrajectory(["shoulder"], [TrajectoryPoint([0.5], time_from_start=1.0)]))
    assert controller.accept_goal(partial)[:2] == (False, INVALID_JOINTS)
    sim, controller = trajectory_arm("Position", allow_partial_joints_goal=True)
    elbow = controller.joints[1].position
    assert controller.accept_goal(partial)[0]
    assert run_until_ended(sim, controller).status == SUCCEEDED
    sim.step(500)
    assert controller.joints[0].position == pytest.approx(0.5, abs=0.01)
    assert controller.joints[1].position == pytest.approx(elbow, abs=0.01)


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf, 1e308, -1e308])
def test_bad_numbers_in_a_goals_tolerances_and_in_query_state_move_nothing(value):
    sim, controller = trajectory_arm("Position")
    tolerances = [JointTolerance(joint, value, value, value) for joint in JOINTS]
    assert controller.accept_goal(goal([(0.5, [0.2, 0.2])], path_tolerance=tolerances, goal_tolerance=tolerances,
                                       goal_time_tolerance=value))[0]
    for _ in range(300):  # the goal ends one way or another, or runs on with the arm where it was sent
        sim.step(10)
        if controller.ended:
            break
    assert [joint.position for joint in controller.joints] == pytest.approx([0.2, 0.2], abs=0.01)
    assert controller.query_state(value) is None or math.isfinite(value)


def test_the_trajectory_controller_updates_between_the_steps_of_a_batch_as_single_steps_would():
    """1,500 steps in one call against one at a time, published as the ROS layer does (each stop sends the outbox
    and the ended goals): the state (50 Hz) and feedback (20 Hz) are taken at the same steps with the same values
    without stopping the loop, the arm ends bit for bit alike, and the goal's end goes out at the next stop,
    within 10 ms of sim time."""
    config = {"type": "position_controllers/JointTrajectoryController", "joints": JOINTS,
              "constraints": {"goal_time": 0.5, "shoulder": {"goal": 0.01}, "elbow": {"goal": 0.01}}}
    runs = []
    for batch in (1, 1500):
        sim, _, plugin = simulate(expand_xacro_arm("Position"), {"arm_controller": config}, "arm")
        try:
            assert plugin.manager.load("arm_controller", plugin.urdf)
            switch_stepping(sim, plugin.manager, ["arm_controller"])
            controller = plugin.manager.find("arm_controller").controller
            outputs, ends, batches = [], [], recording_batches(sim)

            def publish(now, controller=controller, outputs=outputs, ends=ends, update=plugin.update):
                outputs.extend((stamp, points.goal is not None, points.desired, points.actual)
                               for stamp, points in controller.outbox)
                ends.extend((now, end.status) for end in controller.ended)
                controller.ended.clear()
                update(now)
            plugin.update = publish
            assert controller.accept_goal(goal([(0.6, [0.3, -0.4]), (1.0, [0.6, -0.9])]))[0]
            for _ in range(1500 // batch):
                sim.step(batch)
            runs.append((outputs, ends, batches, [joint.position for joint in controller.joints]))
        finally:
            sim.close()
    (single_outputs, single_ends, single_batches, single_end), (outputs, ends, batches, end) = runs
    # The loop's own longest batches (10 steps) and a stop after the goal's end: the state and feedback end none.
    assert len(single_batches) == 1500 and len(batches) <= 152, batches
    assert outputs == single_outputs
    assert sum(feedback for _, feedback, _, _ in outputs) >= 20  # 20 Hz while the goal runs
    assert sum(not feedback for _, feedback, _, _ in outputs) >= 74  # 50 Hz over 1.5 s
    assert end == single_end
    [(single_time, single_status)], [(time, status)] = single_ends, ends
    assert status == single_status == SUCCEEDED and single_time <= time <= single_time + 0.01 + 1e-9
