"""What every ``disable_collisions`` entry of an SRDF really does (``collisions audit``).

Why: an SRDF's collision matrix is trusted blindly by MoveIt and by robotspec's checker, yet it
is usually generated once, for an older URDF, with too few samples, then edited by hand. An
entry can be inert (it names a link the URDF lacks, or one without collision geometry), a
duplicate, an ``Adjacent`` entry whose bodies are not adjacent, or, worst, a ``Never`` entry
whose bodies do collide: the planner then never sees that collision. The audit finds each, with a
witness configuration for the last kind, and lists the pairs a regenerated matrix would disable
that the SRDF does not.

A witness sets only the joints between the two bodies (every other joint at the default pose),
since nothing else moves one body relative to the other; it is printed as ``JOINT=VALUE`` values
that ``robotspec collisions check --q`` and ``robotspec render --q`` load. It is *valid* when no
pair the SRDF leaves checked collides in it: a planner would accept that configuration.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from robotspec.arrays import F64
from robotspec.collision.checker import SelfCollisionChecker
from robotspec.collision.convergence import SrdfComparison, compare_with_srdf
from robotspec.collision.matrix import CollisionMatrix, generate_for_robot
from robotspec.collision.rules import ADJACENT, NEVER, CollisionRules, adjacent_pairs, pair_key
from robotspec.collision.sampling import RandomBlocks, check_sampling, default_configuration
from robotspec.collision.shapes import MissingMeshPolicy
from robotspec.errors import CollisionError
from robotspec.model.world import World
from robotspec.semantic.robot import AbstractRobot

__all__ = ["AuditEntry", "SrdfAudit", "audit_srdf"]


#: Verdicts, in the order the report lists them.
OK = "ok"
UNKNOWN = "unknown link"
NO_GEOMETRY = "no collision geometry"
SELF_PAIR = "same link twice"
DUPLICATE = "duplicate"
NOT_ADJACENT = "not adjacent"
COLLIDES = "collides"
INERT = (UNKNOWN, NO_GEOMETRY, SELF_PAIR)
WRONG = (NOT_ADJACENT, COLLIDES)
_WITNESS_CANDIDATES = 32
_ROUNDS = 4


@dataclass(frozen=True)
class AuditEntry:
    """One ``disable_collisions`` entry and what it does.

    ``witness`` (for ``collides``): joint values between the two bodies, applied over the default
    pose, in which they collide; ``valid`` says whether no SRDF-checked pair collides there.
    """

    link1: str
    link2: str
    reason: str | None
    line: int | None
    verdict: str
    detail: str = ""
    witness: Mapping[str, float] = field(default_factory=dict)
    valid: bool = False
    collisions: int = 0
    culprits: tuple[str, ...] = ()  # the unknown or geometry-less links of an inert entry


@dataclass(frozen=True)
class SrdfAudit:
    """The audit of one robot's SRDF."""

    robot: str
    srdf: str
    entries: tuple[AuditEntry, ...]
    missing: tuple[tuple[str, str, str, str], ...]  # link1, link2, matrix reason, why
    samples: int
    seed: int
    seconds: float
    comparison: SrdfComparison | None = None
    matrix: CollisionMatrix | None = None

    def count(self, *verdicts: str) -> int:
        """How many entries got one of ``verdicts``."""
        return sum(1 for e in self.entries if e.verdict in verdicts)

    @property
    def wrong(self) -> tuple[AuditEntry, ...]:
        """Entries that hide a collision or claim an adjacency that is not there."""
        return tuple(e for e in self.entries if e.verdict in WRONG)


def _pair_joints(world: World, a: str, b: str) -> list[str]:
    """Leader joints (by connection name) between two bodies: all that move one relative to b."""
    common = world.common_ancestor(a, b)
    names: dict[str, None] = {}
    for end in (a, b):
        for c in world.compute_chain_of_connections(common, end):
            if not c.is_fixed:
                for d in c.dofs:
                    names[world.degrees_of_freedom[d].connection] = None
    return list(names)


