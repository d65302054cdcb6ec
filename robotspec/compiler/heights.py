"""The range of heights a frame can reach over the limits of the joints that move it.

Why this module: a camera's ``minimal_height``/``maximal_height`` are claims about forward
kinematics, so the compiler checks them with forward kinematics. Heights are the z coordinate of
the frame's origin in the robot's root frame (``base_footprint``: height above the floor).

Two methods, and the result says which one ran:

- ``exact``: every moving joint above the frame, except at most the last one, is a prismatic joint
  along the vertical or a revolute joint about the vertical (a lift, a pan). Those keep every axis
  below them as vertical as it was, so the height is a sum of independent terms: linear in each
  lift, constant in each pan, and ``c + A cos v + B sin v`` in the last joint (a tilt). The
  extremes of each term over its limits are found in closed form, so the bounds are exact and each
  comes with the joint values that reach it.
- ``sampled``: anything else (an arm carrying a hand camera). Seeded random configurations plus
  the corners of the limit box, the best ones refined joint by joint on a dense grid. Every bound
  is reached by a configuration it reports, so the true range contains the sampled one; how much
  wider it is cannot be proved.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from robotspec.arrays import F64
from robotspec.model.world import Body, Connection, ConnectionType, World

__all__ = ["HeightRange", "chain_fk_batch", "height_range", "leader_bounds"]


#: |z component| of a unit axis above which the axis counts as vertical.
_VERTICAL = 1.0 - 1e-9
_SAMPLES = 2048
_GRID = 121
_SWEEPS = 4
_STARTS = 3
_TIE_DECIMALS = 9  # heights equal to a nanometre are one height (see _sampled)
_TIE = 1e-9


@dataclass(frozen=True)
class HeightRange:
    """Lowest and highest height of a frame, how they were found, and where they are reached.

    ``joints`` are the joints whose values change the height (leaders, in chain order);
    ``lowest_at``/``highest_at`` give their values at the two extremes.
    """

    body: str
    low: float
    high: float
    method: str  # "exact", "sampled" or "fixed"
    joints: tuple[str, ...]
    lowest_at: Mapping[str, float]
    highest_at: Mapping[str, float]
    samples: int = 0


def leader_bounds(world: World, dof: int) -> tuple[float, float] | None:
    """Limits of one DOF for FK sweeps: a continuous joint turns once; unbounded slides: None."""
    d = world.degrees_of_freedom[dof]
    if d.is_bounded:
        return d.lower, d.upper
    conn = world.get_connection_by_name(d.connection)
    if conn.type in (ConnectionType.REVOLUTE, ConnectionType.CONTINUOUS):
        return max(d.lower, -math.pi), min(d.upper, math.pi)
    return None


def _motion(c: Connection, v: F64) -> F64:
    """The joint's motion (N, 4, 4) for joint values ``v`` (N,) (after the mimic map)."""
    n = v.shape[0]
    m = np.broadcast_to(np.eye(4), (n, 4, 4)).copy()
    axis = np.asarray(c.axis, dtype=np.float64)
    if c.type is ConnectionType.PRISMATIC:
        m[:, :3, 3] = v[:, None] * axis
        return m
    k = np.array(
        [[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]],
    )
    s = np.sin(v)[:, None, None]
    c1 = (1.0 - np.cos(v))[:, None, None]
    m[:, :3, :3] = np.eye(3) + s * k + c1 * (k @ k)
    return m


def chain_fk_batch(connections: Sequence[Connection], q: F64) -> F64:
    """``root_T_tip`` (N, 4, 4) of a chain of fixed and 1-DOF joints for configurations (N, D)."""
    n = q.shape[0]
    t = np.broadcast_to(np.eye(4), (n, 4, 4)).copy()
    for c in connections:
        t = t @ c.origin
        if c.is_fixed:
            continue
        v = q[:, c.dofs[0]]
        if c.mimic is not None:
            v = v * c.mimic.multiplier + c.mimic.offset
        t = t @ _motion(c, v)
    return t


