"""Every example in docs/ runs, and the generated pages are current.

Each page's code blocks run in order in one temporary folder (with a copy of docs/examples/ at
docs/examples/, so commands read as if run from the repository root):

* ``sh`` blocks: every line starting with ``robotspec `` runs in-process and must exit 0, or the
  code of a preceding ``<!-- expect-exit: N -->`` comment;
* ``python`` blocks are executed in a fresh namespace;
* ``yaml`` blocks whose first non-comment line is ``robotspec: 1`` must compile (``check_spec``),
  or must fail to when marked ``<!-- invalid -->``; ``<!-- fragment -->`` skips the check.

``<!-- file: NAME -->`` before a block writes its text to NAME first (later blocks use it);
``<!-- no-run: REASON -->`` skips a block and must give a reason. Commands naming the HSR-B need
the shared robot files beside the checkout and are skipped without them. ``<!-- needs: sdt -->``
blocks need the semantic digital twin: they run in CI's SDT stage (``.ci/run`` runs this page's
test there, ``ROBOTSPEC_REQUIRE_SDT=1``: a missing SDT fails), with the SDT tests' stand-ins
(``tests/sdt_support.py``), and are skipped with the reason elsewhere.
"""

from __future__ import annotations

import importlib.util
import os
import re
import shlex
import shutil
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from tests.conftest import SHARED, erd_robots
from tests.sdt_support import REASON as SDT_REASON
from tests.sdt_support import require_sdt, stand_in_cylinder

DOCS = Path(__file__).resolve().parents[1] / "docs"
PAGES = sorted(DOCS.glob("*.md"))
README = DOCS.parent / "README.md"
#: Pages whose examples run: the docs and the README (style rule: every shown example is tested).
RUN_PAGES = [*PAGES, README]
HSRB_PACKAGES = SHARED / "robots" / "hsrb"

_FENCE = re.compile(r"^```(\w*)\s*$")
_MARK = re.compile(r"^<!--\s*([\w-]+)\s*:?\s*(.*?)\s*-->$")


@dataclass
class Block:
    lang: str
    text: str
    line: int  # 1-based line of the opening fence
    marks: dict[str, str] = field(default_factory=dict)


def blocks(page: Path) -> Iterator[Block]:
    """The fenced code blocks of a page, with the marker comments right above each."""
    lines = page.read_text(encoding="utf-8").splitlines()
    i = 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        marks: dict[str, str] = {}
        j = i - 1
        while j >= 0 and (mark := _MARK.match(lines[j].strip())):
            marks[mark.group(1)] = mark.group(2)
            j -= 1
        end = i + 1
        while end < len(lines) and lines[end].strip() != "```":
            end += 1
        yield Block(m.group(1), "\n".join(lines[i + 1 : end]) + "\n", i + 1, marks)
        i = end + 1


def _sdt_ready(folder: Path, monkeypatch: pytest.MonkeyPatch) -> bool:
    """SDT importable, with the SDT tests' stand-ins in place; False where it is not installed."""
    if importlib.util.find_spec("semantic_digital_twin") is None:
        if os.environ.get("ROBOTSPEC_REQUIRE_SDT"):  # CI's SDT stage: never a skip
            pytest.fail(f"ROBOTSPEC_REQUIRE_SDT is set but {SDT_REASON}")
        return False
    require_sdt()
    folder.mkdir(parents=True, exist_ok=True)
    stand_in_cylinder(folder, monkeypatch)
    return True


def _is_spec(text: str) -> bool:
    for line in text.splitlines():
        if line.strip() and not line.lstrip().startswith("#"):
            return line.strip() == "robotspec: 1"
    return False


@pytest.fixture(scope="module")
def app():
    from robotspec.cli.app import app

    return app


def test_generated_pages_are_current() -> None:
    erd_robots()
    from tools.docgen import COMMAND, stale_pages

    stale = stale_pages(DOCS)
    assert not stale, f"stale generated pages {stale}: run `{COMMAND}`"


