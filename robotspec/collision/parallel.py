"""Worker processes for sampling-heavy collision work (the matrix generator's "Never" pass).

Under ``fork`` a worker adopts the parent's built checker (its memory is the parent's). Under
``spawn`` or ``forkserver`` it shares nothing with its parent and coal objects cannot be pickled,
so it gets :class:`CheckerInputs` (plain frozen records: the world's bodies, joints and DOFs, and
the pairs) and builds its own checker once. Either way the answers are the same.
"""

from __future__ import annotations

import multiprocessing
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from multiprocessing.pool import AsyncResult
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotspec.arrays import F64
from robotspec.collision.checker import SelfCollisionChecker
from robotspec.collision.rules import CollisionRules
from robotspec.collision.sampling import RandomBlocks
from robotspec.collision.shapes import MissingMeshPolicy
from robotspec.model.kinematics import available_cpus
from robotspec.model.world import Body, Connection, DegreeOfFreedom, World

__all__ = ["CheckerInputs", "default_processes", "ever_colliding_parallel", "used_processes"]

Bools = NDArray[np.bool_]


@dataclass(frozen=True)
class CheckerInputs:
    """Everything a worker needs to rebuild a checker; picklable."""

    name: str
    source: str | None
    bodies: tuple[Body, ...]
    connections: tuple[Connection, ...]
    dofs: tuple[DegreeOfFreedom, ...]
    pairs: tuple[tuple[str, str], ...]
    on_missing_mesh: MissingMeshPolicy = "error"

    @classmethod
    def of(cls, checker: SelfCollisionChecker, on_missing_mesh: MissingMeshPolicy) -> CheckerInputs:
        """The inputs that rebuild ``checker`` (its world and its pairs, no rules needed)."""
        w = checker.world
        return cls(
            name=w.name,
            source=w.source,
            bodies=w.bodies,
            connections=w.connections,
            dofs=w.degrees_of_freedom,
            pairs=checker.active_pairs,
            on_missing_mesh=on_missing_mesh,
        )

    def build(self) -> SelfCollisionChecker:
        """A checker equal to the one the inputs were taken from."""
        world = World(self.name, self.bodies, self.connections, self.dofs, source=self.source)
        bodies = tuple(dict.fromkeys(b for p in self.pairs for b in p))
        return SelfCollisionChecker(
            world,
            CollisionRules(bodies=bodies),
            pairs=self.pairs,
            on_missing_mesh=self.on_missing_mesh,
        )


#: One checker per worker process, built by the pool initializer. Only worker processes write
#: it; the parent never reads it.
_WORKER_STATE: dict[str, SelfCollisionChecker] = {}


def _init_worker(inputs: CheckerInputs) -> None:
    _WORKER_STATE["checker"] = inputs.build()


def _adopt_checker(checker: SelfCollisionChecker) -> None:
    _WORKER_STATE["checker"] = checker


def _ever_colliding_task(qs: F64, mask: Bools, margin: float) -> Bools:
    return _WORKER_STATE["checker"].ever_colliding(qs, pair_mask=mask, margin=margin)


def default_processes() -> int:
    """The CPUs this process may run on."""
    return available_cpus()


def used_processes(asked: int | None, chunks: int) -> int:
    """Workers worth starting: ``asked`` (default: the CPUs), at most the CPUs and the chunks.

    Why: a worker per chunk is the most that can run at once, and more workers than CPUs only
    share them (each forked worker also holds its own copy of what it touches). ``--jobs 64``
    for two chunks of work starts at most two.
    """
    cpus = default_processes()
    wanted = cpus if asked is None else asked
    return max(1, min(wanted, cpus, chunks))


def ever_colliding_parallel(
    checker: SelfCollisionChecker,
    qs: F64 | RandomBlocks,
    mask: Bools,
    *,
    processes: int,
    chunk: int = 500,
    margin: float = 0.0,
    on_missing_mesh: MissingMeshPolicy = "error",
    start_method: str | None = None,
    progress: Callable[[int], None] | None = None,
    on_chunk: Callable[[int, Bools], None] | None = None,
) -> Bools:
    """Per pair: whether it collides in any configuration of ``qs``, among pairs in ``mask``.

    Chunks go to ``processes`` workers; each chunk is sent with the pairs not yet seen colliding,
    so the work shrinks as the run goes. The answer is a union over chunks, so it does not depend
    on the number of processes or on the order chunks finish in. ``on_chunk(start, hits)`` sees
    each chunk's result in sample order (``start`` = its first sample's index), so a caller can
    tell when each pair was first seen colliding (the matrix's convergence report).

    ``qs`` is an array (split in chunks of ``chunk`` rows) or :class:`RandomBlocks` (drawn block
    by block as workers ask, so memory does not grow with the sample count). Workers are at most
    :func:`used_processes` of ``processes``: never more than the CPUs or the chunks.
    """
    ever = np.zeros(len(checker.active_pairs), dtype=np.bool_)
    if isinstance(qs, np.ndarray):
        arr = qs
        count = -(-len(arr) // max(1, chunk))
        chunks: Iterable[F64] = (arr[i : i + chunk] for i in range(0, len(arr), max(1, chunk)))
    else:
        count, chunks = len(qs), qs
    processes = used_processes(processes, count)
    if processes <= 1:
        done = 0
        for block in chunks:
            hits = checker.ever_colliding(block, pair_mask=mask & ~ever, margin=margin)
            if on_chunk is not None:
                on_chunk(done, hits & ~ever)
            done += len(block)
            ever |= hits
            if progress is not None:
                progress(len(block))
        return ever
    ctx = multiprocessing.get_context(start_method)
    init: Callable[..., None]
    args: tuple[object, ...]
    if ctx.get_start_method() == "fork":
        # A forked worker starts with the parent's memory: it adopts the built checker (meshes
        # read, trees built) instead of reading every mesh again, which cost each worker as much
        # as a fifth of a PR2 matrix. Nothing is pickled on this path.
        checker.geometry  # noqa: B018 - build before forking, so the workers share it
        init, args = _adopt_checker, (checker,)
    else:
        init, args = _init_worker, (CheckerInputs.of(checker, on_missing_mesh),)
    pending: deque[tuple[int, AsyncResult[Any]]] = deque()
    with ctx.Pool(processes, initializer=init, initargs=args) as pool:
        todo: Iterator[F64] = iter(chunks)
        more = True
        done = 0
        while more or pending:
            while more and len(pending) < 2 * processes:
                part = next(todo, None)
                if part is None:
                    more = False
                    break
                task = pool.apply_async(_ever_colliding_task, (part, mask & ~ever, margin))
                pending.append((len(part), task))
            size, task = pending.popleft()
            hits = task.get()
            if on_chunk is not None:
                on_chunk(done, hits & ~ever)
            done += size
            ever |= hits
            if progress is not None:
                progress(size)
    return ever
