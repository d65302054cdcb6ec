"""Configurations for collision queries: the default pose and seeded random ones.

Why MoveIt's rules: the collision matrix is compared with SRDFs written by MoveIt's Setup
Assistant, so "default" and "random" mean what they mean there. The default value of a joint is
0 when its limits allow it and the middle of its range otherwise; random values are uniform over
the limits, ``[-pi, pi]`` for an unbounded revolute (continuous) joint, and 0 for unbounded
translations and multi-DOF base joints (they move the whole robot rigidly, so self-collision
does not depend on them). Mimic joints follow their leader through the world's kinematics.
"""

from __future__ import annotations

import math

import numpy as np

from robotspec.arrays import F64
from robotspec.errors import CollisionError
from robotspec.model.world import ConnectionType, World

__all__ = [
    "default_configuration",
    "random_configurations",
    "sampling_bounds",
]


def sampling_bounds(world: World) -> tuple[F64, F64]:
    """Lower and upper bounds (D,) that random configurations are drawn from."""
    lo = np.zeros(len(world.degrees_of_freedom))
    hi = np.zeros(len(world.degrees_of_freedom))
    for d in world.degrees_of_freedom:
        conn = world.get_connection_by_name(d.connection)
        if d.is_bounded:
            lo[d.index], hi[d.index] = d.lower, d.upper
        elif conn.type in (ConnectionType.REVOLUTE, ConnectionType.CONTINUOUS):
            lo[d.index] = max(d.lower, -math.pi)
            hi[d.index] = min(d.upper, math.pi)
    return lo, hi


def default_configuration(world: World) -> F64:
    """MoveIt's default state (:meth:`World.default_configuration`), the start of every sample."""
    return world.default_configuration()


def random_configurations(world: World, n: int, seed: int | np.random.Generator = 0) -> F64:
    """``n`` configurations (n, D) uniform over :func:`sampling_bounds`, reproducible by seed."""
    if n < 0:
        raise CollisionError(f"sample count must be >= 0, got {n}", kind="config")
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    lo, hi = sampling_bounds(world)
    out: F64 = lo + (hi - lo) * rng.random((n, len(lo)))
    return out
