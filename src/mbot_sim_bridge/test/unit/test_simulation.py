"""core/simulation.py: the seed robot spawned, commanded and stepped through the node's own loop code, with the
plugins' core classes and no ROS master; per-sensor random streams; plugin failures contained."""
import logging
import math
import os
import re
import sys

import numpy as np
import pytest
from sensor_fixtures import plugin_of

from mbot_sim_bridge.core.clock import UpdateTimer
from mbot_sim_bridge.core.drives.diff_drive import DiffDrive
from mbot_sim_bridge.core.errors import ConfigError, ModelError
from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy, yaw
from mbot_sim_bridge.core.joints.joint_states import JointStatePublisher
from mbot_sim_bridge.core.sensors.lidar import RaySensor
from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.simulation import Simulation

WORLDS = os.path.join(os.path.dirname(__file__), "..", "..", "..", "..", "worlds")


def simulation(world="empty.world", seed=0):
    return Simulation(parse_world(os.path.join(WORLDS, world)), CORE_PLUGINS, seed=seed)


def test_spawn_command_step_and_read_odometry(mbot_urdf):
    sim = simulation()
    try:
        spawned = sim.spawn_robot(parse_robot(mbot_urdf, "model 'mbot'"), "mbot")
        drive = plugin_of(spawned, DiffDrive)
        assert drive.driven_joints == ("left_wheel_joint", "right_wheel_joint")
        # The caster is the only movable joint the diff drive neither drives nor publishes.
        assert plugin_of(spawned, JointStatePublisher).joint_names == ["back_caster_joint"]
        assert drive.set_command(0.2, 0.0)
        sim.step(3000)
        (position, _), (vx, _), _ = drive.odometry()
        assert sim.sim_time == pytest.approx(3.0)
        assert vx == pytest.approx(0.2, rel=0.01)
        assert position[0] == pytest.approx(0.2 * 3.0, abs=0.05)  # a short ramp at the start
        assert not drive.set_command(math.nan, 0.0)
        drive.set_command(0.0, 1.0)
        sim.step(1000)
        _, _, angular = drive.odometry()
        assert angular == pytest.approx(1.0, rel=0.02)
    finally:
        sim.close()


def test_reset_simulation_brings_back_time_pose_and_the_command(mbot_urdf):
    sim = simulation()
    try:
        start = pose_from_xyz_rpy((1, 2, 0), (0, 0, 0.5))
        spawned = sim.spawn_robot(parse_robot(mbot_urdf, "model 'mbot'"), "mbot", start)
        drive = plugin_of(spawned, DiffDrive)
        drive.set_command(0.3, 0.2)
        sim.step(1500)
        sim.reset(simulation=True)
        assert sim.sim_time == 0.0
        (position, orientation), _, _ = drive.odometry()
        assert position[:2] == pytest.approx((1.0, 2.0), abs=1e-6)
        assert yaw(orientation) == pytest.approx(0.5, abs=1e-6)
        sim.step(500)
        (position, _), _, _ = drive.odometry()
        assert position[:2] == pytest.approx((1.0, 2.0), abs=1e-3)  # the command was zeroed
    finally:
        sim.close()


def _first_scan(urdf, names_in_order, measured, seed=7):
    """The first scan of ``measured``'s lidar right after spawning ``names_in_order`` (others 50 m away,
    out of the lidar's 6 m range), and the same scan after more scans and a reset_simulation."""
    sim = simulation("playground.world", seed=seed)
    try:
        for name in names_in_order:
            y = 0.0 if name == measured else 50.0 + len(sim.models)
            sim.spawn_robot(parse_robot(urdf, f"model '{name}'"), name, pose_from_xyz_rpy((0, y, 0), (0, 0, 0)))
        lidar = plugin_of(sim.models[measured], RaySensor)
        first = lidar.scan().ranges
        for _ in range(3):
            sim.step(200)
            lidar.scan()
        sim.reset(simulation=True)
        return first, lidar.scan().ranges
    finally:
        sim.close()


def test_noise_of_one_robot_does_not_depend_on_other_robots_or_spawn_order(laser_mbot_urdf):
    alone, _ = _first_scan(laser_mbot_urdf, ["a"], "a")
    assert np.isfinite(alone).sum() > 100
    assert np.array_equal(alone, _first_scan(laser_mbot_urdf, ["a", "b"], "a")[0])
    assert np.array_equal(alone, _first_scan(laser_mbot_urdf, ["b", "a"], "a")[0])
    assert np.array_equal(alone, _first_scan(laser_mbot_urdf, ["c", "b", "a"], "a")[0])
    # Another seed, or another robot name at the same place, draws other noise.
    assert not np.array_equal(alone, _first_scan(laser_mbot_urdf, ["a"], "a", seed=8)[0])
    assert not np.array_equal(alone, _first_scan(laser_mbot_urdf, ["z"], "z")[0])


