"""Tests of the SRDF reader, checker and writer, on real robot files and on broken input."""

from __future__ import annotations

import copy
import dataclasses
import importlib.metadata as md
import time
from collections import Counter
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from robotspec.description.srdf import (
    DisabledCollision,
    DisableDefaultCollisions,
    EnabledCollision,
    EndEffector,
    Group,
    GroupChain,
    GroupState,
    PassiveJoint,
    Srdf,
    SrdfNotFoundError,
    VirtualJoint,
)
from robotspec.description.srdf_checks import check_srdf_against, check_srdf_references
from robotspec.description.srdf_reader import load_srdf, parse_srdf_bytes
from robotspec.errors import NotFoundError, RobotSpecError, RobotSpecErrors, SrdfError
from robotspec.export.srdf import write_srdf
from robotspec.files.xmlsafe import parse_xml_file

from .conftest import shared_path

# --------------------------------------------------------------------------------------------
# Helpers


def _erd_robots() -> Path | None:
    """example-robot-data's robots folder at collection time (None when not installed)."""
    try:
        dist = md.distribution("example-robot-data")
    except md.PackageNotFoundError:
        return None
    robots = Path(str(dist.locate_file("cmeel.prefix/share/example-robot-data"))) / "robots"
    return robots if robots.is_dir() else None


ERD = _erd_robots()
ERD_SRDFS = sorted(p.relative_to(ERD).as_posix() for p in ERD.glob("*/srdf/*.srdf")) if ERD else []


def erd(rel: str) -> Path:
    if ERD is None:
        pytest.skip("example-robot-data is not installed (pip install robotspec[data])")
    return ERD / rel


