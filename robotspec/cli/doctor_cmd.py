"""``robotspec doctor`` and ``robotspec --version``: this install, and which cores answer.

Why a command: the C cores are optional (an install without a compiler, a stale build refused,
``ROBOTSPEC_NO_ACCEL``), and the only symptom of a missing one is speed, 20-60 times slower.
A user who wonders why, or a CI job that must prove a wheel carries its cores (``--require-c``),
asks here instead of timing queries.
"""

from __future__ import annotations

import platform
import sys
import warnings
from typing import Annotated

import typer

from robotspec.cli.table import render_table

#: This module's commands; robotspec.cli.app adds them to the root app.
app = typer.Typer()


def version_line() -> str:
    """``robotspec 0.1.0 (Python 3.11.7, numpy 2.4.6)``: what ``--version`` starts with."""
    from importlib.metadata import PackageNotFoundError, version

    import numpy

    try:
        ours = version("robotspec")
    except PackageNotFoundError:  # run from a source tree that was never installed
        ours = "(not installed)"
    return f"robotspec {ours} (Python {platform.python_version()}, numpy {numpy.__version__})"


def core_rows() -> list[list[str]]:
    """One row per core: its name, what answers (C or the fallback), and why."""
    from robotspec.accel import StaleCoreWarning, report

    with warnings.catch_warnings():  # the reason is in the row: no second copy on stderr
        warnings.simplefilter("ignore", StaleCoreWarning)
        statuses = report()
    return [
        [s.name.rsplit(".", 1)[-1].lstrip("_"), "C" if s.accelerated else "fallback", s.reason]
        for s in statuses
    ]


def print_version(value: bool) -> None:
    """The root app's eager ``--version``: the version and one line per core, then exit 0."""
    if not value:
        return
    lines = [version_line()]
    lines += [f"  {name}: {answers} ({why})" for name, answers, why in core_rows()]
    sys.stdout.write("\n".join(lines) + "\n")
    raise typer.Exit(0)


@app.command()
def doctor(
    require_c: Annotated[
        bool,
        typer.Option(
            "--require-c",
            help="Exit 1 unless every query runs in the C cores (for CI checking a wheel).",
        ),
    ] = False,
) -> None:
    """This install: robotspec's version, and which core answers (C or fallback), and why."""
    rows = core_rows()
    sys.stdout.write(version_line() + "\n")
    sys.stdout.write(render_table(["core", "answers", "why"], rows) + "\n")
    if any(answers != "C" for _, answers, _ in rows):
        sys.stdout.write(
            "A fallback gives the same answers, 20-60 times slower: docs/installing.md says how "
            "to get the C cores (a wheel, or a C compiler and a reinstall).\n"
        )
        if require_c:
            raise typer.Exit(1)
