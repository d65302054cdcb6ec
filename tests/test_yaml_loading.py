"""The located YAML loader gives one answer whichever parser PyYAML bundles.

PyYAML wheels bundle libyaml (which refuses nesting past 1,000 levels by itself) or not; the
loader's own depth limit, its marks and its messages must not depend on which.
"""

from __future__ import annotations

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from robotspec.errors import RobotSpecError
from robotspec.files import yamlio


@pytest.mark.parametrize("depth", [101, 1_001, 5_000, 50_000])
def test_deep_nesting_is_refused_at_the_limit_with_its_place(parser: str, depth: int) -> None:
    for text in ("[" * depth, "[" * depth + "]" * depth, "a:\n" + "- " * depth + "x\n"):
        with pytest.raises(RobotSpecError) as info:
            yamlio.load_yaml_text(text, "deep.yaml")
        assert "YAML nested too deeply (more than 100 levels" in str(info.value), text[:20]
        assert info.value.file == "deep.yaml"


def test_a_raised_limit_reads_past_libyaml_s_own(
    parser: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROBOTSPEC_MAX_YAML_DEPTH", "10000")
    loaded = yamlio.load_yaml_text("[" * 1500 + "1" + "]" * 1500, "deep.yaml")
    inner = loaded.data
    for _ in range(1500):
        assert isinstance(inner, list) and len(inner) == 1
        inner = inner[0]
    assert inner == 1
    assert loaded.position((0,) * 1500) == (1, 1501)


def test_marks_aliases_merges_and_key_order(parser: str) -> None:
    text = "b: [1, {c: &x [2, 3]}, *x]\na: {<<: {d: 1}, e: 2}\n"
    loaded = yamlio.load_yaml_text(text, "f.yaml")
    assert loaded.data == {"b": [1, {"c": [2, 3]}, [2, 3]], "a": {"d": 1, "e": 2}}
    assert list(loaded.data) == ["b", "a"]
    assert loaded.position(("b", 1, "c", 1)) == (1, 19)
    assert loaded.key_position(("a",)) == (2, 1)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("a: 1\n---\nb: 2\n", "2:1: error: invalid YAML: but found another document"),
        ("x: *y\n", "1:4: error: invalid YAML: found undefined alias 'y'"),
        ("a: &z 1\nb: &z 2\n", "2:4: error: invalid YAML: second occurrence"),
        ("a: b: c\n", "1:5: error: invalid YAML: mapping values are not allowed here"),
        ("é€: b: c\n", "1:6: error: invalid YAML: mapping values are not allowed here"),
        ("a: 1\r\nb: c: d\r\n", "2:5: error: invalid YAML: mapping values are not allowed here"),
        ("[1, 2\n", "2:1: error: invalid YAML: expected ',' or ']', but found the end of the file"),
        ("a: [1, 2\nb: 3\n", "2:2: error: invalid YAML: expected ',' or ']', but found ':'"),
        ("{a: b]\n", "1:6: error: invalid YAML: expected ',' or '}', but found ']'"),
        (
            "- a\nb: c\n",
            "2:1: error: invalid YAML: expected '- ' (another item) or less indentation, "
            "but found 'b'",
        ),
        (
            "a: 'b' c\n",
            "1:8: error: invalid YAML: expected a key of this mapping or less indentation, "
            "but found 'c'",
        ),
        ("- [\n-", "2:1: error: invalid YAML: expected a value, but found '-'"),
        (
            "a:\n\t- b\n",
            "2:1: error: invalid YAML: found character '\\t' that cannot start any token",
        ),
        ("a: @b\n", "1:4: error: invalid YAML: found character '@' that cannot start any token"),
        (
            "*\n",
            "1:2: error: invalid YAML: expected a letter or digit, but found the end of the line",
        ),
        ('a: "\\q"\n', "1:6: error: invalid YAML: found unknown escape character 'q'"),
        (
            "%YAML 1.1\n%YAML 1.1\n---\na\n",
            "2:1: error: invalid YAML: found a second %YAML directive",
        ),
        (
            "a: \x07\n",
            "1:4: error: invalid YAML: character '\\x07' is not allowed (control characters and "
            "lone surrogates are not YAML text)",
        ),
        (
            "a: b\nc: \ud800\n",
            "2:4: error: invalid YAML: character '\\ud800' is not allowed (control characters and "
            "lone surrogates are not YAML text)",
        ),
    ],
)
def test_syntax_errors_are_located(parser: str, text: str, message: str) -> None:
    """One wording whichever parser found the error (libyaml's own is terser)."""
    with pytest.raises(RobotSpecError) as info:
        yamlio.load_yaml_text(text, "f.yaml")
    assert str(info.value) == f"f.yaml:{message}"


@pytest.mark.parametrize(
    ("text", "column"),
    [
        ("[" * 1_001, 101),
        ("x: [" + "[" * 5_000, 103),  # the block mapping is level 1
        ("a: {b: " + "{'[': [" * 800, 351),  # a quoted '[' opens nothing
    ],
)
def test_a_dense_run_of_brackets_is_refused_where_it_passes_the_cap(
    parser: str, text: str, column: int
) -> None:
    # libyaml looks ahead past its own limit of 1,000 levels before the events reach the cap
    with pytest.raises(RobotSpecError) as info:
        yamlio.load_yaml_text(text, "deep.yaml")
    assert str(info.value) == (
        f"deep.yaml:1:{column}: error: YAML nested too deeply (more than 100 levels; "
        "set ROBOTSPEC_MAX_YAML_DEPTH to raise it)"
    )


class _Counted:
    made = 0


def test_a_syntax_error_at_the_end_is_found_in_one_parse(
    parser: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The file is parsed once, with the faster parser, also when it is wrong."""
    base = yamlio._SafeComposer

    class Counting(base):  # type: ignore[misc,valid-type]
        events = 0

        def __init__(self, stream: str) -> None:
            _Counted.made += 1
            super().__init__(stream)

        def get_event(self) -> object:
            Counting.events += 1
            return super().get_event()

    monkeypatch.setattr(yamlio, "_SafeComposer", Counting)
    _Counted.made = 0
    lines = [f"k{i}: [{i}, {i}.5, name_{i}]" for i in range(2_000)]
    text = "\n".join([*lines, "oops: : ["]) + "\n"
    with pytest.raises(RobotSpecError) as info:
        yamlio.load_yaml_text(text, "f.yaml")
    assert str(info.value).startswith("f.yaml:2001:7: error: invalid YAML: mapping values")
    assert _Counted.made == 1
    assert Counting.events <= 6 * 2_000 + 10  # each event of the text once


def test_the_shape_check_refuses_recursion_and_keeps_unit_tags(parser: str) -> None:
    yamlio.check_yaml_shape("a: !degrees 90\nb: {<<: {c: 1}}\n", "u.yaml")
    with pytest.raises(RobotSpecError, match=r"^u.yaml:1:8: error: recursive alias '\*a'"):
        yamlio.check_yaml_shape("a: &a [*a]\n", "u.yaml")


json_like = st.recursive(
    st.none() | st.booleans() | st.integers(-(2**40), 2**40) | st.text(max_size=8),
    lambda inner: (
        st.lists(inner, max_size=4)
        | st.dictionaries(st.text(min_size=1, max_size=6), inner, max_size=4)
    ),
    max_leaves=30,
)


@settings(max_examples=150, deadline=None)
@given(json_like)
def test_the_loader_reads_what_pyyaml_reads(data: object) -> None:
    text = yaml.safe_dump(data)
    assert yamlio.load_yaml_text(text).data == yaml.safe_load(text)
