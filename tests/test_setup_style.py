"""New lines the setup assistant writes follow the file's own indentation (setup/text_render.py):
mappings nested by two or four spaces, block lists indented or at their key's column."""

from __future__ import annotations

import difflib
from pathlib import Path

import pytest
import yaml

from robotspec.setup import SetupSession
from robotspec.setup.accept import with_accepted
from robotspec.setup.text_edit import edit_text
from robotspec.setup.text_render import Style, style_of
from tests.conftest import erd_robots


def _added(a: str, b: str) -> list[str]:
    diff = difflib.unified_diff(a.splitlines(), b.splitlines(), lineterm="", n=0)
    lines = [x for x in diff if x[:1] in "+-" and x[:3] not in ("+++", "---")]
    assert all(x.startswith("+") for x in lines), lines
    return [x[1:] for x in lines]


@pytest.mark.parametrize(
    ("text", "style"),
    [
        ("a:\n  b: 1\nl:\n  - x\n", Style(2, 2)),
        ("a:\n    b:\n        c: 1\nl:\n- x\n", Style(4, 0)),
        ("a:\n    b: 1\nl:\n    - x\n", Style(4, 4)),
        ("a: {b: 1}\n", Style(2, 2)),  # nothing nested as a block: the drafter's style
        ("a:\n    b: 1\n", Style(4, 4)),  # no block list: dashes indented by the step
    ],
)
def test_the_files_own_style_is_measured(text: str, style: Style) -> None:
    assert style_of(yaml.compose(text)) == style


def test_new_keys_nest_by_the_files_step() -> None:
    text = "name: x\nchains:\n    arm:\n        root: a\n        tip: b\n"
    old = yaml.safe_load(text)
    new = {**old, "chains": {"arm": {**old["chains"]["arm"], "states": {"park": {"j": 0.5}}}}}
    new["sensors"] = {"lidar": {"type": "generic", "body": "a"}}
    assert _added(text, edit_text(text, old, new)) == [
        "        states:",
        "            park: {j: 0.5}",
        "sensors:",
        "    lidar:",
        "        type: generic",
        "        body: a",
    ]


@pytest.mark.parametrize("dash", ["", "  ", "    "])
def test_a_new_list_puts_its_dashes_where_the_file_does(dash: str) -> None:
    text = f"name: x\ncontrolled_joints:\n{dash}- a\n{dash}- b\n"
    new = with_accepted(text, [("torso", "is on no chain", "why not")])
    assert _added(text, new) == [
        "accept_warnings:",
        f"{dash}- at: torso",
        f'{dash}  says: "is on no chain"',
        f'{dash}  because: "why not"',
    ]


def _four_spaces(text: str) -> str:
    """A drafted spec (two spaces a level) nested by four, as some people write YAML."""
    out = []
    for line in text.splitlines(keepends=True):
        body = line.lstrip(" ")
        out.append(" " * (2 * (len(line) - len(body))) + body)
    return "".join(out)


def test_a_four_space_spec_of_a_robot_nobody_specified_gains_four_space_lines(
    tmp_path: Path,
) -> None:
    kinova = erd_robots() / "kinova_description"
    if not kinova.is_dir():
        pytest.skip("example-robot-data without kinova_description")
    spec = tmp_path / "kinova.yaml"
    s = SetupSession.open(
        str(kinova / "robots" / "kinova.urdf"),
        srdf=str(kinova / "srdf" / "kinova.srdf"),
        output=spec,
    )
    for q in s.snapshot.questions:
        s.answer(q.id)
    s.save()
    text = _four_spaces(spec.read_text())
    spec.write_text(text)
    s = SetupSession.open(str(spec), output=spec)
    assert s.snapshot.text == text and s.validation.valid
    arm = next(c for c in s.draft().chains)
    assert s.set_state(f"chains.{arm.name}", "park", {"j2s6s200_joint_1": 0.5}).valid
    assert s.add_generic_sensor("wrist_ft", "j2s6s200_link_6", "ft").valid
    assert s.accept_warning(
        "description.srdf: group_state 'arm_up' has no group attribute", "a robot-level pose"
    ).valid
    added = _added(text, s.snapshot.text)
    assert added[:2] == ["        states:", "            park: {j2s6s200_joint_1: 0.5}"]
    assert added[2:] == [
        "sensors:",
        "    wrist_ft:",
        "        type: generic",
        "        body: j2s6s200_link_6",
        "        kind: ft",
        "accept_warnings:",
        "    - at: description.srdf",
        "      says: \"group_state 'arm_up' has no group attribute\"",
        '      because: "a robot-level pose"',
    ]
    assert s.validation.valid
    # A new part takes the drafter's lines (their comments too), nested by the file's step.
    text = s.snapshot.text
    assert s.add_camera("wrist_camera", "j2s6s200_link_6").valid
    new = _added(text, s.snapshot.text)
    assert new[0].startswith("    wrist_camera:") and new[1] == "        type: camera"
    assert all(line.startswith("        ") for line in new[1:]), new
