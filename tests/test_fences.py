"""The fence model (docs/security.md, "Which folders may be read"): one test per escape.

A spec is downloaded with its robot, so what it names is fenced like the robot's own files:
inside the project that holds it, never a hidden or system folder, links resolved. Each escape
found against the previous rule ("relative entries below the top-level and home folders") runs
the CLI in a subprocess with HOME set to a folder of the test, and asserts exit 1, the message
at the spec's line, and that the secret was neither opened nor echoed.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

from robotspec.files.fences import hidden_part, project_root, refusal, too_wide
from tests.test_hostile import Result, run_cli, write, xacro

KEY = "SSH-KEY-CANARY-91c2"


@pytest.fixture
def home(tmp_path: Path) -> Path:
    """A home folder with a secret in ``.ssh`` and a download folder holding a spec."""
    home = tmp_path / "home" / "me"
    write(home / ".ssh" / "id_rsa", f"key: {KEY}\n")
    (home / "Downloads" / "evil").mkdir(parents=True)
    (tmp_path / "work").mkdir()
    return home


def cli(home: Path, *args: str, cwd: Path | None = None) -> Result:
    return run_cli(home.parent.parent, *args, cwd=cwd or home, env={"HOME": str(home)})


def leaked(r: Result, *needles: str) -> bool:
    text = r.out + r.err
    return any(n in text for n in (KEY, *needles)) or any(
        ".ssh" in p or p.startswith(("/etc/fonts", "/proc/self/status")) for p in r.opened
    )


def evil_spec(home: Path, desc_extra: str = "", body: str = "", parts: str = "") -> Path:
    folder = home / "Downloads" / "evil"
    xacro(folder, body)
    spec = f"robotspec: 1\nname: R\nroot: base\ndescription:\n  urdf: r.urdf.xacro\n{desc_extra}"
    return write(folder / "spec.yaml", spec + parts)


LOAD_KEY = "<link name=\"leak_${xacro.load_yaml('../../.ssh/id_rsa')['key']}\"/>"


def test_a_downloaded_spec_cannot_name_the_ssh_folder(home: Path) -> None:
    evil_spec(home, "  package_paths: [../../.ssh]\n", LOAD_KEY)
    r = cli(home, "export", "urdf", "Downloads/evil/spec.yaml", "-o", str(home / "out.urdf"))
    assert r.code == 1, r.text
    assert not leaked(r) and not (home / "out.urdf").exists()
    assert r.err.startswith(
        "Downloads/evil/spec.yaml:6:19: error: package path '../../.ssh' resolves to "
        f"{home}/.ssh, which a spec may not name: it lies outside the spec's project "
        f"{home}/Downloads/evil (a spec may name files and folders inside its own project, "
        f"never hidden or system ones; allow it with -P/--package-path {home}/.ssh, or "
        "ROS_PACKAGE_PATH)"
    )


def test_a_parts_package_paths_cannot_name_the_ssh_folder(home: Path) -> None:
    folder = home / "Downloads" / "evil"
    xacro(folder, LOAD_KEY)
    write(
        folder / "spec.yaml",
        "robotspec: 1\nname: R\nroot: base\nparts:\n  arm:\n    urdf: r.urdf.xacro\n"
        "    package_paths: [../../.ssh]\n",
    )
    r = cli(home, "export", "urdf", "Downloads/evil/spec.yaml")
    assert r.code == 1, r.text
    assert not leaked(r)
    assert "spec.yaml:7:21: error: package path '../../.ssh' resolves to" in r.err


@pytest.mark.skipif(not Path("/etc/fonts/fonts.conf").is_file(), reason="no /etc/fonts here")
def test_a_spec_cannot_open_etc_by_dots_or_by_a_link(home: Path) -> None:
    body = '<xacro:include filename="/etc/fonts/fonts.conf"/>'
    spec = evil_spec(home, "  package_paths: [../../../../../../../../etc/fonts]\n", body)
    r = cli(home, "export", "urdf", "Downloads/evil/spec.yaml")
    assert r.code == 1 and not leaked(r, "fontconfig"), r.text
    assert "which a spec may not name: it lies in the system folder /etc" in r.err
    os.symlink("/etc/fonts", spec.parent / "fonts")
    spec.write_text(spec.read_text().replace("../../../../../../../../etc/fonts", "fonts"))
    r = cli(home, "export", "urdf", "Downloads/evil/spec.yaml")
    assert r.code == 1 and not leaked(r, "fontconfig"), r.text
    assert "package path 'fonts' resolves to /etc/fonts, which a spec may not name" in r.err
    # And without naming it at all: the description's folder never opens a system folder.
    spec.write_text(spec.read_text().replace("  package_paths: [fonts]\n", ""))
    r = cli(home, "export", "urdf", "Downloads/evil/spec.yaml")
    assert r.code == 1 and not leaked(r, "fontconfig"), r.text
    assert "outside the allowed folders" in r.text


def test_a_spec_cannot_name_proc(home: Path) -> None:
    body = '<xacro:include filename="/proc/self/status"/>'
    evil_spec(home, "  package_paths: [../../../../../../../../proc/self]\n", body)
    r = cli(home, "export", "urdf", "Downloads/evil/spec.yaml")
    assert r.code == 1 and not leaked(r, "VmPeak"), r.text
    assert "it lies in the system folder /proc" in r.err


def test_hidden_folders_inside_the_project_stay_closed(home: Path) -> None:
    folder = home / "Downloads" / "evil"
    write(folder / ".secret" / "k.yaml", f"key: {KEY}\n")
    # Named by the spec:
    evil_spec(home, "  package_paths: [.secret]\n", "")
    r = cli(home, "validate", "Downloads/evil/spec.yaml")
    assert r.code == 1 and not leaked(r), r.text
    assert "it lies in the hidden folder or file '.secret'" in r.text
    # Read by the description from its own folder, unnamed:
    evil_spec(home, "", "<link name=\"leak_${xacro.load_yaml('.secret/k.yaml')['key']}\"/>")
    r = cli(home, "export", "urdf", "Downloads/evil/spec.yaml")
    assert r.code == 1 and not leaked(r), r.text
    assert f"resolves to {folder}/.secret/k.yaml, outside the allowed folders" in r.text


def test_a_spec_cannot_name_its_urdf_outside_its_project(home: Path) -> None:
    write(home / "Documents" / "r.urdf", '<robot name="r"><link name="base"/></robot>\n')
    write(
        home / "Downloads" / "evil" / "spec.yaml",
        "robotspec: 1\nname: R\nroot: base\ndescription:\n  urdf: ../../Documents/r.urdf\n",
    )
    r = cli(home, "validate", "Downloads/evil/spec.yaml")
    assert r.code == 1, r.text
    assert "Downloads/evil/spec.yaml:5:9: error: URDF '../../Documents/r.urdf' resolves to" in (
        r.text
    )
    assert f"allow it with -P/--package-path {home}/Documents" in r.text
    r = cli(home, "validate", "Downloads/evil/spec.yaml", "-P", "Documents")
    assert r.code == 0, r.text


def test_minus_p_allows_what_the_spec_may_not_name(home: Path) -> None:
    write(home / "robots" / "r" / "r.urdf", '<robot name="r"><link name="base"/></robot>\n')
    write(
        home / "Downloads" / "evil" / "spec.yaml",
        "robotspec: 1\nname: R\nroot: base\n"
        "description: {urdf: r.urdf, package_paths: [../../robots/r]}\n",
    )
    (home / "Downloads" / "evil" / "r.urdf").write_text(
        '<robot name="r"><link name="base"/></robot>\n'
    )
    assert cli(home, "validate", "Downloads/evil/spec.yaml").code == 1
    r = cli(home, "validate", "Downloads/evil/spec.yaml", "-P", "robots")
    assert r.code == 0, r.text


# ------------------------------------------------------------------- layouts users keep
ARM = '<robot name="arm"><link name="base"/></robot>\n'


def layout(root: Path) -> Path:
    write(root / "robots" / "arm" / "urdf" / "arm.urdf", ARM)
    return write(
        root / "specs" / "arm.yaml",
        "robotspec: 1\nname: Arm\nroot: base\n"
        "description: {urdf: ../robots/arm/urdf/arm.urdf, package_paths: [../robots]}\n",
    )


@pytest.mark.parametrize("marker", [".git", "pyproject.toml", "package.xml", None])
def test_specs_beside_robots_in_a_project_validate(home: Path, marker: str | None) -> None:
    root = home / "code" / "project"
    spec = layout(root)
    if marker == ".git":
        (root / ".git").mkdir()
    elif marker is not None:
        write(root / marker, "")
    r = cli(home, "validate", str(spec))
    assert r.code == 0, r.text


def test_a_project_marker_in_a_subfolder_narrows_the_project(home: Path) -> None:
    root = home / "code" / "project"
    spec = layout(root)
    (root / "specs" / ".git").mkdir()  # the specs are their own repository
    r = cli(home, "validate", str(spec))
    assert r.code == 1 and "outside the spec's project" in r.text, r.text


def test_a_spec_without_a_project_reads_only_its_folder(home: Path) -> None:
    root = home / "code" / "project"
    spec = layout(root)
    moved = root / "config" / "arm.yaml"
    moved.parent.mkdir()
    spec.rename(moved)
    r = cli(home, "validate", str(moved))
    assert r.code == 1 and f"outside the spec's project {root}/config" in r.text, r.text


def test_git_checkout_layout_through_git(home: Path) -> None:
    root = home / "code" / "project"
    spec = layout(root)
    proc = subprocess.run(["git", "init", "-q", str(root)], capture_output=True)
    if proc.returncode != 0:
        pytest.skip("git is not installed")
    assert cli(home, "validate", str(spec)).code == 0


# ---------------------------------------------------------------------------- the model
def test_project_root_stops_below_home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    home = tmp_path / "home" / "me"
    (home / "a" / "b").mkdir(parents=True)
    (home / ".git").mkdir()  # a dotfiles repository never makes the home folder a project
    monkeypatch.setenv("HOME", str(home))
    assert project_root(home / "a" / "b") == home / "a" / "b"
    assert project_root(home) is None
    assert too_wide(str(home)) and too_wide(str(home.parent)) and too_wide("/tmp")
    (home / "a" / "setup.cfg").write_text("")
    assert project_root(home / "a" / "b") == home / "a"


def test_refusal_names_each_reason(tmp_path: Path) -> None:
    project = tmp_path / "p"
    assert refusal(str(project / "robots"), project) is None
    assert "hidden folder or file '.cache'" in str(refusal(str(project / ".cache" / "x"), project))
    assert "system folder /dev" in str(refusal("/dev/zero", project))
    assert "outside the spec's project" in str(refusal(str(tmp_path / "q"), project))
    assert "too wide" in str(refusal(str(project), None))
    assert hidden_part("/a/b/.c/d", "/a/b") == ".c" and hidden_part("/a/.b/c", "/a/.b") is None


def test_extends_is_fenced_before_the_base_is_read(home: Path) -> None:
    write(home / ".config" / "base.yaml", f"robotspec: 1\nname: {KEY}\nroot: base\n")
    evil = write(
        home / "Downloads" / "evil" / "spec.yaml",
        "robotspec: 1\nextends: ../../.config/base.yaml\n",
    )
    r = cli(home, "validate", "Downloads/evil/spec.yaml")
    assert r.code == 1 and not leaked(r), r.text
    assert not [p for p in r.opened if p.endswith("base.yaml")], r.opened
    assert r.text.startswith(
        "Downloads/evil/spec.yaml:2:10: error: extended spec '../../.config/base.yaml' resolves "
        f"to {home}/.config/base.yaml, which a spec may not name: it lies outside"
    )
    # A shipped robot by name, and a base inside the project, need no leave.
    write(evil.parent / "r.urdf", '<robot name="r"><link name="base"/></robot>\n')
    write(
        evil.parent / "base.yaml",
        "robotspec: 1\nname: R\nroot: base\ndescription: {urdf: r.urdf}\n",
    )
    evil.write_text("robotspec: 1\nextends: base.yaml\nname: S\n")
    assert cli(home, "validate", "Downloads/evil/spec.yaml").code == 0
    evil.write_text("robotspec: 1\nextends: pr2\nname: MyPR2\n")
    r = cli(home, "inspect", "chains", "Downloads/evil/spec.yaml")
    assert r.code == 0, r.text


def test_the_setup_assistant_opens_a_spec_behind_the_same_fence(
    home: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from robotspec.errors import RobotSpecError
    from robotspec.setup.from_spec import draft_of_spec

    monkeypatch.setenv("HOME", str(home))
    spec = evil_spec(home, "  package_paths: [../../.ssh]\n", LOAD_KEY)
    with pytest.raises(RobotSpecError) as info:
        draft_of_spec(str(spec))
    assert "package path '../../.ssh' resolves to" in str(info.value)
    assert KEY not in str(info.value)
