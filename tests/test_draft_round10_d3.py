"""Marks and questions where the files state only part of an item (issue 30, round 10).

Small layouts built here, one shape each (no robot's files, no robot's name): a TCP a name
states but at the hand's mount, a link drawn with a camera's mesh, a compound camera name, an
SRDF group whose name and the tree disagree on the limb's kind, a differential base rolling
along y.
"""

from __future__ import annotations

from pathlib import Path

from robotspec.spec.draft.confidence import (
    CAMERA_GAZEBO,
    CHAIN_SRDF,
    GRIPPER_MIMIC,
    TOOL_ON_HAND,
    TOOL_SRDF,
)
from robotspec.spec.draft.unassigned import SENSORS
from tests.test_draft_blind import _WHEEL, _draft, _draft_srdf, _joint, _link
from tests.test_draft_marks_whole import _gripper


def _tcp_at(xyz: str) -> list[str]:
    """The 6-joint arm and mimic-coupled gripper of ``_gripper``, its TCP frame at ``xyz``."""
    return [
        p.replace('<origin xyz="0 0 0.1" rpy="0 0 0"/>', f'<origin xyz="{xyz}" rpy="0 0 0"/>')
        for p in _gripper(pad=False)
    ]


def test_a_tcp_out_between_the_tips_is_stated(tmp_path: Path) -> None:
    (m,) = _draft(tmp_path, "arm", _tcp_at("0 0 0.1")).manipulators
    assert (m.tool_frame, m.decide, m.stated) == ("tool0", [], (TOOL_ON_HAND, GRIPPER_MIMIC))


def test_a_tcp_at_the_hands_mount_keeps_the_mark(tmp_path: Path) -> None:
    # Named as a TCP and on the hand, but where the gripper is bolted on, not out between the
    # jaws' far ends (a flange frame): the name states a frame, not the point the jaws close on.
    (m,) = _draft(tmp_path, "arm", _tcp_at("0 0 0.005")).manipulators
    assert m.tool_frame == "tool0" and m.stated == ()
    assert m.decide == ["the tool frame 'tool0' lies at the hand's mount, short of its tips"]


def _camera_mount(name: str, mesh: str | None) -> list[str]:
    """A 4-joint arm on a base carrying a shaped, fixed link ``name`` (drawn with ``mesh``)."""
    geometry = (
        None if mesh is None else f'<visual><geometry><mesh filename="{mesh}"/></geometry></visual>'
    )
    parts = [_link("base", size=0.1)]
    above = "base"
    for i in range(1, 5):
        parts += [_link(f"link{i}", size=0.04), _joint(f"j{i}", above, f"link{i}", xyz="0 0 0.2")]
        above = f"link{i}"
    parts += [_link(name, geometry), _joint(f"{name}_mount", "base", name, "fixed", "0.1 0 0.3")]
    return parts


def _sensor_questions(tmp_path: Path, parts: list[str]) -> list[str]:
    d = _draft(tmp_path, "arm", parts)
    assert not d.cameras
    return [q.text for q in d.questions if q.section == SENSORS]


def test_a_link_drawn_with_a_cameras_mesh_is_asked_about(tmp_path: Path) -> None:
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "d405.stl").write_text("solid d405\nendsolid d405\n")
    parts = _camera_mount("sensor_mount", "meshes/d405.stl")
    assert _sensor_questions(tmp_path, parts) == [
        "sensor_mount (a link whose mesh 'd405.stl' is named as a camera) is no drafted "
        "camera: a camera? which frame?"
    ]


def test_a_plain_mesh_asks_nothing(tmp_path: Path) -> None:
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "bracket.stl").write_text("solid b\nendsolid b\n")
    assert _sensor_questions(tmp_path, _camera_mount("sensor_mount", "meshes/bracket.stl")) == []


def test_a_compound_camera_name_is_asked_about(tmp_path: Path) -> None:
    # 'handeye' glues two words; the name still closes on a camera's word: the drafter takes
    # it for a camera (sensors.camera_words), and the camera carries the question.
    d = _draft(tmp_path, "arm", _camera_mount("handeye", None))
    assert [c.body for c in d.cameras] == ["handeye"] and d.cameras[0].decide


def _limb_srdf(group: str) -> str:
    """A group of the arm's chain and an end effector (a tool plate) hanging on it."""
    return (
        f'<group name="{group}"><chain base_link="base" tip_link="link4"/></group>'
        '<group name="tool"><link name="plate"/></group>'
        f'<end_effector name="tip" parent_link="link4" group="tool" parent_group="{group}"/>'
    )


def _plated() -> list[str]:
    return [
        *_camera_mount("mount", None),
        _link("plate"),
        _joint("plate_j", "link4", "plate", "fixed"),
    ]


def test_an_srdf_group_the_tree_confirms_is_stated(tmp_path: Path) -> None:
    (c,) = _draft_srdf(tmp_path, "arm", _plated(), _limb_srdf("arm")).chains
    assert (c.role, c.stated, c.decide) == ("arm", CHAIN_SRDF, [])


