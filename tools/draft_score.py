"""How close ``robotspec init``'s drafts come to what an expert writes, robot by robot.

Why: "the draft validates" says nothing about whether its arm ends at the wrist or its gripper
is one. Ground truth written by hand for robots of example-robot-data that robotspec ships no
spec for (``tests/data/draft_truth/*.yaml``: the chains, tool frames, grippers, cameras, torso,
neck and drive an expert's spec has) is compared with the draft of the same files, by category::

    python tools/draft_score.py      # the per-robot table and the totals

The robot zoo (``tools/zoo.py``) publishes the same table in ``docs/robot-zoo.md``.

How an item is counted: every item of the truth, plus every item the draft adds that the truth
does not have (an extra chain, camera or parallel gripper is wrong), is one; it is right when
the draft has it:

* chains: same kind (arm or leg) and the same actuated joints (fixed links at the ends do not
  count);
* tool frames: a drafted manipulator has the truth's tool frame, or, where the truth says the
  URDF lacks one (``{parent: LINK}``), a frame the draft proposes on that link;
* grippers/hands: a drafted parallel gripper whose finger tips are the truth's two; a drafted
  hand (``type: hand``) with the truth's thumb tip and other finger tips;
* cameras: a camera on the truth's frame;
* torso, neck: the same actuated joints (present in either); drive: the same type (and the
  same base joints, when the truth names them); forward: the same facing (when either says
  it is not +x).

Whether a wrong item carried a ``DECIDE`` mark (``RobotScore.unmarked`` lists those that did
not): an extra drafted chain, camera, gripper, torso, neck, drive or facing by its own mark; a
missed chain, torso or neck when a drafted chain over some of its joints is marked (the
question the user is asked is then the one that finds it), or a drafted manipulator whose
subtree holds some of its joints (legs drafted as a hand: the hand's question finds them); a
missed tool frame or gripper when some drafted manipulator is marked; a missed camera when a
drafted camera of the same device (rigidly fixed to the same link, within 10 cm: its depth
channel, its mount) is marked (the question asked about that camera is the one that finds it),
else never.

A missed item is also marked when a ``DECIDE`` question about what the draft leaves out names
it (``Draft.questions``, from ``robotspec/spec/draft/unassigned.py``; counted in the rule table
as ``(asked: left out)``): a chain, torso or neck when a question names one of its moving joints;
a manipulator's tool frame or gripper/hand when a question names a link of the truth
manipulator's subtree (below its root; a truth without one: below its tool frame's parent) or a
finger tip; a camera when a question
names its link or a link of the same device (as above). This counting was decided before the
held-out half was measured with it (round 6): it is a counting change, reported as one.

A truth's neck that carries no camera of the truth (none at or below its tip) is no valid neck (a
neck needs a sensor, as SDT's ``HasNeck``): it is scored as the plain chain a valid spec writes
(``kind: chain``, same root, tip and joints), so truths that wrote such a head as a neck and
those that wrote it as a chain count alike.

Which rule of ``robotspec/spec/draft/confidence.py`` left an item unmarked (``RobotScore.rules``:
per rule, the items it left unmarked and how many of those are wrong): a drafted item's own
``stated``; a missed item's, the rules that left the drafted items near it unmarked (``(nothing
asks)`` when none is near); ``(no rule)`` for an unmarked item no rule states (a leak).
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = [
    "CATEGORIES",
    "ASKED",
    "MARKED",
    "TRUTH",
    "RobotScore",
    "Truth",
    "load_truths",
    "main",
    "score_draft",
    "score_lines",
]

#: The ground truth files.
TRUTH = Path(__file__).resolve().parents[1] / "tests" / "data" / "draft_truth"
#: The categories, in the table's order.
CATEGORIES = ("valid", "chains", "tool frames", "grippers/hands", "cameras", "torso/neck/drive")
#: The rule table's rows for marked items, unmarked ones no rule states, missed ones none asks.
MARKED, NO_RULE, NOTHING = "(marked DECIDE)", "(no rule)", "(nothing asks)"
#: The rule table's row for missed items a question about what the draft leaves out names.
ASKED = "(asked: left out)"


def _rule_of(items: Sequence[Any], prefix: str = "") -> str | None:
    """The rules that left ``items`` (drafted near a missed one) unmarked, joined."""
    if not items:
        return NOTHING
    found: list[str] = []
    for item in items:
        stated = item.stated if isinstance(item.stated, tuple) else (item.stated,)
        found += [r for r in stated if r and r.startswith(prefix) and r not in found]
    return " + ".join(found) or None


@dataclass(frozen=True)
class Truth:
    """One robot's ground truth: its zoo name and what its expert spec holds."""

    file: str
    robot: str
    data: dict[str, Any]


