"""robotspec setup edits a spec kept in git: only the lines a change needs, in order, in memory."""

from __future__ import annotations

import copy
import difflib
import random
import shutil
import threading
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from robotspec.compiler import shipped_specs
from robotspec.setup import SetupSession
from robotspec.setup.session import SetupError, Snapshot
from robotspec.setup.text_edit import TextEditError, edit_text
from robotspec.shipped import package_data
from tests.conftest import erd_robots, shared_path

SPECS = package_data("specs")
#: Every shipped spec, composed ones and parts included, by its file.
SHIPPED = sorted([*SPECS.glob("*.yaml"), *(SPECS / "parts").glob("*.yaml")])
#: Chromium-free bound on a wait that only catches a hang (docs/testing.md).
WAIT = 60.0


def _diff(a: str, b: str) -> list[str]:
    return [
        line
        for line in difflib.unified_diff(a.splitlines(), b.splitlines(), lineterm="", n=0)
        if line[:1] in "+-" and line[:3] not in ("+++", "---")
    ]


def _open(spec: Path | str, output: Path) -> SetupSession:
    erd_robots()
    paths = [shared_path("robots", "hsrb")] if "hsrb" in str(spec) else []
    return SetupSession.open(str(spec), output=output, package_paths=paths)


@pytest.mark.parametrize("spec", SHIPPED, ids=lambda p: p.stem)
def test_open_and_save_of_every_shipped_spec_is_byte_identical(spec: Path, tmp_path: Path) -> None:
    # A copy of the shipped folder (parts beside their robots), saved over itself as a user
    # of `robotspec setup robot.yaml` does; the package's own files are never written.
    shutil.copytree(SPECS, tmp_path / "specs")
    copy = tmp_path / "specs" / spec.relative_to(SPECS)
    s = _open(copy, copy)
    assert s.snapshot.text.encode() == spec.read_bytes()
    assert s.validation.valid, [p.message for p in s.validation.errors]
    assert s.save() == copy and copy.read_bytes() == spec.read_bytes()


def test_the_pr2_torso_change_is_a_one_line_diff_with_every_comment_kept(tmp_path: Path) -> None:
    src = shipped_specs()["pr2"]
    before = src.read_text()
    s = _open("pr2", tmp_path / "pr2.yaml")
    assert s.set_state("torso", "mid", {"torso_lift_joint": 0.2}).valid
    text = s.snapshot.text
    assert _diff(before, text) == [
        "-    mid: {torso_lift_joint: 0.15}",
        "+    mid: {torso_lift_joint: 0.2}",
    ]
    assert text.count("# FIX:") == before.count("# FIX:") > 0
    saved = s.save()
    assert saved.read_text() == text and "Drafted by" not in text
    assert s.undo().valid and s.snapshot.text == before  # undone: the file again, byte for byte


def test_a_new_part_is_new_lines_in_its_mapping(tmp_path: Path) -> None:
    before = shipped_specs()["pr2"].read_text()
    s = _open("pr2", tmp_path / "pr2.yaml")
    assert s.add_manipulator("left_tool", "l_wrist_roll_link", "l_gripper_palm_link").valid
    assert s.add_chain("head", "torso_lift_link", "head_plate_frame", kind="chain").valid
    diff = _diff(before, s.snapshot.text)
    assert all(line.startswith("+") for line in diff), diff
    lines = s.snapshot.text.splitlines()
    # The chain is the last entry of chains:, the hand the last of manipulators:.
    at = lines.index("  head:  # from robotspec setup")  # the drafter's lines, its notes too
    assert lines[at - 1].startswith("        r_wrist_roll_joint") and at < lines.index(
        "manipulators:"
    )
    tools = lines[lines.index("manipulators:") : lines.index("sensors:")]
    assert "  left_tool:  # from robotspec setup" in tools
    assert s.validation.valid
    s.remove("manipulators.left_tool")
    s.remove("chains.head")
    assert s.snapshot.text == before


def test_remove_drops_a_part_and_what_names_it(tmp_path: Path) -> None:
    s = _open("pr2", tmp_path / "pr2.yaml")
    v = s.remove("manipulators.left_gripper")
    assert v.valid, [p.message for p in v.errors]
    text = s.snapshot.text
    assert "left_gripper" not in text and "right_gripper:" in text
    assert "manipulators.left_gripper" not in s.parts()
    v = s.remove("sensors.kinect")  # the neck loses its one sensor: validate says so, located
    assert "kinect" not in s.snapshot.text.split("sensors:")[-1]
    assert [p.part for p in v.errors] == ["neck"] and v.errors[0].line is not None
    with pytest.raises(SetupError, match="no part 'wheels'"):
        s.remove("wheels")
    with pytest.raises(SetupError, match="no chain 'nope'"):
        s.remove("chains.nope")


