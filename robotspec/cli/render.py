"""Rendering of robotspec errors, and the exit-code policy (0 ok, 1 invalid, 2 usage)."""

from __future__ import annotations

import os
import sys
import traceback
from collections.abc import Sequence

import typer

from robotspec.errors import RobotSpecError

EXIT_OK = 0
EXIT_INVALID = 1
EXIT_USAGE = 2
EXIT_INTERNAL = 3


def print_error(err: RobotSpecError) -> None:
    """Print every problem an error stands for, one ``file:line:col: error: message`` per line."""
    for detail in err.details:
        sys.stderr.write(detail.render() + "\n")


def _verbose(argv: Sequence[str]) -> bool:
    return "--verbose" in argv or "-v" in argv or bool(os.environ.get("ROBOTSPEC_VERBOSE"))


def run_app(app: typer.Typer, argv: Sequence[str] | None) -> int:
    """Run the app; typer handles usage errors (exit 2), robotspec errors exit 1."""
    args = list(sys.argv[1:] if argv is None else argv)
    try:
        app(args=args, prog_name="robotspec", standalone_mode=True)
    except SystemExit as exc:
        code = exc.code
        return code if isinstance(code, int) else (0 if code is None else EXIT_INVALID)
    except RobotSpecError as exc:
        if _verbose(args):
            traceback.print_exc()
        print_error(exc)
        return EXIT_INVALID
    except KeyboardInterrupt:
        sys.stderr.write("Interrupted.\n")
        return 130
    except Exception as exc:  # a bug: say so plainly, traceback only on request
        if _verbose(args):
            traceback.print_exc()
        sys.stderr.write(
            f"internal error: {type(exc).__name__}: {exc}\n"
            "This is a bug in robotspec; rerun with --verbose and report the traceback.\n"
        )
        return EXIT_INTERNAL
    return EXIT_OK
