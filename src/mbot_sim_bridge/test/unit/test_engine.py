"""The robot driven through the core alone (no ROS): Gazebo-like tracking, caster fix, reset, determinism."""
import math
import os

import pytest

from mbot_sim_bridge.core.drives.diff_drive import DiffDriveGeometry, WheelSpeedRamp
from mbot_sim_bridge.core.engine import Engine
from mbot_sim_bridge.core.errors import ModelError
from mbot_sim_bridge.core.geometry import Pose, pose_from_xyz_rpy, rpy, yaw
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.world_bodies import load_world

WHEELS = ("left_wheel_joint", "right_wheel_joint")
EMPTY_WORLD = os.path.join(os.path.dirname(__file__), "..", "..", "..", "..", "worlds", "empty.world")


class CoreDrive:
    """The diff drive's control loop at 100 Hz, as the ROS plugin runs it, minus the ROS."""

    def __init__(self, urdf, casters_fixed=True):
        self.engine = Engine()
        world = load_world(self.engine.client, parse_world(EMPTY_WORLD))
        self.engine.add_world(world)
        self.robot = self.engine.spawn_robot(parse_robot(urdf), "mbot", driven_joints=WHEELS if casters_fixed else
                                             WHEELS + ("back_caster_joint",))
        self.geometry = DiffDriveGeometry(0.24, 0.032, legacy_mode=True)

    def drive(self, linear, angular, seconds):
        """Returns (pose at the end, pose one second before the end); ``seconds`` must exceed 1."""
        ramp, last, poses = WheelSpeedRamp(1.8), self.engine.sim_time, []
        for step in range(int(round(seconds / 0.001))):
            self.engine.step()
            now = self.engine.sim_time
            if now - last > 0.01 + 1e-9:
                measured = [rate * 0.032 for _, rate, _ in self.robot.joint_state(WHEELS)]
                speeds = ramp.step(self.geometry.wheel_rim_speeds(linear, angular), measured, now - last)
                last += 0.01
                for joint, speed in zip(WHEELS, speeds):
                    self.robot.set_joint_velocity(joint, speed / 0.032, 30.0)
            if step == int(round((seconds - 1.0) / 0.001)) - 1:
                poses.append(self.robot.root_pose())
        return self.robot.root_pose(), poses[0]

    def close(self):
        self.engine.close()


@pytest.fixture
def core_drive(mbot_urdf):
    drive = CoreDrive(mbot_urdf)
    yield drive
    drive.close()


def test_mass_is_what_the_urdf_states(core_drive):
    client, robot = core_drive.engine.client, core_drive.robot
    total = sum(client.getDynamicsInfo(robot.body, index)[0] for index in robot.link_index.values())
    assert total == pytest.approx(20 + 0.5 + 2 + 2, abs=1e-6)


@pytest.mark.parametrize("linear", [0.1, 0.5, -0.2])
def test_straight_line_speed(core_drive, linear):
    end, before = core_drive.drive(linear, 0.0, 3.0)
    speed = math.copysign(math.hypot(end.position[0] - before.position[0], end.position[1] - before.position[1]),
                          end.position[0] - before.position[0])
    assert speed == pytest.approx(linear, rel=0.05)
    assert abs(end.position[2]) < 0.01 and max(abs(a) for a in rpy(end.orientation)[:2]) < math.radians(2)


@pytest.mark.parametrize("angular", [0.5, -1.0])
def test_turning_in_place_with_the_caster_fix(core_drive, angular):
    end, before = core_drive.drive(0.0, angular, 3.0)
    rate = math.remainder(yaw(end.orientation) - yaw(before.orientation), 2 * math.pi)
    assert rate == pytest.approx(angular, rel=0.05)


def test_without_the_caster_fix_the_robot_cannot_turn_in_place(mbot_urdf):
    """Documents why the fix exists: a one-axis sphere caster with friction pins the robot in Bullet."""
    drive = CoreDrive(mbot_urdf, casters_fixed=False)
    try:
        end, before = drive.drive(0.0, 0.5, 3.0)
        assert abs(math.remainder(yaw(end.orientation) - yaw(before.orientation), 2 * math.pi)) < 0.25
    finally:
        drive.close()


def test_spawn_pose_and_reset_world(core_drive, mbot_urdf):
    engine = core_drive.engine
    other = engine.spawn_robot(parse_robot(mbot_urdf), "second", pose_from_xyz_rpy((2.0, 1.0, 0.0), (0, 0, 1.0)))
    assert other.root_pose().position == pytest.approx((2.0, 1.0, 0.0), abs=1e-6)
    assert yaw(other.root_pose().orientation) == pytest.approx(1.0)
    core_drive.drive(0.3, 0.0, 1.5)
    engine.reset_world()
    assert core_drive.robot.root_pose().position == pytest.approx((0.0, 0.0, 0.0), abs=1e-6)
    assert engine.sim_time == pytest.approx(1.5)
    engine.restart()
    assert engine.sim_time == 0.0 and engine.model_names() == []
    engine.respawn(other)
    assert engine.model_names() == ["second"]
    assert other.root_pose().position == pytest.approx((2.0, 1.0, 0.0), abs=1e-6)


def test_duplicate_and_unknown_model_names_are_errors(core_drive, mbot_urdf):
    with pytest.raises(ModelError, match="model 'mbot' already exists"):
        core_drive.engine.spawn_robot(parse_robot(mbot_urdf), "mbot")
    with pytest.raises(ModelError, match="model 'ghost' does not exist"):
        core_drive.engine.remove("ghost")


def test_lumped_link_pose_is_composed_from_its_fixed_joint(core_drive):
    assert core_drive.robot.link_world_pose("base_link").position == pytest.approx((0, 0, 0.042), abs=1e-4)


def test_two_runs_with_the_same_inputs_are_identical(mbot_urdf):
    results = []
    for _ in range(2):
        drive = CoreDrive(mbot_urdf)
        try:
            results.append(drive.drive(0.3, 0.4, 1.5)[0])
        finally:
            drive.close()
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
