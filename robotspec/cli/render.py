"""Rendering of robotspec errors, and the exit-code policy (0 ok, 1 invalid, 2 usage)."""

from __future__ import annotations

import os
import sys
import traceback
from collections.abc import Callable, Sequence
from typing import TypeVar

import click
import typer

from robotspec.errors import RobotSpecError

T = TypeVar("T")

EXIT_OK = 0
EXIT_INVALID = 1
EXIT_USAGE = 2


def print_error(err: RobotSpecError) -> None:
    """Print every problem an error stands for, one ``file:line:col: error: message`` per line."""
    for detail in err.details:
        sys.stderr.write(detail.render() + "\n")


def run_app(app: typer.Typer, argv: Sequence[str] | None) -> int:
    """Run the typer app in standalone=False mode and map outcomes to exit codes."""
    verbose = "--verbose" in (argv or sys.argv[1:]) or "-v" in (argv or sys.argv[1:])
    try:
        result = app(args=list(argv) if argv is not None else None, standalone_mode=False)
    except click.exceptions.UsageError as exc:
        exc.show()
        return EXIT_USAGE
    except click.exceptions.Abort:
        sys.stderr.write("Aborted.\n")
        return 130
    except click.exceptions.Exit as exc:
        return int(exc.exit_code)
    except RobotSpecError as exc:
        if verbose or os.environ.get("ROBOTSPEC_VERBOSE"):
            traceback.print_exc()
        print_error(exc)
        return EXIT_INVALID
    except KeyboardInterrupt:
        sys.stderr.write("Interrupted.\n")
        return 130
    except click.exceptions.ClickException as exc:
        exc.show()
        return EXIT_INVALID
    except Exception as exc:  # a bug: say so plainly, traceback only on request
        if verbose or os.environ.get("ROBOTSPEC_VERBOSE"):
            traceback.print_exc()
        sys.stderr.write(
            f"internal error: {type(exc).__name__}: {exc}\n"
            "This is a bug in robotspec; rerun with --verbose and report the traceback.\n"
        )
        return 3
    if isinstance(result, int):
        return result
    return EXIT_OK


def guarded(fn: Callable[[], T]) -> T:
    """Run ``fn``; used by commands that want to catch errors themselves and continue."""
    return fn()
