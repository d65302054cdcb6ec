"""How far two experts' truths of the same robots agree (issue 30): an inter-annotator study.

Why: the drafter was tuned against one expert's truths (``tests/data/blind_truth/``). Part of its
tune-half score may be that expert's conventions (where an arm ends, which frame is the camera),
not what the files say. A second expert wrote truths of tune robots without seeing the first
(``tests/data/blind_truth_second/``, same file names; a file holding only a comment, ``# could
not load: ...``, is skipped). Where the two experts disagree, no drafter can be right by both::

    python -m tools.corpus.agreement                # per-robot rows, totals both ways round
    python -m tools.corpus.agreement --wrong        # and every disagreement, robot by robot
    python -m tools.corpus.agreement --drafter      # the drafter against each truth, side by side

The second truth is scored against the first with ``tools/draft_score.py``'s rules, the first
taking the truth's place and the second the draft's, on the robot's world loaded as
``tools.corpus.measure`` loads it (the same files, ``-P`` folders and xacro arguments; nothing
is drafted in this mode):

* chains: the same kind and the same actuated joints; both truths get ``draft_score``'s
  normalisation (a neck carrying none of that truth's cameras is scored as a plain chain);
* tool frames: the same URDF frame, or both ``{parent: X}`` (the URDF lacks one; a new frame
  on X) with the same X. A named frame against ``{parent: X}`` disagrees even when X is the
  named frame or its parent: one expert says the URDF's frame is the tool frame, the other that
  the URDF has none (``draft_score`` counts a drafted new frame against a named one as wrong
  too, and a drafted URDF frame against ``{parent: X}``). Such pairs are marked in ``--wrong``
  and counted on their own line ("a named frame vs a new frame on it or its parent");
* grippers/hands: a parallel gripper with the same two finger tips; a hand with the same thumb
  tip and other tips;
* cameras: the same frame;
* torso, neck: the same actuated joints (present in either); drive: the same type, and the same
  base joints when both name them; forward: the same facing (when either says it is not +x).

Items, as ``draft_score`` counts a draft's: every item of the first, plus every item of the
second that matches none of the first's (an extra chain, camera, gripper/hand). One difference:
a manipulator of the second that the first lacks also counts as an extra tool frame (a draft's
extra manipulator is counted only as an extra gripper), so that both directions count the same
items. Matching is one to one, so the totals with the second as the reference must equal those
with the first as the reference; both are printed as a check. The agreement table gives, per
category, how many items each expert states and on how many both agree, and the positive
agreement ``2 * both / (first + second)``: Cohen's kappa needs the items neither states (every
link that is no camera), which have no count here, so it is given only for the drive type, where
each expert gives every robot exactly one label.

``--drafter`` drafts each of the same robots exactly as ``tools.corpus.measure`` does (its
``measure_robot``: ``robotspec init``, ``validate``, the in-process draft) and scores it against
each truth: the drafter's totals against the first truths and against the second, side by side.

Protocol: the tune half only. A robot of the held-out half (``tools.corpus.split.half``) with
truths in both folders makes the tool refuse to run (exit 2) before anything is loaded.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # ``python tools/corpus/agreement.py`` as well as ``-m``
    sys.path.insert(0, str(REPO))

from tools.corpus.measure import (  # noqa: E402
    BLIND_TRUTH,
    CorpusRobot,
    corpus_robots,
    measure_robot,
    totals_lines,
)
from tools.corpus.split import half  # noqa: E402
from tools.corpus.truth_compare import AGREEMENT, NAMED_VS_NEW, Agreement, compare  # noqa: E402
from tools.corpus.truths import load_truth_folder  # noqa: E402
from tools.draft_score import CATEGORIES, RobotScore, Truth  # noqa: E402

__all__ = ["SECOND_TRUTH", "agreement_lines", "drafter_lines", "load_world", "main"]

#: The second expert's truths.
SECOND_TRUTH = REPO / "tests" / "data" / "blind_truth_second"


def load_world(robot: CorpusRobot, tmp: Path) -> object:
    """``robot``'s world, loaded as ``measure`` drafts it (``draft_from_files``'s arguments)."""
    from robotspec.description.load import load_description

    return load_description(
        str(robot.urdf),
        srdf=None if robot.srdf is None else str(robot.srdf),
        package_paths=[str(p) for p in robot.package_paths],
        xacro_args=robot.xacro_args,
        meshes="keep",
        base_folder=tmp,
    ).world


def _cell(got: int, of: int, pct: bool = False) -> str:
    if not of:
        return "-"
    return f"{got}/{of} ({round(100 * got / of)} %)" if pct else f"{got}/{of}"


def _sum(scores: Sequence[RobotScore], category: str) -> tuple[int, int]:
    return (
        sum(s.counts.get(category, (0, 0))[0] for s in scores),
        sum(s.counts.get(category, (0, 0))[1] for s in scores),
    )


def agreement_lines(found: Sequence[Agreement], wrong: bool = False) -> list[str]:
    """The per-robot rows, the totals both ways round, the agreement table (and disagreements)."""
    head = "| robot | " + " | ".join(AGREEMENT) + " |"
    lines = [
        "Second truths scored against the first (the first as the reference):",
        "",
        head,
        "| --- |" + " --- |" * len(AGREEMENT),
    ]
    for a in found:
        cells = [_cell(*a.first.counts.get(c, (0, 0))) for c in AGREEMENT]
        lines.append(f"| {a.robot} | " + " | ".join(cells) + " |")
    lines += [
        "",
        "| reference | robots | " + " | ".join(AGREEMENT) + " |",
        "| --- | --- |" + " --- |" * len(AGREEMENT),
    ]
    for label, scores in (
        ("first", [a.first for a in found]),
        ("second", [a.second for a in found]),
    ):
        cells = [_cell(*_sum(scores, c), pct=True) for c in AGREEMENT]
        lines.append(f"| {label} | {len(scores)} | " + " | ".join(cells) + " |")
    lines += [
        "",
        "| category | first states | second states | both agree | positive agreement |",
        "| --- | --- | --- | --- | --- |",
    ]
    for c in AGREEMENT:
        first = sum(a.stated.get(c, (0, 0, 0))[0] for a in found)
        second = sum(a.stated.get(c, (0, 0, 0))[1] for a in found)
        both = sum(a.stated.get(c, (0, 0, 0))[2] for a in found)
        pa = f"{round(100 * 2 * both / (first + second))} %" if first + second else "-"
        lines.append(f"| {c} | {first} | {second} | {both} | {pa} |")
    lines += ["", _kappa_line([a.drives for a in found])]
    named = sum(NAMED_VS_NEW in w for a in found for w in a.first.wrong)
    lines += ["", f"Tool frames of the first that disagree only as {NAMED_VS_NEW}: {named}."]
    if wrong:
        lines += ["", "Disagreements (the first as the reference; 'the other' is the second):", ""]
        lines += [f"- {a.robot}: {w}" for a in found for w in a.first.wrong]
    return lines


def _kappa_line(labels: Sequence[tuple[str, str]]) -> str:
    """Cohen's kappa of the drive types: agreement beyond what the two experts' rates give."""
    n = len(labels)
    if not n:
        return "Drive type: no robots."
    observed = sum(a == b for a, b in labels) / n
    kinds = {k for pair in labels for k in pair}
    chance = sum(
        (sum(a == k for a, _ in labels) / n) * (sum(b == k for _, b in labels) / n) for k in kinds
    )
    kappa = (
        "undefined (one type only)" if chance == 1 else f"{(observed - chance) / (1 - chance):.2f}"
    )
    return (
        f"Drive type, one label per robot from each: agree on {sum(a == b for a, b in labels)} "
        f"of {n}, chance {chance:.2f}, Cohen's kappa {kappa}."
    )


def drafter_lines(pairs: Sequence[tuple[RobotScore, RobotScore]], wrong: bool = False) -> list[str]:
    """The drafter's totals against the first truths and the second, side by side."""
    firsts, seconds = [p[0] for p in pairs], [p[1] for p in pairs]
    a, b = totals_lines(firsts, "first truths"), totals_lines(seconds, "second truths")
    lines = [
        "The drafter (as tools.corpus.measure drafts) against each truth, same robots:",
        "",
        a[0].replace("| half |", "| scored against |"),
        a[1],
        a[2],
        b[2],
        "",
        "Per robot, right/counted against the first | against the second:",
        "",
        "| robot | " + " | ".join(CATEGORIES) + " |",
        "| --- |" + " --- |" * len(CATEGORIES),
    ]
    for f, s in pairs:
        cells = [
            f"{_cell(*f.counts.get(c, (0, 0)))} \\| {_cell(*s.counts.get(c, (0, 0)))}"
            for c in CATEGORIES
        ]
        lines.append(f"| {f.robot} | " + " | ".join(cells) + " |")
    if wrong:
        for label, scores in (("first", firsts), ("second", seconds)):
            lines += ["", f"Wrong against the {label} truths:", ""]
            lines += [f"- {s.robot}: {w}" for s in scores for w in s.wrong]
    return lines


