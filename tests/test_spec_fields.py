"""Every spec field documents itself: a description, a valid example, and its unit if physical.

The spec reference (``tools/docgen.py``) and the JSON Schema that editors read (``robotspec
schema``) are both made from these ``Field(...)`` arguments, so a field without them would leave
a hole in both.
"""

from __future__ import annotations

import json
import typing
from typing import Annotated, Any

import pytest
from pydantic import BaseModel, TypeAdapter
from pydantic.fields import FieldInfo

from robotspec.spec.load import json_schema
from robotspec.spec.models import RobotSpec

#: Number-valued fields that have no physical unit: unit quaternions and unit vectors.
DIMENSIONLESS = {
    "quaternion",
    "front_facing_orientation",
    "front_facing_axis",
    "forward_facing_axis",
    "forward",
}
UNITS = {"m", "rad", "rad/s or m/s", "rad or m (per joint)"}


def _models_in(tp: Any) -> list[type[BaseModel]]:
    found = [tp] if isinstance(tp, type) and issubclass(tp, BaseModel) else []
    return found + [m for arg in typing.get_args(tp) for m in _models_in(arg)]


def _spec_fields() -> list[tuple[type[BaseModel], str, FieldInfo]]:
    """Every field of every model a spec can contain, each model once."""
    models: list[type[BaseModel]] = [RobotSpec]
    for model in models:  # grows while walked
        for field in model.model_fields.values():
            models += [m for m in _models_in(field.annotation) if m not in models]
    return [(m, name, f) for m in models for name, f in m.model_fields.items()]


FIELDS = _spec_fields()
IDS = [f"{m.__name__}.{name}" for m, name, _ in FIELDS]


def _numbers(tp: Any) -> bool:
    return tp is float or any(_numbers(a) for a in typing.get_args(tp))


def _unit(field: FieldInfo) -> str | None:
    extra = field.json_schema_extra
    return extra.get("unit") if isinstance(extra, dict) else None  # type: ignore[return-value]


def test_every_model_is_walked() -> None:
    names = {m.__name__ for m, _, _ in FIELDS}
    assert {"RobotSpec", "FrameSpec", "AttachSpec", "FingerSpec", "FieldOfViewSpec"} <= names
    assert len(FIELDS) >= 89


@pytest.mark.parametrize(("model", "name", "field"), FIELDS, ids=IDS)
def test_field_has_description_valid_example_and_unit(
    model: type[BaseModel], name: str, field: FieldInfo
) -> None:
    assert field.description, f"{model.__name__}.{name}: Field(description=...) is missing"
    assert field.examples, f"{model.__name__}.{name}: Field(examples=[...]) is missing"
    tp: Any = field.annotation
    if field.metadata:
        tp = Annotated[(tp, *field.metadata)]
    for example in field.examples:
        TypeAdapter(tp).validate_python(example)  # an example a spec could really hold
    unit = _unit(field)
    if _numbers(field.annotation) and name not in DIMENSIONLESS:
        assert unit, f"{model.__name__}.{name} holds numbers: json_schema_extra={{'unit': ...}}"
    assert unit is None or unit in UNITS, f"{model.__name__}.{name}: unknown unit {unit!r}"


def test_the_json_schema_carries_description_example_and_unit() -> None:
    schema = json_schema()
    for model, name, field in FIELDS:
        node = schema if model is RobotSpec else schema["$defs"][model.__name__]
        prop = node["properties"][field.alias or name]
        assert prop["description"] == field.description, (model.__name__, name)
        assert prop["examples"] == json.loads(json.dumps(field.examples)), (model.__name__, name)
        assert prop.get("unit") == _unit(field), (model.__name__, name)
