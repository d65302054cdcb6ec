"""Joint trajectories: the acceptance checks and the interpolation the loop samples.

The checks follow the reference's ``JointTrajectoryInterpolator`` in order, with its messages,
except where the reference is defective (documented in :mod:`robotspec.driver.robot_driver`):

* messages carry the real waypoint index (the reference prints a literal ``{i}``);
* the 100 ms gap rule applies to the trajectory as written, not to the times stretched by a speed
  ratio below 1 (the reference rejects at 0.4 what it accepts at 1.0);
* NaN or infinite values are refused.

Interpolation is a piecewise-cubic Hermite through the waypoints, instead of the reference's
not-a-knot cubic spline. Its velocity at a waypoint is the waypoint's ``joint_velocity`` (times the
speed ratio) when the client gave one: the planner's own curve. Where none is given it is the
monotone (PCHIP, Fritsch-Carlson) slope, as before velocities were honoured. Why PCHIP there: it
never overshoots between waypoints, so a trajectory whose waypoints are within the joint limits
stays within them. The curve starts and ends at rest whatever velocities the first and last
waypoints give: the arm starts from rest and the driver holds the end (a velocity there would be a
jump, an unbounded acceleration).

Where that curve would exceed a joint's velocity or acceleration limit, the segments concerned are
slowed just enough (:mod:`robotspec.driver.stretch`), and the interpolator reports it
(:attr:`TrajectoryInterpolator.stretch`).
"""

from __future__ import annotations

import bisect
import math
import time
from array import array
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from robotspec.arrays import F64
from robotspec.driver.commands import JointLimitArrays
from robotspec.driver.errors import InvalidArgumentError
from robotspec.driver.stretch import Stretch, time_scale

__all__ = [
    "CHUNK",
    "JointTrajectory",
    "TrajectoryColumns",
    "TrajectoryInterpolator",
    "Waypoint",
    "columns_of",
    "load_trajectory",
    "pause",
    "MIN_WAYPOINTS",
    "MAX_WAYPOINT_GAP",
]


MIN_WAYPOINTS = 5
MAX_WAYPOINT_GAP = 0.1
_TIME_EPS = 1e-9
#: Large conversions run in chunks of this many waypoints, yielding the interpreter between them.
#: Why: one ``np.array`` or ``tolist`` over 50,000 waypoints holds the GIL for 50-90 ms, and the
#: loop thread (which needs it every period) waits for all of it.
CHUNK = 256


def pause() -> None:
    """Let another thread (the loop) take the interpreter now, if it is waiting."""
    time.sleep(0)


def _floats(a: F64) -> array[float]:
    """``a`` (1-D) as a Python ``array('d')``: plain floats for the loop's per-step lookups.

    Why not a list: a list of 50,000 floats is 50,000 objects, made in chunks on the uploading
    thread and freed one by one wherever the last reference goes, the loop thread included
    (a trajectory that completes there). An ``array('d')`` is one buffer, copied in and freed
    at once, and indexing it still gives plain floats (bisect and the Hermite sums need them).
    """
    return array("d", np.ascontiguousarray(a, dtype=np.float64).tobytes())


def _rows(rows: Sequence[Sequence[float]], n: int, out: F64 | None = None) -> F64:
    """``np.array(rows)`` as an ``(m, n)`` float array, in chunks (see :data:`CHUNK`).

    Into ``out`` when given: no second array of every waypoint on the uploading thread.
    """
    m = len(rows)
    out = np.empty((m, n)) if out is None else out
    for start in range(0, m, CHUNK):
        out[start : start + CHUNK] = np.array(rows[start : start + CHUNK], dtype=np.float64)
        pause()
    return out


@dataclass(frozen=True)
class Waypoint:
    """One ``JointTrajectoryWaypoint``: positions (rad or m) at ``time_from_start`` (s)."""

    joint_position: tuple[float, ...]
    time_from_start: float
    joint_velocity: tuple[float, ...] = ()
    position_tolerance: tuple[float, ...] = ()
    velocity_tolerance: tuple[float, ...] = ()


