"""Accepting a warning with its reason in the setup assistant (setup/accept.py): the entry is new
lines only, matches the warning exactly (it disappears), undo and redo cover it, and an empty
reason is refused with why."""

from __future__ import annotations

from pathlib import Path

import pytest

from robotspec.compiler import check_spec
from robotspec.setup import SetupSession
from robotspec.setup.accept import acceptances, with_accepted
from robotspec.setup.session import SetupError
from tests.conftest import erd_robots

SRDF_WARNING = "description.srdf: group_state 'arm_up' has no group attribute"


def _kinova(tmp_path: Path) -> SetupSession:
    kinova = erd_robots() / "kinova_description"
    if not kinova.is_dir():
        pytest.skip("example-robot-data without kinova_description")
    return SetupSession.open(
        str(kinova / "robots" / "kinova.urdf"),
        srdf=str(kinova / "srdf" / "kinova.srdf"),
        output=tmp_path / "kinova.yaml",
    )


def test_the_kinova_srdf_warning_accepted_undone_and_redone(tmp_path: Path) -> None:
    s = _kinova(tmp_path)
    before = s.snapshot.text
    assert SRDF_WARNING in [a.label for a in acceptances(s.validation)]
    with pytest.raises(SetupError, match="give the reason"):
        s.accept_warning(SRDF_WARNING, "  ")
    assert s.snapshot.text == before
    with pytest.raises(SetupError, match="no warning") as missing:
        s.accept_warning("description.srdf: group_state 'arm_down'", "x")
    assert missing.value.suggestions == (SRDF_WARNING,)

    v = s.accept_warning(SRDF_WARNING, "the robot's own SRDF; arm_up is a robot-level pose")
    after = s.snapshot.text
    assert after.startswith(before)  # only new lines, at the end
    assert after[len(before) :].splitlines() == [
        "accept_warnings:",
        "  - at: description.srdf",
        "    says: \"group_state 'arm_up' has no group attribute\"",
        '    because: "the robot\'s own SRDF; arm_up is a robot-level pose"',
    ]
    assert not any("has no group attribute" in w.message for w in v.warnings)
    assert not [p for p in v.problems if p.location[:1] == ("accept_warnings",)]

    v, said = s.step(back=True)
    assert said.startswith("undone: line ") and s.snapshot.text == before
    assert any("has no group attribute" in w.message for w in v.warnings)
    v, said = s.step(back=False)
    assert said.startswith("redone: ") and s.snapshot.text == after
    out = s.save(tmp_path / "kinova.yaml")
    assert not any("has no group attribute" in w.message for w in check_spec(out).warnings)


def test_an_entry_is_added_below_the_file_s_own_list() -> None:
    text = (
        "name: x  # kept\n"
        "accept_warnings:\n"
        "- at: chains.leg\n"
        "  says: neither a manipulator nor a sensor\n"
        "  because: a leg\n"
        "states: {}\n"
    )
    assert with_accepted(text, []) is text
    new = with_accepted(text, [("torso", "is on no chain", "why not")])
    assert new.splitlines() == [
        *text.splitlines()[:5],
        "- at: torso",
        '  says: "is on no chain"',
        '  because: "why not"',
        "states: {}",
    ]
