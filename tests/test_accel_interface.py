"""Each C core speaks one interface version with its Python side; a stale core is refused.

Why: a compiled core is a file left by a build, and an editable install keeps it across changes
of the Python side. A core whose ``INTERFACE`` differs (or that has none: built before the
numbers) must not answer: the fallback does, a warning says why once, and ``robotspec doctor``
shows it. The stale cores are made by monkeypatching what the loader finds, not by compiling.
Also: ``kincore.fk_batch`` given a list splits it over its threads like an array.
"""

from __future__ import annotations

import re
import sys
import warnings
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pytest

from robotspec import accel
from robotspec.accel import CoreChoice, StaleCoreWarning
from robotspec.collision import meshcore
from robotspec.model import _kincore_py as kin_py
from robotspec.model import kincore
from robotspec.model.kinematics import Kinematics

ROOT = Path(__file__).resolve().parents[1]
FAKE = "robotspec_test_stale_core"


def run_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    """Run ``robotspec ARGV`` in-process; returns (exit code, stdout, stderr)."""
    from robotspec.cli.app import app
    from robotspec.cli.output import run_app

    code = run_app(app, list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def _fake_core(monkeypatch: pytest.MonkeyPatch, **attrs: Any) -> None:
    """A compiled core as the loader finds it, with the given attributes (INTERFACE or none)."""
    module = ModuleType(FAKE)
    for name, value in attrs.items():
        setattr(module, name, value)
    monkeypatch.setitem(sys.modules, FAKE, module)
    monkeypatch.delenv(accel.NO_ACCEL_ENV, raising=False)


@pytest.mark.parametrize(
    ("attrs", "said"),
    [({"INTERFACE": kincore.INTERFACE + 1}, "speaks interface 2"), ({}, "no interface version")],
)
def test_a_core_of_another_interface_is_refused_once_with_the_reason(
    monkeypatch: pytest.MonkeyPatch, attrs: dict[str, Any], said: str
) -> None:
    _fake_core(monkeypatch, **attrs)
    choice = CoreChoice(FAKE, "robotspec.model._kincore_py", kincore.INTERFACE)
    with pytest.warns(StaleCoreWarning, match=f"{FAKE}: stale build refused: .*{said}"):
        assert choice.core() is kin_py
    assert not choice.accelerated()
    status = choice.status()
    assert (status.accelerated, status.module) == (False, "robotspec.model._kincore_py")
    assert "stale build refused" in status.reason and "needs interface 1" in status.reason
    with warnings.catch_warnings(record=True) as seen:  # once: the choice is made once
        warnings.simplefilter("always")
        choice.core()
        choice.status()
    assert seen == []


def test_a_core_of_the_same_interface_answers(monkeypatch: pytest.MonkeyPatch) -> None:
    _fake_core(monkeypatch, INTERFACE=kincore.INTERFACE)
    choice = CoreChoice(FAKE, "robotspec.model._kincore_py", kincore.INTERFACE)
    assert choice.core() is sys.modules[FAKE]
    assert choice.status().accelerated and choice.status().reason.startswith("loaded from")


@pytest.mark.parametrize("side", [kincore, meshcore], ids=["kincore", "meshcore"])
def test_the_real_core_is_refused_when_its_number_moves(
    monkeypatch: pytest.MonkeyPatch, side: ModuleType
) -> None:
    if accel.accelerators_disabled():
        pytest.skip("loads the compiled core; ROBOTSPEC_NO_ACCEL turns C off")
    compiled = pytest.importorskip(side.CHOICE.compiled, reason="the C core is not built")
    assert compiled.INTERFACE == side.INTERFACE  # the build in use is current
    monkeypatch.setattr(compiled, "INTERFACE", side.INTERFACE - 1)
    choice = CoreChoice(side.CHOICE.compiled, side.CHOICE.fallback, side.INTERFACE)
    with pytest.warns(StaleCoreWarning, match="stale build refused"):
        assert choice.core().__name__ == side.CHOICE.fallback


@pytest.mark.parametrize(
    ("source", "side"),
    [("robotspec/model/_kincore.c", kincore), ("robotspec/collision/_meshcore.c", meshcore)],
)
def test_the_c_sources_state_the_python_sides_number(source: str, side: ModuleType) -> None:
    if not (ROOT / source).is_file():
        pytest.skip(f"reads the C sources; {source} is not beside the tests (an installed wheel)")
    text = (ROOT / source).read_text(encoding="utf-8")
    found = re.findall(r"^#define \w+_INTERFACE (\d+)$", text, flags=re.MULTILINE)
    assert found == [str(side.INTERFACE)], f"{source}: bump its INTERFACE with {side.__name__}'s"


def test_the_kernels_include_no_python_or_numpy_header() -> None:
    for kernels in (
        "robotspec/model/_kincore_kernels.h",
        "robotspec/collision/_meshcore_kernels.h",
    ):
        if not (ROOT / kernels).is_file():
            pytest.skip(f"reads the C sources; {kernels} is not beside the tests (a wheel's run)")
        text = (ROOT / kernels).read_text(encoding="utf-8")
        includes = re.findall(r"^#include\s*[<\"]([^>\"]+)", text, flags=re.MULTILINE)
        assert includes and all(h.split("/")[0] in _C_HEADERS for h in includes), includes
        assert "Py" not in re.sub(r"/\*.*?\*/", "", text, flags=re.DOTALL)


_C_HEADERS = {"math.h", "stddef.h", "stdint.h", "stdlib.h", "string.h", "emmintrin.h"}


def test_the_report_names_every_core_and_the_whole_answer() -> None:
    rows = accel.report()
    assert [r.name for r in rows] == [kincore.CHOICE.compiled, meshcore.CHOICE.compiled]
    assert accel.accelerated() == all(r.accelerated for r in rows)
    assert accel.accelerated() == (kincore.accelerated() and meshcore.accelerated())
    if accel.accelerators_disabled():
        assert all(r.reason == f"{accel.NO_ACCEL_ENV} is set" for r in rows)


def test_doctor_says_which_core_answers_and_why(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run_cli(capsys, "doctor")
    assert code == 0 and out.startswith("robotspec ")
    for row in accel.report():
        line = next(x for x in out.splitlines() if x.startswith(row.name.rsplit("._", 1)[1]))
        assert ("C" if row.accelerated else "fallback") in line.split() and row.reason in line
    code, out, _ = run_cli(capsys, "doctor", "--require-c")
    assert code == (0 if accel.accelerated() else 1)
    code, out, _ = run_cli(capsys, "--version")
    assert code == 0 and out.startswith("robotspec ") and "kincore: " in out


def test_doctor_require_c_fails_on_a_fallback(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    _fake_core(monkeypatch)  # no INTERFACE: a core from before the numbers
    stale = CoreChoice(FAKE, "robotspec.model._kincore_py", kincore.INTERFACE)
    monkeypatch.setattr(accel, "choices", lambda: (stale, meshcore.CHOICE))
    code, out, err = run_cli(capsys, "doctor", "--require-c")
    assert code == 1
    assert f"{FAKE}" not in err  # the warning is not repeated: the reason is in the table
    assert "fallback  stale build refused" in out and "docs/installing.md" in out


class _Recorder:
    """A kinematics core that records the batch sizes of its fk_batch calls, then answers."""

    def __init__(self, core: ModuleType) -> None:
        self.core = core
        self.sizes: list[int] = []
        self.tree_size = core.tree_size

    def fk_batch(self, tree: object, q: Any, out: Any = None, stream: bool = False) -> Any:
        self.sizes.append(len(q))
        return self.core.fk_batch(tree, q, out, stream)


def test_fk_batch_of_a_list_is_split_over_the_threads_like_an_array() -> None:
    from robotspec.compiler import compile_robot

    kin = Kinematics(compile_robot("panda").world)
    q = np.random.default_rng(3).uniform(-1, 1, (9, len(kin.world.degrees_of_freedom)))
    recorder = _Recorder(kincore.core())
    with accel.using((kincore.CHOICE, recorder)):  # type: ignore[arg-type]
        from_array = kincore.fk_batch(kin._tree, q, threads=3)
        assert recorder.sizes == [3, 3, 3]
        recorder.sizes.clear()
        from_list = kincore.fk_batch(kin._tree, q.tolist(), threads=3)
        assert recorder.sizes == [3, 3, 3]
        with pytest.raises(ValueError, match="wrong number of values"):
            kincore.fk_batch(kin._tree, [row[:-1] for row in q.tolist()], threads=3)
        with pytest.raises(ValueError, match="too small depth"):
            kincore.fk_batch(kin._tree, q[0].tolist(), threads=3)
    np.testing.assert_array_equal(from_list, from_array)
