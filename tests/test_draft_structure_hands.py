"""Grippers and hands found from structure where shapes are missing (issue 30, ``bare_fingers``).

Why: ``tools/corpus/robustness.py``'s ``no-meshes`` row drafts the tune half with every mesh
removed (a mesh package missing, a file written for dynamics): fingers then have no shape, and
only masses, joint ranges and mimic tags tell them from the helpers beside them. Each test is a
small layout of one rule's shape; links and joints are only numbered, so no name decides.
"""

from __future__ import annotations

from pathlib import Path

from tests.draft_support import draft_layout as _draft
from tests.draft_support import joint_xml

_MASS = (
    '<inertial><mass value="{m}"/>'
    '<inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>'
)
_BOX = '<{tag}><geometry><box size="0.02 0.02 0.02"/></geometry></{tag}>'


def _link(name: str, mass: float | None = 0.1, shape: str | None = None) -> str:
    """A link with a mass (or none) and a box as ``shape`` ('collision', 'visual' or None)."""
    inner = ("" if mass is None else _MASS.format(m=mass)) + (
        "" if shape is None else _BOX.format(tag=shape)
    )
    return f'<link name="{name}">{inner}</link>'


def _joint(
    name: str,
    parent: str,
    child: str,
    kind: str = "revolute",
    xyz: str = "0 0 0.05",
    axis: str = "1 0 0",
    mimic: str | None = None,
    multiplier: float = 1.0,
    limit: tuple[float, float] = (0.0, 0.8),
) -> str:
    """tests/draft_support.joint_xml with this file's defaults (a mimic writes its multiplier)."""
    return joint_xml(name, parent, child, kind, xyz, axis, mimic, multiplier, limit)


def _arm(hand_mass: float | None = 0.3) -> list[str]:
    """A boxed base and six revolute joints up to a shapeless hand link ``h`` (its meshes gone)."""
    parts = [_link("n0", 2.0, "collision")]
    for i in range(1, 7):
        axis = "0 0 1" if i % 2 else "0 1 0"
        parts += [
            _link(f"n{i}", 1.0),
            _joint(f"q{i}", f"n{i - 1}", f"n{i}", xyz="0 0 0.15", axis=axis),
        ]
    parts += [_link("h", hand_mass), _joint("qh", "n6", "h", kind="fixed", xyz="0 0 0.06")]
    return parts


def _gripper(draft: object) -> tuple[str, str] | None:
    """The finger tips of the one parallel gripper drafted, sorted (None: no gripper)."""
    grippers = [m for m in draft.manipulators if m.thumb is not None and m.finger is not None]  # type: ignore[attr-defined]
    if not grippers:
        return None
    [m] = grippers
    a, b = sorted((m.thumb.tip, m.finger.tip))
    return a, b


def test_a_helper_turning_without_end_beside_two_fingers_is_not_one(tmp_path: Path) -> None:
    """Three shapeless branches with a mass: the one holding a continuous joint is a screw.

    PR2's gripper with its meshes gone: a motor slider (prismatic, a continuous screw below it)
    beside two fingers of two links each, the second finger and both tips on mimic tags.
    """
    parts = _arm()
    parts += [
        _link("s1", 0.01),
        _joint("qs1", "h", "s1", "prismatic", "0.1 0 0", limit=(-0.1, 0.1)),
    ]
    parts += [_link("s2", 0.01), _joint("qs2", "s1", "s2", "continuous", "0 0 0", "0 1 0")]
    for side, y, mimic in (("a", "0.01", None), ("b", "-0.01", "qa1")):
        parts += [
            _link(f"{side}1", 0.17),
            _joint(f"q{side}1", "h", f"{side}1", xyz=f"0 {y} 0.07", mimic=mimic),
        ]
        parts += [
            _link(f"{side}2", 0.04),
            _joint(f"q{side}2", f"{side}1", f"{side}2", xyz=f"0 {y} 0.09", mimic="qa1"),
        ]
    draft = _draft(tmp_path, "screw", parts)
    assert _gripper(draft) == ("a2", "b2")


