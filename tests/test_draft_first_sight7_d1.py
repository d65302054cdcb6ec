"""Drafts of shapes round 7 of the blind corpus asked about (issue 30), on small layouts.

Each layout is built here from boxes (never a copy of a robot's files) and named by numbers
only, so what the drafter finds comes from the tree's shape, not from a maker's names.
"""

from __future__ import annotations

from pathlib import Path

from tests.test_draft_blind import _arm, _draft, _draft_srdf, _joint, _link


def _quadruped(foot_drop: float) -> list[str]:
    """A trunk 0.45 m up carrying four 3-joint runs (about x, y, y) named by numbers only.

    Each run's last link ('c*', the knee's) carries a fixed frame 'e*' ``foot_drop`` below it.
    """
    parts = [_link("t0", size=0.3)]
    corners = ("0.2 0.1 0", "0.2 -0.1 0", "-0.2 0.1 0", "-0.2 -0.1 0")
    for n, at in enumerate(corners, 1):
        parts += [
            _link(f"a{n}", size=0.03),
            _joint(f"q{n}1", "t0", f"a{n}", xyz=at, axis="1 0 0"),
            _link(f"b{n}", size=0.03),
            _joint(f"q{n}2", f"a{n}", f"b{n}", xyz="0 0 0"),
            _link(f"c{n}", size=0.03),
            _joint(f"q{n}3", f"b{n}", f"c{n}", xyz="0 0 -0.2"),
            _link(f"e{n}", size=0.02),
            _joint(f"f{n}", f"c{n}", f"e{n}", "fixed", xyz=f"0 0 {-foot_drop}"),
        ]
    return parts


def test_runs_whose_fixed_ends_stand_on_the_ground_are_legs_whatever_their_names(
    tmp_path: Path,
) -> None:
    # A quadruped named by numbers (the shape of HyQ's, ANYmal's, Mini Cheetah's legs): each
    # knee link sits 25 cm above the ground, its fixed foot frame on it. Where the run ends is
    # the lowest frame it carries, so the four runs are legs ending at their feet.
    d = _draft(tmp_path, "numbered_quadruped", _quadruped(0.25))
    assert sorted(c.role for c in d.chains) == ["leg"] * 4
    assert sorted(c.tip for c in d.chains) == ["e1", "e2", "e3", "e4"]
    assert not d.manipulators
    assert d.drive is not None and d.drive.type == "floating"


def test_runs_hanging_above_the_ground_stay_arms(tmp_path: Path) -> None:
    # The same runs on a trunk whose lowest part is a box far below their ends: nothing stands
    # on them, so they are not legs.
    parts = [
        *_quadruped(0.02),
        _link("s0", size=0.05),
        _joint("s0_fix", "t0", "s0", "fixed", xyz="0 0 -0.9"),
    ]
    d = _draft(tmp_path, "hanging_runs", parts)
    assert all(c.role != "leg" for c in d.chains)


def _mimic(name: str, parent: str, child: str, xyz: str, leader: str, axis: str = "0 1 0") -> str:
    """A revolute joint following ``leader`` (a mimic tag)."""
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>'
        '<limit lower="0" upper="1" effort="1" velocity="1"/>'
        f'<mimic joint="{leader}"/></joint>'
    )


def test_an_end_effector_whose_parent_frame_hangs_beside_the_gripper_keeps_the_gripper(
    tmp_path: Path,
) -> None:
    # HIWIN's layout: the SRDF end effector's parent link is a TCP frame 't0' fixed on the
    # arm's last link, beside the flange 'fl' the gripper is bolted to; the gripper's two jaws
    # move on their own joints. The gripper is the end effector's and 't0' its tool frame.
    parts = [
        *_arm("w4"),
        _link("fl", size=0.03),
        _joint("fl_fix", "w4", "fl", "fixed", xyz="0 0 0"),
        _link("g0", size=0.04),
        _joint("g0_fix", "fl", "g0", "fixed", xyz="0 0 0.03"),
        '<link name="t0"/>',
        _joint("t0_fix", "w4", "t0", "fixed", xyz="0 0 0.12"),
    ]
    for n, sign in ((1, 1), (2, -1)):
        parts += [
            _link(f"p{n}", size=0.01),
            _joint(f"pj{n}", "g0", f"p{n}", "prismatic", f"0 {sign * 0.02} 0.04", f"0 {sign} 0"),
        ]
    groups = (
        '<group name="a"><chain base_link="base" tip_link="w4"/></group>'
        '<group name="g"><joint name="pj1"/><joint name="pj2"/></group>'
        '<end_effector name="e" parent_link="t0" group="g" parent_group="a"/>'
    )
    d = _draft_srdf(tmp_path, "tcp_beside", parts, groups)
    (m,) = d.manipulators
    assert m.is_gripper and m.tool_frame == "t0" and m.root == "w4"
    assert {m.thumb.tip, m.finger.tip} == {"p1", "p2"}  # type: ignore[union-attr]


