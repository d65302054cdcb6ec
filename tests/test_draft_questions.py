"""A draft asks about what it leaves out (``robotspec/spec/draft/unassigned.py``, issue 30).

Small layouts of each kind of question: joints no drafted part covers (a run that may be an arm,
branches that may be a hand, a lone passive joint), a frame that looks like a camera and is none
of the drafted cameras, and the robots that must get no question at all. A part the drafter
leaves out is simulated by dropping it before the questions are asked (``_leaving_out``): the
questions look only at what the draft holds, whichever detector missed it.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from robotspec.spec.draft import build
from robotspec.spec.draft.model import Draft
from robotspec.spec.draft.render import render_draft
from robotspec.spec.draft.unassigned import CHAINS, MANIPULATORS, SENSORS, asked
from tests.test_draft_blind import _arm, _draft, _jaws, _joint, _link


@contextmanager
def _leaving_out(
    monkeypatch: pytest.MonkeyPatch,
    *,
    chains: bool = False,
    manipulators: bool = False,
    torso: bool = False,
) -> Iterator[None]:
    """Draft as if the drafter had missed the chains, the manipulators or the torso."""
    real = build.find_questions

    def dropped(d: build.Drafter) -> list[object]:
        if chains:
            d.draft.chains = []
        if torso:
            d.draft.torso = None
        if manipulators:
            d.draft.manipulators = []
            for c in d.draft.chains:
                c.manipulator = None
        return list(real(d))

    with monkeypatch.context() as m:
        m.setattr(build, "find_questions", dropped)
        yield


def _gripper_arm() -> list[str]:
    """A 4-joint arm with a two-jaw gripper whose jaws a mimic tag couples."""
    parts = [
        *_arm("wrist"),
        _link("jaw_base", size=0.04),
        _joint("jaw_base_joint", "wrist", "jaw_base", "fixed"),
        *_jaws("jaw_base", 0.03),
    ]
    return [
        p.replace("</joint>", '<mimic joint="left_jaw_q"/></joint>')
        if p.startswith('<joint name="right_jaw_q"')
        else p
        for p in parts
    ]


def _hand_arm() -> list[str]:
    """A 4-joint arm with a palm carrying three 2-joint fingers."""
    parts = [
        *_arm("wrist"),
        _link("palm", size=0.05),
        _joint("palm_joint", "wrist", "palm", "fixed"),
    ]
    for name, y in (("index", 0.03), ("middle", 0.0), ("ring", -0.03)):
        parts += [
            _link(f"{name}_1"),
            _joint(f"{name}_q1", "palm", f"{name}_1", xyz=f"0 {y} 0.05"),
            _link(f"{name}_2"),
            _joint(f"{name}_q2", f"{name}_1", f"{name}_2", xyz="0 0 0.03"),
        ]
    return parts


def _spec_text(tmp_path: Path, name: str) -> str:
    return (tmp_path / f"{name}.yaml").read_text(encoding="utf-8")


def test_a_fully_drafted_arm_and_gripper_get_no_question(tmp_path: Path) -> None:
    d = _draft(tmp_path, "covered", _gripper_arm())
    assert d.chains and d.manipulators
    assert d.questions == []
    assert "belong to no part" not in _spec_text(tmp_path, "covered")


def test_an_arm_left_out_is_asked_once_in_the_chains_section(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    with _leaving_out(monkeypatch, chains=True, manipulators=True):
        d = _draft(tmp_path, "no_arm", _gripper_arm())
    (q,) = d.questions  # the arm and its gripper: one subtree, one question
    assert q.section == CHAINS
    assert q.joints == {"j1", "j2", "j3", "j4", "left_jaw_q"}  # the mimic is not asked
    assert "an arm? a leg? a head?" in q.text
    assert "(base -> " in q.text
    text = _spec_text(tmp_path, "no_arm")
    assert f"  # DECIDE: {q.text}" in text
    # Written after the chains line, before what follows it.
    assert text.index("chains: {}") < text.index(q.text)


def test_a_hand_left_out_is_asked_in_the_manipulators_section(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    with _leaving_out(monkeypatch, manipulators=True):
        d = _draft(tmp_path, "no_hand", _hand_arm())
    assert d.chains  # the arm is drafted; its fingers are not
    (q,) = d.questions
    assert q.section == MANIPULATORS and "a hand (3 branches)?" in q.text
    assert {"index_2", "middle_2", "ring_2"} <= q.links
    text = _spec_text(tmp_path, "no_hand")
    assert "# manipulators: none drafted" in text and q.text in text


def test_a_passive_joint_beside_the_arm_is_asked(tmp_path: Path) -> None:
    parts = [
        *_gripper_arm(),
        _link("bellows", size=0.03),
        _joint("bellows_joint", "base", "bellows", "prismatic", "0.2 0 0.1", "0 0 1"),
    ]
    d = _draft(tmp_path, "bellows", parts)
    (q,) = d.questions
    assert q.joints == {"bellows_joint"} and q.links == {"bellows"}
    assert "a tool? a sensor's mount? a passive joint?" in q.text


def test_a_lift_under_the_arm_left_out_is_asked_as_a_torso(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    parts = [p.replace('parent link="base"', 'parent link="column"') for p in _gripper_arm()] + [
        _link("column", size=0.05),
        _joint("lift_joint", "base", "column", "prismatic", "0 0 0.1", "0 0 1"),
    ]
    with _leaving_out(monkeypatch, torso=True):
        d = _draft(tmp_path, "lift", parts)
    (q,) = d.questions
    assert q.joints == {"lift_joint"} and q.section == CHAINS
    assert "a torso (it carries " in q.text


def test_wheels_and_casters_are_the_drive_not_questions(tmp_path: Path) -> None:
    wheel = '<collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision>'
    wheel_x = wheel.replace("<geometry>", '<origin rpy="1.5708 0 0"/><geometry>')
    parts = [
        *_gripper_arm(),
        _link("left_wheel", wheel_x),
        _joint("left_wheel_joint", "base", "left_wheel", "continuous", "0 0.2 0", "0 1 0"),
        _link("right_wheel", wheel_x),
        _joint("right_wheel_joint", "base", "right_wheel", "continuous", "0 -0.2 0", "0 1 0"),
        _link("caster_swivel"),
        _joint("caster_swivel_joint", "base", "caster_swivel", "continuous", "-0.2 0 0", "0 0 1"),
        _link("caster_wheel", wheel_x),
        _joint(
            "caster_wheel_joint", "caster_swivel", "caster_wheel", "continuous", "0 0 -0.05",
            "0 1 0",
        ),
    ]  # fmt: skip
    d = _draft(tmp_path, "wheeled", parts)
    assert d.questions == []


def test_a_camera_frame_no_camera_was_drafted_on_is_asked_once_per_device(
    tmp_path: Path,
) -> None:
    # Camera-named frames that carry other frames: not leaves, not optical, so the camera
    # detector passes them by; the two, 2 cm apart on the wrist, are one device (one question).
    parts = [
        *_gripper_arm(),
        '<link name="wrist_camera"/>',
        _joint("wrist_camera_joint", "wrist", "wrist_camera", "fixed", "0.05 0 0"),
        '<link name="wrist_camera_depth"/>',
        _joint("depth_joint", "wrist", "wrist_camera_depth", "fixed", "0.07 0 0"),
        '<link name="marker_a"/>',
        _joint("marker_a_joint", "wrist_camera", "marker_a", "fixed", "0 0 0.01"),
        '<link name="marker_b"/>',
        _joint("marker_b_joint", "wrist_camera_depth", "marker_b", "fixed", "0 0 0.01"),
    ]
    d = _draft(tmp_path, "cam", parts)
    assert [c.body for c in d.cameras] == []
    (q,) = d.questions
    assert q.section == SENSORS
    assert q.links == {"wrist_camera", "wrist_camera_depth"} and q.joints == frozenset()
    text = _spec_text(tmp_path, "cam")
    assert "# sensors: none drafted" in text and q.text in text


def test_a_drafted_camera_and_its_channels_are_not_asked(tmp_path: Path) -> None:
    # A camera link and its optical frame: one camera drafted, its other frame is its device's.
    parts = [
        *_gripper_arm(),
        '<link name="head_camera_link"/>',
        _joint("head_camera_joint", "base", "head_camera_link", "fixed", "0.1 0 0.3"),
        '<link name="head_camera_optical_frame"/>',
        _joint(
            "head_camera_optical_joint", "head_camera_link", "head_camera_optical_frame",
            "fixed", "0 0 0", rpy="-1.5708 0 -1.5708",
        ),
    ]  # fmt: skip
    d = _draft(tmp_path, "drafted_cam", parts)
    assert len(d.cameras) == 1
    assert d.questions == []


def test_asked_collects_what_the_questions_name(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    with _leaving_out(monkeypatch, manipulators=True):
        d = _draft(tmp_path, "asked", _hand_arm())
    joints, links = asked(d)
    assert "index_q1" in joints and "ring_2" in links
    assert asked(Draft("x", "x.urdf", None, "base", None, [], [], [])) == (
        frozenset(),
        frozenset(),
    )
    # The subject is the scorer's, never the spec's: only the comment is written.
    assert "index_q1" in render_draft(d)
