"""Hands of more than two fingers (``type: hand``): spec, checks, semantic model, export.

The Allegro right hand of example-robot-data: a thumb (joints 12-15) and three fingers (index,
middle, ring: joints 0-3, 4-7, 8-11), shipped as a part and composed into ``b1_ur5_allegro``.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from pydantic import ValidationError

from robotspec.compiler import check_spec, compile_robot
from robotspec.errors import RobotSpecError
from robotspec.semantic import Finger, Hand
from robotspec.shipped import shipped_part_files
from robotspec.spec.models import HandSpec
from tests.conftest import erd_robots

FINGERS = {
    "index": ("link_0.0", "link_3.0_tip"),
    "middle": ("link_4.0", "link_7.0_tip"),
    "ring": ("link_8.0", "link_11.0_tip"),
}


def _hand_spec(fingers: str, thumb: str = "{root: link_12.0, tip: link_15.0_tip}") -> str:
    urdf = erd_robots() / "allegro_hand_description/urdf/allegro_right_hand.urdf"
    return f"""robotspec: 1
name: Hand
description: {{urdf: {urdf}}}
root: palm_link
drive: {{type: fixed}}
manipulators:
  hand:
    type: hand
    root: palm_link
    tool_frame: link_3.0_tip
    thumb: {thumb}
    fingers: {fingers}
