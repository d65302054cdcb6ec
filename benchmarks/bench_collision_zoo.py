"""Every robot of example-robot-data: self-collision and distances with the C core's shortcuts
against coal alone, same checker, same configurations; answers compared before they count.

Run: ``python benchmarks/bench_collision_zoo.py [--configs 40] [--json]`` (needs the dev extra).

Why: the mesh proofs (apart / crossing) and the hull-first distances were built on the PR2; a
shortcut that changes an answer on a robot nobody tuned it for is a bug. Each robot whose URDF
loads gets a checker of every pair of its bodies with geometry and no rules (the matrix
generator's view, the hardest: adjacent meshes touch), and the same checker with the shortcuts
off (``meshes=None``, no hulls: every narrow-phase question goes to coal). Collision answers
must be identical; distances equal within 2e-6 m (coal's own GJK tolerance on curved
primitives; mesh to mesh they agree to 1e-14). Rows: the summed time over the robots, ours
against coal alone, the ratio above 1 when the shortcuts pay.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
from rows import Row, add_json_flag, erd_share, print_rows


def _zoo(robots: Path) -> list[Path]:
    return sorted(robots.glob("*/**/*.urdf"))


def _checkers(urdf: Path) -> tuple[Any, Any] | None:
    from robotspec.collision import CollisionRules, SelfCollisionChecker
    from robotspec.description.urdf import load_urdf
    from robotspec.errors import RobotSpecError
    from robotspec.files.packages import PackageResolver

    try:
        world = load_urdf(urdf, resolver=PackageResolver.create(urdf))
    except RobotSpecError:
        return None  # does not load (two of example-robot-data's URDFs are broken upstream)
    names = tuple(b.name for b in world.bodies if b.collisions)
    if len(names) < 2:
        return None
    pairs = [(a, b) for i, a in enumerate(names) for b in names[i + 1 :]][:1500]
    rules = CollisionRules(bodies=names)
    ours = SelfCollisionChecker(world, rules, pairs=pairs, on_missing_mesh="skip")
    compiled = ours._build()
    coal_only = SelfCollisionChecker(world, rules, pairs=pairs, on_missing_mesh="skip")
    coal_only._compiled = dataclasses.replace(
        compiled, meshes=None, two_meshes=[False] * len(compiled.two_meshes)
    )
    coal_only._hull_fns = (None,) * len(compiled.pair_of)
    ours._hull_functors(compiled)  # hulls built once, outside the timing
    return ours, coal_only


def _timed(fn: Any, qs: Any) -> tuple[list[Any], float]:
    """``fn`` on each configuration of ``qs``, and the time it all took."""
    t = time.perf_counter()
    out = [fn(q) for q in qs]
    return out, time.perf_counter() - t


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--configs", type=int, default=40, help="configurations per robot")
    add_json_flag(parser)
    args = parser.parse_args()
    say = (lambda *a, **k: None) if args.json else print

    from robotspec.collision import random_configurations

    totals = {"batch": [0.0, 0.0], "any": [0.0, 0.0], "distances": [0.0, 0.0]}
    robots = skipped = 0
    worst = 0.0
    for urdf in _zoo(erd_share() / "robots"):
        built = _checkers(urdf)
        if built is None:
            skipped += 1
            continue
        ours, coal_only = built
        qs = random_configurations(ours.world, args.configs, seed=2)
        # Interleaved, ours first then coal alone, per question.
        a, ta = _timed(ours.collisions_batch, [qs])
        b, tb = _timed(coal_only.collisions_batch, [qs])
        assert np.array_equal(a[0], b[0]), urdf
        a, ta2 = _timed(ours.in_collision, qs)
        b, tb2 = _timed(coal_only.in_collision, qs)
        assert a == b, urdf
        a, ta3 = _timed(ours.distances, qs[:2])
        b, tb3 = _timed(coal_only.distances, qs[:2])
        da = np.array([[d.distance for d in x] for x in a])
        db = np.array([[d.distance for d in x] for x in b])
        finite = np.isfinite(db)
        assert np.array_equal(finite, np.isfinite(da)), urdf
        err = float(np.max(np.abs(da[finite] - db[finite]))) if finite.any() else 0.0
        assert err <= 2e-6, (urdf, err)
        worst = max(worst, err)
        for key, (x, y) in {"batch": (ta, tb), "any": (ta2, tb2), "distances": (ta3, tb3)}.items():
            totals[key][0] += x
            totals[key][1] += y
        robots += 1
        name = f"{urdf.parent.parent.name}/{urdf.stem}"
        say(
            f"{name:55s} batch {ta * 1e3:7.1f} / {tb * 1e3:7.1f} ms, any {ta2 * 1e3:6.1f} /"
            f" {tb2 * 1e3:6.1f} ms, distances {ta3 * 1e3:6.1f} / {tb3 * 1e3:6.1f} ms",
            file=sys.stderr,
        )
    say(
        f"{robots} robots (every pair of bodies with geometry, no rules; {skipped} without a "
        f"loadable URDF or two bodies with geometry): collision answers identical, distances "
        f"within {worst:.1e} m\n"
    )
    n = args.configs
    rows = [
        Row(
            f"zoo: all pairs, batch of {n}, summed",
            totals["batch"][0],
            "coal alone",
            totals["batch"][1],
        ),
        Row(f"zoo: any hit, {n} calls, summed", totals["any"][0], "coal alone", totals["any"][1]),
        Row(
            "zoo: distances, 2 calls, summed",
            totals["distances"][0],
            "coal alone",
            totals["distances"][1],
        ),
    ]
    print_rows(rows, args.json, width=40, peer_width=12)


if __name__ == "__main__":
    main()