def _static(robot: AbstractRobot, world: World) -> list[AuditEntry]:
    """Verdicts that need no sampling: unknown, no geometry, same link, duplicate, adjacency."""
    srdf = robot.srdf
    assert srdf is not None
    geometry = {b.name for b in world.bodies if b.has_collision}
    adjacent = adjacent_pairs(world, geometry)
    first_line: dict[tuple[str, str], int | None] = {}
    out: list[AuditEntry] = []
    for d in srdf.disabled_collisions:
        key = pair_key(d.link1, d.link2)
        verdict, detail = OK, ""
        culprits: tuple[str, ...] = ()
        unknown = [x for x in (d.link1, d.link2) if not world.has_body(x)]
        bare = [x for x in dict.fromkeys((d.link1, d.link2)) if x not in geometry]
        if unknown:
            verdict, culprits = UNKNOWN, tuple(unknown)
            detail = ", ".join(f"'{x}'" for x in unknown) + " not in the URDF: the entry is inert"
        elif d.link1 == d.link2:
            verdict, detail = SELF_PAIR, "a body never collides with itself: the entry is inert"
            culprits = (d.link1,)
        elif bare:
            verdict, culprits = NO_GEOMETRY, tuple(bare)
            detail = (
                ", ".join(f"'{x}'" for x in bare) + " has no collision geometry: the entry is inert"
            )
        elif key in first_line:
            line = first_line[key]
            verdict = DUPLICATE
            detail = "the pair is already disabled" + (f" on line {line}" if line else "")
        elif d.reason == ADJACENT and key not in adjacent:
            verdict = NOT_ADJACENT
            joints = _pair_joints(world, d.link1, d.link2)
            detail = (
                f"no joint joins them (directly or through bodies without geometry); "
                f"{len(joints)} joints lie between them"
            )
        first_line.setdefault(key, d.line)
        out.append(
            AuditEntry(d.link1, d.link2, d.reason, d.line, verdict, detail, culprits=culprits)
        )
    return out


def _witnesses(
    robot: AbstractRobot,
    pairs: list[tuple[str, str]],
    samples: int,
    seed: int,
    on_missing_mesh: MissingMeshPolicy,
) -> dict[tuple[str, str], tuple[dict[str, float], bool, int]]:
    """Per pair: joint values in which it collides, whether they are valid, and hit count."""
    world = robot.world
    if not pairs:
        return {}
    bodies = tuple(dict.fromkeys(x for p in pairs for x in p))
    probe = SelfCollisionChecker(
        world, CollisionRules(bodies=bodies), pairs=pairs, on_missing_mesh=on_missing_mesh
    )
    rules = SelfCollisionChecker.from_robot(robot, on_missing_mesh=on_missing_mesh)
    base = default_configuration(world)
    rng = np.random.default_rng(seed)
    # Rare collisions may need more samples than the matrix drew: up to _ROUNDS rounds, each
    # testing only the pairs still without a witness.
    found_q: dict[int, F64] = {}
    counts: dict[int, int] = {}
    for _ in range(_ROUNDS if samples else 0):
        todo = [j for j in range(len(probe.active_pairs)) if j not in found_q]
        if not todo:
            break
        # Block by block (memory flat whatever ``samples`` is); each pair keeps the round's
        # first candidates, as if the round were drawn at once.
        cols = np.array(todo, dtype=np.intp)
        kept: dict[int, list[F64]] = {}
        for qs in RandomBlocks(world, samples, rng):
            hits = probe.collisions_batch(qs)[:, cols]
            for col in np.flatnonzero(hits.any(axis=0)).tolist():
                j = todo[col]
                rows = np.flatnonzero(hits[:, col])
                counts[j] = counts.get(j, 0) + int(len(rows))
                have = kept.setdefault(j, [])
                room = _WITNESS_CANDIDATES - sum(len(a) for a in have)
                if room > 0:
                    have.append(qs[rows[:room]])
        for j in todo:
            counts.setdefault(j, 0)
        for j, parts in kept.items():
            found_q[j] = np.concatenate(parts)
    out: dict[tuple[str, str], tuple[dict[str, float], bool, int]] = {}
    for j, (a, b) in enumerate(probe.active_pairs):
        if j not in found_q:
            continue
        rows_q = found_q[j]
        joints = _pair_joints(world, a, b)
        idx = [world.get_connection_by_name(n).dofs[0] for n in joints]
        cands = np.repeat(base[None], len(rows_q), axis=0)
        cands[:, idx] = rows_q[:, idx]
        bad = rules.in_collision_batch(cands) if rules.active_pairs else np.zeros(len(cands), bool)
        pick = int(np.argmin(bad))  # the first valid candidate, else the first
        witness = {n: float(cands[pick, i]) for n, i in zip(joints, idx, strict=True)}
        out[pair_key(a, b)] = (witness, not bool(bad[pick]), counts[j])
    return out


