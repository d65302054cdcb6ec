"""``robotspec drive --serve`` stops cleanly on SIGTERM and SIGINT, leaving no stale lock files.

The server runs as a subprocess (signals are process-wide); a real RR client connects to it, then
the signal is sent to that child by its handle. The node must close (the client's connection
ends), the summary must be printed, the exit code must be 0, and Robot Raconteur's ``.pid`` and
``.info`` files must be gone from the run folder, while the node's identity is kept.
"""

from __future__ import annotations

import errno
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip(
    "RobotRaconteur",
    reason="robotraconteur is not installed (pip install robotspec[robotraconteur])",
)
pytest.importorskip(
    "RobotRaconteurCompanion",
    reason="robotraconteurcompanion is not installed (pip install robotspec[robotraconteur])",
)

from robotspec.driver.robot_info import Identifier, load_robot_info
from robotspec.driver.sim import SimRobot
from robotspec.driver.state import CommandMode
from robotspec.service.server import RobotServer, ServeOptions

from .driver_support import RRP
from .service_support import CHILD_WAIT, client_node, short_tmp

__all__ = ["client_node", "short_tmp"]  # fixtures from service_support, used by the tests below


def run_files(state: Path) -> list[str]:
    run = state / "run"
    return sorted(p.relative_to(state).as_posix() for p in run.rglob("*") if p.is_file())


@pytest.fixture
def served_child(short_tmp: Path) -> Iterator[tuple[subprocess.Popen[str], str, Path]]:
    """``robotspec drive --sim RRP --serve`` in a child process, until its url is printed."""
    state = short_tmp / "rr"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "robotspec",
            "drive",
            "--sim",
            str(RRP),
            "--serve",
            "--port",
            "0",
            "--state-dir",
            str(state),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stderr is not None
        url = ""
        seen: list[str] = []
        deadline = time.monotonic() + CHILD_WAIT
        while not url and time.monotonic() < deadline:
            line = proc.stderr.readline()
            seen.append(line)
            if not line:
                break
            if line.strip().startswith("url:"):
                url = line.split("url:", 1)[1].strip()
        if not url:
            proc.kill()
            _, rest = proc.communicate()
            pytest.fail(f"no url (exit {proc.returncode}); stderr: {''.join(seen)}{rest}")
        yield proc, url, state
    finally:
        if proc.poll() is None:
            proc.kill()  # only our own child, by its handle
            proc.communicate()


@pytest.mark.parametrize(("sig", "said"), [(signal.SIGTERM, "SIGTERM"), (signal.SIGINT, "Ctrl-C")])
def test_signal_stops_the_server_cleanly(
    served_child: tuple[subprocess.Popen[str], str, Path],
    client_node: Any,
    sig: signal.Signals,
    said: str,
) -> None:
    import RobotRaconteur as RR

    proc, url, state = served_child
    robot = client_node.ConnectService(url)
    robot.command_mode = int(CommandMode.jog)
    assert any(f.endswith(".pid") for f in run_files(state))  # locks held while serving
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=CHILD_WAIT)
    assert proc.returncode == 0, err
    assert f"stopped by {said} after" in out
    assert "Traceback" not in err
    # The node closed: the client's connection is gone.
    with pytest.raises(RR.RobotRaconteurException):
        _ = robot.command_mode
    try:
        client_node.DisconnectService(robot)
    except RR.RobotRaconteurException:
        pass
    assert run_files(state) == []  # no stale .pid or .info files
    # The identity stays: the same NodeID and device UUID next time.
    assert (state / "state" / "nodeids" / "rrp_test_arm").is_file()
    assert (state / "state" / "identifiers" / "device" / "rrp_test_arm").is_file()


def test_stop_removes_only_its_own_lock_files(short_tmp: Path) -> None:
    # Two servers in one process share a state folder: stopping one keeps the other's locks.
    info = load_robot_info(RRP)
    other = info.model_copy(
        update={
            "device_info": info.device_info.model_copy(update={"device": Identifier(name="second")})
        }
    )
    state = short_tmp / "rr"
    a = RobotServer(SimRobot(info), info, ServeOptions(port=0, state_dir=state), start_loop=False)
    b = RobotServer(SimRobot(other), other, ServeOptions(port=0, state_dir=state), start_loop=False)
    with a:
        with b:
            both = run_files(state)
            assert "run/identifiers/device/second.pid" in both
        left = run_files(state)
        assert left and all("second" not in f for f in left)
        assert set(left) < set(both)
        assert "run/identifiers/device/rrp_test_arm.pid" in left  # a's device lock: still held
    assert run_files(state) == []


def _port_of(url: str) -> int:
    return int(url.split("://", 1)[1].split("?", 1)[0].rsplit(":", 1)[1])


def _bind_without_reuse(port: int) -> OSError | None:
    """Try to listen on ``port`` as a server without SO_REUSEADDR would; the error, if any."""
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        s.bind(("127.0.0.1", port))
    except OSError as exc:
        return exc
    finally:
        s.close()
    return None


def test_a_driver_stopped_with_a_client_connected_restarts_on_its_port_at_once(
    served_child: tuple[subprocess.Popen[str], str, Path], client_node: Any
) -> None:
    """Issue 31: after SIGTERM with a client connected, the next driver on the same port said
    "TCP port P is already in use" for 64 s (the closed connection's TIME_WAIT on the port).

    Two clients are connected: a Robot Raconteur client, and one that answers nothing (a hung
    or slow client), so the stopping driver closes that connection first and TIME_WAIT lands
    on the driver's port, on any machine. The test checks that it did (a plain bind fails),
    then starts the next driver on that port at once: it must listen there and serve.
    """
    import RobotRaconteur as RR

    proc, url, state = served_child
    port = _port_of(url)
    robot = client_node.ConnectService(url)
    assert robot.robot_info.device_info.device.name == "rrp_test_arm"
    silent = socket.create_connection(("127.0.0.1", port), timeout=5)
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=CHILD_WAIT)
    assert proc.returncode == 0, err
    assert "stopped by SIGTERM after" in out
    silent.close()  # the driver closed first: its side of this connection waits in TIME_WAIT
    try:
        client_node.DisconnectService(robot)
    except RR.RobotRaconteurException:
        pass
    blocked = _bind_without_reuse(port)
    assert isinstance(blocked, OSError) and blocked.errno == errno.EADDRINUSE, (
        f"the stopped driver left no TIME_WAIT on port {port}: the test proves nothing ({blocked})"
    )
    again = subprocess.run(
        [
            sys.executable,
            "-m",
            "robotspec",
            "drive",
            "--sim",
            str(RRP),
            "--serve",
            "--port",
            str(port),
            "--state-dir",
            str(state),
            "--duration",
            "0.5",
        ],
        capture_output=True,
        text=True,
        timeout=CHILD_WAIT,
    )
    assert again.returncode == 0, again.stderr
    assert "already in use" not in again.stderr
    assert f"url:        rr+tcp://127.0.0.1:{port}?service=robot" in again.stderr