def test_an_actuator_stand_in_the_fingers_mimic_is_not_a_finger(tmp_path: Path) -> None:
    """A shapeless one-joint leaf whose joint both fingers' mimic tags follow is the motor.

    HSR-B's 'hand_motor_dummy_link' beside its two fingers; a box on one finger's end (a
    vacuum pad, the one shape left once meshes are gone) is a decoration, not the finger's tip.
    """
    parts = _arm()
    parts += [_link("m", 0.15), _joint("qm", "h", "m")]
    for side, y in (("a", "0.025"), ("b", "-0.025")):
        parts += [
            _link(f"{side}1", 0.15),
            _joint(f"q{side}1", "h", f"{side}1", xyz=f"0 {y} 0.02", mimic="qm"),
        ]
        parts += [
            _link(f"{side}2", 0.03),
            _joint(
                f"q{side}2", f"{side}1", f"{side}2", xyz="0 0 0.07", mimic="qm", multiplier=-1.0
            ),
        ]
    parts += [
        _link("pad", 0.15, "visual"),
        _joint("qpad", "a2", "pad", kind="fixed", xyz="0 0 0.03"),
    ]
    draft = _draft(tmp_path, "standin", parts)
    assert _gripper(draft) == ("a2", "b2")


def test_a_prop_turning_without_end_beside_the_finger_carriage(tmp_path: Path) -> None:
    """The hand splits into a prop on a continuous joint and a carriage; the jaws split below.

    Interbotix's gripper with its meshes gone: two prismatic jaws moving opposite ways (one
    mimics the other with a negative multiplier) on a link fixed below the carriage.
    """
    parts = _arm()
    parts += [_link("p", 0.008), _joint("qp", "h", "p", "continuous", "0.005 0 0", "1 0 0")]
    parts += [_link("bar", 0.15), _joint("qbar", "h", "bar", kind="fixed", xyz="0 0 0.02")]
    parts += [_link("c", 0.001), _joint("qc", "bar", "c", kind="fixed", xyz="0 0 0.02")]
    parts += [
        _link("ja", 0.03),
        _joint("qja", "c", "ja", "prismatic", "0 0 0", "0 1 0", limit=(0.02, 0.05)),
    ]
    parts += [
        _link("jb", 0.03),
        _joint("qjb", "c", "jb", "prismatic", "0 0 0", "0 1 0", "qja", -1.0, (-0.05, -0.02)),
    ]
    draft = _draft(tmp_path, "prop", parts)
    assert _gripper(draft) == ("ja", "jb")


def test_a_finger_tip_is_its_deepest_link_with_a_mass(tmp_path: Path) -> None:
    """Jaws whose pads hang on fixed joints below the slide: the tip is the pad, not the slide.

    Unitree Dex1's two prismatic jaws with their meshes gone: each carries two fixed links with
    a mass; where the jaw closes is the last of them.
    """
    parts = [_link("n0", 0.11)]
    for side, x, axis in (("a", "0.04", "-1 0 0"), ("b", "-0.04", "1 0 0")):
        parts += [
            _link(f"{side}1", 0.008),
            _joint(
                f"q{side}1", "n0", f"{side}1", "prismatic", f"{x} 0.06 0", axis, limit=(-0.02, 0.02)
            ),
        ]
        parts += [
            _link(f"{side}2", 0.03),
            _joint(f"q{side}2", f"{side}1", f"{side}2", kind="fixed", xyz="0 0.013 0"),
        ]
        parts += [
            _link(f"{side}3", 0.005),
            _joint(f"q{side}3", f"{side}2", f"{side}3", kind="fixed", xyz="0 0.025 0"),
        ]
    parts += [
        _link("frame", None, "collision"),
        _joint("qf", "n0", "frame", kind="fixed", xyz="0 -0.02 0"),
    ]
    draft = _draft(tmp_path, "pads", parts)
    assert _gripper(draft) == ("a3", "b3")


def _finger(name: str, parent: str, xyz: str, mass: float, shape: str | None) -> list[str]:
    """A finger of two links on two revolute joints, its second link ending in a pad."""
    return [
        _link(f"{name}1", mass, shape),
        _joint(f"q{name}1", parent, f"{name}1", xyz=xyz, axis="0 1 0"),
        _link(f"{name}2", mass, shape),
        _joint(f"q{name}2", f"{name}1", f"{name}2", xyz="0 0 0.04", axis="0 1 0"),
    ]


def test_a_thumb_whose_shapes_are_missing_beside_shaped_fingers(tmp_path: Path) -> None:
    """A hand of four boxed fingers and a thumb with a mass but no shape: five fingers.

    Ability's hand with the thumb's mesh gone while its fingers keep primitive collisions: the
    thumb is found by its mass and its finger's range, and by where its base lies (off the
    fingers' row); its tip is its last phalanx.
    """
    parts = [_link("n0", 0.2, "collision")]
    for i, x in enumerate((-0.03, -0.01, 0.01, 0.03)):
        parts += _finger(f"f{i}", "n0", f"{x} 0 0.07", 0.006, "collision")
    parts += _finger("t", "n0", "0.04 0.03 0.02", 0.005, None)
    draft = _draft(tmp_path, "thumb", parts)
    [m] = draft.manipulators
    assert m.thumb is not None and m.thumb.tip == "t2"
    assert sorted(f.tip for f in m.fingers.values()) == ["f02", "f12", "f22", "f32"]
    assert any("thumb" in d for d in m.decide)  # found by where it lies: a question


