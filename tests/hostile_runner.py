"""Run the robotspec CLI on hostile input under memory and CPU limits, logging every file opened.

Usage: ``python hostile_runner.py MEMORY_BYTES CPU_SECONDS OPEN_LOG -- ARGS...``. The audit hook
records every ``open`` (Python's ``open``/``os.open``) so a test can prove that no file outside
the allowed roots was read; the limits turn a bomb into a killed process instead of a hung or
swapping test run.
"""

from __future__ import annotations

import os
import resource
import sys


def main() -> None:
    memory, cpu, log = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    args = sys.argv[sys.argv.index("--") + 1 :]
    resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu))
    opened: list[str] = []

    def hook(event: str, hook_args: tuple[object, ...]) -> None:
        if event == "open" and hook_args and isinstance(hook_args[0], (str, bytes, os.PathLike)):
            opened.append(os.path.abspath(os.fsdecode(hook_args[0])))

    sys.addaudithook(hook)
    from robotspec.cli.app import main as cli

    try:
        cli(args)
    finally:
        with open(log, "w", encoding="utf-8") as f:
            f.write("\n".join(opened))


if __name__ == "__main__":
    main()
