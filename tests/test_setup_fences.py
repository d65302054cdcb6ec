"""The setup assistant's fences (issue 31): its page is the user's alone, its writes stay put.

The page: a real websocket client (the ``websockets`` package viser itself uses) connects as a
page from another site, without the run's token, with a wrong one, and as the page itself; only
the last gets the assistant's state. The writes: "save as" stays in the output's folder (unless
the command line allows another), never replaces a file of the robot, and a refused save leaves
nothing behind; the collision matrix waits in the session until "save" and never takes the
name of the robot's own SRDF.
"""

from __future__ import annotations

import shutil
import urllib.error
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from robotspec.setup.access import PageAccess, is_loopback
from tests.conftest import erd_robots


# ---------------------------------------------------------------------------------- the page
@pytest.fixture(scope="module")
def page(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Any]:
    pytest.importorskip("viser")
    from robotspec.setup import SetupSession
    from robotspec.setup.page import SetupPage

    urdf = erd_robots() / "xarm_description" / "urdf" / "xarm7.urdf"
    out = tmp_path_factory.mktemp("page") / "xarm.yaml"
    p = SetupPage(SetupSession.open(str(urdf), output=out), port=0)
    yield p
    p.stop()


def _connect(page: Any, query: str = "", *, host: str = "127.0.0.1", **kw: Any) -> str:
    """Open the page's websocket; what came back first ('state N bytes') or why it was refused.

    ``host`` is the name the request gives (its Host header); the socket goes to 127.0.0.1.
    """
    import socket

    import viser
    from websockets.exceptions import InvalidStatus
    from websockets.sync.client import connect

    port = page.viewer.port
    sock = socket.create_connection(("127.0.0.1", port), timeout=60)
    try:
        with connect(
            f"ws://{host}:{port}/{query}",
            sock=sock,
            subprotocols=[f"viser-v{viser.__version__}"],
            max_size=None,
            open_timeout=60,
            **kw,
        ) as ws:
            message = ws.recv(timeout=60)  # hang bounds: a busy machine (issue 31)
            return f"state {len(message)} bytes"
    except InvalidStatus as exc:
        body = exc.response.body.decode()
        return f"refused {exc.response.status_code}: {body}"
    finally:
        sock.close()


def test_a_page_from_another_site_is_refused_and_gets_no_state(page: Any) -> None:
    token = page.access.token
    got = _connect(page, origin="http://evil.example")
    assert got.startswith("refused 403") and "token" in got
    # Even a page that somehow holds the token: another origin is refused by name.
    got = _connect(page, f"?token={token}", origin="http://evil.example")
    assert got == (
        "refused 403: robotspec setup: a page from http://evil.example may not use this "
        "page's connection\n"
    )
    # The page's own origin with a port of another server is another origin.
    other = f"http://127.0.0.1:{page.viewer.port + 1}"
    assert _connect(page, f"?token={token}", origin=other).startswith("refused 403")


def test_no_token_or_a_wrong_one_is_refused(page: Any) -> None:
    for query in ("", "?token=", "?token=wrong", f"?token={page.access.token[:-1]}"):
        assert _connect(page, query).startswith("refused 403: robotspec setup: open the address")
    own = f"http://127.0.0.1:{page.viewer.port}"
    assert _connect(page, origin=own).startswith("refused 403")  # own origin, no token
    cookie = {"Cookie": f"{PageAccess.cookie_name(page.viewer.port)}=nope"}
    assert _connect(page, origin=own, additional_headers=cookie).startswith("refused 403")


def test_the_token_and_the_own_origin_get_the_page(page: Any) -> None:
    port = page.viewer.port
    token = page.access.token
    assert page.url.endswith(f":{port}/?token={token}")  # printed as notebook servers do
    assert _connect(page, f"?token={token}").startswith("state ")  # a client without a browser
    own = f"http://127.0.0.1:{port}"
    assert _connect(page, f"?token={token}", origin=own).startswith("state ")
    # A browser: opening the printed address sets the cookie its websocket then presents.
    with urllib.request.urlopen(page.url.replace("localhost", "127.0.0.1"), timeout=60) as resp:
        assert resp.status == 200
        cookie = resp.headers["Set-Cookie"]
    assert "HttpOnly" in cookie and "SameSite=Strict" in cookie
    jar = {"Cookie": cookie.split(";")[0]}
    assert _connect(page, origin=own, additional_headers=jar).startswith("state ")
    # The page without its token says what to open, and serves nothing else.
    with pytest.raises(urllib.error.HTTPError) as exc:
        urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=60)
    assert exc.value.code == 403 and b"carries the page's token" in exc.value.read()


