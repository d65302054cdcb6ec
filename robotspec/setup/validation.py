"""Validation of the text the assistant would save, each problem placed at its part.

Why the text and not the draft object: the assistant promises that what it saves validates, so it
checks exactly what it would write, with the compiler ``robotspec validate`` runs. The text is
read from memory as if it were the output file (``load_spec(text=...)``), so relative
references (``../urdf/robot.urdf``, ``package_paths``) resolve as they will in the saved spec and
nothing is written beside the user's files until they save. A generated SRDF not yet saved is
staged in a private temporary folder (the compiler reads SRDFs from files), named by the checked
text as an absolute path, and its messages name it as it will be saved.
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
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


def _problem(d: ErrorDetail, spec_file: str, shown: Mapping[str, str]) -> Problem:
    own = d.file is None or Path(d.file).name == Path(spec_file).name
    message = d.message.replace(Path(spec_file).name, "the spec")
    file = None if own else d.file
    for staged, real in shown.items():  # a staged file is named as it will be saved
        message = message.replace(staged, real).replace(Path(staged).name, Path(real).name)
        file = real if file == staged else file
    return Problem(
        severity=d.severity,
        message=message,
        part=part_of(d.location) if own else "description",
        line=d.line,
        column=d.column,
        location=tuple(d.location),
        file=file,
    )


def validate_text(
    text: str | Callable[[str], str],
    output: Path,
    *,
    package_paths: Sequence[str | Path] = (),
    srdf: tuple[str, str] | None = None,
) -> Validation:
    """Check ``text`` as if it were the file ``output``; every error and warning, located.

    ``srdf``: an SRDF kept in the session, not yet saved: (its name beside the spec, its text).
    It is staged in a private temporary folder for the check, and ``text`` is then a function
    of the staged file's absolute path (the spec naming it); messages name it as it will be
    saved. Nothing is written beside ``output``.
    """
    from robotspec.compiler.pipeline import compile_loaded
    from robotspec.spec.load import load_spec

    started = time.perf_counter()
    robot = None
    shown: dict[str, str] = {}
    where = str(output.absolute())
    with tempfile.TemporaryDirectory(prefix="robotspec-setup-") as private:
        paths: list[str | Path] = [*package_paths]
        if srdf is not None:
            staged = Path(private) / srdf[0]
            staged.write_text(srdf[1], encoding="utf-8")
            shown[str(staged)] = str(output.absolute().parent / srdf[0])
            paths.append(private)
            spec = text(str(staged)) if callable(text) else text
        elif isinstance(text, str):
            spec = text
        else:
            raise TypeError("a spec text that names a staged SRDF needs the SRDF")
        try:
            loaded = load_spec(where, allowed=paths, text=spec)
            result = compile_loaded(loaded, package_paths=paths)
            details = [d for w in result.warnings for d in w.details]
            robot = result.robot
        except RobotSpecError as exc:
            details = [*exc.details, *(d for w in exc.warnings for d in w.details)]
    problems = tuple(_problem(d, where, shown) for d in details)
    return Validation(problems, time.perf_counter() - started, robot)
