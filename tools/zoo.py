"""The robot zoo: every robot example-robot-data ships, loaded, drafted by ``init``, validated.

Why: ``robotspec init`` promises a spec that validates as written for any robot whose files load.
The zoo keeps that promise honest on every URDF of example-robot-data (with its SRDF where it has
one) and, for the robots robotspec ships a hand-written spec for, counts how many of those chains
the draft found by itself. ``docs/robot-zoo.md`` is generated from it::

    python tools/zoo.py            # rewrite docs/robot-zoo.md
    python tools/zoo.py --check    # exit 1 when the page is stale

``tests/test_zoo.py`` checks every robot (and its forward kinematics against pinocchio's) and
fails when the page is stale. A developer tool that reads the repository and runs the compiler,
so it is not in the package (whose drafting layer must not import the compiler).
"""

from __future__ import annotations

import argparse
import sys
import sysconfig
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from tools.draft_score import RobotScore, Truth

__all__ = [
    "COMMAND",
    "KEPT_SECTION",
    "PAGE",
    "SHIPPED_COMPARED",
    "ZooEntry",
    "ZooRow",
    "erd_robots_folder",
    "kept_section",
    "main",
    "zoo_entries",
    "zoo_page",
    "zoo_row",
]

COMMAND = "python tools/zoo.py"
#: The generated page.
PAGE = Path(__file__).resolve().parents[1] / "docs" / "robot-zoo.md"
#: Shipped specs compared with the draft from the same files: spec name -> URDF of the zoo.
SHIPPED_COMPARED = {
    "pr2": "pr2_description/pr2",
    "tiago": "tiago_description/tiago",
    "panda": "panda_description/panda",
    "ur5": "ur_description/ur5_robot",
}
#: SRDFs that example-robot-data's loaders pair with a URDF of another name.
_SRDF_OF = {"baxter_description/baxter": "baxter_manipulation"}


@dataclass(frozen=True)
class ZooEntry:
    """One URDF of example-robot-data and the SRDF its loaders use with it."""

    name: str  # "<package>/<urdf stem>"
    urdf: Path
    srdf: Path | None
    robots: Path  # example-robot-data's robots folder


@dataclass
class ZooRow:
    """What happened to one robot: loaded, drafted, validated, compared."""

    entry: ZooEntry
    bodies: int = 0
    dof: int = 0
    chains: list[str] = field(default_factory=list)
    grippers: int = 0
    manipulators: int = 0
    cameras: int = 0
    torso: bool = False
    neck: bool = False
    drive: str = ""
    valid: bool = False
    warnings: int = 0
    errors: int = 0
    problem: str = ""  # the first error (load or validation), paths removed
    draft: str = ""  # the draft's text
    #: For shipped robots: (hand-written chains the draft got right, hand-written chains, missed).
    compared: tuple[int, int, list[str]] | None = None
    #: For robots with a ground truth (``tests/data/draft_truth``): the draft scored against it.
    score: RobotScore | None = None


def erd_robots_folder() -> Path | None:
    """example-robot-data's ``robots`` folder, or ``None`` when it is not installed."""
    from robotspec.files.package_search import example_robot_data_folders

    folders = example_robot_data_folders()  # [share/robots, share] when installed
    return folders[0] if folders and folders[0].is_dir() else None


def zoo_entries(robots: Path) -> list[ZooEntry]:
    """Every ``*.urdf`` under ``robots``, with the SRDF of the same name (or longest prefix)."""
    out = []
    for urdf in sorted(robots.glob("*/**/*.urdf")):
        package = urdf.relative_to(robots).parts[0]
        name = f"{package}/{urdf.stem}"
        srdfs = {p.stem: p for p in sorted((robots / package).glob("**/*.srdf"))}
        stem = _SRDF_OF.get(name) or max(
            (s for s in srdfs if urdf.stem == s or urdf.stem.startswith(s)),
            key=len,
            default=None,
        )
        out.append(ZooEntry(name, urdf, srdfs.get(stem) if stem else None, robots))
    return out


def _clean(text: str, robots: Path, folder: Path) -> str:
    """The first line of a message, without this machine's folders (the page is the same anywhere).

    The robots folder becomes ``robots/``; the temporary folder, site-packages and the Python
    prefix are dropped; a list of searched folders is cut.
    """
    line = text.splitlines()[0] if text else text
    line = line.split("; searched:")[0]
    line = line.replace(str(robots), "robots")
    for p in (folder, Path(sysconfig.get_paths()["purelib"]), Path(sys.prefix)):
        line = line.replace(str(p) + "/", "").replace(str(p), p.name)
    return line


