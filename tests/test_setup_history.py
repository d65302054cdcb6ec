"""Undo and redo in the setup assistant: each step said in the spec's words, a failure not undone
past, "nothing to undo" when so (the session every tab shares; setup/history.py)."""

from __future__ import annotations

from pathlib import Path

import pytest

from robotspec.compiler import shipped_specs
from robotspec.setup import SetupSession
from robotspec.setup.history import History, describe
from robotspec.setup.session import SetupError
from tests.conftest import erd_robots


def test_the_pr2_torso_change_is_undone_and_redone_with_its_description(tmp_path: Path) -> None:
    erd_robots()
    before = shipped_specs()["pr2"].read_text()
    s = SetupSession.open("pr2", output=tmp_path / "pr2.yaml")
    assert s.step(back=True)[1] == "nothing to undo"
    assert s.step(back=False)[1] == "nothing to redo"
    s.set_state("torso", "mid", {"torso_lift_joint": 0.2})
    after = s.snapshot.text
    line = 1 + after.splitlines().index("    mid: {torso_lift_joint: 0.2}")
    v, said = s.step(back=True)
    assert said == (
        f"undone: line {line}: mid: {{torso_lift_joint: 0.15}} -> mid: {{torso_lift_joint: 0.2}}"
    )
    assert v.valid and s.snapshot.text == before
    v, said = s.step(back=False)
    assert said.startswith(f"redone: line {line}: ") and s.snapshot.text == after
    versions = s.snapshot.version
    assert s.step(back=False)[1] == "nothing to redo" and s.snapshot.version == versions


def test_a_failed_action_is_not_undone_past(tmp_path: Path) -> None:
    urdf = erd_robots() / "xarm_description" / "urdf" / "xarm7.urdf"
    s = SetupSession.open(str(urdf), output=tmp_path / "xarm.yaml")
    s.set_chain("chains.arm", tip="link7")
    good = s.snapshot.text
    with pytest.raises(SetupError) as exc:
        s.set_chain("chains.arm", tip="no_such_link")
    s.failed(exc.value.message)  # what the page does with every refused action
    v, said = s.step(back=True)  # the failure changed nothing: nothing undone, and it says so
    assert said.startswith("nothing undone: the last action (") and "undo again undoes" in said
    assert s.snapshot.text == good
    assert s.step(back=True)[1].startswith("undone: ") and s.snapshot.text != good
    with pytest.raises(SetupError):
        s.remove_state("chains.arm", "nope")  # refused inside the change: the session notes it
    assert "no state 'nope'" in s.step(back=True)[1]
    s.failed("pick a link first")  # a page action that failed before reaching the session
    assert "pick a link first" in s.step(back=True)[1]
    assert s.step(back=True)[1] == "nothing to undo"


def test_a_new_change_ends_what_can_be_redone() -> None:
    h: History[int] = History()
    h.record(0, 1, "one")
    h.record(1, 2, "two")
    assert h.undo()[1] == "undone: two"
    h.record(1, 3, "three")
    assert h.redo() == (None, "nothing to redo")
    assert [st.what for st in h.undo_steps] == ["one", "three"]


def test_describe_names_the_first_changed_line_and_counts_the_rest() -> None:
    assert describe("a: 1\nb: 2\n", "a: 1\nb: 3\n") == "line 2: b: 2 -> b: 3"
    assert describe("a: 1\n", "a: 1\nb: 2\nc: 3\n") == "line 2 added: b: 2 (and 1 more line)"
    assert describe("a: 1\nb: 2\n", "a: 1\n") == "line 2 removed: b: 2"
    assert describe("x", "x") == "no change to the text"
