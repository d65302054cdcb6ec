"""Geometry records of a body's visual and collision elements, and small rigid-transform helpers.

Why a module of its own: the world model, the collision layer and the viewer all read these
records, and none of them should depend on how a URDF spells them. Records are frozen; poses are
read-only 4x4 numpy arrays (homogeneous transforms, metres and radians).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from robotspec.arrays import F64
from robotspec.errors import RobotSpecError
from robotspec.model.rotations import quaternion_to_matrix, rpy_to_matrix

#: A rotation or homogeneous transform (3x3 or 4x4 float64).
Matrix = F64


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
    "UNIT_TOL",
    "unit_norm",
]


def frozen_array(values: object, shape: tuple[int, ...] | None = None) -> Matrix:
    """A float64 copy of ``values`` that cannot be written to (records must stay immutable)."""
    arr = np.array(values, dtype=np.float64, copy=True)
    if shape is not None:
        arr = arr.reshape(shape)
    arr.setflags(write=False)
    return arr


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
    layer then reports it instead of skipping it silently. ``problem`` is then why it did not
    resolve (``None``: not tried): render and collisions must tell a mesh outside the allowed
    folders from one that is simply missing, with the URDF line.
    """

    uri: str
    path: str | None
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    problem: RobotSpecError | None = field(default=None, compare=False, repr=False)


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
