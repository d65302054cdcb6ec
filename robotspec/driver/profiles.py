"""Online motion profiles: each step moves toward a target position or velocity, time-optimally.

Why online rather than a precomputed trapezoid: a jog may be re-targeted at any step (a new
``jog_freespace`` while moving, a joystick's ``jog_joint`` stream, a Cartesian velocity mapped
through a changing Jacobian, a streamed position). Planning one step at a time from the current
position and velocity, with the velocity and acceleration limits and a braking velocity that stops
exactly at the target and before a joint limit, handles every case with one rule and never needs a
replan.

Why every step takes its real duration ``dt``: the loop's periods jitter, and the simulated (or
real) arm integrates the time that really elapsed. A profile that advanced by the nominal period
would drift from the arm and end somewhere else; one that integrates the same ``dt`` only changes
*when* the arm arrives, never *where*.

The braking rule (:func:`braking_speed`): after a step of duration ``dt`` at speed ``v`` toward a
stop point ``d`` away, the remaining distance is ``d - v dt``; the step is allowed only if the joint
can still stop there at ``a``: ``v**2 <= 2 a (d - v dt)``. That set of states is invariant for *any*
sequence of step durations (braking at ``a`` keeps a state inside it), so no jitter can make a joint
cross a limit or exceed its acceleration limit, and it never allows more than ``sqrt(2 a d)``.
"""

from __future__ import annotations

import math

import numpy as np

from robotspec.arrays import F64

__all__ = [
    "BRAKING_MARGIN",
    "JogMotion",
    "StreamLimiter",
    "braking_speed",
    "rest_to_rest_time",
]

#: Braking onto a *target* is planned at this fraction of the acceleration limit. Why: the final
#: snap onto the target (see :data:`SNAP_FRACTION`) and a shorter next period must never need more
#: than the limit; braking onto a joint *limit* uses the full acceleration.
BRAKING_MARGIN = 0.95
#: A joint snaps exactly onto its target when the remaining distance is below this fraction of
#: ``a dt**2``: the extra velocity change is then at most 5 % of what one step allows.
SNAP_FRACTION = 0.05


def braking_speed(distance: float, amax: float, dt: float) -> float:
    """The highest speed toward a stop point ``distance`` away for a step of ``dt`` seconds.

    The positive root of ``v**2 + 2 a dt v - 2 a d = 0`` (so ``v**2 <= 2 a (d - v dt)``), written
    without cancellation for tiny distances. Zero when the stop point is behind.
    """
    if not distance > 0.0:
        return 0.0
    adt = amax * dt
    two_ad = 2.0 * amax * distance
    return two_ad / (math.sqrt(adt * adt + two_ad) + adt)


def rest_to_rest_time(distance: F64, vmax: F64, amax: F64) -> F64:
    """Time of a trapezoidal (or triangular) rest-to-rest move per joint."""
    d = np.abs(distance)
    tri = d < vmax * vmax / amax
    t_tri = 2.0 * np.sqrt(d / amax)
    t_trap = d / vmax + vmax / amax
    out: F64 = np.where(tri, t_tri, t_trap)
    return out


