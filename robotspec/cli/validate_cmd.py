"""``robotspec validate``: every problem of every spec, as ``file:line:col: severity: message``."""

from __future__ import annotations

import json
import sys
from enum import StrEnum
from typing import Annotated, Any

import typer

from robotspec.cli.options import PackagePath, complete_spec
from robotspec.cli.render import styled

#: This module's commands; robotspec.cli.app adds them to the root app.
app = typer.Typer()


class Format(StrEnum):
    """Output formats of validate."""

    text = "text"
    json = "json"


@app.command()
def validate(
    specs: Annotated[
        list[str],
        typer.Argument(help="Spec files or shipped robot names.", autocompletion=complete_spec),
    ],
    strict: Annotated[bool, typer.Option("--strict", help="Treat warnings as errors.")] = False,
    format: Annotated[Format, typer.Option("--format", help="text or json.")] = Format.text,
    package_path: PackagePath = None,
) -> None:
    """Check specs against their robot files; exit 0 if valid, 1 if not."""
    from robotspec.compiler import check_spec
    from robotspec.errors import ErrorDetail, RobotSpecError

    results: list[dict[str, Any]] = []
    n_err = n_warn = 0
    for ref in specs:
        errors: tuple[ErrorDetail, ...] = ()
        warnings: tuple[ErrorDetail, ...] = ()
        try:
            result = check_spec(ref, package_paths=package_path or (), strict=strict)
            warnings = tuple(d for w in result.warnings for d in w.details)
        except RobotSpecError as exc:
            errors = exc.details
            warnings = tuple(d for w in exc.warnings for d in w.details)
        # Counted by the label each line is printed with, so the summary always matches them.
        printed = (*errors, *warnings)
        n_bad = sum(1 for d in printed if d.severity != "warning")
        n_err += n_bad
        n_warn += len(printed) - n_bad
        results.append({"spec": ref, "valid": not n_bad, "errors": errors, "warnings": warnings})
    if format is Format.json:
        out = [
            {
                "spec": r["spec"],
                "valid": r["valid"],
                "problems": [_as_json(d) for d in (*r["errors"], *r["warnings"])],
            }
            for r in results
        ]
        sys.stdout.write(json.dumps(out, indent=2) + "\n")
    else:
        for r in results:
            for d in (*r["errors"], *r["warnings"]):
                sys.stdout.write(styled(d, sys.stdout) + "\n")
        n_specs = len(results)
        bad = sum(1 for r in results if not r["valid"])
        summary = (
            f"{n_specs - bad} of {_plural(n_specs, 'spec')} valid; "
            f"{_plural(n_err, 'error')}, {_plural(n_warn, 'warning')}"
        )
        sys.stdout.write(summary + "\n")
    if n_err:
        raise typer.Exit(1)


def _as_json(d: Any) -> dict[str, Any]:
    return {
        "severity": d.severity,
        "file": d.file,
        "line": d.line,
        "column": d.column,
        "message": d.message,
        "name": d.name,
        "suggestions": list(d.suggestions),
        "location": list(d.location),
    }


def _plural(n: int, word: str) -> str:
    return f"{n} {word}{'' if n == 1 else 's'}"