def test_add_manipulator_on_a_chain_and_refusals(tmp_path: Path) -> None:
    s = _open("ur5", tmp_path / "ur5.yaml")
    s.remove("manipulators.flange")
    v = s.add_manipulator("tool", "wrist_3_link", "tool0", chain="chains.arm")
    assert v.valid, [p.message for p in v.errors]
    robot = v.robot
    assert robot is not None and robot.get_chain("arm").manipulator.name == "tool"  # type: ignore[union-attr]
    with pytest.raises(SetupError, match="exists"):
        s.add_manipulator("tool", "wrist_3_link", "tool0")
    with pytest.raises(SetupError, match="no link 'wrist_9_link'"):
        s.add_manipulator("t2", "wrist_9_link", "tool0")
    with pytest.raises(SetupError, match="no chain 'legs'"):
        s.add_manipulator("t3", "wrist_3_link", "tool0", chain="chains.legs")
    assert s.snapshot.version == 2  # the refused ones made no state


def test_a_composed_robot_opens_with_its_parts_and_refuses_edits_to_their_files(
    tmp_path: Path,
) -> None:
    before = shipped_specs()["b1_ur5_allegro"].read_text()
    s = _open("b1_ur5_allegro", tmp_path / "b1.yaml")
    assert {"chains.ur5_arm", "manipulators.allegro_hand"} <= set(s.parts())
    origin = s.part_origin("chains.ur5_arm")
    assert origin is not None and origin.split(":")[0].endswith("ur5.yaml")
    assert s.part_origin("drive") is None
    with pytest.raises(SetupError, match=r"defined in .*ur5\.yaml:\d+.*change it in that file"):
        s.set_chain("chains.ur5_arm", tip="ur5_wrist_2_link")
    assert s.snapshot.text == before and s.snapshot.version == 0
    # A state of the composed robot's own is written into its own file.
    d = _open("dual_panda", tmp_path / "dual.yaml")
    ready = dict(d.part_states("robot")["ready"], left_panda_joint1=0.5)
    assert d.part_origin("chains.left_arm") is not None and d.part_origin("states") is None
    assert d.set_state("robot", "ready", ready).valid
    assert _diff(shipped_specs()["dual_panda"].read_text(), d.snapshot.text) == [
        "-    left_panda_joint1: 0.0",
        "+    left_panda_joint1: 0.5",
    ]


_XACRO = """<?xml version="1.0"?>
<robot name="stick" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="length" default="0.5"/>
  <link name="base"/>
  <link name="upper"/>
  <link name="tip"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="elbow" type="revolute">
    <origin xyz="0 0 $(arg length)"/>
    <parent link="upper"/><child link="tip"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>
"""

_STICK = """robotspec: 1
name: Stick  # a xacro robot with arguments, a rotated frame and a generic sensor
description:
  urdf: stick.urdf.xacro
  xacro_args: {length: '0.25'}
  frames:
    tool: {parent: tip, xyz: [0, 0, 0.1], rpy: [0.0, 1.5707963, 0.0]}  # turned
root: base
drive: {type: fixed}

chains:
  arm:
    root: base
    tip: tip
    manipulator: tool
manipulators:
  tool: {type: generic, root: tip, tool_frame: tool}
sensors:
  wrist_imu: {type: generic, body: tip}  # kept as written
"""


def test_xacro_args_rotated_frames_and_generic_sensors_open_and_are_kept(tmp_path: Path) -> None:
    (tmp_path / "stick.urdf.xacro").write_text(_XACRO)
    spec = tmp_path / "stick.yaml"
    spec.write_text(_STICK)
    s = SetupSession.open(str(spec), output=spec)
    assert s.snapshot.text == _STICK and s.validation.valid, s.validation.errors
    assert "sensors.wrist_imu" not in s.parts()  # not a camera: kept, not edited in the page
    assert s.set_state("chains.arm", "bent", {"shoulder": 0.0, "elbow": 0.5}).valid
    assert _diff(_STICK, s.snapshot.text) == [
        "+    states:",
        "+      bent: {shoulder: 0, elbow: 0.5}",
    ]
    robot = s.validation.robot
    assert robot is not None and robot.world.has_body("tool")
    s.save()
    assert spec.read_text() == s.snapshot.text