def height_range(
    world: World, root: Body, body: Body, base: F64, *, seed: int = 0
) -> HeightRange | None:
    """The heights ``body`` reaches above ``root`` over the limits of the joints between them.

    ``base`` is the configuration for every other joint (they do not move ``body`` relative to
    ``root``). None when the chain has a multi-DOF joint or an unbounded slide (no range).
    """
    conns = world.compute_chain_of_connections(root, body)
    moving = [c for c in conns if not c.is_fixed]
    if any(c.type.dof_count != 1 for c in moving):
        return None
    leaders = list(dict.fromkeys(c.dofs[0] for c in moving))
    bounds: dict[int, tuple[float, float]] = {}
    for d in leaders:
        b = leader_bounds(world, d)
        if b is None:
            return None
        bounds[d] = b
    leaders = [d for d in leaders if bounds[d][1] > bounds[d][0]]  # a joint locked by its limits
    q0 = np.array(base, dtype=np.float64)
    for d, (lo, hi) in bounds.items():
        q0[d] = min(max(q0[d], lo), hi)
    z0 = float(chain_fk_batch(conns, q0[None])[0, 2, 3])
    if not leaders:
        return HeightRange(body.name, z0, z0, "fixed", (), {}, {})
    exact = _exact(world, conns, moving, bounds, q0)
    if exact is not None:
        return HeightRange(body.name, *exact)
    return _sampled(world, body, conns, leaders, bounds, q0, seed)


def _dof_name(world: World, d: int) -> str:
    return world.degrees_of_freedom[d].connection


def _exact(
    world: World,
    conns: Sequence[Connection],
    moving: Sequence[Connection],
    bounds: Mapping[int, tuple[float, float]],
    q0: F64,
) -> tuple[float, float, str, tuple[str, ...], dict[str, float], dict[str, float]] | None:
    """Closed-form bounds when the structure allows (see the module docstring), else None."""
    # Axis of every moving joint in the root frame at q0 (verticality is kept by lifts and pans).
    frames: dict[int, F64] = {}
    t = np.eye(4)
    for c in conns:
        t = t @ c.origin
        if not c.is_fixed:
            frames[c.index] = t[:3, :3] @ np.asarray(c.axis)
            v = q0[c.dofs[0]] * (c.mimic.multiplier if c.mimic else 1.0) + (
                c.mimic.offset if c.mimic else 0.0
            )
            t = t @ _motion(c, np.array([v]))[0]
    linear: dict[int, float] = {}
    last: Connection | None = None
    for i, c in enumerate(moving):
        vertical = abs(float(frames[c.index][2])) > _VERTICAL
        mult = c.mimic.multiplier if c.mimic else 1.0
        if vertical and c.type is ConnectionType.PRISMATIC:
            d = c.dofs[0]
            linear[d] = linear.get(d, 0.0) + float(frames[c.index][2]) * mult
        elif vertical:
            continue  # a pan: the height below it does not depend on it
        elif i == len(moving) - 1:
            last = c
        else:
            return None
    if last is not None and last.dofs[0] in linear:
        return None  # one leader drives a lift and the tilt: not separable
    low = high = float(chain_fk_batch(conns, q0[None])[0, 2, 3])
    low_at: dict[str, float] = {}
    high_at: dict[str, float] = {}
    for d, coef in linear.items():
        lo, hi = bounds[d]
        here = q0[d]
        at_lo, at_hi = coef * (lo - here), coef * (hi - here)
        name = _dof_name(world, d)
        if at_lo <= at_hi:
            low, high = low + at_lo, high + at_hi
            low_at[name], high_at[name] = lo, hi
        else:
            low, high = low + at_hi, high + at_lo
            low_at[name], high_at[name] = hi, lo
    if last is not None:
        d = last.dofs[0]
        lo, hi = bounds[d]
        values = _tilt_extremes(conns, d, lo, hi, q0, last)
        zs = _heights(conns, d, values, q0)
        z_here = float(_heights(conns, d, np.array([q0[d]]), q0)[0])
        i_lo, i_hi = int(np.argmin(zs)), int(np.argmax(zs))
        name = _dof_name(world, d)
        low += float(zs[i_lo]) - z_here
        high += float(zs[i_hi]) - z_here
        low_at[name], high_at[name] = float(values[i_lo]), float(values[i_hi])
    moved = [d for d, coef in linear.items() if abs(coef) > 1e-12]
    if last is not None:
        moved.append(last.dofs[0])
    joints = tuple(_dof_name(world, d) for d in moved)
    return low, high, "exact", joints, low_at, high_at