def test_every_page_is_checked() -> None:
    names = {p.name for p in PAGES}
    assert {"index.md", "getting-started.md", "spec-reference.md", "cli.md"} <= names


@pytest.mark.parametrize("page", PAGES, ids=[p.name for p in PAGES])
def test_shown_example_files_match(page: Path) -> None:
    """A block shown as a file of docs/examples/ is that file, character for character."""
    for b in blocks(page):
        name = b.marks.get("file", "")
        if name.startswith("docs/examples/"):
            shipped = DOCS.parent / name
            assert shipped.is_file(), f"{page.name}:{b.line}: {name} does not exist"
            assert b.text == shipped.read_text(encoding="utf-8"), (
                f"{page.name}:{b.line}: the block differs from {name}"
            )


@pytest.mark.parametrize("page", RUN_PAGES, ids=[p.name for p in RUN_PAGES])
def test_examples_run(
    page: Path,
    app: object,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    erd_robots()
    from robotspec.cli.output import run_app
    from robotspec.compiler import check_spec
    from robotspec.errors import RobotSpecError

    if (DOCS / "examples").is_dir():
        shutil.copytree(DOCS / "examples", tmp_path / "docs" / "examples")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("NO_COLOR", "1")
    monkeypatch.delenv("ROBOTSPEC_VERBOSE", raising=False)
    skipped: list[str] = []
    sdt_skipped: list[str] = []
    sdt_ready: bool | None = None
    for b in blocks(page):
        where = f"{page.name}:{b.line}"
        if "no-run" in b.marks:
            assert b.marks["no-run"], f"{where}: <!-- no-run: REASON --> needs a reason"
            continue
        if "needs" in b.marks:
            assert b.marks["needs"] == "sdt", f"{where}: <!-- needs: sdt --> is the one need"
            if sdt_ready is None:
                sdt_ready = _sdt_ready(tmp_path.parent / f"{tmp_path.name}-sdt", monkeypatch)
            if not sdt_ready:
                sdt_skipped.append(where)
                continue
        if "file" in b.marks:
            (tmp_path / b.marks["file"]).parent.mkdir(parents=True, exist_ok=True)
            (tmp_path / b.marks["file"]).write_text(b.text, encoding="utf-8")
        if b.lang == "sh":
            expected = int(b.marks.get("expect-exit", "0"))
            for line in b.text.splitlines():
                if not line.startswith("robotspec "):
                    continue
                argv = shlex.split(line, comments=True)[1:]
                if "hsrb" in argv:
                    if not HSRB_PACKAGES.is_dir():
                        skipped.append(line)
                        continue
                    monkeypatch.setenv("ROS_PACKAGE_PATH", str(HSRB_PACKAGES))
                code = run_app(app, argv)  # type: ignore[arg-type]
                monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
                out = capsys.readouterr()
                assert code == expected, (
                    f"{where}: `{line}` exited {code}, expected {expected}\n"
                    f"stdout:\n{out.out[-3000:]}\nstderr:\n{out.err[-3000:]}"
                )
        elif b.lang == "python":
            namespace: dict[str, object] = {"__name__": "__docs__"}
            exec(compile(b.text, where, "exec"), namespace)
            capsys.readouterr()
        elif b.lang == "yaml" and _is_spec(b.text) and "fragment" not in b.marks:
            spec = tmp_path / b.marks.get("file", f"block_{b.line}.yaml")
            spec.write_text(b.text, encoding="utf-8")
            if "invalid" in b.marks:
                with pytest.raises(RobotSpecError):
                    check_spec(spec)
            else:
                try:
                    check_spec(spec)
                except RobotSpecError as exc:
                    pytest.fail(f"{where}: the spec does not compile:\n{exc}")
    reasons = []
    if skipped:
        reasons.append(f"needs {HSRB_PACKAGES} for: {'; '.join(skipped)}")
    if sdt_skipped:
        reasons.append(f"{SDT_REASON}; the blocks at {', '.join(sdt_skipped)} need it")
    if reasons:
        pytest.skip("; ".join(reasons))