def _strip(value: Any) -> Any:
    """A record with every ``line`` (and the Srdf's ``file``) set to None, recursively."""
    if isinstance(value, tuple):
        return tuple(_strip(v) for v in value)
    if not dataclasses.is_dataclass(value) or isinstance(value, type):
        return value
    changes = {f.name: _strip(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if "line" in changes:
        changes["line"] = None
    if "file" in changes:
        changes["file"] = None
    return dataclasses.replace(value, **changes)


def assert_same_srdf(a: Srdf, b: Srdf) -> None:
    assert _strip(a) == _strip(b)


def roundtrip(s: Srdf) -> Srdf:
    return parse_srdf_bytes(write_srdf(s).encode())


def urdf_names(path: Path) -> tuple[list[str], list[str]]:
    """The link and joint names of a URDF, read safely with lxml."""
    root = parse_xml_file(path)
    links = [str(el.get("name")) for el in root.iterfind("link")]
    joints = [str(el.get("name")) for el in root.iterfind("joint")]
    return links, joints


def check(srdf: Srdf, urdf: Path) -> list[tuple[int | None, str]]:
    links, joints = urdf_names(urdf)
    errors = check_srdf_against(srdf, links, joints, urdf_name=urdf.name)
    for e in errors:
        assert isinstance(e, NotFoundError)
        assert e.file == srdf.file
    return [(e.line, e.message) for e in errors]


def messages(exc: pytest.ExceptionInfo[RobotSpecError]) -> list[tuple[int | None, str]]:
    return [(d.line, d.message) for d in exc.value.details]


def parse_text(text: str, **kw: Any) -> Srdf:
    return parse_srdf_bytes(text.encode(), "bad.srdf", **kw)


def robot(body: str) -> str:
    return f'<?xml version="1.0"?>\n<robot name="r">\n{body}\n</robot>\n'


# --------------------------------------------------------------------------------------------
# example-robot-data: every SRDF parses; the dangling references and missing names are facts

#: The pinocchio-made SRDFs that MoveIt would partly skip: states without a group, subgroups and
#: state groups the file does not define. They parse with strict=False only.
STRICT_PROBLEMS = {
    "borinot_description/srdf/borinot_flying_arm_2.srdf": [
        (13, "group_state 'home' has no group attribute"),
    ],
    "hextilt_description/srdf/hextilt_flying_arm_5.srdf": [
        (16, "group_state 'home' has no group attribute"),
    ],
    "kinova_description/srdf/kinova.srdf": [
        (16, "group_state 'arm_up' has no group attribute"),
    ],
    "z1_description/srdf/z1.srdf": [
        (16, "group_state 'home' has no group attribute"),
        (25, "group_state 'arm_up' has no group attribute"),
    ],
    "simple_humanoid_description/srdf/simple_humanoid.srdf": [
        (94, "group 'all' not found in simple_humanoid.srdf (group of group_state 'half_sitting')"),
    ],
    "simple_humanoid_description/srdf/simple_humanoid_classical.srdf": [
        (
            94,
            "group 'all' not found in simple_humanoid_classical.srdf "
            "(group of group_state 'half_sitting')",
        ),
    ],
}
# hyq.srdf and solo.srdf name the leg groups 'lf', 'rf', 'lh', 'rh' as subgroups (16 times each)
# but define them as 'lf_leg', ...
LEG_SUBGROUP_FILES = ("hyq_description/srdf/hyq.srdf", "solo_description/srdf/solo.srdf")

#: The URDF each SRDF belongs to: the one of the same name beside it, except where the pairing
#: is by content (solo.srdf describes Solo-12: it names the HAA joints solo.urdf lacks).
URDF_OF = {
    "solo_description/srdf/solo.srdf": "solo_description/robots/solo12.urdf",
    "hyq_description/srdf/hyq.srdf": "hyq_description/robots/hyq_no_sensors.urdf",
    "pr2_description/srdf/pr2_manipulation.srdf": "pr2_description/urdf/pr2.urdf",
    "romeo_description/srdf/romeo_moveit.srdf": "romeo_description/urdf/romeo.urdf",
    "talos_data/srdf/talos.srdf": "talos_data/robots/talos_reduced.urdf",
    "ur_description/srdf/ur5.srdf": "ur_description/urdf/ur5_robot.urdf",
}
#: Without a URDF of their own: cassie (none), alexander (the URDF is the lower body only),
#: baxter_manipulation (prefixes every joint with 'baxter/'; tested on its own).
NO_URDF = {
    "alexander_description/srdf/alexander.srdf",
    "baxter_description/srdf/baxter_manipulation.srdf",
    "cassie_description/srdf/cassie_v2.srdf",
}

#: Names the SRDFs use that their URDFs lack (pinocchio's free-flyer is called 'root_joint').
ERD_MISSING: dict[str, list[tuple[int, str]]] = {
    "alex_description/srdf/alex_nub_hands.srdf": [
        (
            68,
            "link 'LeftGripperYaw' not found in alex_nub_hands.urdf; "
            "did you mean 'LeftGripperYawLink', 'RightGripperYawLink' or 'LeftWristYawLink'?",
        ),
        (
            69,
            "link 'RightGripperYaw' not found in alex_nub_hands.urdf; "
            "did you mean 'RightGripperYawLink', 'LeftGripperYawLink' or 'RightWristYawLink'?",
        ),
    ],
    "alex_description/srdf/alex_psyonic_hands.srdf": [
        (
            118,
            "link 'LeftGripperYaw' not found in alex_psyonic_hands.urdf; "
            "did you mean 'LeftGripperYawLink', 'RightGripperYawLink' or 'LeftWristYawLink'?",
        ),
        (
            119,
            "link 'RightGripperYaw' not found in alex_psyonic_hands.urdf; "
            "did you mean 'RightGripperYawLink', 'LeftGripperYawLink' or 'RightWristYawLink'?",
        ),
    ],
    "alex_description/srdf/alex_sake_hands.srdf": [
        (
            86,
            "link 'LeftGripperYaw' not found in alex_sake_hands.urdf; "
            "did you mean 'LeftGripperYawLink', 'RightGripperYawLink' or 'LeftWristYawLink'?",
        ),
        (
            87,
            "link 'RightGripperYaw' not found in alex_sake_hands.urdf; "
            "did you mean 'RightGripperYawLink', 'LeftGripperYawLink' or 'RightWristYawLink'?",
        ),
    ],
    "bolt_description/srdf/bolt.srdf": [
        (28, "joint 'root_joint' not found in bolt.urdf"),
    ],
    "borinot_description/srdf/borinot_flying_arm_2.srdf": [
        (
            8,
            "link 'base' not found in borinot_flying_arm_2.urdf; "
            "did you mean 'borinot__base_link'?",
        ),
    ],
    "hextilt_description/srdf/hextilt_flying_arm_5.srdf": [
        (
            11,
            "link 'base' not found in hextilt_flying_arm_5.urdf; "
            "did you mean 'hextilt__base_link' or 'flying_arm_5__base_link'?",
        ),
    ],
    "hyq_description/srdf/hyq.srdf": [
        (
            69,
            "joint 'root_joint' not found in hyq_no_sensors.urdf; "
            "did you mean 'rh_foot_joint', 'rf_foot_joint' or 'lh_foot_joint'?",
        ),
        (
            85,
            "joint 'root_joint' not found in hyq_no_sensors.urdf; "
            "did you mean 'rh_foot_joint', 'rf_foot_joint' or 'lh_foot_joint'?",
        ),
    ],
    "icub_description/srdf/icub.srdf": [
        (86, "joint 'root_joint' not found in icub.urdf; did you mean 'torso_joint'?"),
    ],
    "romeo_description/srdf/romeo.srdf": [
        (
            95,
            "joint 'LToePitch' not found in romeo.urdf; "
            "did you mean 'LKneePitch', 'LAnklePitch' or 'LShoulderPitch'?",
        ),
        (
            103,
            "joint 'RToePitch' not found in romeo.urdf; "
            "did you mean 'RKneePitch', 'RAnklePitch' or 'RShoulderPitch'?",
        ),
        (
            105,
            "joint 'LFinger11' not found in romeo.urdf; "
            "did you mean 'LFinger31', 'LFinger21' or 'LFinger13'?",
        ),
        (
            118,
            "joint 'RFinger11' not found in romeo.urdf; "
            "did you mean 'RFinger31', 'RFinger21' or 'RFinger13'?",
        ),
        (131, "joint 'LEyeYaw' not found in romeo.urdf; did you mean 'LElbowYaw'?"),
        (
            132,
            "joint 'LEyePitch' not found in romeo.urdf; "
            "did you mean 'LKneePitch', 'LAnklePitch' or 'NeckPitch'?",
        ),
        (133, "joint 'REyeYaw' not found in romeo.urdf; did you mean 'RElbowYaw'?"),
        (
            134,
            "joint 'REyePitch' not found in romeo.urdf; "
            "did you mean 'RKneePitch', 'RAnklePitch' or 'RHipPitch'?",
        ),
    ],
    "romeo_description/srdf/romeo_small.srdf": [
        (
            88,
            "joint 'LToePitch' not found in romeo_small.urdf; "
            "did you mean 'LKneePitch', 'LAnklePitch' or 'LShoulderPitch'?",
        ),
        (
            96,
            "joint 'RToePitch' not found in romeo_small.urdf; "
            "did you mean 'RKneePitch', 'RAnklePitch' or 'RShoulderPitch'?",
        ),
        (98, "joint 'LEyeYaw' not found in romeo_small.urdf; did you mean 'LElbowYaw'?"),
        (
            99,
            "joint 'LEyePitch' not found in romeo_small.urdf; "
            "did you mean 'LKneePitch', 'LAnklePitch' or 'NeckPitch'?",
        ),
        (100, "joint 'REyeYaw' not found in romeo_small.urdf; did you mean 'RElbowYaw'?"),
        (
            101,
            "joint 'REyePitch' not found in romeo_small.urdf; "
            "did you mean 'RKneePitch', 'RAnklePitch' or 'RHipPitch'?",
        ),
    ],
    "simple_humanoid_description/srdf/simple_humanoid.srdf": [
        (29, "link 'r_foot' not found in simple_humanoid.urdf"),
        (33, "link 'l_foot' not found in simple_humanoid.urdf"),
        (89, "link 'r_foot' not found in simple_humanoid.urdf"),
        (90, "link 'l_foot' not found in simple_humanoid.urdf"),
    ],
    "simple_humanoid_description/srdf/simple_humanoid_classical.srdf": [
        (29, "link 'r_foot' not found in simple_humanoid_classical.urdf"),
        (33, "link 'l_foot' not found in simple_humanoid_classical.urdf"),
        (89, "link 'r_foot' not found in simple_humanoid_classical.urdf"),
        (90, "link 'l_foot' not found in simple_humanoid_classical.urdf"),
    ],
    "solo_description/srdf/solo.srdf": [
        (69, "joint 'root_joint' not found in solo12.urdf"),
        (85, "joint 'root_joint' not found in solo12.urdf"),
    ],
    "talos_data/srdf/talos.srdf": [
        (
            104,
            "joint 'root_joint' not found in talos_reduced.urdf; "
            "did you mean 'rgbd_joint', 'rgbd_optical_joint' or 'imu_joint'?",
        ),
    ],
    "z1_description/srdf/z1.srdf": [
        (11, "link 'base' not found in z1.urdf"),
    ],
}


def _urdf_for(rel: str) -> Path | None:
    if rel in URDF_OF:
        return erd(URDF_OF[rel])
    srdf = erd(rel)
    for folder in ("urdf", "robots"):
        candidate = srdf.parents[1] / folder / f"{srdf.stem}.urdf"
        if candidate.exists():
            return candidate
    return None


def test_erd_has_the_srdfs_we_know() -> None:
    if ERD is None:
        pytest.skip("example-robot-data is not installed (pip install robotspec[data])")
    assert len(ERD_SRDFS) == 38
    assert set(STRICT_PROBLEMS) | set(LEG_SUBGROUP_FILES) | set(ERD_MISSING) | NO_URDF <= set(
        ERD_SRDFS
    )


@pytest.mark.parametrize("rel", ERD_SRDFS)
def test_every_erd_srdf_parses_and_round_trips(rel: str) -> None:
    path = erd(rel)
    srdf = load_srdf(path, strict=False)
    assert srdf.file == str(path)
    assert srdf.robot_name
    assert_same_srdf(parse_srdf_bytes(write_srdf(srdf).encode(), strict=False), srdf)
    problems = [(e.line, e.message) for e in check_srdf_references(srdf)]
    if rel in STRICT_PROBLEMS:
        assert problems == STRICT_PROBLEMS[rel]
    elif rel in LEG_SUBGROUP_FILES:
        assert len(problems) == 16
        name = Path(rel).name
        assert problems[0] == (
            33,
            f"group 'lf' not found in {name} (subgroup of group 'all_legs'); "
            "did you mean 'lf_leg'?",
        )
        assert {m.split("'")[1] for _, m in problems} == {"lf", "rf", "lh", "rh"}
    else:
        assert problems == []
        assert_same_srdf(load_srdf(path), srdf)  # strict parsing accepts it too


@pytest.mark.parametrize("rel", sorted(set(STRICT_PROBLEMS) | set(LEG_SUBGROUP_FILES)))
def test_erd_srdfs_with_dangling_groups_fail_strict_parsing(rel: str) -> None:
    path = erd(rel)
    with pytest.raises(RobotSpecError) as exc:
        load_srdf(path)
    assert all(isinstance(e, SrdfError) for e in getattr(exc.value, "errors", [exc.value]))
    expected = [(e.line, e.message) for e in check_srdf_references(load_srdf(path, strict=False))]
    assert messages(exc) == expected
    assert all(d.file == str(path) for d in exc.value.details)


@pytest.mark.parametrize("rel", [r for r in ERD_SRDFS if r not in NO_URDF])
def test_erd_srdf_names_against_its_urdf(rel: str) -> None:
    urdf = _urdf_for(rel)
    assert urdf is not None, f"{rel} has no URDF beside it; list it in NO_URDF"
    srdf = load_srdf(erd(rel), strict=False)
    assert check(srdf, urdf) == ERD_MISSING.get(rel, [])


def test_erd_baxter_manipulation_prefixes_every_joint() -> None:
    srdf = load_srdf(erd("baxter_description/srdf/baxter_manipulation.srdf"))
    found = check(srdf, erd("baxter_description/urdf/baxter.urdf"))
    assert len(found) == 38
    assert found[0] == (
        18,
        "joint 'baxter/head_pan' not found in baxter.urdf; did you mean 'head_pan'?",
    )
    for _, message in found:
        name = message.split("'")[1]
        assert name.startswith("baxter/")
        assert f"'{name.removeprefix('baxter/')}'" in message.split("did you mean")[1]


def test_erd_pr2_facts() -> None:
    srdf = load_srdf(erd("pr2_description/srdf/pr2.srdf"))
    assert srdf.robot_name == "pr2"
    assert srdf.group_names == (
        "base",
        "left_arm",
        "left_arm_and_torso",
        "right_arm",
        "right_arm_and_torso",
        "arms",
        "head",
        "torso",
        "whole_body",
        "right_gripper",
        "left_gripper",
    )
    assert srdf.group("left_arm").chains == (
        GroupChain("torso_lift_link", "l_wrist_roll_link", line=16),
    )
    assert [(s.name, s.group) for s in srdf.group_states] == [
        ("tuck_right_arm", "right_arm"),
        ("tuck_left_arm", "left_arm"),
    ]
    assert srdf.end_effectors == (
        EndEffector("right_eef", "r_wrist_roll_link", "right_gripper", None, line=85),
        EndEffector("left_eef", "l_wrist_roll_link", "left_gripper", None, line=86),
    )
    assert srdf.virtual_joints == (
        VirtualJoint("world_joint", "planar", "odom_combined", "base_footprint", line=88),
    )
    assert srdf.passive_joints == (PassiveJoint("world_joint", line=90),)
    assert len(srdf.disabled_collisions) == 1163
    assert len(srdf.disabled_pairs()) == 1161  # two pairs are listed twice
    assert Counter(d.reason for d in srdf.disabled_collisions) == {
        "Never": 713,
        None: 383,
        "Adjacent": 49,
        "Default": 18,
    }
    assert srdf.disable_default_collisions == srdf.enabled_collisions == ()
    # The passive joint is the virtual joint: a name MoveIt adds, so not missing from the URDF.
    assert check(srdf, erd("pr2_description/urdf/pr2.urdf")) == []


# --------------------------------------------------------------------------------------------
# The shared robot files (HSRB, UR5e, FANUC)


def test_hsrb_srdf_facts() -> None:
    path = shared_path("robots", "hsrb", "hsrb_moveit_config", "config", "hsrb.srdf")
    srdf = load_srdf(path)
    assert srdf.robot_name == "hsrb"
    assert srdf.group_names == (
        "arm",
        "gripper",
        "head",
        "base",
        "whole_body",
        "whole_body_weighted",
        "whole_body_light",
    )
    assert srdf.group("arm").chains == (GroupChain("base_link", "hand_palm_link", line=42),)
    assert srdf.group("gripper").joints == ("hand_motor_joint",)
    assert len(srdf.group("gripper").links) == 6
    assert srdf.group("whole_body").subgroups == ("arm", "base")
    # The arm is a chain (needs the URDF), so only the base's joints come through subgroups.
    assert srdf.group_joints("whole_body") == ["odom_x", "odom_y", "odom_t"]
    assert [(s.group, s.name) for s in srdf.group_states] == [
        ("arm", "neutral"),
        ("arm", "go"),
        ("head", "neutral"),
    ]
    assert dict(srdf.group_states[1].joint_values)["arm_roll_joint"] == (-1.57,)
    assert srdf.end_effectors == (EndEffector("eef", "hand_palm_link", "gripper", line=95),)
    assert srdf.virtual_joints == (
        VirtualJoint("world_joint", "planar", "odom", "base_footprint", line=97),
    )
    assert len(srdf.passive_joints) == 13
    assert len(srdf.disabled_collisions) == 245
    # hand_l_finger_vacuum_frame/hand_r_distal_link is listed twice (lines 315 and 336).
    assert len(srdf.disabled_pairs()) == 244
    twice = [
        d.line
        for d in srdf.disabled_collisions
        if {d.link1, d.link2} == {"hand_l_finger_vacuum_frame", "hand_r_distal_link"}
    ]
    assert twice == [315, 336]


def test_hsrb_srdf_names_odom_joints_the_urdf_lacks() -> None:
    path = shared_path("robots", "hsrb", "hsrb_moveit_config", "config", "hsrb.srdf")
    urdf = shared_path("robots", "hsrb", "hsrb4s.urdf")
    srdf = load_srdf(path)
    links, joints = urdf_names(urdf)
    errors = check_srdf_against(srdf, links, joints, urdf_name="hsrb4s.urdf")
    assert [e.detail.render() for e in errors] == [
        f"{path}:58: error: joint 'odom_x' not found in hsrb4s.urdf",
        f"{path}:59: error: joint 'odom_y' not found in hsrb4s.urdf",
        f"{path}:60: error: joint 'odom_t' not found in hsrb4s.urdf",
    ]
    assert all(isinstance(e, NotFoundError) and e.detail.kind == "joint" for e in errors)
    assert [e.name for e in errors] == ["odom_x", "odom_y", "odom_t"]


def test_ur5e_srdf_facts() -> None:
    path = shared_path("robots", "ur5e", "ur5e_moveit_config", "config", "ur5e.srdf")
    srdf = load_srdf(path)
    assert srdf.robot_name == "ur5e_robot"
    assert srdf.group_names == ("manipulator",)
    assert [(c.base_link, c.tip_link) for c in srdf.group("manipulator").chains] == [
        ("base_link", "tool0")
    ]
    assert [s.name for s in srdf.group_states] == ["home", "up"]
    assert dict(srdf.group_states[1].joint_values)["shoulder_lift_joint"] == (-1.5707,)
    assert srdf.virtual_joints == (
        VirtualJoint("fixed_base", "fixed", "world", "base_link", line=33),
    )
    assert len(srdf.disabled_collisions) == len(srdf.disabled_pairs()) == 11
    assert srdf.end_effectors == srdf.passive_joints == ()
    assert check(srdf, shared_path("robots", "ur5e", "ur5e.urdf")) == []


def test_fanuc_srdf_facts() -> None:
    config = shared_path("robots", "fanuc", "moveit_resources_fanuc_moveit_config", "config")
    srdf = load_srdf(config / "fanuc.srdf")
    assert srdf.robot_name == "fanuc"
    assert srdf.group_names == ("manipulator",)
    assert [(s.name, s.group) for s in srdf.group_states] == [("all-zeros", "manipulator")]
    assert srdf.group_states[0].joint_values == tuple((f"joint_{i}", (0.0,)) for i in range(1, 7))
    assert srdf.virtual_joints == (
        VirtualJoint("FixedBase", "fixed", "world", "base_link", line=25),
    )
    assert len(srdf.disabled_collisions) == len(srdf.disabled_pairs()) == 10
    assert Counter(d.reason for d in srdf.disabled_collisions) == {"Adjacent": 6, "Never": 4}
    urdf = shared_path(
        "robots", "fanuc", "moveit_resources_fanuc_description", "urdf", "fanuc.urdf"
    )
    assert check(srdf, urdf) == []


# --------------------------------------------------------------------------------------------
# Broken input: every problem reported with its file, line and exact message


def test_not_xml_at_all() -> None:
    with pytest.raises(SrdfError) as exc:
        parse_srdf_bytes(b"this is not XML", "bad.srdf")
    assert str(exc.value) == "bad.srdf:1: error: malformed XML: Start tag expected, '<' not found"


def test_empty_and_truncated_documents() -> None:
    with pytest.raises(SrdfError, match="malformed XML: Document is empty"):
        parse_srdf_bytes(b"")
    with pytest.raises(SrdfError) as exc:
        parse_srdf_bytes(b'<robot name="r"><group name="a">')
    assert exc.value.file is None
    assert exc.value.message.startswith("malformed XML: ")


def test_wrong_root_tag() -> None:
    with pytest.raises(SrdfError) as exc:
        parse_text('<?xml version="1.0"?>\n<robt name="r"><group name="a"/></robt>')
    assert str(exc.value) == "bad.srdf:2: error: root element must be <robot>, got <robt>"


def test_a_urdf_given_as_srdf_is_read_but_empty() -> None:
    # Same root tag, no SRDF elements: an empty SRDF, as MoveIt reads it.
    srdf = parse_text(robot('<link name="a"/><joint name="j" type="fixed"/>'))
    assert srdf == Srdf("r", "bad.srdf")


def test_billion_laughs_is_refused_without_expansion() -> None:
    lols = "".join(f'<!ENTITY lol{i} "{f"&lol{i - 1};" * 10}">' for i in range(1, 10))
    data = (
        '<?xml version="1.0"?>\n<!DOCTYPE robot [\n<!ENTITY lol0 "lol">'
        f'{lols}\n]>\n<robot name="&lol9;"><group name="&lol9;"/></robot>\n'
    ).encode()
    start = time.thread_time()  # this thread's CPU time: the same on a busy machine
    with pytest.raises(RobotSpecError) as exc:
        parse_srdf_bytes(data, "lol.srdf")
    assert time.thread_time() - start < 0.5
    assert isinstance(exc.value, SrdfError)
    assert str(exc.value) == (
        "lol.srdf:3: error: XML entity declarations are not allowed (found 'lol0')"
    )
    assert "lollol" not in str(exc.value)


def test_chain_without_tip_link() -> None:
    text = robot('<group name="arm">\n<chain base_link="base"/>\n</group>')
    with pytest.raises(SrdfError) as exc:
        parse_text(text)
    assert str(exc.value) == "bad.srdf:4: error: <chain> of group 'arm' has no tip_link attribute"
    assert exc.value.name == "arm"


def test_group_state_value_not_a_number() -> None:
    text = robot(
        '<group name="arm"><joint name="j1"/></group>\n'
        '<group_state name="home" group="arm">\n<joint name="j1" value="abc"/>\n</group_state>'
    )
    with pytest.raises(SrdfError) as exc:
        parse_text(text)
    assert str(exc.value) == (
        "bad.srdf:5: error: group_state 'home': value of joint 'j1': 'abc' is not a number"
    )
    assert exc.value.name == "home"


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ("nan", "value of joint 'j': 'nan' is not a number"),
        ("1_000", "value of joint 'j': '1_000' is not a number"),
        ("1e999", "value of joint 'j' must be finite, got '1e999'"),
        ("  ", None),
    ],
)
def test_group_state_values_are_decimal_numbers(value: str, message: str | None) -> None:
    text = robot(
        '<group name="g"/><group_state name="s" group="g">'
        f'<joint name="j" value="{value}"/></group_state>'
    )
    with pytest.raises(SrdfError) as exc:
        parse_text(text)
    expected = message or "<joint 'j'> of group_state 's' has no value attribute"
    assert exc.value.message == (f"group_state 's': {message}" if message else expected)


