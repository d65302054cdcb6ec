"""The setup page without a browser: its controls act on the session, and nothing a page sends
ends the server (the browser test, tests/test_setup_browser.py, drives the same page for real).
"""

from __future__ import annotations

import time
import urllib.request
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from robotspec.compiler import check_spec
from tests.conftest import erd_robots


class _Person:
    """A GUI event from a browser (the page ignores events the server caused itself)."""

    client = object()


class _Tab:
    """A GUI event from one browser tab (viser's client, by its id)."""

    def __init__(self, client_id: int) -> None:
        self.client = SimpleNamespace(client_id=client_id)


@pytest.fixture
def page(tmp_path: Path) -> Any:
    pytest.importorskip("viser")
    from robotspec.setup import SetupSession
    from robotspec.setup.page import SetupPage

    urdf = erd_robots() / "xarm_description" / "urdf" / "xarm7.urdf"
    session = SetupSession.open(str(urdf), output=tmp_path / "xarm.yaml")
    p = SetupPage(session, port=0)
    yield p
    p.stop()


def test_the_page_serves_and_its_controls_edit_the_spec(page: Any, tmp_path: Path) -> None:
    with urllib.request.urlopen(page.url, timeout=60) as resp:
        assert resp.status == 200
    s = page.session
    assert "3 open questions" in page._status.content and "tool" in page._tree.content
    page._picker("link3")(_Person())  # what a click on the tree's button calls
    assert page.selected == "link3"
    page.select("link_eef")
    assert page.selected == "link_eef" and "(in tool)" in page.last_message
    page._part.value = "chains.arm"
    page._select_part("chains.arm")
    assert page._f_chain.visible and not page._f_hand.visible
    page.select("link_eef")
    page._set_chain(root=page._pick())
    assert "the spec is now invalid" in page.last_message and "is empty" in page.last_message
    assert "✖ invalid" in page._status.content and "chains.arm" in page._problems.content
    page._after(s.undo(), "undone")
    assert "✔ valid" in page._status.content
    for q in s.snapshot.questions:
        s.answer(q.id)
    assert page._questions_shown == () and "0 open questions" in page._status.content
    page._state_part.value = "manipulators.tool"
    page._show_sliders()
    assert "moves no joint" in page._state_info.content
    page._state_part.value = "chains.arm"
    page._show_sliders()
    page._slide_to(0.5)
    page._state_name.value = "park"
    page._save_state()
    assert "park" in s.part_states("chains.arm")
    page._saved_states.value = "park"
    page._show_state()
    page._save()
    assert "accepts it" in page.last_message
    check_spec(tmp_path / "xarm.yaml")


def test_no_input_ends_the_server(page: Any) -> None:
    guarded = page._guarded(lambda _e: page.select("no_such_link"))
    guarded(_Person())
    assert "no link 'no_such_link'" in page.last_message.replace("&#x27;", "'")
    page._guarded(lambda _e: 1 / 0)(_Person())
    assert "internal error" in page.last_message and "ZeroDivisionError" in page.last_message
    page._guarded(lambda _e: page._set_hand(tool=True))(_Person())
    assert "choose a manipulator as the part first (not drive)" in page.last_message
    page._part.value = "manipulators.tool"
    page._guarded(lambda _e: page._set_hand(tool=True))(_Person())  # nothing picked yet
    assert "pick a link first" in page.last_message
    page.say("")
    page._guarded(lambda _e: page.select("nope"))(type("Server", (), {"client": None})())
    assert page.last_message == ""  # values the server sets itself are not a person's input
    with urllib.request.urlopen(page.url, timeout=60) as resp:
        assert resp.status == 200


def test_collision_matrix_and_audit_from_the_page(page: Any, tmp_path: Path) -> None:
    page._samples.value = 200
    page._collisions("generate")
    end = time.monotonic() + 300  # a hang bound: a few seconds at rest, more on a busy machine
    while page._busy and time.monotonic() < end:
        time.sleep(0.05)
    assert "pairs disabled" in page._collision_text.content and page._progress.value == 100.0
    # Kept in the session until save, which writes it beside the spec.
    assert page.session.draft().srdf == "xarm.srdf" and not (tmp_path / "xarm.srdf").exists()
    assert "save writes beside it" in page._collision_text.content
    page._collisions("audit")
    end = time.monotonic() + 300
    while page._busy and time.monotonic() < end:
        time.sleep(0.05)
    assert "every entry is right" in page._collision_text.content
    assert ".setup-" not in page._collision_text.content  # named as it will be saved
    assert page.session.validation.valid and not page.session.snapshot.saved
    page._save()
    assert (tmp_path / "xarm.srdf").is_file() and page.session.snapshot.saved
    assert "<disable_collisions" in (tmp_path / "xarm.srdf").read_text()
    check_spec(tmp_path / "xarm.yaml")


