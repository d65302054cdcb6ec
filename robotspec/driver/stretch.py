"""Slowing a trajectory just enough to stay within the joint velocity and acceleration limits.

A trajectory's curve is a cubic Hermite per segment (positions and velocities at both waypoints).
Its acceleration is linear in time within a segment, so the largest is at one of the two ends,
exactly; its velocity is quadratic, so the largest is at an end or at the one vertex. Whether a
segment is within the limits is therefore computed, not sampled.

**How a segment is slowed.** Stretching a segment's duration by ``k`` while dividing the velocities
at both its waypoints by ``k`` is a pure time scaling: the same path, velocities ÷ ``k``,
accelerations ÷ ``k²``. But a waypoint's velocity is shared by the two segments that meet there:
dividing it by one segment's factor and not by its neighbour's would break the curve's C1
continuity (a velocity jump, an unbounded acceleration). So the unknowns are one *speed scale*
``σ_j`` in (0, 1] per waypoint, not one factor per segment:

* waypoint ``j`` is passed at ``σ_j`` times its planned velocity, on both sides (the curve stays
  C1, and the velocities at waypoints are the planner's, scaled);
* the segment from ``j`` to ``j + 1`` lasts ``2 h / (σ_j + σ_{j+1})`` (its planned duration ``h``
  over its mean speed scale): when both ends share ``σ`` that is exactly the time scaling by
  ``k = 1 / σ``; when they differ the segment ramps the speed between them, and its accelerations
  are checked exactly like every other segment's.

Each over-limit segment first gets the scale that a pure time scaling needs,
``σ = 1 / sqrt(max(a / a_max, (v / v_max)²))``, at both its waypoints. Where neighbouring scales
then differ too much (a dense trajectory cannot change speed within one 10 ms segment), the
faster waypoint is slowed, by bisection, just enough for the ramp between them to be within the
limits (to :data:`_SLACK`); that may spread the slowing over the neighbouring segments, one more
each round, until every segment is within the limits. Each round evaluates only the segments
beside a waypoint the last round changed, all at once (numpy). The result: only the segments
that need it, and the ramps into and out of them, are slowed. Should that not settle within
:data:`MAX_ROUNDS` rounds, the whole trajectory is slowed by the one factor its worst segment
needs (a pure time scaling, within the limits by construction). Either way the slowing is
reported (:class:`Stretch`), never silent, and a trajectory is never refused for it.

A slowed segment may also not leave the joint position limits (a ramp bends the curve a little);
the curve the client gave may not either (:func:`time_scale` refuses one that does by more than
:data:`POSITION_TOLERANCE`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from robotspec.arrays import F64
from robotspec.driver.commands import JointLimitArrays
from robotspec.driver.errors import InvalidArgumentError

__all__ = [
    "LIMIT_TOLERANCE",
    "MAX_ROUNDS",
    "POSITION_TOLERANCE",
    "Stretch",
    "Timing",
    "time_scale",
]

#: A segment is within the limits when its largest acceleration (and velocity) is at most this
#: much (relative) above the limit: round-off, not motion.
LIMIT_TOLERANCE = 1e-9
#: How far (rad or m) the curve through the client's velocities may pass a joint limit between
#: waypoints before the trajectory is refused. Within it, the command guard's clamp is harmless.
POSITION_TOLERANCE = 1e-6
#: Rounds of ramp-spreading before falling back to one factor for the whole trajectory.
MAX_ROUNDS = 60
#: Bisection steps for a waypoint's speed scale (within 2**-12 of the bracket).
_BISECTIONS = 12
#: The pure time scaling aims this much below the limit, so it is within it after round-off.
_MARGIN = 1e-9
#: A slowed waypoint leaves its ramp this much (relative) below the limit. Why: then the small
#: changes its neighbours make in later rounds do not push it back over; it saves most rounds, for
#: at most a thousandth of acceleration left unused on a ramp.
_SLACK = 1e-3


@dataclass(frozen=True)
class Stretch:
    """How a trajectory was slowed to stay within the joint limits.

    Attributes:
        factor: the largest segment stretch, its duration over the planned one (> 1).
        segments: how many segments were stretched (of ``segment_count``).
        segment_count: the trajectory's segments (waypoints - 1).
        first_segment: the first stretched segment (it starts at this waypoint index).
        last_segment: the last stretched segment.
        planned_duration: seconds as given (after the speed ratio).
        duration: seconds as it will run.
        joint: the joint (index) whose limit demanded the most.
        limit: which of its limits: ``"acceleration"`` or ``"velocity"``.
    """

    factor: float
    segments: int
    segment_count: int
    first_segment: int
    last_segment: int
    planned_duration: float
    duration: float
    joint: int
    limit: str

    def describe(self, joint_names: Sequence[str] = ()) -> str:
        """One line for people: what was slowed, by how much, and why."""
        name = joint_names[self.joint] if self.joint < len(joint_names) else str(self.joint)
        where = (
            f"segment {self.first_segment}"
            if self.segments == 1
            else f"from segment {self.first_segment} to {self.last_segment}"
        )
        return (
            f"slowed to stay within the {self.limit} limit of joint '{name}': {self.segments} of "
            f"{self.segment_count} segments stretched ({where}), up to {self.factor:.3g} x; "
            f"runs {self.duration:.3f} s instead of {self.planned_duration:.3f} s"
        )


@dataclass(frozen=True)
class Timing:
    """The curve to run: waypoint times and velocities, and how it was stretched (if it was)."""

    times: F64
    velocities: F64
    #: Per segment, its duration over the planned one (None when nothing was stretched).
    segment_stretch: F64 | None = None
    #: Per waypoint, its velocity over the planned one, ``σ`` in (0, 1] (None: not stretched).
    speed_scale: F64 | None = None
    stretch: Stretch | None = None


def _no_pause() -> None:
    """The default ``pause``: nothing."""


@dataclass(frozen=True)
class _Segments:
    """Segments' fixed data: ``(M,)`` and ``(M, n)`` arrays (M segments, n joints)."""

    h: F64
    p0: F64
    dq: F64
    v0: F64
    v1: F64
    #: How far past a position limit a stretched segment may go (what the planned one does).
    allow: F64
    #: Whether the segment could reach a position limit at all (else that check is skipped).
    near: npt.NDArray[np.bool_]
    limits: JointLimitArrays

    @classmethod
    def planned(
        cls, times: F64, positions: F64, velocities: F64, limits: JointLimitArrays
    ) -> _Segments:
        """The planned trajectory's segments."""
        h = np.diff(times)
        p0, p1 = positions[:-1], positions[1:]
        v0, v1 = velocities[:-1], velocities[1:]
        # A Hermite cubic strays from its chord by at most 4/27 (|t0| + |t1|) (t = duration x
        # velocity), and a ramp at most doubles a tangent: within this of the waypoints it stays.
        reach = (8.0 / 27.0) * h[:, None] * (np.abs(v0) + np.abs(v1))
        near = (np.minimum(p0, p1) - reach < limits.lower) | (
            np.maximum(p0, p1) + reach > limits.upper
        )
        m = h.shape[0]
        return cls(h, p0, p1 - p0, v0, v1, np.zeros(m), near.any(axis=1), limits)

    def take(self, idx: npt.NDArray[np.intp]) -> _Segments:
        """The segments ``idx`` (gathered once, for the many evaluations of a bisection)."""
        return _Segments(
            self.h[idx],
            self.p0[idx],
            self.dq[idx],
            self.v0[idx],
            self.v1[idx],
            self.allow[idx],
            self.near[idx],
            self.limits,
        )

    def ratios(self, s0: F64, s1: F64) -> tuple[F64, F64, F64]:
        """Acceleration ratio, squared velocity ratio and position excess, per joint.

        For the segments run with speed scales ``s0`` and ``s1`` at their two waypoints (shape
        ``(M,)``): duration ``2 h / (s0 + s1)``, velocities scaled by them. Ratios are to the
        limits (1 is at the limit); the excess is how far (rad or m) the curve passes a position
        limit (-inf when it cannot reach one).
        """
        lim = self.limits
        h = (2.0 * self.h / (s0 + s1))[:, None]
        d0 = self.v0 * s0[:, None]
        d1 = self.v1 * s1[:, None]
        dq = self.dq
        # q(s) = p0 + t0 s + c2 s^2 + c3 s^3 on s in [0, 1], t = h * velocity.
        t0 = d0 * h
        t1 = d1 * h
        c2 = 3.0 * dq - 2.0 * t0 - t1
        c3 = t0 + t1 - 2.0 * dq
        acc = np.maximum(np.abs(c2), np.abs(c2 + 3.0 * c3)) * (2.0 / (h * h))
        excess = np.full(dq.shape, -np.inf)
        with np.errstate(divide="ignore", invalid="ignore"):
            # The velocity's vertex (q''(s) = 0), where it lies inside the segment.
            sv = -c2 / (3.0 * c3)
            inside = (c3 != 0.0) & (sv > 0.0) & (sv < 1.0)
            vv = np.where(inside, np.abs(t0 + (2.0 * c2 + 3.0 * c3 * sv) * sv) / h, 0.0)
            speed = np.maximum(np.maximum(np.abs(d0), np.abs(d1)), vv)
            rows = np.flatnonzero(self.near)
            if rows.size:
                # The position's extremes (q'(s) = 0): roots of 3 c3 s^2 + 2 c2 s + t0.
                a, b, c = 3.0 * c3[rows], 2.0 * c2[rows], t0[rows]
                p0, k2, k3 = self.p0[rows], c2[rows], c3[rows]
                disc = b * b - 4.0 * a * c
                root = np.sqrt(np.maximum(disc, 0.0))
                quad = (a != 0.0) & (disc >= 0.0)
                out = np.full(a.shape, -np.inf)
                for s in (
                    np.where(quad, (-b + root) / (2.0 * a), np.nan),
                    np.where(quad, (-b - root) / (2.0 * a), np.nan),
                    np.where((a == 0.0) & (b != 0.0), -c / b, np.nan),
                ):
                    q = p0 + ((k3 * s + k2) * s + c) * s
                    past = np.maximum(q - lim.upper, lim.lower - q)
                    out = np.where((s > 0.0) & (s < 1.0), np.maximum(out, past), out)
                excess[rows] = out
        return acc / lim.acceleration, (speed / lim.velocity) ** 2, excess

    def demand(self, s0: F64, s1: F64) -> F64:
        """Per segment, how far over its limits it is (<= 1 within; inf off a position limit)."""
        acc, vel, excess = self.ratios(s0, s1)
        worst: F64 = np.maximum(acc, vel).max(axis=1)
        return np.where((excess > self.allow[:, None]).any(axis=1), np.inf, worst)


