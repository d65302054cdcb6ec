"""All rotation maths, in one place: roll/pitch/yaw, quaternions in both orders, matrices.

Why one module (mink's ``lie/``): URDF speaks roll/pitch/yaw, ROS and specs write quaternions as
``(x, y, z, w)``, Robot Raconteur as ``(w, x, y, z)``. Each conversion is written once here, so
the two orders can never drift apart; the driver's hot path uses the tuple forms (no numpy).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from robotspec.arrays import F64

#: A rotation or homogeneous transform (3x3 or 4x4 float64).
Matrix = F64


__all__ = [
    "matrix_to_quat_wxyz",
    "matrix_to_quat_wxyz_tuple",
    "matrix_to_rpy",
    "quat_wxyz_to_matrix",
    "quaternion_to_matrix",
    "rpy_to_matrix",
]


def rpy_to_matrix(roll: float, pitch: float, yaw: float) -> Matrix:
    """URDF's fixed-axis roll/pitch/yaw: R = Rz(yaw) @ Ry(pitch) @ Rx(roll)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def matrix_to_rpy(r: Matrix) -> tuple[float, float, float]:
    """URDF roll/pitch/yaw of a rotation matrix (the inverse of :func:`rpy_to_matrix`).

    At pitch +-90 degrees roll and yaw are not separable; roll is set to 0 there and yaw takes
    the whole rotation about z, which gives the same matrix back.
    """
    cp = math.hypot(float(r[0, 0]), float(r[1, 0]))
    pitch = math.atan2(-float(r[2, 0]), cp)  # atan2, not asin: exact near +-90 degrees too
    if cp > 1e-12:
        roll = math.atan2(float(r[2, 1]), float(r[2, 2]))
        yaw = math.atan2(float(r[1, 0]), float(r[0, 0]))
    else:
        roll = 0.0
        yaw = math.atan2(-float(r[0, 1]), float(r[1, 1]))
    return roll, pitch, yaw


def quaternion_to_matrix(x: float, y: float, z: float, w: float) -> Matrix:
    """Rotation matrix of a unit quaternion given as (x, y, z, w), the ROS order."""
    n = math.sqrt(x * x + y * y + z * z + w * w)
    if n == 0.0:
        raise ValueError("zero quaternion")
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def quat_wxyz_to_matrix(q: Sequence[float] | Matrix) -> Matrix:
    """Rotation matrix of a quaternion ``(w, x, y, z)``, Robot Raconteur's order.

    Normalised first; the zero quaternion gives the identity, as a driver reading an unset pose
    needs.
    """
    w, x, y, z = (float(v) for v in q)
    if w == 0.0 and x == 0.0 and y == 0.0 and z == 0.0:
        return np.eye(3)
    return quaternion_to_matrix(x, y, z, w)


def matrix_to_quat_wxyz_tuple(r: Sequence[float]) -> tuple[float, float, float, float]:
    """Unit quaternion ``(w, x, y, z)``, w >= 0, of a row-major 9-tuple rotation.

    Shepperd's method without numpy: the driver calls it every step.
    """
    m00, m01, m02, m10, m11, m12, m20, m21, m22 = r
    tr = m00 + m11 + m22
    if tr > 0.0:
        s = math.sqrt(tr + 1.0) * 2.0
        w, x, y, z = 0.25 * s, (m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s
    elif m00 > m11 and m00 > m22:
        s = math.sqrt(1.0 + m00 - m11 - m22) * 2.0
        w, x, y, z = (m21 - m12) / s, 0.25 * s, (m01 + m10) / s, (m02 + m20) / s
    elif m11 > m22:
        s = math.sqrt(1.0 + m11 - m00 - m22) * 2.0
        w, x, y, z = (m02 - m20) / s, (m01 + m10) / s, 0.25 * s, (m12 + m21) / s
    else:
        s = math.sqrt(1.0 + m22 - m00 - m11) * 2.0
        w, x, y, z = (m10 - m01) / s, (m02 + m20) / s, (m12 + m21) / s, 0.25 * s
    n = math.sqrt(w * w + x * x + y * y + z * z)
    if w < 0.0:
        n = -n
    return (w / n, x / n, y / n, z / n)


def matrix_to_quat_wxyz(r: Matrix) -> Matrix:
    """Unit quaternion ``(w, x, y, z)``, w >= 0, of a 3x3 rotation matrix, as an array."""
    flat = np.asarray(r, dtype=np.float64)[:3, :3].reshape(9)
    return np.array(matrix_to_quat_wxyz_tuple(tuple(float(v) for v in flat)))
