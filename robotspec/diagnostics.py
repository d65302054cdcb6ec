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
        """Drop the warnings the spec accepts, each entry accepting exactly one warning.

        ``accepted`` are the spec's ``accept_warnings`` entries, in order. Entry ``i`` accepts
        the warning printed at exactly its path ``at`` (not one below it: ``at: chains`` must not
        silence every chain) whose message, after the path, contains ``says`` (case counts,
        surrounding spaces ignored). Why so strict: an acceptance is a reviewed exception for
        one warning; a loose one would also swallow the next, different warning at that place.

        Problems with the entries themselves, each at the entry's line:

        * an entry repeating an earlier one, or accepting the warning an earlier one accepts, is
          an error (one of the two is dead weight and hides which reason holds);
        * ``says`` matching several different warnings at ``at`` is an error naming them (it
          accepts none of them until it quotes enough to pick one);
        * an entry that accepts no warning is a *warning* (an error with ``--strict``), naming a
          warning below ``at`` or at ``at`` with other words when there is one: the robot files
          may have changed so the warning no longer occurs, and that alone must not make a
          valid spec invalid.
        """
        plan = _Acceptance(self.warnings)
        first: dict[tuple[str, str], int] = {}
        owner: dict[int, int] = {}  # warning index -> the entry accepting it
        for i, entry in enumerate(accepted):
            at, says = entry.at.strip(), entry.says.strip()
            if (at, says) in first:
                self.error(
                    ("accept_warnings", i),
                    f"repeats accept_warnings[{first[(at, says)]}] (at '{at}' says '{says}'); "
                    "remove one of them",
                )
                continue
            first[(at, says)] = i
            hits = plan.matches(at, says)
            messages = list(dict.fromkeys(plan.bodies[k] for k in hits))
            if len(messages) > 1:
                quoted = "; ".join(f"'{m}'" for m in messages)
                self.error(
                    ("accept_warnings", i, "says"),
                    f"'{says}' matches {len(messages)} warnings at '{at}': {quoted}; "
                    "quote more of the one to accept",
                )
            elif hits:
                earlier = next((owner[k] for k in hits if k in owner), None)
                if earlier is not None:
                    self.error(
                        ("accept_warnings", i),
                        f"accepts the same warning at '{at}' as accept_warnings[{earlier}]; "
                        "remove one of them",
                    )
                    continue
                owner.update(dict.fromkeys(hits, i))
            else:
                self.warning(("accept_warnings", i), plan.unused(at, says))
        self.warnings = [w for k, w in enumerate(self.warnings) if k not in owner]

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


class _Acceptance:
    """The warnings an ``accept_warnings`` entry may accept, by exact path and message body."""

    def __init__(self, warnings: Sequence[RobotSpecError]) -> None:
        #: Each warning's spec path (``None``: it points at no spec node, so cannot be accepted).
        self.paths: list[str | None] = []
        #: Each warning's message without its ``path: `` prefix: ``says`` may not match the path.
        self.bodies: list[str] = []
        for w in warnings:
            where = loc_text(w.detail.location) if w.detail.location else None
            body = w.message
            if where is not None and body.startswith(f"{where}: "):
                body = body[len(where) + 2 :]
            self.paths.append(where)
            self.bodies.append(body)

    def matches(self, at: str, says: str) -> list[int]:
        """Indexes of the warnings at exactly ``at`` whose message contains ``says``."""
        return [
            k
            for k, (where, body) in enumerate(zip(self.paths, self.bodies, strict=True))
            if where == at and says in body
        ]

    def unused(self, at: str, says: str) -> str:
        """Why an entry accepts nothing, pointing at the warning it may have meant."""
        text = f"no warning at '{at}' says '{says}'"
        below = [
            w
            for w, body in zip(self.paths, self.bodies, strict=True)
            if w is not None and w.startswith((f"{at}.", f"{at}[")) and says in body
        ]
        same_place = [b for w, b in zip(self.paths, self.bodies, strict=True) if w == at]
        saying = [w for w, b in zip(self.paths, self.bodies, strict=True) if w and says in b]
        close = closest_names(at, saying, n=1)
        if below:
            hint = f"; the warning at '{below[0]}' does: write at: {below[0]}"
        elif same_place:
            hint = f"; the warning there says '{same_place[0]}'"
        elif close:
            hint = f"; did you mean at: {close[0]}?"
        else:
            hint = " (any more?); remove this entry"
        return text + hint