def test_multi_dof_values_and_c_style_numbers() -> None:
    text = robot(
        '<group name="g"/><group_state name="s" group="g">'
        '<joint name="root" value=" 0. 0 .5 -1e-3  +2E2 0 1"/><joint name="j" value="-1.57"/>'
        "</group_state>"
    )
    state = parse_text(text).group_states[0]
    assert state.joint_values == (
        ("root", (0.0, 0.0, 0.5, -0.001, 200.0, 0.0, 1.0)),
        ("j", (-1.57,)),
    )


def test_unknown_virtual_joint_type() -> None:
    text = robot('<virtual_joint name="vj" type="revolute" parent_frame="world" child_link="a"/>')
    with pytest.raises(SrdfError) as exc:
        parse_text(text)
    assert str(exc.value) == (
        "bad.srdf:3: error: virtual_joint 'vj' has type 'revolute'; "
        "expected one of fixed, floating, planar"
    )


def test_virtual_joint_type_is_read_like_srdfdom() -> None:
    text = robot('<virtual_joint name="vj" type=" Floating " parent_frame="world" child_link="a"/>')
    assert parse_text(text).virtual_joints[0].type == "floating"


def test_group_state_of_an_undefined_group() -> None:
    text = robot(
        '<group name="right_arm"/>\n<group_state name="tuck" group="right_amr">\n</group_state>'
    )
    with pytest.raises(NotFoundError) as exc:
        parse_text(text)
    assert isinstance(exc.value, SrdfError)
    assert str(exc.value) == (
        "bad.srdf:4: error: group 'right_amr' not found in bad.srdf "
        "(group of group_state 'tuck'); did you mean 'right_arm'?"
    )
    assert exc.value.suggestions == ("right_arm",)
    # Read leniently, the state is kept as written.
    assert parse_text(text, strict=False).group_states[0].group == "right_amr"


