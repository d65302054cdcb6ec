"""Two truths of one robot compared item by item, with ``tools/draft_score.py``'s rules (issue 30).

Why a module of its own: the agreement study (``tools.corpus.agreement``, whose docstring gives
the rules and how items are counted) scores one expert's truth against another's as
``draft_score`` scores a draft against a truth; the rules live here, the command and its tables
there.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

from tools.draft_score import CATEGORIES, RobotScore, Truth, _neck_as_chain

__all__ = ["AGREEMENT", "NAMED_VS_NEW", "Agreement", "compare", "score_truths"]

#: The categories two truths are compared by (``valid`` is a draft's, not a truth's).
AGREEMENT = tuple(c for c in CATEGORIES if c != "valid")
#: The mark of a tool-frame disagreement between a named frame and a new one on it or its parent.
NAMED_VS_NEW = "a named frame vs a new frame on it or its parent"


@dataclass
class _Side:
    """What one comparison found: the score and, per category, [ref states, other states, agree]."""

    score: RobotScore
    stated: dict[str, list[int]] = field(default_factory=dict)

    def state(self, category: str, ref: int, other: int, agree: int) -> None:
        got = self.stated.setdefault(category, [0, 0, 0])
        got[0] += ref
        got[1] += other
        got[2] += agree


@dataclass(frozen=True)
class Agreement:
    """One robot's two truths compared both ways round.

    ``first``: the second scored with the first as the reference (its rows, its ``wrong``);
    ``second``: the other way round. ``stated``: per category, (items the first states, items
    the second states, items both agree on). ``drives``: each truth's drive type (the one
    category with exactly one label per robot from each expert, for Cohen's kappa).
    """

    robot: str
    first: RobotScore
    second: RobotScore
    stated: dict[str, tuple[int, int, int]]
    drives: tuple[str, str]


def _chain_joints(world: Any, root: str, tip: str) -> frozenset[str]:
    """The actuated joints from ``root`` to ``tip`` (as ``draft_score`` counts a truth's)."""
    from robotspec.errors import RobotSpecError

    try:
        conns = world.compute_chain_of_connections(root, tip)
    except RobotSpecError:  # the loaded files lack a link of the truth
        return frozenset({f"<no chain {root} -> {tip}>"})
    return frozenset(c.name for c in conns if c.is_active)


def _tool_key(tool: object) -> tuple[str, str]:
    """``("frame", NAME)`` for a URDF frame, ``("new", X)`` for ``{parent: X}``."""
    if isinstance(tool, dict):
        return "new", str(tool.get("parent"))
    return "frame", str(tool)


def _parent_of(world: Any, name: str) -> str | None:
    up = world.parent_connection(name) if world.has_body(name) else None
    return None if up is None else str(world.bodies[up.parent].name)


def _one_to_one(want: Sequence[Any], have: Sequence[Any]) -> list[int | None]:
    """For each of ``want``, the index of the first unused equal item of ``have`` (or None)."""
    used: set[int] = set()
    out: list[int | None] = []
    for w in want:
        hit = next((i for i, h in enumerate(have) if i not in used and h == w), None)
        if hit is not None:
            used.add(hit)
        out.append(hit)
    return out


def _compare_one(ref: Truth, other: Truth, world: Any) -> _Side:
    """``other`` scored with ``ref`` as the truth (the module docstring's rules)."""
    t, o = _neck_as_chain(ref.data, world), _neck_as_chain(other.data, world)
    side = _Side(RobotScore(ref.robot))
    s = side.score

    def chains(d: dict[str, Any]) -> list[tuple[str, tuple[str, frozenset[str]]]]:
        return [
            (
                f"{n} ({c['root']} -> {c['tip']})",
                (c.get("kind", "arm"), _chain_joints(world, c["root"], c["tip"])),
            )
            for n, c in (d.get("chains") or {}).items()
        ]

    def extras(category: str, have: Sequence[str], hits: Iterable[int | None], what: str) -> None:
        taken = {h for h in hits if h is not None}
        for i, name in enumerate(have):
            if i not in taken:
                s.add(category, False, f"the other's {name}, {what}")

    # Chains: kind and actuated joints.
    want_c, have_c = chains(t), chains(o)
    hits = _one_to_one([w for _, w in want_c], [h for _, h in have_c])
    for (name, _), hit in zip(want_c, hits, strict=True):
        s.add("chains", hit is not None, f"{name}: the other has no such chain")
    extras("chains", [n for n, _ in have_c], hits, "not a chain of the reference")
    side.state("chains", len(want_c), len(have_c), sum(h is not None for h in hits))
    # Tool frames, one to one.
    want_m = list((t.get("manipulators") or {}).items())
    have_m = list((o.get("manipulators") or {}).items())
    hits = _one_to_one(
        [_tool_key(m["tool_frame"]) for _, m in want_m],
        [_tool_key(m["tool_frame"]) for _, m in have_m],
    )
    taken = {h for h in hits if h is not None}
    for (name, m), hit in zip(want_m, hits, strict=True):
        kind, value = _tool_key(m["tool_frame"])
        shown = value if kind == "frame" else f"a new frame on {value}"
        near = _named_vs_new(
            world,
            (kind, value),
            [_tool_key(h["tool_frame"]) for i, (_, h) in enumerate(have_m) if i not in taken],
        )
        s.add(
            "tool frames",
            hit is not None,
            f"{name}: {shown}" + (f" ({NAMED_VS_NEW})" if near else ""),
        )
    for i, (name, m) in enumerate(have_m):
        if i not in taken:
            kind, value = _tool_key(m["tool_frame"])
            shown = value if kind == "frame" else f"a new frame on {value}"
            s.add(
                "tool frames",
                False,
                f"the other's {name}: {shown}, not a tool frame of the reference",
            )
    side.state("tool frames", len(want_m), len(have_m), len(taken))
    # Grippers and hands by their tips.
    want_g = [(n, _tips(m)) for n, m in want_m if m.get("type") in ("parallel_gripper", "hand")]
    have_g = [(n, _tips(m)) for n, m in have_m if m.get("type") in ("parallel_gripper", "hand")]
    hits = _one_to_one([w for _, w in want_g], [h for _, h in have_g])
    for (name, (_kind, thumb, tips)), hit in zip(want_g, hits, strict=True):
        what = f"thumb {thumb}, " if thumb else ""
        s.add("grippers/hands", hit is not None, f"{name}: {what}fingers {sorted(tips)}")
    extras("grippers/hands", [f"{n} ({g[0]})" for n, g in have_g], hits, "not one of the reference")
    side.state("grippers/hands", len(want_g), len(have_g), sum(h is not None for h in hits))
    # Cameras by frame.
    want_cam = [str(c) for c in t.get("cameras") or []]
    have_cam = [str(c) for c in o.get("cameras") or []]
    for body in want_cam:
        s.add("cameras", body in have_cam, f"{body}: not a camera of the other")
    for body in have_cam:
        if body not in want_cam:
            s.add("cameras", False, f"the other's {body}, not a camera of the reference")
    side.state(
        "cameras", len(set(want_cam)), len(set(have_cam)), len(set(want_cam) & set(have_cam))
    )
    _parts(side, t, o, world)
    return side


def _named_vs_new(world: Any, want: tuple[str, str], left: Sequence[tuple[str, str]]) -> bool:
    """Whether ``want`` and one of ``left`` are a named frame and a new one on it or its parent."""
    for kind, value in left:
        if {kind, want[0]} != {"frame", "new"}:
            continue
        named, new = (want[1], value) if want[0] == "frame" else (value, want[1])
        if new in (named, _parent_of(world, named)):
            return True
    return False


def _tips(m: dict[str, Any]) -> tuple[str, str | None, frozenset[str]]:
    """A truth's gripper as (type, thumb tip or None, the other tips)."""
    thumb = m.get("thumb") if m.get("type") == "hand" else None
    return str(m["type"]), None if thumb is None else str(thumb), frozenset(map(str, m["fingers"]))


def _parts(side: _Side, t: dict[str, Any], o: dict[str, Any], world: Any) -> None:
    """Torso, neck, drive and forward facing (one item each where ``draft_score`` counts one)."""
    s = side.score
    for key in ("torso", "neck"):
        want, have = t.get(key), o.get(key)
        if want is None and have is None:
            continue
        want_j = None if want is None else _chain_joints(world, want["root"], want["tip"])
        have_j = None if have is None else _chain_joints(world, have["root"], have["tip"])
        s.add(
            "torso/neck/drive",
            want_j == have_j,
            f"{key}: {sorted(want_j or [])} vs the other's {sorted(have_j or [])}",
        )
        side.state(
            "torso/neck/drive",
            int(want is not None),
            int(have is not None),
            int(want is not None and want_j == have_j),
        )
    want_fwd = tuple(float(v) for v in t.get("forward") or (1.0, 0.0, 0.0))
    have_fwd = tuple(float(v) for v in o.get("forward") or (1.0, 0.0, 0.0))
    if want_fwd != (1.0, 0.0, 0.0) or have_fwd != (1.0, 0.0, 0.0):
        s.add(
            "torso/neck/drive",
            want_fwd == have_fwd,
            f"forward: {list(want_fwd)} vs the other's {list(have_fwd)}",
        )
        side.state("torso/neck/drive", 1, 1, int(want_fwd == have_fwd))
    want_d = t.get("drive") or {"type": "fixed"}
    have_d = o.get("drive") or {"type": "fixed"}
    ok = want_d["type"] == have_d["type"]
    if ok and "joints" in want_d and "joints" in have_d:
        ok = list(want_d["joints"]) == list(have_d["joints"])

    def shown(d: dict[str, Any]) -> str:
        return str(d["type"]) + (f" {list(d['joints'])}" if "joints" in d else "")

    s.add("torso/neck/drive", ok, f"drive: {shown(want_d)} vs the other's {shown(have_d)}")
    side.state("torso/neck/drive", 1, 1, int(ok))


def score_truths(ref: Truth, other: Truth, world: object) -> RobotScore:
    """``other`` scored against ``ref`` as ``draft_score`` scores a draft (module docstring)."""
    return _compare_one(ref, other, world).score


def compare(first: Truth, second: Truth, world: object) -> Agreement:
    """The two truths of one robot compared both ways round."""
    a, b = _compare_one(first, second, world), _compare_one(second, first, world)
    stated = {c: (v[0], v[1], v[2]) for c, v in a.stated.items()}
    drives = (
        (first.data.get("drive") or {}).get("type", "fixed"),
        (second.data.get("drive") or {}).get("type", "fixed"),
    )
    return Agreement(first.robot, a.score, b.score, stated, (str(drives[0]), str(drives[1])))
