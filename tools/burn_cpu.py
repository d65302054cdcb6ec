"""Load every core with busy processes, alone or around a command (the tests under load).

Why: the test suite must not depend on the machine being idle (issue 31). CI runs the tests
whose outcome could depend on timing (loop periods, wire latency, a browser's tab) while this
keeps every core busy, as another build or another engineer's test run would.

    python tools/burn_cpu.py -- .venv/bin/python -m pytest -q tests/test_service.py
    python tools/burn_cpu.py --seconds 60          # just burn, e.g. beside a manual run
    python tools/burn_cpu.py --procs 4 -- CMD ...  # more burners than cores

With a command, the burners start, the command runs, the burners stop, and the exit status is the
command's. Each burner is a separate process (no GIL between them) at the same priority as the
command, spinning in pure Python; each checks now and then that its parent is still alive, so a
killed parent (a cancelled CI job) never leaves burners behind.
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import subprocess
import sys
import time
from multiprocessing.process import BaseProcess

#: Busy iterations between two checks that the parent is alive (a few milliseconds of work).
_CHECK_EVERY = 200_000


def _burn(parent: int, until: float) -> None:
    """Spin until ``until`` (monotonic seconds; inf: forever) or until ``parent`` is gone."""
    x = 0
    while True:
        for i in range(_CHECK_EVERY):
            x ^= i
        if os.getppid() != parent or time.monotonic() >= until:
            return


def start_burners(procs: int, seconds: float = float("inf")) -> list[BaseProcess]:
    """Start ``procs`` busy processes that stop after ``seconds`` or when this process exits."""
    until = time.monotonic() + seconds
    ctx = mp.get_context("spawn")  # no copy of the caller's threads or locks
    burners: list[BaseProcess] = [
        ctx.Process(target=_burn, args=(os.getpid(), until), daemon=True, name=f"burn-{k}")
        for k in range(procs)
    ]
    for p in burners:
        p.start()
    return burners


def stop_burners(burners: list[BaseProcess]) -> None:
    """Stop the burners (each one, by its own process)."""
    for p in burners:
        p.terminate()
    for p in burners:
        p.join(5.0)


def main(argv: list[str] | None = None) -> int:
    """Burn, around ``-- COMMAND`` when given (its exit status), else for ``--seconds``."""
    args = sys.argv[1:] if argv is None else argv
    command: list[str] = []
    if "--" in args:
        k = args.index("--")
        args, command = args[:k], args[k + 1 :]
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--procs", type=int, default=os.cpu_count() or 2, help="busy processes (default: cores)"
    )
    parser.add_argument(
        "--seconds", type=float, default=float("inf"), help="stop after this long (default: never)"
    )
    opts = parser.parse_args(args)
    if opts.procs < 1:
        parser.error("--procs must be at least 1")
    burners = start_burners(opts.procs, opts.seconds)
    sys.stderr.write(f"burn_cpu: {opts.procs} busy processes on {os.cpu_count()} cores\n")
    try:
        if command:
            return subprocess.call(command)
        for p in burners:
            p.join()
        return 0
    except KeyboardInterrupt:
        return 130
    finally:
        stop_burners(burners)


if __name__ == "__main__":
    raise SystemExit(main())