def test_edit_text_sets_adds_and_deletes_only_what_changed() -> None:
    text = "a: 1  # one\n\nb:\n  c: 'x'   # quoted\n  d: [1, 2]\ne: {f: 1}\n"
    old = {"a": 1, "b": {"c": "x", "d": [1, 2]}, "e": {"f": 1}}
    assert edit_text(text, old, old) == text
    new = {"a": 2, "b": {"c": "x", "g": 3}, "e": {"f": 1, "h": 2}}
    assert edit_text(text, old, new) == (
        "a: 2  # one\n\nb:\n  c: 'x'   # quoted\n  g: 3\ne: {f: 1, h: 2}\n"
    )


def test_snapshots_reach_a_listener_in_the_order_the_session_made_them(tmp_path: Path) -> None:
    """The old session called each thread's listeners after its lock: newest-first, [2, 1]."""
    s = _open("ur5", tmp_path / "ur5.yaml")
    seen: list[int] = []
    second: list[threading.Thread] = []

    def edit_two() -> None:
        s.set_state("robot", "b", {"shoulder_pan_joint": 0.2})

    def listener(snap: Snapshot) -> None:
        if snap.version == 1 and not second:
            # While this state is being delivered, another thread makes the next one.
            second.append(threading.Thread(target=edit_two))
            second[0].start()
            second[0].join(WAIT)
            assert not second[0].is_alive()
        seen.append(snap.version)

    s.subscribe(listener)
    s.set_state("robot", "a", {"shoulder_pan_joint": 0.1})
    second[0].join(WAIT)
    assert seen == [1, 2] and s.snapshot.version == 2


def test_edit_text_empties_a_block_keeps_line_breaks_and_refuses_aliases() -> None:
    text = "a:\n  b: 1  # gone with b\n# kept\nc: 2\n"
    assert edit_text(text, {"a": {"b": 1}, "c": 2}, {"a": {}, "c": 2}) == "a: {}\n# kept\nc: 2\n"
    crlf = "a: 1\r\nb:\r\n  c: 2\r\n"
    out = edit_text(crlf, {"a": 1, "b": {"c": 2}}, {"a": 1, "b": {"c": 2, "d": 3}})
    assert out == "a: 1\r\nb:\r\n  c: 2\r\n  d: 3\r\n"
    shared = "base: &arm {root: a, tip: b}\nchains:\n  left: *arm\n"
    data = {"base": {"root": "a", "tip": "b"}, "chains": {"left": {"root": "a", "tip": "b"}}}
    changed = {"base": data["base"], "chains": {"left": {"root": "a", "tip": "c"}}}
    with pytest.raises(TextEditError, match="chains.left.tip is written through a YAML alias"):
        edit_text(shared, data, changed)


def test_keeping_a_guess_removes_its_mark_and_nothing_else(tmp_path: Path) -> None:
    urdf = erd_robots() / "xarm_description" / "urdf" / "xarm7.urdf"
    draft = SetupSession.open(str(urdf), output=tmp_path / "xarm.yaml")
    spec = draft.save()
    before = spec.read_text()
    s = SetupSession.open(str(spec), output=spec)
    assert s.snapshot.text == before
    s.answer("drive")
    diff = _diff(before, s.snapshot.text)
    assert len(diff) == 2 and diff[0].startswith("-drive:") and "DECIDE" in diff[0]
    assert diff[1] == diff[0][:1].replace("-", "+") + diff[0][1:].split("  # DECIDE:")[0]


def test_validation_writes_nothing_beside_the_users_files(tmp_path: Path) -> None:
    urdf = erd_robots() / "xarm_description" / "urdf" / "xarm7.urdf"
    s = SetupSession.open(str(urdf), output=tmp_path / "xarm.yaml")
    s.set_state("robot", "a", {"joint1": 0.1})
    name, v = s.keep_srdf('<?xml version="1.0"?>\n<robot name="UF_ROBOT"/>\n')
    assert v.valid, [p.message for p in v.errors]
    s.set_state("robot", "b", {"joint1": 0.2})
    assert list(tmp_path.iterdir()) == []  # neither the spec nor the kept SRDF, nor a scratch
    s.save()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([name, "xarm.yaml"])


