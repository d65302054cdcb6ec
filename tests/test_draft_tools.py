"""Tool frames a draft takes or proposes (issue 30): from the files first, at the real tips.

Each small layout is written here, one rule a test; real robots follow (skipped when absent).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robotspec.description.load import load_description
from robotspec.spec.draft.tips import far_end, flange_offset
from robotspec.spec.draft.tree import Tree
from tests.draft_support import draft_layout as _draft

from .conftest import erd_robots

_BOX = '<collision><origin xyz="{o}"/><geometry><box size="{s}"/></geometry></collision>'


def _link(name: str, size: str = "0.04 0.04 0.04", at: str = "0 0 0") -> str:
    return f'<link name="{name}">{_BOX.format(o=at, s=size)}</link>'


def _bare(name: str) -> str:
    return f'<link name="{name}"/>'


def _joint(
    name: str,
    parent: str,
    child: str,
    kind: str = "revolute",
    xyz: str = "0 0 0.15",
    axis: str = "0 0 1",
    extra: str = "",
) -> str:
    limit = '<limit lower="-2" upper="2" effort="1" velocity="1"/>'
    if kind == "prismatic":
        limit = '<limit lower="0" upper="0.04" effort="1" velocity="1"/>'
    moving = "" if kind == "fixed" else f'<axis xyz="{axis}"/>{limit}'
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/>{moving}{extra}</joint>'
    )


def _arm(n: int = 6) -> list[str]:
    """A base and ``n`` revolute joints in series, 15 cm apart, the last about z."""
    parts = [_link("base")]
    above = "base"
    for i in range(1, n + 1):
        axis = "0 0 1" if i % 2 == 0 or i == n else "0 1 0"
        parts += [_link(f"link{i}"), _joint(f"joint{i}", above, f"link{i}", axis=axis)]
        above = f"link{i}"
    return parts


def test_a_bare_arm_gets_a_flange_frame_at_the_far_end_of_its_last_link(
    tmp_path: Path,
) -> None:
    parts = _arm()
    # The last link reaches 6 cm out along its joint's axis (z) and 1 cm back.
    parts[-2] = _link("link6", "0.05 0.05 0.07", at="0 0 0.025")
    d = _draft(tmp_path, "bare_arm", parts)
    (tool,) = d.manipulators
    (frame,) = d.frames
    assert tool.tool_frame == frame.name and frame.parent == "link6"
    assert frame.xyz == (0.0, 0.0, 0.06)


def test_a_named_tcp_frame_is_the_tool_frame_without_a_question(tmp_path: Path) -> None:
    parts = _arm()
    parts += [_bare("tool0"), _joint("tool0_joint", "link6", "tool0", "fixed", "0 0 0.05")]
    d = _draft(tmp_path, "tool0_arm", parts)
    (tool,) = d.manipulators
    assert tool.tool_frame == "tool0"
    assert not any("tool frame" in why for why in tool.decide)
    assert not d.frames


def _gripper(finger_size: str, finger_at: str) -> list[str]:
    """An arm with a hand and two prismatic fingers hinged 2 cm out, the second mimicking."""
    parts = [*_arm(), _link("hand")]
    parts.append(_joint("hand_joint", "link6", "hand", "fixed", "0 0 0.03"))
    for side, y, axis in (("left", "0.02", "0 1 0"), ("right", "-0.02", "0 -1 0")):
        finger = f"{side}_finger"
        mimic = '<mimic joint="left_finger_joint"/>' if side == "right" else ""
        parts += [
            _link(finger, finger_size, at=finger_at),
            _joint(f"{finger}_joint", "hand", finger, "prismatic", f"0 {y} 0.02", axis, mimic),
        ]
    return parts


def test_a_frame_between_the_finger_tips_is_at_their_far_ends(tmp_path: Path) -> None:
    # Fingers 6 cm long, hinged at 2 cm: their pads end 8 cm out of the hand, not 2.
    d = _draft(tmp_path, "gripper", _gripper("0.01 0.01 0.06", "0 0 0.03"))
    (m,) = d.manipulators
    assert m.is_gripper
    (frame,) = d.frames
    assert frame.parent == "hand" and m.tool_frame == frame.name
    assert frame.xyz == (0.0, 0.0, 0.08)


def test_a_bare_frame_on_the_joint_the_fingers_mimic_is_the_tcp(tmp_path: Path) -> None:
    # NAO's shape: one motor joint turns a bare 'gripper' frame; the fingers mimic it.
    parts = [*_arm(), _link("wrist_link")]
    parts.append(_joint("wrist_roll", "link6", "wrist_link", xyz="0 0 0.05"))
    parts += [_bare("gripper"), _joint("hand_motor", "wrist_link", "gripper", xyz="0 0 0.06")]
    for i, y in enumerate(("0.02", "-0.02", "0")):
        finger = f"finger{i}"
        above = "wrist_link"
        for k in (1, 2):
            link = f"{finger}_{k}"
            xyz = f"0.0{i} {y} 0.05" if k == 1 else "0 0 0.02"
            mimic = '<mimic joint="hand_motor"/>'
            parts += [
                _link(link, "0.01 0.01 0.02"),
                _joint(f"{link}_joint", above, link, "continuous", xyz, "0 1 0", mimic),
            ]
            above = link
    d = _draft(tmp_path, "one_motor_hand", parts)
    (m,) = d.manipulators
    assert m.tool_frame == "gripper"
    assert not d.frames


# --------------------------------------------------------------------------- real robots
def test_finger_tips_far_ends_lie_past_their_joints_on_the_panda(tmp_path: Path) -> None:
    urdf = erd_robots() / "panda_description/urdf/panda.urdf"
    desc = load_description(str(urdf), meshes="keep")
    world = desc.world
    tree = Tree(world, world.root)
    finger = world.get_body_by_name("panda_leftfinger")
    hand = world.get_body_by_name("panda_hand")
    reach = tree.poses[finger.index][:3, 3] - tree.poses[hand.index][:3, 3]
    end = far_end(tree, finger, reach)
    # The Panda's finger mesh ends about 5 cm past its joint (the pads; TCP at 10.34 cm).
    past = float(np.linalg.norm(end - tree.poses[finger.index][:3, 3]))
    assert 0.04 < past < 0.06
    # Its last link's far end along joint 7's axis: the flange at about 10.7 cm (link8).
    flange = flange_offset(tree, world.get_body_by_name("panda_link7"))
    assert flange is not None and abs(flange[2]) > 0.05


def test_a_rigid_hand_gets_a_flange_the_way_its_forearm_reaches(tmp_path: Path) -> None:
    # Booster T1's shape: the elbow turns a rigid forearm-and-hand link reaching along y.
    parts = _arm(3)
    parts += [
        _link("left_hand_link", "0.04 0.2 0.04", at="0 0.1 0"),
        _joint("elbow_yaw", "link3", "left_hand_link", xyz="0 0.05 0", axis="0 0 1"),
    ]
    d = _draft(tmp_path, "rigid_hand", parts)
    (m,) = d.manipulators
    (frame,) = d.frames
    assert m.tool_frame == frame.name and frame.parent == "left_hand_link"
    assert frame.xyz == (0.0, 0.2, 0.0)


def test_a_finger_ends_at_its_bare_tip_frame_beside_a_decorative_pad(tmp_path: Path) -> None:
    # HSR-B's shape: the distal link carries a bare tip frame and a pad with a look only.
    parts = _gripper("0.01 0.01 0.04", "0 0 0.02")
    for side in ("left", "right"):
        finger = f"{side}_finger"
        pad = f'<link name="{side}_pad"><visual><geometry><sphere radius="0.005"/></geometry>'
        parts += [
            pad + "</visual></link>",
            _joint(f"{side}_pad_joint", finger, f"{side}_pad", "fixed", "0 0 0.03"),
            _bare(f"{side}_tip_frame"),
            _joint(f"{side}_tip_joint", finger, f"{side}_tip_frame", "fixed", "0 0 0.04"),
        ]
    (m,) = _draft(tmp_path, "padded", parts).manipulators
    assert m.thumb is not None and m.finger is not None
    assert {m.thumb.tip, m.finger.tip} == {"left_tip_frame", "right_tip_frame"}


def test_a_linkage_gripper_s_four_branches_are_two_sides_by_where_they_start(
    tmp_path: Path,
) -> None:
    # Robotiq's shape: an outer and an inner knuckle a side, all moved by one motor; the outer
    # finger's pad reaches farther out than the inner knuckles.
    parts = [_link("base", "0.08 0.04 0.04")]
    for side, sign in (("left", -1), ("right", 1)):
        mimic = "" if side == "left" else '<mimic joint="left_outer_joint"/>'
        lead = '<mimic joint="left_outer_joint"/>'
        parts += [
            _link(f"{side}_outer", "0.01 0.01 0.03"),
            _joint(
                f"{side}_outer_joint",
                "base",
                f"{side}_outer",
                xyz=f"0 {sign * 0.03} 0.05",
                axis="1 0 0",
                extra=mimic,
            ),  # fmt: skip
            _link(f"{side}_pad", "0.01 0.01 0.02"),
            _joint(
                f"{side}_pad_joint",
                f"{side}_outer",
                f"{side}_pad",
                "fixed",
                f"0 {-sign * 0.01} 0.09",
            ),  # fmt: skip
            _link(f"{side}_inner", "0.01 0.01 0.01"),
            _joint(
                f"{side}_inner_joint",
                "base",
                f"{side}_inner",
                xyz=f"0 {sign * 0.013} 0.06",
                axis="1 0 0",
                extra=lead,
            ),  # fmt: skip
        ]
    (m,) = _draft(tmp_path, "linkage", parts).manipulators
    assert m.is_gripper
    assert m.thumb is not None and m.finger is not None
    assert {m.thumb.tip, m.finger.tip} == {"left_pad", "right_pad"}


def test_stl_vertices_are_read_without_trimesh_as_trimesh_reads_them(tmp_path: Path) -> None:
    from robotspec.errors import RobotSpecError
    from robotspec.files.meshes import read_triangles
    from robotspec.spec.draft.tips import mesh_vertices

    ascii_stl = tmp_path / "tri.stl"
    ascii_stl.write_text(
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
        "vertex 0 2 0.5\nendloop\nendfacet\nendsolid t\n"
    )
    assert mesh_vertices(str(ascii_stl)).max(axis=0).tolist() == [1.0, 2.0, 0.5]
    bad = tmp_path / "bad.stl"
    bad.write_text("solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 nan\nendsolid t\n")
    with pytest.raises(RobotSpecError, match="finite"):
        mesh_vertices(str(bad))
    meshes = erd_robots() / "g1_description" / "meshes"
    for stl in sorted(meshes.glob("*.STL"))[:5]:  # binary STL files
        mine, theirs = mesh_vertices(str(stl)), read_triangles(str(stl))[0]
        assert np.allclose(mine.min(axis=0), theirs.min(axis=0))
        assert np.allclose(mine.max(axis=0), theirs.max(axis=0))


def test_a_bare_frame_between_the_finger_tips_is_the_tcp_whatever_its_name(
    tmp_path: Path,
) -> None:
    # A frame named as nothing known ('pinch_point') on the hand's axis, just past the pads;
    # a camera mount beside the hand is off that axis and no tool frame.
    parts = _gripper("0.01 0.01 0.06", "0 0 0.03")
    parts += [_bare("pinch_point"), _joint("pinch", "hand", "pinch_point", "fixed", "0 0 0.09")]
    parts += [_bare("mount"), _joint("mount_joint", "hand", "mount", "fixed", "0.05 0 0.02")]
    d = _draft(tmp_path, "pinch", parts)
    (m,) = d.manipulators
    assert m.tool_frame == "pinch_point" and not d.frames
