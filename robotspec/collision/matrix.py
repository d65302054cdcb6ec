"""Collision matrix generation: which body pairs never need checking (MoveIt Setup Assistant's job).

The steps and reason words are the Setup Assistant's (``compute_default_collisions.cpp``):

1. ``Adjacent``: bodies joined by a joint, or only through bodies without geometry
   (:func:`~robotspec.collision.rules.adjacent_pairs`).
2. ``Default``: pairs in collision at the default configuration (0, or mid-range where 0 is out of
   limits).
3. ``Always``: pairs in collision in at least ``always_fraction`` (95 %) of a round of 200 random
   configurations; rounds repeat until one finds no new pair.
4. ``Never``: pairs in collision in none of ``samples`` random configurations (10,000 by default).

What it does better: every sample comes from one seeded generator drawn in the parent, so a run is
reproducible and independent of the number of processes; the "Never" pass uses every core and
stops testing a pair the moment it is seen colliding (the question is only *whether* it ever
collides), behind an exact oriented-box broad phase; pairs keep their counts (how often an
``Always`` pair collided), and mesh problems are errors or reported skips, never silent.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from robotspec.collision.checker import SelfCollisionChecker
from robotspec.collision.parallel import ever_colliding_parallel, used_processes
from robotspec.collision.rules import (
    ADJACENT,
    ALWAYS,
    DEFAULT,
    NEVER,
    CollisionRules,
    adjacent_pairs,
    pair_key,
)
from robotspec.collision.sampling import (
    RandomBlocks,
    check_sampling,
    default_configuration,
    random_configurations,
)
from robotspec.collision.shapes import MeshLibrary, MissingMeshPolicy
from robotspec.errors import CollisionError, RobotSpecError
from robotspec.model.world import World

if TYPE_CHECKING:
    from robotspec.description.srdf import DisabledCollision, Srdf
    from robotspec.semantic.robot import AbstractRobot

__all__ = [
    "CollisionMatrix",
    "MatrixEntry",
    "compare_pairs",
    "generate_collision_matrix",
    "generate_for_robot",
]

#: The Setup Assistant's round size and threshold for "always in collision".
ALWAYS_ROUND = 200
ALWAYS_FRACTION = 0.95
_MAX_ALWAYS_ROUNDS = 20


@dataclass(frozen=True)
class MatrixEntry:
    """A pair the matrix disables, why, and how often it collided in the samples that decided.

    ``link1 < link2`` alphabetically, as MoveIt writes them.
    """

    link1: str
    link2: str
    reason: str
    collisions: int = 0
    samples: int = 0


@dataclass(frozen=True)
class CollisionMatrix:
    """The result of :func:`generate_collision_matrix`.

    ``disabled`` are the pairs to write as SRDF ``disable_collisions``; ``checked`` the pairs that
    collide only sometimes and must stay checked. ``skipped`` lists meshes left out (reported
    skips) when the caller asked for them.
    """

    robot_name: str
    bodies: tuple[str, ...]
    disabled: tuple[MatrixEntry, ...]
    checked: tuple[tuple[str, str], ...]
    samples: int
    seed: int
    always_samples: int
    #: Worker processes the "Never" pass used: the ones asked for, at most the CPUs and the
    #: blocks of samples (what ran, not what was asked).
    processes: int
    seconds: float
    skipped: tuple[RobotSpecError, ...] = ()
    #: Pairs the "Never" pass saw colliding, with the index of the first sample (chunk
    #: resolution: the chunk's first sample) in which they did; see :mod:`.convergence`.
    first_collision: tuple[tuple[str, str, int], ...] = ()

    def count(self, reason: str) -> int:
        """How many pairs were disabled for ``reason``."""
        return sum(1 for e in self.disabled if e.reason == reason)

    def reasons(self) -> dict[str, int]:
        """Pair counts by reason, in MoveIt's order."""
        return {r: self.count(r) for r in (ADJACENT, DEFAULT, ALWAYS, NEVER)}

    def disabled_pairs(self, reasons: Iterable[str] | None = None) -> frozenset[frozenset[str]]:
        """The disabled pairs (of the given reasons), unordered."""
        wanted = None if reasons is None else set(reasons)
        return frozenset(
            frozenset((e.link1, e.link2))
            for e in self.disabled
            if wanted is None or e.reason in wanted
        )

    def disabled_collisions(self) -> tuple[DisabledCollision, ...]:
        """The entries as SRDF records."""
        from robotspec.description.srdf import DisabledCollision

        return tuple(DisabledCollision(e.link1, e.link2, e.reason) for e in self.disabled)

    def to_srdf(self, base: Srdf | None = None, *, merge: bool = True) -> Srdf:
        """An SRDF holding the matrix.

        Without ``base``: a new SRDF with only the ``disable_collisions``. With ``base`` and
        ``merge``: ``base`` with the generated pairs it lacks appended (its own entries, and their
        reasons, win). With ``base`` and not ``merge``: ``base`` with its ``disable_collisions``
        replaced by the matrix (what the Setup Assistant does when it regenerates).
        """
        from robotspec.description.srdf import Srdf

        generated = self.disabled_collisions()
        if base is None:
            return Srdf(robot_name=self.robot_name, disabled_collisions=generated)
        if not merge:
            return replace(base, disabled_collisions=generated)
        have = {frozenset((d.link1, d.link2)) for d in base.disabled_collisions}
        added = tuple(d for d in generated if frozenset((d.link1, d.link2)) not in have)
        return replace(base, disabled_collisions=(*base.disabled_collisions, *added))


