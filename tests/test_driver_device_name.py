"""A device name Robot Raconteur cannot use is refused when the RobotInfo is read.

Served, the device name becomes the node name and the key of the device identifier's lock file,
so a name Robot Raconteur refuses used to pass ``drive --sim`` and fail ``--serve`` only after the
node had started. Now reading the file refuses it, located, for both; nothing starts (no state
folder is made). Needs no Robot Raconteur: the check is the driver's own.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from robotspec.cli.app import app
from robotspec.cli.output import run_app
from robotspec.driver.robot_info import read_robot_info, read_robot_info_text
from robotspec.driver.rr_names import (
    MAX_RR_NAME_CHARS,
    rr_name_problem,
    rr_name_suggestion,
    valid_rr_name,
)
from robotspec.errors import RobotInfoError

from .driver_support import RRP, shared_robotinfo_files


def with_device(name_yaml: str) -> str:
    """The RRP test arm's RobotInfo with another ``device_info`` (line 2 is the device)."""
    body = RRP.read_text().split("robot_type:", 1)[1]
    return f"device_info:\n  device: {name_yaml}\nrobot_type:{body}"


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = run_app(app, list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.mark.parametrize(
    ("name", "problem", "suggestion"),
    [
        ("my robot", "contains ' '", "my_robot"),
        ("1arm", "does not start with a letter", "robot_1arm"),
        ("_arm", "does not start with a letter", "robot__arm"),
        ("arm/left", "contains '/'", "arm_left"),
        ("bras_élevé", "contains 'é'", "bras__lev_"),
        ("a" * (MAX_RR_NAME_CHARS + 1), "characters long", "a" * MAX_RR_NAME_CHARS),
    ],
)
def test_unusable_device_name_is_a_located_error(name: str, problem: str, suggestion: str) -> None:
    with pytest.raises(RobotInfoError) as exc:
        read_robot_info_text(with_device(f'{{name: "{name}"}}'), file="arm.yml")
    err = exc.value
    assert err.line == 2
    assert problem in err.message
    assert f"did you mean '{suggestion}'" in err.message
    assert err.file == "arm.yml"


def test_shorthand_and_uuid_forms() -> None:
    with pytest.raises(RobotInfoError, match="'my arm' contains ' '") as exc:
        read_robot_info_text(with_device('"my arm"'), file="arm.yml")
    assert exc.value.line == 2
    # With a UUID, Robot Raconteur needs no name lookup: the name is only informational.
    uuid = "ca3e2893-f6c1-4fe1-8878-73331aaf1d02"
    loaded = read_robot_info_text(with_device(f'{{name: "my arm", uuid: "{uuid}"}}'))
    assert loaded.info.device_info.device.name == "my arm"
    # No name at all is fine: the file's stem is used as the node name.
    assert read_robot_info_text(with_device("{}")).info.device_info.device.name == ""


def test_every_shared_robotinfo_device_name_is_usable() -> None:
    files = shared_robotinfo_files()
    if not files:
        pytest.skip("needs ../shared/robotinfo (the shared robot files beside the checkout)")
    for path in files:
        name = read_robot_info(path).info.device_info.device.name
        assert valid_rr_name(name), (path, name)


@given(st.text(max_size=40))
def test_suggestion_is_always_valid_and_valid_names_are_kept(name: str) -> None:
    suggestion = rr_name_suggestion(name)
    assert valid_rr_name(suggestion) and rr_name_problem(suggestion) is None
    if valid_rr_name(name):
        assert suggestion == name and rr_name_problem(name) is None
    else:
        assert rr_name_problem(name)


@pytest.mark.parametrize("serve", [False, True])
def test_cli_refuses_before_anything_starts(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], serve: bool
) -> None:
    bad = tmp_path / "bad_arm.yml"
    bad.write_text(with_device("{name: my robot}"))
    state = tmp_path / "state"
    extra = ["--serve", "--port", "0", "--state-dir", str(state)] if serve else ["--virtual-time"]
    code, out, err = run(capsys, "drive", "--sim", str(bad), *extra, "--duration", "0.1")
    assert code == 1
    assert f"{bad}:2:" in err
    assert "device_info.device.name 'my robot' contains ' '" in err
    assert "did you mean 'my_robot'" in err
    assert "Traceback" not in err
    assert "driving" not in err and out == ""  # nothing ran ...
    assert not state.exists()  # ... and no node started


def test_cli_refuses_an_unusable_node_name(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "drive", "--sim", str(RRP), "--serve", "--node-name", "a b")
    assert code == 2
    assert "--node-name 'a b' contains ' '" in err
