"""The package's error hierarchy.

Every error a user can cause is a :class:`RobotSpecError`. Errors are data: each keeps the file,
line and column it points at, the kind of thing involved (link, joint, group, ...), the offending
name and the closest valid names, and builds its message from those fields. The CLI alone renders
them (``file:line:col: error: message``) and maps them to exit code 1, so library code never prints.

A loader or compiler that finds several problems raises one :class:`RobotSpecErrors` holding all of
them, the way pydantic reports every validation error of a model at once.
"""

from __future__ import annotations

import copy
import difflib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

__all__ = [
    "CollisionError",
    "DescriptionError",
    "DriverError",
    "DuplicateNameError",
    "ErrorDetail",
    "KinematicsError",
    "NotFoundError",
    "PackageNotFoundError",
    "PathOutsideRootsError",
    "RobotInfoError",
    "RobotSpecError",
    "RobotSpecErrors",
    "ServiceError",
    "SpecError",
    "SrdfError",
    "closest_names",
    "printable",
]


def closest_names(name: str, candidates: Iterable[str], n: int = 3) -> tuple[str, ...]:
    """Return up to ``n`` candidates that look like ``name``, best first.

    Why: the commonest spec mistake is a drifted name (``_link`` suffixes invented, ``l``/``r``
    swapped), so every "not found" error carries the nearest real names.
    """
    pool = list(dict.fromkeys(candidates))
    found = difflib.get_close_matches(name, pool, n=n, cutoff=0.6)
    if not found:
        # A prefix or substring match still helps when the edit distance is large
        # (``r_wrist`` for ``r_wrist_roll_link``).
        lowered = name.lower()
        found = [c for c in pool if lowered and (lowered in c.lower() or c.lower() in lowered)][:n]
    return tuple(found)


_CONTROL = {c: f"\\x{c:02x}" for c in (*range(0x00, 0x20), *range(0x7F, 0xA0))}
_BIDI = (0x2028, 0x2029, *range(0x202A, 0x202F), *range(0x2066, 0x206A))
_CONTROL.update({c: f"\\u{c:04x}" for c in _BIDI})


def printable(text: str) -> str:
    """``text`` with terminal control characters escaped (as ``x1b`` after a backslash).

    Why: names come from downloaded files; an escape sequence echoed raw can rewrite the
    terminal (move the cursor, hide text, set the title), and bidi overrides reorder what a
    reader sees.
    """
    if text.isprintable():
        return text
    return text.translate(_CONTROL)


def did_you_mean(suggestions: Sequence[str]) -> str:
    if not suggestions:
        return ""
    quoted = [f"'{s}'" for s in suggestions]
    if len(quoted) == 1:
        return f"; did you mean {quoted[0]}?"
    return f"; did you mean {', '.join(quoted[:-1])} or {quoted[-1]}?"


@dataclass(frozen=True)
class ErrorDetail:
    """Where an error points and what it is about; shared by every error of the package."""

    message: str
    file: str | None = None
    line: int | None = None
    column: int | None = None
    kind: str | None = None
    name: str | None = None
    suggestions: tuple[str, ...] = ()
    location: tuple[str | int, ...] = ()
    severity: str = "error"

    def position(self) -> str:
        """``file:line:col`` (as much of it as is known), the prefix editors jump to."""
        parts: list[str] = []
        if self.file is not None:
            parts.append(self.file)
            if self.line is not None:
                parts.append(str(self.line))
                if self.column is not None:
                    parts.append(str(self.column))
        return ":".join(parts)

    def render(self) -> str:
        """One line as compilers print it: ``file:line:col: error: message``."""
        pos = self.position()
        head = f"{pos}: " if pos else ""
        return f"{head}{self.severity}: {self.message}"


def _rebuild(cls: type[RobotSpecError], args: tuple[object, ...]) -> RobotSpecError:
    """Unpickling helper: an instance without calling ``__init__`` (state restored after)."""
    err = cls.__new__(cls)
    err.args = args
    return err


