"""The ROS messages the plugins publish, filled from the core's values: one place for the field layouts."""
from __future__ import annotations

import functools
from typing import TYPE_CHECKING, Sequence

import numpy as np
from sensor_msgs.msg import CameraInfo, Image, Imu

from . import ros_time

if TYPE_CHECKING:  # the drives use this module too, and need not import the camera's and IMU's modules
    from ..core.cameras.camera import Intrinsics
    from ..core.sensors.imu import ImuReading, ImuReadings


def set_xyz(field, values: Sequence[float]):
    """A Point or Vector3 from (x, y, z)."""
    field.x, field.y, field.z = values


def set_quaternion(field, quaternion: Sequence[float]):
    """A geometry_msgs/Quaternion from (x, y, z, w), PyBullet's order."""
    field.x, field.y, field.z, field.w = quaternion


def set_pose(pose, position: Sequence[float], orientation: Sequence[float]):
    set_xyz(pose.position, position)
    set_quaternion(pose.orientation, orientation)


def diagonal_covariance(variances, size: int) -> list:
    """A row-major ``size`` x ``size`` covariance with ``variances`` on the diagonal (one value: on all of it)."""
    covariance = [0.0] * (size * size)
    covariance[::size + 1] = list(variances) if isinstance(variances, (list, tuple)) else [variances] * size
    return covariance


def imu_message(reading: ImuReading, frame_id: str) -> Imu:
    message = Imu()
    message.header.stamp = ros_time(reading.stamp)
    message.header.frame_id = frame_id
    set_quaternion(message.orientation, reading.orientation)
    set_xyz(message.angular_velocity, reading.angular_velocity)
    set_xyz(message.linear_acceleration, reading.linear_acceleration)
    diagonal = diagonal_covariance(reading.covariance, 3)
    message.orientation_covariance = message.angular_velocity_covariance = diagonal
    message.linear_acceleration_covariance = diagonal
    return message


@functools.lru_cache(maxsize=64)
def _imu_record_template(frame_id: str, covariance: float) -> np.ndarray:
    """One sensor_msgs/Imu record with every field a topic's messages share filled in."""
    frame = frame_id.encode()
    layout = np.dtype([("length", "<u4"), ("seq", "<u4"), ("secs", "<u4"), ("nsecs", "<u4"),
                       ("frame_length", "<u4"), ("frame_id", np.uint8, (len(frame),)),
                       ("orientation", "<f8", (4,)), ("orientation_covariance", "<f8", (9,)),
                       ("angular_velocity", "<f8", (3,)), ("angular_velocity_covariance", "<f8", (9,)),
                       ("linear_acceleration", "<f8", (3,)), ("linear_acceleration_covariance", "<f8", (9,))])
    record = np.zeros(1, layout)
    record["length"] = layout.itemsize - 4
    record["frame_length"] = len(frame)
    record["frame_id"] = np.frombuffer(frame, np.uint8)
    covariance_matrix = diagonal_covariance(covariance, 3)
    for field in ("orientation_covariance", "angular_velocity_covariance", "linear_acceleration_covariance"):
        record[field] = covariance_matrix
    return record


def imu_records(readings: ImuReadings, frame_id: str) -> np.ndarray:
    """sensor_msgs/Imu messages as they go on the wire, one numpy record per reading, each with its length
    prefix; ``LoopPublisher.publish_records`` numbers them (``seq``). genpy would build and serialize a message
    object per reading, which at 1000 readings a sim second costs more than the physics."""
    records = np.repeat(_imu_record_template(frame_id, readings.covariance), len(readings.stamps))
    # ros_time's rounding, for every stamp at once.
    records["secs"], records["nsecs"] = np.divmod(np.rint(readings.stamps * 1e9).astype(np.int64), 1000000000)
    records["orientation"] = readings.orientations
    records["angular_velocity"] = readings.angular_velocities
    records["linear_acceleration"] = readings.linear_accelerations
    return records


def camera_info_message(intrinsics: Intrinsics, frame_id: str) -> CameraInfo:
    info = CameraInfo()
    info.header.frame_id = frame_id
    info.width, info.height = intrinsics.width, intrinsics.height
    info.distortion_model = intrinsics.distortion_model
    info.D = list(intrinsics.distortion)
    info.K, info.R, info.P = intrinsics.K, intrinsics.R, intrinsics.P
    return info


def image_message(frame_id: str, encoding: str, pixels) -> Image:
    """An Image holding ``pixels`` ((H, W, channels) C-contiguous), copied once into bytes."""
    image = Image()
    image.header.frame_id = frame_id
    image.height, image.width = pixels.shape[:2]
    image.encoding = encoding
    image.is_bigendian = 0
    image.step = pixels.strides[0]
    image.data = pixels.tobytes()
    return image
