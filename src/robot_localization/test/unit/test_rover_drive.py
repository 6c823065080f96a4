"""The filter on data the simulator recorded (the rover's diff drive odometry and hector IMU over a drive of
about 11 m with arcs both ways and a turn in place, ../data/rover_drive.npz), run with Clearpath's localization
configuration: the final filtered pose is within 2 % of the distance travelled of the ground truth, with or
without NaN, inf and huge values mixed into the inputs, and five times nearer than the odometry alone."""
import sys

import numpy as np
import pytest

from rover_replay import load_recording, path_length, relative_truth, replay

ACCEPTED_FRACTION = 0.02
# The diff drive odometry alone ends 1.26 m off, the filter 0.21 m: fusing the IMU's yaw rate must gain this much.
GAIN_OVER_ODOMETRY = 5.0


@pytest.fixture(scope="module")
def recording():
    return load_recording()


def final_error(recording, outputs):
    truth = relative_truth(recording["truth"], outputs[0][0])
    state = outputs[-1][1]
    return float(np.hypot(state[0] - truth[-1, 1], state[1] - truth[-1, 2])), path_length(truth), truth


def test_filtered_pose_ends_within_two_percent_of_the_distance(recording):
    estimator, outputs = replay(recording)
    error, distance, truth = final_error(recording, outputs)
    odometry = recording["odometry"][-1]
    odometry_error = np.hypot(odometry[1] - truth[-1, 1], odometry[2] - truth[-1, 2])
    print(f"figure: rover drive {distance:.2f} m: filtered pose {error:.3f} m ({100 * error / distance:.2f} %) from "
          f"ground truth, yaw {outputs[-1][1][5] - truth[-1, 3]:+.4f} rad; the diff drive odometry alone "
          f"{odometry_error:.3f} m", file=sys.stderr)
    assert distance > 10.0
    assert error < ACCEPTED_FRACTION * distance
    assert error < odometry_error / GAIN_OVER_ODOMETRY
    assert estimator.warnings == {}


BAD = (np.nan, np.inf, -np.inf, 1e300)


def corrupt(kind, index, messages):
    """Every 50th message of each source gets NaN, inf or huge values in one field."""
    if index % 50:
        return messages
    bad = BAD[(index // 50) % len(BAD)]
    if kind == "odom":
        pose, twist = messages
        twist.covariance[(index // 200) % 6, (index // 200) % 6] = bad
        twist.linear[0] = bad if index % 100 == 0 else twist.linear[0]
        return pose, twist
    imu, = messages
    imu.orientation_covariance[0, 1] = bad
    imu.angular_velocity[2] = bad
    imu.linear_acceleration[:] = bad
    imu.orientation[3] = bad if index % 100 == 0 else imu.orientation[3]
    return (imu,)


def test_nan_inf_and_huge_inputs_are_left_out_and_reported(recording):
    estimator, outputs = replay(recording, corrupt=corrupt)
    states = np.array([state for _, state in outputs])
    assert np.isfinite(states).all()
    error, distance, _ = final_error(recording, outputs)
    print(f"figure: rover drive with every 50th message corrupted: {100 * error / distance:.2f} % of the distance "
          "from ground truth", file=sys.stderr)
    assert error < ACCEPTED_FRACTION * distance
    rejected = {topic for topic, reason in estimator.filter.take_rejections()}
    assert {"odom0_twist", "imu0_twist"} <= rejected
