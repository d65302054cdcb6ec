"""Kinematic checks of ``validate`` on real robots: heights by FK, optical frames by rotation,
parts that cannot move, state order; each with its exact message.

The exact height bounds are also checked against brute force (a dense grid over the joints'
limits, FK of the whole world by :class:`~robotspec.model.kinematics.Kinematics`), and the joint
values each bound names are checked to reach it.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from robotspec.compiler import check_spec
from robotspec.compiler.heights import height_range
from robotspec.errors import RobotSpecError
from robotspec.model.kinematics import Kinematics
from robotspec.semantic import AbstractRobot
from robotspec.shipped import shipped_spec_files
from tests.conftest import erd_robots, shared_path


def _robot(name: str, *paths: str) -> AbstractRobot:
    robot = check_spec(name, package_paths=paths).robot
    assert robot is not None
    return robot


def _problems(tmp_path: Path, text: str, *paths: str) -> list[str]:
    """Rendered errors (else warnings) of a spec written to tmp_path/broken.yaml."""
    spec = tmp_path / "broken.yaml"
    spec.write_text(text)
    try:
        result = check_spec(spec, package_paths=paths)
    except RobotSpecError as exc:
        details = list(exc.details)
    else:
        details = [d for w in result.warnings for d in w.details]
    shipped = str(shipped_spec_files()["pr2"].parent) + "/"
    return [d.render().replace(f"{tmp_path}/", "").replace(shipped, "") for d in details]


def _height(robot: AbstractRobot, body: str, values: dict[str, float]) -> float:
    w = robot.world
    k = Kinematics(w)
    q = w.configuration(values)
    poses = k.forward(q)
    rel = np.linalg.solve(poses[robot.root.index], poses[w.get_body_by_name(body).index])
    return float(rel[2, 3])


@pytest.mark.parametrize(
    ("name", "body", "low", "high"),
    [
        ("pr2", "wide_stereo_optical_frame", 1.166, 1.583),
        ("tiago", "xtion_optical_frame", 0.948, 1.457),
    ],
)
def test_exact_heights_against_brute_force(name: str, body: str, low: float, high: float) -> None:
    erd_robots()
    robot = _robot(name)
    w = robot.world
    h = height_range(w, robot.root, w.get_body_by_name(body), w.configuration())
    assert h is not None and h.method == "exact"
    assert (round(h.low, 3), round(h.high, 3)) == (low, high)
    # The named joint values reach the bounds (FK of the whole world, not the check's own).
    assert _height(robot, body, dict(h.lowest_at)) == pytest.approx(h.low, abs=1e-9)
    assert _height(robot, body, dict(h.highest_at)) == pytest.approx(h.high, abs=1e-9)
    # No configuration on a dense grid (every joint of the chain, pans included) leaves them.
    moving = [
        c
        for c in w.compute_chain_of_connections(robot.root, w.get_body_by_name(body))
        if not c.is_fixed
    ]
    grids = [
        np.linspace(
            w.degrees_of_freedom[c.dofs[0]].lower, w.degrees_of_freedom[c.dofs[0]].upper, 25
        )
        for c in moving
    ]
    k = Kinematics(w)
    qs = np.repeat(w.configuration()[None], 25 ** len(moving), axis=0)
    for i, combo in enumerate(itertools.product(*grids)):
        for c, v in zip(moving, combo, strict=True):
            qs[i, c.dofs[0]] = v
    poses = k.forward_batch(qs)
    z = np.linalg.solve(poses[:, robot.root.index], poses[:, w.get_body_by_name(body).index])[
        :, 2, 3
    ]
    assert z.min() >= h.low - 1e-9 and z.max() <= h.high + 1e-9
    assert z.min() == pytest.approx(h.low, abs=5e-3) and z.max() == pytest.approx(h.high, abs=5e-3)


def test_shipped_specs_pass_every_check() -> None:
    erd_robots()
    for name in ("pr2", "tiago", "panda", "ur5", "dual_panda", "b1_ur5_allegro"):
        assert check_spec(name, strict=True).warnings == (), name


HSRB_HEAD = """robotspec: 1
extends: hsrb
sensors: {head_rgbd_camera: {minimal_height: 0.75, maximal_height: 0.99}}
"""


def test_hsrb_head_camera_heights_by_fk(tmp_path: Path) -> None:
    hsrb = str(shared_path("robots", "hsrb"))
    assert _problems(tmp_path, HSRB_HEAD, hsrb) == [
        "broken.yaml:3:46: error: sensors.head_rgbd_camera.minimal_height: FK puts "
        "'head_rgbd_sensor_link' between 0.832 and 1.326 m above 'base_footprint' over the limits "
        "of 'arm_lift_joint', 'head_tilt_joint' (exact: lifts, pans and one last joint); the "
        "spec says 0.75-0.99 (it is at 1.326 m at arm_lift_joint=0.69, head_tilt_joint=-0.3551; "
        "it never reaches the spec's 0.75 m); use 0.832-1.326"
    ]


def test_hsrb_base_fixed_camera(tmp_path: Path) -> None:
    hsrb = str(shared_path("robots", "hsrb"))
    text = (
        "robotspec: 1\nextends: hsrb\nsensors: {imu_cam: {type: camera, body: base_imu_frame, "
        "preset: kinect_v1, minimal_height: 0.2, maximal_height: 0.2}}\n"
    )
    assert _problems(tmp_path, text, hsrb) == [
        "broken.yaml:3:92: error: sensors.imu_cam.minimal_height: FK puts 'base_imu_frame' at "
        "0.181 m above 'base_footprint' (no joint moves it); the spec says 0.2-0.2; use "
        "0.181-0.181"
    ]


def test_hsrb_optical_frame_by_rotation(tmp_path: Path) -> None:
    hsrb = str(shared_path("robots", "hsrb"))
    text = (
        "robotspec: 1\nextends: hsrb\n"
        "sensors: {head_center_camera: {forward_facing_axis: [1, 0, 0]}}\n"
    )
    # 'head_center_camera_frame' is not named *_optical_frame; its rotation makes it one.
    assert _problems(tmp_path, text, hsrb) == [
        "broken.yaml:3:53: error: sensors.head_center_camera.forward_facing_axis: "
        "'head_center_camera_frame' is an optical frame by its rotation in 'head_tilt_link' "
        "(REP 103: z forward, x right, y down), so the camera looks along +z; the axis [1, 0, 0] "
        "looks to the robot's right"
    ]


def test_hsrb_hand_camera_is_sampled_and_its_witnesses_reach_the_bounds() -> None:
    robot = _robot("hsrb", str(shared_path("robots", "hsrb")))
    w = robot.world
    h = height_range(w, robot.root, w.get_body_by_name("hand_camera_frame"), w.configuration())
    assert h is not None and h.method == "sampled"
    assert h.joints[:2] == ("arm_lift_joint", "arm_flex_joint")
    assert _height(robot, "hand_camera_frame", dict(h.lowest_at)) == pytest.approx(h.low)
    assert _height(robot, "hand_camera_frame", dict(h.highest_at)) == pytest.approx(h.high)
    assert (round(h.low, 2), round(h.high, 2)) == (-0.10, 1.51)


def test_tiago_torso_states_in_the_wrong_order(tmp_path: Path) -> None:
    erd_robots()
    text = (
        "robotspec: 1\nextends: tiago\n"
        "torso: {states: {low: {torso_lift_joint: 0.35}, high: {torso_lift_joint: 0.0}}}\n"
    )
    assert _problems(tmp_path, text) == [
        "broken.yaml:3:55: error: torso.states.high: state 'high' of the torso gives the height "
        "of 'torso_lift_link' 0.888 m, state 'mid' 1.063 m: 'high' must give more than 'mid' "
        "(swapped?)",
        "tiago.yaml:17:10: error: torso.states.mid: state 'mid' of the torso gives the height "
        "of 'torso_lift_link' 1.063 m, state 'low' 1.238 m: 'mid' must give more than 'low' "
        "(swapped?)",
    ]


def test_panda_flange_chain_cannot_move_and_gripper_order(tmp_path: Path) -> None:
    erd_robots()
    text = (
        "robotspec: 1\nextends: panda\n"
        "chains: {flange: {root: panda_link7, tip: panda_link8, kind: chain}}\n"
    )
    assert _problems(tmp_path, text) == [  # a kind: chain needs no manipulator or sensor
        "broken.yaml:3:18: warning: chains.flange: chain 'flange' cannot move: every joint from "
        "'panda_link7' to 'panda_link8' is fixed ('panda_joint8'); 'panda_joint7' moves "
        "'panda_link7': start at 'panda_link6'?",
    ]
    text = (
        "robotspec: 1\nextends: panda\nmanipulators: {hand: {states: "
        "{open: {panda_finger_joint1: 0.0}, close: {panda_finger_joint1: 0.04}}}}\n"
    )
    assert _problems(tmp_path, text) == [
        "broken.yaml:3:38: error: manipulators.hand.states.open: state 'open' of manipulator "
        "'hand' gives the distance between 'panda_leftfinger' and 'panda_rightfinger' 0.000 m, "
        "state 'close' 0.080 m: 'open' must give more than 'close' (swapped?)"
    ]


def test_inspect_notes_srdf_off_and_no_controlled_joints(tmp_path: Path) -> None:
    erd_robots()
    from robotspec.cli.app import app

    spec = tmp_path / "quiet.yaml"
    spec.write_text(
        "robotspec: 1\nextends: pr2\ncollision: {use_srdf: false}\ncontrolled_joints: []\n"
    )
    res = CliRunner().invoke(app, ["inspect", "collisions", str(spec)])
    assert res.exit_code == 0, res.output
    assert res.stderr.splitlines() == [
        "note: the spec turns the SRDF's collision rules off (collision: {use_srdf: false}): "
        "its 1163 disable_collisions entries are not applied",
        "note: the spec controls no joints (controlled_joints: [])",
    ]
    plain = CliRunner().invoke(app, ["inspect", "joints", "pr2"])
    assert plain.exit_code == 0 and "note:" not in plain.stderr


def test_hsrb_two_default_cameras(tmp_path: Path) -> None:
    hsrb = str(shared_path("robots", "hsrb"))
    text = "robotspec: 1\nextends: hsrb\nsensors: {head_rgbd_camera: {default: true}}\n"
    assert _problems(tmp_path, text, hsrb) == [
        "broken.yaml:3:39: error: sensors.head_rgbd_camera.default: cameras "
        "'head_center_camera' (hsrb.yaml:91) and 'head_rgbd_camera' are both the default "
        "camera; the first would win silently: mark one"
    ]


def test_tiago_field_of_view_swapped_and_camera_copy(tmp_path: Path) -> None:
    erd_robots()
    text = (
        "robotspec: 1\nextends: tiago\n"
        "sensors: {head_camera: {field_of_view: {horizontal: 0.7854, vertical: 1.0123}}}\n"
    )
    assert _problems(tmp_path, text) == [
        "broken.yaml:3:40: warning: sensors.head_camera.field_of_view: the field of view is "
        "taller than wide (vertical 1.0123 > horizontal 0.7854 rad): swapped? a landscape image "
        "is wider than tall"
    ]
    text = (
        "robotspec: 1\nextends: tiago\nneck: {sensors: [head_camera, copy]}\n"
        "sensors: {copy: {type: camera, body: xtion_optical_frame, preset: xtion_pro_live}}\n"
    )
    assert _problems(tmp_path, text) == [
        "broken.yaml:4:38: warning: sensors.copy.body: cameras 'head_camera' and 'copy' are on "
        "the same frame 'xtion_optical_frame' (a copy-paste?)"
    ]


def test_panda_copied_arm_and_tool_frame(tmp_path: Path) -> None:
    erd_robots()
    text = (
        "robotspec: 1\nextends: panda\n"
        "chains: {arm2: {root: panda_link0, tip: panda_link8, manipulator: hand2}}\n"
        "manipulators: {hand2: {type: generic, root: panda_hand, tool_frame: panda_hand_tcp}}\n"
    )
    assert _problems(tmp_path, text) == [
        "broken.yaml:3:16: error: chains.arm2: chain 'arm2' has the same links as chain 'arm' "
        "('panda_link0' -> 'panda_link8'); a copy-paste? give each part its own root and tip",
        "broken.yaml:4:69: error: manipulators.hand2.tool_frame: manipulators 'hand' and "
        "'hand2' share the tool frame 'panda_hand_tcp'; one gripper has one tool frame",
    ]


def test_non_camera_hint_by_name_and_mesh() -> None:
    from robotspec.compiler.part_checks import non_camera_hint
    from robotspec.model.geometry import Mesh, Shape
    from robotspec.model.world import Body

    eye = np.eye(4)
    scanner = Body(
        "front_mount", 3, visuals=(Shape(Mesh("package://x/hokuyo_utm30lx.dae", None), eye),)
    )
    assert non_camera_hint(scanner) == "its mesh 'hokuyo_utm30lx.dae' is a Hokuyo laser scanner"
    assert non_camera_hint(Body("base_imu_frame", 1)) == "its name says an IMU ('imu')"
    assert non_camera_hint(Body("head_rgbd_sensor_link", 2)) is None


def test_baxter_finger_that_cannot_move_names_the_joint_above(tmp_path: Path) -> None:
    erd_robots()
    base = Path(__file__).resolve().parent / "data" / "own_robots" / "baxter.yaml"
    text = (
        f"robotspec: 1\nextends: {base}\n"
        "manipulators: {left_gripper: {thumb: {root: l_gripper_l_finger}}}\n"
    )
    # The base lies outside the spec's project (tmp_path): the user allows its folder.
    assert _problems(tmp_path, text, str(base.parent)) == [
        "broken.yaml:3:38: warning: manipulators.left_gripper.thumb: thumb of 'left_gripper' "
        "cannot move: every joint from 'l_gripper_l_finger' to 'l_gripper_l_finger_tip' is fixed "
        "('l_gripper_l_finger_tip_joint'); 'l_gripper_l_finger_joint' moves 'l_gripper_l_finger': "
        "start at 'left_gripper_base_link'?"
    ]
