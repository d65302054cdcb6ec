"""``--physics mujoco`` refusals and the path without MuJoCo (no MuJoCo needed to run these).

A RobotInfo file has no model to simulate, so ``--physics mujoco`` needs ``--spec``; gravity
compensation needs physics; without the ``mujoco`` extra the user is told what to install (exit
1, no traceback), and neither ``import robotspec`` nor the kinematic driver imports MuJoCo.
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from typing import Any

import pytest

from tests.driver_support import RRP
from tests.test_cli import run


def _flat(err: str) -> str:
    """The usage message without the panel's frame and line breaks."""
    return " ".join(w for w in err.split() if not set(w) <= set("│╭╮╰╯─"))


def test_physics_needs_a_spec(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "drive", "--sim", str(RRP), "--physics", "mujoco")
    assert code == 2 and out == ""
    assert "--physics mujoco needs --spec SPEC --chain NAME" in _flat(err)


@pytest.mark.parametrize(
    "argv",
    [
        ["drive", "--spec", "panda", "--chain", "arm", "--gravity-compensation"],
        ["demo", "panda", "--gravity-compensation"],
        ["demo", "panda", "--no-gravity-compensation"],
    ],
)
def test_gravity_compensation_needs_physics(
    capsys: pytest.CaptureFixture[str], argv: list[str]
) -> None:
    code, out, err = run(capsys, *argv)
    assert code == 2
    assert "--gravity-compensation needs --physics mujoco" in _flat(err)


def test_an_unknown_physics_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "drive", "--spec", "panda", "--chain", "arm", "--physics", "ode")
    assert code == 2 and "'kinematic', 'mujoco'" in _flat(err)


@pytest.mark.parametrize(
    "argv",
    [
        ["drive", "--spec", "panda", "--chain", "arm", "--physics", "mujoco", "--duration", "0"],
        ["demo", "panda", "--physics", "mujoco"],
    ],
)
def test_without_mujoco_the_user_is_told_what_to_install(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, argv: list[str]
) -> None:
    real = importlib.util.find_spec

    def find_spec(name: str, *args: Any, **kwargs: Any) -> Any:
        return None if name == "mujoco" else real(name, *args, **kwargs)

    monkeypatch.setattr(importlib.util, "find_spec", find_spec)
    code, out, err = run(capsys, *argv)
    assert code == 1 and out == ""
    assert err == (
        "error: --physics mujoco needs MuJoCo; install it with `pip install 'robotspec[mujoco]'`\n"
    )


def test_the_kinematic_driver_never_imports_mujoco() -> None:
    code = (
        "import sys, robotspec\n"
        "from robotspec.cli.app import app\n"
        "from robotspec.cli.output import run_app\n"
        f"assert run_app(app, ['drive', '--sim', {str(RRP)!r}, '--virtual-time', "
        "'--duration', '0.1']) == 0\n"
        "assert 'mujoco' not in sys.modules, 'mujoco imported'\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
