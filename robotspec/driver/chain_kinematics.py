"""Forward kinematics and Jacobians of H/P chains (general-robotics-toolbox convention).

Every joint frame is parallel to the base frame at q = 0; ``H[i]`` is joint i's axis and ``P[i]``
the offset from joint i-1 to joint i, all in base coordinates at q = 0; ``P[n]`` reaches the chain
end, then ``flange_pose`` and the tool's TCP transform follow. This is general-robotics-toolbox's
``Robot`` convention (``general_robotics_toolbox.fwdkin``, 0.7.3).

Why written here and not taken from the toolbox: it is a small numpy routine, the toolbox is not a
dependency, and the loop calls it every step (1 kHz), so it works on preallocated arrays and
computes the pose and the Jacobian in one pass.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from robotspec.arrays import F64

__all__ = [
    "HPChain",
]


def _axis_kind(h: tuple[float, ...]) -> tuple[int, float]:
    """``(k, sign)`` when ``h`` is ``sign`` times coordinate axis ``k``, else ``(-1, 1)``."""
    for k in range(3):
        if abs(h[k]) == 1.0 and not any(h[j] for j in range(3) if j != k):
            return k, float(h[k])
    return -1, 1.0


def _skew(v: F64) -> F64:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


class HPChain:
    """One serial chain in H/P form, with a flange transform and an optional tool transform.

    Args:
        h: ``(n, 3)`` unit joint axes.
        p: ``(n + 1, 3)`` link offsets.
        prismatic: ``(n,)`` True for prismatic joints.
        flange_rotation: ``(3, 3)`` flange orientation relative to the end of ``P``.
        flange_position: ``(3,)`` flange offset relative to the end of ``P``.
    """

    def __init__(
        self,
        h: F64,
        p: F64,
        prismatic: Sequence[bool] | None = None,
        flange_rotation: F64 | None = None,
        flange_position: F64 | None = None,
    ) -> None:
        self.h = np.asarray(h, dtype=np.float64).reshape(-1, 3)
        self.p = np.asarray(p, dtype=np.float64).reshape(-1, 3)
        self.n = self.h.shape[0]
        if self.p.shape[0] != self.n + 1:
            raise ValueError(f"P needs {self.n + 1} vectors, got {self.p.shape[0]}")
        self.prismatic = np.zeros(self.n, dtype=bool) if prismatic is None else np.array(prismatic)
        self.flange_r = np.eye(3) if flange_rotation is None else np.asarray(flange_rotation)
        self.flange_p = np.zeros(3) if flange_position is None else np.asarray(flange_position)
        self._k = np.stack([_skew(a) for a in self.h]) if self.n else np.zeros((0, 3, 3))
        self._k2 = np.einsum("nij,njk->nik", self._k, self._k)
        self._rev = ~self.prismatic
        # Plain-float copies for the per-step path (faster than numpy on 3-vectors).
        self._h_list = [tuple(float(x) for x in a) for a in self.h]
        self._p_list = [tuple(float(x) for x in a) for a in self.p]
        self._pris_list = [bool(x) for x in self.prismatic]
        self._flange_r_list = tuple(float(x) for x in self.flange_r.reshape(9))
        self._flange_p_list = tuple(float(x) for x in self.flange_p)
        # Per joint for tcp_state: the coordinate axis (0, 1, 2) and sign when ``H[i]`` is +-x,
        # +-y or +-z (most industrial arms), else -1; and whether ``P[i + 1]`` is zero.
        self._axis_kind: list[tuple[int, float]] = [_axis_kind(a) for a in self._h_list]
        self._p_zero = [not any(a) for a in self._p_list]
        # Preallocated work arrays: the loop calls fk_jacobian every step.
        self._axes = np.zeros((self.n, 3))
        self._origins = np.zeros((self.n, 3))
        self._jac = np.zeros((6, self.n))

    def _joint_rotations(self, q: F64) -> F64:
        s = np.where(self._rev, np.sin(q), 0.0)
        c = np.where(self._rev, 1.0 - np.cos(q), 0.0)
        out: F64 = np.eye(3) + s[:, None, None] * self._k + c[:, None, None] * self._k2
        return out

    def tcp_state(
        self,
        q: Sequence[float],
        qd: Sequence[float] | None,
        tool_rotation: Sequence[float] | None = None,
        tool_position: Sequence[float] | None = None,
    ) -> tuple[tuple[float, ...], tuple[float, float, float], tuple[float, ...]]:
        """TCP rotation (row-major 9-tuple), position and spatial velocity, in plain floats.

        Why a second implementation: the loop needs the pose and ``J(q) qd`` of every chain each
        step; on 3-vectors, Python floats are several times faster than numpy calls. The numpy
        :meth:`fk_jacobian` (same maths) is the one tests compare against.
        """
        r00, r01, r02, r10, r11, r12, r20, r21, r22 = 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0
        px, py, pz = self._p_list[0]
        # The twist accumulates during the walk: with w = sum qd_i a_i, the TCP's linear
        # velocity sum qd_i a_i x (p - o_i) is w x p - sum qd_i a_i x o_i (+ prismatic terms),
        # so no second pass over stored axes and origins is needed.
        wx = wy = wz = cx = cy = cz = lx = ly = lz = 0.0
        cos, sin = math.cos, math.sin
        for i in range(self.n):
            kind, sign = self._axis_kind[i]
            if kind == 2:
                ax, ay, az = sign * r02, sign * r12, sign * r22
            elif kind == 1:
                ax, ay, az = sign * r01, sign * r11, sign * r21
            elif kind == 0:
                ax, ay, az = sign * r00, sign * r10, sign * r20
            else:  # a general axis (rare on industrial arms)
                ax, ay, az = _rotate((r00, r01, r02, r10, r11, r12, r20, r21, r22), self._h_list[i])
            if qd is not None:
                qdi = qd[i]
                if qdi != 0.0:
                    if self._pris_list[i]:
                        lx += qdi * ax
                        ly += qdi * ay
                        lz += qdi * az
                    else:
                        wx += qdi * ax
                        wy += qdi * ay
                        wz += qdi * az
                        cx += qdi * (ay * pz - az * py)
                        cy += qdi * (az * px - ax * pz)
                        cz += qdi * (ax * py - ay * px)
            qi = q[i]
            if self._pris_list[i]:
                px += qi * ax
                py += qi * ay
                pz += qi * az
            elif kind >= 0:
                # Rotation about a coordinate axis: only two columns of R change (a third of
                # the work of the general Rodrigues product below).
                c = cos(qi)
                s_ = sign * sin(qi)
                if kind == 2:  # R Rz: col0' = c col0 + s col1, col1' = c col1 - s col0
                    r00, r01 = c * r00 + s_ * r01, c * r01 - s_ * r00
                    r10, r11 = c * r10 + s_ * r11, c * r11 - s_ * r10
                    r20, r21 = c * r20 + s_ * r21, c * r21 - s_ * r20
                elif kind == 1:  # R Ry: col0' = c col0 - s col2, col2' = c col2 + s col0
                    r00, r02 = c * r00 - s_ * r02, c * r02 + s_ * r00
                    r10, r12 = c * r10 - s_ * r12, c * r12 + s_ * r10
                    r20, r22 = c * r20 - s_ * r22, c * r22 + s_ * r20
                else:  # R Rx: col1' = c col1 + s col2, col2' = c col2 - s col1
                    r01, r02 = c * r01 + s_ * r02, c * r02 - s_ * r01
                    r11, r12 = c * r11 + s_ * r12, c * r12 - s_ * r11
                    r21, r22 = c * r21 + s_ * r22, c * r22 - s_ * r21
            else:
                r00, r01, r02, r10, r11, r12, r20, r21, r22 = _times(
                    (r00, r01, r02, r10, r11, r12, r20, r21, r22),
                    _rodrigues(self._h_list[i], cos(qi), sin(qi)),
                )
            if not self._p_zero[i + 1]:
                bx, by, bz = self._p_list[i + 1]
                px += r00 * bx + r01 * by + r02 * bz
                py += r10 * bx + r11 * by + r12 * bz
                pz += r20 * bx + r21 * by + r22 * bz
        rot, (px, py, pz) = _through_frames(
            (r00, r01, r02, r10, r11, r12, r20, r21, r22),
            (px, py, pz),
            ((self._flange_r_list, self._flange_p_list), (tool_rotation, tool_position)),
        )
        vx = wy * pz - wz * py - cx + lx
        vy = wz * px - wx * pz - cy + ly
        vz = wx * py - wy * px - cz + lz
        return rot, (px, py, pz), (wx, wy, wz, vx, vy, vz)

    def fk(
        self,
        q: F64,
        tool_rotation: F64 | None = None,
        tool_position: F64 | None = None,
    ) -> tuple[F64, F64]:
        """Rotation and position of the flange (or of the tool TCP when given) at ``q``."""
        r, p, _ = self._walk(np.asarray(q, dtype=np.float64), tool_rotation, tool_position, False)
        return r, p

    def fk_jacobian(
        self,
        q: F64,
        tool_rotation: F64 | None = None,
        tool_position: F64 | None = None,
    ) -> tuple[F64, F64, F64]:
        """Pose and ``(6, n)`` Jacobian (angular rows first) at the flange or tool TCP.

        The Jacobian maps joint velocities to the TCP's spatial velocity in the base frame:
        angular velocity, then the linear velocity of the TCP point.
        """
        return self._walk(np.asarray(q, dtype=np.float64), tool_rotation, tool_position, True)

    def _walk(
        self,
        q: F64,
        tool_rotation: F64 | None,
        tool_position: F64 | None,
        with_jacobian: bool,
    ) -> tuple[F64, F64, F64]:
        rj = self._joint_rotations(q)
        r = np.eye(3)
        p = self.p[0].copy()
        axes, origins = self._axes, self._origins
        for i in range(self.n):
            origins[i] = p
            axes[i] = r @ self.h[i]
            if self.prismatic[i]:
                p = p + q[i] * axes[i]
            else:
                r = r @ rj[i]
            p = p + r @ self.p[i + 1]
        p = p + r @ self.flange_p
        r = r @ self.flange_r
        if tool_rotation is not None and tool_position is not None:
            p = p + r @ tool_position
            r = r @ tool_rotation
        jac = self._jac
        if with_jacobian and self.n:
            d = p - origins
            lin = np.empty_like(d)
            lin[:, 0] = axes[:, 1] * d[:, 2] - axes[:, 2] * d[:, 1]
            lin[:, 1] = axes[:, 2] * d[:, 0] - axes[:, 0] * d[:, 2]
            lin[:, 2] = axes[:, 0] * d[:, 1] - axes[:, 1] * d[:, 0]
            jac[:3, :] = np.where(self._rev[None, :], axes.T, 0.0)
            jac[3:, :] = np.where(self._rev[None, :], lin.T, axes.T)
        return r, p, jac.copy() if with_jacobian else jac


_Rot = tuple[float, float, float, float, float, float, float, float, float]


def _times(r: Sequence[float], a: Sequence[float]) -> _Rot:
    """The product of two rotations, each row-major in nine plain floats."""
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = r
    a00, a01, a02, a10, a11, a12, a20, a21, a22 = a
    return (
        r00 * a00 + r01 * a10 + r02 * a20,
        r00 * a01 + r01 * a11 + r02 * a21,
        r00 * a02 + r01 * a12 + r02 * a22,
        r10 * a00 + r11 * a10 + r12 * a20,
        r10 * a01 + r11 * a11 + r12 * a21,
        r10 * a02 + r11 * a12 + r12 * a22,
        r20 * a00 + r21 * a10 + r22 * a20,
        r20 * a01 + r21 * a11 + r22 * a21,
        r20 * a02 + r21 * a12 + r22 * a22,
    )


def _rotate(r: Sequence[float], v: Sequence[float]) -> tuple[float, float, float]:
    """``r v`` for a rotation row-major in nine plain floats and a 3-vector."""
    vx, vy, vz = v
    return (
        r[0] * vx + r[1] * vy + r[2] * vz,
        r[3] * vx + r[4] * vy + r[5] * vz,
        r[6] * vx + r[7] * vy + r[8] * vz,
    )


def _through_frames(
    rot: _Rot,
    pos: tuple[float, float, float],
    frames: tuple[tuple[Sequence[float] | None, Sequence[float] | None], ...],
) -> tuple[_Rot, tuple[float, float, float]]:
    """The pose ``(rot, pos)`` carried through fixed frames: the flange, then the tool if given.

    Why apart from :meth:`HPChain.tcp_state`: it runs once per call, after the per-joint walk,
    and is the one step a reader checks against the flange and tool transforms. A frame whose
    rotation or position is None (no tool) is skipped.
    """
    px, py, pz = pos
    for fr, fp in frames:
        if fr is None or fp is None:
            continue
        bx, by, bz = fp
        px += rot[0] * bx + rot[1] * by + rot[2] * bz
        py += rot[3] * bx + rot[4] * by + rot[5] * bz
        pz += rot[6] * bx + rot[7] * by + rot[8] * bz
        rot = _times(rot, fr)
    return rot, (px, py, pz)


def _rodrigues(h: Sequence[float], c: float, s: float) -> _Rot:
    """rot(h, q) = c I + s [h]x + (1 - c) h h^T, from c = cos q and s = sin q."""
    hx, hy, hz = h
    v = 1.0 - c
    return (
        c + v * hx * hx,
        v * hx * hy - s * hz,
        v * hx * hz + s * hy,
        v * hx * hy + s * hz,
        c + v * hy * hy,
        v * hy * hz - s * hx,
        v * hx * hz - s * hy,
        v * hy * hz + s * hx,
        c + v * hz * hz,
    )