def test_a_last_phalanx_whose_shape_is_missing_is_the_tip(tmp_path: Path) -> None:
    """A finger whose middle link keeps a primitive collision and whose last one lost its mesh.

    Shadow's fingers with meshes gone: the distal phalanx still has its mass and its joint, so
    it is the finger's tip, not the last link with a shape.
    """
    parts = _arm()
    for side, y, mimic in (("a", "0.02", None), ("b", "-0.02", "qa1")):
        parts += [
            _link(f"{side}1", 0.03, "collision"),
            _joint(f"q{side}1", "h", f"{side}1", xyz=f"0 {y} 0.03", mimic=mimic),
            _link(f"{side}2", 0.01),
            _joint(f"q{side}2", f"{side}1", f"{side}2", xyz="0 0 0.04", mimic="qa1"),
        ]
    draft = _draft(tmp_path, "phalanx", parts)
    assert _gripper(draft) == ("a2", "b2")


def test_two_wheels_driven_without_end_are_no_gripper(tmp_path: Path) -> None:
    """Two shaped branches on continuous joints, nothing else: a car's front wheels, no fingers.

    As F1TENTH's file has them: no axis given (x, the default) and the wheel's cylinder left
    upright, so neither names nor the shape's axis say "wheel"; the joints do, turning
    without end where a finger closes within a range.
    """
    cyl = '<visual><geometry><cylinder radius="0.05" length="0.04"/></geometry></visual>'
    box = '<visual><geometry><box size="0.4 0.2 0.1"/></geometry></visual>'
    parts = [f'<link name="n0">{box}</link>']
    for side, y in (("a", "0.12"), ("b", "-0.12")):
        parts += [
            f'<link name="{side}0"/>',
            _joint(f"q{side}0", "n0", f"{side}0", kind="fixed", xyz=f"0.33 {y} 0.05"),
            f'<link name="{side}1">{cyl}</link>',
            f'<joint name="q{side}1" type="continuous"><parent link="{side}0"/>'
            f'<child link="{side}1"/></joint>',
        ]
    draft = _draft(tmp_path, "car", parts)
    assert _gripper(draft) is None


def test_rods_ending_in_ball_joints_are_no_fingers(tmp_path: Path) -> None:
    """Six rods from a base, each ending in three revolute joints at one point: a linkage.

    A Stewart platform's legs look like six identical fingers on a circle; no finger has a ball
    joint (three axes spanning space at one point, each a full turn).
    """
    parts = [_link("n0", 0.8, "collision")]
    for i in range(6):
        x, y = (0.04, 0.0) if i % 2 else (-0.04, 0.0)
        y = 0.01 * (i - 3)
        parts += [
            _link(f"h{i}", 0.004, "collision"),
            _joint(f"qh{i}", "n0", f"h{i}", xyz=f"{x} {y} 0.04", axis="0 0 1"),
        ]
        above = f"h{i}"
        for k, axis in enumerate(("1 0 0", "0 1 0", "0 0 1")):
            link = f"b{i}{k}"
            xyz = "0.04 0 0.007" if k == 0 else "0 0 0"
            mass = 0.005 if k == 2 else 1e-9
            parts += [
                _link(link, mass, "collision" if k == 2 else None),
                _joint(f"qb{i}{k}", above, link, xyz=xyz, axis=axis, limit=(-3.14159, 3.14159)),
            ]
            above = link
    draft = _draft(tmp_path, "stewart", parts)
    assert not any(m.is_hand or m.is_gripper for m in draft.manipulators)