def audit_srdf(
    robot: AbstractRobot,
    *,
    samples: int = 10_000,
    seed: int = 0,
    processes: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    on_missing_mesh: MissingMeshPolicy = "error",
    regenerate: bool = True,
) -> SrdfAudit:
    """Audit ``robot``'s SRDF: every entry's verdict, and the pairs a new matrix would add.

    "Never" verdicts come from a regenerated matrix (``samples`` random configurations, the
    generator's seed); witnesses from ``samples`` further configurations (seed ``seed + 1``).
    """
    check_sampling(samples, seed)
    srdf = robot.srdf
    if srdf is None:
        raise CollisionError(f"robot '{robot.name}' has no SRDF to audit", kind="srdf")
    started = time.perf_counter()
    world = robot.world
    entries = _static(robot, world)
    matrix = None
    comparison = None
    never = [e for e in entries if e.verdict == OK and e.reason == NEVER]
    colliding: list[tuple[str, str]] = []
    if regenerate:
        matrix = generate_for_robot(
            robot,
            samples=samples,
            seed=seed,
            processes=processes,
            progress=progress,
            on_missing_mesh=on_missing_mesh,
        )
        name = (srdf.file or "the SRDF").rsplit("/", 1)[-1]
        comparison = compare_with_srdf(matrix, srdf, name)
        hit = {pair_key(a, b) for a, b in _checked_or_hit(matrix)}
        colliding = [(e.link1, e.link2) for e in never if pair_key(e.link1, e.link2) in hit]
    found = _witnesses(robot, colliding, samples, seed + 1, on_missing_mesh)
    wrong = {pair_key(*p) for p in colliding}
    out: list[AuditEntry] = []
    for e in entries:
        key = pair_key(e.link1, e.link2)
        if e.verdict == OK and e.reason == NEVER and key in wrong:
            w = found.get(key)
            where = _matrix_text(matrix, key)
            if w is None:
                e = AuditEntry(
                    e.link1,
                    e.link2,
                    e.reason,
                    e.line,
                    COLLIDES,
                    f"{where}; no witness in {_ROUNDS * samples:,} more samples",
                )
            else:
                witness, valid, hits = w
                e = AuditEntry(
                    e.link1,
                    e.link2,
                    e.reason,
                    e.line,
                    COLLIDES,
                    f"{where}; witness below" + (" (valid)" if valid else ""),
                    witness,
                    valid,
                    hits,
                )
        out.append(e)
    missing: tuple[tuple[str, str, str, str], ...] = ()
    if comparison is not None:
        missing = tuple(
            (d.link1, d.link2, d.reason, d.why)
            for d in comparison.differences
            if d.side == "matrix only"
        )
    return SrdfAudit(
        robot=robot.name,
        srdf=srdf.file or "",
        entries=tuple(out),
        missing=missing,
        samples=samples,
        seed=seed,
        seconds=time.perf_counter() - started,
        comparison=comparison,
        matrix=matrix,
    )


def _checked_or_hit(matrix: CollisionMatrix) -> list[tuple[str, str]]:
    """Pairs the matrix saw colliding: those it keeps checked, and its Default/Always pairs."""
    hit = [(e.link1, e.link2) for e in matrix.disabled if e.reason not in (NEVER, ADJACENT)]
    return [*matrix.checked, *hit]


def _matrix_text(matrix: CollisionMatrix | None, key: tuple[str, str]) -> str:
    if matrix is None:
        return "collides"
    for e in matrix.disabled:
        if pair_key(e.link1, e.link2) == key:
            if e.reason == "Default":
                return "collides at the default configuration"
            return f"collides in {e.collisions} of {e.samples} samples ({e.reason})"
    start = {(a, b): s for a, b, s in matrix.first_collision}.get(key)
    first = "" if start is None else f", first in samples from {start:,}"
    return f"collides in the matrix's samples{first}"
