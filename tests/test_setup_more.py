"""What a spec says beyond a draft, said in the setup assistant (setup/edits_more.py, passive.py):
a frame's rotation, a generic sensor, a camera's axis, an accepted warning's reason, a passive
joint, a collision pair; each a diff of its own lines, on a shipped spec and on a spec drafted
for a robot nobody specified, and each undone and redone with its description."""

from __future__ import annotations

import difflib
import shutil
from pathlib import Path

import pytest
import yaml

from robotspec.compiler import check_spec, shipped_specs
from robotspec.setup import SetupSession
from robotspec.setup.session import SetupError
from robotspec.shipped import package_data
from tests.conftest import erd_robots

SPECS = package_data("specs")
SRDF_WARNING = "description.srdf: group_state 'arm_up' has no group attribute"


def _diff(a: str, b: str) -> list[str]:
    return [
        line
        for line in difflib.unified_diff(a.splitlines(), b.splitlines(), lineterm="", n=0)
        if line[:1] in "+-" and line[:3] not in ("+++", "---")
    ]


def _allegro(tmp_path: Path) -> tuple[SetupSession, Path]:
    erd_robots()
    shutil.copytree(SPECS, tmp_path / "specs")
    spec = tmp_path / "specs" / "parts" / "allegro_right_hand.yaml"
    return SetupSession.open(str(spec), output=spec), spec


def _kinova_spec(tmp_path: Path) -> Path:
    """The Kinova drafted as ``init`` drafts it (every guess kept), saved: nobody's spec."""
    kinova = erd_robots() / "kinova_description"
    if not kinova.is_dir():
        pytest.skip("example-robot-data without kinova_description")
    out = tmp_path / "kinova.yaml"
    s = SetupSession.open(
        str(kinova / "robots" / "kinova.urdf"),
        srdf=str(kinova / "srdf" / "kinova.srdf"),
        output=out,
    )
    for q in s.snapshot.questions:
        s.answer(q.id)
    s.accept_warning(SRDF_WARNING, "arm_up is a pose of the whole robot")
    s.save()
    return out


def test_a_frames_rotation_is_its_own_line_on_a_shipped_spec(tmp_path: Path) -> None:
    s, spec = _allegro(tmp_path)
    before = spec.read_text()
    assert s.frames()["grasp_frame"]["rpy"] == [0.0, 1.5707963, 0.0]
    assert s.set_frame_rotation("grasp_frame", "rpy", [0, 1.5707963, 0.5]).valid
    assert _diff(before, s.snapshot.text) == [
        "-    grasp_frame: {parent: palm_link, xyz: [0.04, 0.0, 0.06], rpy: [0.0, 1.5707963, 0.0]}",
        "+    grasp_frame: {parent: palm_link, xyz: [0.04, 0.0, 0.06], rpy: [0, 1.5707963, 0.5]}",
    ]
    assert s.set_frame_rotation("grasp_frame", "quaternion", [0, 0.7071068, 0, 0.7071068]).valid
    assert _diff(before, s.snapshot.text)[1] == (
        "+    grasp_frame: {parent: palm_link, xyz: [0.04, 0.0, 0.06], "
        "quaternion: [0, 0.7071068, 0, 0.7071068]}"
    )
    robot = s.validation.robot
    assert robot is not None and robot.world.has_body("grasp_frame")
    refusals = {
        ("quaternion", (0, 0, 1, 1)): "is a unit one: the norm of [0, 0, 1, 1] is 1.414",
        ("rpy", (0, 1)): "rpy takes 3 numbers, not 2",
        ("rpy", (0, float("nan"), 0)): "nan is not a finite number",
        ("sideways", ()): "a rotation is none, rpy, quaternion",
    }
    for (kind, values), why in refusals.items():
        with pytest.raises(SetupError, match=why.replace("[", r"\[").replace("]", r"\]")):
            s.set_frame_rotation("grasp_frame", kind, values)
    with pytest.raises(SetupError, match="no frame 'grasp'") as unknown:
        s.set_frame_rotation("grasp", "none")
    assert unknown.value.suggestions == ("grasp_frame",)
    v, said = s.step(back=True)
    assert said.startswith("undone: line 11: grasp_frame: {parent: palm_link")
    v, said = s.step(back=True)
    assert s.snapshot.text == before and v.valid
    assert s.set_frame_rotation("grasp_frame", "none").valid
    assert "rpy" not in s.snapshot.text.splitlines()[10]
    s.save()
    assert not [w for w in check_spec(spec).warnings if "grasp_frame" in str(w)]