class JogMotion:
    """The state of one jog: commanded position and velocity, and what it moves toward.

    Args:
        q: start position (the last command, or the measured position).
        v: start velocity.
        vmax: per-joint speed limit for this jog (already scaled by speed ratio, capped).
        amax: per-joint acceleration limit for this jog.
        lower: position limits the jog must stop before.
        upper: position limits the jog must stop before.
        dt: the nominal loop period (used when :meth:`step` is given no duration).
    """

    def __init__(
        self,
        q: F64,
        v: F64,
        vmax: F64,
        amax: F64,
        lower: F64,
        upper: F64,
        dt: float,
    ) -> None:
        self.q = np.array(q, dtype=np.float64)
        self.v = np.array(v, dtype=np.float64)
        self.vmax = np.array(vmax, dtype=np.float64)
        self.amax = np.array(amax, dtype=np.float64)
        self.lower = lower
        self.upper = upper
        self.dt = dt
        self.target_position: F64 | None = None
        self.target_velocity: F64 | None = None
        #: Scale velocity changes of all joints together (a Cartesian jog keeps its direction
        #: while it speeds up and brakes) instead of joint by joint.
        self.coordinated = False
        #: Set by :meth:`step` when a joint had to brake for its position limit this step.
        self.limit_braking = False
        self.velocity_until = 0.0
        self.t = 0.0
        self.done = False
        # Plain-float copies of the limits for :meth:`step`, rebuilt when an array is replaced
        # (``vmax``/``amax`` are reassigned by the driver, never modified in place).
        self._lists_for: tuple[object, ...] = ()
        self._lists: tuple[list[float], ...] = ()

    def to_position(self, target: F64, synchronize: bool = True) -> None:
        """Move to ``target``; joints are time-synchronised when starting from rest.

        Why synchronise: a freespace jog should reach the goal on all joints together, as the
        reference's trapezoids do, so the path stays close to a straight line in joint space.
        """
        self.target_position = np.clip(np.array(target, dtype=np.float64), self.lower, self.upper)
        self.target_velocity = None
        self.coordinated = False
        self.done = False
        if synchronize and not np.any(self.v):
            dist = self.target_position - self.q
            # A denormal max_velocity (accepted: it is > 0) overflows the move time to inf;
            # then no synchronisation (found by the state machine: NaN scale factors).
            with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
                times = rest_to_rest_time(dist, self.vmax, self.amax)
            t_max = float(times.max()) if times.size else 0.0
            if 0.0 < t_max < math.inf:
                lam = np.where(np.abs(dist) > 0, np.maximum(times / t_max, 1e-3), 1.0)
                self.vmax = self.vmax * lam
                self.amax = self.amax * lam * lam

    def at_velocity(self, velocity: F64, until: float) -> None:
        """Hold ``velocity`` until jog time ``until``, then brake to rest."""
        self.target_velocity = np.clip(np.array(velocity, dtype=np.float64), -self.vmax, self.vmax)
        self.target_position = None
        self.velocity_until = until
        self.done = False

    def _limit_lists(self) -> tuple[list[float], ...]:
        key = (self.amax, self.vmax, self.lower, self.upper)
        if any(a is not b for a, b in zip(key, self._lists_for, strict=False)) or not self._lists:
            self._lists_for = key
            self._lists = tuple(a.tolist() for a in key)
        return self._lists

    def step(self, dt: float | None = None) -> F64:
        """Advance by ``dt`` seconds (default: the nominal period); return the new position.

        Per joint in plain floats: on the handful of joints of an arm this is several times
        faster than numpy's per-call overhead (and touches far less memory, which is what a
        1 kHz loop waking from sleep pays for). The clamps propagate NaN as ``np.minimum`` does.
        """
        if dt is None:
            dt = self.dt
        if not dt > 0.0:
            return self.q.copy()
        amax_l, vmax_l, lower_l, upper_l = self._limit_lists()
        q_l = self.q.tolist()
        v_l = self.v.tolist()
        tgt = self.target_position
        tgt_l = tgt.tolist() if tgt is not None else None
        tv = self.target_velocity
        tv_l = tv.tolist() if tv is not None and self.t < self.velocity_until else None
        want = _wanted_velocity(q_l, tgt_l, tv_l, amax_l, vmax_l, dt)
        v_new = _accelerate(want, v_l, amax_l, dt, coordinated=self.coordinated)
        q_out, all_landed, moving, braking = _brake_and_move(
            q_l, v_new, tgt_l, amax_l, lower_l, upper_l, dt
        )
        self.limit_braking = braking
        if tgt_l is not None:
            self.done = all_landed and not moving
        else:
            self.done = self.t >= self.velocity_until and not moving
        q_arr = np.array(q_out)
        self.q = q_arr
        self.v = np.array(v_new)
        self.t += dt
        return q_arr


