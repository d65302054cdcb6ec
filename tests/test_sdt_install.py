"""What a user is told when SDT cannot be imported: the module really missing, and its fix.

SDT 26.7 from PyPI imports giskardpy (one helper) while it loads its ``World``, and giskardpy
is not on PyPI: "pip install 'robotspec[sdt]'" there sends a user who has the extra in a
circle. Each case is run for real: without SDT (the main environment), and with SDT but no
giskardpy (a child process of the SDT environment, without the tests' stand-in).
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys

import pytest

from robotspec.errors import RobotSpecError
from robotspec.interop.sdt import sdt_api
from robotspec.interop.sdt.install import GISKARDPY_INSTALL
from tests.conftest import erd_robots
from tests.sdt_support import STAND_INS, require_sdt

#: Bound on a child process that imports SDT (seconds at rest, much more on a loaded machine);
#: it only catches a hang.
CHILD_WAIT = 600


def test_without_sdt_the_extra_is_named() -> None:
    if importlib.util.find_spec("semantic_digital_twin") is not None:
        pytest.skip("semantic-digital-twin is installed here; this case needs it absent")
    with pytest.raises(RobotSpecError) as info:
        sdt_api()
    message = str(info.value)
    assert "the semantic digital twin is not installed" in message
    assert "pip install 'robotspec[sdt]'" in message
    assert info.value.detail.kind == "dependency"


def test_with_sdt_but_no_giskardpy_giskardpy_is_named() -> None:
    """The CLI, in a child process without the stand-in: exit 1, giskardpy and its command."""
    require_sdt()
    real = importlib.util.find_spec("giskardpy")
    if real is not None and not str(real.origin).startswith(str(STAND_INS)):
        pytest.skip(f"a real giskardpy is installed here ({real.origin}); this case needs none")
    urdf = erd_robots() / "pr2_description/urdf/pr2.urdf"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    code = (
        "import sys; from robotspec.cli import main; "
        "sys.exit(main(['migrate', 'sdt', 'semantic_digital_twin.robots.pr2:PR2', '--urdf', "
        f"{str(urdf)!r}]))"
    )
    child = subprocess.run(
        [sys.executable, "-c", code],
        env=env,
        capture_output=True,
        text=True,
        timeout=CHILD_WAIT,
        check=False,
    )
    assert child.returncode == 1, child.stderr
    assert "Traceback" not in child.stderr
    assert "semantic-digital-twin 26.7" in child.stderr
    assert "it imports giskardpy" in child.stderr
    assert GISKARDPY_INSTALL in child.stderr.replace("\n", " ")
    assert "robotspec[sdt]" not in child.stderr


def test_an_installed_sdt_without_a_module_is_not_called_absent() -> None:
    """A module of SDT's own that its version lacks: the version named, not 'not installed'."""
    require_sdt()
    import importlib

    from robotspec.interop.sdt.install import import_error

    with pytest.raises(ImportError) as raised:
        importlib.import_module("semantic_digital_twin.robots.no_such_robot_module")
    message = str(import_error(raised.value, tested="26.7"))
    assert "not installed" not in message
    assert "has no module 'semantic_digital_twin.robots.no_such_robot_module'" in message
    assert "pip install 'semantic-digital-twin==26.7.*'" in message