def test_end_effector_groups_must_be_defined() -> None:
    text = robot(
        '<group name="hand"/><group name="arm"/>\n'
        '<end_effector name="eef" parent_link="wrist" group="hnad" parent_group="amr"/>'
    )
    with pytest.raises(RobotSpecErrors) as exc:
        parse_text(text)
    assert messages(exc) == [
        (
            4,
            "group 'hnad' not found in bad.srdf (group of end_effector 'eef'); "
            "did you mean 'hand'?",
        ),
        (
            4,
            "group 'amr' not found in bad.srdf (parent_group of end_effector 'eef'); "
            "did you mean 'arm'?",
        ),
    ]


def test_duplicate_group() -> None:
    text = robot('<group name="arm"/>\n<group name="arm"><joint name="j"/></group>')
    with pytest.raises(SrdfError) as exc:
        parse_text(text)
    assert str(exc.value) == "bad.srdf:4: error: group 'arm' is defined twice (first on line 3)"


def test_undefined_subgroup() -> None:
    text = robot('<group name="legs">\n<group name="lf"/>\n</group>\n<group name="lf_leg"/>')
    with pytest.raises(SrdfError) as exc:
        parse_text(text)
    assert str(exc.value) == (
        "bad.srdf:4: error: group 'lf' not found in bad.srdf (subgroup of group 'legs'); "
        "did you mean 'lf_leg'?"
    )


