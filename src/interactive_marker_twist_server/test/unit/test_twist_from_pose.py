"""The marker pose to Twist mapping of marker_server, as upstream's: scales, clamps and the yaw."""
import math

import pytest

from interactive_marker_twist_server.twist_from_pose import Scales, pose_problem, twist_values, yaw

IDENTITY = (0.0, 0.0, 0.0, 1.0)


def about_z(angle):
    return (0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2))


def test_defaults_drive_x_at_scale_one_and_turn_at_2_2_per_radian():
    linear, angular = twist_values(Scales(), (0.4, 0.3, 0.2), about_z(0.5))
    assert linear == {"x": 0.4}
    assert angular == pytest.approx(1.1)


def test_clamped_to_the_limits():
    linear, angular = twist_values(Scales(), (5.0, 0, 0), about_z(-3.0))
    assert linear == {"x": 1.0} and angular == pytest.approx(-2.2)
    assert twist_values(Scales(), (-5.0, 0, 0), IDENTITY)[0] == {"x": -1.0}
    assert twist_values(Scales(), (1e308, 0, 0), IDENTITY)[0] == {"x": 1.0}


def test_planar_scales_drive_y():
    scales = Scales(linear={"x": 2.0, "y": 0.5}, max_positive_linear={"x": 1.0, "y": 1.0},
                    max_negative_linear={"x": -1.0, "y": -0.1})
    linear, _ = twist_values(scales, (0.25, -1.0, 9.0), IDENTITY)
    assert linear == {"x": 0.5, "y": -0.1}


def test_yaw_of_an_unnormalized_quaternion_is_tfs():
    assert yaw(*[2 * value for value in about_z(0.7)]) == pytest.approx(0.7)


@pytest.mark.parametrize("position, orientation, expected", [
    ((math.nan, 0, 0), IDENTITY, "position.x is nan"),
    ((0, 0, 0), (0, 0, math.inf, 1), "orientation.z is inf"),
    ((0, 0, 0), (0, 0, 0, 0), "squared norm is 0.0"),
    ((0, 0, 0), (0, 0, 1e-200, 0), "squared norm is 0.0"),
    ((0, 0, 0), (0, 0, 1e200, 1e200), "squared norm is inf"),
])
def test_unusable_poses_are_named(position, orientation, expected):
    assert expected in pose_problem(position, orientation)


def test_usable_pose_has_no_problem():
    assert pose_problem((1e300, 0, 0), about_z(1.0)) is None
