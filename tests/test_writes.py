"""Writes that cannot be redirected (issue 31): every file robotspec writes goes through
:mod:`robotspec.files.writing`.

The escapes: ``export bundle -o out`` with ``out/NAME_meshes`` planted as a link wrote the mesh
copies into the folder it pointed at (only the last path component was checked); the setup
assistant's save wrote ``.NAME.saving`` with ``Path.write_text`` (following a link planted at
that name) before renaming it over the spec; an output naming the robot's own URDF or SRDF
replaced it. Each case is run through the CLI or the session and through the module, on the
folder-descriptor path and on the portable ``lstat`` path the module falls back to elsewhere.
"""

from __future__ import annotations

import errno
import os
import shutil
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from robotspec.cli.app import app
from robotspec.cli.output import run_app
from robotspec.errors import RobotSpecError
from robotspec.files import writing
from robotspec.files.writing import check_writable, write_file, write_files
from tests.conftest import DATA
from tests.test_bundle_portable import project

SECRET = "do not overwrite me\n"
LINK = "is a symbolic link; robotspec does not write through links"
EXISTS = "the file exists; pass --force to overwrite it"

pytestmark = pytest.mark.skipif(not hasattr(os, "symlink"), reason="no symbolic links here")


@pytest.fixture(params=["dir-fds", "portable"])
def mode(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    """Each module test on both paths: folder descriptors, and the lstat fallback."""
    if request.param == "dir-fds" and not writing.USE_DIR_FDS:
        pytest.skip("this system has no dir_fd/O_NOFOLLOW")
    monkeypatch.setattr(writing, "USE_DIR_FDS", request.param == "dir-fds")
    return str(request.param)


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str]:
    code = run_app(app, list(argv))
    out = capsys.readouterr()
    return code, " ".join((out.out + out.err).replace("\u2502", " ").split())


def _tree(folder: Path) -> list[str]:
    """Every path below ``folder`` (links not followed), relative, sorted."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


@pytest.fixture
def victim(tmp_path: Path) -> Path:
    """A folder outside every output, with one file that must keep its contents."""
    v = tmp_path / "victim"
    v.mkdir()
    (v / "keep.txt").write_text(SECRET)
    return v


def _robot(tmp_path: Path) -> Path:
    """A copy of the small audit arm (URDF, SRDF, spec) in its own folder; the spec's path."""
    folder = tmp_path / "robot"
    folder.mkdir()
    for name in ("audit_arm.urdf", "audit_arm.srdf", "audit_arm.yaml"):
        shutil.copy(DATA / "audit_arm" / name, folder / name)
    return folder / "audit_arm.yaml"