def test_a_loopback_page_refuses_other_host_names(page: Any) -> None:
    """DNS rebinding: a page of evil.example resolved to 127.0.0.1 names its own host."""
    token = page.access.token
    port = page.viewer.port
    got = _connect(
        page, f"?token={token}", host="evil.example", origin=f"http://evil.example:{port}"
    )
    assert got.startswith("refused 403") and "this machine only" in got
    assert _connect(page, f"?token={token}", host="localhost").startswith("state ")
    two_hosts = {"additional_headers": {"Host": f"127.0.0.1:{port}"}}
    assert "one host" in _connect(page, f"?token={token}", **two_hosts)
    assert is_loopback("127.0.0.1") and is_loopback("localhost") and is_loopback("[::1]")
    assert not is_loopback("0.0.0.0") and not is_loopback("evil.example")
    assert not PageAccess.for_host("0.0.0.0").loopback and PageAccess.for_host("::1").loopback
    assert PageAccess.for_host("x").token != PageAccess.for_host("x").token  # one per run


def test_save_as_on_the_page_outside_its_folder_says_why_and_writes_nothing(
    page: Any, tmp_path: Path
) -> None:
    person = type("Person", (), {"client": object()})()
    page._save_path.value = str(tmp_path / "elsewhere" / "x.yaml")
    page._guarded(lambda _e: page._save())(person)
    assert "not saved" in page.last_message and "--allow-save" in page.last_message
    assert list(tmp_path.iterdir()) == []


def test_a_viser_without_the_hook_is_refused_not_served_unguarded() -> None:
    from robotspec.errors import ServiceError
    from robotspec.setup.access import start_guarded

    stopped: list[str] = []
    with pytest.raises(ServiceError, match="cannot let only this page's own origin"):
        start_guarded(PageAccess(loopback=True), lambda: "server", stopped.append)
    assert stopped == ["server"]


# ---------------------------------------------------------------------------------- the writes
def _panda_beside_its_files(tmp_path: Path) -> tuple[Any, Path]:
    """``robotspec setup panda.urdf --srdf panda.srdf -o panda.yaml`` in the robot's folder."""
    from robotspec.setup import SetupSession

    erd = erd_robots() / "panda_description"
    robot = tmp_path / "robot"
    robot.mkdir()
    shutil.copy(erd / "urdf" / "panda.urdf", robot / "panda.urdf")
    shutil.copy(erd / "srdf" / "panda.srdf", robot / "panda.srdf")
    session = SetupSession.open(
        str(robot / "panda.urdf"), srdf=str(robot / "panda.srdf"), output=robot / "panda.yaml"
    )
    assert session.validation.valid, session.validation.errors
    assert session.draft().srdf == "panda.srdf"
    return session, robot


def _tree(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def _xarm(tmp_path: Path, **kw: Any) -> Any:
    from robotspec.setup import SetupSession

    urdf = erd_robots() / "xarm_description" / "urdf" / "xarm7.urdf"
    return SetupSession.open(str(urdf), output=tmp_path / "out" / "xarm.yaml", **kw)


def test_save_as_outside_the_output_folder_is_refused_and_creates_nothing(tmp_path: Path) -> None:
    from robotspec.errors import RobotSpecError

    s = _xarm(tmp_path)
    assert not (tmp_path / "out").exists()  # checking the draft there created nothing
    (tmp_path / "out").mkdir()
    before = sorted(p.name for p in tmp_path.rglob("*"))
    for target in (
        tmp_path / "elsewhere" / "deep" / "x.yaml",
        tmp_path / "out" / ".." / "x.yaml",
        Path.home() / ".config" / "robotspec-setup-test.yaml",
    ):
        with pytest.raises(RobotSpecError, match="inside .*--allow-save DIR") as exc:
            s.save(target)
        assert exc.value.file == str(target)
    assert sorted(p.name for p in tmp_path.rglob("*")) == before  # no folder, no file
    assert not (Path.home() / ".config" / "robotspec-setup-test.yaml").exists()
    # A link in the output's folder to another folder does not carry a save out of it.
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "out" / "sub").symlink_to(tmp_path / "elsewhere")
    with pytest.raises(RobotSpecError, match="symbolic link"):
        s.save(tmp_path / "out" / "sub" / "x.yaml")
    assert list((tmp_path / "elsewhere").iterdir()) == []
    # Inside the folder, a new subfolder is fine; --allow-save adds a folder.
    assert s.save(tmp_path / "out" / "new" / "x.yaml").is_file()
    s2 = _xarm(tmp_path, allow_save=[tmp_path / "elsewhere"])
    assert s2.save(tmp_path / "elsewhere" / "x.yaml").is_file()


