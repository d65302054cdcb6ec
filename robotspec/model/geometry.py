"""Geometry records of a body's visual and collision elements, and small rigid-transform helpers.

Why a module of its own: the world model, the collision layer and the viewer all read these
records, and none of them should depend on how a URDF spells them. Records are frozen; poses are
read-only 4x4 numpy arrays (homogeneous transforms, metres and radians).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "Box",
    "Capsule",
    "Cylinder",
    "GeometryShape",
    "Mesh",
    "Shape",
    "Sphere",
    "frozen_array",
    "pose_from_xyz_quaternion",
    "pose_from_xyz_rpy",
    "matrix_to_rpy",
    "quaternion_to_matrix",
    "rpy_to_matrix",
    "UNIT_TOL",
    "unit_norm",
]

Matrix = NDArray[np.float64]


def frozen_array(values: object, shape: tuple[int, ...] | None = None) -> Matrix:
    """A float64 copy of ``values`` that cannot be written to (records must stay immutable)."""
    arr = np.array(values, dtype=np.float64, copy=True)
    if shape is not None:
        arr = arr.reshape(shape)
    arr.setflags(write=False)
    return arr


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


def pose_from_xyz_rpy(xyz: tuple[float, float, float], rpy: tuple[float, float, float]) -> Matrix:
    """A read-only 4x4 transform from a translation and URDF roll/pitch/yaw."""
    t = np.eye(4)
    t[:3, :3] = rpy_to_matrix(*rpy)
    t[:3, 3] = xyz
    t.setflags(write=False)
    return t


def pose_from_xyz_quaternion(
    xyz: tuple[float, float, float], quaternion: tuple[float, float, float, float]
) -> Matrix:
    """A read-only 4x4 transform from a translation and an (x, y, z, w) quaternion."""
    t = np.eye(4)
    t[:3, :3] = quaternion_to_matrix(*quaternion)
    t[:3, 3] = xyz
    t.setflags(write=False)
    return t


@dataclass(frozen=True)
class Box:
    """An axis-aligned box centred on its frame; ``size`` is the full edge lengths (m)."""

    size: tuple[float, float, float]


@dataclass(frozen=True)
class Cylinder:
    """A cylinder along its frame's z axis, centred on the frame (m)."""

    radius: float
    length: float


@dataclass(frozen=True)
class Sphere:
    """A sphere centred on its frame (m)."""

    radius: float


@dataclass(frozen=True)
class Capsule:
    """A capsule along z: a cylinder of ``length`` with hemispherical caps (m)."""

    radius: float
    length: float


@dataclass(frozen=True)
class Mesh:
    """A mesh file as written in the description and where it resolved to.

    ``path`` is ``None`` when the description was loaded without resolving meshes; the collision
    layer then reports it instead of skipping it silently.
    """

    uri: str
    path: str | None
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)


GeometryShape = Box | Cylinder | Sphere | Capsule | Mesh


@dataclass(frozen=True)
class Shape:
    """One visual or collision element of a body: a geometry at a pose in the body frame."""

    geometry: GeometryShape
    origin: Matrix = field(compare=False, repr=False)
    name: str | None = None
    line: int | None = None
    rgba: tuple[float, float, float, float] | None = None


UNIT_TOL = 1e-3
"""How far from 1 a spec's unit vector or quaternion may be (specs are typed by hand)."""


def unit_norm(v: tuple[float, ...]) -> float:
    """Euclidean norm of a spec's vector or quaternion (tuples, not arrays, in specs)."""
    return math.sqrt(sum(x * x for x in v))
