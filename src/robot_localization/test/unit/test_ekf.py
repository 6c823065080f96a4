"""The filter core without ROS: upstream's measurement test, the Jacobian against the transfer function, the
sensor mapping (IMU mounted rotated, differential, two_d_mode), bad input and the parameters."""
import heapq
import subprocess
import sys

import numpy as np
import pytest

from robot_localization.ekf import STATE_SIZE, VX, VYAW, X, YAW, Ekf, Measurement
from robot_localization.estimator import Estimator, ImuInput, PoseInput, Source, TwistInput
from robot_localization.geometry import Transform, matrix_rpy, quaternion_matrix, rpy_matrix, rpy_quaternion
from robot_localization.params import read_config

ALL = np.ones(STATE_SIZE, dtype=bool)


def members(*indices):
    update = np.zeros(STATE_SIZE, dtype=bool)
    update[list(indices)] = True
    return update


def enqueue(estimator, measurement):
    heapq.heappush(estimator.queue, (measurement.time, 0, measurement))


def test_measurements_as_upstream_test_ekf():
    """test_ekf.cpp's Measurements: the first measurement initializes the state and covariance, a second one with
    tiny variance pulls the state onto it."""
    estimator = Estimator(lambda *args: Transform(), lambda *args: None)
    estimator.filter.covariance = np.eye(STATE_SIZE) * 0.5
    values, covariance = np.arange(STATE_SIZE) * 0.01 * STATE_SIZE, np.eye(STATE_SIZE) * 1e-9
    enqueue(estimator, Measurement("odom0", 1000.0, values, covariance, ALL))
    estimator.integrate(1001.0)
    assert np.array_equal(estimator.filter.state, values)
    assert np.array_equal(estimator.filter.covariance, covariance)
    estimator.filter.covariance = np.eye(STATE_SIZE) * 0.5
    enqueue(estimator, Measurement("odom0", 1002.0, 2 * values, covariance, ALL))
    estimator.integrate(1003.0)
    assert np.abs(2 * values - estimator.filter.state).max() < 0.001


def test_jacobian_is_the_derivative_of_the_transfer_function():
    rng = np.random.default_rng(1)
    ekf = Ekf()
    ekf.state = rng.normal(0.0, 0.6, STATE_SIZE)
    _, jacobian = ekf.transfer_function(0.05)

    def step(state):
        other = Ekf()
        other.state = state
        return other.transfer_function(0.05)[0] @ state
    numeric = np.column_stack([(step(ekf.state + delta) - step(ekf.state - delta)) / 2e-6
                               for delta in np.eye(STATE_SIZE) * 1e-6])
    assert np.abs(numeric - jacobian).max() < 1e-7


def test_prediction_moves_along_the_heading_and_grows_the_covariance():
    ekf = Ekf()
    ekf.state[YAW], ekf.state[VX], ekf.state[VYAW] = np.pi / 2, 1.0, 0.0
    before = ekf.covariance.copy()
    ekf.predict(0.5)
    assert ekf.state[X] == pytest.approx(0.0, abs=1e-12) and ekf.state[1] == pytest.approx(0.5)
    assert np.all(np.diag(ekf.covariance) > np.diag(before))


def test_a_one_member_correction_takes_the_kalman_gain_of_its_closed_form():
    """x measured alone with variance r against the prior's p: gain k = p / (p + r), the state moves k of the way
    to the measurement and the variance becomes (1 - k) p; the unmeasured members stay."""
    ekf = Ekf()
    p, r, prior, measured = 0.4, 0.1, 1.0, 2.0
    ekf.covariance = np.eye(STATE_SIZE) * 0.3
    ekf.covariance[X, X] = p
    ekf.state[X], ekf.state[VX] = prior, 0.7
    values, covariance = np.zeros(STATE_SIZE), np.eye(STATE_SIZE) * r
    values[X] = measured
    ekf.correct(Measurement("odom0", 1.0, values, covariance, members(X)))
    gain = p / (p + r)
    assert ekf.state[X] == pytest.approx(prior + gain * (measured - prior), abs=1e-12)
    assert ekf.covariance[X, X] == pytest.approx((1 - gain) * p, abs=1e-12)
    assert ekf.state[VX] == 0.7 and ekf.covariance[VX, VX] == 0.3


def test_tf2_euler_conventions():
    rotation = rpy_matrix(0.1, -0.2, 2.5)
    assert np.allclose(matrix_rpy(rotation), (0.1, -0.2, 2.5))
    assert np.allclose(quaternion_matrix(rpy_quaternion(0.1, -0.2, 2.5)), rotation)
    assert np.allclose(matrix_rpy(rpy_matrix(0.3, np.pi / 2, 0.0))[1], np.pi / 2)


def imu_estimator(mounting, **options):
    return Estimator(lambda target, source, stamp: Transform() if target == source else mounting,
                     lambda *args: None, **options)