def _wanted_velocity(
    q: list[float],
    target: list[float] | None,
    target_velocity: list[float] | None,
    amax: list[float],
    vmax: list[float],
    dt: float,
) -> list[float]:
    """Step 1 of a jog: the velocity each joint wants (toward its target, or the one asked)."""
    n = len(q)
    want = [0.0] * n
    for i in range(n):
        if target is not None:
            dist = target[i] - q[i]
            b = braking_speed(abs(dist), amax[i] * BRAKING_MARGIN, dt)
            vm = vmax[i]
            b = vm if b > vm else b
            want[i] = b if dist > 0.0 else (-b if dist < 0.0 else dist * 0.0)
        elif target_velocity is not None:
            want[i] = target_velocity[i]
    return want


def _accelerate(
    want: list[float], v: list[float], amax: list[float], dt: float, *, coordinated: bool
) -> list[float]:
    """Step 2: toward ``want`` within the acceleration limits, joint by joint or all together.

    Coordinated: every joint's change is scaled by one factor, so the joints keep their ratio
    (a Cartesian jog keeps its direction).
    """
    n = len(v)
    if coordinated:
        k = 1.0
        for i in range(n):
            dv = abs(want[i] - v[i])
            adt = amax[i] * dt
            if dv > adt:
                k = min(k, adt / dv)
        return [v[i] + k * (want[i] - v[i]) for i in range(n)]
    out = [0.0] * n
    for i in range(n):
        adt = amax[i] * dt
        vi = v[i]
        x = want[i]
        x = vi - adt if x < vi - adt else x
        out[i] = vi + adt if x > vi + adt else x
    return out


def _brake_and_move(
    q_l: list[float],
    v_new: list[float],
    tgt_l: list[float] | None,
    amax_l: list[float],
    lower_l: list[float],
    upper_l: list[float],
    dt: float,
) -> tuple[list[float], bool, bool, bool]:
    """Step 3: never faster than the speed from which a joint can stop at its limit; move.

    ``v_new`` becomes the velocity each joint realised. Returns the new positions, whether
    every joint landed on its target, whether any moved, and whether a limit braked one.
    """
    n = len(q_l)
    q_out = [0.0] * n
    all_landed = tgt_l is not None
    moving = False
    braking = False
    for i in range(n):
        q, a = q_l[i], amax_l[i]
        lo, hi = lower_l[i], upper_l[i]
        x = v_new[i]
        cap_hi = braking_speed(hi - q, a, dt)
        if x > cap_hi:
            x = cap_hi
            braking = True
        cap_lo = -braking_speed(q - lo, a, dt)
        if x < cap_lo:
            x = cap_lo
            braking = True
        q_new = q + x * dt
        if tgt_l is not None:
            t_i = tgt_l[i]
            # Snap onto the target when it is that close and the snap keeps the joint
            # able to stop at its limits (a target on a limit is approached, not snapped).
            if abs(t_i - q_new) <= SNAP_FRACTION * a * dt * dt and (
                cap_lo <= (t_i - q) / dt <= cap_hi
            ):
                q_new = t_i
            if q_new != t_i:
                all_landed = False
        q_new = lo if q_new < lo else q_new
        q_new = hi if q_new > hi else q_new
        # The velocity actually realised (a snap or a clamp changes it by a hair).
        x = (q_new - q) / dt
        if x != 0.0:
            moving = True
        q_out[i] = q_new
        v_new[i] = x
    return q_out, all_landed, moving, braking


