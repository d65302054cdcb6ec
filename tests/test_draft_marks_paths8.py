"""Paths by which a wrong item ends up unmarked, each closed on a small layout (issue 30, item 3).

Each layout is the shape of one path (numbered, generic names: nothing here rests on a name),
scored with ``tools/draft_score.py``'s counting against the truth an expert would write, so a
test fails exactly when the wrong item would be counted as carrying no ``DECIDE`` mark.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from robotspec.compiler import check_spec
from robotspec.spec.draft import Draft, render_draft
from robotspec.spec.draft.run import draft_from_files
from tests.test_draft_blind import _joint, _link
from tools.draft_score import ASKED, RobotScore, Truth, score_draft

_SENSOR = (
    '<gazebo reference="{0}"><sensor name="{0}_sensor" type="camera"><camera>'
    "<horizontal_fov>1.0</horizontal_fov><image><width>640</width><height>480</height></image>"
    "</camera></sensor></gazebo>"
)


def _draft(tmp_path: Path, parts: list[str], truth: dict[str, Any]) -> tuple[Draft, RobotScore]:
    """The draft of ``parts`` (valid as written) and its score against ``truth``."""
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r">' + "".join(parts) + "</robot>")
    draft, desc = draft_from_files(str(urdf), None, folder=tmp_path, base_folder=tmp_path)
    spec = tmp_path / "r.yaml"
    spec.write_text(render_draft(draft))
    assert check_spec(spec).robot is not None
    score = score_draft(Truth("r", "t/r", {"robot": "t/r", **truth}), draft, desc.world, True)
    return draft, score


def _head(extra: list[str]) -> list[str]:
    """A base, a two-joint head (pan, tilt) and what ``extra`` fixes on it."""
    return [
        _link("link_0", size=0.2),
        _link("link_1"),
        _joint("joint_1", "link_0", "link_1", axis="0 0 1", xyz="0 0 0.5"),
        _link("link_2", size=0.1),
        _joint("joint_2", "link_1", "link_2"),
        *extra,
    ]


def test_a_bare_frame_at_a_head_no_camera_is_drafted_on_is_asked(tmp_path: Path) -> None:
    # The head has no sensor and its camera frame a generic name, not turned as optical frames
    # are: the head is drafted as a plain chain, the camera missed, and nothing named it.
    parts = _head(['<link name="link_3"/>', _joint("joint_3", "link_2", "link_3", "fixed")])
    truth = {"cameras": ["link_3"], "chains": {"c": {"root": "link_0", "tip": "link_2"}}}
    draft, s = _draft(tmp_path, parts, {**truth, "neck": None})
    assert [c.body for c in draft.cameras] == []
    assert s.counts["cameras"] == (0, 1)
    assert s.unmarked == [] and s.rules[ASKED][0] >= 1
    (q,) = [q for q in draft.questions if "link_3" in q.links]
    assert q.text == (
        "nothing is drafted at the end of chain 'head' (link_2), which carries link_3: "
        "a camera? a tool frame?"
    )


def test_a_tool_frame_on_a_chain_no_manipulator_is_drafted_on_is_asked(tmp_path: Path) -> None:
    # The same two-joint run read as a tool on a stand: the tree calls it a plain chain, so no
    # manipulator is drafted, and the tool frame the truth names at its end had nothing near
    # it to ask (a missed tool frame is marked only by a marked manipulator or a question).
    flange = ['<link name="link_3"/>', _joint("joint_3", "link_2", "link_3", "fixed", "0 0 0.1")]
    truth = {"manipulators": {"tool": {"type": "tool", "tool_frame": "link_3"}}}
    draft, s = _draft(tmp_path, _head(flange), truth)
    assert draft.manipulators == []
    assert s.counts["tool frames"] == (0, 1)
    assert s.unmarked == []


def test_a_chain_end_with_nothing_fixed_on_it_asks_nothing(tmp_path: Path) -> None:
    draft, _ = _draft(tmp_path, _head([]), {})
    assert draft.questions == []


def test_a_second_frame_on_a_head_away_from_its_stated_camera_is_asked(tmp_path: Path) -> None:
    # A Gazebo camera states one camera on the head; a second one 15 cm below it is a bare
    # frame with a generic name: without the question, the missed camera carried no mark.
    extra = [
        _link("link_3", size=0.02),
        _joint("joint_3", "link_2", "link_3", "fixed", xyz="0.1 0 0.05"),
        _SENSOR.format("link_3"),
        '<link name="link_4"/>',
        _joint("joint_4", "link_2", "link_4", "fixed", xyz="0.1 0 -0.12"),
    ]
    truth = {
        "cameras": ["link_3", "link_4"],
        "neck": {"root": "link_0", "tip": "link_2"},
    }
    draft, s = _draft(tmp_path, _head(extra), truth)
    assert [(c.body, c.decide) for c in draft.cameras] == [("link_3", [])]
    assert s.counts["cameras"] == (1, 2)
    assert s.unmarked == []
    (q,) = [q for q in draft.questions if "link_4" in q.links]
    assert q.text == (
        "the head (link_2) carries link_4, away from its drafted cameras: another camera? a marker?"
    )


def test_a_frame_of_the_stated_cameras_device_is_not_asked_again(tmp_path: Path) -> None:
    extra = [
        _link("link_3", size=0.02),
        _joint("joint_3", "link_2", "link_3", "fixed", xyz="0.1 0 0.05"),
        _SENSOR.format("link_3"),
        '<link name="link_4"/>',
        _joint("joint_4", "link_2", "link_4", "fixed", xyz="0.1 0 0.02"),
    ]
    draft, _ = _draft(tmp_path, _head(extra), {})
    assert not [q for q in draft.questions if "link_4" in q.links]


def _two_arms(along: str) -> list[str]:
    """A base and two 6-joint arms of numbered names, their shoulders apart along ``along``."""
    parts = [_link("link_0", size=0.2)]
    for k, sign in (("a", 1), ("b", -1)):
        above = "link_0"
        for i in range(1, 7):
            at = f"{0.2 * sign} 0 0.3" if along == "x" else f"0 {0.2 * sign} 0.3"
            parts += [
                _link(f"link_{k}{i}", size=0.03),
                _joint(f"joint_{k}{i}", above, f"link_{k}{i}", xyz=at if i == 1 else "0 0 0.1"),
            ]
            above = f"link_{k}{i}"
    return parts


def test_a_default_facing_across_a_pair_of_arms_is_marked(tmp_path: Path) -> None:
    # No side names: the facing is +x by default. The arms lie apart along x, so the robot
    # faces +y or -y; without the mark, a wrong facing was stated as if the files said it.
    draft, s = _draft(tmp_path, _two_arms("x"), {"forward": [0.0, 1.0, 0.0]})
    assert draft.forward == (1.0, 0.0, 0.0)
    assert draft.forward_decide == "its two arms lie apart along x: it faces +y or -y, not +x?"
    assert "forward: [1, 0, 0]  # DECIDE: its two arms" in render_draft(draft)
    assert "torso/neck/drive: forward: [1.0, 0.0, 0.0]" in s.wrong and s.unmarked == []


def test_a_default_facing_between_a_pair_of_arms_apart_along_y_stays_unwritten(
    tmp_path: Path,
) -> None:
    draft, _ = _draft(tmp_path, _two_arms("y"), {})
    assert draft.forward_decide is None