def imu_message(stamp, yaw, yaw_rate, acceleration, mounting_rotation):
    """What an IMU mounted with ``mounting_rotation`` reports on a base at ``yaw`` turning at ``yaw_rate``."""
    orientation = rpy_quaternion(*matrix_rpy(rpy_matrix(0.0, 0.0, yaw) @ mounting_rotation))
    covariance = np.eye(3) * 1e-4
    return ImuInput(stamp, "imu_link", orientation, covariance, mounting_rotation.T @ [0.0, 0.0, yaw_rate],
                    covariance, mounting_rotation.T @ acceleration, covariance)


def test_imu_mounted_turned_reads_in_base_link():
    """An IMU turned 90 degrees about z: its yaw has the mounting taken off, its rates and accelerations are
    rotated into base_link (the mask follows)."""
    mounting = Transform(rpy_matrix(0.0, 0.0, np.pi / 2), np.zeros(3))
    estimator = imu_estimator(mounting)
    sources = [Source("imu0_pose", members(YAW)), Source("imu0_twist", members(VYAW)),
               Source("imu0_acceleration", members(12, 13))]
    estimator.imu(imu_message(1.0, 0.3, 0.2, [0.5, 0.0, 0.0], mounting.rotation), *sources)
    measurements = sorted((item[2] for item in estimator.queue), key=lambda m: m.topic)
    acceleration, pose, twist = measurements
    assert pose.values[YAW] == pytest.approx(0.3) and pose.update[YAW]
    assert twist.values[VYAW] == pytest.approx(0.2) and twist.update[VYAW]
    assert np.allclose(acceleration.values[12:15], [0.5, 0.0, 0.0]) and acceleration.update[12:14].all()


def test_imu_gravity_removed_for_a_rolled_mounting():
    """bag1's mounting (roll +90, yaw -90 degrees, offset): gravity comes off, a forward push reads forward."""
    mounting = Transform(rpy_matrix(np.pi / 2, 0.0, -np.pi / 2), np.array([0.0, -0.3, 0.52]))
    estimator = imu_estimator(mounting)
    source = Source("imu0_acceleration", members(12, 13, 14), remove_gravity=True)
    sensed = mounting.rotation.T @ np.array([1.0, 0.0, 9.80665])
    orientation = rpy_quaternion(*matrix_rpy(mounting.rotation))
    covariance = np.eye(3) * 1e-4
    message = ImuInput(1.0, "imu_link", orientation, covariance, np.zeros(3), covariance, sensed, covariance)
    values, _, update = estimator.prepare_acceleration(message, source, 1.0, "base_link")
    assert np.allclose(values[12:15], [1.0, 0.0, 0.0]) and update[12:15].all()


def test_differential_pose_becomes_velocity():
    estimator = Estimator(lambda *args: Transform(), lambda *args: None)
    source = Source("pose0", members(X, 1, YAW), differential=True)
    covariance = np.eye(6) * 0.01
    for stamp, x, yaw in ((1.0, 2.0, 0.5), (1.5, 2.0 + 0.5 * np.cos(0.5), 0.6)):
        position = np.array([x, 0.5 * np.sin(0.5) * (stamp - 1.0) / 0.5, 0.0])
        estimator.pose(PoseInput(stamp, "odom", position, rpy_quaternion(0, 0, yaw), covariance), source)
    (_, _, measurement), = estimator.queue
    assert measurement.update[[VX, 7, VYAW]].all() and not measurement.update[:6].any()
    assert measurement.values[VX] == pytest.approx(1.0) and measurement.values[VYAW] == pytest.approx(0.2)


def test_two_d_mode_pins_the_out_of_plane_members():
    estimator = Estimator(lambda *args: Transform(), lambda *args: None, two_d_mode=True)
    twist = TwistInput(1.0, "base_link", np.array([1.0, 0.0, 0.4]), np.array([0.2, 0.0, 0.1]), np.eye(6))
    values, covariance, update = estimator.prepare_twist(twist, "base_link", members(VX, 8, VYAW))
    assert values[8] == 0.0 and update[[2, 3, 4, 8, 9, 10, 14]].all() and covariance[8, 8] == 1e-6


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf, 1e300])
def test_bad_values_and_covariances_leave_the_estimate_finite(bad):
    estimator = Estimator(lambda *args: Transform(), lambda *args: None)
    good = TwistInput(1.0, "base_link", np.array([1.0, 0, 0]), np.zeros(3), np.eye(6) * 0.01)
    source = Source("odom0_twist", members(VX, VYAW))
    estimator.twist(good, source)
    estimator.integrate(1.0)
    for stamp, field in ((1.1, "linear"), (1.2, "covariance"), (1.3, "angular")):
        message = TwistInput(stamp, "base_link", np.array([1.0, 0, 0]), np.zeros(3), np.eye(6) * 0.01)
        getattr(message, field)[0 if field != "covariance" else (0, 0)] = bad
        estimator.twist(message, source)
        estimator.integrate(stamp)
    assert np.isfinite(estimator.filter.state).all() and np.isfinite(estimator.filter.covariance).all()
    assert estimator.filter.state[VX] == pytest.approx(1.0, abs=0.01)
    assert ("odom0_twist", "invalid") in estimator.filter.take_rejections()
    refused = PoseInput(2.0, "odom", np.array([bad, 0, 0]), np.array([0, 0, 0, 1.0]), np.eye(6))
    assert not estimator.set_pose(refused, 2.0)
    assert np.isfinite(estimator.filter.state).all()