def load_truths(folder: Path = TRUTH) -> list[Truth]:
    """Every ground truth file of ``folder``, by file name."""
    import yaml

    out = []
    for path in sorted(folder.glob("*.yaml")):
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
        if not isinstance(data, dict) or not isinstance(data.get("robot"), str):
            raise ValueError(f"{path}: a ground truth needs 'robot: <package>/<urdf stem>'")
        out.append(Truth(path.stem, data["robot"], data))
    return out


@dataclass
class RobotScore:
    """Per category: (right, counted) and what was wrong."""

    robot: str
    counts: dict[str, tuple[int, int]] = field(default_factory=dict)
    wrong: list[str] = field(default_factory=list)
    #: The wrong items the draft states without a ``DECIDE`` mark (a subset of ``wrong``).
    unmarked: list[str] = field(default_factory=list)
    #: Per confidence rule (``MARKED`` for items with a mark): [items, wrong among them].
    rules: dict[str, list[int]] = field(default_factory=dict)
    #: How many questions about what it leaves out the draft asks.
    questions: int = 0

    def add(
        self,
        category: str,
        right: bool,
        what: str,
        marked: bool = True,
        rule: str | None = None,
        asked: bool = False,
    ) -> None:
        """Count one item of ``category``; ``what`` says what was wrong when it is not right.

        ``marked``: whether the draft item this concerns carries a ``DECIDE`` mark (or the draft
        says nothing there); a wrong item without one is also listed in ``unmarked``.
        ``rule``: the confidence rule that left it unmarked (``None``: no rule did).
        ``asked``: a missed item no mark covers, named by a question about what the draft leaves
        out (counted as marked, in its own row of the rule table).
        """
        got, of = self.counts.get(category, (0, 0))
        self.counts[category] = (got + int(right), of + 1)
        if not right and not marked and asked:
            marked, row = True, ASKED
        else:
            row = MARKED if marked else rule or NO_RULE
        if category != "valid":
            per = self.rules.setdefault(row, [0, 0])
            per[0] += 1
            per[1] += int(not right)
        if not right:
            self.wrong.append(f"{category}: {what}")
            if not marked:
                self.unmarked.append(f"{category}: {what}")


