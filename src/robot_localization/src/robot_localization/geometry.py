"""Rotations as tf2 computes them (Matrix3x3::getRPY and setRPY, Quaternion to matrix), in numpy. Written out
because the filter's measurements must follow tf2's Euler conventions exactly, gimbal-lock branch included, and
the filter core stays free of ROS."""
from dataclasses import dataclass, field

import numpy as np


def quaternion_matrix(quaternion):
    """The rotation of a quaternion (x, y, z, w), normalized first (scaled down before, so that huge
    components do not overflow)."""
    with np.errstate(all="ignore"):
        quaternion = np.asarray(quaternion, dtype=float)
        quaternion = quaternion / np.max(np.abs(quaternion))
        x, y, z, w = quaternion / np.linalg.norm(quaternion)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def rpy_matrix(roll, pitch, yaw):
    """tf2::Matrix3x3::setRPY: yaw about z, then pitch about y, then roll about x (fixed axes x-y-z)."""
    sr, cr, sp, cp, sy, cy = np.sin(roll), np.cos(roll), np.sin(pitch), np.cos(pitch), np.sin(yaw), np.cos(yaw)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def matrix_rpy(rotation):
    """tf2::Matrix3x3::getRPY (its first solution)."""
    if abs(rotation[2, 0]) >= 1.0:
        delta = np.arctan2(rotation[2, 1], rotation[2, 2])
        return delta, (np.pi / 2 if rotation[2, 0] < 0 else -np.pi / 2), 0.0
    pitch = -np.arcsin(rotation[2, 0])
    cp = np.cos(pitch)
    return (np.arctan2(rotation[2, 1] / cp, rotation[2, 2] / cp), pitch,
            np.arctan2(rotation[1, 0] / cp, rotation[0, 0] / cp))


def rpy_quaternion(roll, pitch, yaw):
    """tf2::Quaternion::setRPY, as (x, y, z, w)."""
    sr, cr = np.sin(roll / 2), np.cos(roll / 2)
    sp, cp = np.sin(pitch / 2), np.cos(pitch / 2)
    sy, cy = np.sin(yaw / 2), np.cos(yaw / 2)
    return np.array([sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy,
                     cr * cp * cy + sr * sp * sy])


@dataclass
class Transform:
    """A rigid transform: p_target = rotation @ p_source + translation."""
    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    translation: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __mul__(self, other):
        return Transform(self.rotation @ other.rotation, self.rotation @ other.translation + self.translation)

    def inverse(self):
        return Transform(self.rotation.T, -self.rotation.T @ self.translation)

    def inverse_times(self, other):
        return self.inverse() * other


def block_rotation(rotation):
    """The 6x6 rotation of a pose or twist covariance: the 3D rotation on both diagonal blocks."""
    rotation6 = np.eye(6)
    rotation6[:3, :3] = rotation
    rotation6[3:, 3:] = rotation
    return rotation6


def update_mask(rotation, update):
    """Which members a rotated measurement touches: upstream rotates the diagonal mask and keeps the rows whose
    length is at least 1e-6."""
    return (rotation * rotation) @ np.asarray(update, dtype=float) >= 1e-12


def cross(a, b):
    """The cross product of two 3-vectors (numpy's is slow for one pair)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])
