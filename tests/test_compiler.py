"""The compiler's checks: broken specs give exact, located messages; fuzzed specs never crash.

``tests/bad_specs/`` holds small specs with one problem each; the first line of each is
``# expect: <rendered message>`` (paths relative to ``tests/``). They use example-robot-data's PR2,
so they run wherever the ``data`` extra is installed.

``tests/bad_specs/rules/`` is the catalogue of compiler rules the spec reference shows
(``tools/docgen.py`` reads it): each file is ``# group:``, ``# rule:`` and ``# expect:`` lines,
then a ``broken.yaml`` that changes the shipped PR2 by its line 3. It is checked as the page shows
it: its spec lines alone, as ``broken.yaml`` in an empty folder, with machine paths neutral
(``$SITE_PACKAGES``, ``robotspec/specs/``) and no ROS package path set.
"""

from __future__ import annotations

import copy
import math
import sysconfig
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from robotspec.compiler import check_spec, compile_robot, shipped_specs
from robotspec.errors import RobotSpecError, RobotSpecErrors
from robotspec.shipped import shipped_spec_files
from tests.conftest import erd_robots

TESTS = Path(__file__).resolve().parent
BAD = TESTS / "bad_specs"
RULES = BAD / "rules"
BAD_SPECS = sorted(BAD.glob("*.yaml")) + sorted(RULES.glob("*.yaml"))
BAD_IDS = [str(p.relative_to(BAD).with_suffix("")) for p in BAD_SPECS]
PR2_URDF = "package://example-robot-data/robots/pr2_description/urdf/pr2.urdf"
PR2_SRDF = "package://example-robot-data/robots/pr2_description/srdf/pr2.srdf"


def expected(path: Path) -> list[str]:
    lines = path.read_text(encoding="utf-8").splitlines()
    out = [ln.removeprefix("# expect: ") for ln in lines if ln.startswith("# expect: ")]
    assert out, f"{path.name} has no '# expect:' line"
    return out


def rendered(err_or_warnings: RobotSpecError | tuple[RobotSpecError, ...]) -> list[str]:
    """Rendered problems, with the tests folder cut from paths."""
    if isinstance(err_or_warnings, RobotSpecError):
        details = list(err_or_warnings.details)
    else:
        details = [d for w in err_or_warnings for d in w.details]
    return [d.render().replace(f"{TESTS}/", "") for d in details]


def problems(path: Path, *, strict: bool = False) -> list[str]:
    """What check_spec reports for a spec: its errors, or else its warnings."""
    try:
        result = check_spec(path, strict=strict)
    except RobotSpecError as exc:
        return rendered(exc)
    return rendered(result.warnings)


@pytest.fixture(autouse=True, scope="module")
def _needs_erd() -> None:
    erd_robots()


@pytest.fixture
def no_ros_paths(monkeypatch: pytest.MonkeyPatch) -> None:
    """Package searches list the same folders on every machine."""
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)


def checked_file(path: Path, folder: Path) -> Path:
    """The file to check for a bad spec: a rule file becomes ``folder/broken.yaml``."""
    if path.parent != RULES:
        return path
    lines = path.read_text(encoding="utf-8").splitlines(keepends=True)
    broken = folder / "broken.yaml"
    broken.write_text("".join(ln for ln in lines if not ln.startswith("#")), encoding="utf-8")
    return broken


def neutral(lines: list[str], folder: Path) -> list[str]:
    """Rendered problems without this machine's folders (the temporary one, site-packages)."""
    site = sysconfig.get_paths()["purelib"]
    specs = shipped_spec_files()["pr2"].parent
    out = []
    for line in lines:
        for prefix in sorted({f"{folder}/", f"{folder.resolve()}/"}, key=len, reverse=True):
            line = line.replace(prefix, "")
        out.append(line.replace(f"{specs}/", "robotspec/specs/").replace(site, "$SITE_PACKAGES"))
    return out


# --------------------------------------------------------------------------- bad specs
def test_bad_specs_folder_is_complete() -> None:
    assert len(BAD_SPECS) >= 80
    for path in BAD_SPECS:
        head = "# group: " if path.parent == RULES else "# expect: "
        assert path.read_text(encoding="utf-8").startswith(head), path.name
        assert expected(path)


@pytest.mark.parametrize("path", BAD_SPECS, ids=BAD_IDS)
@pytest.mark.usefixtures("no_ros_paths")
def test_bad_spec_reports_exactly_its_problem(path: Path, tmp_path: Path) -> None:
    assert neutral(problems(checked_file(path, tmp_path)), tmp_path) == expected(path)


WARNING_SPECS = [p for p in BAD_SPECS if all(": warning: " in w for w in expected(p))]