class RobotSpecError(Exception):
    """Base of every error robotspec raises for a user's input.

    Subclasses only choose a default ``kind`` wording; the fields are the same for all, so the CLI
    can render any of them without knowing its type.
    """

    def __init__(
        self,
        message: str,
        *,
        file: str | Path | None = None,
        line: int | None = None,
        column: int | None = None,
        kind: str | None = None,
        name: str | None = None,
        suggestions: Iterable[str] = (),
        location: Iterable[str | int] = (),
        severity: str = "error",
    ) -> None:
        self.detail = ErrorDetail(
            message=message,
            file=None if file is None else str(file),
            line=line,
            column=column,
            kind=kind,
            name=name,
            suggestions=tuple(suggestions),
            location=tuple(location),
            severity=severity,
        )
        super().__init__(self.detail.render())

    # Convenience accessors so callers can write ``err.file`` rather than ``err.detail.file``.
    @property
    def message(self) -> str:
        """The message without position."""
        return self.detail.message

    @property
    def file(self) -> str | None:
        """The file the error points into, if known."""
        return self.detail.file

    @property
    def line(self) -> int | None:
        """The 1-based line in ``file``, if known."""
        return self.detail.line

    @property
    def column(self) -> int | None:
        """The 1-based column in ``file``, if known."""
        return self.detail.column

    @property
    def name(self) -> str | None:
        """The offending name, if the error is about one."""
        return self.detail.name

    @property
    def suggestions(self) -> tuple[str, ...]:
        """The closest valid names, best first."""
        return self.detail.suggestions

    @property
    def details(self) -> tuple[ErrorDetail, ...]:
        """All problems this error stands for (one, unless it is a collection)."""
        return (self.detail,)

    @property
    def severity(self) -> str:
        """``error`` or ``warning``."""
        return self.detail.severity

    def __reduce__(self) -> tuple[Any, ...]:
        # Subclasses take other constructor arguments (NotFoundError: kind, name, candidates),
        # so copies and pickles (worker processes) rebuild from the state, not from ``args``.
        return (_rebuild, (type(self), self.args), self.__dict__)

    #: Warnings found in the same run as this error (the CLI prints and counts them too); an
    #: error raised after collecting every problem of a spec carries its warnings this way.
    warnings: tuple[RobotSpecError, ...] = ()

    def with_warnings(self, warnings: Sequence[RobotSpecError]) -> RobotSpecError:
        """A copy of this error that carries the run's ``warnings``."""
        new = copy.copy(self)
        new.warnings = tuple(warnings)
        return new

    def with_severity(self, severity: str) -> RobotSpecError:
        """A copy of this error with another severity (a warning that strict mode may promote)."""
        new = copy.copy(self)
        new.detail = replace(self.detail, severity=severity)
        new.args = (new.detail.render(),)
        return new

    def located(
        self,
        *,
        file: str | None,
        line: int | None,
        column: int | None = None,
        location: tuple[str | int, ...] = (),
    ) -> RobotSpecError:
        """A copy pointing at another place (e.g. the spec node that named a missing link)."""
        new = copy.copy(self)
        new.detail = replace(self.detail, file=file, line=line, column=column, location=location)
        new.args = (new.detail.render(),)
        return new


class NotFoundError(RobotSpecError):
    """A name that does not exist where it is looked up; the message suggests the closest names."""

    def __init__(
        self,
        kind: str,
        name: str,
        candidates: Iterable[str],
        *,
        where: str | None = None,
        file: str | Path | None = None,
        line: int | None = None,
        column: int | None = None,
        location: Iterable[str | int] = (),
    ) -> None:
        suggestions = closest_names(name, candidates)
        scope = f" in {where}" if where else ""
        message = f"{kind} '{name}' not found{scope}{did_you_mean(suggestions)}"
        super().__init__(
            message,
            file=file,
            line=line,
            column=column,
            kind=kind,
            name=name,
            suggestions=suggestions,
            location=location,
        )


class DuplicateNameError(RobotSpecError):
    """Two entities of one kind share a name."""


class DescriptionError(RobotSpecError):
    """A robot description (URDF, xacro, mesh reference) is malformed or inconsistent."""


class PackageNotFoundError(DescriptionError):
    """A ``package://`` URI or ``$(find PKG)`` names a package on none of the search folders."""


class PathOutsideRootsError(DescriptionError):
    """A resolved path escapes the folders robotspec was allowed to read."""


class SrdfError(RobotSpecError):
    """An SRDF is malformed or names things its URDF does not have."""


class KinematicsError(RobotSpecError):
    """A kinematic query cannot be answered (no path between two bodies, bad configuration)."""


class SpecError(RobotSpecError):
    """A robot spec YAML is invalid."""


class CollisionError(RobotSpecError):
    """Collision geometry cannot be built or a collision query is malformed."""


class RobotInfoError(RobotSpecError):
    """A Robot Raconteur RobotInfo YAML is invalid."""


class DriverError(RobotSpecError):
    """A driver command is refused (wrong mode, out of limits, not finite)."""


class ServiceError(RobotSpecError):
    """A network service cannot start or run (port taken, node or device name in use)."""


class RobotSpecErrors(RobotSpecError):  # noqa: N818 - plural of RobotSpecError, by design
    """Several problems found in one run, raised together so a user fixes them all at once."""

    def __init__(self, errors: Sequence[RobotSpecError], *, summary: str | None = None) -> None:
        if not errors:
            raise ValueError("RobotSpecErrors needs at least one error")
        self.errors: tuple[RobotSpecError, ...] = tuple(errors)
        n = len(self.errors)
        head = summary or f"{n} problem{'s' if n != 1 else ''} found"
        super().__init__(head)
        # The rendered text lists every problem, one per line.
        Exception.__init__(self, "\n".join([head, *(e.detail.render() for e in self.errors)]))

    @property
    def details(self) -> tuple[ErrorDetail, ...]:
        """Every collected problem."""
        return tuple(d for e in self.errors for d in e.details)


def raise_collected(errors: Sequence[RobotSpecError], *, summary: str | None = None) -> None:
    """Raise nothing, the single error, or a :class:`RobotSpecErrors` of all of them."""
    if not errors:
        return
    if len(errors) == 1:
        raise errors[0]
    raise RobotSpecErrors(errors, summary=summary)


def missing_file(
    path: str | Path, error_type: type[RobotSpecError] = RobotSpecError
) -> RobotSpecError:
    """'file not found', naming the closest files of the same folder (a typo is likeliest)."""
    p = Path(path)
    try:
        siblings = [c.name for c in p.parent.iterdir() if c.is_file()]
    except OSError:
        siblings = []
    suggestions = closest_names(p.name, siblings)
    return error_type(
        f"file not found{did_you_mean(suggestions)}",
        file=str(path),
        kind="file",
        name=p.name,
        suggestions=suggestions,
    )
