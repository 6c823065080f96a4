"""The robot in the core alone (no ROS): driven by its diff drive plugin, Gazebo-like tracking, the caster fix,
reset, determinism."""
import math
import os

import pytest

from mbot_sim_bridge.core.drives.diff_drive import DiffDrive
from mbot_sim_bridge.core.engine import Engine
from mbot_sim_bridge.core.errors import ModelError
from mbot_sim_bridge.core.geometry import Pose, pose_from_xyz_rpy, rpy, yaw
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.world_bodies import load_world
from sensor_fixtures import measured_motion, plugin_of, world_simulation

WHEELS = ("left_wheel_joint", "right_wheel_joint")
EMPTY_WORLD = os.path.join(os.path.dirname(__file__), "..", "..", "..", "..", "worlds", "empty.world")


class EngineWithMbot:
    """The engine alone with the course's mbot on the empty world; its wheels set straight to a speed, without the
    drive plugin (for what the engine does, such as a free caster)."""

    def __init__(self, urdf, casters_fixed=True):
        self.engine = Engine()
        world = load_world(self.engine.client, parse_world(EMPTY_WORLD))
        self.engine.add_world(world)
        self.robot = self.engine.spawn_robot(parse_robot(urdf), "mbot", driven_joints=WHEELS if casters_fixed else
                                             WHEELS + ("back_caster_joint",))

    def spin_wheels(self, rim_speeds, seconds):
        """Each wheel held at its rim speed (m/s, 0.032 m wheels, 30 N m); the yaw turned."""
        start = yaw(self.robot.root_pose().orientation)
        for _ in range(int(round(seconds / 0.001))):
            for joint, speed in zip(WHEELS, rim_speeds):
                self.robot.set_joint_velocity(joint, speed / 0.032, 30.0)
            self.engine.step()
        return math.remainder(yaw(self.robot.root_pose().orientation) - start, 2 * math.pi)

    def close(self):
        self.engine.close()


@pytest.fixture
def engine_mbot(mbot_urdf):
    drive = EngineWithMbot(mbot_urdf)
    yield drive
    drive.close()


def driven_mbot(tmp_path, urdf):
    """The course's mbot with its diff drive plugin, as the simulator runs it."""
    sim = world_simulation(tmp_path)
    spawned = sim.spawn_robot(parse_robot(urdf, "model 'mbot'"), "mbot")
    return sim, spawned, plugin_of(spawned, DiffDrive)


def test_mass_is_what_the_urdf_states(engine_mbot):
    client, robot = engine_mbot.engine.client, engine_mbot.robot
    total = sum(client.getDynamicsInfo(robot.body, index)[0] for index in robot.link_index.values())
    assert total == pytest.approx(20 + 0.5 + 2 + 2, abs=1e-6)


@pytest.mark.parametrize("linear", [0.1, 0.5, -0.2])
def test_straight_line_speed(tmp_path, mbot_urdf, linear):
    sim, spawned, drive = driven_mbot(tmp_path, mbot_urdf)
    speed, _ = measured_motion(sim, spawned, lambda: drive.set_command(linear, 0.0), settle=2.0)
    end = spawned.robot.root_pose()
    assert speed == pytest.approx(linear, rel=0.05)
    assert abs(end.position[2]) < 0.01 and max(abs(a) for a in rpy(end.orientation)[:2]) < math.radians(2)


@pytest.mark.parametrize("angular", [0.5, -1.0])
def test_turning_in_place_with_the_caster_fix(tmp_path, mbot_urdf, angular):
    sim, spawned, drive = driven_mbot(tmp_path, mbot_urdf)
    _, rate = measured_motion(sim, spawned, lambda: drive.set_command(0.0, angular), settle=2.0)
    assert rate == pytest.approx(angular, rel=0.05)


def test_without_the_caster_fix_the_robot_cannot_turn_in_place(mbot_urdf):
    """Documents why the fix exists: a one-axis sphere caster with friction pins the robot in Bullet. The wheels
    opposite at 0.06 m/s would turn it 0.5 rad/s (0.24 m apart): 1.5 rad in 3 s, as they do with it fixed."""
    engine = EngineWithMbot(mbot_urdf, casters_fixed=False)
    try:
        assert abs(engine.spin_wheels((-0.06, 0.06), 3.0)) < 0.25
    finally:
        engine.close()
    engine = EngineWithMbot(mbot_urdf)
    try:
        assert abs(engine.spin_wheels((-0.06, 0.06), 3.0)) > 1.0
    finally:
        engine.close()


def test_spawn_pose_and_reset_world(engine_mbot, mbot_urdf):
    engine = engine_mbot.engine
    other = engine.spawn_robot(parse_robot(mbot_urdf), "second", pose_from_xyz_rpy((2.0, 1.0, 0.0), (0, 0, 1.0)))
    assert other.root_pose().position == pytest.approx((2.0, 1.0, 0.0), abs=1e-6)
    assert yaw(other.root_pose().orientation) == pytest.approx(1.0)
    engine_mbot.spin_wheels((0.3, 0.3), 1.5)
    assert engine_mbot.robot.root_pose().position[0] > 0.3
    engine.reset_world()
    assert engine_mbot.robot.root_pose().position == pytest.approx((0.0, 0.0, 0.0), abs=1e-6)
    assert engine.sim_time == pytest.approx(1.5)
    engine.restart()
    assert engine.sim_time == 0.0 and engine.model_names() == []
    engine.respawn(other)
    assert engine.model_names() == ["second"]
    assert other.root_pose().position == pytest.approx((2.0, 1.0, 0.0), abs=1e-6)


def test_duplicate_and_unknown_model_names_are_errors(engine_mbot, mbot_urdf):
    with pytest.raises(ModelError, match="model 'mbot' already exists"):
        engine_mbot.engine.spawn_robot(parse_robot(mbot_urdf), "mbot")
    with pytest.raises(ModelError, match="model 'ghost' does not exist"):
        engine_mbot.engine.remove("ghost")


def test_lumped_link_pose_is_composed_from_its_fixed_joint(engine_mbot):
    assert engine_mbot.robot.link_world_pose("base_link").position == pytest.approx((0, 0, 0.042), abs=1e-4)


def test_two_runs_with_the_same_inputs_are_identical(tmp_path, mbot_urdf):
    results = []
    for _ in range(2):
        sim, spawned, drive = driven_mbot(tmp_path, mbot_urdf)
        try:
            measured_motion(sim, spawned, lambda: drive.set_command(0.3, 0.4), settle=1.0, window=0.5)
            results.append(spawned.robot.root_pose())
        finally:
            sim.close()
    assert results[0] == results[1]


@pytest.mark.parametrize("pose, linear, message", [
    (Pose((float("nan"), 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)), (0, 0, 0), "position.x is nan, not a finite number"),
    (Pose((0.0, 0.0, 2e5), (0.0, 0.0, 0.0, 1.0)), (0, 0, 0), "position.z = 200000 is outside ±100000"),
    (Pose((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)), (0, float("inf"), 0), "linear velocity.y is inf"),
])
def test_a_state_that_bullet_cannot_hold_is_refused_and_changes_nothing(pose, linear, message):
    engine = Engine()
    try:
        engine.add_world(load_world(engine.client, parse_world(EMPTY_WORLD)))
        before = engine.model_pose("ground_plane")
        with pytest.raises(ModelError, match=message.replace("(", r"\(").replace(")", r"\)")):
            engine.set_model_state("ground_plane", pose, linear)
        assert engine.model_pose("ground_plane") == before
    finally:
        engine.close()
