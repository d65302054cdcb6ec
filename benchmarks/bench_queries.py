"""Single-configuration kinematics and collision queries against pinocchio, one run.

Run: ``python benchmarks/bench_queries.py [--robots pr2 tiago b1_ur5_allegro] [--json]`` (needs
the dev extra: example-robot-data, pin).

Ours is the public API a robotspec user calls (``Kinematics.forward``, ``.pose``,
``ChainKinematics.fk``/``.jacobian``, ``SelfCollisionChecker.in_collision``/``colliding_pairs``/
``distances``, the batch calls). The peer is what a pinocchio user writes for the same answer, on
the model ``robot.to_pinocchio()`` exports: the same frames and the same collision pairs, and
fewer frames than a model read from the URDF (whose every joint is a frame too), so the peer is
if anything faster than the usual one. Both sides get the same configurations (the peer's
already in pinocchio's layout, untimed), answers are compared before anything is timed, and
the two are timed interleaved, round by round, medians reported. Ratio = peer / ours.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from rows import Row, add_json_flag, print_rows


def per_call(fn: Callable[[Any], object], args: Sequence[Any]) -> float:
    t = time.perf_counter()
    for a in args:
        fn(a)
    return (time.perf_counter() - t) / len(args)


def duel(
    ours: Callable[[Any], object],
    ours_args: Sequence[Any],
    peer: Callable[[Any], object],
    peer_args: Sequence[Any],
    rounds: int,
) -> tuple[float, float]:
    """Median per-call times of ours and the peer, timed alternately round by round."""
    a, b = [], []
    per_call(ours, ours_args[:3])  # warm caches (chains, requests) on both sides
    per_call(peer, peer_args[:3])
    for _ in range(rounds):
        a.append(per_call(ours, ours_args))
        b.append(per_call(peer, peer_args))
    return statistics.median(a), statistics.median(b)


def robot_rows(name: str, rounds: int, n_configs: int) -> list[Row]:
    import pinocchio as pin

    from robotspec.collision import SelfCollisionChecker, random_configurations
    from robotspec.compiler import compile_robot
    from robotspec.model.kinematics import Kinematics

    robot = compile_robot(name)
    world = robot.world
    kin = Kinematics(world)
    checker = SelfCollisionChecker.from_robot(robot)
    pr = robot.to_pinocchio()
    model, gmodel = pr.model, pr.collision_model
    data, gdata = model.createData(), pin.GeometryData(gmodel)
    qs = list(random_configurations(world, n_configs, seed=0))
    pqs = [pr.configuration(q).copy() for q in qs]
    chain_sem = max(robot.manipulator_chains, key=lambda c: len(c.active_connections))
    chain = kin.chain(chain_sem.root, chain_sem.tip)
    tool = chain_sem.manipulator.tool_frame.name if chain_sem.manipulator else chain_sem.tip.name
    tool_id = pr.frames[tool]
    root_id, tip_id = pr.frames[chain_sem.root.name], pr.chain_tips[chain_sem.name]
    lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    rows: list[Row] = []
    label = f"{name}:"

    def check(ours: object, theirs: object) -> None:
        np.testing.assert_allclose(np.asarray(ours), np.asarray(theirs), atol=1e-9)

    # --- FK of every body
    def pin_fk(q: np.ndarray) -> None:
        pin.framesForwardKinematics(model, data, q)

    pin_fk(pqs[0])
    check(kin.forward(qs[0])[-1], data.oMf[pr.frames[world.bodies[-1].name]].homogeneous)
    t = duel(kin.forward, qs, pin_fk, pqs, rounds)
    rows.append(
        Row(
            f"{label} FK all {len(world.bodies)} bodies",
            t[0],
            "framesForwardKinematics (poses left in data)",
            t[1],
        )
    )

    # --- one frame
    def pin_frame(q: np.ndarray) -> np.ndarray:
        pin.forwardKinematics(model, data, q)
        return pin.updateFramePlacement(model, data, tool_id).homogeneous  # type: ignore[no-any-return]

    def ours_frame(q: np.ndarray) -> np.ndarray:
        return kin.pose(q, tool)

    check(ours_frame(qs[0]), pin_frame(pqs[0]))
    t = duel(ours_frame, qs, pin_frame, pqs, rounds)
    rows.append(
        Row(
            f"{label} pose of one frame ({tool})",
            t[0],
            "forwardKinematics + updateFramePlacement",
            t[1],
        )
    )

    # --- a chain's tip in its root frame
    def pin_tip(q: np.ndarray) -> np.ndarray:
        pin.forwardKinematics(model, data, q)
        root = pin.updateFramePlacement(model, data, root_id)
        return root.actInv(pin.updateFramePlacement(model, data, tip_id)).homogeneous  # type: ignore[no-any-return]

    check(chain.fk(qs[0]), pin_tip(pqs[0]))
    t = duel(chain.fk, qs, pin_tip, pqs, rounds)
    n_dof = len(chain.dof_indices)
    rows.append(
        Row(
            f"{label} chain tip in root ({chain_sem.name}, {n_dof} DOF)",
            t[0],
            "FK + 2 updateFramePlacement + actInv",
            t[1],
        )
    )

    # --- the chain's Jacobian
    def pin_jac(q: np.ndarray) -> np.ndarray:
        return pin.computeFrameJacobian(model, data, q, tip_id, lwa)  # type: ignore[no-any-return]

    t = duel(chain.jacobian, qs, pin_jac, pqs, rounds)
    rows.append(
        Row(
            f"{label} chain Jacobian ({chain_sem.name})",
            t[0],
            "computeFrameJacobian (world-aligned, 6 x nv)",
            t[1],
        )
    )

    # --- self-collision
    pairs = checker.active_pairs
    key = {tuple(sorted(p)): p for p in pairs}

    def pin_any(q: np.ndarray) -> bool:
        return pin.computeCollisions(model, data, gmodel, gdata, q, True)  # type: ignore[no-any-return]

    def pin_all(q: np.ndarray) -> set[tuple[str, str]]:
        pin.computeCollisions(model, data, gmodel, gdata, q, False)
        return {
            key[b]
            for b, res in zip(pr.pair_bodies, gdata.collisionResults, strict=True)
            if res.isCollision()
        }

    for q, pq in zip(qs, pqs, strict=True):
        ours_pairs, theirs_pairs = set(checker.colliding_pairs(q)), pin_all(pq)
        if ours_pairs != theirs_pairs:
            # pinocchio's box-box answers can flip between calls on the same configuration (its
            # functors keep state): a disagreement is settled by the pair's signed distance.
            dist = {(d.link1, d.link2): d.distance for d in checker.distances(q)}
            for p in ours_pairs ^ theirs_pairs:
                assert (dist[p] < 0) == (p in ours_pairs), (name, p, dist[p])
            print(
                f"note: {name}: pinocchio disagrees on {sorted(ours_pairs ^ theirs_pairs)}, "
                "robotspec matches the signed distance",
                file=sys.stderr,
            )
        else:
            assert checker.in_collision(q) == pin_any(pq)
    t = duel(checker.in_collision, qs, pin_any, pqs, rounds)
    rows.append(
        Row(
            f"{label} self-collision, any hit ({len(pairs)} pairs)",
            t[0],
            "computeCollisions(stop at first)",
            t[1],
        )
    )
    t = duel(checker.colliding_pairs, qs, pin_all, pqs, rounds)
    rows.append(
        Row(
            f"{label} self-collision, all colliding pairs",
            t[0],
            "computeCollisions + colliding pairs read",
            t[1],
        )
    )

    # The same two queries through pinocchio's broad phase (coal's dynamic AABB tree over the
    # geometries, pinocchio 3+): the best a pinocchio user can run for one configuration. Its
    # results are only written for the pairs the tree lets through, so they are cleared first.
    bgdata = pin.GeometryData(gmodel)
    broad = pin.BroadPhaseManager_DynamicAABBTreeCollisionManager(model, gmodel, bgdata)

    def pin_broad_any(q: np.ndarray) -> bool:
        return pin.computeCollisions(model, data, broad, q, True)  # type: ignore[no-any-return]

    def pin_broad_all(q: np.ndarray) -> set[tuple[str, str]]:
        for res in bgdata.collisionResults:
            res.clear()
        pin.computeCollisions(model, data, broad, q, False)
        return {
            key[b]
            for b, res in zip(pr.pair_bodies, bgdata.collisionResults, strict=True)
            if res.isCollision()
        }

    for q, pq in zip(qs, pqs, strict=True):
        assert pin_broad_any(pq) == checker.in_collision(q), name
        assert pin_broad_all(pq) == set(checker.colliding_pairs(q)), name
    t = duel(checker.in_collision, qs, pin_broad_any, pqs, rounds)
    rows.append(
        Row(
            f"{label} self-collision, any hit, vs broad phase",
            t[0],
            "computeCollisions(BroadPhaseManager, stop)",
            t[1],
        )
    )
    t = duel(checker.colliding_pairs, qs, pin_broad_all, pqs, rounds)
    rows.append(
        Row(
            f"{label} self-collision, all pairs, vs broad phase",
            t[0],
            "BroadPhaseManager + pairs read",
            t[1],
        )
    )

    def pin_dist(q: np.ndarray) -> list[tuple[float, Any, Any]]:
        pin.computeDistances(model, data, gmodel, gdata, q)
        return [
            (r.min_distance, r.getNearestPoint1(), r.getNearestPoint2())
            for r in gdata.distanceResults
        ]

    few = max(2, min(5, n_configs // 10))
    t = duel(checker.distances, qs[:few], pin_dist, pqs[:few], max(3, rounds // 3))
    rows.append(
        Row(
            f"{label} distances of all pairs, with points",
            t[0],
            "computeDistances + results read",
            t[1],
        )
    )
    return rows


def batch_rows(samples: int, collision_configs: int, rounds: int) -> list[Row]:
    import pinocchio as pin

    from robotspec.collision import SelfCollisionChecker, random_configurations
    from robotspec.compiler import compile_robot
    from robotspec.model.kinematics import Kinematics

    robot = compile_robot("pr2")
    kin = Kinematics(robot.world)
    checker = SelfCollisionChecker.from_robot(robot)
    pr = robot.to_pinocchio()
    model, gmodel = pr.model, pr.collision_model
    data, gdata = model.createData(), pin.GeometryData(gmodel)
    rng = np.random.default_rng(0)
    qs = rng.uniform(-1, 1, (samples, len(robot.world.degrees_of_freedom)))
    pqs = [pr.configuration(q).copy() for q in qs]
    ids = [pr.frames[b.name] for b in robot.world.bodies]

    def pin_loop(_: object) -> None:
        for q in pqs:
            pin.framesForwardKinematics(model, data, q)

    def pin_loop_read(_: object) -> np.ndarray:
        out = np.empty((len(pqs), len(ids), 4, 4))
        for k, q in enumerate(pqs):
            pin.framesForwardKinematics(model, data, q)
            for j, i in enumerate(ids):
                out[k, j] = data.oMf[i].homogeneous
        return out

    t = duel(lambda _: kin.forward_batch(qs), [0], pin_loop, [0], rounds)
    rows = [
        Row(
            f"pr2: batched FK, {samples} configs, all bodies",
            t[0],
            "Python loop of framesForwardKinematics",
            t[1],
        )
    ]
    buffer = np.empty((len(qs), len(robot.world.bodies), 4, 4))
    t = duel(lambda _: kin.forward_batch(qs, out=buffer), [0], pin_loop, [0], rounds)
    rows.append(
        Row(
            f"pr2: batched FK, {samples} configs, all bodies, into a reused array (out=)",
            t[0],
            "Python loop of framesForwardKinematics",
            t[1],
        )
    )
    t = duel(lambda _: kin.forward_batch(qs, threads=1), [0], pin_loop, [0], rounds)
    rows.append(
        Row(
            f"pr2: batched FK, {samples} configs, all bodies, one thread",
            t[0],
            "Python loop of framesForwardKinematics",
            t[1],
        )
    )
    t = duel(lambda _: kin.forward_batch(qs), [0], pin_loop_read, [0], 1)
    rows.append(
        Row(
            f"pr2: batched FK, {samples} configs, all bodies",
            t[0],
            "same loop, every pose copied into an array",
            t[1],
        )
    )
    arm = robot.get_chain("right_arm")
    chain = kin.chain(arm.root, arm.tip)
    root_id, tip_id = pr.frames[arm.root.name], pr.chain_tips["right_arm"]

    def pin_tips(_: object) -> np.ndarray:
        out = np.empty((len(pqs), 4, 4))
        for k, q in enumerate(pqs):
            pin.forwardKinematics(model, data, q)
            root = pin.updateFramePlacement(model, data, root_id)
            out[k] = root.actInv(pin.updateFramePlacement(model, data, tip_id)).homogeneous
        return out

    np.testing.assert_allclose(chain.fk_batch(qs[:50]), pin_tips(0)[:50], atol=1e-9)
    t = duel(lambda _: chain.fk_batch(qs), [0], pin_tips, [0], rounds)
    rows.append(
        Row(
            f"pr2: batched chain tip pose (right_arm), {samples} configs",
            t[0],
            "loop of FK + 2 updateFramePlacement + actInv",
            t[1],
        )
    )
    cqs = random_configurations(robot.world, collision_configs, seed=0)
    cpqs = [pr.configuration(q).copy() for q in cqs]
    index = {p: k for k, p in enumerate(checker.active_pairs)}
    key = {tuple(sorted(p)): index[p] for p in checker.active_pairs}
    owner = [key[b] for b in pr.pair_bodies]

    def pin_all(_: object) -> np.ndarray:
        out = np.zeros((len(cpqs), len(index)), dtype=bool)
        for n, q in enumerate(cpqs):
            pin.computeCollisions(model, data, gmodel, gdata, q, False)
            for k, res in zip(owner, gdata.collisionResults, strict=True):
                if res.isCollision():
                    out[n, k] = True
        return out

    def pin_any(_: object) -> np.ndarray:
        return np.array([pin.computeCollisions(model, data, gmodel, gdata, q, True) for q in cpqs])

    assert np.array_equal(checker.collisions_batch(cqs), pin_all(0))
    assert np.array_equal(checker.in_collision_batch(cqs), pin_any(0))
    n = len(cqs)
    t = duel(lambda _: checker.collisions_batch(cqs), [0], pin_all, [0], rounds)
    rows.append(
        Row(
            f"pr2: self-collision all pairs, batch of {n} (per config)",
            t[0] / n,
            "loop of computeCollisions + results read",
            t[1] / n,
        )
    )
    t = duel(lambda _: checker.in_collision_batch(cqs), [0], pin_any, [0], rounds)
    rows.append(
        Row(
            f"pr2: self-collision any hit, batch of {n} (per config)",
            t[0] / n,
            "loop of computeCollisions(stop at first)",
            t[1] / n,
        )
    )
    # pinocchio's own batch: computeCollisionsInParallel over a pool, one answer per
    # configuration (any hit), on every CPU, with and without its broad phase; the checker's
    # batch on as many threads (threads=), as the rows say (it ran on one before issue 34).
    threads = max(1, os.cpu_count() or 1)
    qmat = np.asfortranarray(np.array(cpqs).T)
    pool = pin.GeometryPool(model, gmodel, threads)
    broad_pool = pin.BroadPhaseManagerPool_DynamicAABBTreeCollisionManager(model, gmodel, threads)

    def pin_parallel(_: object) -> np.ndarray:
        return np.asarray(pin.computeCollisionsInParallel(threads, pool, qmat, True))

    def pin_parallel_broad(_: object) -> np.ndarray:
        return np.asarray(pin.computeCollisionsInParallel(threads, broad_pool, qmat, True))

    assert np.array_equal(pin_parallel(0), checker.in_collision_batch(cqs))
    assert np.array_equal(pin_parallel_broad(0), checker.in_collision_batch(cqs))
    for peer, what in (
        (pin_parallel, "computeCollisionsInParallel (GeometryPool)"),
        (pin_parallel_broad, "computeCollisionsInParallel (broad phase pool)"),
    ):
        t = duel(lambda _: checker.in_collision_batch(cqs, threads=threads), [0], peer, [0], rounds)
        rows.append(
            Row(
                f"pr2: self-collision any hit, batch of {n}, {threads} threads (per config)",
                t[0] / n,
                what,
                t[1] / n,
            )
        )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--robots", nargs="+", default=["pr2", "tiago", "b1_ur5_allegro"])
    parser.add_argument("--configs", type=int, default=200, help="configurations per query")
    parser.add_argument("--rounds", type=int, default=7, help="interleaved rounds per row")
    parser.add_argument("--samples", type=int, default=10_000, help="batched FK configurations")
    parser.add_argument("--batch", type=int, default=2000, help="batched collision configurations")
    parser.add_argument("--no-batch", action="store_true", help="skip the batch rows")
    add_json_flag(parser)
    args = parser.parse_args()

    rows: list[Row] = []
    for name in args.robots:
        rows += robot_rows(name, args.rounds, args.configs)
    if not args.no_batch:
        rows += batch_rows(args.samples, args.batch, max(3, args.rounds // 2))
    if not args.json:
        print("answers compared before timing; ratio = pinocchio time / robotspec time\n")
    print_rows(rows, args.json, width=58, peer_width=46)


if __name__ == "__main__":
    main()
