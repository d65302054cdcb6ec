"""What every spec model shares: names, joint values, and the strict, frozen model base.

Every model forbids unknown keys, is frozen, and refuses NaN and infinity; names refuse the
characters XML cannot carry (they are echoed to terminals and written into YAML and XML).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Annotated

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
)

if TYPE_CHECKING:
    pass

__all__ = ["JointValues", "Name", "SpecModel", "States", "finite_values"]


_NOT_IN_XML = frozenset(chr(c) for c in (*range(0x20), 0x7F)) - {"\t", "\n", "\r"}


def _no_control(value: str) -> str:
    """Names are written into SRDF and URDF files: no character XML cannot carry.

    Why not every non-printable character: a URDF may name a link with a newline (XML allows
    it), and a spec must be able to name that link. Echoed names are escaped by the CLI
    (:func:`robotspec.errors.printable`) and drafts quote them, so a newline is harmless.
    """
    bad = next((c for c in value if c in _NOT_IN_XML), None)
    if bad is not None:
        raise ValueError(f"names must not contain control characters (found U+{ord(bad):04X})")
    return value


Name = Annotated[str, Field(min_length=1, max_length=256), AfterValidator(_no_control)]
JointValues = dict[Name, float]
States = dict[Name, JointValues]


def finite_values(values: tuple[float, ...]) -> tuple[float, ...]:
    """``values`` unchanged, or a validation error when one is NaN or infinite."""
    if not all(math.isfinite(v) for v in values):
        raise ValueError("values must be finite numbers")
    return values


class SpecModel(BaseModel):
    """The base of every spec model: unknown keys refused, frozen, finite numbers only."""

    # NaN and infinity are refused wherever a number enters (``abs(x - y) > tol`` is False for
    # NaN, so a NaN would pass every later check).
    model_config = ConfigDict(
        extra="forbid", frozen=True, populate_by_name=True, allow_inf_nan=False
    )