def _heights(conns: Sequence[Connection], d: int, values: F64, q0: F64) -> F64:
    q = np.repeat(q0[None], len(values), axis=0)
    q[:, d] = values
    z: F64 = chain_fk_batch(conns, q)[:, 2, 3]
    return z


def _tilt_extremes(
    conns: Sequence[Connection], d: int, lo: float, hi: float, q0: F64, c: Connection
) -> F64:
    """Candidate values of the last joint's leader: its limits and the sinusoid's extremes."""
    cands = [lo, hi]
    if c.type is not ConnectionType.PRISMATIC:
        mult = c.mimic.multiplier if c.mimic else 1.0
        off = c.mimic.offset if c.mimic else 0.0
        # z(v) = k + A cos v + B sin v, v the joint's own angle: three values determine it.
        vs = np.array([0.0, math.pi / 2.0, math.pi])
        zs = _heights(conns, d, (vs - off) / mult, q0)
        a = (zs[0] - zs[2]) / 2.0
        b = zs[1] - (zs[0] + zs[2]) / 2.0
        phase = math.atan2(float(b), float(a))
        v_lo, v_hi = sorted((lo * mult + off, hi * mult + off))
        for base_v in (phase, phase + math.pi):
            k0 = math.ceil((v_lo - base_v) / (2.0 * math.pi))
            v = base_v + 2.0 * math.pi * k0
            while v <= v_hi + 1e-12:
                cands.append((v - off) / mult)
                v += 2.0 * math.pi
    return np.array(cands, dtype=np.float64)


def _sampled(
    world: World,
    body: Body,
    conns: Sequence[Connection],
    leaders: Sequence[int],
    bounds: Mapping[int, tuple[float, float]],
    q0: F64,
    seed: int,
) -> HeightRange:
    """Seeded samples and limit corners, the best refined coordinate by coordinate."""
    rng = np.random.default_rng(seed)
    lo = np.array([bounds[d][0] for d in leaders])
    hi = np.array([bounds[d][1] for d in leaders])
    idx = np.array(leaders, dtype=np.int64)
    pts = lo + (hi - lo) * rng.random((_SAMPLES, len(leaders)))
    if len(leaders) <= 8:
        corners = np.array(np.meshgrid(*[[a, b] for a, b in zip(lo, hi, strict=True)]))
        pts = np.vstack([pts, corners.reshape(len(leaders), -1).T])
    q = np.repeat(q0[None], len(pts), axis=0)
    q[:, idx] = pts
    z = chain_fk_batch(conns, q)[:, 2, 3]
    best: dict[str, tuple[float, F64]] = {}
    for sign, key in ((1.0, "low"), (-1.0, "high")):
        # Heights equal to a nanometre are ties (a joint that does not move the body gives
        # many): rounded and sorted stably, the witness does not hang on the last bit of BLAS.
        order = np.argsort(np.round(sign * z, _TIE_DECIMALS), kind="stable")[:_STARTS]
        found: tuple[float, F64] | None = None
        for i in order.tolist():
            x = q[i].copy()
            val = float(z[i])
            for _ in range(_SWEEPS):
                improved = False
                for j, d in enumerate(leaders):
                    grid = np.linspace(lo[j], hi[j], _GRID)
                    trial = np.repeat(x[None], _GRID, axis=0)
                    trial[:, d] = grid
                    zz = chain_fk_batch(conns, trial)[:, 2, 3]
                    k = int(np.argmin(np.round(sign * zz, _TIE_DECIMALS)))
                    if sign * float(zz[k]) < sign * val - _TIE:
                        val, x = float(zz[k]), trial[k]
                        improved = True
                if not improved:
                    break
            if found is None or sign * val < sign * found[0] - _TIE:
                found = (val, x)
        assert found is not None
        best[key] = found
    names = tuple(_dof_name(world, d) for d in leaders)
    low_val, low_q = best["low"]
    high_val, high_q = best["high"]
    return HeightRange(
        body.name,
        low_val,
        high_val,
        "sampled",
        names,
        {n: float(low_q[d]) for n, d in zip(names, leaders, strict=True)},
        {n: float(high_q[d]) for n, d in zip(names, leaders, strict=True)},
        samples=len(pts),
    )