def test_parts_added_changed_and_removed_from_the_page(page: Any) -> None:
    s = page.session
    page.select("link7")
    page._new_kind.value = "camera"
    page._new_name.value = "wrist_cam"
    page._add_part()
    assert page._part.value == "sensors.wrist_cam" and page._f_camera.visible
    assert "sensors.wrist_cam.field_of_view" in [q.id for q in s.snapshot.questions]
    page._preset.value = s.source.presets[0]
    page._set_camera(preset=True)
    assert s.draft().cameras[0].preset == s.source.presets[0]
    page._fov.value = (1.2, 0.9)
    page._set_camera(fov=True)
    assert s.draft().cameras[0].field_of_view == (1.2, 0.9) and s.validation.valid
    # The 3D view follows the edit: the new camera's frustum is drawn on its link.
    drawn = [h.name for h in page.viewer._overlays]
    assert "/robot/link7/frustum_wrist_cam" in drawn, drawn
    page._new_kind.value = "leg"
    page._new_name.value = "tail"
    page._add_part()  # root and tip at the picked link: validate says what is wrong
    assert "the spec is now invalid" in page.last_message and "chains.tail" in s.parts()
    page._remove_part()
    assert "chains.tail" not in s.parts() and s.validation.valid
    page._part.value = "drive"
    page._select_part("drive")
    page._drive.value = "omni"
    page._guarded(lambda _e: page._after(s.set_drive(str(page._drive.value)), "set"))(_Person())
    assert s.draft().drive.type == "omni"
    page._forward.value = "faces -y"
    page._set_forward()
    assert s.draft().forward == (0.0, -1.0, 0.0) and "faces -y" in page._part_info.content
    page._guarded(lambda _e: page._remove_part())(_Person())
    assert "cannot be removed" in page.last_message


def test_a_late_older_snapshot_is_not_drawn_and_one_check_runs_at_a_time(page: Any) -> None:
    from robotspec.errors import RobotSpecError

    s = page.session
    old = s.snapshot
    s.set_state("robot", "a", {"joint1": 0.1})
    assert page.shown_version == s.snapshot.version == 1
    drawn = page._problems.content, page._status.content
    page._on_snapshot(old)  # viser's pool delivered it late: the page keeps the newer state
    assert page.shown_version == 1 and (page._problems.content, page._status.content) == drawn
    with page._busy_lock:
        page._busy = True  # a check runs (from another tab)
    with pytest.raises(RobotSpecError, match="is running"):
        page._collisions("generate")
    with page._busy_lock:
        page._busy = False


def test_each_tab_acts_on_its_own_pick(page: Any) -> None:
    """Tab B's pick never becomes tab A's arm tip (issue 33)."""
    page._part.value = "chains.arm"
    page._select_part("chains.arm")
    page._guarded(lambda _e: page.select("link3"))(_Tab(1))
    page._guarded(lambda _e: page.select("link6"))(_Tab(2))
    page._guarded(lambda _e: page._set_chain(tip=page._pick()))(_Tab(1))
    (arm,) = [c for c in page.session.draft().chains if c.name == "arm"]
    assert arm.tip == "link3"
    page._guarded(lambda _e: page._set_chain(tip=page._pick()))(_Tab(3))  # a tab with no pick
    assert "pick a link first" in page.last_message
    assert "nothing undone: the last action (pick a link first" in page.session.step(back=True)[1]


def test_a_camera_is_put_on_a_chain_from_the_parts_tab(page: Any) -> None:
    s = page.session
    s.add_camera("wrist", "link7")
    page._part.value = "sensors.wrist"
    page._select_part("sensors.wrist")
    assert page._carrier.value == "(no chain)" and "chains.arm" in page._carrier.options
    assert "on no chain" in page._part_info.content
    page._carrier.value = "chains.arm"
    page._guarded(lambda _e: page._set_carrier())(_Person())
    assert s.sensor_carrier("sensors.wrist") == "chains.arm"
    assert "carried by chains.arm" in page._part_info.content
    assert "on no chain" not in page._part_info.content