def score_draft(truth: Truth, draft: object, world: object, valid: bool) -> RobotScore:
    """The draft of ``truth``'s robot against it (see the module docstring)."""
    from robotspec.errors import RobotSpecError
    from robotspec.model.world import World
    from robotspec.spec.draft.model import Draft

    assert isinstance(draft, Draft) and isinstance(world, World)
    t = _neck_as_chain(truth.data, world)
    s = RobotScore(truth.robot)
    s.add("valid", valid, "the draft does not validate as written")
    questions = list(getattr(draft, "questions", ()))
    s.questions = len(questions)
    asked_joints = frozenset(j for q in questions for j in q.joints)
    asked_links = frozenset(link for q in questions for link in q.links)

    def held(m: Any) -> frozenset[str]:
        """The moving joints below a drafted manipulator's root (what its question covers)."""
        if not world.has_body(m.root):
            return frozenset()
        root = world.get_body_by_name(m.root)
        return frozenset(
            c.name
            for b in world.subtree(root)
            if b is not root and (c := world.parent_connection(b)) is not None and c.is_active
        )

    def links_asked(root: str, extra: str | None = None) -> bool:
        """Whether a question names a link of ``root``'s subtree (or ``extra``)."""
        if extra is not None and extra in asked_links:
            return True
        if not world.has_body(root):
            return False
        return any(b.name in asked_links for b in world.subtree(world.get_body_by_name(root)))

    def joints(root: str, tip: str) -> frozenset[str]:
        try:
            conns = world.compute_chain_of_connections(root, tip)
        except RobotSpecError:  # the loaded files lack a link of the truth
            return frozenset({f"<no chain {root} -> {tip}>"})
        return frozenset(c.name for c in conns if c.is_active)

    # Chains: kind and joints.
    drafted = [(c.role, c.joints, c.name) for c in draft.chains]
    matched: set[int] = set()
    for name, c in (t.get("chains") or {}).items():
        want = (c.get("kind", "arm"), joints(c["root"], c["tip"]))
        hit = next((i for i, d in enumerate(drafted) if i not in matched and d[:2] == want), None)
        if hit is not None:
            matched.add(hit)
        # A miss is marked when a drafted chain over some of its joints asks to be checked.
        near: list[Any] = [d for d in draft.chains if d.joints & want[1]]
        near += [m for m in draft.manipulators if held(m) & want[1]]
        if hit is not None:
            near = [draft.chains[hit]]
        s.add(
            "chains",
            hit is not None,
            f"{name} ({c['root']} -> {c['tip']}) not drafted",
            marked=any(d.decide for d in near),
            rule=_rule_of(near),
            asked=bool(want[1] & asked_joints),
        )
    for i, (_, _, name) in enumerate(drafted):
        if i not in matched:
            s.add(
                "chains",
                False,
                f"drafted {name}, not a chain of the truth",
                marked=bool(draft.chains[i].decide),
                rule=draft.chains[i].stated,
            )
    # Tool frames and grippers.
    frames = {f.name: f.parent for f in draft.frames}
    grippers = [m for m in draft.manipulators if m.is_gripper or m.is_hand]
    # A missed tool frame or gripper is marked when a drafted manipulator asks to be checked.
    any_marked = any(m.decide for m in draft.manipulators)
    used: set[str] = set()
    for name, m in (t.get("manipulators") or {}).items():
        tool = m.get("tool_frame")
        tool_parent: str | None
        if isinstance(tool, dict):
            hits = [d for d in draft.manipulators if frames.get(d.tool_frame) == tool["parent"]]
            shown = f"a new frame on {tool['parent']}"
            tool_parent = str(tool["parent"])
        else:
            hits = [d for d in draft.manipulators if d.tool_frame == tool]
            shown = str(tool)
            up = world.parent_connection(str(tool)) if world.has_body(str(tool)) else None
            tool_parent = world.bodies[up.parent].name if up is not None else None
        ok = bool(hits)
        # The manipulator's links: its root's subtree (a truth names its root rarely), else the
        # tool frame's parent's; and its finger tips.
        m_asked = links_asked(str(m.get("root") or tool_parent or ""), tool_parent) or bool(
            {str(f) for f in (m.get("fingers") or [])} & asked_links
            or str(m.get("thumb")) in asked_links
        )
        s.add(
            "tool frames",
            ok,
            f"{name}: {shown}",
            marked=any(d.decide for d in hits) if ok else any_marked,
            rule=_rule_of(hits[:1] or draft.manipulators, "tool frame"),
            asked=m_asked,
        )
        if m.get("type") in ("parallel_gripper", "hand"):
            tips = frozenset(m["fingers"])
            want_thumb = m.get("thumb")  # a hand's; a gripper's two tips are unordered
            hit_g = next(
                (
                    g
                    for g in grippers
                    if g.name not in used and _tips(g, want_thumb is not None) == (want_thumb, tips)
                ),
                None,
            )
            if hit_g is not None:
                used.add(hit_g.name)
            what = f"thumb {want_thumb}, " if want_thumb else ""
            s.add(
                "grippers/hands",
                hit_g is not None,
                f"{name}: {what}fingers {sorted(tips)}",
                marked=bool(hit_g.decide) if hit_g is not None else any_marked,
                rule=_rule_of([hit_g], "gripper")
                if hit_g is not None
                else _rule_of(draft.manipulators),
                asked=m_asked,
            )
    for g in grippers:
        if g.name not in used:
            kind = "a hand" if g.is_hand else "a parallel gripper"
            s.add(
                "grippers/hands",
                False,
                f"drafted {g.name} as {kind}, not one",
                marked=bool(g.decide),
                rule=_rule_of([g], "gripper"),
            )
    # Cameras.
    want_cams = list(t.get("cameras") or [])
    have_cams = [c.body for c in draft.cameras]
    for body in want_cams:
        same = [c for c in draft.cameras if c.body == body]
        if not same:
            same = [c for c in draft.cameras if _same_device(world, c.body, body)]
        s.add(
            "cameras",
            body in have_cams,
            f"{body} not a camera",
            marked=any(c.decide for c in same),
            rule=_rule_of(same),
            asked=body in asked_links
            or any(_same_device(world, link, body) for link in asked_links),
        )
    for cam in draft.cameras:
        if cam.body not in want_cams:
            s.add(
                "cameras",
                False,
                f"drafted {cam.body}, not a camera of the truth",
                marked=bool(cam.decide),
                rule=cam.stated,
            )
    # Torso, neck, drive.
    for key in ("torso", "neck"):
        want_part = t.get(key)
        have_part = getattr(draft, key)
        if want_part is None and have_part is None:
            continue
        want_j = None if want_part is None else joints(want_part["root"], want_part["tip"])
        have_j = None if have_part is None else have_part.joints
        near = [have_part] if have_part is not None else []
        if have_part is None:  # a missed torso or neck, as a missed chain: a marked chain asks
            near = [d for d in draft.chains if d.joints & (want_j or frozenset())]
            near += [m for m in draft.manipulators if held(m) & (want_j or frozenset())]
        s.add(
            "torso/neck/drive",
            want_j == have_j,
            f"{key}: {sorted(have_j or [])}",
            marked=any(d.decide for d in near),
            rule=_rule_of(near),
            asked=have_part is None and bool((want_j or frozenset()) & asked_joints),
        )
    want_fwd = tuple(float(v) for v in t.get("forward") or (1.0, 0.0, 0.0))
    have_fwd = draft.forward or (1.0, 0.0, 0.0)
    if want_fwd != (1.0, 0.0, 0.0) or have_fwd != (1.0, 0.0, 0.0):
        s.add(
            "torso/neck/drive",
            want_fwd == have_fwd,
            f"forward: {list(have_fwd)}",
            marked=bool(draft.forward_decide),
        )
    drive = t.get("drive") or {"type": "fixed"}
    d = draft.drive
    ok = d is not None and d.type == drive["type"]
    if ok and "joints" in drive:
        ok = list(getattr(d, "joints", None) or []) == list(drive["joints"])
    s.add(
        "torso/neck/drive",
        ok,
        f"drive: {d.type if d is not None else None}",
        marked=d is not None and bool(d.decide),
        rule=None if d is None else d.stated,
    )
    return s


