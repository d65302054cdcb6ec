"""NaN, infinity and absurd magnitudes are refused wherever a number enters the driver.

RobotInfo files (axes, offsets, flange quaternion, limits) give located errors naming the file and
line; tools, payloads and commands are refused with InvalidArgument; nothing publishes a NaN pose.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from robotspec.driver.commands import RobotJointCommand
from robotspec.driver.errors import InvalidArgumentError
from robotspec.driver.robot_info import (
    DeviceInfo,
    Identifier,
    PayloadInfo,
    Pose,
    Quaternion,
    ToolInfo,
    Transform,
    Vector3,
    read_robot_info_text,
)
from robotspec.driver.state import CommandMode
from robotspec.errors import RobotSpecError, RobotSpecErrors
from tests.driver_support import RRP, make_sim

TEXT = RRP.read_text()


def _mutate(old: str, new: str) -> str:
    assert old in TEXT
    return TEXT.replace(old, new, 1)


def _line_of(text: str, needle: str) -> int:
    return next(i for i, line in enumerate(text.splitlines(), 1) if needle in line)


def _problems(text: str) -> list[RobotSpecError]:
    with pytest.raises(RobotSpecError) as info:
        read_robot_info_text(text, file="bad.yml")
    err = info.value
    return list(err.errors) if isinstance(err, RobotSpecErrors) else [err]


@pytest.mark.parametrize(
    ("old", "new", "where"),
    [
        ("- {x: 0.0, y: 1.0, z: 0.0}", "- {x: .nan, y: 1.0, z: 0.0}", "chains[0].H[1].x"),
        ("- {x: 0.4, y: 0.0, z: 0.0}", "- {x: 0.4, y: .inf, z: 0.0}", "chains[0].P[2].y"),
        (
            "orientation: {w: 1.0, x: 0.0, y: 0.0, z: 0.0}",
            "orientation: {w: .nan, x: 0.0, y: 0.0, z: 0.0}",
            "chains[0].flange_pose.orientation.w",
        ),
        ("lower: -1.5, upper: 1.5", "lower: -1.5, upper: -.inf", "joint_limits.upper"),
    ],
)
def test_non_finite_robotinfo_values_are_located_errors(old: str, new: str, where: str) -> None:
    text = _mutate(old, new)
    (err,) = _problems(text)
    rendered = str(err)
    assert rendered.startswith(f"bad.yml:{_line_of(text, new.strip('- '))}:"), rendered
    assert where in rendered and "finite" in rendered


def test_huge_axis_is_a_located_error_not_an_overflow() -> None:
    text = _mutate("- {x: 0.0, y: 1.0, z: 0.0}", "- {x: 1e200, y: 1.0, z: 0.0}")
    (err,) = _problems(text)
    assert str(err) == (
        f"bad.yml:{_line_of(text, '1e200')}:5: error: chains[0].H[1] must be a unit vector "
        "(norm is 1e+200)"
    )


def test_huge_flange_quaternion_and_offset_are_located() -> None:
    text = _mutate(
        "orientation: {w: 1.0, x: 0.0, y: 0.0, z: 0.0}",
        "orientation: {w: 1e200, x: 0.0, y: 0.0, z: 0.0}",
    )
    (err,) = _problems(text)
    assert f"bad.yml:{_line_of(text, '1e200')}:" in str(err)
    assert "quaternion must have unit norm (norm is 1e+200)" in str(err)
    text = _mutate("- {x: 0.1, y: 0.0, z: 0.0}", "- {x: 1e200, y: 0.0, z: 0.0}")
    (err,) = _problems(text)
    assert str(err).startswith(f"bad.yml:{_line_of(text, '1e200')}:")
    assert "P[3] is 1e+200 m from its frame" in str(err)
    text = _mutate("velocity: 2.0, acceleration: 8.0", "velocity: 2.0, acceleration: 1e300")
    (err,) = _problems(text)
    assert "joint_limits.acceleration: must be within +-1e+09" in str(err)


def test_cli_refuses_a_nan_robotinfo_with_exit_1(tmp_path: Path) -> None:
    bad = tmp_path / "nan_arm.yml"
    bad.write_text(_mutate("- {x: 0.0, y: 1.0, z: 0.0}", "- {x: .nan, y: 1.0, z: 0.0}"))
    result = subprocess.run(
        [sys.executable, "-m", "robotspec", "drive", "--sim", str(bad), "--duration", "0.05"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    output = result.stdout + result.stderr
    assert result.returncode == 1, output
    assert "nan_arm.yml:" in output and "finite" in output
    assert "Traceback" not in output


def _tool(tx: float = 0.0, w: float = 1.0, name: str = "gripper") -> ToolInfo:
    # model_construct: what another front end could hand the driver without validation.
    tcp = Transform.model_construct(
        rotation=Quaternion.model_construct(w=w, x=0.0, y=0.0, z=0.0),
        translation=Vector3.model_construct(x=tx, y=0.0, z=0.1),
    )
    return ToolInfo.model_construct(
        device_info=DeviceInfo(device=Identifier(name=name)), tcp=tcp, tool_type="unknown"
    )


@pytest.mark.parametrize(
    ("tool", "message"),
    [
        (_tool(tx=math.nan), "must not contain NaN"),
        (_tool(w=math.inf), "must not contain NaN"),
        (_tool(w=2.0), "unit quaternion"),
        (_tool(tx=1e200), "offset beyond"),
    ],
)
def test_tool_with_a_bad_tcp_is_refused(tool: ToolInfo, message: str) -> None:
    robot = make_sim(RRP)
    with pytest.raises(InvalidArgumentError, match=message):
        robot.tool_attached(0, tool)
    assert robot.robot_info.chains[0].current_tool is None
    st = robot.step()
    assert np.all(np.isfinite(st.kin_chain_tcp[0].position))


def test_validated_models_refuse_nan_too() -> None:
    with pytest.raises(ValueError, match="finite"):
        Vector3(x=math.nan, y=0.0, z=0.0)
    with pytest.raises(ValueError, match="finite"):
        Quaternion(w=math.inf, x=0.0, y=0.0, z=0.0)


def test_payload_with_a_bad_pose_is_refused() -> None:
    robot = make_sim(RRP)
    robot.tool_attached(0, _tool())
    pose = Pose.model_construct(
        orientation=Quaternion.model_construct(w=1.0, x=0.0, y=0.0, z=0.0),
        position=Vector3.model_construct(x=math.nan, y=0.0, z=0.0),
    )
    payload = PayloadInfo(device_info=DeviceInfo(device=Identifier(name="box")))
    with pytest.raises(InvalidArgumentError, match="payload 'box' pose must not contain NaN"):
        robot.payload_attached(0, payload, pose)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_commands_refuse_non_finite_values(bad: float) -> None:
    robot = make_sim(RRP)
    robot.command_mode = CommandMode.jog
    robot.step()
    q = list(robot.robot_state.joint_position)
    with pytest.raises(InvalidArgumentError, match="NaN or infinite"):
        robot.jog_freespace([q[0], bad, q[2]], [0.1, 0.1, 0.1])
    with pytest.raises(InvalidArgumentError, match="NaN or infinite"):
        robot.jog_joint([0.1, bad, 0.0], 0.5)
    with pytest.raises(InvalidArgumentError, match="NaN or infinite"):
        robot.jog_cartesian([0, 0, 0, bad, 0, 0], 0.5)
    with pytest.raises(InvalidArgumentError, match="finite"):
        robot.jog_joint([0.1, 0.0, 0.0], bad)
    with pytest.raises(InvalidArgumentError, match="speed_ratio"):
        robot.speed_ratio = bad
    robot.halt()
    robot.step()
    robot.command_mode = CommandMode.position_command
    robot.step()
    robot.record_commands = True
    robot.set_position_command(RobotJointCommand(1, robot.robot_state.seqno, [q[0], bad, q[2]]))
    st = robot.step()
    assert not robot.sent or robot.sent[-1][1] is None  # ignored, nothing sent
    assert np.all(np.isfinite(st.joint_position))