def test_four_branches_two_motors_move_two_each_are_a_parallel_gripper(tmp_path: Path) -> None:
    # A Moveo-like gripper: two gears on their own joints, each carrying a tip on a mimic,
    # and two pivot arms on mimics of the gears: two sides by the joints that move together.
    parts = [*_arm("w4")]
    for n, sign in ((1, 1), (2, -1)):
        parts += [
            _link(f"g{n}", size=0.01),
            _joint(f"gj{n}", "w4", f"g{n}", xyz=f"0 {sign * 0.015} 0.04"),
            _link(f"t{n}", size=0.01),
            _mimic(f"tj{n}", f"g{n}", f"t{n}", "0 0 0.04", f"gj{n}"),
            _link(f"v{n}", size=0.01),
            _mimic(f"vj{n}", "w4", f"v{n}", f"0.02 {sign * 0.01} 0.05", f"gj{n}"),
        ]
    d = _draft(tmp_path, "two_motor_linkage", parts)
    (m,) = d.manipulators
    assert m.is_gripper and {m.thumb.tip, m.finger.tip} == {"t1", "t2"}  # type: ignore[union-attr]


def test_of_two_moving_finger_ends_the_one_reaching_farther_is_the_tip(tmp_path: Path) -> None:
    # An AG-95-like four-bar finger pair: on each side an outer knuckle whose finger link
    # turns back inward on a mimic, and an inner knuckle whose pad reaches farther out.
    parts = [_link("h0", size=0.05)]
    for n, sign in ((1, 1), (2, -1)):
        y = sign * 0.016
        lead = "kj1"
        knuckle = (
            _joint("kj1", "h0", "k1", xyz=f"0 {y} 0.1")
            if n == 1
            else _mimic("kj2", "h0", "k2", f"0 {y} 0.1", lead)
        )
        parts += [
            _link(f"k{n}", size=0.01),
            knuckle,
            _link(f"o{n}", size=0.01),
            _mimic(f"oj{n}", f"k{n}", f"o{n}", f"0 {sign * 0.03} -0.02", lead),
            _link(f"i{n}", size=0.01),
            _mimic(f"ij{n}", "h0", f"i{n}", f"0 {y} 0.1", lead),
            _link(f"d{n}", size=0.01),
            _mimic(f"dj{n}", f"i{n}", f"d{n}", f"0 {sign * 0.04} 0.04", lead),
        ]
    d = _draft(tmp_path, "four_bar", parts)
    (m,) = d.manipulators
    assert m.is_gripper and {m.thumb.tip, m.finger.tip} == {"d1", "d2"}  # type: ignore[union-attr]


def test_of_three_fingers_the_one_without_a_spread_joint_is_the_thumb(tmp_path: Path) -> None:
    # A BarrettHand-like palm: fingers 1 and 3 turn about the palm's normal on spread joints
    # (one mimicking the other) and bend on two joints; finger 2, fixed to the palm, only
    # bends. Its base is no farther off the others' row than theirs: the joints decide.
    parts = [_link("p0", size=0.05)]
    for n, at in ((1, "-0.016 0.028 0.1"), (3, "-0.016 -0.028 0.1")):
        spread = (
            _joint("sj1", "p0", "s1", xyz=at, axis="0 0 1")
            if n == 1
            else _mimic("sj3", "p0", "s3", at, "sj1", axis="0 0 1")
        )
        parts += [_link(f"s{n}", size=0.01), spread]
    parts += [_link("s2", size=0.01), _joint("s2_fix", "p0", "s2", "fixed", xyz="0.032 0 0.1")]
    for n in (1, 2, 3):
        parts += [
            _link(f"m{n}", size=0.01),
            _joint(f"mj{n}", f"s{n}", f"m{n}", xyz="0.01 0 0.02"),
            _link(f"d{n}", size=0.01),
            _joint(f"dj{n}", f"m{n}", f"d{n}", xyz="0.04 0 0.03"),
        ]
    d = _draft(tmp_path, "three_fingers", parts)
    (m,) = d.manipulators
    assert m.thumb is not None and m.thumb.tip == "d2"
    assert sorted(f.tip for f in m.fingers.values()) == ["d1", "d3"]


def test_a_planar_virtual_joint_from_a_link_of_the_urdf_is_not_the_drive(tmp_path: Path) -> None:
    # A setup assistant's SRDF: a planar virtual joint from 'o0', a frame the URDF fixes on the
    # arm's base. It cannot be declared (the compiler refuses it); the arm stands fixed.
    parts = [*_arm("w4"), '<link name="o0"/>', _joint("o0_fix", "base", "o0", "fixed")]
    groups = (
        '<group name="a"><chain base_link="base" tip_link="w4"/></group>'
        '<virtual_joint name="v" type="planar" parent_frame="o0" child_link="base"/>'
    )
    d = _draft_srdf(tmp_path, "planar_from_a_link", parts, groups)
    assert d.drive is not None and d.drive.type == "fixed" and d.drive.decide


