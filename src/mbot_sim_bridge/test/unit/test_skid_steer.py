"""libgazebo_ros_skid_steer_drive.so (core/drives/skid_steer_drive.py) on mobile_test_robots' skid-steer base: straight
lines within 5 %, turns the commanded way, ground-truth odometry, bad joints refused, NaN ignored, reset."""
import math
import re

import pytest
from plugin_robots import SKID_XACRO
from sensor_fixtures import measured_motion, plugin_of, world_simulation

from mbot_sim_bridge.core.errors import ConfigError
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.drives.skid_steer_drive import SkidSteerDrive
from mbot_sim_bridge.robot_description import expand_xacro


def urdf():
    return expand_xacro(SKID_XACRO)


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    sim = world_simulation(tmp_path_factory.mktemp("skid"))
    spawned = sim.spawn_robot(parse_robot(urdf(), "model 'skid_steer_base'"), "skid_steer_base")
    sim.step(300)
    yield sim, spawned, plugin_of(spawned, SkidSteerDrive)
    sim.close()


@pytest.mark.parametrize("linear", [0.5, -0.3])
def test_straight_lines_within_5_percent(base, linear):
    sim, spawned, plugin = base
    speed, yaw_rate = measured_motion(sim, spawned, lambda: plugin.set_command(linear, 0.0), settle=1.0)
    print(f"figure: skid steer plugin: {linear} m/s commanded -> {speed:.4f} m/s")
    assert speed == pytest.approx(linear, rel=0.05)
    assert abs(yaw_rate) < 0.01


@pytest.mark.parametrize("angular", [0.8, -0.8])
def test_turns_in_place_the_commanded_way(base, angular):
    """Skid steering turns by sliding the wheels sideways: the rate depends on friction (README)."""
    sim, spawned, plugin = base
    speed, yaw_rate = measured_motion(sim, spawned, lambda: plugin.set_command(0.0, angular), settle=1.0)
    print(f"figure: skid steer plugin: {angular} rad/s commanded -> {yaw_rate:.3f} rad/s")
    assert yaw_rate * angular > 0 and abs(yaw_rate) > 0.3 * abs(angular)
    assert abs(speed) < 0.02


def test_odometry_is_the_ground_truth_and_nan_is_ignored_and_reset_stops(base):
    sim, spawned, plugin = base
    measured_motion(sim, spawned, lambda: plugin.set_command(0.4, 0.0), settle=0.5, window=0.2)
    sim.step(10)  # one update at 100 Hz
    assert plugin.latest.pose.position == pytest.approx(spawned.robot.root_pose().position, abs=0.01)
    assert plugin.latest.linear[0] == pytest.approx(0.4, rel=0.05)
    assert not plugin.set_command(math.nan, 0.0)
    sim.reset(simulation=False)
    sim.step(500)
    assert math.hypot(*spawned.robot.root_velocity()[0][:2]) < 0.01


def test_a_wheel_joint_the_robot_lacks_is_refused(tmp_path):
    sim = world_simulation(tmp_path)
    with pytest.raises(ConfigError, match="<leftRearJoint> names joint 'rear_left_wheel_joint'"):
        sim.spawn_robot(parse_robot(urdf().replace('name="rear_left_wheel_joint"', 'name="rear_left_hinge"'),
                                    "model 'skid'"), "skid")
    sim.close()


def test_wheels_mapped_to_one_joint_are_refused(tmp_path):
    sim = world_simulation(tmp_path)
    try:
        text = urdf()
        for tag in ("rightFrontJoint", "leftRearJoint", "rightRearJoint"):
            text = re.sub(f"<{tag}>[^<]*</{tag}>", f"<{tag}>front_left_wheel_joint</{tag}>", text)
        with pytest.raises(ConfigError, match="<leftFrontJoint> and <rightFrontJoint> both name joint "
                                              "'front_left_wheel_joint'"):
            sim.spawn_robot(parse_robot(text, "model 'skid'"), "skid")
    finally:
        sim.close()


@pytest.mark.parametrize("tag", ["wheelDiameter", "wheelSeparation"])
def test_a_wheel_size_below_a_millimetre_is_refused(tmp_path, tag):
    """Found by the fuzz sweep: a diameter of 5e-324 halves to 0, and the drive divided by it while stepping."""
    sim = world_simulation(tmp_path)
    try:
        text = re.sub(f"<{tag}>[^<]*</{tag}>", f"<{tag}>5e-324</{tag}>", urdf())
        with pytest.raises(ConfigError, match=f"<{tag}> has bad value '5e-324': .* outside the valid range >= 0.001"):
            sim.spawn_robot(parse_robot(text, "model 'skid'"), "skid")
    finally:
        sim.close()
