"""Which joint and body of a user's MJCF is which of the compiled robot's, by name.

Why a module of its own: the same robot is spelled differently by everyone who converted it.
Menagerie's Panda says ``joint1`` and ``link0`` where the URDF says ``panda_joint1`` and
``panda_link0``; robosuite prefixes every name with ``robot0_``. Matching goes, in order:
``--map THEIRS=OURS`` (the user's word), the same name, then the same name once the one prefix
pair that explains the most names is stripped from both sides (``""``/``"panda_"`` for
Menagerie). Nothing is matched by similarity alone: a near name is only ever a suggestion in
an error (mjlab's silent default on an unmatched pattern is the trap avoided).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from robotspec.errors import NotFoundError, RobotSpecError, closest_names

__all__ = ["Matched", "NameMatch", "best_prefixes", "match_names", "parse_map"]

#: Characters after which a name may carry a prefix (``panda_``, ``robot0/``, ``left:``).
_SEPARATORS = "_/:-."


@dataclass(frozen=True)
class Matched:
    """One of their names and the robot's name it stands for, and how that was decided."""

    theirs: str
    ours: str
    how: str  # "map", "name" or "prefix"


@dataclass(frozen=True)
class NameMatch:
    """Their names matched to ours, for one kind of thing (joints or bodies)."""

    pairs: tuple[Matched, ...]

    def ours_of(self) -> dict[str, str]:
        """Their name to ours."""
        return {m.theirs: m.ours for m in self.pairs}

    def theirs_of(self) -> dict[str, str]:
        """Our name to theirs."""
        return {m.ours: m.theirs for m in self.pairs}

    def count(self, how: str) -> int:
        """How many pairs were decided ``how``."""
        return sum(1 for m in self.pairs if m.how == how)


def parse_map(items: Iterable[str]) -> dict[str, str]:
    """``THEIRS=OURS`` strings as a mapping; a malformed or repeated one is refused."""
    out: dict[str, str] = {}
    for item in items:
        theirs, sep, ours = item.partition("=")
        theirs, ours = theirs.strip(), ours.strip()
        if not sep or not theirs or not ours:
            raise RobotSpecError(
                f"--map '{item}' is not THEIRS=OURS (a name of the MJCF, '=', a name of the robot)",
                kind="option",
                name=item,
            )
        if theirs in out and out[theirs] != ours:
            raise RobotSpecError(
                f"--map names '{theirs}' twice ('{out[theirs]}' and '{ours}')",
                kind="option",
                name=theirs,
            )
        out[theirs] = ours
    return out


def _prefixes(names: Iterable[str]) -> set[str]:
    """Every prefix ending at a separator that at least two names share, and ``""``."""
    seen: dict[str, int] = {}
    for name in names:
        for i, ch in enumerate(name[:-1]):
            if ch in _SEPARATORS:
                seen[name[: i + 1]] = seen.get(name[: i + 1], 0) + 1
    return {""} | {p for p, n in seen.items() if n >= 2}


def _stripped(names: Iterable[str], prefix: str) -> dict[str, str]:
    """Name without ``prefix`` to name, for the names that carry it."""
    return {n[len(prefix) :]: n for n in names if n.startswith(prefix) and len(n) > len(prefix)}


def best_prefixes(theirs: Sequence[str], ours: Sequence[str]) -> tuple[str, str]:
    """The pair of prefixes (theirs, ours) whose stripping makes the most names equal.

    Ties go to the shorter prefixes, so ``("", "")`` wins when plain names already agree.
    """
    best: tuple[int, int, str, str] = (0, 0, "", "")
    ours_by_prefix = {p: set(_stripped(ours, p)) for p in _prefixes(ours)}
    for pt in sorted(_prefixes(theirs)):
        stripped = set(_stripped(theirs, pt))
        for po in sorted(ours_by_prefix):
            score = len(stripped & ours_by_prefix[po])
            key = (score, -(len(pt) + len(po)), pt, po)
            if key[:2] > best[:2]:
                best = key
    return best[2], best[3]


def match_names(
    kind: str,
    theirs: Sequence[str],
    ours: Sequence[str],
    mapping: Mapping[str, str],
    prefixes: tuple[str, str],
) -> NameMatch:
    """Their ``kind`` names matched to ours: the map first, then equal names, then prefixed.

    ``mapping`` holds only the entries for this kind (checked by the caller). A name of ours
    is matched at most once; what is left unmatched on either side is the caller's to judge.
    """
    pairs: list[Matched] = []
    taken: set[str] = set()
    ours_set = set(ours)
    for t, o in mapping.items():
        pairs.append(Matched(t, o, "map"))
        taken.add(o)
    done = set(mapping)
    for t in theirs:
        if t not in done and t in ours_set and t not in taken:
            pairs.append(Matched(t, t, "name"))
            taken.add(t)
            done.add(t)
    pt, po = prefixes
    if pt or po:
        ours_stripped = _stripped(ours, po)
        for short, t in _stripped(theirs, pt).items():
            found = ours_stripped.get(short)
            if t not in done and found is not None and found not in taken:
                pairs.append(Matched(t, found, "prefix"))
                taken.add(found)
                done.add(t)
    return NameMatch(tuple(pairs))


def check_map(
    mapping: Mapping[str, str],
    their_joints: Sequence[str],
    their_bodies: Sequence[str],
    our_joints: Sequence[str],
    our_bodies: Sequence[str],
    model: str,
) -> tuple[dict[str, str], dict[str, str]]:
    """Split ``--map`` into joint and body entries; a name found on neither side is refused."""
    joints: dict[str, str] = {}
    bodies: dict[str, str] = {}
    for t, o in mapping.items():
        if t in their_joints:
            if o not in our_joints:
                raise NotFoundError("joint", o, our_joints, where=f"the robot (--map {t}={o})")
            joints[t] = o
        elif t in their_bodies:
            if o not in our_bodies:
                raise NotFoundError("body", o, our_bodies, where=f"the robot (--map {t}={o})")
            bodies[t] = o
        else:
            raise NotFoundError(
                "joint or body", t, [*their_joints, *their_bodies], where=f"{model} (--map)"
            )
    return joints, bodies


def unmatched_error(
    kind: str,
    ours: str,
    role: str,
    theirs: Sequence[str],
    free: Sequence[str],
    prefixes: tuple[str, str],
    model: str,
) -> RobotSpecError:
    """Our ``kind`` ``ours`` (needed as ``role``) has no match: name their likeliest names.

    Their names still unmatched (``free``) come first, as only one of them can be it.
    """
    pt, po = prefixes
    probe = pt + ours[len(po) :] if po and ours.startswith(po) else ours
    suggestions = closest_names(probe, free) or tuple(free[:3]) or closest_names(probe, theirs)
    near = (
        f"; closest in the model: {', '.join(repr(s) for s in suggestions)}" if suggestions else ""
    )
    hint = f" (add --map {suggestions[0] if suggestions else 'THEIRS'}={ours})"
    if not free:
        near, hint = (
            "",
            (
                f": each {kind} of the model is matched to another one of the robot, so the model "
                "has no such part (an arm without its gripper?)"
            ),
        )
    return RobotSpecError(
        f"{kind} '{ours}' ({role}) has no {kind} of the same name in {model}{near}{hint}",
        file=model,
        kind=kind,
        name=ours,
        suggestions=suggestions,
    )
