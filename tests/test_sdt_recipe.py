"""The SDT mapping as data (robotspec.interop.sdt.mapping, .recipe): runs without SDT installed.

What each robotspec part becomes in SDT, which joints get hardware interfaces, which states
keep an SDT kind, and that importing robotspec (or the bridge package) never imports SDT.
"""

from __future__ import annotations

import json
import subprocess
import sys
from functools import cache
from pathlib import Path

import pytest

from robotspec.errors import RobotSpecError
from robotspec.interop.sdt.mapping import STATE_KINDS, robot_recipe
from robotspec.interop.sdt.recipe import RobotRecipe
from robotspec.semantic import AbstractRobot
from tests.conftest import erd_robots, shared_path

ROOT = Path(__file__).resolve().parents[1]


@cache
def _robot(name: str) -> AbstractRobot:
    from robotspec.robots import load

    paths = [shared_path("robots", "hsrb")] if name == "hsrb" else []
    return load(name, package_paths=paths)


def _pr2() -> AbstractRobot:
    erd_robots()
    return _robot("pr2")


def test_pr2_parts_are_sdt_kinds_in_sdt_slots() -> None:
    robot = _pr2()
    recipe = robot_recipe(robot)
    parts = recipe.parts()
    assert len(parts) == 12
    assert [s for s, _ in recipe.children] == ["mobile_base"]
    (base,) = recipe.slot("mobile_base")
    (torso,) = base.slot("torso")
    assert (base.root, torso.root, torso.tip) == ("base_link", "base_link", "torso_lift_link")
    left, right = torso.slot("arms")
    assert (left.tip, right.tip) == (robot.left_arm.tip.name, robot.right_arm.tip.name)
    (gripper,) = left.slot("end_effector")
    thumb, finger = gripper.slot("fingers")
    manipulator = robot.left_arm.manipulator
    assert manipulator is not None
    assert gripper.tool_frame == manipulator.tool_frame.name
    assert thumb.root == "l_gripper_l_finger_link"  # the thumb is SDT's first finger
    assert finger.root == "l_gripper_r_finger_link"
    (neck,) = torso.slot("neck")
    (kinect,) = neck.slot("sensors")
    assert kinect.kind == "camera" and kinect.default_camera
    assert kinect.minimal_height == robot.cameras[0].minimal_height


def test_hardware_interfaces_are_the_controlled_joints_that_move_a_chain() -> None:
    robot = _pr2()
    recipe = robot_recipe(robot)
    hardware = [j for p in recipe.parts() for j in p.hardware_joints]
    assert len(hardware) == len(set(hardware)) == 17
    controlled = {c.name for c in robot.controlled_connections}
    assert set(hardware) < controlled
    # Left without: the grippers (their own action commands them) and the laser tilt (no chain).
    assert controlled - set(hardware) == {
        "l_gripper_l_finger_joint",
        "r_gripper_l_finger_joint",
        "laser_tilt_mount_joint",
    }
    assert recipe.extra_hardware_joints == ()


def test_a_mimic_leader_moves_the_chain_of_its_follower() -> None:
    # HSRB's torso_lift_joint follows arm_lift_joint: the torso's hardware joint is the leader.
    robot = _robot("hsrb")
    recipe = robot_recipe(robot)
    (base,) = recipe.slot("mobile_base")
    (torso,) = base.slot("torso")
    assert torso.hardware_joints == ("arm_lift_joint",)
    assert [s.joints for s in torso.states][1] == (("arm_lift_joint", 0.34),)


def test_the_mobile_base_starts_at_the_base_body_sdts_classes_name() -> None:
    # The body with the base's collision geometry (coraplex plans with its box): SDT's PR2,
    # TIAGo and HSR-B classes name base_link, below a bare base_footprint root; for TIAGo the
    # torso starts elsewhere (torso_fixed_link), where the base used to be rooted.
    erd_robots()
    for name in ("pr2", "tiago", "hsrb"):
        robot = _robot(name)
        assert not robot.root.collisions
        (base,) = robot_recipe(robot).slot("mobile_base")
        assert base.root == "base_link", name
    assert _robot("tiago").torso.root.name == "torso_fixed_link"