@dataclass(frozen=True)
class JointTrajectory:
    """A ``JointTrajectory``: joint names (empty means "the robot's order") and waypoints."""

    joint_names: tuple[str, ...] = ()
    waypoints: tuple[Waypoint, ...] | None = field(default_factory=tuple)

    @classmethod
    def from_arrays(
        cls, times: Sequence[float], positions: Any, joint_names: Sequence[str] = ()
    ) -> JointTrajectory:
        """A trajectory from a time list and a ``(m, n)`` position array."""
        pos = np.asarray(positions, dtype=np.float64)
        return cls(
            joint_names=tuple(joint_names),
            waypoints=tuple(
                Waypoint(joint_position=tuple(float(x) for x in pos[i]), time_from_start=float(t))
                for i, t in enumerate(times)
            ),
        )

    @classmethod
    def smooth_move(
        cls, start: Any, end: Any, duration: float, spacing: float = 0.05
    ) -> JointTrajectory:
        """A rest-to-rest quintic move from ``start`` to ``end`` in ``duration`` seconds."""
        a = np.asarray(start, dtype=np.float64)
        b = np.asarray(end, dtype=np.float64)
        m = max(MIN_WAYPOINTS, int(math.ceil(duration / spacing)) + 1)
        times = np.linspace(0.0, duration, m)
        s = times / duration
        blend = 10 * s**3 - 15 * s**4 + 6 * s**5
        q = a[None, :] + blend[:, None] * (b - a)[None, :]
        # Exact ends: a + (b - a) can miss b by an ulp, which a target on a joint limit turns
        # into "exceeds joint limits".
        q[0], q[-1] = a, b
        return cls.from_arrays(times.tolist(), q)


