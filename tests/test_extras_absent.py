"""Each optional extra, hidden, gives the line docs/installing.md documents for it, word for word.

A module is hidden the way Python itself reads it: ``sys.modules[name] = None`` makes ``import``
fail and ``importlib.util.find_spec`` answer ``None``, which is all the fence
(``robotspec/extras.py``) asks. The entry point is the one a user calls (the CLI in-process
where the check comes before any work, else the function the command calls).
"""

from __future__ import annotations

import re
import sys
from collections.abc import Callable
from pathlib import Path

import pytest

from robotspec.cli.app import app
from robotspec.cli.output import run_app
from robotspec.errors import RobotSpecError
from robotspec.extras import OPTIONAL

from .conftest import erd_robots

DOC = Path(__file__).resolve().parents[1] / "docs" / "installing.md"


def _documented() -> dict[str, str]:
    """module -> the documented line, from the table of docs/installing.md's 'Optional extras'."""
    row = re.compile(r"^\| `[^`]+` \| `([^`]+)` \|.*\| ``(error: .*?) `` \|$", re.M)
    return dict(row.findall(DOC.read_text(encoding="utf-8")))


def _needs_robots() -> None:
    erd_robots()  # the shipped robots' files, or skip with the reason


def _cli(*argv: str) -> Callable[[pytest.CaptureFixture[str], Path], str]:
    def run(capsys: pytest.CaptureFixture[str], tmp: Path) -> str:
        _needs_robots()
        code = run_app(app, [a.replace("{tmp}", str(tmp)) for a in argv])
        err = capsys.readouterr().err
        assert code == 1, err
        return err.strip()

    return run


def _raises(call: Callable[[Path], object]) -> Callable[[pytest.CaptureFixture[str], Path], str]:
    def run(capsys: pytest.CaptureFixture[str], tmp: Path) -> str:
        with pytest.raises(RobotSpecError) as info:
            call(tmp)
        assert info.value.detail.kind == "dependency"
        return str(info.value)

    return run


def _to_pinocchio(tmp: Path) -> object:
    _needs_robots()
    from robotspec.compiler import compile_robot

    return compile_robot("ur5").to_pinocchio()


def _plot(tmp: Path) -> object:
    from robotspec.render.plot import JointTrace, plot_joint_trace

    return plot_joint_trace(JointTrace(("a",)), tmp / "plot.png")


def _serve(tmp: Path) -> object:
    from robotspec.service.node import rr

    return rr()


#: module -> what a user runs that needs it.
ENTRY: dict[str, Callable[[pytest.CaptureFixture[str], Path], str]] = {
    "pinocchio": _raises(_to_pinocchio),
    "mujoco": _cli("drive", "--spec", "panda", "--chain", "arm", "--physics", "mujoco"),
    "PIL": _cli("render", "pr2", "-o", "{tmp}/pr2.png"),
    "viser": _cli("view", "pr2"),
    "matplotlib": _raises(_plot),
    "RobotRaconteur": _raises(_serve),
    "RobotRaconteurCompanion": _raises(_serve),
}


def test_every_extra_is_documented_and_has_an_entry_point() -> None:
    modules = [e.module for e in OPTIONAL]
    assert sorted(_documented()) == sorted(modules)
    assert sorted(ENTRY) == sorted(modules)


@pytest.mark.parametrize("module", [e.module for e in OPTIONAL])
def test_a_hidden_extra_gives_its_documented_line(
    module: str,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
) -> None:
    monkeypatch.setitem(sys.modules, module, None)
    assert ENTRY[module](capsys, tmp_path) == _documented()[module]


def test_two_absent_packages_are_named_in_one_line(monkeypatch: pytest.MonkeyPatch) -> None:
    for e in OPTIONAL:
        if e.extra == "robotraconteur":
            monkeypatch.setitem(sys.modules, e.module, None)
    with pytest.raises(RobotSpecError) as info:
        _serve(Path())
    assert str(info.value) == (
        "error: serving needs the 'robotraconteur' and 'robotraconteurcompanion' packages; "
        "install them with `pip install 'robotspec[robotraconteur]'`"
    )


def test_the_annotate_command_says_the_same_for_mujoco(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    from robotspec.interop.mujoco_model import read_model

    monkeypatch.setitem(sys.modules, "mujoco", None)
    with pytest.raises(RobotSpecError, match=r"^error: robotspec annotate mjcf needs MuJoCo; "):
        read_model(tmp_path / "robot.xml")


def test_drawing_from_python_says_the_same_for_pillow(monkeypatch: pytest.MonkeyPatch) -> None:
    _needs_robots()
    from robotspec.compiler import compile_robot
    from robotspec.render import build_scene, render_scene

    robot = compile_robot("ur5")
    scene = build_scene(robot)
    monkeypatch.setitem(sys.modules, "PIL", None)
    with pytest.raises(RobotSpecError) as info:
        render_scene(scene, robot.world.default_configuration())
    assert str(info.value) == _documented()["PIL"]
