"""The corpus counting of items a draft leaves out (``tools/draft_score.py``, issue 30, item 3).

A missed item counts as marked when a question about what the draft leaves out names it (a
chain or torso by a moving joint, a manipulator by a link of its subtree, a camera by its link
or one of its device's); a truth's neck that carries no camera is scored as a plain chain.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from robotspec.spec.draft.run import draft_from_files
from tests.test_draft_blind import _joint
from tests.test_draft_questions import _gripper_arm, _leaving_out
from tools.draft_score import ASKED, NOTHING, RobotScore, Truth, _neck_as_chain, score_draft


def _camera_arm() -> list[str]:
    """The gripper arm with two camera-named frames on its wrist no camera is drafted on."""
    return [
        *_gripper_arm(),
        '<link name="wrist_camera"/>',
        _joint("wrist_camera_joint", "wrist", "wrist_camera", "fixed", "0.05 0 0"),
        '<link name="marker_a"/>',
        _joint("marker_a_joint", "wrist_camera", "marker_a", "fixed", "0 0 0.01"),
    ]


_ARM = {"root": "base", "tip": "wrist", "kind": "arm"}
_GRIPPER = {
    "type": "parallel_gripper",
    "tool_frame": {"parent": "jaw_base"},
    "fingers": ["left_jaw", "right_jaw"],
}


def _score(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    truth: dict[str, Any],
    parts: list[str],
    **leave_out: bool,
) -> RobotScore:
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r">' + "".join(parts) + "</robot>")
    with _leaving_out(monkeypatch, **leave_out):
        draft, desc = draft_from_files(str(urdf), None, folder=tmp_path, base_folder=tmp_path)
    return score_draft(Truth("r", "t/r", {"robot": "t/r", **truth}), draft, desc.world, True)


def test_a_missed_arm_a_question_names_a_joint_of_is_marked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    s = _score(tmp_path, monkeypatch, {"chains": {"arm": _ARM}}, _gripper_arm(), chains=True)
    assert s.counts["chains"] == (0, 1)
    assert s.unmarked == [] and s.rules[ASKED] == [1, 1]
    assert s.questions == 1


def test_a_missed_torso_a_question_names_a_joint_of_is_marked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    truth = {"torso": {"root": "base", "tip": "link1"}}
    s = _score(tmp_path, monkeypatch, truth, _gripper_arm(), chains=True, manipulators=True)
    assert any(w.startswith("torso/neck/drive: torso") for w in s.wrong)
    assert not any(w.startswith("torso/neck/drive: torso") for w in s.unmarked)


def test_a_missed_gripper_a_question_names_a_link_of_is_marked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    truth = {"chains": {"arm": _ARM}, "manipulators": {"gripper": _GRIPPER}}
    s = _score(tmp_path, monkeypatch, truth, _gripper_arm(), manipulators=True)
    assert s.counts["tool frames"] == (0, 1) and s.counts["grippers/hands"] == (0, 1)
    # The arm's own mark does not reach a manipulator the draft lacks; the question does.
    assert s.unmarked == [] and s.rules[ASKED] == [2, 2]


def test_a_missed_camera_a_question_names_its_link_or_its_device_is_marked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # 'wrist_camera' is named by the question; 'marker_a' is fixed on it, 1 cm away.
    truth = {"cameras": ["wrist_camera", "marker_a"]}
    s = _score(tmp_path, monkeypatch, truth, _camera_arm())
    assert s.counts["cameras"] == (0, 2)
    assert s.unmarked == [] and s.rules[ASKED] == [2, 2]


def test_a_missed_item_no_question_names_stays_unmarked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    s = _score(tmp_path, monkeypatch, {"cameras": ["link2"]}, _gripper_arm())
    assert s.questions == 0
    assert s.unmarked == ["cameras: link2 not a camera"] and s.rules[NOTHING] == [1, 1]


def test_a_neck_without_a_camera_is_scored_as_the_chain_a_valid_spec_writes(
    tmp_path: Path,
) -> None:
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r">' + "".join(_camera_arm()) + "</robot>")
    _, desc = draft_from_files(str(urdf), None, folder=tmp_path, base_folder=tmp_path)
    head = {"root": "base", "tip": "wrist"}
    bare = _neck_as_chain({"neck": head, "cameras": []}, desc.world)
    assert bare["neck"] is None
    assert bare["chains"] == {"neck": {"root": "base", "tip": "wrist", "kind": "chain"}}
    # A camera at or below the neck's tip makes it a neck.
    seeing = {"neck": head, "cameras": ["wrist_camera"]}
    assert _neck_as_chain(seeing, desc.world) is seeing


def test_a_missed_chain_inside_a_marked_manipulator_is_marked(tmp_path: Path) -> None:
    # Legs drafted as a hand alone (Mini Pupper 2): the hand at the root holds the legs' joints,
    # and the question on the hand is the one that finds them.
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r">' + "".join(_gripper_arm()) + "</robot>")
    draft, desc = draft_from_files(str(urdf), None, folder=tmp_path, base_folder=tmp_path)
    draft.chains, draft.questions = [], []
    (m,) = draft.manipulators
    m.root = "base"
    m.decide = ["a hand alone (no arm): rooted at the robot's root"]
    truth = Truth("r", "t/r", {"robot": "t/r", "chains": {"arm": _ARM}})
    s = score_draft(truth, draft, desc.world, True)
    assert s.counts["chains"] == (0, 1) and s.unmarked == []
    m.decide = []  # an unmarked manipulator asks nothing
    s = score_draft(truth, draft, desc.world, True)
    assert "chains: arm (base -> wrist) not drafted" in s.unmarked
