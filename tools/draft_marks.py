"""What the ``DECIDE`` marks of the drafts cost and catch, on the tune half of the blind corpus.

Why: a mark means something only if it is on the wrong items (it catches them) and off the
right ones (it costs the user a look for nothing). ``tools.corpus.measure`` counts the wrong
items without a mark; this counts, per kind of drafted item, how many the drafts mark at all,
and how many are right with a mark, so the cost of a rule is visible beside what it catches
(``robotspec/spec/draft/confidence.py`` is the rule)::

    python tools/draft_marks.py

Tune half only (the protocol of ``tools.corpus.measure``: the holdout is never looked at).
Each drafted item is right when the scorer found no fault with it: a chain, camera, torso, neck
or drive the scorer lists as wrong is wrong; a manipulator is wrong when its robot has a wrong
tool frame or gripper.
"""

from __future__ import annotations

import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

__all__ = ["main"]

KINDS = ("chains", "manipulators", "cameras", "torso/neck", "drive")


def _items(draft: object) -> list[tuple[str, str, bool]]:
    """(kind, what the scorer calls it, marked) for every drafted item."""
    from robotspec.spec.draft.model import Draft

    assert isinstance(draft, Draft)
    out = [("chains", f"drafted {c.name},", bool(c.decide)) for c in draft.chains]
    out += [("manipulators", m.name, bool(m.decide)) for m in draft.manipulators]
    out += [("cameras", f"drafted {c.body},", bool(c.decide)) for c in draft.cameras]
    for key in ("torso", "neck"):
        part = getattr(draft, key)
        if part is not None:
            out.append(("torso/neck", f"{key}:", bool(part.decide)))
    if draft.drive is not None:
        out.append(("drive", "drive:", bool(draft.drive.decide)))
    return out


def main(argv: Sequence[str] | None = None) -> int:
    """``python tools/draft_marks.py``: the table of marks by kind, on the tune half."""
    from robotspec.errors import RobotSpecError
    from robotspec.spec.draft.run import draft_from_files
    from tools.corpus.measure import _truths, corpus_robots
    from tools.draft_score import score_draft

    del argv
    robots, skipped = corpus_robots()
    for msg in skipped:
        sys.stderr.write(f"skipped: {msg}\n")
    truths = _truths()
    # kind -> [items, marked, right with a mark, wrong with a mark, wrong without]
    table = {k: [0, 0, 0, 0, 0] for k in KINDS}
    with tempfile.TemporaryDirectory(prefix="robotspec-marks-") as tmp:
        for robot in (r for r in robots if r.half == "tune"):
            try:
                draft, desc = draft_from_files(
                    str(robot.urdf),
                    None if robot.srdf is None else str(robot.srdf),
                    folder=Path(tmp),
                    package_paths=[str(p) for p in robot.package_paths],
                    base_folder=Path(tmp),
                    xacro_args=robot.xacro_args,
                )
            except RobotSpecError:
                continue
            score = score_draft(truths[robot.id], draft, desc.world, True)
            wrong = score.wrong
            for kind, what, marked in _items(draft):
                if kind == "manipulators":
                    bad = any(w.startswith(("tool frames:", "grippers/hands:")) for w in wrong)
                elif kind in ("torso/neck", "drive"):
                    bad = any(w.startswith(f"torso/neck/drive: {what}") for w in wrong)
                else:
                    bad = any(w.startswith(f"{kind}: {what}") for w in wrong)
                row = table[kind]
                row[0] += 1
                row[1] += marked
                row[2] += marked and not bad
                row[3] += marked and bad
                row[4] += bad and not marked
    lines = [
        "| drafted | items | marked | right, marked | wrong, marked | wrong, unmarked |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    lines += [f"| {k} | " + " | ".join(map(str, v)) + " |" for k, v in table.items()]
    total = [sum(v[i] for v in table.values()) for i in range(5)]
    lines.append("| **all** | " + " | ".join(map(str, total)) + " |")
    sys.stdout.write("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