def test_an_srdf_group_named_as_a_leg_the_tree_finds_an_arm_keeps_the_mark(
    tmp_path: Path,
) -> None:
    (c,) = _draft_srdf(tmp_path, "arm", _plated(), _limb_srdf("front_leg")).chains
    assert c.role == "arm" and c.stated is None
    assert c.decide == ["the SRDF group 'front_leg' is named as a leg; the tree finds an arm"]


def _cart(axis: str) -> list[str]:
    """A chassis on two continuous wheels turning about ``axis``, 0.3 m apart across it."""
    sign = {"0 1 0": ("0 {} 0", "0 {} 0"), "1 0 0": ("{} 0 0", "{} 0 0")}[axis]
    wheel = _WHEEL if axis == "0 1 0" else _WHEEL.replace('rpy="1.5708 0 0"', 'rpy="0 1.5708 0"')
    return [
        _link("chassis", size=0.3),
        _link("wheel_a", wheel),
        _joint("wheel_a_joint", "chassis", "wheel_a", "continuous", sign[0].format(0.15), axis),
        _link("wheel_b", wheel),
        _joint("wheel_b_joint", "chassis", "wheel_b", "continuous", sign[1].format(-0.15), axis),
    ]


def test_a_differential_base_rolling_along_x_faces_x_unasked(tmp_path: Path) -> None:
    d = _draft(tmp_path, "cart", _cart("0 1 0"))
    assert d.drive is not None and d.drive.type == "differential"
    assert d.forward_decide is None


def test_a_differential_base_whose_wheels_turn_about_x_asks_its_facing(tmp_path: Path) -> None:
    d = _draft(tmp_path, "cart", _cart("1 0 0"))
    assert d.drive is not None and d.drive.type == "differential"
    assert d.forward == (1.0, 0.0, 0.0)
    assert d.forward_decide == "its wheels turn about x: it drives along y, not x?"


def _two_arms(extra: bool) -> list[str]:
    """A trunk and two mirrored 4-joint arms held out level; the left one has a fifth joint."""
    parts = [_link("trunk", size=0.3)]
    for side, y in (("left", 0.3), ("right", -0.3)):
        above = "trunk"
        count = 5 if extra and side == "left" else 4
        for i in range(1, count + 1):
            xyz = f"0 {y} 0.5" if i == 1 else f"0 {y / 1.5} 0"
            axis = "0 1 0" if i % 2 else "1 0 0"
            child = f"{side}_link{i}"
            parts += [
                _link(child, size=0.04),
                _joint(f"{side}_j{i}", above, child, xyz=xyz, axis=axis),
            ]
            above = child
    return parts


def test_limbs_alike_ask_nothing(tmp_path: Path) -> None:
    d = _draft(tmp_path, "pair", _two_arms(extra=False))
    assert [c.role for c in d.chains] == ["arm", "arm"]
    assert d.questions == []


def test_an_arm_longer_than_its_mirror_asks_what_its_extra_joint_carries(tmp_path: Path) -> None:
    d = _draft(tmp_path, "pair", _two_arms(extra=True))
    assert sorted(len(c.joints) for c in d.chains) == [4, 5]
    (q,) = d.questions
    assert q.joints == frozenset(f"left_j{i}" for i in range(1, 6))
    assert q.links == frozenset({"left_link5"})
    assert q.text.endswith(
        "a part more at its end (left_j5: an arm on the arm? a hand's joint?) or at its start "
        "(a torso's joint)?"
    )


def test_a_joint_driven_beside_mimic_coupled_fingers_keeps_the_mark(tmp_path: Path) -> None:
    # The mimic tag couples two fingers; beside them a joint driven on its own (a shapeless
    # third branch the tree does not take for a finger): the tag does not describe the hand.
    third = ['<link name="third"/>', _joint("third_q", "gripper_base", "third", axis="1 0 0")]
    (m,) = _draft(tmp_path, "arm", [*_gripper(pad=False), *third]).manipulators
    assert m.is_gripper and m.stated == ()
    assert m.decide == ["'third_q' moves beside the two fingers: a third finger, a hand?"]


def _quadruped_turned(turned: bool) -> list[str]:
    """``_quadruped``'s four legs, their hips at (x, y) or, ``turned``, at (y, x): long along y."""
    from tests.test_draft_first_sight7_d1 import _quadruped

    parts = _quadruped(0.25)
    if not turned:
        return parts
    swap = {"0.2 0.1 0": "0.1 0.2 0", "0.2 -0.1 0": "-0.1 0.2 0"}
    swap |= {"-0.2 0.1 0": "0.1 -0.2 0", "-0.2 -0.1 0": "-0.1 -0.2 0"}
    out = []
    for p in parts:
        for old, new in swap.items():
            p = p.replace(f'xyz="{old}"', f'xyz="{new}"')
        out.append(p)
    return out


def test_four_legs_long_along_x_face_x_unasked(tmp_path: Path) -> None:
    d = _draft(tmp_path, "dog", _quadruped_turned(turned=False))
    assert [c.role for c in d.chains] == ["leg"] * 4
    assert d.forward_decide is None