def zoo_row(entry: ZooEntry, folder: Path) -> ZooRow:
    """Load, draft (into ``folder``) and validate one robot; never raises on a bad robot."""
    from robotspec.compiler import check_spec
    from robotspec.errors import RobotSpecError
    from robotspec.spec.draft import render_draft
    from robotspec.spec.draft.render import camera_presets
    from robotspec.spec.draft.run import draft_from_files

    row = ZooRow(entry)
    robots = entry.robots
    try:
        draft, desc = draft_from_files(
            str(entry.urdf),
            None if entry.srdf is None else str(entry.srdf),
            folder=folder,
            base_folder=folder,
        )
    except RobotSpecError as e:
        row.problem = "does not load: " + _clean(str(e), robots, folder)
        return row
    world = desc.world
    row.bodies, row.dof = len(world.bodies), len(world.degrees_of_freedom)
    row.chains = [c.name for c in draft.chains]
    row.manipulators = len(draft.manipulators)
    row.grippers = sum(1 for m in draft.manipulators if m.is_gripper)
    row.cameras = len(draft.cameras)
    row.torso, row.neck = draft.torso is not None, draft.neck is not None
    row.drive = draft.drive.type if draft.drive is not None else ""
    row.draft = render_draft(draft, presets=camera_presets())
    spec = folder / (entry.name.replace("/", "__") + ".yaml")
    spec.write_text(row.draft, encoding="utf-8")
    try:
        result = check_spec(spec)
    except RobotSpecError as e:
        problems = list(getattr(e, "errors", ()) or [e])
        row.errors = len(problems)
        row.problem = _clean(str(problems[0]), robots, folder)
    else:
        row.valid = True
        row.warnings = len(result.warnings)
    shipped = next((s for s, n in SHIPPED_COMPARED.items() if n == entry.name), None)
    if shipped is not None:
        row.compared = compare_with_shipped(shipped, draft, world, desc.srdf)
    truth = _truths().get(entry.name)
    if truth is not None:
        from tools.draft_score import score_draft

        row.score = score_draft(truth, draft, world, row.valid)
    return row


_TRUTHS: dict[str, Truth] = {}


def _truths() -> dict[str, Truth]:
    """The ground truths by robot, read once."""
    from tools.draft_score import load_truths

    if not _TRUTHS:
        _TRUTHS.update({t.robot: t for t in load_truths()})
    return _TRUTHS


def compare_with_shipped(
    shipped: str, draft: object, world: object, srdf: object
) -> tuple[int, int, list[str]]:
    """How many chains (torso, neck, arms) of a shipped spec the draft has, by their joints.

    A drafted chain is right when it has the same role (torso, neck or chain) and moves the same
    actuated joints; where it starts and ends among fixed links does not count.
    """
    from robotspec.compiler import resolve_spec
    from robotspec.description.srdf import Srdf
    from robotspec.model.world import World
    from robotspec.spec.draft.model import Draft
    from robotspec.spec.draft.srdf_groups import group_chains
    from robotspec.spec.load import load_spec

    assert isinstance(draft, Draft) and isinstance(world, World)
    spec = load_spec(resolve_spec(shipped)).spec
    groups = (
        {gc.group.name: gc.joints for gc in group_chains(world, srdf)}
        if isinstance(srdf, Srdf)
        else {}
    )

    def joints(root: str | None, tip: str | None, group: str | None) -> frozenset[str]:
        if group is not None:
            return groups.get(group, frozenset())
        assert isinstance(world, World) and root is not None and tip is not None
        conns = world.compute_chain_of_connections(root, tip)
        return frozenset(c.name for c in conns if c.is_active)

    wanted: list[tuple[str, str, frozenset[str]]] = []
    if spec.torso is not None:
        wanted.append(("torso", "torso", joints(spec.torso.root, spec.torso.tip, None)))
    if spec.neck is not None:
        wanted.append(("neck", "neck", joints(spec.neck.root, spec.neck.tip, None)))
    for name, c in spec.chains.items():
        wanted.append((name, "chain", joints(c.root, c.tip, c.group)))
    have = {("chain", c.joints) for c in draft.chains}
    if draft.torso is not None:
        have.add(("torso", draft.torso.joints))
    if draft.neck is not None:
        have.add(("neck", draft.neck.joints))
    missed = [name for name, role, js in wanted if (role, js) not in have]
    return len(wanted) - len(missed), len(wanted), missed


def _yes(flag: bool) -> str:
    return "yes" if flag else "-"


#: The page's section written by hand (the blind corpus's measurements), kept when regenerating.
KEPT_SECTION = "## Blind corpus"


def kept_section(page: Path = PAGE) -> list[str]:
    """The lines of ``page``'s hand-written section (``KEPT_SECTION`` to the next ``## ``).

    Why kept and not generated: the blind corpus is measured by ``tools/corpus/measure.py``
    from third-party files a checkout may not have, at chosen moments (a baseline, an after);
    its figures are a record, not something each regeneration recomputes.
    """
    if not page.is_file():
        return []
    lines = page.read_text(encoding="utf-8").splitlines()
    if KEPT_SECTION not in lines:
        return []
    start = lines.index(KEPT_SECTION)
    end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("## ")), len(lines))
    return lines[start:end]