def test_subgroup_cycles() -> None:
    text = robot(
        '<group name="a"><group name="b"/></group>\n'
        '<group name="b"><group name="c"/></group>\n'
        '<group name="c"><group name="a"/></group>\n'
        '<group name="d"><group name="d"/><group name="a"/></group>'
    )
    with pytest.raises(RobotSpecErrors) as exc:
        parse_text(text)
    assert messages(exc) == [
        (3, "groups contain each other: a -> b -> c -> a"),
        (6, "groups contain each other: d -> d"),
    ]
    # Read leniently nothing changes: a cycle is malformed in any mode.
    with pytest.raises(RobotSpecErrors):
        parse_text(text, strict=False)


def test_several_problems_in_one_raise() -> None:
    text = robot(
        '<group name="arm">\n'
        '  <chain base_link="base"/>\n'
        "  <joint/>\n"
        "</group>\n"
        '<group name="arm"/>\n'
        '<group_state name="home" group="amr">\n'
        '  <joint name="j1" value="0.1 x"/>\n'
        "</group_state>\n"
        '<virtual_joint name="vj" type="prismatic" parent_frame="world"/>\n'
        '<end_effector name="eef" group="arm"/>\n'
        "<passive_joint/>\n"
        '<disable_collisions link1="a"/>\n'
        "<disable_default_collisions/>"
    )
    with pytest.raises(RobotSpecErrors) as exc:
        parse_text(text)
    assert messages(exc) == [
        (4, "<chain> of group 'arm' has no tip_link attribute"),
        (5, "<joint> of group 'arm' has no name attribute"),
        (7, "group 'arm' is defined twice (first on line 3)"),
        (8, "group 'amr' not found in bad.srdf (group of group_state 'home'); did you mean 'arm'?"),
        (9, "group_state 'home': value of joint 'j1': 'x' is not a number"),
        (11, "virtual_joint 'vj' has no child_link attribute"),
        (11, "virtual_joint 'vj' has type 'prismatic'; expected one of fixed, floating, planar"),
        (12, "end_effector 'eef' has no parent_link attribute"),
        (13, "<passive_joint> has no name attribute"),
        (14, "<disable_collisions> has no link2 attribute"),
        (15, "<disable_default_collisions> has no link attribute"),
    ]
    assert str(exc.value).splitlines()[0] == "bad.srdf: 11 problems"
    assert all(isinstance(e, SrdfError) and e.file == "bad.srdf" for e in exc.value.errors)


