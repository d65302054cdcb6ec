"""The setup assistant's session, without a browser: questions, edits, validation, saving.

On example-robot-data's robots: the xArm7 (a URDF alone, every part guessed) and the PR2 (URDF
and SRDF, cameras whose angles are open). What is saved must be what ``robotspec validate``
accepts, with the draft's comments kept and the answered DECIDE marks gone.
"""

from __future__ import annotations

import threading
from pathlib import Path

import pytest

from robotspec.cli.app import main
from robotspec.compiler import check_spec
from robotspec.errors import DescriptionError, RobotSpecError
from robotspec.setup import SetupSession
from robotspec.setup.questions import KEEP
from robotspec.setup.session import SetupError
from robotspec.setup.validation import part_of
from tests.conftest import erd_robots


def _xarm(tmp_path: Path) -> SetupSession:
    urdf = erd_robots() / "xarm_description" / "urdf" / "xarm7.urdf"
    return SetupSession.open(str(urdf), output=tmp_path / "xarm.yaml")


def _pr2(tmp_path: Path) -> SetupSession:
    pr2 = erd_robots() / "pr2_description"
    return SetupSession.open(
        str(pr2 / "urdf" / "pr2.urdf"),
        srdf=str(pr2 / "srdf" / "pr2.srdf"),
        output=tmp_path / "out" / "pr2.yaml",
    )


def _validate_exit(path: Path) -> int:
    with pytest.raises(SystemExit) as exc:
        main(["validate", str(path)])
    return int(exc.value.code or 0)


def test_part_of_maps_spec_locations_to_parts() -> None:
    assert part_of(("chains", "left_arm", "tip")) == "chains.left_arm"
    assert part_of(("torso", "root")) == "torso"
    assert part_of(("description", "frames", "tcp", "parent")) == "frames.tcp"
    assert part_of(("sensors", "cam")) == "sensors.cam"
    assert part_of(()) == "robot"


