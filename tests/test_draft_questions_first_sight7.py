"""Questions about what a draft leaves out, for shapes first-sight robots showed (issue 30).

Small layouts built here: a camera frame with a generic name and no Gazebo sensor, turned as
optical frames are (a rear camera looking backwards), is asked about by name; a frame that is
not turned so is not. Whichever part finds such a frame (the camera detector drafts some,
marked), none is left out unasked.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from robotspec.spec.draft.unassigned import SENSORS
from tests.test_draft_blind import _draft, _joint, _link

#: REP 103's optical rotation for a camera looking backwards (-x), and one looking forwards.
_BACKWARDS = "-1.5707963 0 1.5707963"
_TILTED_DOWN = "-2.3562 0 -1.5707963"


def _base(frames: list[tuple[str, str, str]]) -> list[str]:
    """A box on four fixed feet (nothing moves) with bare frames (name, xyz, rpy) on it."""
    parts = [_link("body", size=0.3)]
    for name, xyz, rpy in frames:
        parts += [
            f'<link name="{name}"/>',
            _joint(f"{name}_joint", "body", name, kind="fixed", xyz=xyz, rpy=rpy),
        ]
    return parts


def test_a_bare_frame_turned_as_an_optical_frame_is_asked_about(tmp_path: Path) -> None:
    d = _draft(
        tmp_path,
        "box",
        _base([("rear_a", "-0.4 0 0.05", _BACKWARDS), ("front_b", "0.4 0 0.06", _TILTED_DOWN)]),
    )
    # Drafted as a camera (marked), or asked about: never left out unasked.
    sensors = [q for q in d.questions if q.section == SENSORS]
    asked = {name for q in sensors for name in q.links}
    drafted = {c.body for c in d.cameras if c.decide}
    assert asked | drafted >= {"rear_a", "front_b"}
    assert all("turned as a camera's optical frame" in q.text for q in sensors)


def test_frames_not_turned_as_optical_frames_are_not_asked_about(tmp_path: Path) -> None:
    d = _draft(
        tmp_path,
        "box",
        _base([("marker", "0.4 0 0.05", "0 0 0"), ("imu", "0 0 0.1", "3.1415926 0 0")]),
    )
    assert not [q for q in d.questions if q.section == SENSORS]


def test_the_question_names_the_frame_when_no_camera_is_drafted_there(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The camera detector set aside (it may draft such frames itself): the question alone.
    monkeypatch.setattr("robotspec.spec.draft.parts.find_cameras", lambda tree: [])
    d = _draft(tmp_path, "box", _base([("rear_a", "-0.4 0 0.05", _BACKWARDS)]))
    (q,) = d.questions
    assert q.section == SENSORS and q.links == frozenset({"rear_a"})
    assert q.text == (
        "rear_a (a bare frame turned as a camera's optical frame (z ahead, y down)) is no "
        "drafted camera: a camera? which frame?"
    )


def test_a_neck_of_more_joints_than_a_head_turns_on_is_asked_about(tmp_path: Path) -> None:
    # An arm carrying a camera, taken for a neck, covers its joints: nothing else would ask.
    from types import SimpleNamespace

    from robotspec.description.load import load_description
    from robotspec.spec.draft.model import Draft, DraftChain
    from robotspec.spec.draft.unassigned import CHAINS, _long_part_questions

    parts = [_link("base", size=0.1)]
    for i in range(1, 6):
        above = "base" if i == 1 else f"l{i - 1}"
        parts += [_link(f"l{i}", size=0.03), _joint(f"q{i}", above, f"l{i}", xyz="0 0 0.1")]
    urdf = tmp_path / "arm.urdf"
    urdf.write_text('<robot name="arm">' + "".join(parts) + "</robot>")
    world = load_description(str(urdf)).world
    draft = Draft("arm", "arm.urdf", None, "base", None, [], [], [])
    for n in (3, 5):
        joints = frozenset(f"q{i}" for i in range(1, n + 1))
        draft.neck = DraftChain("neck", "base", f"l{n}", "the URDF tree", "neck", joints=joints)
        asked = _long_part_questions(SimpleNamespace(draft=draft, world=world))  # type: ignore[arg-type]
        if n == 3:
            assert asked == []  # a head's pan, tilt and roll
        else:
            (q,) = asked
            assert q.section == CHAINS and q.joints == joints
            assert q.text == (
                "the neck moves 5 joints (q1 .. q5 (5 joints)), more than a head turns on: "
                "an arm carrying a camera?"
            )


def test_a_round_hip_carrying_a_knee_is_asked_about_not_taken_for_a_wheel(
    tmp_path: Path,
) -> None:
    # Four legs whose hips are continuous joints turning a round motor about a level axis
    # (wheel-shaped), each carrying a limited knee: whatever the draft makes of them, no hip is
    # left as a wheel nobody asks about.
    from tests.test_draft_blind import _WHEEL

    parts = [_link("body", size=0.3)]
    for leg, (x, y) in {
        "fl": (0.3, 0.2),
        "fr": (0.3, -0.2),
        "hl": (-0.3, 0.2),
        "hr": (-0.3, -0.2),
    }.items():
        parts += [
            _link(f"{leg}_hip", _WHEEL),
            _joint(f"{leg}_hip_j", "body", f"{leg}_hip", "continuous", f"{x} {y} 0", "0 1 0"),
            _link(f"{leg}_shin", size=0.03),
            _joint(f"{leg}_knee_j", f"{leg}_hip", f"{leg}_shin", xyz="0 0 -0.2"),
        ]
    d = _draft(tmp_path, "quad", parts)
    covered = {j for c in d.chains for j in c.joints} | {
        j for m in d.manipulators for j in m.joints
    }
    asked = {j for q in d.questions for j in q.joints}
    hips = {f"{leg}_hip_j" for leg in ("fl", "fr", "hl", "hr")}
    assert hips <= covered | asked