def _neck_as_chain(t: dict[str, Any], world: object) -> dict[str, Any]:
    """The truth with a neck that carries no truth camera scored as a chain (module docstring)."""
    from robotspec.model.world import World

    assert isinstance(world, World)
    neck = t.get("neck")
    if not isinstance(neck, dict) or not world.has_body(str(neck.get("tip"))):
        return t
    tip = world.get_body_by_name(str(neck["tip"]))
    cams = [str(c) for c in t.get("cameras") or [] if world.has_body(str(c))]
    if any(world.is_ancestor(tip, c) for c in cams):
        return t
    chains = dict(t.get("chains") or {})
    name = "neck" if "neck" not in chains else "neck_chain"
    chains[name] = {"root": neck["root"], "tip": neck["tip"], "kind": "chain"}
    return {**t, "chains": chains, "neck": None}


#: How far apart (m) two frames of one camera device may be.
DEVICE_SPAN = 0.1


def _same_device(world: object, a: str, b: str) -> bool:
    """Whether links ``a`` and ``b`` are one device's: fixed to one link, within 10 cm."""
    import numpy as np

    from robotspec.model.kinematics import Kinematics
    from robotspec.model.world import World

    assert isinstance(world, World)
    if not (world.has_body(a) and world.has_body(b)):
        return False

    def carrier(name: str) -> object:
        body = world.get_body_by_name(name)
        while (c := world.parent_connection(body)) is not None and c.is_fixed:
            body = world.bodies[c.parent]
        return body

    if carrier(a) is not carrier(b):
        return False
    poses = Kinematics(world).forward(world.default_configuration())
    ia, ib = world.get_body_by_name(a).index, world.get_body_by_name(b).index
    return float(np.linalg.norm(poses[ia][:3, 3] - poses[ib][:3, 3])) <= DEVICE_SPAN