def test_one_jaw_of_a_gripper_says_why_nothing_is_written_yet(page: Any) -> None:
    page._part.value = "manipulators.tool"
    page._select_part("manipulators.tool")
    page._guarded(lambda _e: page.select("link7"))(_Tab(1))
    page._guarded(lambda _e: page._set_hand(finger=True))(_Tab(1))
    assert "finger kept; nothing written until its thumb tip is picked too" in page.last_message
    assert "type: generic" in page.last_message and "finger:" not in page.session.snapshot.text


def test_refused_inputs_say_why_at_once(page: Any) -> None:
    """A joint value past its limit is put back, an empty 'save as' named, each with why."""
    page._state_part.value = "chains.arm"
    page._show_sliders()
    lo, hi = page.session.joint_range("joint1")
    page._sliders["joint1"].value = hi + 5.0  # what a number typed in the slider's box sends
    page._guarded(lambda _e: page._slid("joint1"))(_Person())
    assert page._sliders["joint1"].value == hi
    assert f"joint1: {hi + 5.0:g} is outside its limits [{lo:g}, {hi:g}]" in page.last_message
    page._save_path.value = "  "
    page._guarded(lambda _e: page._save())(_Person())
    assert "'save as' is empty: give the file to write" in page.last_message.replace("&#x27;", "'")
    assert not page.session.snapshot.saved


def test_the_yaml_pane_and_the_proposed_tool_frame(page: Any) -> None:
    """The text save writes, the lines errors cite marked; a facing answer drawn before applied."""
    s = page.session
    assert "chains:" in page._yaml.content and "#ffd9d9" not in page._yaml.content
    page._part.value = "chains.arm"
    page._select_part("chains.arm")
    page._guarded(lambda _e: page.select("link_eef"))(_Tab(1))
    page._guarded(lambda _e: page._set_chain(root=page._pick()))(_Tab(1))  # an empty chain
    (err,) = [p for p in s.validation.errors if p.part == "chains.arm"]
    marked = [r for r in page._yaml.content.split("<div") if "#ffd9d9" in r]
    assert len(marked) == 1 and f"{err.line:>4} " in marked[0]
    assert f"line {err.line}: " in page._yaml.content  # the message listed under the text
    (q,) = [q for q in s.snapshot.questions if q.part == "manipulators.tool"]
    (choice,) = [h for h in page._q_handles if getattr(h, "label", "") == f"answer {q.id}"]
    assert page._proposed and page._proposed[-1].text == f"proposed: {choice.value} (red)"
    choice.value = "tool faces +z"
    page._proposer(q, choice)(_Person())
    assert page._proposed[-1].text == "proposed: tool faces +z (red)"
    assert page._proposed[0].name == "/robot/link_eef/proposed"


def _generated(page: Any) -> None:
    page._samples.value = 200
    page._collisions("generate")
    end = time.monotonic() + 300  # a hang bound: a few seconds at rest, more on a busy machine
    while page._busy and time.monotonic() < end:
        time.sleep(0.05)
    assert "pairs disabled" in page._collision_text.content


def test_the_collision_pairs_table_and_pairs_toggled_by_hand(page: Any) -> None:
    from robotspec.setup.pairs import pair_rows

    assert "generate the matrix" in page._pair_table.content
    _generated(page)
    rows = pair_rows(page.session)
    assert rows and {r.reason for r in rows} <= {"Adjacent", "Never", "Always", "Default"}
    assert "Adjacent" in page._pair_table.content and "pairs not checked, and why" in (
        page._pair_table.content
    )
    adjacent = next(r for r in rows if r.reason == "Adjacent")
    checked = next(
        (a, b)
        for a in page._pair_a.options
        for b in page._pair_b.options
        if a < b and not any({r.link1, r.link2} == {a, b} for r in rows)
    )
    # One pair disabled by hand, one adjacent pair checked again.
    page._pair_a.value, page._pair_b.value = checked
    page._guarded(lambda _e: page._toggle(disable=True))(_Person())
    assert "not checked (User)" in page.last_message
    page._pair_a.value, page._pair_b.value = adjacent.link1, adjacent.link2
    page._guarded(lambda _e: page._toggle(disable=False))(_Person())
    page._pair_filter.value = "User"
    page._show_pairs()
    assert page._pair_table.content.count("<tr><td>") == 1 and "✋" in page._pair_table.content

    def by_hand() -> tuple[bool, bool]:
        now = {frozenset((r.link1, r.link2)): r.reason for r in pair_rows(page.session)}
        return now.get(frozenset(checked)) == "User", frozenset(
            (adjacent.link1, adjacent.link2)
        ) not in now

    assert by_hand() == (True, True)
    _generated(page)  # regenerated: the choices made by hand are kept
    assert by_hand() == (True, True)
    page._pair_a.value = page._pair_b.value = adjacent.link1
    page._guarded(lambda _e: page._toggle(disable=True))(_Person())
    assert "a pair is two links" in page.last_message


