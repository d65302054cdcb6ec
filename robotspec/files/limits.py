"""The caps that bound the work any input can cause, and how a user raises them.

Why caps at all: robot files are downloaded from everywhere and run through xacro, which
evaluates expressions. robotspec's promise is that a file can at worst give an error, so every
reader stops at a size, the YAML reader at a depth and a node count, a spec's ``extends`` chain
at a depth, and xacro at budgets of time, macro calls and value sizes. The defaults are far
above any real robot (the PR2's xacro tree is 1.3 MB, its largest mesh 9 MB); a user with a
bigger robot raises one cap with an environment variable, ``ROBOTSPEC_<NAME>`` (for example
``ROBOTSPEC_MAX_MESH_BYTES=1e9``).

The values are read from the environment each time a reader asks (no module state), so a test or
a server can change them per call.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, fields

__all__ = ["Limits", "limits"]


@dataclass(frozen=True)
class Limits:
    """One value per cap; the field name upper-cased and prefixed ``ROBOTSPEC_`` sets it."""

    #: Bytes of one YAML file (spec, RobotInfo, scenario, a xacro ``load_yaml``).
    max_yaml_bytes: int = 8 * 1024 * 1024
    #: Nesting depth of YAML collections, checked before anything recurses.
    max_yaml_depth: int = 100
    #: Nodes of one YAML document with every alias expanded (alias bombs). An alias is shared,
    #: not copied, so reading costs memory in proportion to the text; this bounds the work of
    #: whatever walks the data afterwards (validation, the compiler).
    max_yaml_nodes: int = 1_000_000
    #: Nodes the aliases of one YAML document stand for, in all (each alias counts its anchor's
    #: nodes, aliases inside expanded). Why besides the node cap: validation and the compiler
    #: walk every value an alias stands for, so a 16 kB spec of 990 aliases of a 500-joint state
    #: held 570 MB; a real document's anchors (a chain, a state, a joint's limits reused) stand
    #: for a few thousand.
    max_yaml_alias_nodes: int = 100_000
    #: Files one spec's ``extends`` chain may reach beyond the spec itself (a real chain is two
    #: or three deep; each file is read and validated once).
    max_extends_depth: int = 100
    #: Bytes of one URDF file, and of a xacro expansion's output.
    max_urdf_bytes: int = 64 * 1024 * 1024
    #: Bytes of one SRDF file.
    max_srdf_bytes: int = 32 * 1024 * 1024
    #: Bytes of one file a xacro document includes (or the top xacro file).
    max_xacro_include_bytes: int = 16 * 1024 * 1024
    #: Files one xacro expansion may open (includes and ``load_yaml``), counted with repeats.
    max_xacro_includes: int = 2_000
    #: Bytes of one mesh file.
    max_mesh_bytes: int = 256 * 1024 * 1024
    #: Triangles of one mesh file. Why besides the bytes: memory follows triangles, not bytes
    #: (a collision check holds about 1.6 KB per triangle: 10^6 triangles, a 50 MB binary STL,
    #: peak near 1.8 GB), and a file may pack them densely. The largest robot mesh known here
    #: (Go1's trunk) has 351,394.
    max_mesh_triangles: int = 1_000_000
    #: Wall-clock seconds one xacro document may take to expand.
    xacro_seconds: float = 30.0
    #: Macro calls one xacro document may expand.
    xacro_macro_calls: int = 10_000
    #: Macro calls nested inside each other.
    xacro_macro_depth: int = 100
    #: Characters (or items) of one ``${...}`` value, and of any string or list made on the way.
    xacro_value_size: int = 1_000_000
    #: Bits of an integer made by a ``${...}`` expression.
    xacro_int_bits: int = 1_024
    #: Loop steps (comprehension items, ``range`` length) of one xacro document.
    xacro_loop_steps: int = 1_000_000


def _parse(raw: str, kind: type) -> int | float | None:
    try:
        value = float(raw)
    except ValueError:
        return None
    if not (value > 0 and value < float("inf")):
        return None
    return int(value) if kind is int else value


def limits(environ: Mapping[str, str] | None = None) -> Limits:
    """The caps in force: the defaults, each overridden by its ``ROBOTSPEC_*`` variable.

    A variable that is not a positive number is ignored (the default stays), so a typo can
    never switch a fence off.
    """
    env = os.environ if environ is None else environ
    values: dict[str, int | float] = {}
    for f in fields(Limits):
        raw = env.get(f"ROBOTSPEC_{f.name.upper()}")
        if raw is None:
            continue
        kind = float if f.type in ("float", float) else int
        parsed = _parse(raw.strip(), kind)
        if parsed is not None:
            values[f.name] = parsed
    return Limits(**values)  # type: ignore[arg-type]


def env_name(field_name: str) -> str:
    """The environment variable that raises the cap ``field_name`` (for error messages)."""
    return f"ROBOTSPEC_{field_name.upper()}"
