"""``to_sdt`` on the PR2 against SDT's own hand-written PR2 on the same files: import, load, build.

Each side is measured the same way. *Import*: a new process that imports what each side needs
(robotspec's compiler and the bridge with SDT, or SDT's URDF parser and PR2 class). *Load*:
robotspec compiles example-robot-data's PR2 and its spec; SDT parses the same URDF (its parser,
meshes found through ROS_PACKAGE_PATH) and adds the omni drive, as SDT's tests do. *Build*:
``to_sdt`` (an SDT world from robotspec's model, the generated classes, SDT's ``from_world``)
against SDT's ``PR2.from_world`` on its parsed world (without its collision rules: the SRDF they
read is missing from SDT's wheel). ``to_sdt`` builds its SDT world itself, so its build does what
SDT's load and build do together; the last row adds load and build up. The first load of a
robot also spends SDT's mesh decomposition, cached afterwards; a warm-up round takes it out.
SDT's worlds accumulate in its global symbol graph, so every figure grows with the number of
worlds built in one process: keep ``--repeat`` small.

*First build*: what a PyCRAM program pays once, in a new process after its imports and its
load: the first ``to_sdt`` (its SDT world, the part classes, whose type hints krrood resolves
then, and the robot) against the first ``PR2.from_world`` of SDT's class on its parsed world
(whose classes' hints were resolved when its module was imported). Both sides import the same
SDT modules first, SDT's ``pr2`` module included (the class the PR2 spec names; a PyCRAM
program has it imported). SDT's ``from_world`` runs SDT's first entity query (a part's
``_robot``), on which krrood imports its query backends, pandas among them (about 1 s);
``to_sdt``'s parts answer ``_robot`` without a query (``robotspec.interop.sdt.backref``), so
it does not. A program that runs entity queries of its own pays that import at its first one,
so a second pair of rows imports the backends before the clock on both sides: what each side
pays beyond it. ``to_sdt`` builds its SDT world inside its clock, SDT's side parsed its world
before it: each case's third row sets the first ``to_sdt`` against SDT's first parse and
``from_world`` together, the same work. Each round starts one new process per side and case,
interleaved, round by round; the mesh decomposition cache is warm (the in-process rounds run
first).

Run: ``python benchmarks/bench_sdt.py [--repeat N]`` in the SDT environment (the ``sdt`` extra
and example-robot-data; without giskardpy, tests/sdt_stand_ins supplies its one helper).
Prints medians.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from rows import Row, add_json_flag, erd_share, median_times, print_rows

STAND_INS = Path(__file__).resolve().parents[1] / "tests" / "sdt_stand_ins"


def _new_process(code: str, repeat: int) -> float:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([*sys.path[1:], str(STAND_INS)]))
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], check=True, env=env, capture_output=True)
        times.append(time.perf_counter() - t)
    return sorted(times)[len(times) // 2]


_FIRST_OURS = """
import sys, time, warnings
warnings.simplefilter("ignore")
{pre}
from robotspec.robots import PR2
import robotspec.interop.sdt._api
import semantic_digital_twin.robots.pr2
from robotspec.interop.sdt import to_sdt
robot = PR2.load()
t = time.perf_counter()
to_sdt(robot)
print(time.perf_counter() - t)
"""

_FIRST_SDT = """
import sys, time, warnings
warnings.simplefilter("ignore")
{pre}
sys.path.insert(0, {here!r})
from bench_sdt import _sdt_world
from semantic_digital_twin.robots.pr2 import PR2
PR2._setup_collision_rules = lambda self: None
t = time.perf_counter()
world = _sdt_world({urdf!r})
t1 = time.perf_counter()
PR2.from_world(world)
t2 = time.perf_counter()
print(t2 - t, t2 - t1)
"""


#: Imported before the clock in the second case: krrood's query backends (pandas, ...).
_BACKENDS = "import krrood.entity_query_language.backends"

#: Per case: (to_sdt, SDT's from_world, SDT's parse + from_world), seconds per round.
First = dict[str, tuple[list[float], list[float], list[float]]]


def _first_builds(urdf: Path, repeat: int) -> First:
    """Seconds of the first build in a new process, per round (see :data:`First`).

    Two cases, keyed ``""`` (as a program starts) and ``"backends"`` (krrood's query backends
    imported first on both sides), all four processes of a round interleaved. SDT's process
    also times its parse: its first world and robot, the work ``to_sdt`` does inside its clock.
    """
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([*sys.path[1:], str(STAND_INS)]))
    here = str(Path(__file__).resolve().parent)
    cases = {"": "", "backends": _BACKENDS}
    out: First = {case: ([], [], []) for case in cases}
    for _ in range(repeat):
        for case, pre in cases.items():
            ours, theirs, theirs_loaded = out[case]
            for code in (
                _FIRST_OURS.format(pre=pre),
                _FIRST_SDT.format(pre=pre, here=here, urdf=str(urdf)),
            ):
                run = subprocess.run(
                    [sys.executable, "-c", code],
                    check=True,
                    env=env,
                    capture_output=True,
                    text=True,
                )
                *_, last = run.stdout.strip().splitlines()
                figures = [float(x) for x in last.split()]
                if len(figures) == 1:
                    ours.append(figures[0])
                else:
                    theirs_loaded.append(figures[0])
                    theirs.append(figures[1])
    return out


def _sdt_world(urdf: Path) -> Any:
    from semantic_digital_twin.adapters.urdf import URDFParser
    from semantic_digital_twin.datastructures.prefixed_name import PrefixedName
    from semantic_digital_twin.world_description.connections import OmniDrive
    from semantic_digital_twin.world_description.world_entity import Body

    world = URDFParser.from_file(str(urdf)).parse()
    with world.modify_world():
        base = world.root
        odom = Body(name=PrefixedName("odom_combined"))
        world.add_kinematic_structure_entity(odom)
        world.add_connection(OmniDrive.create_with_dofs(parent=odom, child=base, world=world))
    return world


def _build_times(robot: Any, world: Any, cls: Any, repeat: int) -> tuple[float, float]:
    """Medians of ``to_sdt(robot)`` and of ``cls.from_world`` on a fresh parsed world (untimed).

    SDT's ``from_world`` adds the robot to the world it is given, so each call needs a new
    world; its parsing is not part of the figure.
    """
    from robotspec.interop.sdt import to_sdt

    ours, theirs = [], []
    for _ in range(repeat + 1):  # the first round is the warm-up
        t = time.perf_counter()
        to_sdt(robot)
        ours.append(time.perf_counter() - t)
        w = world()
        t = time.perf_counter()
        cls.from_world(w)
        theirs.append(time.perf_counter() - t)
    return statistics.median(ours[1:]), statistics.median(theirs[1:])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument(
        "--first-only", action="store_true", help="only the first-build rows (new processes)"
    )
    add_json_flag(parser)
    args = parser.parse_args()
    if importlib.util.find_spec("giskardpy") is None:
        sys.path.append(str(STAND_INS))
    share = erd_share()
    os.environ["ROS_PACKAGE_PATH"] = str(share)  # SDT takes an entry named after the package
    urdf = share / "robots/pr2_description/urdf/pr2.urdf"

    if args.first_only:
        first = _first_builds(urdf, args.repeat)
        print_rows(_first_rows(first), args.json)
        return
    ours_import = _new_process(
        "import robotspec.robots, robotspec.compiler, robotspec.interop.sdt._api", args.repeat
    )
    sdt_import = _new_process(
        "import semantic_digital_twin.adapters.urdf, semantic_digital_twin.robots.pr2",
        args.repeat,
    )

    from semantic_digital_twin.robots.pr2 import PR2 as SDT_PR2

    from robotspec.robots import PR2

    SDT_PR2._setup_collision_rules = lambda self: None  # type: ignore[method-assign]
    robot = PR2.load()
    load = median_times([PR2.load, lambda: _sdt_world(urdf)], args.repeat)
    build = _build_times(robot, lambda: _sdt_world(urdf), SDT_PR2, args.repeat)
    rows = [
        Row("PR2: import (new process)", ours_import, "SDT: import", sdt_import),
        Row("PR2: load (compile the spec)", load[0], "SDT: load (parse URDF, drive)", load[1]),
        Row("PR2: build (to_sdt)", build[0], "SDT: build (PR2.from_world)", build[1]),
        Row("PR2: load + build", load[0] + build[0], "SDT: load + build", load[1] + build[1]),
    ]
    rows += _first_rows(_first_builds(urdf, args.repeat))
    print_rows(rows, args.json)


def _first_rows(first: First) -> list[Row]:
    rows = []
    for case, (ours, theirs, theirs_loaded) in first.items():
        what = ", query backends imported first" if case else ""
        print(
            f"first build{what}, per round (to_sdt / SDT's from_world, s): "
            + ", ".join(f"{a:.3f}/{b:.3f}" for a, b in zip(ours, theirs, strict=True)),
            file=sys.stderr,
        )
        rows += [
            Row(
                f"PR2: first to_sdt in a new process{what} (median)",
                statistics.median(ours),
                "SDT: first PR2.from_world in a new process",
                statistics.median(theirs),
            ),
            Row(f"PR2: same{what}, min", min(ours), "SDT: same, min", min(theirs)),
            Row(
                f"PR2: first to_sdt{what} (median)",
                statistics.median(ours),
                "SDT: first parse + PR2.from_world",
                statistics.median(theirs_loaded),
            ),
        ]
    return rows


if __name__ == "__main__":
    main()