def _press(page: Any, action: Any) -> None:
    """A button of the page pressed by a person (through the guard every control has)."""
    page._guarded(lambda _e: action())(_Person())


def test_frames_other_sensors_and_passive_joints_from_their_tab(page: Any) -> None:
    """Each refused input says why under its own inputs; each change is undone with its words."""
    from robotspec.setup.page_more import at_input

    s = page.session
    page.select("link7")
    page._frame_name.value, page._frame_xyz.value = "tcp", "0, 0, zero"
    _press(page, at_input(page._frame_note, page._add_frame))
    assert "&#x27;zero&#x27; is not a number" in page._frame_note.content
    page._frame_xyz.value = "0, 0, 0.1"
    _press(page, at_input(page._frame_note, page._add_frame))
    assert page._frame_note.content == "" and "tcp: {parent: link7, xyz: [0, 0, 0.1]}" in (
        s.snapshot.text
    )
    assert page._frame_pick.value == "tcp" and "no rotation" in page._frame_info.content
    page._rot_kind.value, page._rot_values.value = "quaternion", "0, 0, 1, 1"
    _press(page, at_input(page._frame_note, page._rotate))
    assert "is a unit one" in page._frame_note.content and "is a unit one" in page.last_message
    page._rot_kind.value, page._rot_values.value = "rpy", "[0, 0, 1.5708]"
    _press(page, at_input(page._frame_note, page._rotate))
    assert "rpy: [0, 0, 1.5708]" in s.snapshot.text and "rpy [0, 0, 1.5708]" in (
        page._frame_info.content
    )

    page._gs_name.value = " "
    _press(page, at_input(page._gs_note, page._add_sensor))
    assert "a sensor needs a name" in page._gs_note.content
    page._gs_name.value, page._gs_kind.value = "wrist_ft", "ft"
    _press(page, at_input(page._gs_note, page._add_sensor))
    assert "wrist_ft:\n    type: generic\n    body: link7\n    kind: ft" in s.snapshot.text
    assert page._gs_pick.value == "wrist_ft" and "on link7, ft" in page._gs_info.content
    page._gs_carrier.value = "chains.arm"
    _press(page, page._carry_sensor)
    assert s.sensor_carrier("sensors.wrist_ft") == "chains.arm"

    page._pj_pick.value = "joint7"
    _press(page, at_input(page._pj_note, lambda: page._passive(True)))
    assert "joint7: passive" in page.last_message and "joint7 ✋" in page._pj_list.content
    _press(page, lambda: page._stepped(back=True))
    assert "undone: joint joint7: passive" in page.last_message
    assert "no joint is passive" in page._pj_list.content
    _press(page, lambda: page._stepped(back=True))
    assert "undone: line" in page.last_message and "sensors: [wrist_ft]" not in s.snapshot.text


def test_an_accepted_warning_is_edited_and_removed_from_the_check_tab(page: Any) -> None:
    from robotspec.setup.accept import acceptances
    from robotspec.setup.page_more import at_input

    s = page.session
    page.select("link7")
    s.add_generic_sensor("wrist_ft", "link7", "ft")  # on no chain: a warning to accept
    warning = next(a for a in acceptances(s.validation) if a.at == "sensors.wrist_ft")
    s.accept_warning(warning.label, "wired to the controller box")
    assert page._acc_pick.value == warning.label
    assert "wired to the controller box" in page._acc_info.content
    page._acc_reason.value = ""
    _press(page, at_input(page._acc_note, page._reason))
    assert "give the reason" in page._acc_note.content
    page._acc_reason.value = "read by the wrist's own board"
    _press(page, at_input(page._acc_note, page._reason))
    assert page._acc_note.content == "" and "read by the wrist" in s.snapshot.text
    _press(page, at_input(page._acc_note, page._unaccept))
    assert (
        "accept_warnings" not in s.snapshot.text and page._acc_pick.value == "(no accepted warning)"
    )
    assert any(p.location[:2] == ("sensors", "wrist_ft") for p in s.validation.warnings)
