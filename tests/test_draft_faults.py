"""Drafts an expert would sign: each fault the issue found, on a small URDF of its own shape.

Each test writes a URDF of the robot's shape (names as the real robot's files have them), drafts
it as ``robotspec init`` does, checks the draft validates as written, and checks the decision
that was wrong: an arm ending one joint early (Interbotix), a motor horn taken for a finger, an
arm of base and pan/tilt joints (LoCoBot), legs swapped on a robot facing -y (ARMAR-4), arms
stopping at the elbow and a head not drafted (GR1T2), a hand or gripper alone drafted as nothing,
jaws one below the other (WSG-50), a camera on its body link beside its optical frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import yaml

from robotspec.compiler import check_spec
from robotspec.spec.draft import Draft, render_draft
from robotspec.spec.draft.render import camera_presets
from robotspec.spec.draft.run import draft_from_files

BOX = '<visual><geometry><box size="0.03 0.03 0.03"/></geometry></visual>'
OPTICAL_RPY = "-1.5707963 0 -1.5707963"


@dataclass(frozen=True)
class J:
    """One joint of a fixture URDF (its child link gets geometry unless ``bare``)."""

    name: str
    kind: str
    parent: str
    child: str
    xyz: str = "0 0 0.1"
    axis: str = "0 0 1"
    rpy: str = "0 0 0"
    mimic: str | None = None
    bare: bool = False
    lower: float = -1.5
    upper: float = 1.5


def _urdf(name: str, root: str, joints: list[J], bare_root: bool = False) -> str:
    links = [f'<link name="{root}">{"" if bare_root else BOX}</link>']
    body = []
    for j in joints:
        links.append(f'<link name="{j.child}">{"" if j.bare else BOX}</link>')
        limit = (
            f'<limit lower="{j.lower}" upper="{j.upper}" velocity="1" effort="1"/>'
            if j.kind in ("revolute", "prismatic")
            else '<limit velocity="1" effort="1"/>'
            if j.kind == "continuous"
            else ""
        )
        mimic = f'<mimic joint="{j.mimic}"/>' if j.mimic else ""
        axis = f'<axis xyz="{j.axis}"/>' if j.kind != "fixed" else ""
        body.append(
            f'<joint name="{j.name}" type="{j.kind}"><parent link="{j.parent}"/>'
            f'<child link="{j.child}"/><origin xyz="{j.xyz}" rpy="{j.rpy}"/>'
            f"{axis}{limit}{mimic}</joint>"
        )
    return f'<robot name="{name}">' + "".join(links) + "".join(body) + "</robot>"


def _draft(tmp_path: Path, text: str) -> tuple[Draft, str]:
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(text)
    draft, _ = draft_from_files(str(urdf), None, folder=tmp_path)
    out = render_draft(draft, presets=camera_presets())
    spec = tmp_path / "draft.yaml"
    spec.write_text(out)
    assert check_spec(spec).robot is not None, out  # valid as written
    return draft, out


def _line(text: str, start: str) -> str:
    return next(li for li in text.splitlines() if li.lstrip().startswith(start))


# ------------------------------------------------------------- arms to the wrist, grippers

WX250S = [
    J("waist", "revolute", "base_link", "shoulder_link", "0 0 0.07"),
    J("shoulder", "revolute", "shoulder_link", "upper_arm_link", "0 0 0.04", "0 1 0"),
    J("elbow", "revolute", "upper_arm_link", "forearm_link", "0.05 0 0.25", "0 1 0"),
    J("wrist_angle", "revolute", "forearm_link", "wrist_link", "0.25 0 0", "0 1 0"),
    J("wrist_rotate", "revolute", "wrist_link", "gripper_link", "0.065 0 0", "1 0 0"),
    J("ee_arm", "fixed", "gripper_link", "ee_arm_link", "0.043 0 0", bare=True),
    # The gripper motor's horn: a revolute branch with geometry beside the finger carriage.
    J("gripper", "revolute", "ee_arm_link", "gripper_prop_link", "0.005 0 0", "1 0 0"),
    J("gripper_bar", "fixed", "ee_arm_link", "gripper_bar_link", "0 0 0"),
    J("ee_bar", "fixed", "gripper_bar_link", "fingers_link", "0.023 0 0", bare=True),
    J(
        "left_finger",
        "prismatic",
        "fingers_link",
        "left_finger_link",
        "0 0 0",
        "0 1 0",
        lower=0.015,
        upper=0.037,
    ),
    J(
        "right_finger",
        "prismatic",
        "fingers_link",
        "right_finger_link",
        "0 0 0",
        "0 -1 0",
        mimic="left_finger",
        lower=0.015,
        upper=0.037,
    ),
    J("ee_gripper", "fixed", "fingers_link", "ee_gripper_link", "0.028 0 0", bare=True),
]


def test_interbotix_arm_reaches_the_wrist_and_the_horn_is_no_finger(tmp_path: Path) -> None:
    # The fault: the arm ended at wrist_link (the joint turning 'gripper_link' was left out),
    # the horn was drafted as a finger and the flange 'ee_arm_link' as the tool frame.
    d, _ = _draft(tmp_path, _urdf("wx250s", "base_link", WX250S))
    (arm,) = d.chains
    assert (arm.root, arm.tip) == ("base_link", "gripper_link")
    assert arm.joints == {"waist", "shoulder", "elbow", "wrist_angle", "wrist_rotate"}
    (hand,) = d.manipulators
    assert hand.is_gripper and arm.manipulator == hand.name
    assert hand.thumb is not None and hand.finger is not None
    assert {hand.thumb.tip, hand.finger.tip} == {"left_finger_link", "right_finger_link"}
    assert hand.thumb.tip == "left_finger_link"  # the driven one; its mimic is the finger
    assert hand.tool_frame == "ee_gripper_link"


def test_wrists_named_after_the_hand_stay_in_the_arm(tmp_path: Path) -> None:
    # GR1T2: links 'l_hand_yaw', 'l_hand_roll', 'l_hand_pitch' are the wrist; the arm stopped
    # at the elbow (4 of 7 joints). Its 3-joint head has no camera frame: drafted as a chain.
    names = ["shoulder_pitch", "shoulder_roll", "shoulder_yaw", "elbow_pitch"]
    names += ["hand_yaw", "hand_roll", "hand_pitch"]
    joints = [J("waist_yaw", "revolute", "base", "waist_yaw_link", "0 0 0.9")]
    for side, y in (("l", 0.15), ("r", -0.15)):
        parent = "waist_yaw_link"
        for i, n in enumerate(names):
            child = f"{side}_{n}"
            xyz = f"0 {y} 0.3" if i == 0 else "0 0 -0.12"
            joints.append(J(f"{side}_{n}_joint", "revolute", parent, child, xyz, "0 1 0"))
            parent = child
        for f in ("thumb", "index"):
            joints.append(
                J(f"{side}_{f}_joint", "revolute", parent, f"{side}_{f}_link", "0 0.01 -0.05")
            )
    parent = "waist_yaw_link"
    for n, axis in (("head_yaw", "0 0 1"), ("head_roll", "1 0 0"), ("head_pitch", "0 1 0")):
        joints.append(J(f"{n}_joint", "revolute", parent, f"{n}_link", "0 0 0.4", axis))
        parent = f"{n}_link"
    d, text = _draft(tmp_path, _urdf("gr1t2", "base", joints))
    arms = {c.name: c for c in d.chains if c.role == "arm"}
    assert set(arms) == {"left_arm", "right_arm"}
    assert arms["left_arm"].joints == {f"l_{n}_joint" for n in names}
    assert arms["left_arm"].tip == "l_hand_pitch"
    head = next(c for c in d.chains if c.name == "head")
    assert head.role == "chain" and head.joints == {
        "head_yaw_joint",
        "head_roll_joint",
        "head_pitch_joint",
    }
    assert "DECIDE" in _line(text, "head:")


def test_jaws_one_below_the_other_are_a_parallel_gripper(tmp_path: Path) -> None:
    # A WSG-50: the second jaw hangs on the first (it moves twice as far, the other way).
    joints = [
        J("arm_1", "revolute", "base_link", "arm_1_link", "0 0 0.1"),
        J("arm_2", "revolute", "arm_1_link", "arm_2_link", "0 0 0.3", "0 1 0"),
        J("arm_3", "revolute", "arm_2_link", "arm_3_link", "0 0 0.3", "0 1 0"),
        J("mount", "fixed", "arm_3_link", "wsg_50_gripper_base_link", "0 0 0.1"),
        J(
            "wsg_50_base_joint_gripper_left",
            "prismatic",
            "wsg_50_gripper_base_link",
            "wsg_50_gripper_left",
            "0 -0.05 0.07",
            "0 1 0",
            lower=0.0,
            upper=0.055,
        ),
        J(
            "wsg_50_base_joint_gripper_right",
            "prismatic",
            "wsg_50_gripper_left",
            "wsg_50_gripper_right",
            "0 0.1 0",
            "0 -1 0",
            mimic="wsg_50_base_joint_gripper_left",
            lower=0.0,
            upper=0.055,
        ),
        J("tcp", "fixed", "wsg_50_gripper_base_link", "wsg_50_tcp", "0 0 0.15", bare=True),
    ]
    d, _ = _draft(tmp_path, _urdf("wsg", "base_link", joints))
    (hand,) = d.manipulators
    assert hand.is_gripper, hand
    assert hand.thumb is not None and hand.finger is not None
    assert (hand.thumb.root, hand.thumb.tip) == ("wsg_50_gripper_base_link", "wsg_50_gripper_left")
    assert (hand.finger.root, hand.finger.tip) == ("wsg_50_gripper_left", "wsg_50_gripper_right")
    assert hand.tool_frame == "wsg_50_tcp"


# ------------------------------------------------------------------ hands and grippers alone


def test_a_gripper_alone_is_drafted_as_one(tmp_path: Path) -> None:
    # The fault: "no arm or leg found", nothing drafted. Now: the gripper, rooted at its base,
    # its fingers, a tool frame between them; on no chain, which the draft accepts with why.
    joints = [
        J(
            "finger_joint1",
            "prismatic",
            "hand",
            "leftfinger",
            "0 0 0.058",
            "0 1 0",
            lower=0.0,
            upper=0.04,
        ),
        J(
            "finger_joint2",
            "prismatic",
            "hand",
            "rightfinger",
            "0 0 0.058",
            "0 -1 0",
            mimic="finger_joint1",
            lower=0.0,
            upper=0.04,
        ),
    ]
    d, text = _draft(tmp_path, _urdf("gripper", "hand", joints))
    assert d.chains == [] and d.lone_hand is not None
    (hand,) = d.manipulators
    assert hand.is_gripper and hand.root == "hand"
    assert hand.thumb is not None and hand.thumb.tip == "leftfinger"
    (frame,) = d.frames
    assert hand.tool_frame == frame.name and frame.parent == "hand"
    assert "DECIDE" in _line(text, f"{hand.name}:")
    data = yaml.safe_load(text)
    assert data["accept_warnings"][0]["at"] == f"manipulators.{hand.name}"


def test_a_hand_of_fingers_alone_is_drafted_as_one(tmp_path: Path) -> None:
    joints = []
    for i, y in enumerate((0.03, 0.0, -0.03)):
        parent = "palm_link"
        for k in range(3):
            child = f"finger_{i}_link_{k}"
            xyz = f"0 {y} 0.08" if k == 0 else "0 0 0.04"
            joints.append(J(f"finger_{i}_joint_{k}", "revolute", parent, child, xyz, "0 1 0"))
            parent = child
    joints.append(J("thumb_joint_0", "revolute", "palm_link", "thumb_link_0", "0.03 0 0.03"))
    joints.append(J("thumb_joint_1", "revolute", "thumb_link_0", "thumb_link_1", "0.03 0 0"))
    d, text = _draft(tmp_path, _urdf("hand", "palm_link", joints))
    (hand,) = d.manipulators
    assert hand.is_hand and hand.root == "palm_link" and "type: hand" in text
    assert hand.thumb is not None and hand.thumb.tip == "thumb_link_1"  # by its name
    assert len(hand.fingers) == 3
    assert d.frames and d.frames[0].parent == "palm_link" and hand.tool_frame == d.frames[0].name
    assert d.frames[0].xyz[2] > 0.1  # out among the finger tips


# ----------------------------------------------------- bases, necks, sides, cameras


def _locobot() -> list[J]:
    joints = [
        J(
            "odom_x",
            "prismatic",
            "odom",
            "x_link",
            "0 0 0",
            "1 0 0",
            bare=True,
            lower=-50,
            upper=50,
        ),
        J(
            "odom_y",
            "prismatic",
            "x_link",
            "y_link",
            "0 0 0",
            "0 1 0",
            bare=True,
            lower=-50,
            upper=50,
        ),
        J("odom_theta", "continuous", "y_link", "base_link", "0 0 0"),
        J("wheel_left_joint", "continuous", "base_link", "wheel_left_link", "0 0.12 0.03", "0 1 0"),
        J(
            "wheel_right_joint",
            "continuous",
            "base_link",
            "wheel_right_link",
            "0 -0.12 0.03",
            "0 1 0",
        ),
        J("pan", "revolute", "base_link", "cam_pan_link", "0.05 0 0.5"),
        J("tilt", "revolute", "cam_pan_link", "cam_tilt_link", "0 0 0.05", "0 1 0"),
        J("camera_joint", "fixed", "cam_tilt_link", "camera_link", "0.05 0 0"),
        J(
            "camera_color_optical_joint",
            "fixed",
            "camera_link",
            "camera_color_optical_frame",
            "0 0 0",
            rpy=OPTICAL_RPY,
            bare=True,
        ),
        J(
            "camera_depth_optical_joint",
            "fixed",
            "camera_link",
            "camera_depth_optical_frame",
            "0 0.02 0",
            rpy=OPTICAL_RPY,
            bare=True,
        ),
    ]
    return joints + [
        J(
            j.name,
            j.kind,
            "base_link" if j.parent == "base_link" else j.parent,
            j.child,
            j.xyz,
            j.axis,
            mimic=j.mimic,
            bare=j.bare,
            lower=j.lower,
            upper=j.upper,
        )
        for j in WX250S
    ]


def test_a_base_of_x_y_theta_joints_is_the_drive_and_the_pan_tilt_a_neck(tmp_path: Path) -> None:
    # LoCoBot: the fault drafted a 5-joint "arm" of the base's x, y, theta and the pan/tilt
    # joints, with a manipulator on the tilt link, and a neck holding the base's rotation.
    d, text = _draft(tmp_path, _urdf("locobot", "odom", _locobot(), bare_root=True))
    assert d.drive is not None and d.drive.joints == ("odom_x", "odom_y", "odom_theta")
    assert d.drive.type == "differential"
    assert d.root == "base_link"
    assert "DECIDE" in _line(text, "drive:")
    (arm,) = d.chains
    assert arm.joints == {"waist", "shoulder", "elbow", "wrist_angle", "wrist_rotate"}
    assert d.neck is not None and d.neck.joints == {"pan", "tilt"}
    # One camera, on its colour optical frame (not on camera_link, not twice).
    assert [c.body for c in d.cameras] == ["camera_color_optical_frame"]
    assert d.neck.sensors == [d.cameras[0].name]
    assert all(m.root not in ("cam_tilt_link", "cam_pan_link") for m in d.manipulators)


def test_sides_follow_a_robot_facing_minus_y(tmp_path: Path) -> None:
    # ARMAR-4 is modelled facing -y: its left leg lies at +x. The fault swapped the legs.
    joints = []
    for side, x in (("L", 0.1), ("R", -0.1)):
        parent = "Pelvis"
        for i, (n, axis) in enumerate((("Hip1", "1 0 0"), ("Hip2", "0 1 0"), ("Knee", "1 0 0"))):
            child = f"Leg{side}_{n}_link"
            xyz = f"{x} 0 -0.05" if i == 0 else "0 0 -0.35"
            joints.append(J(f"Leg{side}_{n}", "revolute", parent, child, xyz, axis))
            parent = child
        joints.append(J(f"Leg{side}_Ankle", "fixed", parent, f"Leg{side}_Foot", "0 -0.05 -0.35"))
    d, text = _draft(tmp_path, _urdf("armar4", "Pelvis", joints))
    assert d.forward == (0.0, -1.0, 0.0)
    assert "DECIDE" in _line(text, "forward:")
    legs = {c.name: c for c in d.chains}
    assert set(legs) == {"left_leg", "right_leg"}
    assert legs["left_leg"].tip.startswith("LegL")
    assert all(c.role == "leg" for c in d.chains)


def test_the_field_of_view_hint_is_followed_by_replacing_the_line(tmp_path: Path) -> None:
    # The fault: the hint suggested a preset name under field_of_view:, an invalid line. Done as
    # the hint says (the line replaced by 'preset: NAME'), the spec validates.
    d, text = _draft(tmp_path, _urdf("locobot", "odom", _locobot(), bare_root=True))
    line = _line(text, "field_of_view:")
    assert "replace this line with 'preset: NAME'" in line and "DECIDE" in line
    indent = line[: len(line) - len(line.lstrip())]
    followed = text.replace(line, f"{indent}preset: {camera_presets()[0]}")
    spec = tmp_path / "followed.yaml"
    spec.write_text(followed)
    assert check_spec(spec).robot is not None


def test_an_end_effector_whose_group_is_the_arm_is_that_arms_hand(tmp_path: Path) -> None:
    # Alex's SRDF: end effector 'left_arm_end_effector' has the arm's own group and a parent link
    # the URDF lacks; it was hung on the spine (then made the torso), leaving it on no chain and
    # the gripper drafted twice.
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(_urdf("wx250s", "base_link", WX250S))
    srdf = tmp_path / "robot.srdf"
    srdf.write_text(
        '<robot name="wx250s"><group name="arm"><chain base_link="base_link"'
        ' tip_link="gripper_link"/></group>'
        '<end_effector name="arm_end_effector" parent_link="gripper" group="arm"/></robot>'
    )
    draft, _ = draft_from_files(str(urdf), str(srdf), folder=tmp_path)
    spec = tmp_path / "draft.yaml"
    spec.write_text(render_draft(draft))
    assert check_spec(spec).robot is not None
    (arm,) = draft.chains
    (hand,) = draft.manipulators
    assert arm.manipulator == hand.name == "arm_end_effector"
    assert hand.is_gripper and hand.tool_frame == "ee_gripper_link"


def test_a_camera_named_by_its_model_is_a_camera(tmp_path: Path) -> None:
    # G1's head RealSense is 'd435_link': its words split into 'd' and '435'.
    joints = [
        J("j1", "revolute", "base_link", "link_1", "0 0 0.1"),
        J("d435_joint", "fixed", "base_link", "d435_link", "0.1 0 0.5"),
    ]
    d, text = _draft(tmp_path, _urdf("robot", "base_link", joints))
    assert [(c.body, c.optical) for c in d.cameras] == [("d435_link", False)]
    # Its model names a shipped preset: drafted, marked DECIDE on the camera's line.
    assert d.cameras[0].preset == "realsense_d435" and "preset: realsense_d435" in text
    assert "DECIDE" in _line(text, f"{d.cameras[0].name}:")


def test_a_robot_whose_head_camera_looks_along_minus_y_faces_minus_y(tmp_path: Path) -> None:
    # Stretch-like: no limb names a side, but the head's optical frame looks along -y; the arm
    # at +x is then the left one (up x forward).
    joints = [
        J("mast_joint", "fixed", "base_link", "mast_link", "0 0 1.0", rpy="0 0 -1.5707963"),
        J("camera_optical_joint", "fixed", "mast_link", "camera_optical_frame", "0.05 0 0.3",
          rpy=OPTICAL_RPY, bare=True),
    ]  # fmt: skip
    for tag, x in (("a", 0.2), ("b", -0.2)):
        parent = "base_link"
        for i in range(3):
            child = f"arm_{tag}_link_{i}"
            xyz = f"{x} 0 0.8" if i == 0 else f"{x} 0 0"
            joints.append(J(f"arm_{tag}_joint_{i}", "revolute", parent, child, xyz, "0 1 0"))
            parent = child
    d, text = _draft(tmp_path, _urdf("stretchy", "base_link", joints))
    assert d.forward == (0.0, -1.0, 0.0)
    assert "DECIDE" in _line(text, "forward:")
    arms = {c.name: c.tip for c in d.chains}
    assert arms == {"left_arm": "arm_a_link_2", "right_arm": "arm_b_link_2"}


def test_a_camera_link_rigid_with_an_optical_frame_is_that_cameras_body(tmp_path: Path) -> None:
    # Go1's 'camera_laserscan_link_left' beside 'camera_optical_left': one camera, the optical.
    joints = [
        J("j1", "revolute", "base_link", "head", "0 0 0.3"),
        J("a", "fixed", "head", "camera_optical_left", "0.1 0 0", rpy=OPTICAL_RPY, bare=True),
        J("b", "fixed", "head", "camera_laserscan_link_left", "0.1 0 0.01", bare=True),
    ]
    d, _ = _draft(tmp_path, _urdf("robot", "base_link", joints))
    assert [(c.body, c.optical) for c in d.cameras] == [("camera_optical_left", True)]


def test_a_turned_camera_frame_looking_ahead_along_z_looks_along_z(tmp_path: Path) -> None:
    # Baxter's 'head_camera_link': not REP 103's rotation, but its z axis points ahead.
    joints = [
        J("head_pan", "revolute", "base_link", "head", "0 0 0.6"),
        J("cam", "fixed", "head", "head_camera_link", "0.1 0 0.05", rpy="0 1.5707963 0"),
    ]
    d, text = _draft(tmp_path, _urdf("robot", "base_link", joints))
    (cam,) = d.cameras
    assert cam.body == "head_camera_link" and cam.looks_along_z and not cam.optical
    assert "forward_facing_axis: [0, 0, 1]" in text


def test_a_link_turned_like_an_optical_frame_is_no_camera_and_a_bare_gripper_frame_a_tcp(
    tmp_path: Path,
) -> None:
    # iCub (reduced): 'neck_2' happens to be turned as REP 103's optical frames are, and
    # carries the head: not a camera. Its hands' TCP is the bare frame 'l_gripper'.
    joints = [
        J("neck_fixed", "fixed", "chest", "neck_2", "0 0 0.2", rpy=OPTICAL_RPY),
        J("head_fixed", "fixed", "neck_2", "head", "0 0.05 0"),
        J("l_shoulder", "revolute", "chest", "l_shoulder_1", "0 0.1 0.15", "0 1 0"),
        J("l_elbow", "revolute", "l_shoulder_1", "l_elbow_1", "0 0 -0.15", "0 1 0"),
        J("l_wrist_yaw", "revolute", "l_elbow_1", "l_hand", "0 0 -0.15"),
        J("l_gripper_joint", "fixed", "l_hand", "l_gripper", "0 0 -0.05", bare=True),
    ]
    d, _ = _draft(tmp_path, _urdf("icub", "chest", joints))
    assert d.cameras == []
    (hand,) = d.manipulators
    assert hand.tool_frame == "l_gripper"
