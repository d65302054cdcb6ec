"""``robotspec init`` on Talos (URDF + SRDF) as a user runs it, in a fresh process; target < 2 s.

Three figures, measured in rounds (each takes its turn once per round, so a slow spell of the
shared machine hits all alike): the whole command in a new process (Python start, imports, load,
draft, write); a new process that only loads the same files (``load_description``), to show
what is loading and what is drafting; and ``draft_spec`` alone on the loaded world, in process.
CPU time of the child processes is printed beside wall time, since wall time on a loaded
machine says more about the machine than about the code.

Run: ``python benchmarks/bench_init.py [--repeat N]`` (needs example-robot-data). Prints medians.
"""

from __future__ import annotations

import argparse
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from rows import Row, add_json_flag, erd_share, print_rows


def _child_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=5)
    add_json_flag(parser)
    args = parser.parse_args()
    say = (lambda *a, **k: None) if args.json else print
    talos = erd_share() / "robots/talos_data"
    urdf, srdf = talos / "robots/talos_reduced.urdf", talos / "srdf/talos.srdf"
    out = Path(tempfile.mkdtemp()) / "talos.yaml"
    init = [sys.executable, "-m", "robotspec", "init", str(urdf), "--srdf", str(srdf)]
    init += ["-o", str(out), "--force"]
    load = [
        sys.executable,
        "-c",
        "from robotspec.description.load import load_description as f; "
        f"f({str(urdf)!r}, srdf={str(srdf)!r}, meshes='keep')",
    ]
    from robotspec.description.load import load_description
    from robotspec.spec.draft import draft_spec

    desc = load_description(urdf, srdf=srdf, meshes="keep")

    def draft() -> None:
        draft_spec(desc.world, urdf_ref="t.urdf", srdf=desc.srdf, srdf_ref="t.srdf", name="t")

    wall: dict[str, list[float]] = {"init": [], "load only": [], "draft_spec": []}
    cpu: dict[str, list[float]] = {"init": [], "load only": []}
    draft()
    for _ in range(args.repeat):
        for name, cmd in (("init", init), ("load only", load)):
            c0, t0 = _child_cpu(), time.perf_counter()
            subprocess.run(cmd, check=True, capture_output=True)
            wall[name].append(time.perf_counter() - t0)
            cpu[name].append(_child_cpu() - c0)
        t0 = time.perf_counter()
        draft()
        wall["draft_spec"].append(time.perf_counter() - t0)
    say(f"Talos reduced + SRDF, {args.repeat} rounds, medians")
    for name, times in wall.items():
        line = f"  {name:12s} wall {statistics.median(times) * 1e3:8.1f} ms"
        if name in cpu:
            line += f"   cpu {statistics.median(cpu[name]) * 1e3:8.1f} ms"
        say(line)
    verdict = "met" if statistics.median(wall["init"]) < 2 else "missed"
    say(f"  target: init < 2 s -> {verdict}")
    if args.json:
        init_s = statistics.median(wall["init"])
        print_rows(
            [
                Row("robotspec init on Talos, a fresh process (wall)", init_s, "target < 2 s", 2.0),
                Row(
                    "robotspec init on Talos, a fresh process (CPU)",
                    statistics.median(cpu["init"]),
                    "loading the description alone, a fresh process (CPU)",
                    statistics.median(cpu["load only"]),
                ),
                Row(
                    "draft_spec on Talos (in process)",
                    statistics.median(wall["draft_spec"]),
                    "-",
                    None,
                ),
            ],
            True,
        )


if __name__ == "__main__":
    main()