def test_set_pose_sets_the_state_and_ignores_older_data():
    estimator = Estimator(lambda *args: Transform(), lambda *args: None)
    pose = PoseInput(5.0, "odom", np.array([1.0, 2.0, 0.0]), rpy_quaternion(0, 0, 0.7), np.eye(6) * 0.1)
    assert estimator.set_pose(pose, 5.0)
    assert np.allclose(estimator.filter.state[[0, 1, YAW]], [1.0, 2.0, 0.7])
    estimator.twist(TwistInput(4.0, "base_link", np.ones(3), np.ones(3), np.eye(6)), Source("twist0", members(VX)))
    assert not estimator.queue


def read(parameters):
    config, problems = read_config(parameters)
    return config, [line for _, line in problems]


CONFIG = [False] * 6 + [True, True, False] + [False] * 6


def test_parameters_of_a_clearpath_configuration_read_cleanly():
    config, lines = read({"frequency": 50, "two_d_mode": True, "odom0": "odom", "odom0_config": CONFIG,
                          "odom0_queue_size": 10, "imu0": "imu/data", "imu0_config": [False] * 5 + [True] + [False] *
                          5 + [True] + [False] * 3, "imu0_differential": True,
                          "imu0_remove_gravitational_acceleration": True})
    assert lines == [] and config.frequency == 50 and [s.name for s in config.sensors] == ["odom0", "imu0"]
    assert config.sensors[0].queue_size == 10 and config.sensors[1].sources["pose"].differential


@pytest.mark.parametrize("parameters, named", [
    ({"process_noise_covariance": [0.1] * 224}, "~process_noise_covariance"),
    ({"initial_estimate_covariance": [-1.0] * 225}, "~initial_estimate_covariance"),
    ({"process_noise_covariance": [float("nan")] * 225}, "~process_noise_covariance"),
    ({"odom0": "odom", "odom0_config": "true"}, "~odom0_config"),
    ({"odom0": "odom", "odom0_config": CONFIG, "odom0_queue_size": 0}, "~odom0_queue_size"),
    ({"imu0": "imu", "imu0_config": CONFIG, "imu0_pose_rejection_threshold": -2.0}, "~imu0_pose_rejection_threshold"),
    ({"frequency": 0}, "~frequency"),
    ({"two_d_mode": "yes"}, "~two_d_mode"),
    ({"frequnecy": 50}, "~frequnecy"),
    ({"odom0": "odom", "odom0_config": CONFIG, "odom0_relatve": True}, "~odom0_relatve"),
    ({"odom1": "odom", "odom1_config": CONFIG}, "~odom1"),
    ({"use_control": True}, "~use_control"),
])
def test_a_bad_or_unknown_parameter_gets_one_line_naming_it(parameters, named):
    _, lines = read({"print_diagnostics": False, **parameters})
    assert len([line for line in lines if line.startswith(named + ":")]) == 1, lines


def test_covariance_given_as_yaml_strings_is_read_as_upstream_reads_it():
    config, lines = read({"initial_estimate_covariance": ["1e-9" if i % 16 == 0 else 0 for i in range(225)]})
    assert lines == [] or all("~initial" not in line for line in lines)
    assert np.allclose(np.diag(config.initial_estimate_covariance), 1e-9)


def test_the_filter_core_imports_no_ros():
    code = ("import sys; import robot_localization.ekf, robot_localization.estimator, robot_localization.params; "
            "sys.exit('rospy' in sys.modules)")
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


@pytest.mark.parametrize("history_length, same", [(None, False), (1.0, True)])
def test_late_data_is_fused_in_order_with_smooth_lagged_data(history_length, same):
    """A measurement arriving after the prediction went past its stamp: lost motion without smoothing, the
    in-order estimate with it (upstream's smooth_lagged_data)."""
    source = Source("twist0", members(VX, VYAW))

    def twist(stamp, speed):
        return TwistInput(stamp, "base_link", np.array([speed, 0, 0]), np.array([0, 0, 0.5]), np.eye(6) * 1e-4)
    in_order, late = (Estimator(lambda *args: Transform(), lambda *args: None) for _ in range(2))
    late.history_length = history_length
    for estimator in (in_order, late):
        estimator.twist(twist(1.0, 1.0), source)
        estimator.integrate(1.0)
    in_order.twist(twist(1.1, 2.0), source)
    in_order.integrate(1.3)
    in_order.integrate(1.3)
    late.integrate(1.3)
    late.twist(twist(1.1, 2.0), source)
    late.integrate(1.3)
    late.integrate(1.3)
    assert np.allclose(in_order.filter.state, late.filter.state) == same