def test_states_keep_their_sdt_kind_and_the_rest_is_reported() -> None:
    robot = _pr2()
    recipe = robot_recipe(robot)
    kinds = {(p.name, s.name): s.kind for p in recipe.parts() for s in p.states}
    assert kinds[("torso", "mid")] == ("TorsoState", "MID")
    assert kinds[("left_arm", "park")] == ("StaticJointState", "PARK")
    assert kinds[("right_gripper", "close")] == ("GripperState", "CLOSE")
    assert len(kinds) == len(robot.joint_states)
    assert recipe.left_out == ()
    erd_robots()
    panda = robot_recipe(_robot("panda"))
    assert "ready" not in STATE_KINDS
    assert any("'arm.ready'" in note for note in panda.left_out)


def test_other_chains_are_left_out_but_named_joints_keep_interfaces(tmp_path: Path) -> None:
    erd_robots()
    spec = tmp_path / "lift.yaml"
    spec.write_text(
        "robotspec: 1\nname: PR2Lift\nextends: pr2\n"
        "chains:\n  tilt: {root: torso_lift_link, tip: laser_tilt_mount_link, kind: chain}\n"
        "controlled_joints: [torso_lift_joint, head_pan_joint, laser_tilt_mount_joint,"
        " l_gripper_l_finger_joint]\n",
        encoding="utf-8",
    )
    from robotspec.compiler import compile_robot

    recipe = robot_recipe(compile_robot(spec))
    assert any(note.startswith("chain 'tilt'") for note in recipe.left_out)
    # Named joints keep hardware interfaces wherever they are: on no SDT part, the robot's.
    assert sorted(recipe.extra_hardware_joints) == [
        "l_gripper_l_finger_joint",
        "laser_tilt_mount_joint",
    ]
    on_parts = {j for p in recipe.parts() for j in p.hardware_joints}
    assert on_parts == {"torso_lift_joint", "head_pan_joint"}


def test_a_robot_gives_equal_recipes_and_json_keeps_them() -> None:
    erd_robots()
    from robotspec.robots import load

    first, second = robot_recipe(load("pr2")), robot_recipe(load("pr2"))
    assert first == second and first.digest() == second.digest()
    again = RobotRecipe.from_json(json.loads(json.dumps(first.to_json())))
    assert again == first and again.digest() == first.digest()
    other = robot_recipe(_robot("tiago"))
    assert other.digest() != first.digest()