def test_robot_without_name() -> None:
    with pytest.raises(SrdfError, match=r"^bad.srdf:1: error: <robot> has no name attribute$"):
        parse_text("<robot/>")


def test_missing_and_unreadable_files(tmp_path: Path) -> None:
    with pytest.raises(SrdfError) as exc:
        load_srdf(tmp_path / "none.srdf")
    assert str(exc.value) == f"{tmp_path / 'none.srdf'}: error: file not found"
    with pytest.raises(SrdfError, match="is a directory"):
        load_srdf(tmp_path)


# --------------------------------------------------------------------------------------------
# Dialects, comments, unknown elements


def test_giskard_dialect_aliases() -> None:
    text = robot(
        '<disable_all_collisions link="base"/>\n'
        '<disable_self_collision link1="a" link2="b" reason="Never"/>\n'
        '<disable_collisions link1="b" link2="c"/>'
    )
    srdf = parse_text(text)
    assert srdf.disable_default_collisions == (DisableDefaultCollisions("base", line=3),)
    assert srdf.disabled_collisions == (
        DisabledCollision("a", "b", "Never", line=4),
        DisabledCollision("b", "c", None, line=5),
    )
    assert srdf.disabled_pairs() == {frozenset({"a", "b"}), frozenset({"b", "c"})}
    # The writer speaks MoveIt's dialect only.
    written = write_srdf(srdf)
    assert "disable_self_collision" not in written
    assert "disable_all_collisions" not in written
    assert_same_srdf(roundtrip(srdf), srdf)


def test_comments_and_unknown_elements_are_skipped() -> None:
    text = robot(
        "<!-- a comment -->\n"
        '<group name="arm"><!-- inside --><joint name="j"/><rotor_params/></group>\n'
        '<group_state name="s" group="arm"><!-- c --><joint name="j" value="1"/></group_state>\n'
        "<specificities><feet/></specificities>\n"
        '<gripper name="g"><link name="x"/></gripper>\n'
        '<enable_collisions link1="a" link2="b" reason="Needed"/>'
    )
    srdf = parse_text(text)
    assert srdf.groups == (Group("arm", joints=("j",), line=4),)
    assert srdf.group_states == (GroupState("s", "arm", (("j", (1.0,)),), line=5),)
    assert srdf.enabled_collisions == (EnabledCollision("a", "b", "Needed", line=8),)


def test_member_lines_point_at_each_member() -> None:
    text = robot(
        '<group name="g">\n<joint name="j"/>\n<link name="l"/>\n<group name="h"/>\n</group>\n'
        '<group name="h"/>'
    )
    group = parse_text(text).group("g")
    assert (group.joint_lines, group.link_lines, group.subgroup_lines) == ((4,), (5,), (6,))


# --------------------------------------------------------------------------------------------
# Convenience methods


def _sample() -> Srdf:
    return Srdf(
        "r",
        groups=(
            Group("arm", joints=("j1", "j2")),
            Group("hand", joints=("f1",), links=("palm",)),
            Group("both", joints=("j2", "x"), subgroups=("arm", "hand", "both")),
            Group("loop_a", joints=("a",), subgroups=("loop_b",)),
            Group("loop_b", joints=("b",), subgroups=("loop_a", "undefined")),
        ),
    )


def test_group_lookup_suggests_names() -> None:
    srdf = _sample()
    assert srdf.group("hand").links == ("palm",)
    assert srdf.group_names == ("arm", "hand", "both", "loop_a", "loop_b")
    with pytest.raises(SrdfNotFoundError) as exc:
        srdf.group("hnad")
    assert str(exc.value) == "error: group 'hnad' not found in the SRDF; did you mean 'hand'?"


def test_group_joints_follows_subgroups_once() -> None:
    srdf = _sample()
    assert srdf.group_joints("both") == ["j2", "x", "j1", "f1"]
    assert srdf.group_joints("loop_a") == ["a", "b"]
    assert srdf.group_joints("loop_b") == ["b", "a"]


