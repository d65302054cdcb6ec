"""Chains found from the tree's shape when no name helps (issue 30: arms and legs by structure).

Why: another maker's names match none of the drafter's word lists; a leg is a run standing the
robot on the ground in mirrored pairs, an arm a mirrored pair of runs on the trunk, whatever
they are called. Each test is a small layout of one rule's shape whose links and joints are
only numbered, so no name can decide it; the trunk frame is also placed off the robot's middle
(a maker's root link at a hip), which a mirror test must not depend on.
"""

from __future__ import annotations

from pathlib import Path

from tests.draft_support import draft_layout as _draft

_BOX = '<collision><geometry><box size="{s} {s} {s}"/></geometry></collision>'
_MASS = (
    '<inertial><mass value="0.3"/>'
    '<inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>'
)


def _link(name: str, size: float = 0.03) -> str:
    return f'<link name="{name}">{_MASS}{_BOX.format(s=size)}</link>'


def _joint(
    name: str, parent: str, child: str, xyz: str, axis: str = "0 1 0", kind: str = "revolute"
) -> str:
    moving = (
        ""
        if kind == "fixed"
        else f'<axis xyz="{axis}"/><limit lower="-1" upper="1" effort="5" velocity="2"/>'
    )
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/>{moving}</joint>'
    )


def _run(prefix: str, parent: str, offsets: list[str], axes: list[str]) -> list[str]:
    """A serial run of revolute joints below ``parent``: links ``{prefix}1``..."""
    parts: list[str] = []
    above = parent
    for i, (xyz, axis) in enumerate(zip(offsets, axes, strict=True), 1):
        parts += [_link(f"{prefix}{i}"), _joint(f"{prefix}j{i}", above, f"{prefix}{i}", xyz, axis)]
        above = f"{prefix}{i}"
    return parts


#: Where the trunk's frame lies off the robot's middle (m): a maker's root at a hip.
_OFF = 0.07


def test_four_mirrored_two_joint_runs_well_below_the_trunk_are_legs(tmp_path: Path) -> None:
    # A hip and a knee each (a small quadruped's), the feet 32 cm below the trunk on the
    # ground in mirrored pairs; the trunk's frame sits 7 cm off the middle.
    parts = [_link("t0", 0.3)]
    for n, (x, y) in enumerate(((0.2, 0.14), (0.2, -0.14), (-0.2, 0.14), (-0.2, -0.14)), 1):
        parts += _run(f"r{n}", "t0", [f"{x} {y - _OFF} 0", "0 0 -0.16"], ["0 1 0", "0 1 0"])
        parts += [
            _link(f"f{n}", 0.02),
            _joint(f"fj{n}", f"r{n}2", f"f{n}", "0 0 -0.16", kind="fixed"),
        ]
    d = _draft(tmp_path, "two_joint_legs", parts)
    assert sorted(c.role for c in d.chains) == ["leg"] * 4
    assert sorted(c.tip for c in d.chains) == ["f1", "f2", "f3", "f4"]


def test_four_casters_steering_and_rolling_are_no_legs(tmp_path: Path) -> None:
    # Four mirrored runs of a steering joint and a wheel (continuous) reaching the ground: a
    # base's casters; a wheel's joint is no leg's.
    parts = [_link("t0", 0.3)]
    for n, (x, y) in enumerate(((0.2, 0.18), (0.2, -0.18), (-0.2, 0.18), (-0.2, -0.18)), 1):
        parts += [
            _link(f"s{n}"),
            _joint(f"sj{n}", "t0", f"s{n}", f"{x} {y} -0.1", "0 0 1"),
            _link(f"w{n}", 0.1),
            _joint(f"wj{n}", f"s{n}", f"w{n}", "0 0 -0.15", "0 1 0", "continuous"),
        ]
    d = _draft(tmp_path, "casters", parts)
    assert all(c.role != "leg" for c in d.chains)