def test_importing_robotspec_and_the_bridge_does_not_import_sdt() -> None:
    code = (
        "import sys, robotspec, robotspec.interop.sdt, robotspec.interop.sdt.mapping\n"
        "robotspec.load_robot\n"
        "print(sorted(m for m in sys.modules if m.startswith('semantic_digital_twin')))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == "[]"


def test_without_sdt_the_bridge_says_how_to_install_it(monkeypatch: pytest.MonkeyPatch) -> None:
    from robotspec.interop import sdt

    # Every SDT module as if absent: where SDT is installed, earlier tests imported them.
    for name in [m for m in sys.modules if m.split(".")[0] == "semantic_digital_twin"]:
        monkeypatch.setitem(sys.modules, name, None)
    monkeypatch.setitem(sys.modules, "semantic_digital_twin", None)
    monkeypatch.delitem(sys.modules, "robotspec.interop.sdt._api", raising=False)
    # Where SDT is installed an earlier test imported the module: the package holds it too.
    monkeypatch.delattr(sdt, "_api", raising=False)
    # ... and its distribution as if not installed (the message tells a missing SDT from an
    # installed one that lacks a module by the installed distributions).
    from robotspec.interop.sdt import install

    monkeypatch.setattr(install, "_installed", lambda distribution: None)
    with pytest.raises(RobotSpecError, match=r"pip install 'robotspec\[sdt\]'"):
        sdt.sdt_api()


def test_without_sdt_the_migrate_command_says_how_to_install_it(
    capsys: pytest.CaptureFixture[str],
) -> None:
    import importlib.util

    if importlib.util.find_spec("semantic_digital_twin") is not None:
        pytest.skip("SDT is installed here; tests/test_sdt_migrate.py runs the command")
    from robotspec.cli.app import app
    from robotspec.cli.output import run_app

    argv = ["migrate", "sdt", "semantic_digital_twin.robots.pr2:PR2", "--urdf", "pr2.urdf"]
    assert run_app(app, argv) == 1
    assert "pip install 'robotspec[sdt]'" in capsys.readouterr().err


def test_a_hand_is_an_end_effector_with_its_thumb_first() -> None:
    erd_robots()
    recipe = robot_recipe(_robot("b1_ur5_allegro"))
    (hand,) = [p for p in recipe.parts() if p.kind == "end_effector"]
    fingers = hand.slot("fingers")
    assert [(f.kind, f.name, f.root, f.tip) for f in fingers] == [
        ("finger", f"allegro_hand_{n}", f"allegro_link_{r}.0", f"allegro_link_{t}.0_tip")
        for n, r, t in (("thumb", 12, 15), ("index", 0, 3), ("middle", 4, 7), ("ring", 8, 11))
    ]


def pr2_elsewhere(folder: Path) -> Path:
    """example-robot-data's PR2 copied under ``folder`` (another install): its package folder."""
    import shutil

    share = erd_robots().parent
    copy = folder / "share" / "example-robot-data"
    (copy / "robots").mkdir(parents=True)
    shutil.copy2(share / "package.xml", copy / "package.xml")
    shutil.copytree(share / "robots" / "pr2_description", copy / "robots" / "pr2_description")
    return folder / "share"


def test_the_digest_is_the_robots_not_the_install_paths(tmp_path: Path) -> None:
    # Issue 32: the class names (the digest) travel in pickles and world histories; the same
    # spec read from files installed elsewhere must give the same recipe and digest.
    from robotspec.robots import load

    here = _pr2()
    there = load("pr2", package_paths=[pr2_elsewhere(tmp_path)])
    assert there.world.source is not None and there.world.source.startswith(str(tmp_path))
    assert here.world.source != there.world.source
    first, second = robot_recipe(here), robot_recipe(there)
    # The package as its package.xml names it (example-robot-data's declares
    # example_robot_descriptions), the file relative to it.
    assert first.source.startswith("package://")
    assert first.source.endswith("/robots/pr2_description/urdf/pr2.urdf")
    assert first == second and first.digest() == second.digest()
    assert first.name == "PR2"
    assert str(tmp_path) not in json.dumps(second.to_json())


def test_recipes_are_written_only_where_the_user_asks(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from robotspec.interop.sdt.classes import class_store, remember

    recipe = robot_recipe(_pr2())
    monkeypatch.delenv("ROBOTSPEC_SDT_CLASSES", raising=False)
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    assert class_store() is None and remember(recipe) is None  # the default: in memory
    assert not any(tmp_path.iterdir())
    asked = remember(recipe, tmp_path / "mine")
    assert asked == tmp_path / "mine" / f"{recipe.digest()}.json" and asked.is_file()
    monkeypatch.setenv("ROBOTSPEC_SDT_CLASSES", str(tmp_path / "env"))
    assert remember(recipe) == tmp_path / "env" / f"{recipe.digest()}.json"


def test_a_damaged_recipe_file_is_named(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # Not an AttributeError from deep inside: the file, and what to do about it.
    from robotspec.interop.sdt import classes

    damaged = tmp_path / "0123456789.json"
    damaged.write_text('{"name": "PR2", "root":')
    monkeypatch.setenv("ROBOTSPEC_SDT_CLASSES", str(tmp_path))
    with pytest.raises(RobotSpecError, match="damaged") as info:
        classes.PR2_0123456789  # noqa: B018 - the lookup is the test
    assert info.value.file == str(damaged)
    damaged.write_text('{"name": "PR2"}')  # valid JSON, not a recipe
    with pytest.raises(RobotSpecError, match="damaged"):
        classes.PR2_0123456789  # noqa: B018
    with pytest.raises(AttributeError, match="no stored recipe"):
        classes.PR2_abcdefabcd  # noqa: B018 - absent is still an AttributeError