def time_scale(
    times: F64,
    positions: F64,
    velocities: F64,
    limits: JointLimitArrays,
    pause: Callable[[], None] = _no_pause,
) -> Timing:
    """The times and waypoint velocities that keep the curve within the joint limits.

    Args:
        times: waypoint times (s, increasing, already divided by the speed ratio), ``(m,)``.
        positions: waypoint positions, ``(m, n)``, within the position limits.
        velocities: waypoint velocities (the curve's slopes), ``(m, n)``.
        limits: the joints' limits (velocity and acceleration).
        pause: called between whole-array steps (the driver yields the interpreter there).

    Returns:
        The given times and velocities unchanged when every segment is within the limits (to
        :data:`LIMIT_TOLERANCE`); otherwise the stretched ones and the report.

    Raises:
        InvalidArgumentError: when the curve through the given velocities leaves a joint's
            position limits between waypoints.
    """
    m = times.shape[0]
    seg = _Segments.planned(times, positions, velocities, limits)
    ones = np.ones(m - 1)
    acc, vel, excess = seg.ratios(ones, ones)
    pause()
    off = excess > POSITION_TOLERANCE
    if off.any():
        i, j = (int(x) for x in np.argwhere(off)[0])
        raise InvalidArgumentError(
            f"Waypoint {i + 1}: the curve through the given joint_velocity leaves joint {j}'s "
            f"limits before it (by {float(excess[i, j]):.3g})"
        )
    ratio = np.maximum(acc, vel).max(axis=1)
    if not np.any(ratio > 1.0 + LIMIT_TOLERANCE):
        return Timing(times, velocities)
    # A stretched segment may pass a limit no further than the planned one did (round-off).
    seg.allow[:] = np.maximum(excess.max(axis=1), 0.0) + 1e-12
    cap = np.minimum(1.0, (1.0 - _MARGIN) / np.sqrt(np.maximum(ratio, 1e-300)))
    # Each waypoint at most the cap of both its segments: equal ends are then within the limits.
    sigma = np.ones(m)
    sigma[:-1] = cap
    sigma[1:] = np.minimum(sigma[1:], cap)
    check = np.arange(m - 1)
    for _ in range(MAX_ROUNDS):
        if check.size == 0:
            break
        dem = seg.take(check).demand(sigma[check], sigma[check + 1])
        bad = check[dem > 1.0 + LIMIT_TOLERANCE]
        if bad.size == 0:
            break
        changed = _slow_faster_ends(seg.take(bad), bad, sigma)
        near = np.concatenate([changed - 1, changed])
        check = np.unique(near[(near >= 0) & (near < m - 1)])
        pause()
    else:
        sigma[:] = float(cap.min())  # the pure time scaling by the worst segment's factor
    h_new = 2.0 * seg.h / (sigma[:-1] + sigma[1:])
    new_times = np.concatenate([[0.0], np.cumsum(h_new)])
    k = np.diff(new_times) / seg.h
    stretched = np.flatnonzero(k > 1.0 + 1e-12)
    worst = int(np.argmax(ratio))
    joint = int(np.argmax(np.maximum(acc[worst], vel[worst])))
    report = Stretch(
        factor=float(k.max()),
        segments=int(stretched.size),
        segment_count=m - 1,
        first_segment=int(stretched[0]) if stretched.size else 0,
        last_segment=int(stretched[-1]) if stretched.size else 0,
        planned_duration=float(times[-1]),
        duration=float(new_times[-1]),
        joint=joint,
        limit="acceleration" if acc[worst, joint] >= vel[worst, joint] else "velocity",
    )
    return Timing(new_times, velocities * sigma[:, None], k, sigma, report)


def _slow_faster_ends(
    seg: _Segments, bad: npt.NDArray[np.intp], sigma: F64
) -> npt.NDArray[np.intp]:
    """Slow the faster waypoint of each segment ``bad`` (``seg``) just enough; those changed.

    At equal scales a segment is a pure time scaling of the planned one by at most its own
    factor (every scale is at most the cap of both its segments), so within the limits: the
    bisection between the slower end's scale (within) and the faster's (not) always ends on a
    scale that is within.
    """
    s0, s1 = sigma[bad], sigma[bad + 1]
    low = np.minimum(s0, s1)
    right_faster = s1 > s0
    good, over = low.copy(), np.maximum(s0, s1)
    for _ in range(_BISECTIONS):
        mid = 0.5 * (good + over)
        dem = seg.demand(np.where(right_faster, low, mid), np.where(right_faster, mid, low))
        ok = dem <= 1.0 - _SLACK
        good = np.where(ok, mid, good)
        over = np.where(ok, over, mid)
    target = bad + right_faster.astype(np.intp)
    np.minimum.at(sigma, target, good)
    return np.unique(target)
