"""The collision matrix pair by pair: why each pair is not checked, and a person's own choices.

Why: MoveIt's Setup Assistant shows its self-collision matrix as a table (each pair, its
reason: Adjacent, Never, Always, Default) and lets a person tick a pair by hand. Here the pairs
are the ``disable_collisions`` of the SRDF the spec names (a generated one is kept in the
session until save); a pair toggled by hand is written with reason ``User`` (or dropped, to be
checked again), and remembered in the session's ``pair_choices`` so "generate" applies it again
after regenerating: a person's choice outlives a rerun, as in MoveIt's assistant. Each toggle is
one change of the session's history: undo takes it back (the SRDF kept before it, the choice).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from robotspec.errors import closest_names
from robotspec.setup.session import SetupError, SetupSession

if TYPE_CHECKING:
    from robotspec.description.srdf import Srdf

__all__ = ["USER", "PairRow", "apply_choices", "pair_rows", "toggle_pair"]

#: The reason written for a pair a person disabled (MoveIt's assistant writes "User").
USER = "User"
#: Sort orders of the page's table.
SORTS = ("pair", "reason")


@dataclass(frozen=True)
class PairRow:
    """One disabled pair of the SRDF and why (the SRDF's reason word, or "" when it gives none)."""

    link1: str
    link2: str
    reason: str
    #: Whether a person chose this pair by hand (kept on regenerate).
    by_hand: bool


def _key(a: str, b: str) -> frozenset[str]:
    return frozenset((a, b))


def pair_rows(session: SetupSession, *, text: str = "", sort: str = "pair") -> list[PairRow]:
    """The disabled pairs of the spec's SRDF, those whose links or reason contain ``text``."""
    robot = session.validation.robot
    if robot is None or robot.srdf is None:
        return []
    needle = text.strip().lower()
    rows = [
        PairRow(d.link1, d.link2, d.reason or "", _key(d.link1, d.link2) in session.pair_choices)
        for d in robot.srdf.disabled_collisions
    ]
    rows = [r for r in rows if needle in f"{r.link1} {r.link2} {r.reason}".lower()]
    if sort == "reason":
        return sorted(rows, key=lambda r: (r.reason, r.link1, r.link2))
    return sorted(rows, key=lambda r: (r.link1, r.link2))


def apply_choices(srdf: Srdf, choices: dict[frozenset[str], bool]) -> Srdf:
    """``srdf`` with a person's choices: True disables a pair (reason User), False checks it."""
    from robotspec.description.srdf import DisabledCollision

    kept = [d for d in srdf.disabled_collisions if _key(d.link1, d.link2) not in choices]
    for pair, disabled in choices.items():
        if disabled:
            a, b = sorted(pair)
            kept.append(DisabledCollision(a, b, USER))
    return replace(srdf, disabled_collisions=tuple(kept))


def toggle_pair(session: SetupSession, link1: str, link2: str, *, disable: bool) -> str:
    """Disable (reason User) or check again one pair; the SRDF is kept until save. Says what."""
    from robotspec.export.srdf import write_srdf

    robot = session.validation.robot
    if robot is None:
        raise SetupError("the spec has errors; fix them before editing collision pairs")
    if robot.srdf is None:
        raise SetupError("the spec names no SRDF; generate the collision matrix first", kind="srdf")
    with_geometry = [b.name for b in robot.bodies_with_collisions]
    for link in (link1, link2):
        if link not in with_geometry:
            raise SetupError(
                f"no link '{link}' with collision geometry",
                kind="link",
                name=link,
                suggestions=closest_names(link, with_geometry),
            )
    if link1 == link2:
        raise SetupError(f"a pair is two links; both are '{link1}'", kind="link", name=link1)
    pair = _key(link1, link2)
    srdf = apply_choices(robot.srdf, {pair: disable})
    what = "not checked (User)" if disable else "checked again"
    name, _ = session.keep_srdf(
        write_srdf(srdf),
        extras=lambda e: e.with_pair(pair, disable),
        what=f"collision pair {link1} - {link2}: {what}",
    )
    return f"{link1} - {link2}: {what}; kept in {name} until save, and on regenerate"