def test_xarm_questions_answered_and_saved_validate(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    s = _xarm(tmp_path)
    assert s.validation.valid  # a draft validates as written
    ids = [q.id for q in s.snapshot.questions]
    assert ids == ["drive", "chains.arm", "manipulators.tool"]
    q = s.snapshot.questions[2]
    assert q.guess.endswith("tool frame link_eef") and "tool faces +z" in q.alternatives
    assert "which way does the tool face" in q.reason
    s.answer("drive")
    s.answer("chains.arm", KEEP)
    v = s.answer("manipulators.tool", "tool faces +z")
    assert v.valid and not s.snapshot.questions
    v = s.set_state("chains.arm", "park", dict.fromkeys(s.part_joints("chains.arm"), 0.0))
    assert v.valid and len(s.part_joints("chains.arm")) == 7
    path = s.save()
    text = path.read_text()
    assert "DECIDE: " not in text.split("delete the mark.")[1]
    assert "# from the URDF tree" in text  # the draft's comments are kept
    assert "front_facing_orientation: [0, 0.7071068, 0, 0.7071068]" in text
    assert "park: {joint1: 0" in text
    assert _validate_exit(path) == 0
    assert "1 of 1 spec valid; 0 errors, 0 warnings" in capsys.readouterr().out
    assert s.snapshot.saved


def test_a_change_that_breaks_the_spec_shows_the_validators_message(tmp_path: Path) -> None:
    s = _xarm(tmp_path)
    v = s.set_chain("chains.arm", root="link_eef", tip="link3")  # root and tip swapped
    assert not v.valid
    (err,) = v.at("chains.arm")
    assert "root 'link_eef' is not an ancestor of tip 'link3'" in err.message
    assert err.line is not None
    with pytest.raises(SetupError, match="not saved: the spec has 1 error"):
        s.save()
    assert not (tmp_path / "xarm.yaml").exists()
    assert s.undo().valid  # back to the draft
    assert s.set_chain("chains.arm", tip="link7").valid


def test_picks_of_unknown_names_are_refused_with_the_nearest_links(tmp_path: Path) -> None:
    s = _xarm(tmp_path)
    before = s.snapshot.version
    with pytest.raises(SetupError) as exc:
        s.set_manipulator("manipulators.tool", tool_frame="link_ef")
    assert "link_eef" in exc.value.suggestions
    with pytest.raises(SetupError, match="no chain 'leg'"):
        s.set_chain("chains.leg", tip="link3")
    with pytest.raises(SetupError, match="not a choice"):
        s.answer("drive", "drive: hover")
    with pytest.raises(SetupError, match="no joint"):
        s.set_state("chains.arm", "x", {"nope": 1.0})
    assert s.snapshot.version == before  # nothing changed


def test_pr2_cameras_presets_states_and_round_trip(tmp_path: Path) -> None:
    s = _pr2(tmp_path)
    qs = s.snapshot.questions
    assert sum(q.id.endswith(".field_of_view") for q in qs) == 5
    for q in qs:
        s.answer(q.id, "preset: kinect_v1" if q.id.endswith("field_of_view") else KEEP)
    s.set_state("torso", "low", {"torso_lift_joint": 0.0})
    s.set_state("torso", "high", {"torso_lift_joint": 0.3})
    joints = s.part_joints("manipulators.left_eef")
    assert joints == ("l_gripper_l_finger_joint",)
    lo, hi = s.joint_range(joints[0])
    assert s.set_state("manipulators.left_eef", "open", {joints[0]: hi}).valid
    v = s.set_state("manipulators.left_eef", "close", {joints[0]: lo})
    assert v.valid and not s.snapshot.questions
    path = s.save()
    text = path.read_text()
    assert text.count("preset: kinect_v1") == 5 and "# Note: SRDF group" in text
    check_spec(path)  # validate accepts the file as written
    # The saved spec opened again is the same spec, and saves to the same text.
    again = SetupSession.open(str(path), output=tmp_path / "again" / "pr2.yaml")
    assert again.validation.valid and not again.snapshot.questions
    assert again.save().read_text() == text


def test_a_spec_keeps_its_marks_and_what_setup_does_not_edit(tmp_path: Path) -> None:
    s = _xarm(tmp_path)
    s.answer("drive")
    spec = tmp_path / "xarm.yaml"
    text = s.snapshot.text + "collision: {buffer_distance: 0.02}\n"
    spec.write_text(text)
    again = SetupSession.open(str(spec), output=tmp_path / "b" / "xarm.yaml")
    assert [q.id for q in again.snapshot.questions] == ["chains.arm", "manipulators.tool"]
    assert again.validation.valid
    assert again.snapshot.text == text  # kept as written: setup edits the text, not a render


def test_files_it_cannot_read_get_the_clis_located_errors(tmp_path: Path) -> None:
    with pytest.raises(DescriptionError, match="file not found"):
        SetupSession.open(str(tmp_path / "nope.urdf"), output=tmp_path / "x.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("robotspec: 1\nname: [\n")
    with pytest.raises(RobotSpecError) as exc:
        SetupSession.open(str(bad), output=tmp_path / "x.yaml")
    assert exc.value.file is not None and exc.value.file.endswith("bad.yaml")


def test_the_shipped_pr2_opens_and_saves_with_its_camera_heights(tmp_path: Path) -> None:
    erd_robots()
    session = SetupSession.open("pr2", output=tmp_path / "pr2.yaml")
    saved = session.save()
    text = saved.read_text(encoding="utf-8")
    assert "minimal_height: 1.166" in text and "maximal_height: 1.583" in text
    assert "default: true" in text
    camera = check_spec(saved).robot.cameras[0]
    assert camera.name == "kinect"


def test_two_threads_editing_see_one_state(tmp_path: Path) -> None:
    s = _xarm(tmp_path)
    seen: list[int] = []
    s.subscribe(lambda snap: seen.append(snap.version))

    def work(k: int) -> None:
        for i in range(3):
            s.set_state("robot", f"s{k}_{i}", {"joint1": 0.1 * i})

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    # In the order made (a listener may skip a state a newer one replaced), ending on the last.
    assert seen == sorted(set(seen)) and seen[-1] == 6 and s.snapshot.version == 6
    assert len(s.part_states("robot")) == 6 and s.validation.valid


def test_the_setup_command_reports_bad_input_like_the_cli(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    pytest.importorskip("viser")
    with pytest.raises(SystemExit) as exc:
        main(["setup", str(tmp_path / "nope.urdf"), "-o", str(tmp_path / "x.yaml")])
    assert exc.value.code == 1
    err = capsys.readouterr().err
    assert "nope.urdf: error: file not found" in err and "Traceback" not in err
    urdf = erd_robots() / "xarm_description" / "urdf" / "xarm7.urdf"
    existing = tmp_path / "xarm.yaml"
    existing.write_text("name: mine\n")
    with pytest.raises(SystemExit) as exc:
        main(["setup", str(urdf), "-o", str(existing)])
    assert exc.value.code == 1
    assert "robotspec setup" in capsys.readouterr().err and existing.read_text() == "name: mine\n"
    with pytest.raises(SystemExit) as exc:
        main(["setup", str(urdf), "--port", "70000"])
    assert exc.value.code == 2


def test_the_robots_facing_is_set_and_read_back(tmp_path: Path) -> None:
    s = _xarm(tmp_path)
    with pytest.raises(SetupError, match="unit vector"):
        s.set_forward((1.0, 1.0, 0.0))
    v = s.set_forward((0.0, -1.0, 0.0))
    assert v.valid and "forward: [0, -1, 0]\n" in s.snapshot.text  # decided: no DECIDE mark
    spec = s.save()
    again = SetupSession.open(str(spec), output=tmp_path / "b" / "xarm.yaml")
    assert again.draft().forward == (0.0, -1.0, 0.0)
    assert "forward" not in [q.id for q in again.snapshot.questions]
    # A drafted facing is a question; keeping it removes its mark.
    marked = spec.read_text().replace("forward: [0, -1, 0]", "forward: [0, -1, 0]  # DECIDE: why")
    spec.write_text(marked)
    third = SetupSession.open(str(spec), output=tmp_path / "c" / "xarm.yaml")
    (q,) = [q for q in third.snapshot.questions if q.id == "forward"]
    assert q.reason == "why" and "faces +x" in q.alternatives
    assert third.answer("forward", "faces +y").valid
    assert "forward: [0, 1, 0]\n" in third.snapshot.text


def test_tiago_a_camera_model_chosen_as_a_preset(tmp_path: Path) -> None:
    urdf = erd_robots() / "tiago_description" / "robots" / "tiago.urdf"
    s = SetupSession.open(str(urdf), output=tmp_path / "tiago.yaml")
    cams = [c.name for c in s.draft().cameras]
    assert cams
    for q in s.snapshot.questions:
        s.answer(q.id, KEEP)
    for cam in cams:
        assert s.set_camera(f"sensors.{cam}", preset="kinect_v1").valid
    assert not s.snapshot.questions and s.validation.valid
    text = s.save().read_text()
    assert "preset: kinect_v1" in text and "DECIDE: " not in text.split("delete the mark.")[1]
    check_spec(tmp_path / "tiago.yaml")


def test_an_output_that_cannot_be_written_is_a_located_error(tmp_path: Path) -> None:
    (tmp_path / "a_file").write_text("")
    urdf = erd_robots() / "xarm_description" / "urdf" / "xarm7.urdf"
    # Opening writes nothing (validation reads the text from memory); saving says why not.
    s = SetupSession.open(str(urdf), output=tmp_path / "a_file" / "xarm.yaml")
    with pytest.raises(RobotSpecError) as exc:
        s.save()
    assert exc.value.file is not None and "a_file" in exc.value.file
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file"]


def test_a_gripper_made_a_hand_of_named_fingers_and_generic_again(tmp_path: Path) -> None:
    s = _pr2(tmp_path)
    with pytest.raises(SetupError, match="needs a name"):
        s.set_manipulator("manipulators.left_eef", named=(" ", "l_gripper_r_finger_tip_link"))
    v = s.set_manipulator("manipulators.left_eef", named=("index", "l_gripper_r_finger_tip_link"))
    assert v.valid
    text = s.snapshot.text
    assert "    type: hand\n" in text
    assert "index: {root: l_gripper_r_finger_link, tip: l_gripper_r_finger_tip_link}" in text
    assert "thumb: {root: l_gripper_l_finger_link, tip: l_gripper_l_finger_tip_link}" in text
    assert s.set_manipulator("manipulators.left_eef", generic=True).valid
    assert "fingers:" not in s.snapshot.text


def test_the_shipped_hsrb_and_its_bare_urdf_open_and_save_valid(tmp_path: Path) -> None:
    from tests.conftest import shared_path

    folder = shared_path("robots", "hsrb")
    for ref, name in (("hsrb", "hsrb.yaml"), (str(folder / "hsrb4s.urdf"), "draft.yaml")):
        session = SetupSession.open(ref, output=tmp_path / name, package_paths=[folder])
        assert session.validation.valid, session.validation.errors
        saved = session.save()
        assert check_spec(saved, package_paths=[folder]).robot.name
