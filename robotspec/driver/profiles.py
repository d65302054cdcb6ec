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


def _braking_velocity(distance: FloatArray, amax: FloatArray, dt: float) -> FloatArray:
    # The largest speed from which a discrete-time deceleration at amax stops within ``distance``.
    # Plain ufuncs (no np.clip / np.where wrappers): the loop calls this three times a step.
    half = 0.5 * amax * dt
    root = np.sqrt(half * half + 2.0 * amax * np.abs(distance))
    root -= half
    root *= np.sign(distance)
    return root


def _any(a: FloatArray | npt.NDArray[np.bool_]) -> bool:
    """``np.any`` for the loop's short arrays, without its wrapper overhead (~2 us a call)."""
    return any(a.tolist())


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
        # The three braking curves of a step (target, upper limit, lower limit) are evaluated in
        # one (3, n) pass; the stacked goals and accelerations are rebuilt only when the target
        # or ``amax`` object changes (both are replaced, never modified in place).
        n = self.q.shape[0]
        self._goals: FloatArray = np.empty((3, n))
        self._goals[1] = upper
        self._goals[2] = lower
        self._goals_for: FloatArray | None = None
        self._acc3: FloatArray = np.empty((3, n))
        self._acc3_for: FloatArray | None = None
        self._dist3: FloatArray = np.empty((3, n))

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

    def step(self) -> FloatArray:
        """Advance one period; return the new position command.

        Written with plain ufuncs (``np.minimum``/``np.maximum`` for clips, masks only when a
        joint is landing): at 1 kHz the ``np.clip``/``np.where``/``np.any`` wrappers cost more
        than the arithmetic. Same maths, same results, bit for bit.
        """
        dt = self.dt
        q, v, amax, vmax = self.q, self.v, self.amax, self.vmax
        adt = amax * dt
        tgt = self.target_position
        if tgt is not None and tgt is not self._goals_for:
            self._goals[0] = tgt
            self._goals_for = tgt
        if amax is not self._acc3_for:
            np.multiply(amax, BRAKING_MARGIN, out=self._acc3[0])
            self._acc3[1] = amax
            self._acc3[2] = amax
            self._acc3_for = amax
        # Row 0: toward the target (unused without one); rows 1 and 2: toward the limits.
        dist3 = np.subtract(self._goals, q, out=self._dist3)
        brake3 = _braking_velocity(dist3, self._acc3, dt)
        if tgt is not None:
            dist = dist3[0]
            v_des = np.minimum(np.maximum(brake3[0], -vmax), vmax)
        elif self.target_velocity is not None and self.t < self.velocity_until:
            v_des = self.target_velocity
        else:
            v_des = np.zeros_like(q)
        # Never plan past a joint limit: brake so as to stop on it.
        # (At the full deceleration: a target on the limit is then governed by its own braking.)
        v_hi = np.maximum(brake3[1], 0.0)
        v_lo = np.minimum(brake3[2], 0.0)
        v_des = np.minimum(np.maximum(v_des, v_lo), v_hi)
        dv = np.minimum(np.maximum(v_des - v, -adt), adt)
        v_new = v + dv
        q_new = q + v_new * dt
        if tgt is not None:
            # Land exactly on the target instead of oscillating around it.
            crossed = dist * (tgt - q_new) <= 0.0
            slow = np.abs(v_new) <= adt * 1.0001
            near = np.abs(tgt - q_new) < 1e-12
            if _any((crossed | near) & slow):
                # Landing implies the velocity (tgt - q) / dt; only land when that is reachable.
                feasible = np.abs(dist / dt - v) <= adt * (1 + 1e-9)
                land = (crossed & slow & feasible) | near & slow
                # Crossing but unable to land this step: brake as hard as allowed; the overshoot
                # is below a_max * dt^2 and is taken back on the next step.
                brake = crossed & slow & ~feasible
                v_new = np.where(brake, v - np.sign(v) * adt, v_new)
                q_new = np.where(brake, q + v_new * dt, q_new)
                q_new = np.where(land, tgt, q_new)
                v_new = np.where(land, 0.0, v_new)
                self.done = bool((q_new == tgt).all()) and not _any(v_new)
            else:
                self.done = False
        else:
            self.done = self.t >= self.velocity_until and not _any(v_new)
        q_out: FloatArray = np.minimum(np.maximum(q_new, self.lower), self.upper)
        self.q = q_out
        self.v = v_new
        self.t += dt
        return q_out
