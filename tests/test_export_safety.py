"""``robotspec export`` never writes through a link, never overwrites unasked, never escapes ``-o``.

Why: ``export bundle`` followed a symbolic link planted in its output folder and overwrote the
file it pointed at, overwrote existing files without being asked, and ``--name ../../x`` wrote
outside the output folder. ``export urdf/srdf/robotinfo -o`` shared the overwrite and the link.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from robotspec.cli.app import app
from robotspec.cli.options import write_file
from robotspec.cli.output import run_app
from robotspec.errors import RobotSpecError
from tests.conftest import DATA

ARM = str(DATA / "audit_arm" / "audit_arm.yaml")
SECRET = "do not overwrite me\n"


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str]:
    code = run_app(app, list(argv))
    out = capsys.readouterr()
    return code, " ".join((out.out + out.err).replace("\u2502", " ").split())


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    """``tmp/out`` is the output folder; ``tmp/victim.txt`` a file outside it."""
    (tmp_path / "out").mkdir()
    (tmp_path / "victim.txt").write_text(SECRET)
    return tmp_path


@pytest.mark.parametrize("suffix", [".urdf", ".srdf", ".yaml"])
def test_bundle_never_writes_through_a_link(
    folder: Path, capsys: pytest.CaptureFixture[str], suffix: str
) -> None:
    link = folder / "out" / f"audit_arm{suffix}"
    link.symlink_to(folder / "victim.txt")
    for force in ([], ["--force"]):
        code, text = _run(capsys, "export", "bundle", ARM, "-o", str(folder / "out"), *force)
        assert code == 1
        assert f"{link}: error: is a symbolic link; robotspec does not write through links" in text
    assert (folder / "victim.txt").read_text() == SECRET
    # Refused before anything was written: no half bundle beside the link.
    assert sorted(p.name for p in (folder / "out").iterdir()) == [link.name]


def test_bundle_refuses_a_dangling_link(folder: Path, capsys: pytest.CaptureFixture[str]) -> None:
    link = folder / "out" / "audit_arm.yaml"
    link.symlink_to(folder / "created_through_the_link.txt")
    code, text = _run(capsys, "export", "bundle", ARM, "-o", str(folder / "out"), "--force")
    assert code == 1
    assert "is a symbolic link" in text
    assert not (folder / "created_through_the_link.txt").exists()


def test_bundle_overwrites_only_with_force(
    folder: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = folder / "out"
    assert _run(capsys, "export", "bundle", ARM, "-o", str(out))[0] == 0
    (out / "audit_arm.srdf").write_text(SECRET)
    code, text = _run(capsys, "export", "bundle", ARM, "-o", str(out))
    assert code == 1
    assert f"{out / 'audit_arm.urdf'}: error: the file exists; pass --force" in text
    assert (out / "audit_arm.srdf").read_text() == SECRET
    assert _run(capsys, "export", "bundle", ARM, "-o", str(out), "--force")[0] == 0
    assert (out / "audit_arm.srdf").read_text() != SECRET
    assert _run(capsys, "validate", str(out / "audit_arm.yaml"))[0] == 0


@pytest.mark.parametrize("name", ["../../x", "../x", "a/b", "..", ".", "x\\y", "x\x00y", " "])
def test_bundle_name_is_a_plain_file_name(
    folder: Path, capsys: pytest.CaptureFixture[str], name: str
) -> None:
    code, text = _run(capsys, "export", "bundle", ARM, "-o", str(folder / "out"), "--name", name)
    assert code == 2
    assert f"Invalid value for '--name': {name!r} is not a plain file name" in text
    assert list((folder / "out").iterdir()) == []
    assert sorted(p.name for p in folder.iterdir()) == ["out", "victim.txt"]


def test_bundle_plain_name_is_used(folder: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert (
        _run(capsys, "export", "bundle", ARM, "-o", str(folder / "out"), "--name", "arm-2")[0] == 0
    )
    assert sorted(p.name for p in (folder / "out").iterdir()) == [
        "arm-2.srdf",
        "arm-2.urdf",
        "arm-2.yaml",
    ]


@pytest.mark.parametrize(
    "command", [["urdf"], ["srdf"], ["robotinfo", "--chain", "arm"]], ids=lambda c: c[0]
)
def test_single_file_exports_refuse_overwrite_and_links(
    folder: Path, capsys: pytest.CaptureFixture[str], command: list[str]
) -> None:
    target = folder / "out" / "file.txt"
    target.write_text(SECRET)
    code, text = _run(capsys, "export", command[0], ARM, *command[1:], "-o", str(target))
    assert code == 1
    assert f"{target}: error: the file exists; pass --force to overwrite it" in text
    assert target.read_text() == SECRET
    code, _ = _run(capsys, "export", command[0], ARM, *command[1:], "-o", str(target), "--force")
    assert code == 0
    assert target.read_text() != SECRET

    link = folder / "out" / "link.txt"
    link.symlink_to(folder / "victim.txt")
    code, text = _run(capsys, "export", command[0], ARM, *command[1:], "-o", str(link), "--force")
    assert code == 1
    assert f"{link}: error: is a symbolic link" in text
    assert (folder / "victim.txt").read_text() == SECRET


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_a_fifo_is_refused_without_blocking(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(RobotSpecError) as info:
        write_file(fifo, "text", force=True)
    assert info.value.file == str(fifo)


def test_write_file_writes_new_files_exactly(tmp_path: Path) -> None:
    target = tmp_path / "new" / "folder" / "f.txt"
    write_file(target, "é\nline\n", force=False)
    assert target.read_bytes() == "é\nline\n".encode()
    with pytest.raises(RobotSpecError, match="the file exists"):
        write_file(target, "again", force=False)
    write_file(target, "again", force=True)
    assert target.read_text() == "again"


def test_render_never_writes_through_a_link(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from tests.conftest import erd_robots

    erd_robots()
    target = tmp_path / "victim.txt"
    target.write_text("keep me")
    link = tmp_path / "robot.png"
    link.symlink_to(target)
    code, text = _run(capsys, "render", "ur5", "-o", str(link), "--size", "64x48")
    assert code == 1 and "symbolic link" in text
    assert target.read_text() == "keep me"
    out = tmp_path / "real.png"
    code, text = _run(capsys, "render", "ur5", "-o", str(out), "--size", "64x48")
    assert code == 0, text
    assert out.read_bytes().startswith(b"\x89PNG")
