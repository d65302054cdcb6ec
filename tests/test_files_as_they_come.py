"""Robot files as users bring them (issue 30, "files as they come"), each on a small layout.

A description folder without ``package.xml`` found by its name; the user's own package of a
name the installed ``example-robot-data`` also has; a xacro including a sibling file; ``init -P``
writing a spec that validates as written; meshes in a sibling folder of the project; an SRDF
declaring one virtual joint twice.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from robotspec.compiler import check_spec
from robotspec.description.srdf_reader import parse_srdf_bytes

URDF = """<robot name="r">
  <link name="base_link"/>
  <link name="arm"/>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="arm"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
</robot>
"""

TWICE = """<robot name="r">
  <group name="arm"><joint name="j1"/></group>
  <virtual_joint name="world_joint" type="fixed" parent_frame="world" child_link="base_link"/>
  <virtual_joint name="world_joint" type="floating" parent_frame="world" child_link="base_link"/>
</robot>
"""


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


# ----------------------------------------------------------------------------- f. SRDF repeats
def test_a_virtual_joint_declared_twice_is_read_once_with_a_located_warning() -> None:
    srdf = parse_srdf_bytes(TWICE.encode(), "r.srdf")
    assert [(v.name, v.type, v.line) for v in srdf.virtual_joints] == [("world_joint", "fixed", 3)]
    assert srdf.group_names == ("arm",)  # the rest of the file is kept
    assert [str(w) for w in srdf.warnings] == [
        "r.srdf:4: warning: virtual_joint 'world_joint' is declared again (first on line 3) "
        "(this one: floating from 'world' to 'base_link'; the first: fixed from 'world' to "
        "'base_link'); read as MoveIt does, the first declaration only (delete this one)"
    ]


def test_a_spec_with_that_srdf_validates_and_says_where(tmp_path: Path) -> None:
    write(tmp_path / "r.urdf", URDF)
    write(tmp_path / "r.srdf", TWICE)
    spec = write(
        tmp_path / "r.yaml",
        "robotspec: 1\nname: R\ndescription: {urdf: r.urdf, srdf: r.srdf}\nroot: base_link\n"
        "chains: {arm: {root: base_link, tip: arm}}\n",
    )
    result = check_spec(spec)
    warned = [str(w) for w in result.warnings if "declared again" in str(w)]
    assert len(warned) == 1 and warned[0].startswith(f"{tmp_path}/r.srdf:4: warning:"), warned
    assert result.robot.drive is None  # the first declaration: fixed


def test_names_repeated_in_other_elements_stay_errors() -> None:
    text = TWICE.replace("world_joint", "a", 1).replace('"arm"><joint', '"arm"><joint', 1)
    text = text.replace("</robot>", '<group name="arm"><joint name="j1"/></group></robot>')
    with pytest.raises(Exception, match="group 'arm' is defined twice"):
        parse_srdf_bytes(text.encode(), "r.srdf")
