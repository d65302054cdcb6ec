"""Joint rates for a Cartesian jog: damped least squares, and whether the request is possible.

Why a check and not just a damped solve: near a singular pose (Baxter's straight arm at q = 0, a
UR's wrist singularity) the damped least-squares rates move the tool somewhere else than asked --
+x became mostly +z on Baxter. A driver must then refuse, not move the tool the wrong way. The
solve reports how far the motion it can make is from the one requested (an angle in the weighted
twist space), and the driver refuses when that exceeds :data:`DIRECTION_TOLERANCE_DEG`.

Weighting: a twist mixes rad/s and m/s. The angular rows are scaled by the chain's reach ``L``
(metres), so a 1 rad/s turn weighs as much as the tool moving ``L`` m/s -- what the tool point of
an arm of that size does; the result does not depend on the choice of units.

Damping (Nakamura and Hanafusa, Maciejewski and Klein): no damping while the smallest singular
value of the weighted Jacobian is above ``SINGULAR_FRACTION * L``, then a damping that grows
smoothly to ``DAMPING_FRACTION * L`` at the singularity, so rates stay bounded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robotspec.arrays import F64

__all__ = ["DIRECTION_TOLERANCE_DEG", "TwistRates", "chain_reach", "twist_rates"]


#: A Cartesian jog is refused (or stopped) when the achievable motion is further than this from
#: the requested one, in degrees of the weighted twist space.
DIRECTION_TOLERANCE_DEG = 3.0
#: Damping starts below this smallest singular value (a fraction of the chain's reach).
SINGULAR_FRACTION = 0.02
#: The damping at a singularity (a fraction of the chain's reach).
DAMPING_FRACTION = 0.02


@dataclass(frozen=True)
class TwistRates:
    """Joint rates for a twist and how well they achieve it."""

    rates: F64
    #: Angle between the achieved and the requested twist (weighted), degrees.
    direction_error_deg: float
    #: Smallest singular value of the weighted Jacobian, metres per radian (or metre).
    sigma_min: float
    #: The chain's reach used for weighting, metres.
    reach: float

    @property
    def singular(self) -> bool:
        """Whether the pose is in the damped (near-singular) zone."""
        return self.sigma_min < SINGULAR_FRACTION * self.reach


def chain_reach(p: F64, flange_position: F64) -> float:
    """A characteristic length of a chain: the sum of its link offsets after the base (metres)."""
    links = float(np.sum(np.linalg.norm(p[1:], axis=1))) if p.shape[0] > 1 else 0.0
    reach = links + float(np.linalg.norm(flange_position))
    return reach if reach > 1e-3 else 1.0


def twist_rates(jacobian: F64, twist: F64, reach: float) -> TwistRates:
    """Joint rates moving the TCP along ``twist`` ``[wx, wy, wz, vx, vy, vz]`` (base frame).

    ``jacobian`` is ``(6, n)``, angular rows first. A zero twist gives zero rates and no error.
    """
    w = np.array([reach, reach, reach, 1.0, 1.0, 1.0])
    jw = jacobian * w[:, None]
    xw = twist * w
    n = jacobian.shape[1]
    if n == 0:
        return TwistRates(np.zeros(0), 180.0 if np.any(twist) else 0.0, 0.0, reach)
    u, s, vt = np.linalg.svd(jw, full_matrices=False)
    s_min = float(s[-1])
    eps = SINGULAR_FRACTION * reach
    lam2 = 0.0
    if s_min < eps:
        lam2 = (1.0 - (s_min / eps) ** 2) * (DAMPING_FRACTION * reach) ** 2
    safe = np.where(s > 0.0, s, 1.0)
    inv = s / (s * s + lam2) if lam2 > 0.0 else np.where(s > 0.0, 1.0 / safe, 0.0)
    rates: F64 = vt.T @ (inv * (u.T @ xw))
    norm_req = float(np.linalg.norm(xw))
    if norm_req == 0.0:
        return TwistRates(np.zeros(n), 0.0, s_min, reach)
    achieved = jw @ rates
    norm_ach = float(np.linalg.norm(achieved))
    if norm_ach == 0.0:
        return TwistRates(rates, 180.0, s_min, reach)
    cos = float(achieved @ xw) / (norm_ach * norm_req)
    angle = math.degrees(math.acos(max(-1.0, min(1.0, cos))))
    return TwistRates(rates, angle, s_min, reach)