def test_reset_simulation_rederives_the_random_streams(laser_mbot_urdf):
    first, after_reset = _first_scan(laser_mbot_urdf, ["a", "b"], "a")
    assert np.array_equal(first, after_reset)


def test_a_failing_plugin_is_disabled_and_the_rest_runs(mbot_urdf, caplog):
    sim = simulation()
    try:
        spawned = sim.spawn_robot(parse_robot(mbot_urdf, "model 'mbot'"), "mbot")
        drive = plugin_of(spawned, DiffDrive)
        drive.update = lambda now: 1 / 0
        with caplog.at_level(logging.ERROR):
            sim.step(100)
        assert drive not in spawned.plugins and len(spawned.plugins) == 1
        assert "model 'mbot': plugin GazeboRosDiffDrive(ns = /) failed and is disabled" in caplog.text
        sim.step(100)
        assert sim.sim_time == pytest.approx(0.2)
    finally:
        sim.close()


def test_a_plugin_whose_timer_overflows_is_disabled_and_the_rest_runs(mbot_urdf, caplog):
    """A timer that raises (here a period of 1e308 s counted in steps, as a rate of 1e-308 Hz gave) is its
    plugin's failure, contained like one, in stepping and in reset."""
    sim = simulation()
    try:
        spawned = sim.spawn_robot(parse_robot(mbot_urdf, "model 'mbot'"), "mbot")
        drive = plugin_of(spawned, DiffDrive)

        def overflow(*_):
            return math.floor(math.inf)
        drive.timer.steps_until_due = overflow
        with caplog.at_level(logging.ERROR):
            sim.step(100)
        assert drive not in spawned.plugins
        assert caplog.text.count("GazeboRosDiffDrive(ns = /) failed and is disabled: OverflowError") == 1
        joint_states = plugin_of(spawned, JointStatePublisher)
        joint_states.timer.due = overflow
        sim.reset(simulation=False)
        sim.step(100)
        assert spawned.plugins == [] and sim.sim_time == pytest.approx(0.2)
    finally:
        sim.close()


def test_a_rate_or_period_too_small_to_count_is_refused_and_never_overflows(mbot_urdf):
    """1e-308 Hz is a period of 1e308 s: refused at the door, and a timer given it anyway is never due."""
    sim = simulation()
    try:
        urdf = mbot_urdf.replace("<updateRate>100.0</updateRate>", "<updateRate>1e-308</updateRate>", 1)
        assert urdf != mbot_urdf
        with pytest.raises(ConfigError, match=r"model 'mbot':\d+: GazeboRosDiffDrive\(ns = /\): <updateRate> has bad "
                                              r"value '1e-308': 1e-308 is outside the valid range <= 0 or >= 1e-06$"):
            sim.spawn_robot(parse_robot(urdf, "model 'mbot'"), "mbot")
        assert sim.model_names() == ["ground_plane"]
    finally:
        sim.close()
    for rate in (1e-308, 5e-324):
        timer = UpdateTimer(rate)
        assert timer.steps_until_due(1.0, 0.001) == sys.maxsize and not timer.due(1e9)


def revolute_chain(joints: int) -> str:
    links = ['<link name="l0"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" '
             'iyz="0"/></inertial><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>']
    for index in range(1, joints + 1):
        links.append(f'<link name="l{index}"><inertial><mass value="0.1"/><inertia ixx="0.001" iyy="0.001" '
                     f'izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>'
                     f'<joint name="j{index}" type="revolute"><parent link="l{index - 1}"/><child link="l{index}"/>'
                     f'<origin xyz="0 0 0.01"/><axis xyz="0 0 1"/>'
                     f'<limit lower="-1" upper="1" effort="10" velocity="1"/></joint>')
    return f'<robot name="chain">{chr(10).join(links)}</robot>'


@pytest.mark.parametrize("joints", [128, 1000])
def test_more_movable_joints_than_a_pybullet_body_holds_are_refused_and_leave_nothing(joints):
    sim = simulation()
    try:
        with pytest.raises(ModelError, match=rf"^SpawnModel: model 'chain': {joints} movable joints; a PyBullet body "
                                             r"holds at most 127 \(128 links with the base\); nothing was spawned$"):
            sim.spawn_robot(parse_robot(revolute_chain(joints), "model 'chain'"), "chain")
        assert sim.model_names() == ["ground_plane"] and sim.engine.client.getNumBodies() == 1
        sim.spawn_robot(parse_robot(revolute_chain(127), "model 'chain'"), "chain")
        sim.step(10)
        assert sim.engine.models_not_finite() == []
    finally:
        sim.close()