def _biped(waist: bool, arm_joints: int) -> list[str]:
    """Two 3-joint legs on a trunk, arms of ``arm_joints`` on it (or on a waist it turns)."""
    parts = [_link("t0", 0.2)]
    for n, y in ((1, 0.1), (2, -0.1)):
        parts += _run(
            f"g{n}",
            "t0",
            [f"0 {y - _OFF} -0.05", "0 0 -0.15", "0 0 -0.15"],
            ["1 0 0", "0 1 0", "0 1 0"],
        )
    carrier = "t0"
    if waist:
        parts += [_link("w1", 0.1), _joint("wj1", "t0", "w1", "0 0 0.08", "0 0 1")]
        carrier = "w1"
    for n, y in ((1, 0.11), (2, -0.11)):
        off = -_OFF if carrier == "t0" else 0.0
        offsets = [f"0 {y + off} 0.12", "0 0 -0.1"][:arm_joints]
        parts += _run(f"a{n}", carrier, offsets, ["0 1 0", "1 0 0"][:arm_joints])
    return parts


def test_a_mirrored_pair_of_single_shoulders_on_a_waist_above_legs_are_arms(
    tmp_path: Path,
) -> None:
    # A biped whose arms are one shoulder joint each, on a link a waist turns above the legs'
    # trunk (a small research biped's): the mirrored pair is its arms.
    d = _draft(tmp_path, "one_joint_arms", _biped(waist=True, arm_joints=1))
    arms = sorted((c.root, c.tip, tuple(sorted(c.joints))) for c in d.chains if c.role == "arm")
    assert arms == [("w1", "a11", ("a1j1",)), ("w1", "a21", ("a2j1",))]
    assert sorted(c.role for c in d.chains if c.role == "leg") == ["leg", "leg"]
    assert all(c.decide for c in d.chains)  # found by shape: each asks to be checked


def test_two_joint_arms_beside_legs_with_the_trunk_frame_off_the_middle(tmp_path: Path) -> None:
    # The mirror plane is the runs' own middle, not the trunk frame's x-z plane.
    d = _draft(tmp_path, "off_middle", _biped(waist=False, arm_joints=2))
    arms = sorted(tuple(sorted(c.joints)) for c in d.chains if c.role == "arm")
    assert arms == [("a1j1", "a1j2"), ("a2j1", "a2j2")]


def test_legs_below_hips_reach_the_ground_when_the_root_frame_sits_on_it(tmp_path: Path) -> None:
    # The trunk's frame on the ground under the pelvis (a maker's choice): the legs start at
    # hips 54 cm up and end 9 cm above that frame; they drop from their hips, not from it.
    parts = [_link("t0", 0.2)]
    for n, y in ((1, 0.08), (2, -0.08)):
        parts += _run(
            f"g{n}",
            "t0",
            [f"0 {y} 0.54", "0 0 -0.15", "0 0 -0.15", "0 0 -0.15"],
            ["1 0 0", "0 1 0", "0 1 0", "0 1 0"],
        )
    for n, y in ((1, 0.15), (2, -0.15)):
        parts += _run(
            f"a{n}", "t0", [f"0 {y} 0.76", "0 0 -0.1", "0 0 -0.1"], ["0 1 0", "1 0 0", "0 1 0"]
        )
    d = _draft(tmp_path, "pelvis_up", parts)
    legs = sorted(tuple(sorted(c.joints)) for c in d.chains if c.role == "leg")
    assert legs == [tuple(f"g1j{i}" for i in range(1, 5)), tuple(f"g2j{i}" for i in range(1, 5))]
    assert sorted(c.root for c in d.chains if c.role == "arm") == ["t0", "t0"]


def _humanoid_with_head(head: list[tuple[str, str]]) -> list[str]:
    """Two legs, two arms and a head of ``head`` (offset, axis) joints on the trunk's top."""
    parts = [_link("t0", 0.2)]
    for n, y in ((1, 0.08), (2, -0.08)):
        parts += _run(f"g{n}", "t0", [f"0 {y} -0.1", "0 0 -0.2", "0 0 -0.2"], ["1 0 0"] * 3)
        parts += _run(
            f"a{n}", "t0", [f"0 {2 * y} 0.2", "0 0 -0.1", "0 0 -0.1"], ["0 1 0", "1 0 0", "0 1 0"]
        )
    offsets, axes = [o for o, _ in head], [a for _, a in head]
    return parts + _run("h", "t0", offsets, axes)


