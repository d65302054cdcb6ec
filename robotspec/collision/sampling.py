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
from collections.abc import Iterator

import numpy as np

from robotspec.arrays import F64
from robotspec.errors import CollisionError
from robotspec.model.world import ConnectionType, World

__all__ = [
    "BLOCK",
    "MAX_SAMPLES",
    "MAX_SEED",
    "RandomBlocks",
    "check_sampling",
    "default_configuration",
    "random_configurations",
    "sampling_bounds",
]

#: The most random configurations one run may ask for. Why a cap: memory no longer grows with
#: the count (samples are drawn in blocks), but time does, and ``-n 10**12`` is a typo, not a
#: plan: a billion samples of a PR2 take days. The CLI's ``--samples`` carries the same bound.
MAX_SAMPLES = 1_000_000_000
#: The largest seed: numpy's generators take any integer >= 0; a 64-bit one is what a user
#: can write down and reproduce (the CLI's ``--seed`` carries the same bound).
MAX_SEED = 2**64 - 1
#: Rows of one block of samples (what a worker gets at a time).
BLOCK = 500


def check_sampling(samples: int, seed: int) -> None:
    """Refuse a sample count or seed outside the bounds above (the message names the value)."""
    if not 0 <= samples <= MAX_SAMPLES:
        raise CollisionError(
            f"samples must be between 0 and {MAX_SAMPLES:,}, got {samples:,}", kind="config"
        )
    if not 0 <= seed <= MAX_SEED:
        raise CollisionError(f"seed must be between 0 and 2**64 - 1, got {seed}", kind="config")


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


class RandomBlocks:
    """``n`` random configurations drawn block by block, only when a block is asked for.

    Why: drawing every sample at once costs ``n * D * 8`` bytes (a MemoryError for ``n = 10**12``);
    blocks keep memory bounded whatever ``n`` is. The values are those of
    ``random_configurations(world, n, rng)``: a generator fills an array in order, so blocks
    drawn one after another from one generator continue the same stream. Iterate once: a second
    pass continues the generator (other values).
    """

    def __init__(self, world: World, n: int, rng: np.random.Generator, size: int = BLOCK) -> None:
        if n < 0:
            raise CollisionError(f"sample count must be >= 0, got {n}", kind="config")
        self.world, self.n, self.rng, self.size = world, n, rng, max(1, size)

    def __len__(self) -> int:
        """The number of blocks."""
        return -(-self.n // self.size)

    def __iter__(self) -> Iterator[F64]:
        for start in range(0, self.n, self.size):
            yield random_configurations(self.world, min(self.size, self.n - start), self.rng)