def _pairs(
    first: dict[str, Truth], second: dict[str, Truth], only: Sequence[str] | None
) -> tuple[list[str], list[str]]:
    """The robot ids with both truths (``only`` those), and the holdout ids among them."""
    ids = sorted(set(first) & set(second))
    if only is not None:
        ids = [i for i in ids if i in set(only)]
    return ids, [i for i in ids if half(i) != "tune"]


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m tools.corpus.agreement [--first DIR] [--second DIR] [--wrong] [--drafter]``."""
    parser = argparse.ArgumentParser(prog="python -m tools.corpus.agreement", description=__doc__)
    parser.add_argument("--first", type=Path, default=BLIND_TRUTH, help="the reference truths")
    parser.add_argument("--second", type=Path, default=SECOND_TRUTH, help="the second truths")
    parser.add_argument("--wrong", action="store_true", help="list every disagreement")
    parser.add_argument("--drafter", action="store_true", help="score drafts against both")
    parser.add_argument("--only", nargs="*", default=None, help="robot ids (tune half only)")
    args = parser.parse_args(argv)
    for folder in (args.first, args.second):
        if not folder.is_dir():
            parser.error(f"{folder}: no such folder")
    first, skipped = load_truth_folder(args.first)
    second, skipped_second = load_truth_folder(args.second)
    skipped += skipped_second
    ids, holdout = _pairs(first, second, args.only)
    if args.only is not None:
        holdout += [i for i in args.only if half(i) != "tune" and i not in holdout]
    if holdout:
        sys.stderr.write(
            f"refused: {', '.join(sorted(holdout))}: of the held-out half "
            "(tools.corpus.split.half); this tool runs on the tune half only\n"
        )
        return 2
    robots, not_on_disk = corpus_robots()
    by_id = {r.id: r for r in robots}
    skipped += not_on_disk
    found: list[Agreement] = []
    pairs: list[tuple[RobotScore, RobotScore]] = []
    problems: list[str] = []
    with tempfile.TemporaryDirectory(prefix="robotspec-agree-") as tmp:
        for i, rid in enumerate(ids):
            robot = by_id.get(rid)
            if robot is None:
                skipped.append(f"{rid}: its files are not on disk")
                continue
            folder = Path(tmp) / str(i)
            folder.mkdir()
            if args.drafter:
                f, s, problem = _drafted(robot, first[rid], second[rid], folder)
                pairs.append((f, s))
                problems += [f"- {rid}: {problem}"] if problem else []
                continue
            found_one = _agreement(robot, first[rid], second[rid], folder, skipped)
            if found_one is not None:
                found.append(found_one)
    for msg in skipped:
        sys.stderr.write(f"skipped: {msg}\n")
    if args.drafter:
        lines = drafter_lines(pairs, args.wrong)
        lines += ["", "Problems:", "", *problems] if problems else []
    else:
        lines = agreement_lines(found, args.wrong)
    sys.stdout.write("\n".join(lines) + "\n")
    return 0


def _agreement(
    robot: CorpusRobot, first: Truth, second: Truth, tmp: Path, skipped: list[str]
) -> Agreement | None:
    from robotspec.errors import RobotSpecError

    try:
        world = load_world(robot, tmp)
    except RobotSpecError as exc:
        skipped.append(f"{robot.id}: not loaded ({type(exc).__name__})")
        return None
    return compare(first, second, world)


def _drafted(
    robot: CorpusRobot, first: Truth, second: Truth, tmp: Path
) -> tuple[RobotScore, RobotScore, str]:
    """The draft of ``robot`` (as ``measure`` makes it) scored against each truth.

    ``measure_robot`` drafts and scores in one call, so the robot is drafted once per truth:
    the same files in a fresh folder each time give the same draft (the drafter is
    deterministic). Returns both scores and what went wrong drafting (``measure``'s problem).
    """
    scores, problems = [], []
    for name, truth in (("a", first), ("b", second)):
        (tmp / name).mkdir()
        score, problem = measure_robot(robot, truth, tmp / name)
        score.robot = robot.id
        scores.append(score)
        problems += [problem] if problem and problem not in problems else []
    return scores[0], scores[1], "; ".join(problems)


if __name__ == "__main__":
    raise SystemExit(main())
