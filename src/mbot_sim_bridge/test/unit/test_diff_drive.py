import math

import pytest

from mbot_sim_bridge.core.drives.diff_drive import DiffDriveGeometry, EncoderOdometry, WheelSpeedRamp
from mbot_sim_bridge.core.drives.twist_drive import yaw_rotated_velocity

SEPARATION, RADIUS = 0.24, 0.032


@pytest.mark.parametrize("legacy, expected", [(False, (0.2 - 0.12, 0.2 + 0.12)), (True, (0.2 + 0.12, 0.2 - 0.12))])
def test_command_split_with_and_without_legacy_mode(legacy, expected):
    left, right = DiffDriveGeometry(SEPARATION, RADIUS, legacy).wheel_rim_speeds(0.2, 1.0)
    assert (left, right) == pytest.approx(expected)


def test_ramp_limits_the_change_per_update_to_acceleration_times_dt():
    ramp = WheelSpeedRamp(1.8)
    speeds = ramp.step((0.5, 0.5), (0.0, 0.0), 0.011)
    assert speeds == pytest.approx((1.8 * 0.011, 1.8 * 0.011))


def test_ramp_applies_targets_at_once_when_either_wheel_is_close():
    ramp = WheelSpeedRamp(1.8)
    assert ramp.step((0.5, -0.5), (0.495, 0.0), 0.011) == (0.5, -0.5)


def test_zero_acceleration_means_no_ramp():
    assert WheelSpeedRamp(0.0).step((0.5, 0.3), (0.0, 0.0), 0.01) == (0.5, 0.3)


def test_ramp_reset_forgets_the_integrated_command():
    ramp = WheelSpeedRamp(1.0)
    ramp.step((1.0, 1.0), (0.0, 0.0), 0.1)
    ramp.reset()
    assert ramp.step((1.0, 1.0), (0.0, 0.0), 0.1) == pytest.approx((0.1, 0.1))


@pytest.mark.parametrize("legacy", [False, True])
def test_encoder_odometry_integrates_a_quarter_turn_in_place(legacy):
    geometry = DiffDriveGeometry(SEPARATION, RADIUS, legacy)
    odometry = EncoderOdometry(geometry)
    left, right = geometry.wheel_rim_speeds(0.0, math.pi / 2)
    for _ in range(1000):
        odometry.integrate(left / RADIUS, right / RADIUS, 0.001)
    assert odometry.theta == pytest.approx(math.pi / 2, rel=1e-6)
    assert (odometry.x, odometry.y) == pytest.approx((0.0, 0.0), abs=1e-9)
    assert odometry.angular == pytest.approx(math.pi / 2)


def test_encoder_speed_is_a_magnitude_even_when_reversing():
    geometry = DiffDriveGeometry(SEPARATION, RADIUS, False)
    odometry = EncoderOdometry(geometry)
    for _ in range(1000):
        odometry.integrate(-0.2 / RADIUS, -0.2 / RADIUS, 0.001)
    assert odometry.x == pytest.approx(-0.2)
    assert odometry.linear == pytest.approx(0.2)


def test_world_twist_is_rotated_by_yaw_into_the_base_frame():
    assert yaw_rotated_velocity((0.0, 1.0, 0.0), math.pi / 2) == pytest.approx((1.0, 0.0))
    assert yaw_rotated_velocity((1.0, 0.0, 0.0), math.pi / 2) == pytest.approx((0.0, -1.0))
