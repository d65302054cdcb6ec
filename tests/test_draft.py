"""``robotspec init``'s drafts: semantics found on real robots, and YAML that survives any name."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from robotspec.cli.app import app
from robotspec.cli.output import run_app
from robotspec.compiler import check_spec
from robotspec.model.entities import Body, Connection, ConnectionType, DegreeOfFreedom, Mimic
from robotspec.model.geometry import Box, Shape
from robotspec.model.world import World
from robotspec.spec.draft import Draft, draft_spec, render_draft
from robotspec.spec.draft.render import scalar
from robotspec.spec.draft.run import draft_from_files

from .conftest import erd_robots


def _draft(urdf: str, srdf: str | None, tmp_path: Path) -> tuple[Draft, str]:
    robots = erd_robots()
    draft, _ = draft_from_files(
        str(robots / urdf), None if srdf is None else str(robots / srdf), folder=tmp_path
    )
    text = render_draft(draft)
    out = tmp_path / "draft.yaml"
    out.write_text(text)
    assert check_spec(out).robot is not None  # the draft validates as written
    return draft, text


# ------------------------------------------------------------------------ real robots


def test_baxter_without_srdf_has_two_arms_grippers_neck(tmp_path: Path) -> None:
    # The issue: Baxter without its SRDF drafted `chains: {}`.
    d, text = _draft("baxter_description/urdf/baxter.urdf", None, tmp_path)
    arms = {c.name: (c.root, c.tip, c.manipulator) for c in d.chains}
    assert arms == {
        "left_arm": ("torso", "left_wrist", "left_gripper"),
        "right_arm": ("torso", "right_wrist", "right_gripper"),
    }
    grippers = {m.name: m for m in d.manipulators}
    right = grippers["right_gripper"]
    assert right.is_gripper and right.root == "right_gripper_base_link"
    # The thumb is the driven finger; the other one mimics it. Each ends at its fixed tip link.
    assert right.thumb is not None and right.thumb.tip == "r_gripper_l_finger_tip"
    assert right.finger is not None and right.finger.tip == "r_gripper_r_finger_tip"
    # Baxter's tool frame hangs on a joint named 'right_endpoint': found by its joint's name.
    assert right.tool_frame == "right_gripper"
    assert grippers["left_gripper"].tool_frame == "left_gripper"
    assert d.neck is not None and (d.neck.root, d.neck.tip) == ("torso", "head")
    assert d.neck.sensors == ["head_camera"]
    assert d.neck.yaw_body == "head"
    assert d.drive is not None and d.drive.type == "fixed"
    assert "DECIDE" in text


def test_panda_with_srdf_arm_group_and_parallel_gripper(tmp_path: Path) -> None:
    # The issue: the draft named the chain 'chain_1' and made the hand a generic manipulator.
    d, _ = _draft(
        "panda_description/urdf/panda.urdf", "panda_description/srdf/panda.srdf", tmp_path
    )
    # The group ends at panda_link7; the chain at the flange past it, where the files say.
    assert [(c.name, c.root, c.tip) for c in d.chains] == [("arm", "panda_link0", "panda_link8")]
    (hand,) = d.manipulators
    assert d.chains[0].manipulator == hand.name == "end_effector"  # the SRDF's own name
    assert hand.is_gripper and hand.root == "panda_hand" and hand.tool_frame == "panda_hand_tcp"
    assert hand.thumb is not None and hand.thumb.tip == "panda_leftfinger"  # panda_finger_joint1
    assert hand.finger is not None and hand.finger.tip == "panda_rightfinger"  # its mimic
    # Grasping along the hand's reach: the TCP's +z, as the hand-written spec says.
    assert hand.front_facing == pytest.approx((0.0, 0.7071068, 0.0, 0.7071068))
    # The SRDF's 'default' state of 'arm_and_hand' is split among the parts it sets.
    assert set(d.chains[0].states["default"]) == {f"panda_joint{i}" for i in range(1, 8)}
    assert d.drive is not None and d.drive.type == "fixed"


def test_talos_groups_of_joints_and_feet(tmp_path: Path) -> None:
    # The issue: groups listing joints plus a chain were skipped; the feet were rooted at base.
    d, _ = _draft("talos_data/robots/talos_reduced.urdf", "talos_data/srdf/talos.srdf", tmp_path)
    chains = {c.name: c for c in d.chains}
    assert set(chains) == {"l_arm", "r_arm", "l_leg", "r_leg"}
    assert chains["l_leg"].role == "leg" and chains["l_arm"].role == "arm"
    feet = {m.name: m for m in d.manipulators if m.name.endswith("_foot")}
    assert feet["l_leg_foot"].root == "left_sole_link" if "l_leg_foot" in feet else True
    roots = {m.root for m in d.manipulators}
    assert "base_link" not in roots
    assert {"left_sole_link", "right_sole_link"} <= roots
    assert d.torso is not None and d.torso.joints == {"torso_1_joint", "torso_2_joint"}
    assert d.neck is not None and d.neck.joints == {"head_1_joint", "head_2_joint"}
    assert d.drive is not None and d.drive.type == "floating"
    # The SRDF's one state (group 'all') becomes a state of every part.
    for part in [*d.chains, d.torso, d.neck]:
        assert "half_sitting" in part.states, part.name
    # IMUs are not cameras.
    assert [c.body for c in d.cameras] == ["rgbd_optical_frame"]


def test_pr2_imu_and_laser_are_not_cameras_and_stereo_is_one_camera(tmp_path: Path) -> None:
    d, _ = _draft("pr2_description/urdf/pr2.urdf", "pr2_description/srdf/pr2.srdf", tmp_path)
    bodies = {c.body for c in d.cameras}
    assert "imu_link" not in bodies and "base_laser_link" not in bodies
    assert "wide_stereo_optical_frame" in bodies
    assert not any("gazebo" in b for b in bodies)  # a simulated channel of wide_stereo
    # Every camera rotated as REP 103 says is optical; the forearm cameras ride on the arms.
    assert all(c.optical for c in d.cameras)
    arms = {c.name: c for c in d.chains}
    assert arms["left_arm"].sensors == ["l_forearm_cam"]
    assert d.neck is not None and "wide_stereo" in d.neck.sensors
    assert d.torso is not None and (d.torso.root, d.torso.tip) == ("base_link", "torso_lift_link")


def test_tiago_without_srdf_torso_neck_differential_hand(tmp_path: Path) -> None:
    d, _ = _draft("tiago_description/robots/tiago.urdf", None, tmp_path)
    # The arm ends at its flange, one fixed joint past arm_7_link (issue 30).
    assert [(c.name, c.root, c.tip) for c in d.chains] == [
        ("arm", "torso_lift_link", "arm_tool_link")
    ]
    (hand,) = d.manipulators
    # Five fingers: a hand, not a parallel gripper; its tool frame is in its own subtree.
    assert not hand.is_gripper and hand.name == "hand"
    assert (hand.root, hand.tool_frame) == ("hand_palm_link", "hand_grasping_frame")
    assert d.torso is not None and (d.torso.root, d.torso.tip) == (
        "torso_fixed_link",
        "torso_lift_link",
    )
    assert d.neck is not None and (d.neck.root, d.neck.tip) == ("torso_lift_link", "head_2_link")
    assert (d.neck.yaw_body, d.neck.pitch_body) == ("head_1_link", "head_2_link")
    assert [c.body for c in d.cameras] == ["xtion_optical_frame"]
    assert d.drive is not None and d.drive.type == "differential"


def test_legs_are_named_front_hind_left_right(tmp_path: Path) -> None:
    d, _ = _draft("laikago_description/urdf/laikago.urdf", None, tmp_path)
    legs = {c.name: c.tip for c in d.chains}
    assert set(legs) == {"front_left_leg", "front_right_leg", "hind_left_leg", "hind_right_leg"}
    assert legs["front_left_leg"].startswith("FL")
    assert all(c.role == "leg" for c in d.chains)
    assert d.drive is not None and d.drive.type == "floating"


def test_a_hand_alone_is_not_an_arm(tmp_path: Path) -> None:
    # The Allegro hand's fingers are four serial runs of four joints: never arms.
    d, _ = _draft("allegro_hand_description/urdf/allegro_right_hand.urdf", None, tmp_path)
    assert d.chains == []
    # It is drafted as the hand it is: rooted at its palm, its thumb the finger off the row of
    # the others (joints 12-15, as the shipped part spec says), a tool frame among the tips.
    (hand,) = d.manipulators
    assert hand.is_hand and hand.root == "palm_link" and d.lone_hand == hand.name
    assert hand.thumb is not None and (hand.thumb.root, hand.thumb.tip) == (
        "link_12.0",
        "link_15.0_tip",
    )
    assert {f.root for f in hand.fingers.values()} == {"link_0.0", "link_4.0", "link_8.0"}
    assert [f.parent for f in d.frames] == ["palm_link"]


# ------------------------------------------------------------------ YAML of any name

_NAMES = st.text(
    alphabet=st.characters(codec="utf-8", exclude_categories=["Cs"]), min_size=1, max_size=12
)


def _world(names: list[str]) -> World:
    """A base, a 4-joint arm, a two-finger gripper and a camera on a 2-joint head, named freely."""
    box = (Shape(Box((0.05, 0.05, 0.05)), np.eye(4)),)
    bodies: list[Body] = []
    conns: list[Connection] = []
    dofs: list[DegreeOfFreedom] = []

    def add(
        parent: int | None,
        kind: ConnectionType,
        xyz: tuple[float, float, float],
        rot: np.ndarray | None = None,
        mimic: str | None = None,
        geo: bool = True,
    ) -> int:
        i = len(bodies)
        bodies.append(Body(names[i], i, collisions=box if geo else ()))
        if parent is None:
            return i
        origin = np.eye(4)
        origin[:3, 3] = xyz
        if rot is not None:
            origin[:3, :3] = rot
        dof: tuple[int, ...] = ()
        if kind is not ConnectionType.FIXED:
            if mimic is None:
                joint = f"{names[i]}#joint"
                dofs.append(DegreeOfFreedom(joint, len(dofs), joint, -1.0, 1.0))
                dof = (len(dofs) - 1,)
            else:
                dof = (len(dofs) - 1,)
        conns.append(
            Connection(
                f"{names[i]}#joint",
                len(conns),
                kind,
                parent,
                i,
                origin,
                (0.0, 0.0, 1.0),
                dof,
                Mimic(mimic) if mimic else None,
            )  # fmt: skip
        )
        return i

    rev, fix, pri = ConnectionType.REVOLUTE, ConnectionType.FIXED, ConnectionType.PRISMATIC
    base = add(None, fix, (0, 0, 0))
    torso = add(base, fix, (0, 0, 0.5))
    link = torso
    for _ in range(4):
        link = add(link, rev, (0.2, 0, 0))
    hand = add(link, fix, (0.1, 0, 0))
    thumb = add(hand, pri, (0.05, 0.02, 0))
    add(hand, pri, (0.05, -0.02, 0), mimic=f"{names[thumb]}#joint")
    pan = add(torso, rev, (0, 0, 0.3))
    tilt = add(pan, rev, (0, 0, 0.1))
    optical = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    add(tilt, fix, (0.1, 0, 0), rot=optical, geo=False)
    return World(names[0], bodies, conns, dofs)


N_BODIES = 12


@given(st.lists(_NAMES, min_size=N_BODIES, max_size=N_BODIES, unique=True))
def test_any_names_round_trip_through_the_draft_yaml(names: list[str]) -> None:
    world = _world(names)
    d = draft_spec(world, urdf_ref=names[1], srdf=None, srdf_ref=None, name=names[2])
    text = render_draft(d)
    data = yaml.safe_load(text)  # never breaks, whatever the names hold
    # Only the keys the draft writes, nothing a name injected.
    allowed = {"robotspec", "name", "description", "root", "drive", "torso", "neck", "chains"}
    allowed |= {"manipulators", "sensors", "states", "accept_warnings"}
    assert set(data) <= allowed
    assert data["name"] == names[2]
    assert data["description"]["urdf"] == names[1]
    assert data["root"] == names[0]
    assert set(data["chains"]) == {c.name for c in d.chains}
    for c in d.chains:
        assert data["chains"][c.name]["tip"] == c.tip
    for m in d.manipulators:
        assert data["manipulators"][m.name]["root"] == m.root
    for cam in d.cameras:
        assert data["sensors"][cam.name]["body"] == cam.body
    # Every line is one YAML line: no name opened a new one.
    assert len(text.splitlines()) == text.count("\n")


@given(_NAMES)
def test_scalar_reads_back_as_itself(name: str) -> None:
    assert yaml.safe_load(f"key: {scalar(name)}")["key"] == name


@pytest.mark.parametrize(
    "name", ["null", "true", "yes", "No", "~", ".inf", "-.nan", "1e3", "0x1f", "a: b", "#x", "-"]
)
def test_scalar_quotes_what_yaml_would_read_otherwise(name: str) -> None:
    assert yaml.safe_load(f"key: {scalar(name)}")["key"] == name
    assert not math.isnan(len(scalar(name)))


def test_newline_in_a_link_name_does_not_inject_keys(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    # The issue: a link name with a newline landed raw in a YAML comment; its second line
    # became a key that validated.
    urdf = tmp_path / "bad.urdf"
    evil = "tip&#10;velocity_limits: {default: 0.001}"
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="{p}"/><child link="{c}"/>'
        f'<origin xyz="0.2 0 0"/><axis xyz="0 0 1"/>'
        f'<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        for i, (p, c) in enumerate([("base", "l1"), ("l1", "l2"), ("l2", evil)])
    )
    links = "".join(f'<link name="{n}"/>' for n in ("base", "l1", "l2", evil))
    urdf.write_text(f'<robot name="bad">{links}{joints}</robot>')
    out = tmp_path / "bad.yaml"
    assert run_app(app, ["init", str(urdf), "-o", str(out)]) == 0
    capsys.readouterr()
    data = yaml.safe_load(out.read_text())
    assert "velocity_limits" not in data
    (chain,) = data["chains"].values()
    assert chain["tip"] == "tip\nvelocity_limits: {default: 0.001}"
    assert check_spec(out).robot is not None


def test_no_machine_path_in_a_draft(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    # The issue: the draft pointed its schema at a file:// path of the author's machine.
    robots = erd_robots()
    out = tmp_path / "sub" / "ur5.yaml"
    out.parent.mkdir()
    urdf = robots / "ur_description/urdf/ur5_robot.urdf"
    assert run_app(app, ["init", str(urdf), "-o", str(out)]) == 0
    capsys.readouterr()
    text = out.read_text()
    assert text.startswith("# yaml-language-server: $schema=robotspec.schema.json\n")
    assert "file://" not in text and str(Path.home()) not in text and str(tmp_path) not in text
    assert str(robots) not in text and "templates" not in text.split("robotspec: 1")[0]
    assert "robotspec templates" not in text


# ------------------------------------------------------------ SRDF forms, shared robots


HOME = {1: 0.1, 2: 0.1, 3: 0.1, 4: -1.0, 5: 0.1, 6: 1.0, 7: 0.1}


def test_srdf_groups_of_links_and_subgroups(tmp_path: Path) -> None:
    # Every group form: links make the arm, subgroups a whole-robot group whose state is split.
    robots = erd_robots()
    srdf = tmp_path / "panda_links.srdf"
    links = "".join(f'<link name="panda_link{i}"/>' for i in range(1, 8))
    srdf.write_text(
        '<robot name="panda">'
        f'<group name="manipulator">{links}</group>'
        '<group name="fingers"><joint name="panda_finger_joint1"/>'
        '<joint name="panda_finger_joint2"/></group>'
        '<group name="whole"><group name="manipulator"/><group name="fingers"/></group>'
        '<group_state name="home" group="whole">'
        + "".join(f'<joint name="panda_joint{i}" value="{v}"/>' for i, v in HOME.items())
        + '<joint name="panda_finger_joint1" value="0.02"/></group_state>'
        '<group_state name="bad" group="manipulator">'
        + "".join(f'<joint name="panda_joint{i}" value="0.1"/>' for i in range(1, 8))
        + "</group_state>"
        '<end_effector name="gripper" parent_link="panda_link8" group="fingers"'
        ' parent_group="manipulator"/>'
        "</robot>"
    )
    draft, _ = draft_from_files(
        str(robots / "panda_description/urdf/panda.urdf"), str(srdf), folder=tmp_path
    )
    out = tmp_path / "d.yaml"
    out.write_text(render_draft(draft))
    check_spec(out)
    (chain,) = draft.chains
    assert (chain.name, chain.root, chain.tip) == ("manipulator", "panda_link0", "panda_link8")
    assert chain.group is None  # not one <chain>: written as root and tip
    assert chain.states == {"home": {f"panda_joint{i}": v for i, v in HOME.items()}}
    # A state outside a joint's limits is left out, and the draft says why.
    assert "SRDF state 'bad' of 'manipulator' left out: 'panda_joint4'" in " ".join(draft.notes)
    (m,) = draft.manipulators
    assert (m.name, m.is_gripper, m.root) == ("gripper", True, "panda_hand")
    assert chain.manipulator == "gripper"
    assert m.states == {"home": {"panda_finger_joint1": 0.02}}


def test_pr2_from_its_tree_alone_matches_the_hand_written_parts(tmp_path: Path) -> None:
    # The xacro-made PR2 without any SRDF: torso, neck and arms as specs/pr2.yaml has them.
    from .conftest import shared_path

    urdf = shared_path("robots", "pr2", "pr2.urdf")
    draft, _ = draft_from_files(str(urdf), None, folder=tmp_path, package_paths=[urdf.parent])
    assert draft.torso is not None and (draft.torso.root, draft.torso.tip) == (
        "base_link",
        "torso_lift_link",
    )
    assert draft.neck is not None and (draft.neck.root, draft.neck.tip) == (
        "torso_lift_link",
        "head_tilt_link",
    )
    arms = {c.name: (c.root, c.tip) for c in draft.chains}
    assert arms == {
        "left_arm": ("torso_lift_link", "l_wrist_roll_link"),
        "right_arm": ("torso_lift_link", "r_wrist_roll_link"),
    }
    right = next(m for m in draft.manipulators if m.name == "right_gripper")
    assert right.finger is not None and right.finger.tip == "r_gripper_r_finger_tip_link"
    assert draft.drive is not None and draft.drive.type == "omni"


def test_hsrb_neck_above_a_lift(tmp_path: Path) -> None:
    # HSR-B's head rides on a lift that mimics the arm's: the neck is the two revolute joints.
    from .conftest import shared_path

    hsrb = shared_path("robots", "hsrb")
    draft, _ = draft_from_files(
        str(hsrb / "hsrb4s.urdf"),
        str(hsrb / "hsrb_moveit_config/config/hsrb.srdf"),
        folder=tmp_path,
        package_paths=[hsrb],
    )
    n = draft.neck
    assert n is not None and (n.root, n.tip) == ("torso_lift_link", "head_tilt_link")
    assert (n.yaw_body, n.pitch_body) == ("head_pan_link", "head_tilt_link")
    assert "head_rgbd_sensor" in n.sensors


def test_linkage_gripper_of_tiago_pro(tmp_path: Path) -> None:
    # Robotiq-style: four branches (inner and outer links, two a side) moved by one actuator.
    d, _ = _draft("tiago_pro_description/robots/tiago_pro.urdf", None, tmp_path)
    left = next(m for m in d.manipulators if m.name == "left_gripper")
    assert left.is_gripper
    # The thumb is the side holding the driven joint (gripper_left_finger_joint).
    assert left.thumb is not None and left.thumb.tip == "gripper_left_fingertip_left_link"
    assert left.finger is not None and left.finger.tip == "gripper_left_fingertip_right_link"


def test_a_one_motor_hand_with_a_thumb_is_not_a_gripper(tmp_path: Path) -> None:
    d, _ = _draft(
        "romeo_description/urdf/romeo.urdf", "romeo_description/srdf/romeo.srdf", tmp_path
    )
    assert not any(m.is_gripper for m in d.manipulators)


def test_legs_coded_fore_and_hind_say_which_way_the_robot_faces(tmp_path: Path) -> None:
    # example-robot-data's quadruped: 2-joint legs coded FL/FR/BL/BR, its front legs at +y.
    d, text = _draft("quadruped_description/urdf/quadruped.urdf", None, tmp_path)
    assert d.forward == (0.0, 1.0, 0.0) and "DECIDE" in text.split("forward:")[1].split("\n")[0]
    legs = {c.name: c.tip for c in d.chains}
    assert legs == {  # each ends at its foot's contact frame, fixed past the shank (issue 30)
        "front_left_leg": "FL_contact",
        "front_right_leg": "FR_contact",
        "hind_left_leg": "BL_contact",
        "hind_right_leg": "BR_contact",
    }
    assert d.drive is not None and d.drive.type == "floating"


def test_a_leg_the_srdf_leaves_out_is_named_by_its_code(tmp_path: Path) -> None:
    d, _ = _draft(
        "hyq_description/robots/hyq_no_sensors.urdf", "hyq_description/srdf/hyq.srdf", tmp_path
    )
    assert sorted(c.name for c in d.chains) == ["lf_leg", "lh_leg", "rf_leg", "rh_leg"]
