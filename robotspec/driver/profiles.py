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
    half = 0.5 * amax * dt
    v: FloatArray = np.sign(distance) * (
        np.sqrt(half * half + 2.0 * amax * np.abs(distance)) - half
    )
    return v


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
        """Advance one period; return the new position command."""
        dt = self.dt
        if self.target_position is not None:
            dist = self.target_position - self.q
            v_des = np.clip(
                _braking_velocity(dist, self.amax * BRAKING_MARGIN, dt), -self.vmax, self.vmax
            )
        elif self.target_velocity is not None and self.t < self.velocity_until:
            v_des = self.target_velocity
        else:
            v_des = np.zeros_like(self.q)
        # Never plan past a joint limit: brake so as to stop on it.
        # (At the full deceleration: a target on the limit is then governed by its own braking.)
        v_hi = np.maximum(_braking_velocity(self.upper - self.q, self.amax, dt), 0.0)
        v_lo = np.minimum(_braking_velocity(self.lower - self.q, self.amax, dt), 0.0)
        v_des = np.clip(v_des, v_lo, v_hi)
        dv = np.clip(v_des - self.v, -self.amax * dt, self.amax * dt)
        v_new = self.v + dv
        q_new = self.q + v_new * dt
        if self.target_position is not None:
            # Land exactly on the target instead of oscillating around it.
            tgt = self.target_position
            crossed = (tgt - self.q) * (tgt - q_new) <= 0.0
            slow = np.abs(v_new) <= self.amax * dt * 1.0001
            # Landing implies the velocity (tgt - q) / dt; only land when that is reachable.
            feasible = np.abs((tgt - self.q) / dt - self.v) <= self.amax * dt * (1 + 1e-9)
            land = (crossed & slow & feasible) | (np.abs(tgt - q_new) < 1e-12) & slow
            # Crossing but unable to land this step: brake as hard as allowed; the overshoot is
            # below a_max * dt^2 and is taken back on the next step.
            brake = crossed & slow & ~feasible
            v_new = np.where(brake, self.v - np.sign(self.v) * self.amax * dt, v_new)
            q_new = np.where(brake, self.q + v_new * dt, q_new)
            q_new = np.where(land, tgt, q_new)
            v_new = np.where(land, 0.0, v_new)
            self.done = bool(np.all(q_new == tgt) and not np.any(v_new))
        else:
            self.done = self.t >= self.velocity_until and not np.any(v_new)
        q_new = np.clip(q_new, self.lower, self.upper)
        self.q = q_new
        self.v = v_new
        self.t += dt
        return q_new
