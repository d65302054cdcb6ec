"""Loading URDFs into worlds: real robots, and every kind of bad input with its exact message."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from robotspec.description.urdf import world_from_urdf_xml
from robotspec.errors import DescriptionError, RobotSpecError, RobotSpecErrors
from robotspec.files.xmlsafe import parse_xml_bytes, parse_xml_file
from robotspec.model.world import ConnectionType

from .conftest import erd_robots, shared_path


def world_of(text: str, file: str = "robot.urdf"):
    return world_from_urdf_xml(parse_xml_bytes(text.encode(), file), file)


ARM = """<robot name="arm">
  <link name="base"/>
  <link name="upper"/>
  <link name="tool"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="2" effort="10"/>
  </joint>
  <joint name="wrist" type="fixed">
    <parent link="upper"/><child link="tool"/>
  </joint>
</robot>
"""


def test_small_arm_structure() -> None:
    w = world_of(ARM)
    assert w.name == "arm"
    assert w.root.name == "base"
    assert [b.name for b in w.bodies] == ["base", "upper", "tool"]
    assert w.dof_names == ("shoulder",)
    d = w.get_degree_of_freedom_by_name("shoulder")
    assert (d.lower, d.upper, d.velocity, d.effort) == (-1.0, 1.0, 2.0, 10.0)
    assert w.get_connection_by_name("wrist").type is ConnectionType.FIXED
    assert w.get_connection_by_name("shoulder").line == 5


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (  # printed exactly: 1.0000001 > 1 must not read as "1 is greater than 1"
            ARM.replace('lower="-1" upper="1"', 'lower="1.0000001" upper="1"'),
            "robot.urdf:8: error: joint 'shoulder': limit lower 1.0000001 is greater than upper 1",
        ),
        (
            ARM.replace('<robot name="arm">', "<robot>"),
            "robot.urdf:1: error: <robot> has no name attribute",
        ),
        (
            ARM.replace('<child link="upper"/>', '<child link="uper"/>'),
            "robot.urdf:6: error: link 'uper' not found in robot.urdf (child of joint "
            "'shoulder'); did you mean 'upper'?",
        ),
        (
            ARM.replace('<link name="tool"/>', '<link name="tool"/><link name="upper"/>'),
            "robot.urdf:4: error: link 'upper' is defined twice (first on line 3)",
        ),
        (
            ARM.replace('lower="-1" upper="1"', 'lower="1" upper="-1"'),
            "robot.urdf:8: error: joint 'shoulder': limit lower 1 is greater than upper -1",
        ),
        (
            ARM.replace('lower="-1"', 'lower="nan"'),
            "robot.urdf:8: error: joint 'shoulder': limit lower must be finite, got 'nan'",
        ),
        (
            ARM.replace('xyz="0 0 0.1"', 'xyz="0 0 inf"'),
            "robot.urdf:7: error: joint 'shoulder': origin xyz must be finite, got 'inf'",
        ),
        (
            ARM.replace('xyz="0 0 0.1"', 'xyz="0 0"'),
            "robot.urdf:7: error: joint 'shoulder': origin xyz must have 3 numbers, got '0 0'",
        ),
        (
            ARM.replace('type="revolute"', 'type="hinge"'),
            "robot.urdf:5: error: joint 'shoulder' has type 'hinge'; expected one of fixed, "
            "revolute, continuous, prismatic, floating, planar",
        ),
        (
            ARM.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'),
            "robot.urdf:7: error: joint 'shoulder': axis must not be zero",
        ),
        (
            ARM.replace('<limit lower="-1" upper="1" velocity="2" effort="10"/>', ""),
            "robot.urdf:5: error: revolute joint 'shoulder' has no <limit>",
        ),
    ],
)
def test_bad_urdf_exact_message(text: str, message: str) -> None:
    with pytest.raises(RobotSpecError) as info:
        world_of(text)
    assert [d.render() for d in info.value.details] == [message]


def test_all_problems_are_collected() -> None:
    text = ARM.replace('<child link="upper"/>', '<child link="uper"/>').replace(
        'lower="-1"', 'lower="x"'
    )
    with pytest.raises(RobotSpecErrors) as info:
        world_of(text)
    assert [d.render() for d in info.value.details] == [
        "robot.urdf:6: error: link 'uper' not found in robot.urdf (child of joint 'shoulder'); "
        "did you mean 'upper'?",
        "robot.urdf:8: error: joint 'shoulder': limit lower: 'x' is not a number",
    ]


def test_cycle_and_several_roots() -> None:
    two_roots = ARM.replace('<link name="tool"/>', '<link name="tool"/><link name="stray"/>')
    with pytest.raises(DescriptionError) as info:
        world_of(two_roots)
    assert str(info.value) == (
        "robot.urdf: error: the description has 2 root links ('base', 'stray'); "
        "a robot must be one tree"
    )
    cycle = ARM.replace(
        "</robot>",
        '<link name="a"/><link name="b"/>'
        '<joint name="ab" type="fixed"><parent link="a"/><child link="b"/></joint>'
        '<joint name="ba" type="fixed"><parent link="b"/><child link="a"/></joint></robot>',
    )
    with pytest.raises(DescriptionError, match="the joints form a cycle through link 'a'"):
        world_of(cycle)
    two_parents = ARM.replace(
        "</robot>",
        '<joint name="again" type="fixed"><parent link="base"/><child link="tool"/></joint>'
        "</robot>",
    )
    with pytest.raises(DescriptionError) as info2:
        world_of(two_parents)
    assert "link 'tool' has two parent joints ('wrist' and 'again')" in str(info2.value)


def test_malformed_xml_has_line(tmp_path: Path) -> None:
    f = tmp_path / "broken.urdf"
    f.write_text('<robot name="x">\n  <link name="a">\n</robot>\n')
    with pytest.raises(DescriptionError) as info:
        parse_xml_file(f)
    assert info.value.line == 3
    assert "malformed XML: Opening and ending tag mismatch" in str(info.value)


def test_billion_laughs_fails_fast(tmp_path: Path) -> None:
    lol = "".join(f'<!ENTITY l{i} "{"&l" + str(i - 1) + ";" * 1}' for i in range(0))
    del lol
    ents = ['<!ENTITY l0 "lol">'] + [
        f'<!ENTITY l{i} "{("&l" + str(i - 1) + ";") * 10}">' for i in range(1, 10)
    ]
    text = f'<?xml version="1.0"?>\n<!DOCTYPE r [\n{chr(10).join(ents)}\n]>\n<robot name="&l9;"/>'
    f = tmp_path / "lol.urdf"
    f.write_text(text)
    with pytest.raises(DescriptionError, match="XML entity declarations are not allowed"):
        parse_xml_file(f)


def test_external_entity_is_refused(tmp_path: Path) -> None:
    f = tmp_path / "xxe.urdf"
    f.write_text(
        '<?xml version="1.0"?>\n<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>\n'
        '<robot name="&x;"/>'
    )
    with pytest.raises(DescriptionError, match="XML entity declarations are not allowed"):
        parse_xml_file(f)


def test_missing_file() -> None:
    with pytest.raises(DescriptionError) as info:
        parse_xml_file("/nonexistent/robot.urdf")
    assert str(info.value) == "/nonexistent/robot.urdf: error: file not found"


def test_mimic_composition() -> None:
    text = ARM.replace(
        "</robot>",
        '<link name="f1"/><link name="f2"/>'
        '<joint name="m1" type="revolute"><parent link="tool"/><child link="f1"/>'
        '<limit lower="-9" upper="9" velocity="1" effort="1"/>'
        '<mimic joint="shoulder" multiplier="2" offset="0.5"/></joint>'
        '<joint name="m2" type="revolute"><parent link="f1"/><child link="f2"/>'
        '<limit lower="-9" upper="9" velocity="1" effort="1"/>'
        '<mimic joint="m1" multiplier="-1" offset="0.1"/></joint></robot>',
    )
    w = world_of(text)
    m2 = w.get_connection_by_name("m2")
    assert m2.mimic is not None
    assert (m2.mimic.leader, m2.mimic.multiplier, m2.mimic.offset) == ("shoulder", -2.0, -0.4)
    assert w.dof_names == ("shoulder",)


@given(st.binary(max_size=300))
def test_garbage_never_crashes(data: bytes) -> None:
    try:
        world_from_urdf_xml(parse_xml_bytes(data, "g.urdf"), "g.urdf")
    except RobotSpecError:
        pass


@given(
    name=st.text(min_size=1, max_size=10),
    lower=st.floats(allow_nan=True, allow_infinity=True),
    xyz=st.lists(st.floats(allow_nan=True), min_size=0, max_size=4),
)
def test_fuzzed_attributes_never_crash(name: str, lower: float, xyz: list[float]) -> None:
    from xml.sax.saxutils import quoteattr

    text = (
        ARM.replace('name="upper"', f"name={quoteattr(name)}")
        .replace('lower="-1"', f'lower="{lower}"')
        .replace('xyz="0 0 0.1"', 'xyz="' + " ".join(map(str, xyz)) + '"')
    )
    try:
        w = world_of(text)
    except RobotSpecError:
        return
    assert all(math.isfinite(float(v)) for c in w.connections for v in c.origin.ravel())


#: Files of example-robot-data 6.0.0 that are wrong, and the problem robotspec reports.
KNOWN_BROKEN = {
    # An empty shell: <robot> without name or links.
    "ur3.urdf": "<robot> has no name attribute",
    # Mimic references to joints that do not exist (pinocchio ignores <mimic>).
    "alex_psyonic_hands.urdf": "joint 'index_q1' not found in alex_psyonic_hands.urdf "
    "(mimicked by joint 'Left_index_q2'); did you mean 'Left_index_q1'",
}


def _erd_urdfs() -> list[Path]:
    try:
        robots = erd_robots()
    except pytest.skip.Exception:
        return []
    return sorted(robots.glob("*/**/*.urdf"))


@pytest.mark.parametrize("path", _erd_urdfs(), ids=lambda p: p.name)
def test_every_example_robot_data_urdf_loads(path: Path) -> None:
    import pinocchio as pin

    if path.name in KNOWN_BROKEN:
        with pytest.raises(RobotSpecError) as info:
            world_from_urdf_xml(parse_xml_file(path), str(path))
        assert KNOWN_BROKEN[path.name] in str(info.value)
        return
    w = world_from_urdf_xml(parse_xml_file(path), str(path))
    model = pin.buildModelFromUrdf(str(path))
    movable = [c for c in w.connections if not c.is_fixed]
    assert len(movable) == model.njoints - 1
    from robotspec.model.kinematics import Kinematics

    poses = Kinematics(w).forward(w.configuration())
    assert np.all(np.isfinite(poses))


def test_shared_urdfs_load() -> None:
    for rel, n_links in (
        ("robots/pr2/pr2.urdf", 88),
        ("robots/hsrb/hsrb4s.urdf", 48),
        ("robots/ur5e/ur5e.urdf", 11),
        ("robots/fanuc/moveit_resources_fanuc_description/urdf/fanuc.urdf", 9),
    ):
        path = shared_path(rel)
        w = world_from_urdf_xml(parse_xml_file(path), str(path))
        assert len(w.bodies) == n_links, rel
