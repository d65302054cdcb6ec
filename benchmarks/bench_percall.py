"""The per-call cost of single-configuration queries, against a recorded baseline.

Run: ``python benchmarks/bench_percall.py [--robot pr2] [--calls 200] [--rounds 60] [--json]``
(needs the dev extra: example-robot-data; and the C cores built: this times the path a planner
calls thousands of times a second, which only the C cores make short).

Why a baseline file: ``forward``, ``pose``, a chain's ``jacobian`` and ``in_collision`` cost one
to a few microseconds, most of it Python in front of the C call (argument checks, the core's
lookup). A change that adds a few hundred nanoseconds there is invisible in any other benchmark,
yet makes every query 20-40 % slower (issue 34 measured it). ``in_collision`` is timed on a
free configuration whose boxes all stay apart (kinematics and broad phase only) and on one near
contact (a pair within 2 cm: the narrow phase's mesh proofs run too); the second row's baseline
was recorded later than the others, on the same commit and machine (the file says when).
``benchmarks/percall_baseline.json`` holds the per-call times of the landing before those checks
(c19da32) on the machine named in it; each row is that time against today's (ratio = baseline /
now: below 1 means the calls got slower). Another machine gives other times: record its own
baseline on the baseline commit, ``git worktree add /tmp/base c19da32``, ``python setup.py
build_ext --inplace`` there, then
``PYTHONPATH=/tmp/base python benchmarks/bench_percall.py --record FILE`` (then
``--baseline FILE``).

How it times: ``calls`` calls of one query in a block, the queries in turn, ``rounds`` blocks
each; the figure is the FASTEST block's time per call. On a shared machine other processes only
ever add time to a block, so the minimum is the one figure a loaded machine leaves alone (a
median there measures the load). Blocks are short (200 calls: 4 ms of ``in_collision``) so that
some of them run without being preempted at a load average of 8 on two cores.
"""

from __future__ import annotations

import argparse
import json
import platform
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from rows import Row, add_json_flag, print_rows

BASELINE = Path(__file__).with_name("percall_baseline.json")


def queries(robot_name: str) -> dict[str, Callable[[], object]]:
    """The timed calls on one robot, each on a fixed random configuration."""
    from robotspec.collision import SelfCollisionChecker, random_configurations
    from robotspec.compiler import compile_robot
    from robotspec.model.kinematics import Kinematics

    robot = compile_robot(robot_name)
    kin = Kinematics(robot.world)
    checker = SelfCollisionChecker.from_robot(robot)
    qs = np.asarray(random_configurations(robot.world, 4, seed=0), dtype=np.float64)
    chain = max(robot.manipulator_chains, key=lambda ch: len(ch.active_connections))
    root, tip = chain.root.name, chain.tip.name
    arm = kin.chain(root, tip)
    q, free = qs[0], next(q for q in qs if not checker.in_collision(q))
    # Free, but a pair within 2 cm: boxes meet, so the narrow phase runs (mesh proofs) too, as
    # near contact in a planner's queries. Public calls only, so the baseline commit finds it.
    more = np.asarray(random_configurations(robot.world, 64, seed=0), dtype=np.float64)
    near = next(
        q for q in more if not checker.in_collision(q) and checker.in_collision(q, margin=0.02)
    )
    return {
        "forward": lambda: kin.forward(q),
        "pose": lambda: kin.pose(q, tip),
        "chain jacobian": lambda: arm.jacobian(q),
        "in_collision": lambda: checker.in_collision(free),
        "in_collision, near contact": lambda: checker.in_collision(near),
    }


def per_call(fns: dict[str, Callable[[], object]], calls: int, rounds: int) -> dict[str, float]:
    """Seconds per call of each query: its fastest block of ``calls`` calls over ``rounds``."""
    best = dict.fromkeys(fns, float("inf"))
    for fn in fns.values():
        fn()
    for _ in range(rounds):
        for name, fn in fns.items():
            t = time.perf_counter()
            for _ in range(calls):
                fn()
            best[name] = min(best[name], (time.perf_counter() - t) / calls)
    return best


def machine() -> str:
    """The CPU, its count, the load and the Python of this run: what a baseline was taken on."""
    import os

    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            names = [ln.split(":", 1)[1].strip() for ln in f if ln.startswith("model name")]
        cpu = names[0] if names else cpu
    except OSError:
        pass
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return (
        f"{cpu}, {os.cpu_count()} CPUs, load {load:.1f}, Python {platform.python_version()}, "
        f"numpy {np.__version__}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--robot", default="pr2", help="a shipped robot (example-robot-data)")
    parser.add_argument("--calls", type=int, default=200, help="calls per timed block")
    parser.add_argument("--rounds", type=int, default=60, help="blocks per query (fastest kept)")
    parser.add_argument("--baseline", type=Path, default=BASELINE, help="recorded per-call times")
    parser.add_argument("--record", type=Path, help="write this run's times as a baseline file")
    parser.add_argument("--raw", action="store_true", help="print the times as one JSON object")
    add_json_flag(parser)
    args = parser.parse_args()

    times = per_call(queries(args.robot), args.calls, args.rounds)
    if args.raw:
        print(json.dumps(times))
    if args.record:
        import subprocess

        commit = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=False
        ).stdout.strip()
        record = {
            "robot": args.robot,
            "commit": commit,
            "machine": machine(),
            "statistic": f"fastest of {args.rounds} blocks of {args.calls} calls",
            "per_call_s": times,
        }
        args.record.write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")
    if args.raw or args.record:
        return
    base = json.loads(args.baseline.read_text(encoding="utf-8"))
    peer = f"baseline {base['commit']}"
    rows = [
        Row(f"{args.robot}: {name} per call", t, peer, base["per_call_s"].get(name))
        for name, t in times.items()
        if base.get("robot") == args.robot
    ]
    print_rows(rows, args.json, width=42, peer_width=24)


if __name__ == "__main__":
    main()
