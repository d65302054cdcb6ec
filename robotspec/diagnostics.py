"""Collecting every problem of a spec in one run, each pointing at its YAML node.

Why: a user fixing a spec wants the whole list at once, each as ``file:line:col`` with the name
that failed and the closest valid names; stopping at the first error makes them run the tool
once per typo.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

from robotspec.errors import (
    NotFoundError,
    RobotSpecError,
    RobotSpecErrors,
    SpecError,
    closest_names,
)

__all__ = ["Accepted", "Diagnostics", "Loc", "SpecSource", "loc_text"]

Loc = tuple[str | int, ...]


class _Document(Protocol):
    @property
    def file(self) -> str: ...


class Accepted(Protocol):
    """A spec's accepted warning (:class:`robotspec.spec.models.AcceptedWarning`)."""

    @property
    def at(self) -> str:
        """The spec path the warning is about."""
        ...

    @property
    def says(self) -> str:
        """A part of its message."""
        ...


class SpecSource(Protocol):
    """Where a spec's nodes are: what the collector needs of a loaded spec (no import of it)."""

    @property
    def file(self) -> Path:
        """The spec file the user named (its problems are listed first)."""
        ...

    @property
    def documents(self) -> Sequence[_Document]:
        """The spec's documents, the extending file first."""
        ...

    def position(self, loc: Loc) -> tuple[str, int | None, int | None]:
        """``(file, line, column)`` of a spec node."""
        ...


def loc_text(loc: Sequence[str | int]) -> str:
    """A spec path as a user reads it: ``chains.left_arm.tip``, ``joints[2]``."""
    out = ""
    for part in loc:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


@dataclass
class Diagnostics:
    """Errors and warnings of one compilation, located in the spec's files."""

    loaded: SpecSource
    errors: list[RobotSpecError] = field(default_factory=list)
    warnings: list[RobotSpecError] = field(default_factory=list)

    def _at(self, loc: Loc) -> tuple[str, int | None, int | None]:
        return self.loaded.position(loc)

    def _problem(
        self,
        loc: Loc,
        message: str,
        *,
        severity: str,
        name: str | None = None,
        kind: str | None = None,
        suggestions: Iterable[str] = (),
    ) -> SpecError:
        file, line, col = self._at(loc)
        return SpecError(
            f"{loc_text(loc)}: {message}" if loc else message,
            file=file,
            line=line,
            column=col,
            name=name,
            kind=kind,
            suggestions=suggestions,
            location=loc,
            severity=severity,
        )

    def error(
        self,
        loc: Loc,
        message: str,
        *,
        name: str | None = None,
        kind: str | None = None,
        suggestions: Iterable[str] = (),
    ) -> None:
        """Record an error about the spec node at ``loc``."""
        self.errors.append(
            self._problem(
                loc, message, severity="error", name=name, kind=kind, suggestions=suggestions
            )
        )

    def warning(self, loc: Loc, message: str, *, name: str | None = None) -> None:
        """Record a warning (an error in strict mode)."""
        self.warnings.append(self._problem(loc, message, severity="warning", name=name))

    def not_found(
        self, loc: Loc, kind: str, name: str, candidates: Iterable[str], where: str
    ) -> None:
        """Record a name that does not exist, with the closest valid names."""
        err = NotFoundError(kind, name, candidates, where=where)
        file, line, col = self._at(loc)
        self.errors.append(err.located(file=file, line=line, column=col, location=loc))

    def add(self, err: RobotSpecError, loc: Loc | None = None) -> None:
        """Record an error raised elsewhere, moved to ``loc`` when it has no file of its own."""
        if loc is not None and err.file is None:
            file, line, col = self._at(loc)
            err = err.located(file=file, line=line, column=col, location=loc)
        (self.warnings if err.severity == "warning" else self.errors).append(err)

    def add_all(self, err: RobotSpecError, loc: Loc | None = None) -> None:
        """Record every problem of an error raised elsewhere (one or a collection).

        A missing file is the spec's mistake: it is moved to the spec line at ``loc`` that names
        the file, keeping the file's path in the message.
        """
        for one in getattr(err, "errors", (err,)):
            if loc is not None and one.detail.kind == "file" and one.file is not None:
                file, line, col = self._at(loc)
                one = RobotSpecError(
                    f"{one.file}: {one.message}",
                    file=file,
                    line=line,
                    column=col,
                    kind="file",
                    name=one.detail.name,
                    suggestions=one.detail.suggestions,
                    location=loc,
                )
            self.add(one, loc)

    def suggest(self, name: str, candidates: Iterable[str]) -> tuple[str, ...]:
        """Closest names, for messages built by hand."""
        return closest_names(name, candidates)

    def in_file_order(self, problems: Iterable[RobotSpecError]) -> list[RobotSpecError]:
        """Problems in reading order: the spec's own file first, then by line and column.

        Checks run part by part (torso, neck, manipulators, ...), not in the order the file is
        written; a user fixes a file top to bottom, so that is the order they are reported in.
        """
        main = str(self.loaded.file)
        files = [d.file for d in self.loaded.documents]

        def key(e: RobotSpecError) -> tuple[int, str, int, int]:
            f = e.file or ""
            rank = 0 if f == main or f == files[0] else (1 if f in files else 2)
            return (rank, f, e.line or 0, e.column or 0)

        return sorted(problems, key=key)

    def accept(self, accepted: Sequence[Accepted]) -> None:
        """Drop the warnings the spec accepts; an acceptance that matches none is a warning.

        ``accepted`` are the spec's ``accept_warnings`` entries, in order; entry ``i`` matches a
        warning located at its spec path ``at`` (or below it) whose message contains ``says``.
        """
        used = [False] * len(accepted)
        kept: list[RobotSpecError] = []
        for warning in self.warnings:
            where = loc_text(warning.detail.location)
            hit = False
            for i, entry in enumerate(accepted):
                at = entry.at.strip()
                inside = where == at or where.startswith((f"{at}.", f"{at}["))
                if warning.detail.location and inside and entry.says in warning.message:
                    used[i] = hit = True
            if not hit:
                kept.append(warning)
        self.warnings = kept
        for i, entry in enumerate(accepted):
            if not used[i]:
                self.warning(
                    ("accept_warnings", i),
                    f"no warning at '{entry.at}' says '{entry.says}' (any more?); "
                    "remove this entry",
                )

    def raise_if_failed(self, *, strict: bool = False) -> None:
        """Raise every error (and, in strict mode, every warning as an error) at once."""
        problems = list(self.errors)
        if strict:
            problems += [w.with_severity("error") for w in self.warnings]
        problems = self.in_file_order(problems)
        if not problems:
            return
        warnings = () if strict else self.in_file_order(self.warnings)
        if len(problems) == 1:
            raise problems[0].with_warnings(warnings)
        raise RobotSpecErrors(
            problems, summary=f"{self.loaded.file.name}: {len(problems)} problems"
        ).with_warnings(warnings)