# ------------------------------------------------------------------ a link on the way
def test_bundle_refuses_a_planted_mesh_folder_link(
    tmp_path: Path, victim: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = project(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    planted = out / "arm_meshes"
    planted.symlink_to(victim, target_is_directory=True)
    for force in ([], ["--force"]):
        code, text = _run(capsys, "export", "bundle", str(spec), "-o", str(out), *force)
        assert code == 1, text
        assert f"its folder {planted} {LINK}" in text
        assert str(out / "arm_meshes" / "base.stl") in text  # the file it was to write
    assert _tree(victim) == ["keep.txt"]
    assert (victim / "keep.txt").read_text() == SECRET
    # Checked before anything was written: no URDF, SRDF or spec beside the link either.
    assert _tree(out) == ["arm_meshes"]


def test_a_link_deeper_below_the_named_folder_is_refused(
    tmp_path: Path, victim: Path, mode: str
) -> None:
    out = tmp_path / "out"
    (out / "a").mkdir(parents=True)
    (out / "a" / "b").symlink_to(victim, target_is_directory=True)
    target = out / "a" / "b" / "c" / "file.txt"
    for force in (False, True):
        with pytest.raises(RobotSpecError, match=f"its folder {out / 'a' / 'b'} {LINK}") as info:
            write_file(target, "x", under=out, force=force)
        assert info.value.file == str(target) and info.value.detail.kind == "output"
    assert _tree(victim) == ["keep.txt"]
    assert _tree(out) == ["a", "a/b"]


def test_the_named_folder_and_those_above_it_may_be_links(tmp_path: Path, mode: str) -> None:
    # The user's own choice: `-o ~/link-to-somewhere/robot.urdf` writes there.
    real = tmp_path / "real"
    (real / "out").mkdir(parents=True)
    (tmp_path / "above").symlink_to(real, target_is_directory=True)
    assert write_file(tmp_path / "above" / "out" / "f.txt", "via the user's link") == (
        tmp_path / "above" / "out" / "f.txt"
    )
    assert (real / "out" / "f.txt").read_text() == "via the user's link"
    named = tmp_path / "named"
    named.symlink_to(real / "out", target_is_directory=True)
    write_file(named / "sub" / "g.txt", "made below", under=named)
    assert (real / "out" / "sub" / "g.txt").read_text() == "made below"


def test_a_link_at_the_target_is_refused_always(tmp_path: Path, victim: Path, mode: str) -> None:
    link = tmp_path / "out.txt"
    link.symlink_to(victim / "keep.txt")
    dangling = tmp_path / "dangling.txt"
    dangling.symlink_to(tmp_path / "created_through_the_link.txt")
    for target in (link, dangling):
        for force in (False, True):
            with pytest.raises(RobotSpecError, match=LINK):
                write_file(target, "x", force=force)
    assert (victim / "keep.txt").read_text() == SECRET
    assert not (tmp_path / "created_through_the_link.txt").exists()
    assert link.is_symlink() and dangling.is_symlink()


def test_a_path_leaving_the_named_folder_is_refused(tmp_path: Path, mode: str) -> None:
    out = tmp_path / "out"
    out.mkdir()
    for target in (tmp_path / "elsewhere.txt", out / ".." / "up.txt", out):
        with pytest.raises(RobotSpecError, match="robotspec writes only inside|name a file"):
            write_file(target, "x", under=out)
    assert _tree(tmp_path) == ["out"]


# ------------------------------------------------------------------ the temporary file
def test_setup_save_never_writes_through_a_planted_saving_link(
    tmp_path: Path, victim: Path
) -> None:
    from robotspec.setup import SetupSession

    spec = _robot(tmp_path)
    out = spec.parent  # the spec beside its robot's files (inside the spec's project)
    planted = out / ".x.yaml.saving"  # the name the save used to write through
    planted.symlink_to(victim / "keep.txt")
    session = SetupSession.open(
        str(spec.with_suffix(".urdf")), srdf=str(spec.with_suffix(".srdf")), output=out / "x.yaml"
    )
    assert session.validation.valid
    saved = session.save()
    assert saved == out / "x.yaml"
    assert saved.read_text().startswith("# yaml-language-server")
    assert (victim / "keep.txt").read_text() == SECRET
    assert planted.is_symlink()
    assert [p for p in _tree(out) if p.startswith(".")] == [".x.yaml.saving"]  # no temp left


def test_write_spec_refuses_a_link_at_the_spec(tmp_path: Path, victim: Path) -> None:
    from robotspec.setup.save import write_spec

    link = tmp_path / "x.yaml"
    link.symlink_to(victim / "keep.txt")
    with pytest.raises(RobotSpecError, match=LINK):
        write_spec(link, "robotspec: 1\n")
    assert (victim / "keep.txt").read_text() == SECRET
    write_spec(tmp_path / "y.yaml", "one\n")
    write_spec(tmp_path / "y.yaml", "two\n")  # the assistant saves again and again
    assert (tmp_path / "y.yaml").read_text() == "two\n"


def _names(first: list[str]) -> Iterator[str]:
    yield from first
    while True:
        yield f".planted-free.{len(first)}.tmp"
        first.append("")


def test_a_link_planted_at_the_temporary_name_is_never_opened(
    tmp_path: Path, victim: Path, mode: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The name is random; were it guessed, the exclusive create refuses the planted link and
    # another name is drawn.
    planted = tmp_path / ".f.txt.guessed.tmp"
    planted.symlink_to(victim / "keep.txt")
    names = _names([planted.name])
    monkeypatch.setattr(writing, "_temp_name", lambda name: next(names))
    write_file(tmp_path / "f.txt", "written")
    assert (tmp_path / "f.txt").read_text() == "written"
    assert (victim / "keep.txt").read_text() == SECRET
    assert planted.is_symlink()
    assert _tree(tmp_path) == [".f.txt.guessed.tmp", "f.txt", "victim", "victim/keep.txt"]


def test_no_free_temporary_name_is_an_error_that_leaves_nothing(
    tmp_path: Path, victim: Path, mode: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    planted = tmp_path / "out" / ".guessed.tmp"
    planted.parent.mkdir()
    planted.symlink_to(victim / "keep.txt")
    monkeypatch.setattr(writing, "_temp_name", lambda name: planted.name)
    with pytest.raises(RobotSpecError, match="cannot write file: no free temporary file name"):
        write_file(tmp_path / "out" / "f.txt", "x")
    assert _tree(tmp_path / "out") == [".guessed.tmp"]
    assert (victim / "keep.txt").read_text() == SECRET


# ------------------------------------------------------------------ the robot's own files
@pytest.mark.parametrize(
    ("head", "tail", "suffix", "role"),
    [
        (["export", "urdf"], ["--force"], ".urdf", "its URDF"),
        (["export", "srdf"], ["--force"], ".srdf", "its SRDF"),
        (["export", "robotinfo"], ["--chain", "arm", "--force"], ".yaml", "its spec"),
        (
            ["collisions", "generate"],
            ["-n", "10", "-j", "1", "--merge", "--force"],
            ".srdf",
            "its SRDF",
        ),
        (["render"], ["--size", "32x24"], ".urdf", "its URDF"),  # render overwrites unasked
    ],
    ids=["export-urdf", "export-srdf", "export-robotinfo", "collisions-generate", "render"],
)
def test_an_output_naming_the_robots_own_file_is_refused(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    head: list[str],
    tail: list[str],
    suffix: str,
    role: str,
) -> None:
    spec = _robot(tmp_path)
    own = spec.with_suffix(suffix)
    before = own.read_bytes()
    code, text = _run(capsys, *head, str(spec), *tail, "-o", str(own))
    assert code == 1, text
    assert (
        f"{own}: error: is an input of the robot ({role}); robotspec never writes over a "
        "robot's own files; name another file" in text
    )
    assert own.read_bytes() == before
    assert _tree(spec.parent) == ["audit_arm.srdf", "audit_arm.urdf", "audit_arm.yaml"]


def test_another_name_of_an_input_is_refused_too(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Compared by device and inode: a hard link, or a path through a link, is the same file.
    spec = _robot(tmp_path)
    srdf = spec.with_suffix(".srdf")
    before = srdf.read_bytes()
    hard = tmp_path / "hard.srdf"
    os.link(srdf, hard)
    (tmp_path / "via").symlink_to(spec.parent, target_is_directory=True)
    for target in (hard, tmp_path / "via" / "audit_arm.srdf"):
        code, text = _run(capsys, "export", "srdf", str(spec), "-o", str(target), "--force")
        assert code == 1, text
        assert "is an input of the robot (its SRDF)" in text
    assert srdf.read_bytes() == before and hard.read_bytes() == before


def test_init_refuses_to_write_over_its_urdf(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = _robot(tmp_path)
    urdf = spec.with_suffix(".urdf")
    before = urdf.read_bytes()
    code, text = _run(capsys, "init", str(urdf), "-o", str(urdf), "--force")
    assert code == 1
    assert "is an input of the robot (its URDF)" in text
    assert urdf.read_bytes() == before


def test_the_bundle_never_replaces_a_mesh_it_copies(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A bundle written into the description's own mesh folder names a source mesh as a copy.
    spec = project(tmp_path)
    meshes = spec.parent / "robots" / "arm" / "meshes"
    stl = (meshes / "base.stl").read_bytes()
    os.link(meshes / "base.stl", tmp_path / "copy.stl")
    out = tmp_path / "out"
    (out / "arm_meshes").mkdir(parents=True)
    os.link(meshes / "base.stl", out / "arm_meshes" / "base.stl")
    code, text = _run(capsys, "export", "bundle", str(spec), "-o", str(out), "--force")
    assert code == 1, text
    assert "is an input of the robot (one of its meshes)" in text
    assert (meshes / "base.stl").read_bytes() == stl
    assert _tree(out) == ["arm_meshes", "arm_meshes/base.stl"]


def test_module_inputs_by_role(tmp_path: Path, mode: str) -> None:
    own = tmp_path / "robot.srdf"
    own.write_text(SECRET)
    with pytest.raises(RobotSpecError, match=r"input of the robot \(its SRDF\)"):
        write_file(own, "x", force=True, inputs={own: "its SRDF"})
    with pytest.raises(RobotSpecError, match="is an input of the robot; robotspec never"):
        write_file(own, "x", force=True, inputs=[own])
    write_file(tmp_path / "other.srdf", "x", inputs=[own, tmp_path / "missing.urdf"])
    assert own.read_text() == SECRET


# ------------------------------------------------------------------ --force, and what is left
def test_force_replaces_only_a_regular_file(tmp_path: Path, mode: str) -> None:
    target = tmp_path / "f.txt"
    write_file(target, "first")
    with pytest.raises(RobotSpecError, match=EXISTS):
        write_file(target, "second")
    assert target.read_text() == "first"
    os.chmod(target, 0o640)
    write_file(target, "second", force=True)
    assert target.read_text() == "second"
    assert (target.stat().st_mode & 0o777) == 0o640  # an overwritten file keeps its mode
    (tmp_path / "folder").mkdir()
    with pytest.raises(RobotSpecError, match="is not a regular file"):
        write_file(tmp_path / "folder", "x", force=True)
    assert _tree(tmp_path) == ["f.txt", "folder"]


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_a_fifo_at_the_target_is_refused_without_blocking(tmp_path: Path, mode: str) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    for force in (False, True):
        with pytest.raises(RobotSpecError, match="is not a regular file") as info:
            write_file(fifo, "x", force=force)
        assert info.value.file == str(fifo)
    assert _tree(tmp_path) == ["pipe"]


def test_schema_and_collisions_keep_an_existing_file_without_force(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = _robot(tmp_path)
    out = tmp_path / "out.txt"
    out.write_text(SECRET)
    for argv in (
        ["schema"],
        ["collisions", "generate", str(spec), "-n", "10", "-j", "1"],
        ["init", str(spec.with_suffix(".urdf"))],
    ):
        code, text = _run(capsys, *argv, "-o", str(out))
        assert code == 1, text
        assert f"{out}: error: {EXISTS}" in text
        assert out.read_text() == SECRET
    assert _run(capsys, "schema", "-o", str(out), "--force")[0] == 0
    assert out.read_text().startswith("{")


def test_a_failed_write_leaves_no_folder_and_no_temporary_file(
    tmp_path: Path, mode: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "out"
    out.mkdir()

    def full(fd: int, data: bytes, mode_: int | None) -> None:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(writing, "_fill", full)
    target = out / "new" / "deeper" / "f.txt"
    with pytest.raises(RobotSpecError, match="cannot write file: No space left") as info:
        write_file(target, "x", under=out)
    assert info.value.detail.kind == "file" and info.value.file == str(target)
    assert _tree(out) == []
    # A folder the user named that did not exist is not left behind either.
    with pytest.raises(RobotSpecError, match="No space left"):
        write_file(tmp_path / "made" / "f.txt", "x")
    assert _tree(tmp_path) == ["out"]


def test_a_refused_bundle_file_leaves_no_file_of_the_bundle(tmp_path: Path, mode: str) -> None:
    out = tmp_path / "out"
    (out / "m").mkdir(parents=True)
    (out / "m" / "b.stl").write_text(SECRET)
    files: list[tuple[Path, str | bytes]] = [
        (out / "r.urdf", "urdf"),
        (out / "new" / "a.stl", b"a"),
        (out / "m" / "b.stl", b"b"),
    ]
    with pytest.raises(RobotSpecError, match=EXISTS) as info:
        write_files(files, under=out)
    assert info.value.file == str(out / "m" / "b.stl")
    assert _tree(out) == ["m", "m/b.stl"]
    assert write_files(files, under=out, force=True) == [p for p, _ in files]
    assert (out / "m" / "b.stl").read_bytes() == b"b"
    assert (out / "new" / "a.stl").read_bytes() == b"a"


def test_check_writable_creates_nothing(tmp_path: Path, victim: Path, mode: str) -> None:
    out = tmp_path / "out"
    out.mkdir()
    check_writable(out / "a" / "b" / "f.txt", under=out)
    assert _tree(out) == []
    (out / "l").symlink_to(victim, target_is_directory=True)
    with pytest.raises(RobotSpecError, match=LINK):
        check_writable(out / "l" / "f.txt", under=out)


# ------------------------------------------------------------------ racing writers
@pytest.mark.parametrize("hard_links", [True, False], ids=["link", "no-hard-links"])
def test_concurrent_exclusive_creation_has_one_winner(
    tmp_path: Path, mode: str, monkeypatch: pytest.MonkeyPatch, hard_links: bool
) -> None:
    if not hard_links:  # a file system without hard links: the name is claimed another way
        real_link = os.link

        def no_link(*args: object, **kwargs: object) -> None:
            raise OSError(errno.EPERM, os.strerror(errno.EPERM))

        monkeypatch.setattr(os, "link", no_link)
        assert os.link is not real_link
    writers = 8
    for round_ in range(10):
        target = tmp_path / f"r{round_}" / "f.txt"
        outcome = _race(target, tmp_path, writers)
        winners = [i for i, o in outcome.items() if o == "wrote"]
        assert len(winners) == 1, outcome
        assert all(o == EXISTS for i, o in outcome.items() if i != winners[0]), outcome
        assert target.read_text() == f"writer {winners[0]}\n" * 1000  # whole, one writer's
        assert _tree(target.parent) == ["f.txt"]  # no temporary file left by the losers


def _race(target: Path, under: Path, writers: int) -> dict[int, str]:
    """``writers`` threads released together, each writing ``target`` without force."""
    barrier = threading.Barrier(writers)
    outcome: dict[int, str] = {}

    def write(i: int) -> None:
        barrier.wait()
        try:
            write_file(target, f"writer {i}\n" * 1000, under=under)
            outcome[i] = "wrote"
        except RobotSpecError as exc:
            outcome[i] = exc.message

    threads = [threading.Thread(target=write, args=(i,)) for i in range(writers)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return outcome


def test_drive_plot_never_writes_through_a_link(tmp_path: Path, victim: Path) -> None:
    pytest.importorskip("matplotlib")
    from robotspec.render.plot import JointTrace, plot_joint_trace

    link = tmp_path / "plot.png"
    link.symlink_to(victim / "keep.txt")
    with pytest.raises(RobotSpecError, match=LINK):
        plot_joint_trace(JointTrace(("j",)), link)
    assert (victim / "keep.txt").read_text() == SECRET
    drawn = plot_joint_trace(JointTrace(("j",)), tmp_path / "real.png")
    assert drawn.path.read_bytes().startswith(b"\x89PNG")


def test_a_state_log_is_never_written_through_a_link(tmp_path: Path) -> None:
    from robotspec.driver.statelog import StateLog

    victim = tmp_path / "victim.txt"
    victim.write_text("keep me\n")
    (tmp_path / "log.csv").symlink_to(victim)
    with pytest.raises(RobotSpecError, match="is a symbolic link"):
        StateLog(tmp_path / "log.csv", ("j1",), 1)
    assert victim.read_text() == "keep me\n"
    os.mkfifo(tmp_path / "fifo.csv")
    with pytest.raises(RobotSpecError, match="not a regular file"):
        StateLog(tmp_path / "fifo.csv", ("j1",), 1)
    log = StateLog(tmp_path / "ok.csv", ("j1",), 1)
    log.close()
    assert (tmp_path / "ok.csv").read_text().startswith("t,seqno")