def test_a_leg_ending_on_a_continuous_joint_ends_at_the_wheels_axle(tmp_path: Path) -> None:
    # A wheel-legged quadruped (Unitree B2W's shape): each knee link carries a wheel on a
    # continuous joint about a level axis, its shape a box (a mesh the drafter cannot
    # measure). The leg ends at the knee link; the wheels roll it: a differential drive.
    parts = []
    for p in _quadruped(0.02):
        parts.append(p.replace('type="fixed"', 'type="continuous"').replace(
            '<origin xyz="0 0 -0.02" rpy="0 0 0"/>',
            '<origin xyz="0 0 -0.2" rpy="0 0 0"/><axis xyz="0 1 0"/>',
        ) if 'name="f' in p else p)  # fmt: skip
    d = _draft(tmp_path, "wheel_legs", parts)
    assert sorted(c.role for c in d.chains) == ["leg"] * 4
    assert sorted(c.tip for c in d.chains) == ["c1", "c2", "c3", "c4"]
    assert all(not any(j.startswith("f") for j in c.joints) for c in d.chains)
    assert d.drive is not None and d.drive.type == "differential"


def test_a_mirrored_pair_of_two_joint_runs_beside_two_legs_are_arms(tmp_path: Path) -> None:
    # A kid-size humanoid (the shape of a RoboCup robot's): two 4-joint legs and two 2-joint
    # arms (a shoulder and an elbow, 17 cm) from the trunk, a 2-joint head; numbers only.
    parts = [_link("t0", size=0.1)]
    for side, y in (("1", 0.05), ("2", -0.05)):
        above = "t0"
        for i, (xyz, axis) in enumerate(
            ((f"0 {y} -0.1", "0 0 1"), ("0 0 0", "1 0 0"), ("0 0 -0.15", "0 1 0")), 1
        ):
            parts.append(_link(f"l{side}{i}", size=0.02))
            parts.append(_joint(f"lj{side}{i}", above, f"l{side}{i}", xyz=xyz, axis=axis))
            above = f"l{side}{i}"
        parts.append(_link(f"l{side}4", size=0.02))
        parts.append(_joint(f"lj{side}4", above, f"l{side}4", xyz="0 0 -0.15"))
        parts += [
            _link(f"a{side}1", size=0.02),
            _joint(f"aj{side}1", "t0", f"a{side}1", xyz=f"0 {y * 1.5} 0.05"),
            _link(f"a{side}2", size=0.02),
            _joint(f"aj{side}2", f"a{side}1", f"a{side}2", xyz="0 0 -0.1"),
        ]
    parts += [
        _link("n1", size=0.02),
        _joint("nj1", "t0", "n1", xyz="0 0 0.08", axis="0 0 1"),
        _link("n2", size=0.03),
        _joint("nj2", "n1", "n2", xyz="0 0 0.02"),
    ]
    d = _draft(tmp_path, "kid_humanoid", parts)
    roles = sorted((c.role, c.tip) for c in d.chains)
    assert [r for r in roles if r[0] == "arm"] == [("arm", "a12"), ("arm", "a22")]
    assert [r for r in roles if r[0] == "leg"] == [("leg", "l14"), ("leg", "l24")]


def test_a_leg_ends_at_its_lowest_fixed_frame_among_several(tmp_path: Path) -> None:
    # Each knee link carries its foot frame 25 cm down and a sensor's frame 6 cm down and 3 cm
    # aside (neither on the knee's axis, neither named): the leg ends at the foot, the lowest.
    parts = list(_quadruped(0.25))
    for n in (1, 2, 3, 4):
        parts.append(_link(f"s{n}", size=0.01))
        parts.append(_joint(f"s{n}_fix", f"c{n}", f"s{n}", "fixed", xyz="0.03 0 -0.06"))
    d = _draft(tmp_path, "foot_and_sensor", parts)
    assert sorted(c.tip for c in d.chains) == ["e1", "e2", "e3", "e4"]


def test_two_continuous_joints_on_one_axle_are_wheels_whatever_their_names(
    tmp_path: Path,
) -> None:
    # A base whose two wheels are boxes (meshes the drafter cannot measure) on continuous
    # joints named by numbers, on one axle (the line between them along their axes): a
    # differential drive, and no gripper of two "fingers".
    parts = [_link("b0", size=0.3)]
    for n, y in ((1, 0.2), (2, -0.2)):
        parts.append(_link(f"r{n}", size=0.1))
        parts.append(_joint(f"q{n}", "b0", f"r{n}", "continuous", xyz=f"0 {y} -0.1"))
    d = _draft(tmp_path, "unnamed_wheels", parts)
    assert not d.manipulators
    assert d.drive is not None and d.drive.type == "differential"


def test_two_continuous_jaws_side_by_side_across_their_axes_are_no_wheels(tmp_path: Path) -> None:
    # Two one-link jaws on continuous joints about parallel axes, 4 cm apart across them:
    # a gripper's jaws, not an axle.
    parts = [_link("h0", size=0.05)]
    for n, x in ((1, 0.02), (2, -0.02)):
        parts.append(_link(f"j{n}", size=0.01))
        parts.append(_joint(f"q{n}", "h0", f"j{n}", "continuous", xyz=f"{x} 0 0.06"))
    d = _draft(tmp_path, "continuous_jaws", parts)
    assert d.drive is not None and d.drive.type == "fixed"
