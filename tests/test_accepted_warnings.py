"""Warnings a correct spec can silence: by saying what a chain is, or accepting one.

An ``accept_warnings`` entry accepts exactly one warning: the one printed at exactly its ``at``
path whose message contains its ``says`` (issue 31: ``at: chains`` accepted a warning at
``chains.spare``, ``says: ' '`` accepted anything, duplicates passed silently).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import pytest

from robotspec.compiler import check_spec
from robotspec.diagnostics import Diagnostics, Loc
from robotspec.errors import RobotSpecError

from .conftest import erd_robots

SPARE = "  spare: {root: torso_lift_link, tip: l_elbow_flex_link}\n"
SPARE_WARNING = (
    "chains.spare: chain 'spare' has neither a manipulator nor a sensor (not an arm? say "
    "'kind: leg' or 'kind: chain')"
)
#: The spec's first line below the header written by :func:`write` (``extends: pr2`` is line 3).
FIRST = 4


def write(tmp_path: Path, text: str) -> Path:
    spec = tmp_path / "robot.yaml"
    spec.write_text("robotspec: 1\nname: W\nextends: pr2\n" + text)
    return spec


def warnings_of(tmp_path: Path, text: str, *, strict: bool = False) -> list[str]:
    erd_robots()
    return [w.message for w in check_spec(write(tmp_path, text), strict=strict).warnings]


def problems_of(tmp_path: Path, text: str) -> list[str]:
    """Every problem the spec raises, rendered as ``line:col: severity: message``."""
    erd_robots()
    with pytest.raises(RobotSpecError) as caught:
        check_spec(write(tmp_path, text))
    err = caught.value
    found = [*err.details, *(w.detail for w in err.warnings)]
    return [f"{d.line}:{d.column}: {d.severity}: {d.message}" for d in found]


def accepting(*entries: str) -> str:
    return "chains:\n" + SPARE + "accept_warnings:\n" + "".join(f"  - {e}\n" for e in entries)


def test_a_leg_or_a_lift_is_no_arm_without_a_tool(tmp_path: Path) -> None:
    chains = "chains:\n  lift: {kind: chain, root: torso_lift_link, tip: l_shoulder_pan_link}\n"
    chains += "  leg: {kind: leg, root: torso_lift_link, tip: r_shoulder_pan_link}\n"
    assert warnings_of(tmp_path, chains + SPARE) == [SPARE_WARNING]


def test_an_accepted_warning_is_gone_even_in_strict_mode(tmp_path: Path) -> None:
    accept = (
        "accept_warnings:\n"
        "  - at: chains.spare\n    says: neither a manipulator nor a sensor\n"
        "    because: the elbow carries a strain gauge we do not model\n"
    )
    assert warnings_of(tmp_path, "chains:\n" + SPARE + accept, strict=True) == []


def test_says_matches_case_and_ignores_surrounding_spaces(tmp_path: Path) -> None:
    spaced = "{at: chains.spare, says: '  has neither a  ', because: a spare}"
    assert warnings_of(tmp_path, accepting(spaced)) == []
    shouted = "{at: chains.spare, says: HAS NEITHER A, because: a spare}"
    assert warnings_of(tmp_path, accepting(shouted)) == [
        SPARE_WARNING,
        "accept_warnings[0]: no warning at 'chains.spare' says 'HAS NEITHER A'; the warning "
        f"there says '{SPARE_WARNING.removeprefix('chains.spare: ')}'",
    ]


def test_an_acceptance_matches_its_place_and_its_words_only(tmp_path: Path) -> None:
    found = warnings_of(
        tmp_path,
        accepting(
            "{at: chains.spar, says: neither a manipulator, because: typo in the place}",
            "{at: chains.spare, says: cannot move, because: other words}",
        ),
    )
    assert found == [
        SPARE_WARNING,
        "accept_warnings[0]: no warning at 'chains.spar' says 'neither a manipulator'; "
        "did you mean at: chains.spare?",
        "accept_warnings[1]: no warning at 'chains.spare' says 'cannot move'; the warning "
        f"there says '{SPARE_WARNING.removeprefix('chains.spare: ')}'",
    ]
    with pytest.raises(RobotSpecError):
        warnings_of(
            tmp_path, accepting("{at: chains.spare, says: cannot move, because: x}"), strict=True
        )


def test_a_parent_path_accepts_nothing_below_it(tmp_path: Path) -> None:
    found = warnings_of(
        tmp_path, accepting("{at: chains, says: neither a manipulator, because: all of them}")
    )
    assert found == [
        SPARE_WARNING,
        "accept_warnings[0]: no warning at 'chains' says 'neither a manipulator'; the warning "
        "at 'chains.spare' does: write at: chains.spare",
    ]


def test_the_path_is_not_part_of_the_words(tmp_path: Path) -> None:
    """``says`` is matched against the message after its ``path: `` prefix."""
    found = warnings_of(
        tmp_path, accepting("{at: chains.spare, says: 'chains.spare:', because: x}")
    )
    assert found[0] == SPARE_WARNING


@pytest.mark.parametrize("says", ["' '", "''", "neither", "'  a b c  '", '"\\t"'])
def test_says_too_short_to_identify_a_warning_is_an_error_at_its_line(
    tmp_path: Path, says: str
) -> None:
    entry = f"{{at: chains.spare, says: {says}, because: anything}}"
    problems = problems_of(tmp_path, accepting(entry))
    assert len(problems) == 1
    assert problems[0].startswith(f"{FIRST + 3}:30: error: accept_warnings[0].says: ")
    if says != "''":  # the empty string is refused by the schema's minLength first
        assert (
            "'says' must quote the warning: at least 8 characters besides spaces" in (problems[0])
        )


def test_a_repeated_entry_is_an_error_at_the_repeat(tmp_path: Path) -> None:
    entry = "{at: chains.spare, says: neither a manipulator, because: a spare}"
    problems = problems_of(tmp_path, accepting(entry, entry))
    assert problems == [
        f"{FIRST + 4}:5: error: accept_warnings[1]: repeats accept_warnings[0] (at "
        "'chains.spare' says 'neither a manipulator'); remove one of them"
    ]


def test_two_entries_accepting_one_warning_is_an_error(tmp_path: Path) -> None:
    problems = problems_of(
        tmp_path,
        accepting(
            "{at: chains.spare, says: neither a manipulator, because: a spare}",
            "{at: chains.spare, says: nor a sensor, because: the same again}",
        ),
    )
    assert problems == [
        f"{FIRST + 4}:5: error: accept_warnings[1]: accepts the same warning at 'chains.spare' "
        "as accept_warnings[0]; remove one of them"
    ]


def test_an_acceptance_needs_a_reason(tmp_path: Path) -> None:
    with pytest.raises(RobotSpecError, match="because"):
        warnings_of(
            tmp_path, "accept_warnings: [{at: chains.spare, says: neither a manipulator}]\n"
        )


# ------------------------------------------------------------ several warnings at one path
# No shipped rule puts two different warnings on one spec node today, so the collector is
# driven directly, with a spec source that places every node on a line of its own.


@dataclass
class _Entry:
    at: str
    says: str


@dataclass
class _Doc:
    file: str = "robot.yaml"


@dataclass
class _Source:
    file: Path = Path("robot.yaml")
    documents: list[_Doc] = field(default_factory=lambda: [_Doc()])
    lines: dict[Loc, int] = field(default_factory=dict)

    def position(self, loc: Loc) -> tuple[str, int | None, int | None]:
        return "robot.yaml", self.lines.setdefault(loc, len(self.lines) + 1), 1


def test_words_matching_two_warnings_at_one_path_accept_neither() -> None:
    diag = Diagnostics(_Source())
    diag.warning(("states", "park", "x"), "the two states give the same value")
    diag.warning(("states", "park", "x"), "the two states are out of order")
    diag.accept([_Entry("states.park.x", "the two states")])
    assert [e.message for e in diag.errors] == [
        "accept_warnings[0].says: 'the two states' matches 2 warnings at 'states.park.x': "
        "'the two states give the same value'; 'the two states are out of order'; quote more "
        "of the one to accept"
    ]
    assert len(diag.warnings) == 2
    diag = Diagnostics(_Source())
    diag.warning(("states", "park", "x"), "the two states give the same value")
    diag.warning(("states", "park", "x"), "the two states are out of order")
    diag.accept([_Entry("states.park.x", "give the same value")])
    assert not diag.errors
    assert [w.message for w in diag.warnings] == ["states.park.x: the two states are out of order"]


def test_a_warning_printed_twice_is_one_warning() -> None:
    diag = Diagnostics(_Source())
    for _ in range(2):
        diag.warning(("chains", "a"), "chain 'a' has neither a manipulator nor a sensor")
    diag.accept([_Entry("chains.a", "neither a manipulator")])
    assert diag.errors == [] and diag.warnings == []


def test_a_warning_outside_the_spec_cannot_be_accepted() -> None:
    diag = Diagnostics(_Source())
    diag.warnings.append(RobotSpecError("a URDF warning", file="robot.urdf", severity="warning"))
    diag.accept([_Entry("robot.urdf", "a URDF warning")])
    assert [w.message for w in diag.warnings] == [
        "a URDF warning",
        "accept_warnings[0]: no warning at 'robot.urdf' says 'a URDF warning' (any more?); "
        "remove this entry",
    ]
