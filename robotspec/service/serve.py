"""``robotspec drive --sim ROBOTINFO --serve``: the command-line side of serving a driver.

Kept out of ``robotspec/cli/drive_cmd.py`` so that the command itself only gains its options and
one call: the driver it builds (the same one ``drive --sim`` runs) is handed to
:func:`serve_driver`, which serves it until the duration ends or Ctrl-C.
"""

from __future__ import annotations

import gc
import sys
import time
from pathlib import Path

from robotspec.driver.robot_driver import RobotDriver
from robotspec.driver.robot_info import RobotInfo
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
    if virtual_time:
        return "--serve runs in real time; drop --virtual-time"
    if script is not None:
        return "--serve and --script cannot be combined (clients drive the served robot)"
    return None


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
) -> None:
    """Serve ``driver`` until ``duration`` seconds pass (None: until Ctrl-C, which propagates).

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
    server = RobotServer(driver, info, options, fallback_name=fallback_name)
    with server:
        # Everything loaded so far lives as long as the process: move it out of the cyclic
        # collector's reach, so a full collection (tens of ms over all of pydantic, numpy and
        # RR) does not stall the 250 Hz loop. This is the process's own CLI, so the global
        # setting is ours to make.
        gc.freeze()
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
        while end is None or time.monotonic() < end:
            remaining = 0.2 if end is None else min(0.2, max(0.0, end - time.monotonic()))
            time.sleep(remaining)