def compare_pairs(
    generated: frozenset[frozenset[str]], reference: frozenset[frozenset[str]]
) -> tuple[float, float]:
    """Precision and recall of ``generated`` disabled pairs against ``reference``."""
    common = len(generated & reference)
    precision = common / len(generated) if generated else 1.0
    recall = common / len(reference) if reference else 1.0
    return precision, recall


def generate_collision_matrix(
    world: World,
    bodies: Sequence[str] | None = None,
    *,
    robot_name: str | None = None,
    samples: int = 10_000,
    seed: int = 0,
    always_fraction: float = ALWAYS_FRACTION,
    processes: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    meshes: MeshLibrary | None = None,
    on_missing_mesh: MissingMeshPolicy = "error",
    start_method: str | None = None,
) -> CollisionMatrix:
    """Compute the disabled pairs of ``bodies`` (default: every body with collision geometry).

    ``progress(done, total)`` is called as samples complete (total = every sample drawn).
    """
    check_sampling(samples, seed)
    if not 0.0 < always_fraction <= 1.0:
        raise CollisionError(
            f"always_fraction must be in (0, 1], got {always_fraction}", kind="config"
        )
    started = time.perf_counter()
    names = _body_names(world, bodies)
    pairs = [(a, b) for i, a in enumerate(names) for b in names[i + 1 :]]
    checker = SelfCollisionChecker(
        world,
        CollisionRules(bodies=names),
        pairs=pairs,
        meshes=meshes,
        on_missing_mesh=on_missing_mesh,
    )
    pairs = list(checker.active_pairs)
    verdict: dict[int, MatrixEntry] = {}

    def decide(k: int, reason: str, collisions: int = 0, n: int = 0) -> None:
        a, b = sorted(pairs[k])
        verdict[k] = MatrixEntry(a, b, reason, collisions, n)

    adjacent = adjacent_pairs(world, names)
    for k, (a, b) in enumerate(pairs):
        if pair_key(a, b) in adjacent:
            decide(k, ADJACENT)
    undecided = np.array([k not in verdict for k in range(len(pairs))], dtype=np.bool_)

    # Decided pairs are not tested again: adjacent ones are the costliest to test (their meshes
    # touch or nearly touch in every configuration).
    hits = checker.collisions_batch(default_configuration(world)[None], pair_mask=undecided)[0]
    for k in np.flatnonzero(hits & undecided).tolist():
        decide(k, DEFAULT, 1, 1)
    undecided &= ~hits

    rng = np.random.default_rng(seed)
    ticks = _Progress(progress, samples + ALWAYS_ROUND)
    limit = math.ceil(always_fraction * ALWAYS_ROUND - 1e-9)
    always_drawn = _always_pass(checker, world, rng, undecided, limit, decide, ticks)

    ever, first, procs = _never_pass(
        checker, world, rng, samples, undecided, processes, on_missing_mesh, start_method, ticks
    )
    for k in np.flatnonzero(undecided & ~ever).tolist():
        decide(k, NEVER, 0, samples)
    entries = tuple(sorted(verdict.values(), key=lambda e: (e.link1, e.link2)))
    checked = tuple(pairs[k] for k in range(len(pairs)) if k not in verdict)
    return CollisionMatrix(
        robot_name=robot_name or world.name,
        bodies=names,
        disabled=entries,
        checked=checked,
        samples=samples,
        seed=seed,
        always_samples=always_drawn,
        processes=procs,
        seconds=time.perf_counter() - started,
        skipped=tuple(checker.skipped),
        first_collision=tuple((*pair_key(*pairs[k]), start) for k, start in sorted(first.items())),
    )