class TrajectoryInterpolator:
    """Samples a checked trajectory at any time (cubic Hermite through the waypoints).

    Args:
        times: waypoint times (s), increasing from 0, ``(m,)``.
        positions: waypoint positions, ``(m, n)``.
        velocities: the waypoints' velocities, ``(m, n)``, a row of NaN where none was given
            (that waypoint gets the PCHIP slope); None: PCHIP everywhere.
        limits: the joint limits the curve must stay within; None: not checked (the curve as
            given, for tests of the interpolation itself).
    """

    def __init__(
        self,
        times: F64,
        positions: F64,
        velocities: F64 | None = None,
        limits: JointLimitArrays | None = None,
    ) -> None:
        #: The waypoint times as planned (after the speed ratio), before any stretch.
        self.planned_times = times
        self.positions = positions
        self.n_waypoints = int(times.shape[0])
        h = np.diff(times)
        delta = np.diff(positions, axis=0) / h[:, None]
        pause()  # a large trajectory: let the loop thread in between whole-array steps
        d = np.zeros_like(positions)
        if positions.shape[0] > 2:
            h0 = h[:-1, None]
            h1 = h[1:, None]
            w1 = 2.0 * h1 + h0
            w2 = h1 + 2.0 * h0
            d0, d1 = delta[:-1], delta[1:]
            same = d0 * d1 > 0.0
            pause()
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                hm = (w1 + w2) / (w1 / d0 + w2 / d1)
            pause()
            d[1:-1] = np.where(same & np.isfinite(hm), hm, 0.0)
        if velocities is not None:
            given = ~np.isnan(velocities[:, 0])
            d[given] = velocities[given]
            d[0] = d[-1] = 0.0  # starts and ends at rest (see the module's docstring)
        #: How the curve was slowed to stay within the limits; None when it was not.
        self.stretch: Stretch | None = None
        #: Per segment, its duration over the planned one (None when nothing was stretched).
        self.segment_stretch: F64 | None = None
        #: Per waypoint, its velocity over the planned one (None when nothing was stretched).
        self.speed_scale: F64 | None = None
        if limits is not None:
            pause()
            timing = time_scale(times, positions, d, limits, pause=pause)
            times, d = timing.times, timing.velocities
            self.stretch = timing.stretch
            self.segment_stretch = timing.segment_stretch
            self.speed_scale = timing.speed_scale
            if timing.stretch is not None:
                h = np.diff(times)
        self.times = times
        self.max_time = float(times[-1])
        #: The curve's velocity at each waypoint, ``(m, n)`` (given ones scaled by any stretch).
        self.velocities = d
        self._h = h
        self._stretch_l: array[float] = (
            array("d") if self.segment_stretch is None else _floats(self.segment_stretch)
        )
        # Plain-float copies for evaluate(), which the loop calls every step.
        self._times_l: array[float] = _floats(times)
        self._h_l: array[float] = _floats(h)
        # Rows as plain floats only for the segment being sampled: converting all 50,000 rows
        # up front made 100,000 small lists, and the garbage collector's pass over them froze
        # the loop thread for 170 ms.
        self._segment = -1
        self._rows: tuple[list[float], list[float], list[float], list[float]] = ([], [], [], [])

    def stretch_at(self, segment: int) -> float:
        """How much segment ``segment`` was stretched (1.0: as planned)."""
        if 0 <= segment < len(self._stretch_l):
            return self._stretch_l[segment]
        return 1.0

    def evaluate(self, t: float) -> tuple[F64, int]:
        """Position at time ``t`` (clamped to the ends; a new array) and the segment's start.

        Per joint in plain floats: on an arm's few joints that is several times faster than
        numpy's per-call overhead; the same operations in the same order as the vector form.
        """
        if t >= self.max_time:
            return self.positions[-1].copy(), self.n_waypoints - 1
        if t <= 0.0:
            return self.positions[0].copy(), 0
        k = self._segment
        times = self._times_l
        if not (0 <= k and times[k] <= t < times[k + 1]):
            # Not the segment of the last step (a step in a new segment, or the first):
            # O(log n) by bisection; within a segment, O(1).
            k = bisect.bisect_right(times, t) - 1
        h = self._h_l[k]
        s = (t - self._times_l[k]) / h
        s2 = s * s
        s3 = s2 * s
        h00 = 2 * s3 - 3 * s2 + 1
        h10 = s3 - 2 * s2 + s
        h01 = -2 * s3 + 3 * s2
        h11 = s3 - s2
        hh10 = h10 * h
        hh11 = h11 * h
        if k != self._segment:
            self._segment = k
            self._rows = (
                self.positions[k].tolist(),
                self.positions[k + 1].tolist(),
                self.velocities[k].tolist(),
                self.velocities[k + 1].tolist(),
            )
        p0, p1, m0, m1 = self._rows
        out = [p0[i] * h00 + (hh10 * m0[i] + h01 * p1[i] + hh11 * m1[i]) for i in range(len(p0))]
        return np.array(out), k