def test_a_generic_sensor_added_changed_carried_and_removed_on_the_pr2(tmp_path: Path) -> None:
    erd_robots()
    before = shipped_specs()["pr2"].read_text()
    s = SetupSession.open("pr2", output=tmp_path / "pr2.yaml")
    assert s.add_generic_sensor("base_laser", "base_laser_link", "lidar").valid
    assert _diff(before, s.snapshot.text) == [
        "+  base_laser:",
        "+    type: generic",
        "+    body: base_laser_link",
        "+    kind: lidar",
    ]
    lines = s.snapshot.text.splitlines()
    assert lines[lines.index("  base_laser:") - 1] == "    default: true"  # the kinect's last
    added = s.snapshot.text
    assert s.set_generic_sensor("base_laser", kind="hokuyo").valid
    assert _diff(added, s.snapshot.text) == ["-    kind: lidar", "+    kind: hokuyo"]
    assert s.set_sensor_carrier("sensors.base_laser", "neck").valid
    assert _diff(added, s.snapshot.text)[:2] == [
        "-  sensors: [kinect]",
        "+  sensors: [kinect, base_laser]",
    ]
    assert s.sensor_carrier("sensors.base_laser") == "neck"
    with pytest.raises(SetupError, match="no link 'base_lazer_link'"):
        s.add_generic_sensor("imu", "base_lazer_link")
    with pytest.raises(SetupError, match="a sensor 'kinect' exists already"):
        s.add_generic_sensor("kinect", "base_link")
    with pytest.raises(SetupError, match="a sensor needs a name"):
        s.add_generic_sensor("  ", "base_link")
    assert s.remove_generic_sensor("base_laser").valid
    assert s.snapshot.text == before  # its lines and its name on the neck gone
    assert s.step(back=True)[1].startswith("undone: ") and "base_laser" in s.snapshot.text


def test_a_camera_looks_along_another_axis_and_reads_back(tmp_path: Path) -> None:
    spec = _kinova_spec(tmp_path)
    s = SetupSession.open(str(spec), output=spec)
    assert s.add_camera("wrist_camera", "j2s6s200_link_6", optical=False).valid
    s.set_camera("sensors.wrist_camera", preset=s.source.presets[0])
    s.save()
    s = SetupSession.open(str(spec), output=spec)
    text = s.snapshot.text
    assert s.set_camera_axis("sensors.wrist_camera", (0.0, -1.0, 0.0)).valid
    assert _diff(text, s.snapshot.text) == [
        "-    forward_facing_axis: [1, 0, 0]  # a body frame: looks along +x",
        "+    forward_facing_axis: [0, -1, 0]  # a body frame: looks along +x",
    ]
    with pytest.raises(SetupError, match="a unit vector"):
        s.set_camera_axis("sensors.wrist_camera", (0.0, 2.0, 0.0))
    s.save()
    again = SetupSession.open(str(spec), output=spec)
    cam = next(c for c in again.draft().cameras if c.name == "wrist_camera")
    assert cam.axis == (0.0, -1.0, 0.0) and again.snapshot.text == s.snapshot.text
    assert again.set_camera_axis("sensors.wrist_camera", (0.0, 0.0, 1.0)).valid
    assert "forward_facing_axis" not in again.snapshot.text  # +z: an optical frame's default


def test_an_accepted_warnings_reason_changed_and_the_entry_removed(tmp_path: Path) -> None:
    spec = _kinova_spec(tmp_path)
    before = spec.read_text()
    s = SetupSession.open(str(spec), output=spec)
    at, says = SRDF_WARNING.split(": ", 1)
    assert s.accepted_entries() == [(at, says, "arm_up is a pose of the whole robot")]
    assert s.set_accepted_reason(at, says, "the SRDF's own robot-level pose").valid
    assert _diff(before, s.snapshot.text) == [
        '-    because: "arm_up is a pose of the whole robot"',
        '+    because: "the SRDF\'s own robot-level pose"',
    ]
    with pytest.raises(SetupError, match="give the reason"):
        s.set_accepted_reason(at, says, "   ")
    with pytest.raises(SetupError, match="no accept_warnings entry") as unknown:
        s.remove_accepted(at, "group_state 'arm_up' has no group")
    assert unknown.value.suggestions == (SRDF_WARNING,)
    v = s.remove_accepted(at, says)
    assert [line[0] for line in _diff(before, s.snapshot.text)] == ["-"] * 4
    assert any("has no group attribute" in w.message for w in v.warnings)  # warned again
    assert yaml.safe_load(s.snapshot.text).get("accept_warnings") is None
    # Accepted again in this session: its own new lines, which the page edits in the draft.
    s.accept_warning(SRDF_WARNING, "first reason")
    assert s.set_accepted_reason(at, says, "second reason").valid
    assert s.snapshot.text.endswith('    because: "second reason"\n')
    assert s.remove_accepted(at, says).valid and "accept_warnings" not in s.snapshot.text


