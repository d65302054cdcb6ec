"""``robotspec drive --sim ROBOTINFO --serve``: the command-line side of serving a driver.

Kept out of ``robotspec/cli/drive_cmd.py`` so that the command itself only gains its options and
one call: the driver it builds (the same one ``drive --sim`` runs) is handed to
:func:`serve_driver`, which serves it until the duration ends, Ctrl-C or SIGTERM, and then
shuts down cleanly.
"""

from __future__ import annotations

import signal
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from types import FrameType

from robotspec.driver.robot_driver import RobotDriver
from robotspec.driver.robot_info import RobotInfo
from robotspec.driver.rr_names import rr_name_problem, rr_name_suggestion
from robotspec.service.realtime import prepare_process
from robotspec.service.server import RobotServer, ServeOptions

__all__ = ["serve_driver", "serve_option_problem"]


def serve_option_problem(
    *,
    serve: bool,
    port: int | None,
    public: bool,
    node_name: str | None,
    state_dir: Path | None,
    script: Path | None,
    virtual_time: bool,
) -> str | None:
    """What is wrong with the serving options (with or without ``--serve``), or None."""
    if not serve:
        given = [
            flag
            for flag, value in (
                ("--port", port is not None),
                ("--public", public),
                ("--node-name", node_name is not None),
                ("--state-dir", state_dir is not None),
            )
            if value
        ]
        return f"{', '.join(given)} only apply with --serve" if given else None
    if node_name is not None and (problem := rr_name_problem(node_name)):
        return (
            f"--node-name '{node_name}' {problem}: use letters, digits, '_', '.' and '-', "
            f"starting with a letter (e.g. '{rr_name_suggestion(node_name)}')"
        )
    if virtual_time:
        return "--serve runs in real time; drop --virtual-time"
    if script is not None:
        return "--serve and --script cannot be combined (clients drive the served robot)"
    return None


@contextmanager
def _stop_on_signals(stop: threading.Event, received: list[str]) -> Iterator[None]:
    """While inside, SIGTERM and SIGINT set ``stop`` (recording which) instead of killing.

    Why: a served driver must close its node and remove its lock files however it is stopped;
    the default SIGTERM kills the process on the spot. After the first signal the previous
    handlers are back, so a second Ctrl-C interrupts a shutdown that hangs. Signal handlers can
    only be set from the main thread; elsewhere (a caller's own thread) nothing is changed.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    names = {signal.SIGTERM: "SIGTERM", signal.SIGINT: "Ctrl-C"}
    previous = {sig: signal.getsignal(sig) for sig in names}

    def restore() -> None:
        for sig, handler in previous.items():
            signal.signal(sig, handler)

    def on_signal(signum: int, _frame: FrameType | None) -> None:
        received.append(names.get(signal.Signals(signum), str(signum)))
        stop.set()
        restore()

    for sig in names:
        signal.signal(sig, on_signal)
    try:
        yield
    finally:
        restore()


def serve_driver(
    driver: RobotDriver,
    info: RobotInfo,
    *,
    port: int | None,
    public: bool,
    node_name: str | None,
    state_dir: Path | None,
    duration: float | None,
    fallback_name: str,
) -> str | None:
    """Serve ``driver`` until ``duration`` seconds pass, or SIGTERM or SIGINT (Ctrl-C).

    Either signal ends serving cleanly: the loop stops, the node closes (clients see the
    connection end) and its lock files are removed.

    Returns:
        What stopped it: "SIGTERM", "Ctrl-C", or None when the duration ended.

    Raises:
        ServiceError: the port or the node or device name is in use, or the extra is missing.
    """
    defaults = ServeOptions()
    options = ServeOptions(
        port=defaults.port if port is None else port,
        public=public,
        node_name=node_name,
        state_dir=state_dir,
    )
    stop = threading.Event()
    received: list[str] = []
    with _stop_on_signals(stop, received):
        server = RobotServer(driver, info, options, fallback_name=fallback_name)
        with server:
            # This is the process's own CLI, so the global settings are ours to make: what is
            # loaded so far out of the collector's reach, and a switch interval that hands the
            # interpreter to the loop within a fraction of its period (see service.realtime).
            prepare_process(driver.update_period)
            exposure = (
                "on every interface, discoverable"
                if public
                else "on loopback only (--public to expose)"
            )
            sys.stderr.write(
                f"serving com.robotraconteur.robotics.robot.Robot {exposure}\n"
                f"  url:        {server.url}\n"
                f"  node name:  {server.node_name}\n"
                f"  state dir:  {server.state_dir}\n"
            )
            if server.dropped_fields:
                sys.stderr.write(
                    "note: map fields not served (the Robot Raconteur parser cannot read them): "
                    f"{', '.join(server.dropped_fields)}\n"
                )
            sys.stderr.flush()
            end = None if duration is None else time.monotonic() + duration
            while not stop.is_set():
                if end is None:
                    stop.wait(0.2)
                    continue
                remaining = end - time.monotonic()
                if remaining <= 0.0:
                    break
                stop.wait(min(0.2, remaining))
    return received[0] if received else None
