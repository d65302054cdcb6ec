"""Rules that hold when another maker's files say less (issue 30, round 8: robustness).

Why: ``tools/corpus/robustness.py`` drafts the tune half under perturbations another maker's
files show (names blinded, neutral ids, the root moved, no meshes); a rule that falls there is
made structural. Each test is a small layout of the rule's shape whose links are only numbered
(``n0``, ``n1``...), so no name can decide it.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

from tests.draft_support import draft_layout as _draft
from tests.draft_support import joint_xml

_MASS = (
    '<inertial><mass value="{m}"/>'
    '<inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>'
)
_BOX = '<collision><geometry><box size="0.04 0.04 0.04"/></geometry></collision>'


def _link(name: str, mass: float | None = 0.3, box: bool = False) -> str:
    inner = ("" if mass is None else _MASS.format(m=mass)) + (_BOX if box else "")
    return f'<link name="{name}">{inner}</link>'


_joint = partial(joint_xml, limit=(-0.04, 0.04))


def _arm_with_jaws(box_on_base: bool = False) -> list[str]:
    """Six revolute joints, a hand, two prismatic jaws (one mimics the other): no shape at all."""
    parts = [_link("n0", box=box_on_base)]
    for i in range(1, 7):
        axis = "0 0 1" if i % 2 else "0 1 0"
        parts += [_link(f"n{i}"), _joint(f"q{i}", f"n{i - 1}", f"n{i}", axis=axis)]
    parts += [_link("n7"), _joint("q7", "n6", "n7", kind="fixed", xyz="0 0 0.08")]
    parts += [_link("n8"), _joint("q8", "n7", "n8", "prismatic", "0 0.02 0.06", "0 1 0")]
    parts += [_link("n9"), _joint("q9", "n7", "n9", "prismatic", "0 -0.02 0.06", "0 -1 0", "q8")]
    parts += [_link("n10", None), _joint("q10", "n7", "n10", kind="fixed", xyz="0 0 0.1")]
    return parts


def test_a_file_without_shapes_still_has_a_gripper(tmp_path: Path) -> None:
    """No shape anywhere (a kinematics-only file, meshes stripped): links with a mass are parts.

    The two jaws are found as fingers by their inertia, where a file with shapes finds them by
    their geometry; the massless leaf on the hand stays a bare frame.
    """
    draft = _draft(tmp_path, "shapeless", _arm_with_jaws())
    [m] = draft.manipulators
    assert m.thumb is not None and m.finger is not None
    assert {m.thumb.tip, m.finger.tip} == {"n8", "n9"}


def test_massive_shapeless_jaws_beside_shapes_elsewhere_are_fingers(tmp_path: Path) -> None:
    """A shape elsewhere (a box on the base) does not make massive shapeless jaws helpers.

    Where a hand's meshes are missing, its jaws' masses and mimic tag still say what they are;
    helpers beside them are told by structure (``tests/test_draft_structure_hands.py``).
    """
    draft = _draft(tmp_path, "helpers", _arm_with_jaws(box_on_base=True))
    [m] = draft.manipulators
    assert m.thumb is not None and m.finger is not None
    assert {m.thumb.tip, m.finger.tip} == {"n8", "n9"}


def _arm(root_xyz: str) -> list[str]:
    """Six revolute joints in series on a boxed base whose first joint sits at ``root_xyz``."""
    parts = [_link("n0", box=True)]
    for i in range(1, 7):
        axis = "0 0 1" if i % 2 else "0 1 0"
        xyz = root_xyz if i == 1 else "0.15 0 0"  # stretched out level, as UR arms are drawn
        parts += [
            _link(f"n{i}", box=True),
            _joint(f"q{i}", f"n{i - 1}", f"n{i}", xyz=xyz, axis=axis),
        ]
    return parts


def test_a_lone_run_reaching_below_its_base_frame_is_an_arm(tmp_path: Path) -> None:
    """A base frame placed 45 cm above the arm (another maker's ``base_link``) makes no leg.

    The run ends lowest, as a leg on the ground does; but a robot stands on two legs or more,
    and nothing names this one a leg: it is the arm, as with the frame placed at its foot.
    """
    for name, xyz in (("low", "0 0 0.1"), ("high", "0.3 -0.2 -0.45")):
        draft = _draft(tmp_path, name, _arm(xyz))
        assert [c.role for c in draft.chains] == ["arm"], name
        assert draft.chains[0].joints == frozenset(f"q{i}" for i in range(1, 7))


def test_two_runs_reaching_the_ground_stay_legs(tmp_path: Path) -> None:
    """Two mirrored runs from a trunk down to the ground stay legs (the rule is the lone run)."""
    parts = [_link("n0", box=True)]
    for side, y in (("a", "0.1"), ("b", "-0.1")):
        above = "n0"
        for i in range(1, 4):
            link = f"n{side}{i}"
            xyz = f"0 {y} -0.05" if i == 1 else "0 0 -0.2"
            parts += [_link(link, box=True), _joint(f"q{side}{i}", above, link, xyz=xyz)]
            above = link
    draft = _draft(tmp_path, "biped", parts)
    assert sorted(c.role for c in draft.chains) == ["leg", "leg"]


def test_a_run_of_frames_past_the_last_joint_ends_at_the_tool_frame(tmp_path: Path) -> None:
    """A frame fixed on a frame past the arm (a UR's flange, then tool0): the run's end is the TCP.

    Nothing is bolted to the run but where it ends; with the names gone (numbered links), the
    tool frame is still the last frame, not the flange it hangs on.
    """
    parts = [*_arm("0 0 0.1"), _link("n7", None), _joint("q7", "n6", "n7", "fixed", "0.05 0 0")]
    parts += [_link("n8", None), _joint("q8", "n7", "n8", "fixed", "0 0 0")]
    draft = _draft(tmp_path, "frames", parts)
    [m] = draft.manipulators
    assert m.tool_frame == "n8"


def _short_runs(feet: list[tuple[float, float]]) -> list[str]:
    """A boxed trunk with a 3-joint run of 12 cm hanging down from each (x, y) given."""
    parts = [_link("n0", box=True)]
    for i, (x, y) in enumerate(feet):
        above = "n0"
        for k, (xyz, axis) in enumerate(
            ((f"{x} {y} 0", "1 0 0"), ("0 0 -0.02", "0 1 0"), ("0 0 -0.05", "0 1 0"))
        ):
            link = f"n{i + 1}{k}"
            parts += [
                _link(link, box=True),
                _joint(f"q{i + 1}{k}", above, link, xyz=xyz, axis=axis),
            ]
            above = link
        parts += [
            _link(f"n{i + 1}9", None),
            _joint(f"q{i + 1}9", above, f"n{i + 1}9", "fixed", "0 0 -0.05"),
        ]
    return parts


def test_short_mirrored_runs_standing_on_the_ground_are_legs(tmp_path: Path) -> None:
    """Four 12 cm runs from the trunk, feet on the ground in mirrored pairs: a small quadruped.

    Shorter than an arm must be, and no name says "leg": where they stand decides.
    """
    feet = [(0.1, 0.05), (0.1, -0.05), (-0.1, 0.05), (-0.1, -0.05)]
    draft = _draft(tmp_path, "quadruped", _short_runs(feet))
    assert sorted(c.role for c in draft.chains) == ["leg"] * 4


def test_short_runs_side_by_side_are_no_legs(tmp_path: Path) -> None:
    """Four such runs side by side (a hand's fingers hanging down), not mirrored: no legs."""
    feet = [(0.0, 0.045), (0.0, 0.015), (0.0, -0.015), (0.03, -0.04)]
    draft = _draft(tmp_path, "fingers", _short_runs(feet))
    assert all(c.role != "leg" for c in draft.chains)