def test_save_as_never_replaces_a_file_of_the_robot_or_another_file(tmp_path: Path) -> None:
    from robotspec.errors import RobotSpecError
    from robotspec.setup import SetupSession

    session, robot = _panda_beside_its_files(tmp_path)
    files = _tree(robot)
    for name, why in (
        ("panda.urdf", "a spec is a .yaml or .yml file"),
        ("panda.srdf", "a spec is a .yaml or .yml file"),
    ):
        with pytest.raises(RobotSpecError, match=why):
            session.save(robot / name)
    # Another name of the URDF (a hard link) is still the URDF.
    (robot / "alias.yaml").hardlink_to(robot / "panda.urdf")
    with pytest.raises(RobotSpecError, match="this is its URDF, a file of the robot"):
        session.save(robot / "alias.yaml")
    (robot / "alias.yaml").unlink()
    # Someone else's file in the folder is not replaced either.
    (robot / "mine.yaml").write_text("name: mine\n")
    with pytest.raises(RobotSpecError, match="the file exists and is not the spec"):
        session.save(robot / "mine.yaml")
    (robot / "mine.yaml").unlink()
    # A save whose relative paths would not resolve there is refused, leaving no folder.
    with pytest.raises(RobotSpecError, match="relative paths do not resolve"):
        session.save(robot / "sub" / "panda.yaml")
    assert not (robot / "sub").exists()
    assert _tree(robot) == files  # nothing written by the refusals
    # The output itself is saved, and saved again; the spec it was opened from only as output.
    assert session.save() == robot / "panda.yaml"
    assert session.save() == robot / "panda.yaml"
    again = SetupSession.open(str(robot / "panda.yaml"), output=robot / "copy.yaml")
    with pytest.raises(RobotSpecError, match="this is the spec it was opened from"):
        again.save(robot / "panda.yaml")
    in_place = SetupSession.open(str(robot / "panda.yaml"), output=robot / "panda.yaml")
    assert in_place.save().read_text() == (robot / "panda.yaml").read_text()
    assert (robot / "panda.urdf").read_bytes() == files["panda.urdf"]


def test_the_collision_matrix_never_replaces_the_robots_srdf(tmp_path: Path) -> None:
    from robotspec.compiler import check_spec
    from robotspec.setup.collisions import audit_session, generate_matrix

    session, robot = _panda_beside_its_files(tmp_path)
    files = _tree(robot)
    own = files["panda.srdf"]
    assert own.count(b"<disable_collisions") == 35
    result = generate_matrix(session, samples=200)
    # Nothing is written before save, and the spec names a file that is not the robot's SRDF.
    assert _tree(robot) == files
    assert result.srdf == robot / "panda.collisions.srdf" and not result.srdf.exists()
    assert session.draft().srdf == "panda.collisions.srdf" and session.validation.valid
    assert "panda.collisions.srdf, which save writes" in result.summary
    ok, report = audit_session(session, samples=100)
    assert ".setup-" not in report
    assert not session.snapshot.saved
    session.save()
    assert (robot / "panda.srdf").read_bytes() == own  # byte-identical
    generated = (robot / "panda.collisions.srdf").read_text()
    assert generated.count("<disable_collisions") != 35 and "<group " in generated
    assert "srdf: panda.collisions.srdf" in (robot / "panda.yaml").read_text()
    assert check_spec(robot / "panda.yaml").robot.srdf is not None
    assert session.snapshot.saved
    # Generating again replaces the session's own SRDF at save, still never the robot's.
    generate_matrix(session, samples=100, seed=1)
    assert not session.snapshot.saved
    session.save()
    assert (robot / "panda.srdf").read_bytes() == own
    # Undone back to the robot's SRDF, the spec names it again (and save writes no SRDF).
    session.undo()
    session.undo()
    assert session.draft().srdf == "panda.srdf" and session.validation.valid
    assert "srdf: panda.srdf" in session.snapshot.text


def test_the_setup_command_checks_its_save_options(tmp_path: Path) -> None:
    from robotspec.cli.app import main

    pytest.importorskip("viser")
    urdf = erd_robots() / "xarm_description" / "urdf" / "xarm7.urdf"
    for args in (
        ["-o", str(tmp_path / "xarm.urdf")],
        ["--allow-save", str(tmp_path / "missing")],
    ):
        with pytest.raises(SystemExit) as exc:
            main(["setup", str(urdf), *args])
        assert exc.value.code == 2
    assert list(tmp_path.iterdir()) == []


def test_the_command_prints_the_address_with_its_token_and_warns_beyond_loopback(
    tmp_path: Path,
) -> None:
    import os
    import re
    import subprocess
    import sys
    import time

    pytest.importorskip("viser")
    urdf = erd_robots() / "xarm_description" / "urdf" / "xarm7.urdf"
    cmd = [sys.executable, "-m", "robotspec", "setup", str(urdf), "-o", str(tmp_path / "x.yaml")]
    proc = subprocess.Popen(
        [*cmd, "--host", "0.0.0.0", "--port", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    try:
        lines: list[str] = []
        end = time.monotonic() + 120
        while time.monotonic() < end and not any("note: serving on" in x for x in lines):
            line = proc.stdout.readline() if proc.stdout else ""
            if not line:
                break
            lines.append(line)
        out = "".join(lines)
        found = re.search(r"http://localhost:(\d+)/\?token=([\w-]+)", out)
        assert found, out + (proc.stderr.read() if proc.poll() is not None and proc.stderr else "")
        assert "note: serving on 0.0.0.0" in out and "token is required" in out

        class _Page:  # what _connect needs of a page
            viewer = type("V", (), {"port": int(found[1])})

        assert _connect(_Page(), f"?token={found[2]}").startswith("state ")
        assert _connect(_Page(), origin="http://evil.example").startswith("refused 403")
    finally:
        proc.terminate()
        proc.communicate(timeout=30)  # waits, and closes its pipes
