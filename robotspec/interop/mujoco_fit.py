"""Two models of one robot whose bodies are framed differently: the constant offsets between them.

Why: a converted model keeps the kinematics but not the frames. Menagerie re-frames bodies, a
robosuite model rounds a quaternion, MuJoCo's URDF reader fuses fixed links into their parent.
Two bodies are the same rigid body when, at every configuration, their poses relative to the
matched root differ by one constant transform on each side:

    X_theirs(b, q) = inv(C_root) @ X_ours(b, q) @ C_b

``C_b`` is read at the first configuration and checked at the others. ``C_root`` (how their
root body is framed against ours) is the identity for nearly every model; when it is not, it is
solved from the bodies' motions (``R_ours @ C = C @ R_theirs`` for every displacement: a linear
null space), so a re-framed root is accepted, not refused. Pure numpy, no MuJoCo.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from robotspec.arrays import F64

__all__ = ["FrameFit", "TOLERANCE", "fit_frames", "inverse", "pose_error"]

#: How far two poses may be apart and still be the same (metres, and radians).
TOLERANCE = 1e-6


def inverse(pose: F64) -> F64:
    """The inverse of a rigid 4x4 transform."""
    out = np.eye(4)
    out[:3, :3] = pose[:3, :3].T
    out[:3, 3] = -pose[:3, :3].T @ pose[:3, 3]
    return out


def pose_error(a: F64, b: F64) -> float:
    """The larger of the distance (m) and the rotation angle (rad) between two poses."""
    dist = float(np.linalg.norm(a[:3, 3] - b[:3, 3]))
    cos = (float(np.trace(a[:3, :3].T @ b[:3, :3])) - 1.0) / 2.0
    angle = float(np.arccos(np.clip(cos, -1.0, 1.0)))
    if angle < 1e-4:  # arccos loses digits near 0: the skew part holds them
        r = a[:3, :3].T @ b[:3, :3]
        angle = float(np.linalg.norm([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]))
        angle /= 2.0
    return max(dist, angle)


@dataclass(frozen=True)
class FrameFit:
    """How their frames sit on ours: the root's offset, each body's, and the worst misfit.

    ``errors`` holds, per body key, the largest :func:`pose_error` over the configurations
    (0 for a body that fits exactly).
    """

    root: F64
    offsets: Mapping[str, F64]
    errors: Mapping[str, float]

    @property
    def worst(self) -> float:
        """The largest misfit of any body."""
        return max(self.errors.values(), default=0.0)

    def failing(self, tolerance: float = TOLERANCE) -> list[str]:
        """The bodies that do not fit, worst first."""
        bad = [k for k, e in self.errors.items() if e > tolerance]
        return sorted(bad, key=lambda k: -self.errors[k])


def _solve_root(ours: Mapping[str, Sequence[F64]], theirs: Mapping[str, Sequence[F64]]) -> F64:
    """``C_root`` from the displacements of every body (least squares; identity if degenerate)."""
    rows: list[F64] = []
    samples: list[tuple[F64, F64]] = []
    for key, xs in ours.items():
        for k in range(1, len(xs)):
            mo = xs[k] @ inverse(xs[0])
            mt = theirs[key][k] @ inverse(theirs[key][0])
            # R_o X - X R_t = 0, row-major vec: (R_o (x) I - I (x) R_t^T) vec(X) = 0
            rows.append(np.kron(mo[:3, :3], np.eye(3)) - np.kron(np.eye(3), mt[:3, :3].T))
            samples.append((mo, mt))
    if not rows:
        return np.eye(4)
    _, s, vt = np.linalg.svd(np.vstack(rows))
    if len(s) < 9 or s[-2] < 1e-6:  # the commutant is more than the scalars: underdetermined
        return np.eye(4)
    x = vt[-1].reshape(3, 3)
    if np.linalg.det(x) < 0.0:
        x = -x
    u, _, wt = np.linalg.svd(x)
    rot = u @ wt
    # R_o p_c + p_o = R_c p_t + p_c  ->  (R_o - I) p_c = R_c p_t - p_o
    a = np.vstack([mo[:3, :3] - np.eye(3) for mo, _ in samples])
    b = np.concatenate([rot @ mt[:3, 3] - mo[:3, 3] for mo, mt in samples])
    pc = np.linalg.lstsq(a, b, rcond=None)[0]
    out = np.eye(4)
    out[:3, :3] = rot
    out[:3, 3] = pc
    return out


def _fit_with(
    root: F64, ours: Mapping[str, Sequence[F64]], theirs: Mapping[str, Sequence[F64]]
) -> FrameFit:
    back = inverse(root)
    offsets: dict[str, F64] = {}
    errors: dict[str, float] = {}
    for key, xs in ours.items():
        c = inverse(xs[0]) @ root @ theirs[key][0]
        offsets[key] = c
        errors[key] = max(
            (pose_error(back @ xs[k] @ c, theirs[key][k]) for k in range(1, len(xs))),
            default=0.0,
        )
    return FrameFit(root, offsets, errors)


def fit_frames(
    ours: Mapping[str, Sequence[F64]],
    theirs: Mapping[str, Sequence[F64]],
    tolerance: float = TOLERANCE,
) -> FrameFit:
    """The offsets that make ``theirs`` (poses relative to their root) equal ``ours``.

    Both map a body key to its pose relative to the matched root at the same configurations,
    the first of which defines the offsets. The identity root offset is tried first, then the
    solved one; the one with fewer misfit bodies (then the smaller misfit) is returned, so a
    wrong joint shows as the bodies below it (the caller judges against ``tolerance``).
    """
    first = _fit_with(np.eye(4), ours, theirs)
    if first.worst <= tolerance:
        return first
    second = _fit_with(_solve_root(ours, theirs), ours, theirs)
    fails = (
        (len(second.failing(tolerance)), second.worst),
        (len(first.failing(tolerance)), first.worst),
    )
    better = fails[0] < fails[1]
    return second if better else first