def zoo_page(rows: Sequence[ZooRow], kept: Sequence[str] | None = None) -> str:
    """The Markdown page ``docs/robot-zoo.md`` (``kept``: the hand-written section, else PAGE's)."""
    kept = kept_section() if kept is None else kept
    ok = sum(1 for r in rows if r.valid)
    loaded = sum(1 for r in rows if r.bodies)
    lines = [
        "# Robot zoo",
        "",
        f"<!-- Generated by `{COMMAND}` from example-robot-data; do not edit, except the"
        f" section '{KEPT_SECTION[3:]}', written by hand and kept. -->",
        "",
        "Every URDF that example-robot-data ships, with the SRDF its loaders pair with it, as a",
        "new user would bring it: `robotspec init URDF --srdf SRDF -o robot.yaml`, then",
        "`robotspec validate robot.yaml`. `tests/test_zoo.py` also checks that each world",
        "matches pinocchio's forward kinematics on random configurations.",
        "",
        f"{len(rows)} robots; {loaded} load; {ok} drafts validate as written (warnings allowed).",
        "Where a draft does not validate, the column `valid` shows the first problem.",
        "",
    ]
    compared = [r for r in rows if r.compared is not None]
    if compared:
        right = sum(r.compared[0] for r in compared if r.compared is not None)
        total = sum(r.compared[1] for r in compared if r.compared is not None)
        lines += [
            "## The draft against the hand-written specs",
            "",
            "The shipped specs (`specs/`) drafted again from the same URDF and SRDF. A drafted",
            "chain is right when it has the same role (torso, neck or chain) and moves the same",
            "joints as the hand-written one.",
            "",
            "| spec | robot | chains right | missed |",
            "| --- | --- | --- | --- |",
        ]
        for r in compared:
            assert r.compared is not None
            spec = next(s for s, n in SHIPPED_COMPARED.items() if n == r.entry.name)
            got, of, missed = r.compared
            lines.append(f"| {spec} | {r.entry.name} | {got} / {of} | {', '.join(missed) or '-'} |")
        lines += ["", f"In all: {right} of {total} hand-written chains drafted right.", ""]
    scored = [r.score for r in rows if r.score is not None]
    if scored:
        from tools.draft_score import score_lines

        lines += [
            "## The draft against ground truth",
            "",
            "Robots robotspec ships no spec for, with what an expert's spec of each holds written",
            "by hand (`tests/data/draft_truth/`), scored by `python tools/draft_score.py`: each",
            "item of the truth, and each item the draft adds that the truth lacks, counts once",
            "(see the tool's docstring for what is right).",
            "",
            *score_lines(scored),
            "",
        ]
    if kept:
        lines += [*kept] if kept[-1] == "" else [*kept, ""]
    lines += [
        "## Every robot",
        "",
        "| robot | SRDF | bodies | DOF | drafted chains | grippers of manipulators | cameras"
        " | torso | neck |"
        " drive | valid |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in rows:
        srdf = r.entry.srdf.name if r.entry.srdf is not None else "-"
        chains = ", ".join(f"`{c}`" for c in r.chains) or "-"
        grippers = f"{r.grippers} of {r.manipulators}" if r.manipulators else "-"
        if r.valid:
            valid = "yes" + (f" ({r.warnings} warnings)" if r.warnings else "")
        elif r.bodies:
            valid = f"no, {r.errors} errors: {r.problem}".replace("|", "\\|")
        else:
            valid = r.problem.replace("|", "\\|")
        lines.append(
            f"| {r.entry.name} | {srdf} | {r.bodies or '-'} | {r.dof if r.bodies else '-'} "
            f"| {chains} | {grippers} | {r.cameras or '-'} | {_yes(r.torso)} | {_yes(r.neck)} "
            f"| {r.drive or '-'} | {valid} |"
        )
    return "\n".join(lines) + "\n"


def zoo_rows(robots: Path, progress: Callable[[ZooRow], None] | None = None) -> list[ZooRow]:
    """Every robot's row (drafts are written in a temporary folder and removed)."""
    rows = []
    with tempfile.TemporaryDirectory(prefix="robotspec-zoo-") as tmp:
        for entry in zoo_entries(robots):
            row = zoo_row(entry, Path(tmp))
            rows.append(row)
            if progress is not None:
                progress(row)
    return rows


def main(argv: Sequence[str] | None = None) -> int:
    """``python tools/zoo.py [--check] [--page FILE]``: rewrite (or check) the zoo page."""
    parser = argparse.ArgumentParser(prog=COMMAND, description="Rewrite docs/robot-zoo.md.")
    parser.add_argument("--check", action="store_true", help="only report a stale page (exit 1)")
    parser.add_argument("--page", type=Path, default=None, help="the page to write")
    args = parser.parse_args(argv)
    robots = erd_robots_folder()
    if robots is None:
        sys.stderr.write("example-robot-data is not installed: pip install 'robotspec[data]'\n")
        return 2
    page: Path = args.page or PAGE
    text = zoo_page(zoo_rows(robots))
    current = page.read_text(encoding="utf-8") if page.is_file() else None
    if args.check:
        if current != text:
            sys.stderr.write(f"{page}: stale; run `{COMMAND}`\n")
            return 1
        return 0
    if current != text:
        page.write_text(text, encoding="utf-8")
        sys.stderr.write(f"wrote {page}\n")
    else:
        sys.stderr.write(f"{page} is up to date\n")
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # ``tools`` as a package
    sys.exit(main())