def test_disabled_pairs_are_unordered() -> None:
    srdf = Srdf(
        "r",
        disabled_collisions=(
            DisabledCollision("a", "b"),
            DisabledCollision("b", "a", "Never"),
            DisabledCollision("c", "c"),
        ),
        enabled_collisions=(EnabledCollision("a", "b"),),
    )
    assert srdf.disabled_pairs() == {frozenset({"a", "b"}), frozenset({"c"})}


# --------------------------------------------------------------------------------------------
# Checking against a URDF


def test_check_against_urdf_names_every_use_in_file_order() -> None:
    text = robot(
        '<group name="arm">\n'
        '  <chain base_link="torso" tip_link="r_wrist_roll_lnk"/>\n'
        '  <joint name="world_joint"/>\n'
        '  <joint name="elbow"/>\n'
        '  <link name="hand"/>\n'
        "</group>\n"
        '<group_state name="s" group="arm">\n'
        '  <joint name="world_joint" value="0 0 0"/>\n'
        '  <joint name="elbw" value="0"/>\n'
        "</group_state>\n"
        '<end_effector name="e" parent_link="hnd" group="arm"/>\n'
        '<virtual_joint name="world_joint" type="planar" parent_frame="odom" child_link="bas"/>\n'
        '<passive_joint name="world_joint"/>\n'
        '<passive_joint name="caster"/>\n'
        '<disable_collisions link1="gost" link2="gost"/>\n'
        '<enable_collisions link1="base" link2="torsoo"/>\n'
        '<disable_default_collisions link="hand"/>'
    )
    srdf = parse_text(text)
    links = ["base", "torso", "r_wrist_roll_link", "hand"]
    joints = ["elbow", "wrist"]
    errors = check_srdf_against(srdf, links, joints, urdf_name="pr2.urdf")
    assert [(e.line, e.message) for e in errors] == [
        (4, "link 'r_wrist_roll_lnk' not found in pr2.urdf; did you mean 'r_wrist_roll_link'?"),
        (11, "joint 'elbw' not found in pr2.urdf; did you mean 'elbow'?"),
        (13, "link 'hnd' not found in pr2.urdf; did you mean 'hand'?"),
        (14, "link 'bas' not found in pr2.urdf; did you mean 'base'?"),
        (16, "joint 'caster' not found in pr2.urdf"),
        (17, "link 'gost' not found in pr2.urdf"),
        (18, "link 'torsoo' not found in pr2.urdf; did you mean 'torso'?"),
    ]
    assert all(isinstance(e, NotFoundError) and e.file == "bad.srdf" for e in errors)
    assert [e.detail.kind for e in errors] == [
        "link",
        "joint",
        "link",
        "link",
        "joint",
        "link",
        "link",
    ]


def test_check_against_urdf_without_member_lines_uses_the_group_line() -> None:
    srdf = Srdf("r", groups=(Group("g", joints=("x", "x"), links=("y",), line=7),))
    errors = check_srdf_against(srdf, ["l"], ["j"], urdf_name="r.urdf")
    assert [(e.line, e.message) for e in errors] == [
        (7, "joint 'x' not found in r.urdf"),
        (7, "link 'y' not found in r.urdf"),
    ]


def test_clean_srdf_checks_clean() -> None:
    srdf = Srdf(
        "r",
        groups=(Group("g", joints=("j",), chains=(GroupChain("a", "b"),)),),
        virtual_joints=(VirtualJoint("v", "fixed", "outside_world", "a"),),
    )
    assert check_srdf_against(srdf, ["a", "b"], ["j"], urdf_name="r.urdf") == []


# --------------------------------------------------------------------------------------------
# Writing

FULL = Srdf(
    "demo",
    groups=(
        Group("arm", joints=("j1",), links=("l1",), chains=(GroupChain("base", "tip"),)),
        Group("hand"),
        Group("all", subgroups=("arm", "hand")),
    ),
    group_states=(GroupState("home", "arm", (("j1", (0.0,)), ("free", (1.5, -2e-05)))),),
    end_effectors=(EndEffector("eef", "tip", "hand", "arm"),),
    virtual_joints=(VirtualJoint("world_joint", "planar", "odom", "base"),),
    passive_joints=(PassiveJoint("caster"),),
    disabled_collisions=(
        DisabledCollision("base", "l1", "Adjacent"),
        DisabledCollision("l1", "tip"),
    ),
    disable_default_collisions=(DisableDefaultCollisions("tip"),),
    enabled_collisions=(EnabledCollision("tip", "base", 'a "quoted" <&> reason'),),
)

FULL_TEXT = """\
<?xml version="1.0"?>
<robot name="demo">
    <group name="arm">
        <link name="l1"/>
        <joint name="j1"/>
        <chain base_link="base" tip_link="tip"/>
    </group>
    <group name="hand"/>
    <group name="all">
        <group name="arm"/>
        <group name="hand"/>
    </group>
    <group_state name="home" group="arm">
        <joint name="j1" value="0.0"/>
        <joint name="free" value="1.5 -2e-05"/>
    </group_state>
    <end_effector name="eef" parent_link="tip" group="hand" parent_group="arm"/>
    <virtual_joint name="world_joint" type="planar" parent_frame="odom" child_link="base"/>
    <passive_joint name="caster"/>
    <disable_default_collisions link="tip"/>
    <enable_collisions link1="tip" link2="base" reason="a &quot;quoted&quot; &lt;&amp;&gt; reason"/>
    <disable_collisions link1="base" link2="l1" reason="Adjacent"/>
    <disable_collisions link1="l1" link2="tip"/>
</robot>
"""


def test_write_srdf_text() -> None:
    assert write_srdf(FULL) == FULL_TEXT
    assert write_srdf(FULL) == write_srdf(roundtrip(FULL))


def test_write_empty_srdf() -> None:
    assert write_srdf(Srdf("e")) == '<?xml version="1.0"?>\n<robot name="e"/>\n'
    assert roundtrip(Srdf("e")) == Srdf("e")


# --------------------------------------------------------------------------------------------
# Properties

NAMES = st.text(alphabet="ab_1", min_size=1, max_size=4)
REASONS = st.none() | st.text(alphabet="ab <&\"'>", max_size=6)
VALUES = st.floats(allow_nan=False, allow_infinity=False)


