"""RobotInfo loading: every real file loads; every mistake is a located error with a hint."""

from __future__ import annotations

from pathlib import Path

import pytest

from robotspec.driver.robot_info import (
    CAPABILITY_BITS,
    JointType,
    RobotCapability,
    load_robot_info,
    read_robot_info,
    read_robot_info_text,
)
from robotspec.errors import RobotInfoError, RobotSpecError, RobotSpecErrors
from tests.driver_support import RRP, shared_robotinfo_files

SHARED_FILES = shared_robotinfo_files()


def test_fixture_loads() -> None:
    info = load_robot_info(RRP)
    assert info.joint_names == ("base_yaw", "shoulder", "slide")
    assert info.joint_info[2].joint_type is JointType.prismatic
    assert info.has(RobotCapability.homing_command)
    assert info.device_info.serial_number == "1"


@pytest.mark.skipif(not SHARED_FILES, reason="../shared/robotinfo is absent")
@pytest.mark.parametrize("path", SHARED_FILES, ids=lambda p: p.name)
def test_every_shared_file_loads(path: Path) -> None:
    loaded = read_robot_info(path)
    info = loaded.info
    assert info.joint_info and info.chains
    for chain in info.chains:
        assert len(chain.H) == len(chain.joint_numbers)
        assert len(chain.P) == len(chain.joint_numbers) + 1
    expected_warnings = 1 if path.name == "realman_rml63.yml" else 0
    assert len(loaded.warnings) == expected_warnings


def test_capability_bits() -> None:
    assert CAPABILITY_BITS[RobotCapability.jog_command] == 0x1
    assert CAPABILITY_BITS[RobotCapability.speed_ratio] == 0x400
    info = load_robot_info(RRP)
    assert info.capability_bits == 0x1 | 0x2 | 0x4 | 0x8 | 0x10 | 0x20 | 0x40


def _error(text: str) -> RobotSpecError:
    with pytest.raises(RobotSpecError) as info:
        read_robot_info_text(text, file="bad.yml")
    return info.value


def _mutate(old: str, new: str) -> str:
    text = RRP.read_text()
    assert old in text
    return text.replace(old, new, 1)


def _line_of(text: str, needle: str) -> int:
    return next(i for i, line in enumerate(text.splitlines(), 1) if needle in line)


def test_unknown_key_with_suggestion() -> None:
    text = _mutate("acceleration: 8.0", "acceleraton: 8.0, acceleration: 8.0")
    err = _error(text)
    assert isinstance(err, RobotInfoError)
    assert err.file == "bad.yml"
    assert err.line == _line_of(text, "acceleraton")
    assert "unknown key 'acceleraton'" in err.message
    assert "did you mean 'acceleration'?" in err.message


def test_wrong_unit_name() -> None:
    text = _mutate("default_units: radian", "default_units: radians")
    err = _error(text)
    assert err.line == _line_of(text, "radians")
    assert "unknown position unit 'radians'; did you mean 'radian'?" in err.message


def test_wrong_enum_names() -> None:
    err = _error(_mutate("- jog_command", "- jog_comand"))
    assert "unknown robot capability 'jog_comand'; did you mean 'jog_command'?" in err.message
    err = _error(_mutate("joint_type: prismatic", "joint_type: prismatik"))
    assert "did you mean 'prismatic'?" in err.message
    err = _error(_mutate("robot_type: serial", "robot_type: serail"))
    assert "did you mean 'serial'?" in err.message


def test_wrong_array_lengths() -> None:
    text = _mutate("  - {x: 0.1, y: 0.0, z: 0.0}\n", "")
    err = _error(text)
    assert "chains[0].P has 3 vectors but needs 4" in err.message
    assert err.line == _line_of(text, "  P:")
    text = _mutate("  - {x: 1.0, y: 0.0, z: 0.0}\n", "")
    err = _error(text)
    assert "chains[0].H has 2 axes but the chain has 3 joints" in err.message


def test_chain_names_missing_joint() -> None:
    text = _mutate("joint_numbers: [0, 1, 2]", "joint_numbers: [0, 1, 7]")
    err = _error(text)
    assert err.message == (
        "chains[0].joint_numbers[2] names joint 7, but joint_info has only 3 joints (0..2)"
    )
    assert err.line == _line_of(text, "joint_numbers")


def test_non_increasing_joint_numbers() -> None:
    err = _error(_mutate("joint_numbers: [0, 1, 2]", "joint_numbers: [0, 2, 1]"))
    assert "strictly increasing" in err.message


def test_bad_values() -> None:
    err = _error(_mutate("velocity: 2.0", "velocity: 0.0"))
    assert "greater than 0" in err.message
    err = _error(_mutate("lower: -3.0, upper: 3.0", "lower: 3.0, upper: -3.0"))
    assert "lower limit 3.0 is above upper limit -3.0" in err.message
    err = _error(_mutate("{x: 0.0, y: 0.0, z: 1.0}", "{x: 0.0, y: 0.0, z: 2.0}"))
    assert "H[0] must be a unit vector" in err.message
    err = _error(_mutate("{w: 1.0, x: 0.0", "{w: 0.0, x: 0.0"))
    assert "quaternion must have unit norm" in err.message


def test_several_problems_reported_together() -> None:
    text = _mutate("default_units: radian", "default_units: radians")
    text = text.replace("acceleration: 6.0", "acceleraton: 6.0, acceleration: 6.0")
    with pytest.raises(RobotSpecErrors) as info:
        read_robot_info_text(text, file="bad.yml")
    lines = [d.line for d in info.value.details]
    assert lines == sorted(lines) and len(lines) == 2


def test_missing_file_and_not_a_mapping(tmp_path: Path) -> None:
    with pytest.raises(RobotSpecError, match="file not found"):
        load_robot_info(tmp_path / "nope.yml")
    with pytest.raises(RobotInfoError, match="must be a YAML mapping"):
        read_robot_info_text("- 1\n- 2\n")
    with pytest.raises(RobotSpecError, match="unsupported YAML tag"):
        read_robot_info_text("device_info: !!python/object:os.system {}\n")


def test_loading_writes_nothing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # The reference InfoFileLoader persists a device UUID and a lock; this loader is read-only.
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("HOME", str(tmp_path))
    load_robot_info(RRP)
    assert list(tmp_path.iterdir()) == []