def test_a_single_yaw_joint_carrying_the_top_of_the_robot_is_its_head(tmp_path: Path) -> None:
    d = _draft(tmp_path, "yaw_head", _humanoid_with_head([("0 0 0.3", "0 0 1")]))
    [head] = [c for c in d.chains if c.joints == frozenset({"hj1"})]
    assert head.role == "chain" and head.decide


def test_a_head_that_tilts_then_pans_on_top_is_a_head(tmp_path: Path) -> None:
    d = _draft(
        tmp_path, "tilt_pan", _humanoid_with_head([("0 0 0.3", "0 1 0"), ("0 0 0.05", "0 0 1")])
    )
    assert [c.role for c in d.chains if c.joints == frozenset({"hj1", "hj2"})] == ["chain"]


def test_a_yaw_joint_below_the_top_of_the_robot_is_no_head(tmp_path: Path) -> None:
    # The same joint on the trunk's front, lower than the shoulders: no head.
    d = _draft(tmp_path, "low_yaw", _humanoid_with_head([("0.1 0 0.05", "0 0 1")]))
    assert not [c for c in d.chains if c.joints == frozenset({"hj1"})]


def test_a_three_joint_neck_carrying_the_top_between_the_arms_is_a_head(tmp_path: Path) -> None:
    # A neck's pitch, roll and yaw (23 cm: as long as a short arm) on the trunk beside the arms,
    # numbers only: it carries the robot's top and pans, so a head, not a third arm.
    offsets = [("0 0 0.2", "0 1 0"), ("0 0 0.03", "1 0 0"), ("0 0 0.2", "0 0 1")]
    d = _draft(tmp_path, "neck3", _humanoid_with_head(offsets))
    assert sorted(c.role for c in d.chains) == ["arm", "arm", "chain", "leg", "leg"]
    [head] = [c for c in d.chains if c.role == "chain"]
    assert head.joints == frozenset({"hj1", "hj2", "hj3"})


def test_a_yaw_joint_on_a_lower_body_without_arms_is_no_head(tmp_path: Path) -> None:
    # A lower body whose torso stub turns on the hips' link (example-robot-data's Alexander
    # lower body): the top of the robot, but no arm hangs beside it: a waist, not a head.
    parts = [_link("t0", 0.2)]
    for n, y in ((1, 0.08), (2, -0.08)):
        parts += _run(f"g{n}", "t0", [f"0 {y} -0.1", "0 0 -0.2", "0 0 -0.2"], ["1 0 0"] * 3)
    d = _draft(tmp_path, "lower_body", parts + _run("h", "t0", ["0 0 0.2"], ["0 0 1"]))
    assert not [c for c in d.chains if c.joints == frozenset({"hj1"})]


def test_spinners_turning_about_parallel_vertical_axes_on_top_are_no_head(tmp_path: Path) -> None:
    # Four rotors on a multirotor's body, revolute joints without a real range (example-robot-
    # data's Iris): each pans on top of the robot, but siblings spinning alike are no head.
    parts = [_link("t0", 0.2)]
    for n, (x, y) in enumerate(((0.13, -0.22), (-0.13, 0.2), (0.13, 0.22), (-0.13, -0.2)), 1):
        parts += [
            _link(f"p{n}", 0.01),
            f'<joint name="p{n}j1" type="revolute"><parent link="t0"/><child link="p{n}"/>'
            f'<origin xyz="{x} {y} 0.023"/><axis xyz="0 0 1"/>'
            '<limit lower="-1e16" upper="1e16" effort="0" velocity="0"/></joint>',
        ]
    d = _draft(tmp_path, "rotors", parts)
    assert not [c for c in d.chains if c.joints & {"p1j1", "p2j1", "p3j1", "p4j1"}]
