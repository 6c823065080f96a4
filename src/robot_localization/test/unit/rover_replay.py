"""The recorded rover drive (../data/rover_drive.npz, made by ../record_rover_drive.py) fed to the ROS-free
estimator as the node feeds it: messages in stamp order, the periodic update every 1/frequency of their clock."""
from pathlib import Path

import numpy as np
import yaml

from robot_localization.estimator import Estimator, ImuInput, PoseInput, TwistInput
from robot_localization.geometry import Transform, matrix_rpy, quaternion_matrix
from robot_localization.params import read_config

TEST = Path(__file__).resolve().parent.parent
DATA = TEST / "data" / "rover_drive.npz"
CLEARPATH_CONFIG = TEST / "clearpath_localization.yaml"


def load_recording():
    with np.load(DATA) as data:
        return {name: data[name] for name in data.files}


def relative_truth(truth, start_time):
    """Ground truth (time, x, y, yaw) in the frame of the rover's pose at ``start_time``: the odom frame."""
    first = truth[np.searchsorted(truth[:, 0], start_time)]
    origin = Transform(quaternion_matrix(first[4:8]), first[1:4])
    rows = []
    for row in truth:
        pose = origin.inverse_times(Transform(quaternion_matrix(row[4:8]), row[1:4]))
        rows.append([row[0], pose.translation[0], pose.translation[1], matrix_rpy(pose.rotation)[2]])
    return np.array(rows)


def path_length(truth):
    return float(np.linalg.norm(np.diff(truth[:, 1:3], axis=0), axis=1).sum())


def replay(recording, parameters=None, corrupt=None):
    """Run the estimator over the recording; returns (estimator, [(time, state)] after each periodic update).
    ``corrupt(kind, index, messages)`` may change the index-th message of a kind before it goes in."""
    parameters = parameters or yaml.safe_load(CLEARPATH_CONFIG.read_text())
    config, problems = read_config(parameters)
    assert not [line for level, line in problems if level == "error"], problems
    mounting_row = recording["imu_mounting"]
    mounting = Transform(quaternion_matrix(mounting_row[3:7]), mounting_row[:3])
    odom_frame, child_frame, imu_frame = (str(name) for name in recording["frames"])

    def lookup(target, source, stamp):
        if target == source:
            return Transform()
        return {(config.frames.base_link, imu_frame): mounting,
                (imu_frame, config.frames.base_link): mounting.inverse()}.get((target, source))

    warnings = {}
    estimator = Estimator(lookup, warnings.setdefault, config.frames, config.two_d_mode,
                          config.gravitational_acceleration, config.predict_to_current_time)
    estimator.warnings = warnings
    ekf = estimator.filter
    ekf.process_noise, ekf.sensor_timeout = config.process_noise_covariance, config.sensor_timeout
    sensors = {sensor.kind: sensor for sensor in config.sensors}
    pose_covariance = recording["odometry_pose_covariance"].reshape(6, 6)
    twist_covariance = recording["odometry_twist_covariance"].reshape(6, 6)
    imu_covariances = [recording[f"imu_{name}_covariance"].reshape(3, 3)
                       for name in ("orientation", "angular_velocity", "linear_acceleration")]
    records = []
    for index, row in enumerate(recording["odometry"]):
        records.append((row[0], "odom", index, (
            PoseInput(row[0], odom_frame, row[1:4], row[4:8], pose_covariance.copy()),
            TwistInput(row[0], child_frame, row[8:11], row[11:14], twist_covariance.copy()))))
    for index, row in enumerate(recording["imu"]):
        records.append((row[0], "imu", index, (ImuInput(
            row[0], imu_frame, row[1:5], imu_covariances[0].copy(), row[5:8], imu_covariances[1].copy(), row[8:11],
            imu_covariances[2].copy()),)))
    records.sort(key=lambda record: (record[0], record[1]))
    period = 1.0 / config.frequency
    start = records[0][0]
    ekf.last_measurement_time = start
    next_update, outputs = start + period, []
    for stamp, kind, index, messages in records:
        while next_update <= stamp:
            estimator.integrate(next_update)
            estimator.differentiate(next_update)
            if ekf.initialized:
                outputs.append((next_update, ekf.state.copy()))
            next_update += period
        if corrupt is not None:
            messages = corrupt(kind, index, messages)
        sources = sensors[kind].sources
        if kind == "odom":
            estimator.odometry(*messages, sources["pose"], sources["twist"])
        else:
            estimator.imu(*messages, sources["pose"], sources["twist"], sources["acceleration"])
    estimator.integrate(next_update)
    outputs.append((next_update, ekf.state.copy()))
    return estimator, outputs