class StreamLimiter:
    """Acceleration and limit braking for streamed commands (position and velocity streams).

    A client's stream may jump (a new target far away, 3 rad/s to 0 in one sample, a velocity
    into a joint limit); what reaches the arm never changes speed faster than the acceleration
    limit and never approaches a joint limit faster than it can stop there.

    Args:
        q: the start position (last command sent, or the measured position).
        v: the start velocity.
        vmax, amax, lower, upper: the joint limits.
    """

    def __init__(
        self,
        q: F64,
        v: F64,
        vmax: F64,
        amax: F64,
        lower: F64,
        upper: F64,
    ) -> None:
        self.q: list[float] = [float(x) for x in q]
        self.v: list[float] = [float(x) for x in v]
        self._vmax = vmax.tolist()
        self._amax = amax.tolist()
        self._lower = lower.tolist()
        self._upper = upper.tolist()

    def position(self, target: list[float], target_velocity: list[float] | None, dt: float) -> F64:
        """The next position command toward the streamed ``target`` after ``dt`` seconds.

        Why ``target_velocity``: a stream that moves steadily must be followed without lag, so the
        braking speed toward the target is raised by the speed at which the target itself moves
        that way (when the stream holds still, the arm brakes onto it without overshoot).
        """
        if not dt > 0.0:
            return np.array(self.q)
        q_l, v_l = self.q, self.v
        out = [0.0] * len(q_l)
        for i in range(len(q_l)):
            q, v, a, vm = q_l[i], v_l[i], self._amax[i], self._vmax[i]
            lo, hi = self._lower[i], self._upper[i]
            tgt = target[i]
            tgt = lo if tgt < lo else (hi if tgt > hi else tgt)
            dist = tgt - q
            cap = braking_speed(abs(dist), a * BRAKING_MARGIN, dt)
            if target_velocity is not None:
                tv = target_velocity[i] if dist > 0.0 else -target_velocity[i]
                cap += tv if tv > 0.0 else 0.0
            cap = vm if cap > vm else cap
            x = dist / dt
            x = -cap if x < -cap else (cap if x > cap else x)
            adt = a * dt
            x = v - adt if x < v - adt else (v + adt if x > v + adt else x)
            x = _limit_cap(x, q, lo, hi, a, dt)
            q_new = q + x * dt
            if (
                abs(tgt - q_new) <= SNAP_FRACTION * a * dt * dt
                and _limit_cap((tgt - q) / dt, q, lo, hi, a, dt) == (tgt - q) / dt
            ):
                q_new = tgt
            q_new = lo if q_new < lo else (hi if q_new > hi else q_new)
            v_l[i] = (q_new - q) / dt
            q_l[i] = q_new
            out[i] = q_new
        return np.array(out)

    def velocity(
        self, command: list[float], measured: list[float], dt: float, horizon: float
    ) -> F64:
        """The next velocity command for the streamed ``command`` at position ``measured``.

        ``dt`` is the time since the last command (the acceleration budget); ``horizon`` the time
        the command may stay applied before the next one, over which the joint must still be
        able to stop at its limit. Keep ``horizon`` fixed: the set of states braked this way is
        invariant for every step up to ``2 * horizon`` long (a varying horizon breaks that).
        """
        v_l = self.v
        out = [0.0] * len(v_l)
        for i in range(len(v_l)):
            v, a, vm = v_l[i], self._amax[i], self._vmax[i]
            x = command[i]
            x = -vm if x < -vm else (vm if x > vm else x)
            adt = a * dt
            x = v - adt if x < v - adt else (v + adt if x > v + adt else x)
            x = _limit_cap(x, measured[i], self._lower[i], self._upper[i], a, horizon)
            v_l[i] = x
            out[i] = x
        self.q = [float(m) for m in measured]
        return np.array(out)


def _limit_cap(x: float, q: float, lo: float, hi: float, a: float, dt: float) -> float:
    """``x`` capped so that joint at ``q`` can still stop at ``lo`` and ``hi`` (see module)."""
    cap_hi = braking_speed(hi - q, a, dt)
    if x > cap_hi:
        x = cap_hi
    cap_lo = -braking_speed(q - lo, a, dt)
    return cap_lo if x < cap_lo else x