def test_four_legs_long_along_y_ask_the_facing(tmp_path: Path) -> None:
    d = _draft(tmp_path, "dog", _quadruped_turned(turned=True))
    assert [c.role for c in d.chains] == ["leg"] * 4
    assert d.forward == (1.0, 0.0, 0.0)
    assert d.forward_decide == (
        "its four legs stand farther apart along y than x: it faces +y or -y?"
    )


def _pitched_camera(pitch: float) -> list[str]:
    """``_camera``'s body and optical frame, its sensor pitched by ``pitch``, the frame named.

    The sensor's plugin publishes in the optical frame (``frameName``): the draft takes it.
    """
    from tests.test_draft_marks_whole import _camera

    head = '<sensor name="cam_sensor" type="camera">'
    named = (
        '<plugin name="p" filename="libgazebo_ros_camera.so">'
        "<frameName>cam_optical</frameName></plugin></sensor>"
    )
    return [
        p.replace(head, f"{head}<pose>0 0 0 0 {pitch} 0</pose>").replace("</sensor>", named)
        for p in _camera([("cam_optical", "0 0 0")])
    ]


def test_a_frame_looking_the_sensors_way_is_stated(tmp_path: Path) -> None:
    (cam,) = _draft(tmp_path, "cam", _pitched_camera(0.1)).cameras
    assert (cam.body, cam.decide, cam.stated) == ("cam_optical", [], CAMERA_GAZEBO)


def test_a_frame_looking_away_from_its_sensor_keeps_the_mark(tmp_path: Path) -> None:
    # The sensor looks straight down; the optical frame its plugin names looks ahead.
    (cam,) = _draft(tmp_path, "cam", _pitched_camera(1.5708)).cameras
    assert cam.body == "cam_optical" and cam.stated is None
    assert cam.decide == [
        "'cam_optical' looks another way than its Gazebo sensor: which frame is the camera?"
    ]


def test_a_camera_files_own_root_is_asked_about_when_no_camera_is_drafted(
    tmp_path: Path,
) -> None:
    # A camera's own URDF, rooted at the camera, a mounting plate below it: the drafter takes
    # no root for a camera, so a question says what nothing drafted does.
    parts = [
        _link("camera_link", size=0.05),
        _link("mount_plate", size=0.1),
        _joint("mount", "camera_link", "mount_plate", "fixed", xyz="0 0 -0.05"),
    ]
    d = _draft(tmp_path, "cam", parts)
    assert not d.cameras
    assert [q.text for q in d.questions] == [
        "camera_link (a frame named as a camera) is no drafted camera: a camera? which frame?"
    ]


def test_a_urdf_declaring_xml_version_0_0_is_drafted_valid_as_written(tmp_path: Path) -> None:
    # Some exporters write '<?xml version="0.0" ?>'; libxml2 refuses the version, urdfdom
    # and pybullet read the file: so does robotspec, as version 1.0.
    from robotspec.compiler import check_spec
    from robotspec.spec.draft import render_draft
    from robotspec.spec.draft.run import draft_from_files

    urdf = tmp_path / "ball.urdf"
    body = "".join(_camera_mount("plate", None))
    urdf.write_text(f'<?xml version="0.0" ?>\n<robot name="ball">{body}</robot>')
    draft, _ = draft_from_files(str(urdf), None, folder=tmp_path, base_folder=tmp_path)
    spec = tmp_path / "ball.yaml"
    spec.write_text(render_draft(draft))
    assert check_spec(spec).robot is not None
    assert [c.role for c in draft.chains] == ["arm"]


def _cupped(cup_out: str) -> list[str]:
    """The arm of ``_camera_mount`` with a bare 'tool0' at its flange and a cup fixed past it."""
    return [
        *_camera_mount("mount", None),
        '<link name="tool0"/>',
        _joint("tool0_j", "link4", "tool0", "fixed", xyz="0 0 0.02"),
        _link("cup", size=0.03),
        _joint("cup_j", "link4", "cup", "fixed", xyz=f"0 0 {cup_out}"),
    ]


_CUP_SRDF = (
    '<group name="arm"><chain base_link="base" tip_link="link4"/></group>'
    '<group name="tool"><link name="cup"/></group>'
    '<end_effector name="cup_tool" parent_link="tool0" group="tool" parent_group="arm"/>'
)


def test_an_srdf_tcp_past_which_nothing_reaches_is_stated(tmp_path: Path) -> None:
    (m,) = _draft_srdf(tmp_path, "arm", _cupped("0.02"), _CUP_SRDF).manipulators
    assert m.tool_frame == "tool0" and m.stated == (TOOL_SRDF,)
    assert not any("reaches past" in why for why in m.decide)


def test_a_shape_reaching_past_an_srdf_tcp_keeps_the_mark(tmp_path: Path) -> None:
    # The end effector's parent link is a bare frame at the flange; a cup is fixed 12 cm out.
    (m,) = _draft_srdf(tmp_path, "arm", _cupped("0.12"), _CUP_SRDF).manipulators
    assert m.tool_frame == "tool0" and m.stated == ()
    assert "'cup' reaches past the tool frame: a tool bolted on, whose TCP?" in m.decide
