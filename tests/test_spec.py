"""The spec format: validation errors located in the YAML, extends, and the shipped schema."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from robotspec.errors import RobotSpecError, RobotSpecErrors, SpecError
from robotspec.spec.load import json_schema_text, load_spec

MINIMAL = """robotspec: 1
name: arm
description:
  urdf: arm.urdf
root: base
"""


def write(tmp_path: Path, text: str, name: str = "robot.yaml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def test_minimal_spec_loads(tmp_path: Path) -> None:
    loaded = load_spec(write(tmp_path, MINIMAL))
    assert loaded.spec.name == "arm"
    assert loaded.spec.collision.buffer_distance == 0.05
    assert loaded.position(("root",)) == (str(tmp_path / "robot.yaml"), 5, 7)


def test_unknown_key_is_located_with_suggestion(tmp_path: Path) -> None:
    path = write(tmp_path, MINIMAL + "torso:\n  root: a\n  tipp: b\n")
    with pytest.raises(RobotSpecError) as info:
        load_spec(path)
    rendered = [d.render() for d in info.value.details]
    assert rendered == [
        f"{path}:7:3: error: torso: missing required key 'tip'",
        f"{path}:8:3: error: unknown key 'tipp' at torso.tipp; did you mean 'tip'?",
    ]


def test_wrong_type_and_enum(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        MINIMAL + "drive: {type: hover}\nvelocity_limits: {default: -1}\n",
    )
    with pytest.raises(RobotSpecErrors) as info:
        load_spec(path)
    rendered = [d.render() for d in info.value.details]
    assert rendered[0].startswith(f"{path}:6:15: error: drive.type: Input should be 'omni'")
    assert rendered[1] == (
        f"{path}:7:28: error: velocity_limits.default: Input should be greater than 0 (got -1)"
    )


def test_manipulator_type_is_a_discriminator(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        MINIMAL + "manipulators:\n  g:\n    type: gripper\n    root: a\n    tool_frame: b\n",
    )
    with pytest.raises(SpecError) as info:
        load_spec(path)
    assert str(info.value).startswith(f"{path}:8:5: error: manipulators.g:")
    assert "'parallel_gripper', 'hand', 'generic'" in str(info.value)


def test_yaml_syntax_error_has_line(tmp_path: Path) -> None:
    path = write(tmp_path, MINIMAL + "chains: [unclosed\n")
    with pytest.raises(RobotSpecError) as info:
        load_spec(path)
    assert info.value.line == 7
    assert "invalid YAML" in str(info.value)


def test_duplicate_key_is_an_error(tmp_path: Path) -> None:
    path = write(tmp_path, MINIMAL + "root: other\n")
    with pytest.raises(RobotSpecError) as info:
        load_spec(path)
    assert str(info.value) == f"{path}:6:1: error: duplicate key 'root'"


def test_python_tags_are_refused(tmp_path: Path) -> None:
    path = write(tmp_path, MINIMAL + "name2: !!python/object/apply:os.system ['echo hi']\n")
    with pytest.raises(RobotSpecError) as info:
        load_spec(path)
    assert str(info.value) == (
        f"{path}:6:8: error: unsupported YAML tag 'tag:yaml.org,2002:python/object/apply:os.system'"
        " (only plain YAML data is read)"
    )


def test_extends_overrides_by_name(tmp_path: Path) -> None:
    (tmp_path / "base").mkdir()
    write(
        tmp_path / "base",
        MINIMAL + "chains:\n  arm: {root: base, tip: tool}\n",
        "base.yaml",
    )
    child = write(
        tmp_path,
        "extends: base/base.yaml\nname: variant\nchains:\n  arm: {tip: flange}\n",
    )
    loaded = load_spec(child)
    assert loaded.spec.name == "variant"
    assert loaded.spec.chains["arm"].root == "base"
    assert loaded.spec.chains["arm"].tip == "flange"
    # The base's relative URDF path still points next to the base spec.
    assert loaded.spec.description.urdf == str(tmp_path / "base" / "arm.urdf")
    assert loaded.position(("chains", "arm", "tip"))[0] == str(child)
    assert loaded.position(("root",))[0] == str(tmp_path / "base" / "base.yaml")


def test_extends_cycle(tmp_path: Path) -> None:
    write(tmp_path, "extends: b.yaml\nname: a\n", "a.yaml")
    write(tmp_path, "extends: a.yaml\nname: b\n", "b.yaml")
    with pytest.raises(SpecError, match="'extends' forms a cycle: a.yaml -> b.yaml -> a.yaml"):
        load_spec(tmp_path / "a.yaml")


def test_shipped_schema_is_current() -> None:
    shipped = Path(__file__).resolve().parents[1] / "robotspec" / "data" / "robotspec.schema.json"
    assert shipped.read_text() == json_schema_text(), (
        "the shipped JSON Schema is stale: run `robotspec schema -o "
        "robotspec/data/robotspec.schema.json`"
    )
    schema = json.loads(shipped.read_text())
    assert "chains" in schema["properties"]


@given(
    st.recursive(
        st.none() | st.booleans() | st.floats() | st.text(max_size=8) | st.integers(),
        lambda inner: (
            st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=8), inner, max_size=4)
        ),
        max_leaves=12,
    )
)
def test_random_documents_never_crash(tmp_path_factory, data) -> None:
    import yaml

    folder = tmp_path_factory.mktemp("fuzz")
    path = folder / "s.yaml"
    path.write_text(
        yaml.safe_dump({"name": "x", "description": {"urdf": "a"}, "root": "r", "chains": data})
    )
    try:
        load_spec(path)
    except RobotSpecError:
        pass
