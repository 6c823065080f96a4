"""Rigid transforms as (position, quaternion xyzw) pairs.

PyBullet's module-level transform helpers are pure functions (they need no physics client), so they are
used here instead of hand-written quaternion maths. For arrays of poses (a step recording) they would cost a
call per row; the array forms at the end are written out in numpy instead, as scipy's Rotation would cost the
simulator half a second of start-up to import.
"""
from typing import NamedTuple, Sequence, Tuple

import numpy as np
import pybullet


class Pose(NamedTuple):
    position: Tuple[float, float, float]
    orientation: Tuple[float, float, float, float]  # x, y, z, w


Vector = Tuple[float, float, float]
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


# The array forms work on a batch of a few rows, where numpy's cost per call outweighs its arithmetic; so each
# is one matrix product of the row-wise outer products (a bilinear form as a matrix), not a dozen array ops.
def _product(a, b):
    """The Hamilton product a ⊗ b of xyzw quaternions, written out."""
    (ax, ay, az, aw), (bx, by, bz, bw) = a, b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def _rotation(a, b):
    """The rotation matrix of a unit quaternion q, row-major, as the bilinear form (q, q) it is: each entry
    written homogeneous (1 = x² + y² + z² + w²)."""
    (x, y, z, w), (bx, by, bz, bw) = a, b
    return (w * bw + x * bx - y * by - z * bz, 2 * (x * by - z * bw), 2 * (x * bz + y * bw),
            2 * (x * by + z * bw), w * bw - x * bx + y * by - z * bz, 2 * (y * bz - x * bw),
            2 * (x * bz - y * bw), 2 * (y * bz + x * bw), w * bw - x * bx - y * by + z * bz)


def _cross(a, b):
    (ax, ay, az), (bx, by, bz) = a, b
    return (ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx)


def _bilinear_matrix(form, size: int) -> np.ndarray:
    """M with form(a, b) == outer(a, b).ravel() @ M, for a form bilinear in two vectors of ``size``."""
    basis = np.eye(size)
    return np.array([form(basis[i], basis[j]) for i in range(size) for j in range(size)])


_PRODUCT = _bilinear_matrix(_product, 4)
_ROTATION = _bilinear_matrix(_rotation, 4)
_CROSS = _bilinear_matrix(_cross, 3)


def _outer_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    outer = a[..., :, None] * b[..., None, :]
    return outer.reshape(outer.shape[:-2] + (-1,))


def quaternion_products(a, b) -> np.ndarray:
    """Row-wise a ⊗ b of (N, 4) or (4,) xyzw quaternions: the rotation b, then a."""
    return _outer_rows(np.asarray(a, dtype=float), np.asarray(b, dtype=float)) @ _PRODUCT


def cross_products(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise a × b of (N, 3) arrays (numpy.cross costs four times as much on a few rows)."""
    return _outer_rows(a, b) @ _CROSS


def rotation_matrices(orientations) -> np.ndarray:
    """(N, 3, 3) rotation matrices of (N, 4) unit xyzw quaternions."""
    orientations = np.asarray(orientations, dtype=float)
    return (_outer_rows(orientations, orientations) @ _ROTATION).reshape(orientations.shape[:-1] + (3, 3))