def _tips(m: object, hand: bool) -> tuple[str | None, frozenset[str]]:
    """A drafted gripper's two tips (thumb ``None``), or a hand's thumb tip and other tips."""
    from robotspec.spec.draft.model import DraftManipulator

    assert isinstance(m, DraftManipulator)
    if hand:
        if not m.is_hand or m.thumb is None:
            return None, frozenset()
        return m.thumb.tip, frozenset(f.tip for f in m.fingers.values())
    if not m.is_gripper or m.thumb is None or m.finger is None:
        return None, frozenset()
    return None, frozenset((m.thumb.tip, m.finger.tip))


def _pct(got: int, of: int) -> str:
    return f"{got}/{of} ({round(100 * got / of)} %)" if of else "-"


def score_lines(scores: Sequence[RobotScore]) -> list[str]:
    """The Markdown table: one row per robot, the totals by category, and what was wrong."""
    head = "| robot | " + " | ".join(CATEGORIES) + " |"
    lines = [head, "| --- |" + " --- |" * len(CATEGORIES)]
    totals = {c: [0, 0] for c in CATEGORIES}
    for s in scores:
        cells = []
        for c in CATEGORIES:
            got, of = s.counts.get(c, (0, 0))
            totals[c][0] += got
            totals[c][1] += of
            cells.append(f"{got}/{of}" if of else "-")
        lines.append(f"| {s.robot} | " + " | ".join(cells) + " |")
    lines.append("| **all** | " + " | ".join(_pct(*totals[c]) for c in CATEGORIES) + " |")
    wrong = [(s.robot, w) for s in scores for w in s.wrong]
    if wrong:
        lines += ["", "Wrong:", ""]
        lines += [f"- {robot}: {w}".replace("|", "\\|") for robot, w in wrong]
    return lines


def main(argv: Sequence[str] | None = None) -> int:
    """``python tools/draft_score.py``: draft every robot with a ground truth, print the table."""
    import tempfile

    from tools.zoo import erd_robots_folder, zoo_entries, zoo_row

    del argv
    robots = erd_robots_folder()
    if robots is None:
        sys.stderr.write("example-robot-data is not installed: pip install 'robotspec[data]'\n")
        return 2
    entries = {e.name: e for e in zoo_entries(robots)}
    scores = []
    with tempfile.TemporaryDirectory(prefix="robotspec-score-") as tmp:
        for truth in load_truths():
            row = zoo_row(entries[truth.robot], Path(tmp))
            if row.score is not None:
                scores.append(row.score)
    sys.stdout.write("\n".join(score_lines(scores)) + "\n")
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    sys.exit(main())