@pytest.mark.parametrize(
    "path", WARNING_SPECS, ids=[str(p.relative_to(BAD).with_suffix("")) for p in WARNING_SPECS]
)
def test_strict_turns_warnings_into_errors(path: Path, tmp_path: Path) -> None:
    warning = expected(path)
    checked = checked_file(path, tmp_path)
    # not strict: the spec compiles, with the warning
    result = check_spec(checked)
    assert neutral(rendered(result.warnings), tmp_path) == warning
    # strict: the same messages, as errors, raised
    with pytest.raises(RobotSpecError) as info:
        check_spec(checked, strict=True)
    errors = [w.replace(": warning: ", ": error: ") for w in warning]
    assert neutral(rendered(info.value), tmp_path) == errors


def test_shipped_specs_have_no_warnings() -> None:
    for name in ("pr2", "tiago", "panda", "ur5"):
        assert check_spec(name, strict=True).warnings == (), name


FIVE_PROBLEMS = f"""\
robotspec: 1
name: five
description:
  urdf: {PR2_URDF}
root: base_footprint
chains:
  left_arm:
    root: r_shoulder_pan_link
    tip: l_wrist_roll_link
    manipulator: left_gripper
sensors:
  kinect:
    type: camera
    body: wide_stereo_optical_frame
    field_of_view: {{horizontal: 0.99, vertical: 4.0}}
manipulators:
  left_gripper:
    type: parallel_gripper
    root: l_gripper_palm_link
    tool_frame: l_gripper_tool_frame
    front_facing_orientation: [0, 0, 0, 2]
    thumb: {{root: l_gripper_l_finger_link, tip: l_gripper_l_finger_tip_link}}
    finger: {{root: l_gripper_r_finger_link, tip: l_gripper_r_finger_tip_link}}
torso:
  root: torso_lift_link
  tip: torso_lift_link
neck:
  root: torso_lift_link
  tip: head_tilt_link
  sensors: [kinect]
velocity_limits:
  joints: {{l_elbow_flx_joint: 0.5}}
"""


def test_five_problems_reported_together_in_file_order(tmp_path: Path) -> None:
    spec = tmp_path / "five.yaml"
    spec.write_text(FIVE_PROBLEMS)
    with pytest.raises(RobotSpecErrors) as info:
        check_spec(spec)
    err = info.value
    assert len(err.errors) == 5
    lines = [e.line for e in err.errors]
    assert lines == sorted(lines) == [8, 15, 21, 25, 32]
    assert all(e.file == str(spec) for e in err.errors)
    fragments = [
        "common ancestor is 'torso_lift_link'",
        "angle must lie in (0, pi) radians, got 4",
        "must be a unit quaternion [x, y, z, w], its norm is 2",
        "is empty: root and tip are both 'torso_lift_link'",
        "joint 'l_elbow_flx_joint' not found",
    ]
    for e, fragment in zip(err.errors, fragments, strict=True):
        assert fragment in e.message
    # the rendered text lists all of them under one head line
    text = str(err).splitlines()
    assert text[0] == "five.yaml: 5 problems"
    assert len(text) == 6


def test_not_found_errors_carry_name_and_suggestions() -> None:
    with pytest.raises(RobotSpecError) as info:
        check_spec(BAD / "link_not_found.yaml")
    err = info.value
    assert err.name == "l_wrist_rol_link"
    assert err.suggestions[0] == "l_wrist_roll_link"
    assert (err.line, err.column) == (10, 10)


def test_extending_spec_errors_point_at_the_child_file(tmp_path: Path) -> None:
    child = tmp_path / "child.yaml"
    child.write_text(
        f"extends: {shipped_specs()['pr2']}\nname: child\n"
        "sensors:\n  kinect: {preset: kinect_v9}\n"
    )
    with pytest.raises(RobotSpecError) as info:
        check_spec(child)
    assert rendered(info.value) == [
        f"{child}:4:20: error: camera preset 'kinect_v9' not found in "
        "templates/cameras.yaml; did you mean 'kinect_v1'?"
    ]


def test_unknown_key_inside_a_named_part_gets_a_suggestion(tmp_path: Path) -> None:
    spec = tmp_path / "s.yaml"
    spec.write_text(
        f"name: s\ndescription: {{urdf: '{PR2_URDF}'}}\nroot: base_footprint\n"
        "chains:\n  arm:\n    root: torso_lift_link\n    tip: l_wrist_roll_link\n"
        "    manipulater: g\n"
    )
    assert problems(spec) == [
        f"{spec}:8:5: error: unknown key 'manipulater' at chains.arm.manipulater; "
        "did you mean 'manipulator'?"
    ]


def test_missing_key_of_a_manipulator_has_a_clean_location(tmp_path: Path) -> None:
    spec = tmp_path / "s.yaml"
    spec.write_text(
        f"name: s\ndescription: {{urdf: '{PR2_URDF}'}}\nroot: base_footprint\n"
        "manipulators:\n  g:\n    type: generic\n    root: l_gripper_palm_link\n"
    )
    assert problems(spec) == [
        f"{spec}:6:5: error: manipulators.g: missing required key 'tool_frame'"
    ]


# --------------------------------------------------------------------------- hypothesis
def _pr2_data() -> dict[str, Any]:
    data = yaml.safe_load(shipped_specs()["pr2"].read_text(encoding="utf-8"))
    assert isinstance(data, dict)
    return data


