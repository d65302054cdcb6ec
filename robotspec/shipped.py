"""Where the data shipped inside the package lives: robot specs, parts, templates, the schema.

One module knows the package's folder layout, so an installed wheel and a source checkout find
the same files, and nothing else computes paths from ``__file__``. It imports nothing of the
package at module level, so every layer may use it.
"""

from __future__ import annotations

from pathlib import Path

__all__ = [
    "package_data",
    "shipped_part_files",
    "shipped_schema_path",
    "shipped_spec_files",
]

_ROOT = Path(__file__).resolve().parent


def package_data(*parts: str) -> Path:
    """A path inside the installed package (``package_data("templates", "cameras.yaml")``)."""
    return _ROOT.joinpath(*parts)


def shipped_spec_files() -> dict[str, Path]:
    """The robots shipped with robotspec: name -> spec file (``extends: pr2`` works)."""
    return {f.stem: f for f in sorted(package_data("specs").glob("*.yaml"))}


def shipped_part_files() -> dict[str, Path]:
    """Parts shipped with robotspec for composed robots (``spec: allegro_right_hand``)."""
    return {f.stem: f for f in sorted(package_data("specs", "parts").glob("*.yaml"))}


def shipped_schema_path() -> Path:
    """Where the installed package keeps the schema (specs written by robotspec point here)."""
    return package_data("data", "robotspec.schema.json")