def test_a_new_camera_keeps_its_open_question_in_the_saved_file(tmp_path: Path) -> None:
    before = shipped_specs()["ur5"].read_text()
    out = tmp_path / "ur5.yaml"
    s = _open("ur5", out)
    assert s.add_camera("wrist_cam", "wrist_3_link").valid
    assert [q.id for q in s.snapshot.questions] == ["sensors.wrist_cam.field_of_view"]
    diff = _diff(before, s.snapshot.text)
    assert all(line.startswith("+") for line in diff) and diff[0] == "+sensors:"
    assert "# DECIDE: the camera's angles" in diff[-1]
    s.save()
    again = SetupSession.open(str(out), output=out)  # the question is still the file's
    assert [q.id for q in again.snapshot.questions] == ["sensors.wrist_cam.field_of_view"]
    again.answer("sensors.wrist_cam.field_of_view", "preset: realsense_d435")
    assert _diff(out.read_text(), again.snapshot.text) == [
        "-    field_of_view: {horizontal: 1.0, vertical: 0.75}  # DECIDE: the camera's angles; "
        "or replace this line with 'preset: NAME' (kinect_v1, xtion_pro_live, realsense_d435, "
        "generic_optical)",
        "+    preset: realsense_d435",
    ]


def test_a_new_part_in_a_section_that_lost_its_only_entry_keeps_the_drafters_lines(
    tmp_path: Path,
) -> None:
    s = _open("pr2", tmp_path / "pr2.yaml")
    s.add_camera("cam1", "head_plate_frame")
    s.remove("sensors.kinect")  # sensors: held only the kinect in the file
    text = s.snapshot.text
    assert "sensors:\n  cam1:\n    type: camera\n" in text
    assert "field_of_view: {horizontal: 1.0, vertical: 0.75}  # DECIDE: the camera's angles" in text


def _mutate(data: dict[str, Any], rng: random.Random) -> dict[str, Any]:
    """``data`` with a few keys set, added or deleted, at any depth."""
    out = copy.deepcopy(data)
    values: list[Any] = [1.5, "x y", {"root": "a", "tip": "b"}, [1, 2], {"s": {"j": 0.1}}, {}]

    def walk(d: dict[str, Any]) -> None:
        for _ in range(rng.randint(1, 3)):
            if not d:
                return
            k = rng.choice(list(d))
            r = rng.random()
            if r < 0.2 and len(d) > 1:
                del d[k]
            elif r < 0.4:
                d[f"new_{rng.randint(0, 99)}"] = copy.deepcopy(rng.choice(values))
            elif r < 0.6:
                d[k] = copy.deepcopy(rng.choice([0.25, "name", [0.0, 1.0], {"q": 1}, {}]))
            elif isinstance(d[k], dict):
                walk(d[k])

    walk(out)
    return out


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), which=st.integers(0, len(SHIPPED) - 1))
def test_edit_text_states_exactly_the_new_data(seed: int, which: int) -> None:
    """Whatever changes, the edited text reads as the new data; what did not change stays."""
    text = SHIPPED[which].read_text()
    old = yaml.safe_load(text)
    new = _mutate(old, random.Random(seed))
    out = edit_text(text, old, new)
    assert yaml.safe_load(out) == new
    if new == old:
        assert out == text


def test_what_the_page_changes_reads_back_as_the_same_draft(tmp_path: Path) -> None:
    """Random session edits on the PR2: the saved text, reopened, is the session's draft."""
    from robotspec.setup.round_trip import data_of

    rng = random.Random(7)
    s = _open("pr2", tmp_path / "pr2.yaml")
    links = list(s.world.body_names)
    out = tmp_path / "check.yaml"
    for step in range(12):
        part = rng.choice(s.parts())
        try:
            match rng.choice(("state", "chain", "remove", "add", "camera", "answer", "undo")):
                case "state":
                    joints = s.part_joints("robot")[step : step + 2]
                    s.set_state("robot", rng.choice("ab"), dict.fromkeys(joints, 0.1 * step))
                case "chain" if part.partition(".")[0] in ("chains", "torso", "neck"):
                    s.set_chain(part, tip=rng.choice(links), kind=rng.choice((None, "leg")))
                case "remove" if part != "drive":
                    s.remove(part)
                case "add":
                    s.add_manipulator(f"h{step}", rng.choice(links), rng.choice(links))
                case "camera":
                    s.add_camera(f"cam{step}", rng.choice(links))
                case "answer" if s.snapshot.questions:
                    q = rng.choice(s.snapshot.questions)
                    s.answer(q.id, rng.choice(q.choices))
                case "undo":
                    s.undo()
        except SetupError:
            continue
        out.write_text(s.snapshot.text)
        again = SetupSession.open(str(out), output=out)
        assert data_of(again.draft()) == data_of(s.draft())
        assert [q.id for q in again.snapshot.questions] == [q.id for q in s.snapshot.questions]
