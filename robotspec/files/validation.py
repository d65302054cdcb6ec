"""Pydantic validation errors turned into located errors: ``file:line:col``, closest keys.

Why a module of its own: the spec, RobotInfo files and driver scenarios are all validated by
Pydantic models over YAML read by :mod:`robotspec.files.yamlio`; each pydantic location path is
mapped back to the YAML node it came from, and an unknown key gets the closest valid ones.
"""

from __future__ import annotations

import math
import types
from collections.abc import Mapping, Sequence
from typing import Annotated, Any, Union, get_args, get_origin

from pydantic import BaseModel, ValidationError

from robotspec.diagnostics import loc_text
from robotspec.errors import RobotSpecError, RobotSpecErrors, closest_names
from robotspec.files.yamlio import LocatedYaml

__all__ = ["validation_errors"]

Loc = tuple[str | int, ...]


def _leaves(annotation: Any) -> list[Any]:
    """An annotation without its wrappers: Annotated, Optional and unions flattened."""
    origin = get_origin(annotation)
    if origin is Annotated:
        return _leaves(get_args(annotation)[0])
    if origin is Union or origin is types.UnionType:
        return [leaf for arg in get_args(annotation) for leaf in _leaves(arg)]
    return [annotation]


def _is_model(ann: Any) -> bool:
    return isinstance(ann, type) and issubclass(ann, BaseModel)


def _model_fields_at(model: type[BaseModel], loc: Sequence[str | int]) -> list[str]:
    """The keys valid in the mapping at ``loc`` (for unknown-key suggestions).

    Why the walk by annotation: a part's name (``chains.left_arm``) is a dict key, not a field,
    so each step either names a field of the current models or enters a dict value or list item.
    """
    current: list[Any] = [model]
    for part in loc:
        step: list[Any] = []
        for ann in (leaf for a in current for leaf in _leaves(a)):
            if _is_model(ann):
                for name, fld in ann.model_fields.items():
                    if part in (name, fld.alias):
                        step.append(fld.annotation)
            elif get_origin(ann) in (dict, Mapping) and get_args(ann):
                step.append(get_args(ann)[-1])
            elif get_origin(ann) in (list, tuple, Sequence) and isinstance(part, int):
                step.extend(get_args(ann)[:1])
        current = step
    names: list[str] = []
    for ann in (leaf for a in current for leaf in _leaves(a)):
        if _is_model(ann):
            for name, fld in ann.model_fields.items():
                key = fld.alias or name
                if key not in names:
                    names.append(key)
    return names


def validation_errors(
    exc: ValidationError,
    doc: LocatedYaml,
    model: type[BaseModel],
    error_type: type[RobotSpecError] = RobotSpecError,
    loc_prefix: Sequence[str | int] = (),
) -> RobotSpecError:
    """Turn a pydantic ValidationError into located RobotSpecErrors (one per problem)."""
    errors: list[RobotSpecError] = []
    for err in exc.errors(include_url=False):
        loc = tuple(p for p in err["loc"] if isinstance(p, (str, int)))  # drop discriminator tags
        # Pydantic appends union member names and function tags to locs; keep real keys only.
        real_loc = _strip_to_document(loc, doc)
        full_loc = (*loc_prefix, *real_loc)
        where = loc_text(full_loc) or "(document)"
        kind = err["type"]
        if kind == "extra_forbidden":
            key = str(real_loc[-1]) if real_loc else "?"
            valid = _model_fields_at(model, real_loc[:-1])
            suggestions = closest_names(key, valid)
            hint = ""
            if suggestions:
                hint = f"; did you mean '{suggestions[0]}'?"
            elif valid:
                hint = f"; valid keys: {', '.join(valid)}"
            line, col = doc.key_position(real_loc)
            errors.append(
                error_type(
                    f"unknown key '{key}' at {where}{hint}",
                    file=doc.file,
                    line=line,
                    column=col,
                    kind="key",
                    name=key,
                    suggestions=suggestions,
                    location=full_loc,
                )
            )
            continue
        line, col = doc.position(real_loc)
        if kind == "missing" and real_loc:
            parent = loc_text((*loc_prefix, *real_loc[:-1])) or "(document)"
            errors.append(
                error_type(
                    f"{parent}: missing required key '{real_loc[-1]}'",
                    file=doc.file,
                    line=line,
                    column=col,
                    kind="key",
                    name=str(real_loc[-1]),
                    location=full_loc,
                )
            )
            continue
        msg = str(err["msg"])
        if msg.startswith("Value error, "):
            msg = msg[len("Value error, ") :]
        given = err.get("input")
        shown = ""
        if kind not in ("missing",) and _is_short_scalar(given):
            shown = f" (got {given!r})"
        errors.append(
            error_type(
                f"{where}: {msg}{shown}",
                file=doc.file,
                line=line,
                column=col,
                location=full_loc,
            )
        )
    errors.sort(key=lambda e: (e.line or 0, e.column or 0))
    if len(errors) == 1:
        return errors[0]
    return RobotSpecErrors(errors, summary=f"{doc.file}: {len(errors)} problems")


def _is_short_scalar(value: Any) -> bool:
    if isinstance(value, float) and not math.isfinite(value):
        return True
    return isinstance(value, (str, int, float, bool)) and len(repr(value)) <= 60


def _strip_to_document(loc: Loc, doc: LocatedYaml) -> Loc:
    """Drop pydantic's union/validator tags that are not keys of the document.

    Every part but the last exists in the document (validation reached it); a part that does
    not is a tag, such as a discriminated union's member name ('parallel_gripper'). The last
    part may be a key the document lacks (a missing key), so only tag-shaped ones go.
    """
    out: list[str | int] = []
    for i, part in enumerate(loc):
        candidate = (*out, part)
        last = i == len(loc) - 1
        if candidate in doc.marks or candidate in doc.key_marks or isinstance(part, int):
            out.append(part)
        elif last and not _is_tag(part):
            out.append(part)
    return tuple(out)


def _is_tag(part: str) -> bool:
    # Pydantic union member tags look like 'function-after[...]', 'list[...]', 'ModelName'.
    return "[" in part or (part[:1].isupper() and part.isidentifier())
