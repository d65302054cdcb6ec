"""SDT's hand-written PR2 class read back into a spec (robotspec.interop.sdt.migrate).

The spec must say what SDT's class says, and robotspec's checks must find the class's defects:
compiled, it fails on exactly the camera heights SDT made up; with FK's heights it compiles, and
``to_sdt`` of it gives SDT's own PR2 back part for part.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml

from robotspec.errors import RobotSpecError
from robotspec.interop.sdt.summary import summarize
from tests.conftest import erd_robots, shared_path
from tests.sdt_support import hand_written, package_path, sdt, sdt_world_from_urdf  # noqa: F401

pytestmark = pytest.mark.usefixtures("sdt")


def _pr2_files(monkeypatch: pytest.MonkeyPatch) -> tuple[Path, Path]:
    share = erd_robots().parent
    monkeypatch.setenv("ROS_PACKAGE_PATH", package_path([share]))
    folder = share / "robots/pr2_description"
    return folder / "urdf/pr2.urdf", folder / "srdf/pr2.srdf"


def _write(spec: dict[str, Any], path: Path) -> Path:
    path.write_text(yaml.safe_dump(spec, sort_keys=False), encoding="utf-8")
    return path


def test_sdts_pr2_class_becomes_a_spec_that_gives_it_back(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from semantic_digital_twin.robots.pr2 import PR2 as HAND_WRITTEN

    from robotspec.compiler import check_spec, compile_robot
    from robotspec.interop.sdt import to_sdt
    from robotspec.interop.sdt.migrate import spec_from_sdt
    from robotspec.robots import PR2

    urdf, srdf = _pr2_files(monkeypatch)
    world = sdt_world_from_urdf(urdf, odom="odom_combined")
    migration = spec_from_sdt(HAND_WRITTEN, world, urdf=str(urdf), srdf=str(srdf))
    spec = migration.spec
    assert set(spec["chains"]) == {"left_arm", "right_arm"}
    # Only what SDT's class states: sides by geometry (SDT's agree, so nothing is noted and no
    # `side` written), the drive the SRDF's planar virtual joint states (left to the compiler),
    # no front-facing axis beside the orientation SDT derives it from.
    assert not any("side" in c for c in spec["chains"].values())
    assert "drive" not in spec
    assert spec["sdt"] == {"class": "PR2"}  # to_sdt's robot is an instance of SDT's PR2
    assert "front_facing_axis" not in spec["manipulators"]["left_gripper"]
    assert spec["manipulators"]["left_gripper"]["thumb"]["root"] == "l_gripper_l_finger_link"
    assert len(spec["controlled_joints"]) == 17
    assert spec["velocity_limits"]["default"] == 1.0
    # SDT's gripper states set the two mimics of one joint to opposite values: noted, and the
    # one inside the joint's limits kept, on the joint they follow.
    assert len(migration.notes) == 2 and all("disagreeing" in n for n in migration.notes)
    assert spec["manipulators"]["left_gripper"]["states"]["open"] == {
        "l_gripper_l_finger_joint": 0.548
    }

    # Compiled, the one defect of SDT's class robotspec refuses: heights FK never reaches.
    with pytest.raises(RobotSpecError, match="minimal_height: FK puts") as err:
        check_spec(_write(spec, tmp_path / "pr2.yaml"))
    assert len(err.value.details) == 1
    (camera,) = spec["sensors"].values()
    (kinect,) = PR2.load().cameras
    camera["minimal_height"], camera["maximal_height"] = (
        kinect.minimal_height,
        kinect.maximal_height,
    )
    robot = compile_robot(_write(spec, tmp_path / "pr2.yaml"))

    ours = summarize(to_sdt(robot))
    theirs = summarize(
        hand_written(HAND_WRITTEN, sdt_world_from_urdf(urdf, odom="odom_combined"), monkeypatch)
    )
    assert [p for p in ours.parts if p.kind != "Camera"] == [
        p for p in theirs.parts if p.kind != "Camera"
    ]
    (ours_cam,) = [p for p in ours.parts if p.kind == "Camera"]
    (their_cam,) = [p for p in theirs.parts if p.kind == "Camera"]
    assert ours_cam.heights == (kinect.minimal_height, kinect.maximal_height)
    assert ours_cam.field_of_view == their_cam.field_of_view and ours_cam.axis == their_cam.axis
    assert ours.hardware_joints == theirs.hardware_joints
    assert ours.velocity_limits == theirs.velocity_limits
    assert (ours.left_arm, ours.right_arm) == (theirs.left_arm, theirs.right_arm)


def test_only_an_sdt_robot_class_migrates() -> None:
    from robotspec.interop.sdt.migrate import spec_from_sdt
    from robotspec.robots import PR2

    with pytest.raises(RobotSpecError, match="not an SDT robot class"):
        spec_from_sdt(PR2, None, urdf="pr2.urdf")


def test_the_migrate_command_writes_a_spec_validate_checks(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from robotspec.cli.app import app
    from robotspec.cli.output import run_app

    urdf, srdf = _pr2_files(monkeypatch)
    out = tmp_path / "pr2.yaml"
    argv = ["migrate", "sdt", "semantic_digital_twin.robots.pr2:PR2", "--urdf", str(urdf)]
    assert run_app(app, [*argv, "--srdf", str(srdf), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert err.count("note: ") == 2 and f"wrote {out}" in err
    assert out.read_text(encoding="utf-8").count("# NOTE: ") == 2
    assert run_app(app, ["validate", str(out)]) == 1
    assert "minimal_height: FK puts" in capsys.readouterr().out  # validate reports on stdout
    assert run_app(app, [*argv, "-o", str(out)]) == 1  # exists, no --force
    assert "pass --force" in capsys.readouterr().err


def test_a_class_that_names_a_missing_body_is_a_located_error(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # SDT's HSRB class names the IAI tool frame, which no upstream HSR URDF has.
    from robotspec.interop.sdt.migrate import migrate_files

    folder = shared_path("robots", "hsrb")
    with pytest.raises(RobotSpecError, match="SDT's class HSRB cannot be built") as err:
        migrate_files(
            "semantic_digital_twin.robots.hsrb:HSRB",
            str(folder / "hsrb4s.urdf"),
            folder=folder,
            package_paths=[folder],
        )
    assert "hand_gripper_tool_frame" in str(err.value)


def test_sdts_missing_cylinder_mesh_is_named_not_a_crash(monkeypatch: pytest.MonkeyPatch) -> None:
    # Without the tests' stand-in, SDT's collision sync loads resources/obj/cylinder.obj from
    # SDT's wheel, which lacks it: the bridge says so instead of crashing.
    from semantic_digital_twin.collision_checking import pybullet_collision_detector as pcd

    from robotspec.interop.sdt import to_sdt
    from robotspec.robots import HSRB

    folder = shared_path("robots", "hsrb")
    missing = str(folder.parent / "absent" / "resources" / "obj" / "cylinder.obj")
    bullet = pcd.bullet

    def create_cylinder_shape(diameter: float, height: float) -> Any:
        return bullet.load_convex_shape(missing, single_shape=True)

    monkeypatch.setattr(pcd, "create_cylinder_shape", create_cylinder_shape)
    with pytest.raises(RobotSpecError, match="wheel lacks its resources/ folder"):
        to_sdt(HSRB.load(package_paths=[folder]))


def test_a_hand_of_four_fingers_migrates_as_a_hand() -> None:
    from robotspec.compiler import compile_robot
    from robotspec.interop.sdt.classes import robot_class
    from robotspec.interop.sdt.mapping import robot_recipe
    from robotspec.interop.sdt.migrate import spec_from_sdt
    from robotspec.interop.sdt.world import sdt_world

    erd_robots()
    robot = compile_robot("b1_ur5_allegro")
    cls = robot_class(robot_recipe(robot))
    world = sdt_world(robot.world, drive=robot.drive_type)
    migration = spec_from_sdt(cls, world, urdf="b1_ur5_allegro.urdf", files=robot.world)
    (hand,) = migration.spec["manipulators"].values()
    assert hand["type"] == "hand"
    assert hand["thumb"] == {"root": "allegro_link_12.0", "tip": "allegro_link_15.0_tip"}
    assert hand["fingers"] == {
        n: {"root": f"allegro_link_{r}.0", "tip": f"allegro_link_{t}.0_tip"}
        for n, r, t in (("index", 0, 3), ("middle", 4, 7), ("ring", 8, 11))
    }
    assert not any("fingers" in n for n in migration.notes)