def test_a_passive_joint_and_a_collision_pair_are_undone_and_redone(tmp_path: Path) -> None:
    from robotspec.setup.pairs import pair_rows, toggle_pair
    from robotspec.setup.passive import passive_rows, set_passive

    erd_robots()
    before = shipped_specs()["pr2"].read_text()
    s = SetupSession.open("pr2", output=tmp_path / "pr2.yaml")
    said = set_passive(s, "head_tilt_joint", passive=True)
    assert said.startswith("head_tilt_joint: passive") and "kept in pr2.srdf" in said
    assert _diff(before, s.snapshot.text) == [
        "-  srdf: package://example-robot-data/robots/pr2_description/srdf/pr2.srdf",
        "+  srdf: pr2.srdf",
    ]
    robot = s.validation.robot
    assert robot is not None and "head_tilt_joint" not in [
        c.name for c in robot.controlled_connections
    ]
    assert next(r for r in passive_rows(s) if r.joint == "head_tilt_joint").by_hand
    with pytest.raises(SetupError, match="no moving joint 'head_tilt'"):
        set_passive(s, "head_tilt", passive=True)

    link1, link2 = "base_link", "l_forearm_link"
    toggle_pair(s, link1, link2, disable=True)
    assert any(r.by_hand and {r.link1, r.link2} == {link1, link2} for r in pair_rows(s))
    v, undone = s.step(back=True)
    assert undone == f"undone: collision pair {link1} - {link2}: not checked (User)"
    assert not s.pair_choices and not any(r.by_hand for r in pair_rows(s))
    _, redone = s.step(back=False)
    assert redone == f"redone: collision pair {link1} - {link2}: not checked (User)"
    assert s.pair_choices == {frozenset((link1, link2)): True}
    s.step(back=True)
    _, undone = s.step(back=True)
    assert undone.startswith("undone: joint head_tilt_joint: passive")
    assert s.snapshot.text == before and not s.extras.passive and s.extras.srdf is None
    assert not next(r for r in passive_rows(s) if r.joint == "head_tilt_joint").passive


def test_each_edit_is_its_own_lines_on_a_spec_nobody_specified(tmp_path: Path) -> None:
    """The drafted Kinova: a frame added, moved and turned; a joint made passive."""
    from robotspec.setup.passive import set_passive

    spec = _kinova_spec(tmp_path)
    before = spec.read_text()
    s = SetupSession.open(str(spec), output=spec)
    assert s.add_frame("grasp", "j2s6s200_end_effector", (0, 0, 0.05)).valid
    assert _diff(before, s.snapshot.text) == [
        "+  frames:",
        "+    grasp: {parent: j2s6s200_end_effector, xyz: [0, 0, 0.05]}",
    ]
    added = s.snapshot.text
    assert s.set_frame_position("grasp", (0, 0, 0.06)).valid
    assert s.set_frame_rotation("grasp", "rpy", (0, 0, 3.1416)).valid
    assert _diff(added, s.snapshot.text) == [
        "-    grasp: {parent: j2s6s200_end_effector, xyz: [0, 0, 0.05]}",
        "+    grasp: {parent: j2s6s200_end_effector, xyz: [0, 0, 0.06], rpy: [0, 0, 3.1416]}",
    ]
    with pytest.raises(SetupError, match="'base' is a link or frame already"):
        s.add_frame("base", "j2s6s200_end_effector")
    assert s.remove("frames.grasp").valid and s.snapshot.text == before  # its rotation too
    with pytest.raises(SetupError, match="no moving joint 'j2s6s200_joint_finger_1'"):
        set_passive(s, "j2s6s200_joint_finger_1", passive=True)  # a fixed joint
    said = set_passive(s, "j2s6s200_joint_6", passive=True)
    assert "kept in kinova.srdf" in said
    diff = _diff(before, s.snapshot.text)
    assert len(diff) == 2 and diff[1] == "+  srdf: kinova.srdf"
    s.save()
    assert "j2s6s200_joint_6" in (tmp_path / "kinova.srdf").read_text()
    assert "<passive_joint" in (tmp_path / "kinova.srdf").read_text()


def test_a_shipped_camera_turned_is_one_line_and_validate_says_why_not(tmp_path: Path) -> None:
    erd_robots()
    before = shipped_specs()["pr2"].read_text()
    s = SetupSession.open("pr2", output=tmp_path / "pr2.yaml")
    v = s.set_camera_axis("sensors.kinect", (1.0, 0.0, 0.0))
    assert _diff(before, s.snapshot.text) == ["+    forward_facing_axis: [1, 0, 0]"]
    assert any("is an optical frame by its rotation" in p.message for p in v.errors)
    assert s.undo().valid and s.snapshot.text == before