@dataclass(frozen=True)
class TrajectoryColumns:
    """A trajectory as arrays, one row per waypoint: what the checks and the planner read.

    Why arrays: a client's trajectory of 50,000 waypoints as Python objects (a waypoint, its
    tuples, their floats) is hundreds of thousands of objects to make, check and collect, all
    holding the interpreter the driver loop needs every period. A front end that receives
    waypoints (the Robot Raconteur service) fills these arrays directly; the in-process
    :class:`JointTrajectory` is converted by :func:`columns_of`.

    Attributes:
        joint_names: as given (empty: the robot's order).
        times: each waypoint's ``time_from_start`` as given, ``(m,)``.
        positions: ``(m, n)``; rows of the wrong length are NaN (``lengths`` says so).
        lengths: each waypoint's ``joint_position`` length, ``(m,)``.
        option_sizes: lengths of ``joint_velocity``, ``position_tolerance`` and
            ``velocity_tolerance``, ``(m, 3)``.
        velocities: ``(m, n)``, NaN rows where a waypoint gave none (or not ``n`` of them);
            None when no waypoint gave any.
    """

    joint_names: tuple[str, ...]
    times: F64
    positions: F64
    lengths: npt.NDArray[np.intp]
    option_sizes: npt.NDArray[np.intp]
    velocities: F64 | None = None

    @classmethod
    def empty(cls, m: int, n: int, joint_names: Sequence[str] = ()) -> TrajectoryColumns:
        """Columns for ``m`` waypoints of ``n`` joints, to be filled row by row."""
        return cls(
            tuple(joint_names),
            np.zeros(m),
            np.full((m, n), np.nan),
            np.zeros(m, dtype=np.intp),
            np.zeros((m, 3), dtype=np.intp),
            None,
        )

    @property
    def size(self) -> int:
        """The number of waypoints."""
        return int(self.times.shape[0])


def columns_of(traj: JointTrajectory, n: int) -> TrajectoryColumns:
    """The waypoints of ``traj`` as :class:`TrajectoryColumns` for ``n`` joints.

    Values are converted only when every array has a valid length, so a length error is
    reported before a value error, in the reference's order.

    Raises:
        InvalidArgumentError: a value is not a number.
    """
    wps = traj.waypoints or ()
    m = len(wps)
    cols = TrajectoryColumns.empty(m, n, traj.joint_names)
    rows: list[Sequence[float]] = []
    vrows: list[Sequence[float]] = []
    vidx: list[int] = []
    try:
        for start in range(0, m, CHUNK):
            for i in range(start, min(m, start + CHUNK)):
                w = wps[i]
                jp, jv = w.joint_position, w.joint_velocity
                cols.lengths[i] = len(jp)
                sizes = (len(jv), len(w.position_tolerance), len(w.velocity_tolerance))
                cols.option_sizes[i] = sizes
                cols.times[i] = w.time_from_start
                rows.append(jp)
                if len(jv) == n:
                    vrows.append(jv)
                    vidx.append(i)
            pause()
        sizes_ok = (cols.option_sizes == 0) | (cols.option_sizes == n)
        if not (np.all(cols.lengths == n) and np.all(sizes_ok)):
            return cols  # _check_and_plan reports the first wrong length
        _rows(rows, n, cols.positions)
        velocities = None
        if vidx:
            velocities = np.full((m, n), np.nan)
            velocities[np.array(vidx)] = _rows(vrows, n)
    except (TypeError, ValueError, OverflowError):
        raise InvalidArgumentError("Waypoint values must be numbers") from None
    return TrajectoryColumns(
        cols.joint_names, cols.times, cols.positions, cols.lengths, cols.option_sizes, velocities
    )


def load_trajectory(
    traj: JointTrajectory | TrajectoryColumns,
    joint_names: Sequence[str],
    limits: JointLimitArrays,
    speed_ratio: float,
) -> TrajectoryInterpolator:
    """Check ``traj`` against the robot and build its interpolator, on times ÷ ``speed_ratio``.

    The interpolator follows the waypoints' velocities (times ``speed_ratio``) and is slowed
    where it would exceed the velocity or acceleration limits (its ``stretch`` says how much).
    Everything here is array work on the caller's thread, never under the loop's lock: the
    loop receives the finished interpolator in one step (``execute_trajectory``).

    Raises:
        InvalidArgumentError: with the reference's message for the first failed check; or when
            the curve through the given velocities leaves the position limits between waypoints.
    """
    n = len(joint_names)
    if traj.joint_names and tuple(traj.joint_names) != tuple(joint_names):
        raise InvalidArgumentError("Joint names in trajectory must match robot joint names")
    if isinstance(traj, JointTrajectory):
        if traj.waypoints is None:
            raise InvalidArgumentError("Waypoint list must not be null")
        count = len(traj.waypoints)
        first_time = traj.waypoints[0].time_from_start if count else 0.0
    else:
        count = traj.size
        first_time = float(traj.times[0]) if count else 0.0
    if count < MIN_WAYPOINTS:
        raise InvalidArgumentError(
            f"Waypoint list must contain five or more waypoints (got {count})"
        )
    if first_time != 0.0:
        raise InvalidArgumentError("Trajectory time_from_start must equal zero for first waypoint")
    cols = columns_of(traj, n) if isinstance(traj, JointTrajectory) else traj
    return _check_and_plan(cols, n, limits, speed_ratio)


