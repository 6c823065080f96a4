"""Rigid transforms as (position, quaternion xyzw) pairs.

PyBullet's module-level transform helpers are pure functions (they need no physics client), so they are
used here instead of hand-written quaternion maths.
"""
from typing import NamedTuple, Sequence, Tuple

import pybullet


class Pose(NamedTuple):
    position: Tuple[float, float, float]
    orientation: Tuple[float, float, float, float]  # x, y, z, w


IDENTITY = Pose((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def pose_from_xyz_rpy(xyz: Sequence[float], rpy: Sequence[float]) -> Pose:
    """URDF/SDF convention: fixed-axis roll, then pitch, then yaw (R = Rz·Ry·Rx)."""
    return Pose(tuple(float(v) for v in xyz), tuple(pybullet.getQuaternionFromEuler([float(v) for v in rpy])))


def compose(a: Pose, b: Pose) -> Pose:
    """a ∘ b: b expressed in a's parent frame."""
    position, orientation = pybullet.multiplyTransforms(a.position, a.orientation, b.position, b.orientation)
    return Pose(tuple(position), tuple(orientation))


def inverse(a: Pose) -> Pose:
    position, orientation = pybullet.invertTransform(a.position, a.orientation)
    return Pose(tuple(position), tuple(orientation))


def rpy(orientation: Sequence[float]) -> Tuple[float, float, float]:
    return tuple(pybullet.getEulerFromQuaternion(orientation))


def yaw(orientation: Sequence[float]) -> float:
    return rpy(orientation)[2]


def rotation_matrix(orientation: Sequence[float]):
    """3x3 row-major rotation matrix as a nested tuple."""
    m = pybullet.getMatrixFromQuaternion(orientation)
    return (tuple(m[0:3]), tuple(m[3:6]), tuple(m[6:9]))


def rotate(orientation: Sequence[float], vector: Sequence[float]) -> Tuple[float, float, float]:
    """``vector`` rotated by the quaternion ``orientation``."""
    position, _ = pybullet.multiplyTransforms((0.0, 0.0, 0.0), orientation, vector, (0.0, 0.0, 0.0, 1.0))
    return tuple(position)
