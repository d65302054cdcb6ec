"""Drafts of shapes round 6 of the blind corpus showed (issue 30), on small layouts.

Each layout is the shape of a miss on the tune half, built here from boxes (never a copy of a
robot's files): a one-jaw gripper whose fixed jaw is the wrist link's own shape.
"""

from __future__ import annotations

from pathlib import Path

from tests.test_draft_blind import _arm, _draft, _joint, _link


def _box_link(name: str, size: str, at: str) -> str:
    """A link whose collision box of ``size`` is centred at ``at`` in its frame."""
    box = f'<origin xyz="{at}"/><geometry><box size="{size}"/></geometry>'
    return f'<link name="{name}"><visual>{box}</visual><collision>{box}</collision></link>'


def _one_jaw(jaw_range: str, fixed_jaw_length: float) -> list[str]:
    """A 4-joint arm whose last link 'wrist' holds a fixed jaw of ``fixed_jaw_length`` along x
    and carries one moving jaw 'fngr' hinged 12 cm out about y (nothing named as a hand)."""
    lower, upper = jaw_range.split()
    hinge = (
        '<joint name="f1x" type="revolute"><parent link="wrist"/><child link="fngr"/>'
        '<origin xyz="0.12 0 0.015"/><axis xyz="0 1 0"/>'
        f'<limit lower="{lower}" upper="{upper}" effort="1" velocity="1"/></joint>'
    )
    return [
        *[p for p in _arm("wrist") if 'name="wrist"' not in p or "<joint" in p],
        _box_link("wrist", f"{fixed_jaw_length} 0.04 0.03", f"{fixed_jaw_length / 2} 0 0"),
        _box_link("fngr", "0.08 0.03 0.02", "0.04 0 0"),
        hinge,
    ]


def test_a_jaw_swinging_onto_the_wrists_own_shape_is_a_one_jaw_gripper(tmp_path: Path) -> None:
    # Spot's arm: the wrist link's meshes include the fixed jaw, reaching 20 cm out, past the
    # moving jaw's hinge (12 cm); the jaw swings a quarter turn about an axis across it.
    d = _draft(tmp_path, "one_jaw_shape", _one_jaw("-1.57 0", 0.2))
    (arm,) = d.chains
    assert arm.tip == "wrist" and "f1x" not in arm.joints and len(arm.joints) == 4
    (m,) = d.manipulators
    assert m.root == "wrist"
    (frame,) = [f for f in d.frames if f.name == m.tool_frame]
    assert frame.parent == "wrist"  # a new tool frame on the link holding both jaws


def test_a_last_link_hinged_past_the_shape_above_it_stays_the_arms(tmp_path: Path) -> None:
    # The same joint where the link above ends at the hinge (an elbow turning a forearm, a
    # wrist): no fixed jaw out there, so the last link is the arm's and the chain ends on it.
    d = _draft(tmp_path, "last_link", _one_jaw("-1.57 0", 0.12))
    (arm,) = d.chains
    assert arm.tip == "fngr" and "f1x" in arm.joints


def test_a_wrist_turning_all_the_way_round_is_not_a_jaw(tmp_path: Path) -> None:
    # A full turn is a wrist's roll, not a jaw's swing, whatever the shape above it.
    d = _draft(tmp_path, "wrist_roll", _one_jaw("-3.14 3.14", 0.2))
    (arm,) = d.chains
    assert arm.tip == "fngr" and "f1x" in arm.joints


def test_five_four_joint_fingers_on_one_palm_are_a_hand_not_five_arms(tmp_path: Path) -> None:
    # Tesollo DG-5F's shape: a palm carrying five fingers of four joints each, 24 cm long
    # (long enough for an arm), named by numbers only: a hand of five fingers, no arm.
    parts = [_link("mount", size=0.02), _link("palm", size=0.05)]
    parts.append(_joint("mount_palm", "mount", "palm", "fixed"))
    bases = ("0 0.05 0.02", "0.03 0.02 0.08", "0.03 0 0.08", "0.03 -0.02 0.08", "0.03 -0.04 0.08")
    for f, at in enumerate(bases, 1):
        above = "palm"
        for i in range(1, 5):
            parts.append(_link(f"l_{f}_{i}", size=0.01))
            xyz = at if i == 1 else "0 0 0.06"
            parts.append(_joint(f"j_{f}_{i}", above, f"l_{f}_{i}", xyz=xyz))
            above = f"l_{f}_{i}"
    d = _draft(tmp_path, "five_fingers", parts)
    assert not d.chains
    (m,) = d.manipulators
    assert m.root == "palm" and m.thumb is not None and len(m.fingers) == 4
