"""What ``migrate sdt`` reads off the robot's own files (robotspec.interop.sdt.migrate_facts).

No SDT needed: the drive and the arms' sides come from robotspec's model of real robot files,
never from SDT's class (which states neither), and never a blanket ``omni`` (issue 32).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from robotspec.description.load import Description, load_description
from robotspec.interop.sdt.migrate_facts import arm_offsets, drive_fact, geometric_left
from tests.conftest import erd_robots


def _erd(urdf: str, srdf: str | None = None) -> Description:
    robots = erd_robots()
    return load_description(
        robots / urdf,
        srdf=None if srdf is None else robots / srdf,
        package_paths=[robots.parent],
        base_folder=Path.cwd(),
    )


def test_an_srdf_planar_virtual_joint_is_left_to_the_compiler() -> None:
    pr2 = _erd("pr2_description/urdf/pr2.urdf", "pr2_description/srdf/pr2.srdf")
    fact = drive_fact(pr2.world, pr2.srdf, "base_footprint", moves=True)
    assert fact.spec is None and fact.note is None  # the compiler reads 'world_joint'


def test_a_base_its_files_do_not_move_gets_no_drive_but_a_note() -> None:
    # PR2's URDF alone: casters only, no planar joint, no SRDF: nobody says omni.
    pr2 = _erd("pr2_description/urdf/pr2.urdf")
    fact = drive_fact(pr2.world, None, "base_footprint", moves=True)
    assert fact.spec is None
    assert fact.note is not None and fact.note.startswith("drive: SDT's class gives")
    assert "no wheels" in fact.note and "above 'base_footprint'" in fact.note


def test_two_driven_wheels_are_a_differential_drive() -> None:
    # TIAGo: two driven wheels and four casters (on swivels, not counted).
    tiago = _erd("tiago_description/robots/tiago.urdf")
    fact = drive_fact(tiago.world, None, tiago.world.root.name, moves=True)
    assert fact.spec == {"type": "differential"} and fact.note is None


def test_a_legged_robot_states_no_drive() -> None:
    g1 = _erd("g1_description/urdf/g1_29dof_with_hand_rev_1_0.urdf")
    fact = drive_fact(g1.world, None, "pelvis", moves=True)
    assert fact.spec is None and fact.note is not None and "no wheels" in fact.note


def test_a_class_without_a_mobile_base_overrules_the_virtual_joint() -> None:
    pr2 = _erd("pr2_description/urdf/pr2.urdf", "pr2_description/srdf/pr2.srdf")
    fact = drive_fact(pr2.world, pr2.srdf, "base_footprint", moves=False)
    assert fact.spec == {"type": "fixed"}
    assert fact.note is not None and "virtual joint 'world_joint' (planar)" in fact.note
    bare = _erd("pr2_description/urdf/pr2.urdf")
    assert drive_fact(bare.world, None, "base_footprint", moves=False).spec is None


def test_the_left_arm_is_the_one_at_plus_y_of_the_root() -> None:
    pr2 = _erd("pr2_description/urdf/pr2.urdf")
    arms = [("torso_lift_link", "r_wrist_roll_link"), ("torso_lift_link", "l_wrist_roll_link")]
    right, left = arm_offsets(pr2.world, "base_footprint", arms)
    assert left == pytest.approx(-right) and left > 0.1
    assert geometric_left([right, left]) == 1
    # A robot modelled facing -y (Stretch's forward): its left is +x, not +y.
    facing = arm_offsets(pr2.world, "base_footprint", arms, (0.0, -1.0, 0.0))
    assert facing != pytest.approx([right, left])
    assert geometric_left([0.2, 0.2]) is None