"""


def _problems(tmp_path: Path, text: str) -> list[str]:
    path = tmp_path / "hand.yaml"
    path.write_text(text, encoding="utf-8")
    try:
        result = check_spec(path)
    except RobotSpecError as exc:
        return [d.render() for d in exc.details]
    rendered = [d.render() for w in result.warnings for d in w.details]
    return [r for r in rendered if "is on no chain" not in r]  # a hand alone is on no arm


def test_hand_spec_needs_a_thumb_and_a_finger() -> None:
    ok = {"type": "hand", "root": "a", "tool_frame": "b", "thumb": {"root": "c", "tip": "d"}}
    HandSpec.model_validate({**ok, "fingers": {"index": {"root": "e", "tip": "f"}}})
    with pytest.raises(ValidationError):
        HandSpec.model_validate({**ok, "fingers": {}})
    with pytest.raises(ValidationError):
        HandSpec.model_validate({k: v for k, v in ok.items() if k != "thumb"} | {"fingers": {}})
    with pytest.raises(ValidationError, match="'thumb' is the hand's thumb"):
        HandSpec.model_validate({**ok, "fingers": {"thumb": {"root": "e", "tip": "f"}}})
    with pytest.raises(ValidationError):  # unknown keys are refused
        HandSpec.model_validate(
            {**ok, "fingers": {"index": {"root": "e", "tip": "f"}}, "finger": {}}
        )


def test_shipped_allegro_is_a_hand() -> None:
    erd_robots()
    robot = compile_robot(shipped_part_files()["allegro_right_hand"])
    (hand,) = robot.manipulators
    assert isinstance(hand, Hand)
    assert (hand.thumb.root.name, hand.thumb.tip.name) == ("link_12.0", "link_15.0_tip")
    assert {k: (f.root.name, f.tip.name) for k, f in hand.fingers.items()} == FINGERS
    assert [f.name for f in hand.all_fingers] == [
        "hand_thumb",
        "hand_index",
        "hand_middle",
        "hand_ring",
    ]
    for f in hand.all_fingers:
        assert isinstance(f, Finger)
        assert robot.world.is_ancestor(hand.root, f.root)
        assert len(f.degrees_of_freedom) == 3  # the joint above the root moves the whole finger


def test_composed_allegro_keeps_its_fingers() -> None:
    erd_robots()
    robot = compile_robot("b1_ur5_allegro")
    (hand,) = robot.manipulators
    assert isinstance(hand, Hand)
    assert hand.thumb.root.name == "allegro_link_12.0"
    assert hand.fingers["ring"].tip.name == "allegro_link_11.0_tip"


def test_hand_checks(tmp_path: Path) -> None:
    good = (
        "{index: {root: link_0.0, tip: link_3.0_tip}, middle: {root: link_4.0, tip: link_7.0_tip}}"
    )
    assert _problems(tmp_path, _hand_spec(good)) == []
    bad = _problems(tmp_path, _hand_spec("{index: {root: link_0.0, tip: link_3.0_tpi}}"))
    assert len(bad) == 1 and "did you mean 'link_3.0_tip'" in bad[0]
    shared = _problems(tmp_path, _hand_spec("{index: {root: link_13.0, tip: link_15.0}}"))
    assert len(shared) == 1
    assert (
        "manipulators.hand.fingers.index: finger 'index' of 'hand' shares links with the thumb"
        in shared[0]
    )
    twins = _problems(
        tmp_path,
        _hand_spec("{a: {root: link_0.0, tip: link_2.0}, b: {root: link_1.0, tip: link_3.0}}"),
    )
    assert len(twins) == 1 and "shares links with the finger 'a' (link_1.0, link_2.0)" in twins[0]
    above = _problems(
        tmp_path,
        _hand_spec("{index: {root: link_0.0, tip: link_3.0}}", "{root: palm_link, tip: link_15.0}"),
    )
    assert len(above) == 1
    assert "thumb root 'palm_link' is not below the hand root 'palm_link' (a finger" in above[0]
    reversed_ = _problems(tmp_path, _hand_spec("{index: {root: link_3.0, tip: link_0.0}}"))
    assert len(reversed_) == 1 and "swap root and tip" in reversed_[0]
    fixed = _problems(tmp_path, _hand_spec("{index: {root: link_3.0, tip: link_3.0_tip}}"))
    assert len(fixed) == 1 and ": warning: " in fixed[0] and "cannot move" in fixed[0]


def test_hand_exports_to_srdf() -> None:
    from robotspec.export.srdf import srdf_from_robot

    erd_robots()
    robot = compile_robot(shipped_part_files()["allegro_right_hand"])
    srdf = srdf_from_robot(robot)
    assert [e.group for e in srdf.end_effectors] == ["hand"]
    assert all("hand_" not in g.name for g in srdf.groups)  # fingers are links of the hand


def test_a_drafted_hand_reads_back_into_the_setup_draft(tmp_path: Path) -> None:
    from robotspec.cli.app import app
    from robotspec.cli.output import run_app
    from robotspec.setup.from_spec import draft_of_spec

    urdf = erd_robots() / "allegro_hand_description/urdf/allegro_right_hand.urdf"
    out = tmp_path / "allegro.yaml"
    assert run_app(app, ["init", str(urdf), "-o", str(out)]) == 0
    assert "type: hand" in out.read_text(encoding="utf-8")
    draft = draft_of_spec(str(out)).draft
    (hand,) = draft.manipulators
    assert hand.is_hand and hand.thumb is not None and hand.thumb.root == "link_12.0"
    assert {f.root for f in hand.fingers.values()} == {"link_0.0", "link_4.0", "link_8.0"}


def test_the_setup_asks_about_a_drafted_hand_as_a_hand(tmp_path: Path) -> None:
    from robotspec.cli.app import app
    from robotspec.cli.output import run_app
    from robotspec.setup.from_spec import draft_of_spec
    from robotspec.setup.questions import questions_of

    urdf = erd_robots() / "allegro_hand_description/urdf/allegro_right_hand.urdf"
    out = tmp_path / "allegro.yaml"
    assert run_app(app, ["init", str(urdf), "-o", str(out)]) == 0
    draft = draft_of_spec(str(out)).draft
    (q,) = [q for q in questions_of(draft) if q.part == "manipulators.hand"]
    assert q.guess.startswith("a hand of 4 fingers") and "make it generic" in q.choices


def test_inspect_shows_a_hands_fingers(capsys: pytest.CaptureFixture[str]) -> None:
    import json

    from robotspec.cli.app import app
    from robotspec.cli.output import run_app

    erd_robots()
    assert run_app(app, ["inspect", "manipulators", "b1_ur5_allegro", "--json"]) == 0
    (item,) = json.loads(capsys.readouterr().out)
    assert item["type"] == "hand" and item["thumb"] == "allegro_link_15.0_tip"
    assert item["finger"] == "allegro_link_3.0_tip, allegro_link_7.0_tip, allegro_link_11.0_tip"
    assert run_app(app, ["inspect", "chains", "b1_ur5_allegro", "--json"]) == 0
    kinds = {c["name"]: c["kind"] for c in json.loads(capsys.readouterr().out)}
    assert [n for n, k in kinds.items() if k == "finger"] == [
        f"allegro_hand_{f}" for f in ("thumb", "index", "middle", "ring")
    ]
