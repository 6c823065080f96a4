"""The ROS messages the plugins publish, filled from the core's values: one place for the field layouts."""
from typing import Sequence

from sensor_msgs.msg import CameraInfo, Image, Imu

from ..core.camera import Intrinsics
from ..core.imu import ImuReading
from . import ros_time


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