PR2_DATA = _pr2_data()

LINKS = [
    "base_footprint",
    "base_link",
    "torso_lift_link",
    "head_pan_link",
    "head_tilt_link",
    "l_wrist_roll_link",
    "r_wrist_roll_link",
    "l_gripper_palm_link",
    "l_gripper_tool_frame",
    "r_gripper_l_finger_link",
    "wide_stereo_optical_frame",
    "l_shoulder_pan_joint",
    "torso_lift_joint",
    "world_joint",
    "odom_combined",
]


def _typo(name: str) -> st.SearchStrategy[str]:
    i = st.integers(0, max(0, len(name) - 1))
    return st.one_of(
        i.map(lambda k: name[:k] + name[k + 1 :] or "x"),  # dropped letter
        i.map(lambda k: name[:k] + "_" + name[k:]),  # extra letter
        st.just(name.removesuffix("_link") + "_link_link"),
        st.just(name.upper()),
    )


NAMES = st.sampled_from(LINKS).flatmap(lambda n: st.one_of(st.just(n), _typo(n)))
NUMBERS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 1.0, -1.0, math.pi, 1e308, -1e-308, 3.5]),
    st.integers(-(2**70), 2**70),
)
SCALARS = st.one_of(NAMES, NUMBERS, st.booleans(), st.none(), st.text(max_size=8))
VALUES = st.recursive(
    SCALARS,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.dictionaries(st.one_of(NAMES, st.text(max_size=6)), inner)
    ),
    max_leaves=6,
)


def _paths(node: Any, prefix: tuple[Any, ...] = ()) -> Iterator[tuple[Any, ...]]:
    if isinstance(node, dict):
        for k, v in node.items():
            yield (*prefix, k)
            yield from _paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield (*prefix, i)
            yield from _paths(v, (*prefix, i))


def _parent(data: Any, path: tuple[Any, ...]) -> Any:
    node = data
    for p in path[:-1]:
        node = node[p]
    return node


@st.composite
def mutated_specs(draw: st.DrawFn) -> dict[str, Any]:
    data = copy.deepcopy(PR2_DATA)
    # a random subset of the top-level parts (the essentials most of the time)
    for key in list(data):
        if key not in ("name", "description", "root") and draw(st.booleans()):
            del data[key]
    for _ in range(draw(st.integers(1, 4))):
        paths = [p for p in _paths(data) if p[:2] != ("description", "urdf")]
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent = _parent(data, path)
        old = parent[path[-1]]
        # Mostly type-preserving changes, so that most examples get past validation and
        # exercise the compiler's own checks; some wrong types and shapes for the validator.
        action = draw(st.sampled_from(["typed"] * 4 + ["replace", "delete", "extra"]))
        if action == "delete":
            del parent[path[-1]]
        elif action == "extra" and isinstance(parent, dict):
            parent[draw(st.one_of(NAMES, st.text(min_size=1, max_size=8)))] = draw(VALUES)
        elif action == "typed" and isinstance(old, str):
            parent[path[-1]] = draw(NAMES)
        elif action == "typed" and isinstance(old, (int, float)) and not isinstance(old, bool):
            parent[path[-1]] = draw(NUMBERS)
        elif action == "typed" and isinstance(old, list) and old and not isinstance(old[0], dict):
            elem = NAMES if isinstance(old[0], str) else NUMBERS
            parent[path[-1]] = draw(st.lists(elem, min_size=len(old), max_size=len(old)))
        else:
            parent[path[-1]] = draw(VALUES)
    return data


@settings(max_examples=40, deadline=None)
@given(mutated_specs())
def test_mutated_specs_never_crash_the_compiler(data: dict[str, Any]) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "fuzz.yaml"
        path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
        try:
            check_spec(path)
        except RobotSpecError as exc:
            # every problem is rendered and located in some file
            for d in exc.details:
                assert d.render()
                assert d.severity == "error"


# Any text, control characters included (they once escaped as a raw yaml.reader.ReaderError).
TEXT = st.text(st.characters(blacklist_categories=("Cs",)), max_size=200)


@settings(max_examples=20, deadline=None)
@given(TEXT)
def test_arbitrary_text_never_crashes_the_loader(text: str) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "fuzz.yaml"
        path.write_text(text, encoding="utf-8")
        with pytest.raises(RobotSpecError):
            check_spec(path)


def test_control_character_is_a_located_error(tmp_path: Path) -> None:
    path = tmp_path / "ctrl.yaml"
    path.write_text("name: a\x08b\n", encoding="utf-8")
    with pytest.raises(RobotSpecError):
        check_spec(path)


def test_compile_robot_by_name_and_by_path_agree() -> None:
    by_name = compile_robot("ur5")
    by_path = compile_robot(shipped_specs()["ur5"])
    assert by_name.name == by_path.name == "UR5"
    assert [c.name for c in by_name.kinematic_chains] == [c.name for c in by_path.kinematic_chains]