@dataclass
class _Progress:
    """Samples done of the total expected (which grows with each further round of "always")."""

    report: Callable[[int, int], None] | None
    total: int
    done: int = 0

    def tick(self, n: int) -> None:
        self.done += n
        if self.report is not None:
            self.report(self.done, self.total)


def _always_pass(
    checker: SelfCollisionChecker,
    world: World,
    rng: np.random.Generator,
    undecided: NDArray[np.bool_],
    limit: int,
    decide: Callable[[int, str, int, int], None],
    ticks: _Progress,
) -> int:
    """Rounds of samples deciding the pairs that collide in nearly all of them; samples drawn.

    Rounds are drawn until one finds no new such pair (at most ``_MAX_ALWAYS_ROUNDS``); each
    adds its samples to the progress total. ``undecided`` loses the pairs decided.
    """
    drawn = 0
    for _ in range(_MAX_ALWAYS_ROUNDS):
        qs = random_configurations(world, ALWAYS_ROUND, rng)
        drawn += ALWAYS_ROUND
        counts = checker.collisions_batch(qs, pair_mask=undecided).sum(axis=0)
        ticks.tick(ALWAYS_ROUND)
        found = np.flatnonzero(undecided & (counts >= limit))
        for k in found.tolist():
            decide(k, ALWAYS, int(counts[k]), ALWAYS_ROUND)
        undecided[found] = False
        if not len(found):
            break
        ticks.total += ALWAYS_ROUND
    return drawn


def _body_names(world: World, bodies: Sequence[str] | None) -> tuple[str, ...]:
    """The bodies the matrix covers, in the world's order: default every body with geometry."""
    if bodies is None:
        return tuple(b.name for b in world.bodies if b.has_collision)
    return tuple(sorted(set(bodies), key=lambda b: world.get_body_by_name(b).index))


def _never_pass(
    checker: SelfCollisionChecker,
    world: World,
    rng: np.random.Generator,
    samples: int,
    undecided: NDArray[np.bool_],
    processes: int | None,
    on_missing_mesh: MissingMeshPolicy,
    start_method: str | None,
    ticks: _Progress,
) -> tuple[NDArray[np.bool_], dict[int, int], int]:
    """The "Never" pass: which undecided pairs ever collide in ``samples`` configurations.

    Returns the pairs seen colliding (a mask), the first sample (chunk resolution) each was seen
    in, and the worker processes used. Samples are drawn block by block as the workers ask, so
    memory stays flat whatever ``samples`` is; ``undecided`` is not changed.
    """
    blocks = RandomBlocks(world, samples, rng)
    procs = used_processes(processes, len(blocks))
    first: dict[int, int] = {}

    def seen(start: int, hits: NDArray[np.bool_]) -> None:
        for k in np.flatnonzero(hits).tolist():
            first.setdefault(k, start)

    ever = ever_colliding_parallel(
        checker,
        blocks,
        undecided.copy(),
        processes=procs,
        on_missing_mesh=on_missing_mesh,
        start_method=start_method,
        progress=ticks.tick,
        on_chunk=seen,
    )
    return ever, first, procs


def generate_for_robot(
    robot: AbstractRobot,
    *,
    samples: int = 10_000,
    seed: int = 0,
    processes: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    on_missing_mesh: MissingMeshPolicy = "error",
) -> CollisionMatrix:
    """:func:`generate_collision_matrix` over the robot's bodies with collision geometry.

    The robot's own rules (its SRDF) are not used: the matrix is what they are compared with.
    """
    bodies = [b.name for b in robot.bodies_with_collisions]
    name = robot.srdf.robot_name if robot.srdf is not None else robot.name
    return generate_collision_matrix(
        robot.world,
        bodies,
        robot_name=name,
        samples=samples,
        seed=seed,
        processes=processes,
        progress=progress,
        on_missing_mesh=on_missing_mesh,
    )
