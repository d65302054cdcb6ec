"""Validation of the text the assistant would save, each problem placed at its part.

Why the text and not the draft object: the assistant promises that what it saves validates, so it
checks exactly what it would write, with the compiler ``robotspec validate`` runs. The text goes
to a hidden file beside the real output, so relative references (``../urdf/robot.urdf``,
``package_paths``) resolve as they will in the saved spec; the file is removed at once.
"""

from __future__ import annotations

import os
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from robotspec.errors import ErrorDetail, RobotSpecError

if TYPE_CHECKING:
    from robotspec.semantic import AbstractRobot

__all__ = ["Problem", "Validation", "part_of", "validate_text"]

#: Spec keys whose entries are parts of their own (``chains.left_arm``).
_KEYED = ("chains", "manipulators", "sensors", "states")


def part_of(location: Sequence[str | int]) -> str:
    """The part a spec location concerns: ``chains.left_arm``, ``torso``, ``drive``, ``robot``."""
    if not location:
        return "robot"
    head = str(location[0])
    if head in _KEYED and len(location) > 1:
        return f"{head}.{location[1]}"
    if head == "description" and len(location) > 2 and location[1] == "frames":
        return f"frames.{location[2]}"
    return head


@dataclass(frozen=True)
class Problem:
    """One error or warning of validate, with the part of the spec it is about."""

    severity: str
    message: str
    part: str
    line: int | None
    column: int | None
    location: tuple[str | int, ...] = ()
    #: The file the problem is in when it is not the spec (a URDF, an SRDF); None: the spec.
    file: str | None = None

    def render(self, spec_file: str) -> str:
        """``file:line:col: severity: message``, as ``robotspec validate`` prints it."""
        return ErrorDetail(
            self.message,
            file=self.file or spec_file,
            line=self.line,
            column=self.column,
            severity=self.severity,
        ).render()


@dataclass(frozen=True)
class Validation:
    """What validate says of one text: its problems, and the robot when it compiled."""

    problems: tuple[Problem, ...]
    seconds: float
    robot: AbstractRobot | None = field(default=None, compare=False, repr=False)

    @property
    def errors(self) -> tuple[Problem, ...]:
        """The problems that make the spec invalid."""
        return tuple(p for p in self.problems if p.severity != "warning")

    @property
    def warnings(self) -> tuple[Problem, ...]:
        """The problems validate prints as warnings."""
        return tuple(p for p in self.problems if p.severity == "warning")

    @property
    def valid(self) -> bool:
        """Whether ``robotspec validate`` would accept the text (exit 0)."""
        return not self.errors

    def at(self, part: str) -> tuple[Problem, ...]:
        """The problems of one part."""
        return tuple(p for p in self.problems if p.part == part)


def _problem(d: ErrorDetail, spec_file: str) -> Problem:
    own = d.file is None or Path(d.file).name == Path(spec_file).name
    return Problem(
        severity=d.severity,
        message=d.message.replace(Path(spec_file).name, "the spec"),
        part=part_of(d.location) if own else "description",
        line=d.line,
        column=d.column,
        location=tuple(d.location),
        file=None if own else d.file,
    )


def validate_text(
    text: str, output: Path, *, package_paths: Sequence[str | Path] = ()
) -> Validation:
    """Check ``text`` as if it were the file ``output``; every error and warning, located."""
    from robotspec.compiler import check_spec

    started = time.perf_counter()
    folder = output.resolve().parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{output.stem}.setup-", suffix=".yaml", dir=folder)
    except OSError as exc:
        raise RobotSpecError(
            f"cannot write the spec's folder: {exc.strerror or exc}", file=str(output), kind="file"
        ) from None
    robot = None
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        try:
            result = check_spec(tmp, package_paths=package_paths)
            details = [d for w in result.warnings for d in w.details]
            robot = result.robot
        except RobotSpecError as exc:
            details = [*exc.details, *(d for w in exc.warnings for d in w.details)]
    finally:
        Path(tmp).unlink(missing_ok=True)
    problems = tuple(_problem(d, tmp) for d in details)
    return Validation(problems, time.perf_counter() - started, robot)