def _check_and_plan(
    cols: TrajectoryColumns, n: int, limits: JointLimitArrays, speed_ratio: float
) -> TrajectoryInterpolator:
    """The per-waypoint checks in the reference's order, then the interpolator."""
    # Vectorised checks (a 50,000-waypoint upload must not hold the interpreter for a second),
    # then the first failure in the reference's order: by waypoint, then by check.
    failures: list[tuple[int, int, str]] = []

    def first(rank: int, bad: npt.NDArray[np.bool_], message: str) -> None:
        hits = np.flatnonzero(bad)
        if hits.size:
            i = int(hits[0])
            failures.append((i, rank, message.format(i=i)))

    first(0, cols.lengths != n, "Waypoint {i} invalid joint array length")
    for rank, what in enumerate(("joint_velocity", "position_tolerance", "velocity_tolerance"), 1):
        sizes = cols.option_sizes[:, rank - 1]
        first(rank, (sizes != 0) & (sizes != n), f"Waypoint {{i}} invalid {what} array length")
    if failures:
        raise InvalidArgumentError(min(failures)[2])
    pos, raw = cols.positions, cols.times
    given = cols.option_sizes[:, 0] == n
    vel = cols.velocities
    vel_finite = np.ones(raw.shape[0], dtype=bool)
    wp_fast = np.zeros(raw.shape[0], dtype=bool)
    if vel is not None and given.any():
        with np.errstate(invalid="ignore", over="ignore"):
            vel_finite = ~given | np.all(np.isfinite(vel), axis=1)
            wp_fast = given & np.any(np.abs(vel * speed_ratio) > limits.velocity, axis=1)
    finite = np.all(np.isfinite(pos), axis=1) & np.isfinite(raw) & vel_finite
    first(4, ~finite, "Waypoint {i} contains NaN or infinite values")
    pause()  # each whole-array step below takes a millisecond or two: yield between them
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        times = raw / speed_ratio
        dt = np.diff(times)
        gap = np.diff(raw)
        inc = np.concatenate([[False], ~(dt > 0.0)])
        first(5, inc & finite, "Waypoint {i} time_from_start must be increasing")
        far = np.concatenate([[False], gap > MAX_WAYPOINT_GAP + _TIME_EPS])
        first(6, far & finite, "Waypoint {i} more than 100 ms from previous waypoint")
        pause()
        outside = np.any(pos < limits.lower, axis=1) | np.any(pos > limits.upper, axis=1)
        first(7, outside & finite, "Waypoint {i} exceeds joint limits")
        pause()
        fd = np.abs(np.diff(pos, axis=0)) / dt[:, None]
        fd_fast = np.concatenate([[False], np.any(fd > limits.velocity, axis=1)])
        first(8, (wp_fast | fd_fast) & finite, "Waypoint {i} exceeds joint velocity limits")
    if failures:
        # A non-finite waypoint poisons its neighbours' differences: report it first.
        raise InvalidArgumentError(min(failures)[2])
    velocities = None
    if vel is not None and given.any():
        # The client's velocities are on its time axis: on the driver's (÷ speed ratio) they
        # are faster by the ratio, as the velocity check above takes them.
        velocities = np.where(given[:, None], vel * speed_ratio, np.nan)
    return TrajectoryInterpolator(times, pos, velocities, limits)