def test_the_thumb_is_the_finger_that_is_no_copy_of_the_others(tmp_path: Path) -> None:
    """Three fingers built alike and one unlike them: with no name to say, the odd one is the thumb.

    Leap's hand: its three fingers are one part placed three times along the palm (here also
    one alone on its side, which would have made it the thumb); the thumb's joints differ.
    """
    parts = [_link("n0", 0.2, "collision")]
    for i, y in enumerate((0.045, -0.0, -0.045)):
        parts += [
            _link(f"f{i}1", 0.01, "collision"),
            _joint(f"qf{i}1", "n0", f"f{i}1", xyz=f"0 {y} 0.08", axis="0 1 0", limit=(-0.3, 2.2)),
            _link(f"f{i}2", 0.01, "collision"),
            _joint(f"qf{i}2", f"f{i}1", f"f{i}2", xyz="0 0 0.04", axis="0 1 0", limit=(0.0, 1.8)),
            _link(f"f{i}3", 0.01, "collision"),
            _joint(f"qf{i}3", f"f{i}2", f"f{i}3", xyz="0 0 0.036", axis="0 1 0", limit=(-0.3, 2.0)),
        ]
    parts += [
        _link("t1", 0.01, "collision"),
        _joint("qt1", "n0", "t1", xyz="0.03 -0.02 0.02", axis="1 0 0", limit=(-0.3, 2.1)),
        _link("t2", 0.01, "collision"),
        _joint("qt2", "t1", "t2", xyz="0 0 0.015", axis="0 1 0", limit=(-0.4, 2.4)),
        _link("t3", 0.01, "collision"),
        _joint("qt3", "t2", "t3", xyz="0 0 0.05", axis="0 1 0", limit=(-1.2, 1.9)),
    ]
    draft = _draft(tmp_path, "copies", parts)
    [m] = draft.manipulators
    assert m.thumb is not None and m.thumb.tip == "t3"
    assert sorted(f.tip for f in m.fingers.values()) == ["f03", "f13", "f23"]
    assert any("unlike the others" in d for d in m.decide)


def test_a_shapeless_helper_beside_two_shaped_fingers_is_no_finger(tmp_path: Path) -> None:
    """Two jaws with shapes and a slider with a mass but none, on a prismatic joint of its own.

    Two shaped branches are the gripper's fingers (as before shapes were read as missing); a
    massive shapeless branch beside them is a helper, whatever its joint.
    """
    parts = _arm()
    parts += [_link("s", 0.01), _joint("qs", "h", "s", "prismatic", "0 0 0.01", limit=(-0.1, 0.1))]
    for side, y, mimic in (("a", "0.02", None), ("b", "-0.02", "qa")):
        parts += [
            _link(side, 0.05, "collision"),
            _joint(f"q{side}", "h", side, "prismatic", f"0 {y} 0.05", "0 1 0", mimic, -1.0),
        ]
    draft = _draft(tmp_path, "helper", parts)
    assert _gripper(draft) == ("a", "b")


def _linkage(transmission: bool) -> list[str]:
    """A linkage gripper of four branches (outer and inner knuckles) with no mimic tag at all."""
    parts = _arm()
    for side, s in (("a", 1), ("b", -1)):
        parts += [
            _link(f"{side}o", 0.02, "collision"),
            _joint(f"q{side}o", "h", f"{side}o", xyz=f"0.055 {0.031 * s} 0"),
            _link(f"{side}f", 0.03, "collision"),
            _joint(f"q{side}f", f"{side}o", f"{side}f", kind="fixed", xyz=f"0 {0.03 * s} 0.01"),
            _link(f"{side}i", 0.03, "collision"),
            _joint(f"q{side}i", "h", f"{side}i", xyz=f"0.061 {0.013 * s} 0"),
            _link(f"{side}t", 0.02, "collision"),
            _joint(f"q{side}t", f"{side}i", f"{side}t", xyz=f"0.043 {0.038 * s} 0"),
        ]
    if transmission:
        parts.append(
            '<transmission name="tr"><type>transmission_interface/SimpleTransmission</type>'
            '<joint name="qao"><hardwareInterface>hardware_interface/PositionJointInterface'
            '</hardwareInterface></joint><actuator name="m"><mechanicalReduction>1'
            "</mechanicalReduction></actuator></transmission>"
        )
    return parts


def test_a_linkage_without_mimic_tags_one_transmission_drives(tmp_path: Path) -> None:
    """Four finger branches, no mimic tag, one joint in a transmission: one motor, a gripper.

    A Robotiq-style linkage whose file couples its links only in a simulator plugin: the
    control block says one joint is driven, so the four branches are two sides of one
    gripper (still a question: no mimic tag states the coupling); without the block they are
    four separately driven branches, no gripper.
    """
    draft = _draft(tmp_path, "linkage", _linkage(transmission=True))
    assert _gripper(draft) == ("at", "bt")
    [m] = draft.manipulators
    assert m.decide  # not stated by a mimic tag: still asked
    plain = _draft(tmp_path, "plain", _linkage(transmission=False))
    assert _gripper(plain) is None
