"""What a user without the C accelerators pays: the numpy fallbacks against the C cores, one run.

Run: ``python benchmarks/bench_fallback.py [--robot pr2] [--batch 2000] [--samples 2000] [--cpu]
[--json]`` (needs the dev extra: example-robot-data, coal; and the C cores built, to compare with).

Ours is the public API on the pure-Python cores (``robotspec/model/_kincore_py.py``,
``robotspec/collision/_meshcore_py.py``: what ``ROBOTSPEC_NO_ACCEL=1`` or an install without a
compiler runs); the peer is the same call on the C cores (``_kincore.c``, ``_meshcore.c``). Both
sides are built separately in this process, their answers compared before anything is timed, and
timed in turns (rows.median_times). Ratio = C time / fallback time: the fraction of the
accelerated speed a user without a compiler gets. The collision matrix (the ``robotspec
collisions generate`` path) runs in this process (``processes=1``) on each side once.

``--cpu`` times each call by this thread's CPU time (``time.thread_time``) instead of the wall
clock: on a machine other processes keep busy, the wall clock counts the time this process waited
for a CPU, which the numpy side (several times longer, more memory traffic) suffers more than the C
side; the CPU time counts the work. Every call compared runs on this one thread (``threads=1``,
``processes=1``), so nothing is left out. Give the load (``uptime``) with any figure.

What a user without the cores gets (the README's table has the figures): a batch of FKs at about
half the C speed or a little more (it is bound by memory: a batch of 2,000 PR2 configurations is
21 MB of poses; its steps run numpy calls bound once per batch, ``_kintree_plan.py``), single
configurations at a few percent (numpy's fixed cost per operation, paid per call), the collision
matrix at 0.4-0.5 and a batch of collision queries at about a third. Why collisions stay there:
the fallback's answers come from coal, one Python call per broad-phase candidate, and the C
core's mesh proofs are what spare those calls. On the PR2 a batch of 64 leaves 444 candidates;
coal turns a free one away in a few microseconds but takes about six times as long on one that
collides (93 of them), and FK and the broad phase of the 64 take about as long again as coal
(1.8 and 2.0 ms of 8.3). The matrix spends nearly all its coal time on pairs that nearly touch
and never collide; there the fallback has proofs of its own (``collision/free_balls.py``): a
coal distance at one pose proves the pair free at every pose that moves no point of the mesh by
that much, so a pair whose relative pose turns on one or two joints (the PR2's shoulder against
its upper arm, its fingers) is settled by some 80 distances for 2,000 samples; the forearm
against the palm (two joints, 0.3-2.7 mm apart) is left to coal, about 1 s of the 2.5. Measured
and not kept (issue 34): the meshes' own oriented boxes, tested for every candidate at once,
prove a third of the free candidates, for what coal's quick rejection of those far pairs costs;
descending box trees to the triangles, as the C core does, proves the touching and crossing
pairs but costs ten times the coal calls it removes; convex hulls along the centre line prove
fewer still; triangle pairs coal named in earlier collisions prove 4 of the batch's 93 colliding
candidates on fresh configurations; the hulls of each mesh and of its halves (up to 8x8) do not
separate the matrix's six costliest pairs (they nest 0.4-12 mm apart); crossing proofs (a piece
of one mesh's surface with a vertex in a cell inside the other, closed mesh and one outside its
box must cross its surface) prove 27-33 of the batch's 93 colliding candidates, never wrongly,
but half the PR2's meshes are open and the numpy pass costs what the coal calls it spares
(collisions_batch 0.97x, in_collision_batch 0.78x, interleaved); coal's distance lower bound
from collision calls, its ``rel_err``, a security margin as a cheap distance and OBB instead of
OBBRSS gained nothing. So the batch's fallback proves nothing and asks coal.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from types import ModuleType
from typing import Any

import numpy as np
from rows import Row, add_json_flag, median_times, print_rows


def median_cpu_times(fns: list[Callable[[], object]], repeat: int) -> list[float]:
    """:func:`rows.median_times` timed by this thread's CPU time (see ``--cpu``)."""
    for fn in fns:
        fn()
    times: list[list[float]] = [[] for _ in fns]
    for _ in range(repeat):
        for fn, out in zip(fns, times, strict=True):
            t = time.thread_time()
            fn()
            out.append(time.thread_time() - t)
    return [sorted(t)[len(t) // 2] for t in times]


@contextmanager
def using(kin: ModuleType, mesh: ModuleType) -> Iterator[None]:
    """Run with the given cores (the dispatch's choice, restored after)."""
    from robotspec.accel import using as use_cores
    from robotspec.collision import meshcore
    from robotspec.model import kincore

    with use_cores((kincore.CHOICE, kin), (meshcore.CHOICE, mesh)):
        yield


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--robot", default="pr2", help="a shipped robot (example-robot-data)")
    parser.add_argument("--batch", type=int, default=2000, help="configurations per FK batch")
    parser.add_argument("--samples", type=int, default=2000, help="collision matrix samples")
    parser.add_argument("--rounds", type=int, default=15, help="timing rounds (medians)")
    parser.add_argument("--cpu", action="store_true", help="time by this thread's CPU time")
    add_json_flag(parser)
    args = parser.parse_args()

    from robotspec.collision import SelfCollisionChecker, random_configurations
    from robotspec.collision import _meshcore as mesh_c
    from robotspec.collision import _meshcore_py as mesh_py
    from robotspec.collision.matrix import generate_for_robot
    from robotspec.compiler import compile_robot
    from robotspec.model import _kincore as kin_c
    from robotspec.model import _kincore_py as kin_py
    from robotspec.model.kinematics import Kinematics

    robot = compile_robot(args.robot)
    world = robot.world
    c, py = (kin_c, mesh_c), (kin_py, mesh_py)
    sides: dict[str, Any] = {}
    for name, cores in (("c", c), ("py", py)):
        with using(*cores):
            sides[name] = (Kinematics(world), SelfCollisionChecker.from_robot(robot))
    qs = np.asarray(random_configurations(world, max(args.batch, 64), seed=0))
    batch = qs[: args.batch]
    chain_sem = max(robot.manipulator_chains, key=lambda ch: len(ch.active_connections))
    root, tip = chain_sem.root.name, chain_sem.tip.name
    label = f"{args.robot}:"

    def on(
        name: str, fn: Callable[[Kinematics, SelfCollisionChecker], object], reps: int = 1
    ) -> Callable[[], object]:
        """``fn`` on one side, ``reps`` times in one go (the core switch stays out of the time)."""
        cores = c if name == "c" else py
        kin, checker = sides[name]

        def run() -> object:
            with using(*cores):
                for _ in range(reps - 1):
                    fn(kin, checker)
                return fn(kin, checker)

        return run

    cases: list[tuple[str, Callable[[Kinematics, SelfCollisionChecker], Any], float, int]] = [
        (f"FK all {len(world.bodies)} bodies", lambda k, _: k.forward(qs[0]), 1e-12, 100),
        (f"pose of one frame ({tip})", lambda k, _: k.pose(qs[0], tip), 1e-12, 100),
        (f"Jacobian {root} -> {tip}", lambda k, _: k.chain(root, tip).jacobian(qs[0]), 1e-12, 100),
        (f"FK batch of {len(batch)}", lambda k, _: k.forward_batch(batch), 1e-12, 1),
        ("in_collision (one configuration)", lambda _, ch: ch.in_collision(qs[1]), 0.0, 10),
        ("collisions_batch of 64", lambda _, ch: ch.collisions_batch(qs[:64]), 0.0, 1),
    ]
    rows: list[Row] = []
    for what, fn, tol, reps in cases:
        ours, peer = on("py", fn), on("c", fn)
        np.testing.assert_allclose(np.asarray(ours()), np.asarray(peer()), rtol=0, atol=tol)
        timed = median_cpu_times if args.cpu else median_times
        t_ours, t_peer = timed([on("py", fn, reps), on("c", fn, reps)], args.rounds)
        rows.append(Row(f"{label} {what}", t_ours / reps, "C accelerators", t_peer / reps))

    # The `robotspec collisions generate` path, once a side (seconds each).
    matrices, times = {}, {}
    clock = time.thread_time if args.cpu else time.perf_counter
    for name in ("c", "py"):
        with using(*(c if name == "c" else py)):
            t = clock()
            matrices[name] = generate_for_robot(robot, samples=args.samples, seed=0, processes=1)
            times[name] = clock() - t
    assert matrices["c"].disabled_pairs() == matrices["py"].disabled_pairs()
    rows.append(
        Row(
            f"{label} collision matrix, {args.samples} samples",
            times["py"],
            "C accelerators (processes=1)",
            times["c"],
        )
    )
    print_rows(rows, args.json)


if __name__ == "__main__":
    main()
