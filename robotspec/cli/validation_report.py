"""Validation printed for people: every problem as ``file:line:col: severity: message``.

Shared by ``robotspec validate`` and ``robotspec demo``; commands never call each other.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from robotspec.cli.output import plural, styled

__all__ = ["report_validation"]


def report_validation(
    specs: Sequence[str],
    *,
    strict: bool = False,
    as_json: bool = False,
    package_paths: Sequence[str | Path] = (),
) -> int:
    """Check each spec, print its problems and a summary; return the number of errors."""
    from robotspec.compiler import check_spec
    from robotspec.errors import ErrorDetail, RobotSpecError

    results: list[dict[str, Any]] = []
    n_err = n_warn = 0
    for ref in specs:
        errors: tuple[ErrorDetail, ...] = ()
        warnings: tuple[ErrorDetail, ...] = ()
        try:
            result = check_spec(ref, package_paths=package_paths, strict=strict)
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
    if as_json:
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
            f"{n_specs - bad} of {plural(n_specs, 'spec')} valid; "
            f"{plural(n_err, 'error')}, {plural(n_warn, 'warning')}"
        )
        sys.stdout.write(summary + "\n")
    return n_err


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
