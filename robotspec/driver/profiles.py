"""Online jog profiles: each step moves toward a target position or velocity, time-optimally.

Why online rather than a precomputed trapezoid: a jog may be re-targeted at any step (a new
``jog_freespace`` while moving, a joystick's ``jog_joint`` stream, a Cartesian velocity mapped
through a changing Jacobian). Planning one step at a time from the current position and velocity,
with the velocity and acceleration limits and a braking velocity that stops exactly at the target
(and before a joint limit), handles every case with one rule and never needs a replan.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

__all__ = ["JogMotion", "rest_to_rest_time"]

#: Braking is planned at this fraction of the acceleration limit. Why: the discrete braking curve
#: is exact only on its own grid; the spare 10 % lets the last step land exactly on the target
#: without ever exceeding the acceleration limit.
BRAKING_MARGIN = 0.9

FloatArray = npt.NDArray[np.float64]


def rest_to_rest_time(distance: FloatArray, vmax: FloatArray, amax: FloatArray) -> FloatArray:
    """Time of a trapezoidal (or triangular) rest-to-rest move per joint."""
    d = np.abs(distance)
    tri = d < vmax * vmax / amax
    t_tri = 2.0 * np.sqrt(d / amax)
    t_trap = d / vmax + vmax / amax
    out: FloatArray = np.where(tri, t_tri, t_trap)
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
        dt: the loop period.
    """

    def __init__(
        self,
        q: FloatArray,
        v: FloatArray,
        vmax: FloatArray,
        amax: FloatArray,
        lower: FloatArray,
        upper: FloatArray,
        dt: float,
    ) -> None:
        self.q = np.array(q, dtype=np.float64)
        self.v = np.array(v, dtype=np.float64)
        self.vmax = np.array(vmax, dtype=np.float64)
        self.amax = np.array(amax, dtype=np.float64)
        self.lower = lower
        self.upper = upper
        self.dt = dt
        self.target_position: FloatArray | None = None
        self.target_velocity: FloatArray | None = None
        self.velocity_until = 0.0
        self.t = 0.0
        self.done = False
        # Plain-float copies of the limits for :meth:`step`, rebuilt when an array is replaced
        # (``vmax``/``amax`` are reassigned by the driver, never modified in place).
        self._lists_for: tuple[object, ...] = ()
        self._lists: tuple[list[float], ...] = ()

    def to_position(self, target: FloatArray, synchronize: bool = True) -> None:
        """Move to ``target``; joints are time-synchronised when starting from rest.

        Why synchronise: a freespace jog should reach the goal on all joints together, as the
        reference's trapezoids do, so the path stays close to a straight line in joint space.
        """
        self.target_position = np.clip(np.array(target, dtype=np.float64), self.lower, self.upper)
        self.target_velocity = None
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

    def at_velocity(self, velocity: FloatArray, until: float) -> None:
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

    def step(self) -> FloatArray:
        """Advance one period; return the new position command.

        Per joint in plain floats: on the handful of joints of an arm this is several times
        faster than numpy's per-call overhead (and touches far less memory, which is what a
        1 kHz loop waking from sleep pays for). Same IEEE operations in the same order as the
        vectorised form, so the same results; clamps propagate NaN as ``np.minimum`` does.
        """
        dt = self.dt
        amax_l, vmax_l, lower_l, upper_l = self._limit_lists()
        q_l = self.q.tolist()
        v_l = self.v.tolist()
        tgt = self.target_position
        tgt_l = tgt.tolist() if tgt is not None else None
        tv = self.target_velocity
        tv_l = tv.tolist() if tv is not None and self.t < self.velocity_until else None
        n = len(q_l)
        q_out = [0.0] * n
        v_out = [0.0] * n
        landing = False  # a joint crossed or reached its target slowly: check for arrival
        all_landed = tgt_l is not None
        moving = False
        sqrt = math.sqrt
        for i in range(n):
            q, v, amax = q_l[i], v_l[i], amax_l[i]
            adt = amax * dt
            half = 0.5 * amax * dt
            if tgt_l is not None:
                dist = tgt_l[i] - q
                a9 = amax * BRAKING_MARGIN
                h9 = 0.5 * a9 * dt
                b = (sqrt(h9 * h9 + 2.0 * a9 * abs(dist)) - h9) * _sign(dist)
                vm = vmax_l[i]
                b = -vm if b < -vm else b
                v_des = vm if b > vm else b
            elif tv_l is not None:
                v_des = tv_l[i]
            else:
                v_des = 0.0
            # Never plan past a joint limit: brake so as to stop on it.
            # (At the full deceleration: a target on the limit is then governed by its own
            # braking.)
            d_hi = upper_l[i] - q
            v_hi = (sqrt(half * half + 2.0 * amax * abs(d_hi)) - half) * _sign(d_hi)
            v_hi = 0.0 if v_hi < 0.0 else v_hi
            d_lo = lower_l[i] - q
            v_lo = (sqrt(half * half + 2.0 * amax * abs(d_lo)) - half) * _sign(d_lo)
            v_lo = 0.0 if v_lo > 0.0 else v_lo
            v_des = v_lo if v_des < v_lo else v_des
            v_des = v_hi if v_des > v_hi else v_des
            dv = v_des - v
            dv = -adt if dv < -adt else dv
            dv = adt if dv > adt else dv
            v_new = v + dv
            q_new = q + v_new * dt
            if tgt_l is not None:
                # Land exactly on the target instead of oscillating around it.
                t_i = tgt_l[i]
                crossed = dist * (t_i - q_new) <= 0.0
                slow = abs(v_new) <= adt * 1.0001
                near = abs(t_i - q_new) < 1e-12
                if (crossed or near) and slow:
                    landing = True
                    # Landing implies the velocity (tgt - q) / dt: land only when reachable.
                    feasible = abs(dist / dt - v) <= adt * (1 + 1e-9)
                    if crossed and not feasible:
                        # Crossing but unable to land this step: brake as hard as allowed;
                        # the overshoot is below a_max * dt^2 and is taken back next step.
                        v_new = v - _sign(v) * adt
                        q_new = q + v_new * dt
                    if (crossed and feasible) or near:
                        q_new = t_i
                        v_new = 0.0
                if q_new != t_i:
                    all_landed = False
            if v_new != 0.0:
                moving = True
            lo, hi = lower_l[i], upper_l[i]
            q_new = lo if q_new < lo else q_new
            q_out[i] = hi if q_new > hi else q_new
            v_out[i] = v_new
        if tgt_l is not None:
            self.done = landing and all_landed and not moving
        else:
            self.done = self.t >= self.velocity_until and not moving
        q_arr = np.array(q_out)
        self.q = q_arr
        self.v = np.array(v_out)
        self.t += dt
        return q_arr


def _sign(x: float) -> float:
    """``np.sign`` of one float (0 for 0, NaN for NaN)."""
    if x > 0.0:
        return 1.0
    if x < 0.0:
        return -1.0
    return x * 0.0 if x != x else 0.0