@st.composite
def srdfs(draw: st.DrawFn) -> Srdf:
    group_names = draw(st.lists(NAMES, unique=True, max_size=4))
    groups = []
    for i, name in enumerate(group_names):
        groups.append(
            Group(
                name,
                joints=tuple(draw(st.lists(NAMES, max_size=3))),
                links=tuple(draw(st.lists(NAMES, max_size=3))),
                chains=tuple(
                    GroupChain(a, b) for a, b in draw(st.lists(st.tuples(NAMES, NAMES), max_size=2))
                ),
                # Only earlier groups: subgroups never form a cycle.
                subgroups=tuple(draw(st.lists(st.sampled_from(group_names[:i]), max_size=2)))
                if i
                else (),
            )
        )
    states: list[GroupState] = []
    ees: list[EndEffector] = []
    if group_names:
        in_group = st.sampled_from(group_names)
        keys = draw(st.lists(st.tuples(NAMES, in_group), unique=True, max_size=3))
        for name, group in keys:
            joints = draw(
                st.lists(st.tuples(NAMES, st.lists(VALUES, min_size=1, max_size=7)), max_size=3)
            )
            states.append(GroupState(name, group, tuple((j, tuple(v)) for j, v in joints)))
        for name in draw(st.lists(NAMES, unique=True, max_size=2)):
            ees.append(EndEffector(name, draw(NAMES), draw(in_group), draw(st.none() | in_group)))
    vj_names = draw(st.lists(NAMES, unique=True, max_size=2))
    pair = st.tuples(NAMES, NAMES, REASONS)
    return Srdf(
        draw(NAMES),
        groups=tuple(groups),
        group_states=tuple(states),
        end_effectors=tuple(ees),
        virtual_joints=tuple(
            VirtualJoint(
                n, draw(st.sampled_from(["fixed", "floating", "planar"])), draw(NAMES), draw(NAMES)
            )
            for n in vj_names
        ),
        passive_joints=tuple(PassiveJoint(n) for n in draw(st.lists(NAMES, max_size=2))),
        disabled_collisions=tuple(DisabledCollision(*p) for p in draw(st.lists(pair, max_size=3))),
        disable_default_collisions=tuple(
            DisableDefaultCollisions(n) for n in draw(st.lists(NAMES, max_size=2))
        ),
        enabled_collisions=tuple(EnabledCollision(*p) for p in draw(st.lists(pair, max_size=2))),
    )


@given(srdfs())
def test_write_then_parse_is_identity(srdf: Srdf) -> None:
    again = roundtrip(srdf)
    assert_same_srdf(again, srdf)
    assert write_srdf(again) == write_srdf(srdf)


def _seed_srdf() -> bytes:
    # A real MoveIt Setup Assistant file with comments; PR2's is too large to mutate quickly.
    return erd("panda_description/srdf/panda.srdf").read_bytes()


SNIPPETS = [
    b"<",
    b">",
    b"&",
    b'"',
    b"&amp;",
    b"&lol;",
    b"nan",
    b"abc",
    b"<group/>",
    b"</group>",
    b"<!-- -->",
    b"<!DOCTYPE robot [<!ENTITY a 'b'>]>",
    b'<?xml version="1.0" encoding="latin-1"?>',
    b'<?xml version="1.0" encoding="bogus"?>',
    b"\x00",
    b"\xff\xfe",
    b'<group_state name="s" group="x"><joint name="j" value="1 2 z"/></group_state>',
    b'<group name="a"><group name="a"/></group>',
]


@given(
    st.lists(
        st.tuples(
            st.floats(min_value=0, max_value=1),
            st.integers(min_value=0, max_value=40),
            st.sampled_from(SNIPPETS) | st.binary(max_size=4),
        ),
        min_size=1,
        max_size=4,
    )
)
def test_mutated_srdf_raises_only_our_errors(edits: list[tuple[float, int, bytes]]) -> None:
    data = _seed_srdf()
    for where, cut, insert in edits:
        at = int(where * len(data))
        data = data[:at] + insert + data[at + cut :]
    for strict in (True, False):
        try:
            srdf = parse_srdf_bytes(data, "mutant.srdf", strict=strict)
        except RobotSpecError as exc:
            assert exc.details
            continue
        # Whatever parses writes and reads back to the same value.
        assert_same_srdf(parse_srdf_bytes(write_srdf(srdf).encode(), strict=strict), srdf)


TAGS = ["robot", "group", "joint", "link", "chain", "group_state", "end_effector", "virtual_joint"]
ATTRS = ["name", "group", "value", "type", "link1", "link2", "base_link", "tip_link", "parent_link"]
ATTR_VALUES = st.sampled_from(["", " ", "nan", "1e999", "0 1", "hand", "panda_arm", "fixed"]) | (
    st.text(alphabet="ab 0.-e<&", max_size=5)
)


@given(
    st.lists(
        st.tuples(
            st.integers(min_value=0),
            st.sampled_from(["drop_attr", "set_attr", "rename", "remove", "duplicate"]),
            st.sampled_from(ATTRS),
            ATTR_VALUES,
            st.sampled_from(TAGS),
        ),
        min_size=1,
        max_size=4,
    )
)
def test_well_formed_mutants_raise_only_our_errors(
    edits: list[tuple[int, str, str, str, str]],
) -> None:
    from lxml import etree

    root = etree.fromstring(_seed_srdf())
    for index, action, attr, value, tag in edits:
        elements = [el for el in root.iter() if isinstance(el.tag, str)]
        el = elements[index % len(elements)]
        parent = el.getparent()
        if action == "drop_attr":
            el.attrib.pop(attr, None)
        elif action == "set_attr":
            el.set(attr, value)
        elif action == "rename":
            el.tag = tag
        elif parent is not None and action == "remove":
            parent.remove(el)
        elif parent is not None:
            parent.insert(parent.index(el), copy.deepcopy(el))
    data = etree.tostring(root)
    for strict in (True, False):
        try:
            srdf = parse_srdf_bytes(data, "mutant.srdf", strict=strict)
        except RobotSpecError as exc:
            assert all(d.file == "mutant.srdf" for d in exc.details)
            continue
        assert_same_srdf(parse_srdf_bytes(write_srdf(srdf).encode(), strict=strict), srdf)
