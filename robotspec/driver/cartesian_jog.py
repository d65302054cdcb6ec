"""Cartesian jogs in the loop: joint rates for the twist each step, and when to stop.

The rates and the check that they move the tool the requested way are in
:mod:`~robotspec.driver.cartesian`; this mixin applies them to the running jog, looks ahead to
the pose where the arm would come to rest, and stops the jog (braking along the path) when the
tool could not follow the twist there or a joint would reach its limit.
"""

from __future__ import annotations

import numpy as np

from robotspec.arrays import F64
from robotspec.driver.cartesian import DIRECTION_TOLERANCE_DEG, twist_rates
from robotspec.driver.errors import (
    OperationFailedError,
)
from robotspec.driver.profiles import JogMotion
from robotspec.driver.state_fill import StateFill

__all__ = ["CartesianJog"]


class CartesianJog(StateFill):
    """The Cartesian side of step 4: rates for ``jog_cartesian`` and its stop rules."""

    def _limit_reason(self, q: F64) -> str:
        lo, hi = self._limits.lower, self._limits.upper
        worst = int(np.argmin(np.minimum(q - lo, hi - q)))
        side = "lower" if q[worst] - lo[worst] < hi[worst] - q[worst] else "upper"
        return f"joint '{self._joint_names[worst]}' reached its {side} limit"

    def _stop_cartesian_jog(self, motion: JogMotion, reason: str) -> None:
        """End a Cartesian jog that cannot go on: brake (along the path), fail its waiter."""
        chain = self._jog_cartesian[0] if self._jog_cartesian is not None else 0
        self._jog_cartesian = None
        motion.at_velocity(np.zeros(self._joint_count), 0.0)
        if self._jog_waiter is not None:
            self._jog_waiter.fail(
                OperationFailedError(f"Cartesian jog of chain {chain} stopped: {reason}")
            )
            self._jog_waiter = None

    def _cartesian_rates(self, chain: int, q: F64, twist: F64) -> F64 | str:
        """Joint velocities (all joints) for ``twist`` at ``q``, or why it cannot be done."""
        idx = self._chain_joints[chain]
        tf = self._tool_tf[chain]
        _, _, jac = self._hp[chain].fk_jacobian(
            q[idx], None if tf is None else tf[0], None if tf is None else tf[1]
        )
        sol = twist_rates(jac, twist, self._reach[chain])
        if sol.direction_error_deg > DIRECTION_TOLERANCE_DEG:
            why = (
                f"chain {chain} cannot move along the requested twist at this pose: the closest "
                f"motion it can make is {sol.direction_error_deg:.1f} degrees off "
                f"(tolerance {DIRECTION_TOLERANCE_DEG:g})"
            )
            if sol.singular:
                why += (
                    f"; the chain is at or near a singular configuration (smallest singular "
                    f"value {sol.sigma_min:.3g} m)"
                )
            elif len(idx) < 6:
                why += f"; a chain of {len(idx)} joints cannot follow every twist"
            return why
        qd_chain = sol.rates
        vlim = self._jog_limits()[0][idx]
        scale = float(np.max(np.abs(qd_chain) / vlim)) if qd_chain.size else 0.0
        if scale > 1.0:
            qd_chain = qd_chain / scale
        qd = np.zeros(self._joint_count)
        qd[idx] = qd_chain
        lo, hi = self._limits.lower, self._limits.upper
        for i in idx.tolist():
            if (qd[i] > 0.0 and q[i] >= hi[i]) or (qd[i] < 0.0 and q[i] <= lo[i]):
                side = "upper" if qd[i] > 0.0 else "lower"
                return (
                    f"chain {chain} cannot move along the requested twist: joint "
                    f"'{self._joint_names[i]}' is at its {side} limit"
                )
        return qd

    def _update_cartesian_jog(self, motion: JogMotion) -> None:
        """New joint rates for the twist at the commanded pose, and a look ahead.

        Why look ahead: braking takes time, and near a singular pose the rates that keep the tool
        on course change fast. The twist is also checked at the pose where the arm would come
        to rest if it braked now; if the tool could not follow it there, braking starts now,
        while the direction is still good.
        """
        assert self._jog_cartesian is not None
        chain, twist = self._jog_cartesian
        qd = self._cartesian_rates(chain, motion.q, twist)
        if isinstance(qd, str):
            self._stop_cartesian_jog(motion, qd)
            return
        v = motion.v
        if np.any(v):
            # All joints brake together (coordinated), each covering v t_stop / 2.
            t_stop = float(np.max(np.abs(v) / motion.amax))
            ahead = motion.q + v * (0.5 * t_stop + 2.0 * self._step_dt)
            lo, hi = self._limits.lower, self._limits.upper
            if np.any(ahead > hi) or np.any(ahead < lo):
                self._stop_cartesian_jog(motion, self._limit_reason(np.clip(ahead, lo, hi)))
                return
            later = self._cartesian_rates(chain, ahead, twist)
            if isinstance(later, str):
                self._stop_cartesian_jog(motion, later)
                return
        motion.target_velocity = qd
