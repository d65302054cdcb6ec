"""ROS 1 xacro files with unprefixed tags (``<macro>``, ``<insert_block>``) load (issue 30)."""

from __future__ import annotations

from pathlib import Path

from robotspec.description.load import load_description
from robotspec.files.xacro_legacy import prefix_legacy_tags

_ROBOT = """<?xml version="1.0"?>
<robot name="old" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <property name="reach" value="0.3"/>
  <macro name="limb" params="name parent *origin">
    <link name="${name}"/>
    <joint name="${name}_joint" type="revolute">
      <parent link="${parent}"/><child link="${name}"/>
      <insert_block name="origin"/>
      <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
    </joint>
  </macro>
  <link name="base"/>
  <xacro:limb name="upper" parent="base"><origin xyz="0 0 ${reach}"/></xacro:limb>
</robot>
"""


def test_a_ros1_xacro_with_unprefixed_tags_loads(tmp_path: Path) -> None:
    top = tmp_path / "old.urdf.xacro"
    top.write_text(_ROBOT)
    world = load_description(str(top), base_folder=tmp_path).world
    joint = world.get_connection_by_name("upper_joint")
    assert world.has_body("upper") and abs(float(joint.origin[2, 3]) - 0.3) < 1e-12


def test_only_documents_declaring_xacro_and_only_xacro_tags_change() -> None:
    assert prefix_legacy_tags(b"<robot><macro/></robot>") == b"<robot><macro/></robot>"
    text = b'<robot xmlns:xacro="x"><macro name="m"/><macros/><link name="if"/></robot>'
    assert prefix_legacy_tags(text) == (
        b'<robot xmlns:xacro="x"><xacro:macro name="m"/><macros/><link name="if"/></robot>'
    )
