"""What the CLI prints for robotspec errors, and the exit-code policy (0 ok, 1 invalid, 2 usage)."""

from __future__ import annotations

import os
import shlex
import sys
import traceback
from collections.abc import Sequence
from typing import TextIO

import typer

from robotspec.errors import ErrorDetail, RobotSpecError, printable

EXIT_OK = 0
EXIT_INVALID = 1
EXIT_INTERNAL = 3


_COLOURS = {"error": "\x1b[1;31m", "warning": "\x1b[1;33m"}
_BOLD, _RESET = "\x1b[1m", "\x1b[0m"


def use_colour(stream: TextIO) -> bool:
    """Colour only for a person at a terminal: never when piped, never with NO_COLOR set."""
    if os.environ.get("NO_COLOR"):
        return False
    if os.environ.get("FORCE_COLOR"):
        return True
    isatty = getattr(stream, "isatty", None)
    return bool(isatty and isatty()) and os.environ.get("TERM") != "dumb"


def styled(detail: ErrorDetail, stream: TextIO) -> str:
    """``file:line:col: error: message``, with the position bold and the severity coloured.

    Control characters from names in the input are escaped, never sent to the terminal.
    """
    text = printable(detail.render())
    if not use_colour(stream):
        return text
    marker = f": {detail.severity}: "
    head, sep, tail = text.partition(marker)
    if not sep:
        if text.startswith(f"{detail.severity}: "):
            n = len(detail.severity)
            return f"{_COLOURS.get(detail.severity, _BOLD)}{text[:n]}{_RESET}{text[n:]}"
        return text
    colour = _COLOURS.get(detail.severity, _BOLD)
    return f"{_BOLD}{head}{_RESET}: {colour}{detail.severity}{_RESET}: {tail}"


def print_error(err: RobotSpecError) -> None:
    """Print every problem an error stands for, then the warnings the run attached to it.

    One ``file:line:col: error: message`` per line, as ``validate`` prints them; the warnings
    matter because one can be the cause of an error (a missing mesh package behind a body the
    spec cannot find, say).
    """
    for detail in (*err.details, *(d for w in err.warnings for d in w.details)):
        sys.stderr.write(styled(detail, sys.stderr) + "\n")


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
    except Exception as exc:  # noqa: BLE001 - a bug: say so plainly, traceback only on request
        if _verbose(args):
            traceback.print_exc()
        rerun = shlex.join(["robotspec", "--verbose", *(a for a in args if a != "--verbose")])
        sys.stderr.write(
            f"internal error: {type(exc).__name__}: {printable(str(exc))}\n"
            "This is a bug in robotspec; please report it with the traceback that\n"
            f"  {printable(rerun)}\nprints.\n"
        )
        return EXIT_INTERNAL
    return EXIT_OK


def plural(n: int, word: str) -> str:
    """``1 chain``, ``2 chains``: a count in a message (regular plurals only)."""
    return f"{n} {word}{'' if n == 1 else 's'}"