@pytest.mark.parametrize("name", ["", "a::b", "/", "a b"])
def test_a_name_gazebo_could_not_address_is_refused(mbot_urdf, name):
    sim = simulation()
    try:
        with pytest.raises(ModelError, match=rf"^SpawnModel: model name {re.escape(repr(name))}: a model name must be "
                                             r"non-empty, without whitespace, '::' .* or '/'; nothing was spawned$"):
            sim.spawn_robot(parse_robot(mbot_urdf, "model 'mbot'"), name)
        assert sim.model_names() == ["ground_plane"]
    finally:
        sim.close()


def test_a_bad_tag_refuses_the_spawn_and_leaves_nothing(mbot_urdf):
    sim = simulation()
    try:
        bad = mbot_urdf.replace("<wheelDiameter>0.064</wheelDiameter>", "<wheelDiameter>0</wheelDiameter>")
        assert bad != mbot_urdf
        with pytest.raises(ConfigError) as error:
            sim.spawn_robot(parse_robot(bad, "model 'mbot'"), "mbot")
        message = str(error.value)
        assert message.startswith("model 'mbot':") and "GazeboRosDiffDrive" in message
        assert "<wheelDiameter> has bad value '0': 0 is outside the valid range >= 0.001" in message
        assert sim.model_names() == ["ground_plane"] and sim.models == {}
        sim.spawn_robot(parse_robot(mbot_urdf, "model 'mbot'"), "mbot")
        assert "mbot" in sim.model_names()
    finally:
        sim.close()


def _drive_and_record(sim, drive, commands):
    """Odometry after each (command, steps) of a script: the core of a lockstep test."""
    record = []
    for linear, angular, steps in commands:
        drive.set_command(linear, angular)
        sim.step(steps)
        record.append(drive.odometry())
    return record


def test_reset_simulation_repeats_a_run_bit_for_bit(mbot_urdf, laser_mbot_urdf):
    script = [(0.3, 0.0, 700), (0.2, 0.8, 900), (-0.1, -0.5, 600), (0.0, 0.0, 300)]
    sim = simulation("playground.world", seed=3)
    try:
        sim.spawn_robot(parse_robot(mbot_urdf, "model 'plain'"), "plain", pose_from_xyz_rpy((1, -1, 0), (0, 0, 0)))
        spawned = sim.spawn_robot(parse_robot(laser_mbot_urdf, "model 'lidar'"), "lidar")
        drive, lidar = plugin_of(spawned, DiffDrive), plugin_of(spawned, RaySensor)
        first = _drive_and_record(sim, drive, script), lidar.scan().ranges
        sim.reset(simulation=True)
        again = _drive_and_record(sim, drive, script), lidar.scan().ranges
        assert first[0] == again[0]
        assert np.array_equal(first[1], again[1])
        other = simulation("playground.world", seed=3)
        try:
            other.spawn_robot(parse_robot(mbot_urdf, "model 'plain'"), "plain",
                              pose_from_xyz_rpy((1, -1, 0), (0, 0, 0)))
            twin = other.spawn_robot(parse_robot(laser_mbot_urdf, "model 'lidar'"), "lidar")
            fresh = (_drive_and_record(other, plugin_of(twin, DiffDrive), script),
                     plugin_of(twin, RaySensor).scan().ranges)
            assert fresh[0] == first[0] and np.array_equal(fresh[1], first[1])
        finally:
            other.close()
    finally:
        sim.close()


def test_fifty_lidar_robots_share_a_world_and_each_scans(laser_mbot_urdf):
    sim = simulation()
    try:
        model = parse_robot(laser_mbot_urdf, "model 'mbot'")
        robots = [sim.spawn_robot(model, f"mbot_{index}", pose_from_xyz_rpy((index % 10, index // 10, 0), (0, 0, 0)))
                  for index in range(50)]
        sim.step(200)
        scans = [plugin_of(spawned, RaySensor).scan().ranges for spawned in robots[:9]]
        # A row of ten along x, 1 m apart: each laser but the last sees the next robot's lidar cylinder (radius
        # 0.05 m, the laser's own height) 1 - 0.05 = 0.95 m ahead; the course lidar's noise is 0.01 m (5 sigma).
        ahead = [ranges[len(ranges) // 2] for ranges in scans]
        assert all(abs(distance - 0.95) < 0.05 for distance in ahead), ahead
    finally:
        sim.close()
