"""Self-collision checking and collision matrix generation on the PR2, against pinocchio, one run.

Run: ``python benchmarks/bench_collision.py`` (needs the dev extra: example-robot-data, pin, coal).
Both sides check the same pairs (the SRDF's active pairs) on the same random configurations with
the same coal geometry; the answers are compared before anything is timed. Ratios are peer time /
robotspec time: above 1 means robotspec is faster.

The thread rows (``--threads``, default 2) run the batches on that many threads against
pinocchio's ``computeCollisionsInParallel`` with a broad-phase pool on as many, and against
robotspec's own batch on one thread (the ratio is then the speed-up). A control row runs work
that holds no lock at all (sha256 of 32 MB per thread, which releases the GIL) on one thread
and on ``--threads``: the speed-up the machine itself gives at that moment, so a loaded machine's
figures can be read. All of them are interleaved rounds in one run (``--rounds``).

Below the table, the CPU time of the thread rows: the process's CPU time (every thread) against
the wall time of each batch, and the CPU time of each thread of a batch split by hand as the
checker splits it. Why: on a loaded machine the speed-up measures the other processes, while CPU
time does not; work that is serialised (one thread doing it, or threads taking turns on a lock)
shows as one thread's CPU holding most of the total, or as a total that grows with the threads.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import statistics
import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from rows import Row, add_json_flag, erd_share, print_rows


def median_time(fn: Callable[[], object], repeat: int) -> float:
    """Median wall time of ``repeat`` calls (seconds); interleave peers to share machine noise."""
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--configs", type=int, default=2000, help="configurations per check run")
    parser.add_argument("--samples", type=int, default=10_000, help="matrix generation samples")
    parser.add_argument("--jobs", type=int, default=None, help="processes for the matrix")
    parser.add_argument("--threads", type=int, default=2, help="threads of the parallel rows")
    parser.add_argument("--rounds", type=int, default=9, help="interleaved rounds, thread rows")
    parser.add_argument("--no-matrix", action="store_true", help="skip the matrix generation")
    add_json_flag(parser)
    args = parser.parse_args()
    say = (lambda *a, **k: None) if args.json else print

    import pinocchio as pin

    from robotspec.collision import (
        CollisionRules,
        SelfCollisionChecker,
        compare_pairs,
        generate_for_robot,
        random_configurations,
    )
    from robotspec.compiler import check_spec
    from robotspec.description.urdf import load_urdf

    share = erd_share().parent
    urdf = share / "example-robot-data/robots/pr2_description/urdf/pr2.urdf"
    robot = check_spec("pr2").robot
    assert robot is not None and robot.srdf is not None
    world = load_urdf(urdf)
    checker = SelfCollisionChecker(world, CollisionRules.for_world(world, srdf=robot.srdf))
    pairs = checker.active_pairs

    model, gmodel, _ = pin.buildModelsFromUrdf(str(urdf), package_dirs=[str(share)])
    data = model.createData()
    link = [model.frames[g.parentFrame].name for g in gmodel.geometryObjects]
    index = {frozenset(p): k for k, p in enumerate(pairs)}
    owner = []
    for i in range(len(link)):
        for j in range(i + 1, len(link)):
            k = index.get(frozenset((link[i], link[j])))
            if k is not None:
                gmodel.addCollisionPair(pin.CollisionPair(i, j))
                owner.append(k)
    gdata = pin.GeometryData(gmodel)

    qs = random_configurations(world, args.configs, seed=0)
    # robotspec configuration -> pinocchio configuration (continuous joints are cos/sin).
    pq = []
    for q in qs:
        v = pin.neutral(model)
        for jid in range(1, model.njoints):
            c = world.get_connection_by_name(model.names[jid])
            jm = model.joints[jid]
            x = q[c.dofs[0]] * (c.mimic.multiplier if c.mimic else 1.0) + (
                c.mimic.offset if c.mimic else 0.0
            )
            if jm.nq == 2:
                v[jm.idx_q : jm.idx_q + 2] = (np.cos(x), np.sin(x))
            else:
                v[jm.idx_q] = x
        pq.append(v)

    def pin_all() -> np.ndarray:
        out = np.zeros((len(pq), len(pairs)), dtype=bool)
        for n, v in enumerate(pq):
            pin.computeCollisions(model, data, gmodel, gdata, v, False)
            for k, res in zip(owner, gdata.collisionResults, strict=True):
                if res.isCollision():
                    out[n, k] = True
        return out

    def pin_all_noread() -> None:
        for v in pq:
            pin.computeCollisions(model, data, gmodel, gdata, v, False)

    def pin_any() -> np.ndarray:
        return np.array([pin.computeCollisions(model, data, gmodel, gdata, v, True) for v in pq])

    ours_all = checker.collisions_batch(qs)
    assert np.array_equal(ours_all, pin_all()), "robotspec and pinocchio disagree"
    assert np.array_equal(checker.in_collision_batch(qs), pin_any())

    rows: list[tuple[str, float, str, float]] = []
    n = len(qs)
    t_ours, t_pin, t_pin_bare = [], [], []
    for _ in range(5):  # interleaved, so both sides see the same machine load
        t_ours.append(median_time(lambda: checker.collisions_batch(qs), 1))
        t_pin.append(median_time(pin_all, 1))
        t_pin_bare.append(median_time(pin_all_noread, 1))
    ours = statistics.median(t_ours) / n
    rows.append(
        ("all colliding pairs, batch", ours, "computeCollisions + read results", _m(t_pin) / n)
    )
    rows.append(("all colliding pairs, batch", ours, "computeCollisions only", _m(t_pin_bare) / n))
    t_ours, t_pin = [], []
    for _ in range(5):
        t_ours.append(median_time(lambda: checker.in_collision_batch(qs), 1))
        t_pin.append(median_time(pin_any, 1))
    rows.append(
        ("in collision? (first hit), batch", _m(t_ours) / n, "stop at first", _m(t_pin) / n)
    )
    few = qs[:200]
    t_single = median_time(lambda: [checker.colliding_pairs(q) for q in few], 3) / len(few)
    rows.append(
        (
            "all colliding pairs, one call per config",
            t_single,
            "computeCollisions only",
            _m(t_pin_bare) / n,
        )
    )

    say(
        f"PR2 (example-robot-data): {len(pairs)} checked body pairs "
        f"({len(owner)} geometry pairs), {n} random configurations; answers identical\n"
    )
    table = [Row(name, a, f"pinocchio {peer}", b) for name, a, peer, b in rows]
    cpu_notes: list[str] = []
    table += thread_rows(checker, qs, pin, model, gmodel, pq, args.threads, args.rounds, cpu_notes)
    if args.no_matrix:
        print_rows(table, args.json)
        say("\n" + "\n".join(cpu_notes))
        return

    t = time.perf_counter()
    matrix = generate_for_robot(robot, samples=args.samples, seed=0, processes=args.jobs)
    wall = time.perf_counter() - t
    geometry = set(matrix.bodies)
    reference = frozenset(
        frozenset((d.link1, d.link2))
        for d in robot.srdf.disabled_collisions
        if d.link1 in geometry and d.link2 in geometry
    )
    precision, recall = compare_pairs(matrix.disabled_pairs(), reference)
    counts = ", ".join(f"{k} {v}" for k, v in matrix.reasons().items())
    table.append(
        Row(
            f"collision matrix, {args.samples} samples, {matrix.processes} processes (wall)",
            wall,
            "target < 5 s",
            5.0,
        )
    )
    print_rows(table, args.json)
    say("\n" + "\n".join(cpu_notes))
    say(
        f"\ncollision matrix: {counts}; {len(matrix.checked)} pairs stay checked"
        f"\n  against the shipped pr2.srdf ({len(reference)} pairs between bodies with geometry): "
        f"precision {precision:.3f}, recall {recall:.3f}"
    )


def thread_rows(
    checker: Any,
    qs: np.ndarray,
    pin: Any,
    model: Any,
    gmodel: Any,
    pq: list[np.ndarray],
    threads: int,
    rounds: int,
    cpu_notes: list[str],
) -> list[Row]:
    """The batches on ``threads`` threads: against pinocchio's parallel batch, against one thread.

    Every timing of a row is taken in the same round as the others (interleaved), so machine
    load hits all of them alike; each figure is the median over ``rounds``. ``cpu_notes``
    receives the CPU-time lines (see the module's doc).
    """
    n = len(qs)
    qmat = np.asfortranarray(np.array(pq).T)
    pool = pin.BroadPhaseManagerPool_DynamicAABBTreeCollisionManager(model, gmodel, threads)
    any_one = checker.in_collision_batch(qs)
    assert np.array_equal(checker.in_collision_batch(qs, threads=threads), any_one)
    assert np.array_equal(
        np.asarray(pin.computeCollisionsInParallel(threads, pool, qmat, True)), any_one
    )
    assert np.array_equal(
        checker.collisions_batch(qs, threads=threads), checker.collisions_batch(qs)
    )
    blob = b"\x5a" * (32 << 20)

    def control(k: int) -> None:
        workers = [threading.Thread(target=hashlib.sha256, args=(blob,)) for _ in range(k)]
        for w in workers:
            w.start()
        for w in workers:
            w.join()

    timed: dict[str, Callable[[], object]] = {
        "any1": lambda: checker.in_collision_batch(qs, threads=1),
        "anyN": lambda: checker.in_collision_batch(qs, threads=threads),
        "pinN": lambda: pin.computeCollisionsInParallel(threads, pool, qmat, True),
        "all1": lambda: checker.collisions_batch(qs, threads=1),
        "allN": lambda: checker.collisions_batch(qs, threads=threads),
        "ctl1": lambda: control(1),
        "ctlN": lambda: control(threads),
    }
    t: dict[str, list[float]] = {k: [] for k in timed}
    cpu: dict[str, list[float]] = {k: [] for k in timed}
    split: dict[str, list[list[float]]] = {"any": [], "all": []}
    for _ in range(rounds):
        for k, fn in timed.items():
            c0 = time.process_time()
            t[k].append(median_time(fn, 1))
            cpu[k].append(time.process_time() - c0)
        split["any"].append(split_cpu(checker.in_collision_batch, qs, threads))
        split["all"].append(split_cpu(checker.collisions_batch, qs, threads))
    m = {k: _m(v) for k, v in t.items()}
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    cpu_notes.append(f"CPU time, median of {rounds} rounds (load {load}):")
    for kind, one, many in (("any hit", "any1", "anyN"), ("all pairs", "all1", "allN")):
        each = [_m([r[i] for r in split[one[:3]]]) for i in range(threads)]
        cpu_notes.append(
            f"  {kind}: 1 thread {_m(cpu[one]) * 1e3:.1f} ms CPU in {m[one] * 1e3:.1f} ms wall; "
            f"{threads} threads {_m(cpu[many]) * 1e3:.1f} ms CPU in {m[many] * 1e3:.1f} ms wall "
            f"(CPU/wall {_m(cpu[many]) / m[many]:.2f}); split by hand, per thread: "
            + " + ".join(f"{x * 1e3:.1f}" for x in each)
            + " ms"
        )
    return [
        Row(
            f"any hit, batch, {threads} threads (per config)",
            m["anyN"] / n,
            f"pinocchio computeCollisionsInParallel, broad-phase pool, {threads} threads",
            m["pinN"] / n,
        ),
        Row(
            f"any hit, batch, {threads} threads (per config)",
            m["anyN"] / n,
            "robotspec on 1 thread (ratio = speed-up)",
            m["any1"] / n,
        ),
        Row(
            f"all colliding pairs, batch, {threads} threads (per config)",
            m["allN"] / n,
            "robotspec on 1 thread (ratio = speed-up)",
            m["all1"] / n,
        ),
        Row(
            f"control: {threads} x sha256(32 MB) on {threads} threads (load {load})",
            m["ctlN"] / threads,
            "1 x sha256 on 1 thread (ratio = the machine's speed-up)",
            m["ctl1"],
        ),
    ]


def split_cpu(query: Callable[..., object], qs: np.ndarray, threads: int) -> list[float]:
    """CPU seconds of each of ``threads`` threads running ``query`` on its contiguous slice.

    The slices are the checker's own (``threads=N`` cuts the batch the same way), each thread
    reads its own CPU clock (``time.thread_time``), so the figures do not depend on the load.
    """
    bounds = np.linspace(0, len(qs), threads + 1).astype(int)
    spent = [0.0] * threads

    def work(i: int) -> None:
        c0 = time.thread_time()
        query(qs[bounds[i] : bounds[i + 1]], threads=1)
        spent[i] = time.thread_time() - c0

    workers = [threading.Thread(target=work, args=(i,)) for i in range(threads)]
    for w in workers:
        w.start()
    for w in workers:
        w.join()
    return spent


def _m(values: list[float]) -> float:
    return statistics.median(values)


if __name__ == "__main__":
    main()
