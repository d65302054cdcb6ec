"""``robotspec export mjcf`` without MuJoCo: what the file says, and what the command refuses.

A small layout written here holds each MJCF feature once (floating base, mimic, camera,
damping, a disabled pair, a massless moving link); MuJoCo's own verdict on the exported files
is in ``test_export_mjcf_oracle``.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from lxml import etree

from robotspec.compiler import check_spec, resolve_spec
from robotspec.errors import RobotSpecError
from robotspec.export.mjcf import mjcf_export
from robotspec.export.mjcf_meshes import MAX_FACES, MeshAssets
from robotspec.export.urdf import joined_urdf
from robotspec.semantic import AbstractRobot
from robotspec.spec.load import load_spec
from tests.conftest import erd_robots

TINY_URDF = """<?xml version="1.0"?>
<robot name="tiny">
  <link name="base_link">
    <inertial><origin xyz="0 0 0.05"/><mass value="2.0"/>
      <inertia ixx="0.02" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="link1">
    <inertial><origin xyz="0 0 0.15" rpy="0.3 0 0"/><mass value="1.0"/>
      <inertia ixx="0.01" iyy="0.012" izz="0.002" ixy="0.0001" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.15"/>
      <geometry><cylinder radius="0.04" length="0.3"/></geometry></collision>
  </link>
  <link name="link2">
    <inertial><origin xyz="0 0 0.1"/><mass value="0.5"/>
      <inertia ixx="0.004" iyy="0.004" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><sphere radius="0.05"/></geometry></collision>
  </link>
  <link name="tool0"/>
  <link name="finger_left">
    <inertial><mass value="0.05"/>
      <inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="finger_right"/>
  <link name="camera_link"/>
  <link name="camera_optical_frame"/>
  <joint name="j1" type="revolute">
    <parent link="base_link"/><child link="link1"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 0 1"/><limit lower="-2.5" upper="2.5" effort="40" velocity="2.0"/>
    <dynamics damping="0.5" friction="0.1"/>
  </joint>
  <joint name="j2" type="revolute">
    <parent link="link1"/><child link="link2"/><origin xyz="0 0 0.3" rpy="0 0.2 0"/>
    <axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" effort="20" velocity="2.5"/>
  </joint>
  <joint name="tool_joint" type="fixed">
    <parent link="link2"/><child link="tool0"/><origin xyz="0 0 0.25"/>
  </joint>
  <joint name="finger_left_joint" type="prismatic">
    <parent link="link2"/><child link="finger_left"/><origin xyz="0 0.02 0.2"/>
    <axis xyz="0 1 0"/><limit lower="0" upper="0.04" effort="5" velocity="0.1"/>
  </joint>
  <joint name="finger_right_joint" type="prismatic">
    <parent link="link2"/><child link="finger_right"/><origin xyz="0 -0.02 0.2"/>
    <axis xyz="0 1 0"/><limit lower="-0.04" upper="0" effort="5" velocity="0.1"/>
    <mimic joint="finger_left_joint" multiplier="-1" offset="0"/>
  </joint>
  <joint name="camera_joint" type="fixed">
    <parent link="link1"/><child link="camera_link"/><origin xyz="0.05 0 0.2"/>
  </joint>
  <joint name="camera_optical_joint" type="fixed">
    <parent link="camera_link"/><child link="camera_optical_frame"/>
    <origin rpy="-1.5707963267948966 0 -1.5707963267948966"/>
  </joint>
</robot>
"""

TINY_SRDF = """<?xml version="1.0"?>
<robot name="tiny">
  <disable_collisions link1="base_link" link2="link2" reason="Never"/>
</robot>
"""

TINY_SPEC = """robotspec: 1
name: Tiny
description: {urdf: tiny.urdf, srdf: tiny.srdf}
root: base_link
drive: {type: floating}
chains:
  arm:
    root: base_link
    tip: link2
    manipulator: gripper
    states:
      ready: {j1: 0.5, j2: -0.75}
manipulators:
  gripper:
    type: generic
    root: link2
    tool_frame: tool0
    states:
      open: {finger_left_joint: 0.04}
sensors:
  eye:
    type: camera
    body: camera_optical_frame
    field_of_view: {horizontal: 1.2, vertical: 0.9}
"""


@pytest.fixture()
def tiny(tmp_path: Path) -> Path:
    (tmp_path / "tiny.urdf").write_text(TINY_URDF)
    (tmp_path / "tiny.srdf").write_text(TINY_SRDF)
    spec = tmp_path / "tiny.yaml"
    spec.write_text(TINY_SPEC)
    return spec


def _export(ref: str | Path, name: str = "robot") -> tuple[AbstractRobot, object]:
    path = resolve_spec(ref)
    robot = check_spec(path).robot
    assert robot is not None
    return robot, mjcf_export(robot, joined_urdf(load_spec(path)), name=name)


# ------------------------------------------------------------------ without MuJoCo
def test_the_small_layout_holds_every_feature_once(tiny: Path) -> None:
    robot, ex = _export(tiny)
    doc = etree.fromstring(ex.xml.encode())  # type: ignore[attr-defined]
    bodies = [b.get("name") for b in doc.iter("body")]
    # Every body kept, the fixed leaves and the massless optical frame too.
    assert sorted(bodies) == sorted(b.name for b in robot.world.bodies)
    (free,) = doc.iter("freejoint")
    assert free.getparent().getparent().tag == "worldbody"
    j1 = doc.find(".//joint[@name='j1']")
    assert j1.get("range") == "-2.5 2.5" and j1.get("damping") == "0.5"
    assert j1.get("frictionloss") == "0.1"
    assert doc.find(".//site[@name='tool0']").getparent().get("name") == "tool0"
    camera = doc.find(".//camera[@name='eye']")
    assert camera.getparent().get("name") == "camera_optical_frame"
    assert float(camera.get("fovy")) == pytest.approx(math.degrees(0.9))
    # The SRDF's pair, and the adjacent pairs robotspec's own checker skips too.
    excluded = [(e.get("body1"), e.get("body2")) for e in doc.iter("exclude")]
    assert excluded == [("base_link", "link1"), ("base_link", "link2"), ("link1", "link2")]
    (coupling,) = doc.find("equality")
    assert coupling.get("joint1") == "finger_right_joint"
    assert coupling.get("joint2") == "finger_left_joint"
    assert coupling.get("polycoef") == "0 -1.0 0 0 0"
    servos = {a.get("joint"): a for a in doc.iter("position")}
    assert set(servos) == {"j1", "j2", "finger_left_joint"}  # not the mimic, not the base
    assert servos["j1"].get("ctrlrange") == "-2.5 2.5"
    assert servos["j1"].get("forcerange") == "-40.0 40.0"
    # A prismatic servo moves its link's mass: kp = m (2 pi f)^2, critically damped.
    omega = 2.0 * math.pi * 8.0
    assert float(servos["finger_left_joint"].get("kp")) == pytest.approx(0.05 * omega**2)
    assert float(servos["finger_left_joint"].get("kv")) == pytest.approx(2 * 0.05 * omega)
    ready = doc.find(".//key[@name='arm.ready']")
    assert ready.get("ctrl") == "0.5 -0.75 0"  # the servos hold the state: j1, j2, finger
    keys = [k.get("name") for k in doc.iter("key")]
    assert keys == ["default", "gripper.open", "arm.ready"]  # the robot's order of states
    # The velocity limits MJCF cannot hold are said in the file.
    assert re.search(r"velocity limits.*j1: 2\.0.*j2: 2\.5", ex.xml)
    # finger_right moves (a mimic) and has no mass: it gets a tiny one, and a note says so.
    assert any("finger_right" in n for n in ex.notes)


def test_a_bad_inertial_names_the_link_and_line(tmp_path: Path, tiny: Path) -> None:
    (tmp_path / "tiny.urdf").write_text(TINY_URDF.replace('mass value="1.0"', 'mass value="nan"'))
    path = resolve_spec(tiny)
    with pytest.raises(RobotSpecError) as caught:
        robot = check_spec(path).robot
        assert robot is not None
        mjcf_export(robot, joined_urdf(load_spec(path)), name="robot")
    assert "link1" in str(caught.value) and "tiny.urdf:" in str(caught.value)


def test_an_infinite_inertia_names_the_link_and_its_line(tmp_path: Path, tiny: Path) -> None:
    """The inertia tensor is read by the export alone: its error still says where."""
    (tmp_path / "tiny.urdf").write_text(TINY_URDF.replace('ixy="0.0001"', 'ixy="inf"'))
    line = next(i for i, t in enumerate(TINY_URDF.splitlines(), 1) if 'ixy="0.0001"' in t)
    link = next(i for i, t in enumerate(TINY_URDF.splitlines(), 1) if 'name="link1"' in t)
    path = resolve_spec(tiny)
    robot = check_spec(path).robot
    assert robot is not None
    with pytest.raises(RobotSpecError) as caught:
        mjcf_export(robot, joined_urdf(load_spec(path)), name="robot")
    assert str(caught.value).endswith(
        f"link 'link1' (URDF line {link}): ixy='inf' must be 1 finite number"
    )
    assert caught.value.line == line


def test_an_impossible_inertia_is_said(tmp_path: Path, tiny: Path) -> None:
    """A tensor with a negative principal moment is raised to MuJoCo's floor with a note."""
    bad = TINY_URDF.replace('ixx="0.004" iyy="0.004"', 'ixx="-0.004" iyy="0.004"')
    (tmp_path / "tiny.urdf").write_text(bad)
    robot, out = _export(tiny)
    assert any(
        n.startswith("body 'link2': the URDF inertia has a negative principal moment (-0.004")
        for n in out.notes  # type: ignore[attr-defined]
    )
    (tmp_path / "tiny.urdf").write_text(TINY_URDF)
    _, fine = _export(tiny)
    assert not any("negative principal" in n for n in fine.notes)  # type: ignore[attr-defined]


def test_servos_are_tuned_at_the_largest_inertia_not_the_default(tiny: Path) -> None:
    """j1 turns link2 about z: upright at the default it sees less than tilted at 'arm.ready'.

    A servo tuned at the default alone would be too soft (Kinova's base joint: 400 times).
    """
    from robotspec.export.mjcf_bodies import BodyWriter
    from robotspec.export.mjcf_dynamics import joint_inertias

    robot, ex = _export(tiny)
    world = robot.world
    j1 = world.get_connection_by_name("j1")
    inertials = BodyWriter(robot, joined_urdf(load_spec(resolve_spec(tiny))), "m").inertials

    def inertia(state: dict[str, float]) -> float:
        poses = robot.kinematics.forward(world.configuration(state))
        return joint_inertias(world, poses, inertials, [j1])["j1"]

    at_default, at_ready = inertia({}), inertia({"j1": 0.5, "j2": -0.75})
    assert at_ready > 1.05 * at_default
    act = etree.fromstring(ex.xml.encode()).find(".//position[@name='j1']")  # type: ignore[attr-defined]
    omega = 2.0 * math.pi * 8.0
    assert float(act.get("kp")) >= at_ready * omega**2 * (1.0 - 1e-12)


def test_a_mesh_over_mujocos_face_cap_is_cut_in_pieces(tmp_path: Path) -> None:
    n = MAX_FACES + 10
    vertices = np.random.default_rng(1).random((n + 2, 3))
    faces = np.stack([np.arange(n), np.arange(n) + 1, np.arange(n) + 2], axis=1)
    lines = [f"v {x} {y} {z}" for x, y, z in vertices] + [
        f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces
    ]
    obj = tmp_path / "big.obj"
    obj.write_text("\n".join(lines) + "\n")
    assets = MeshAssets("m")
    names = assets.assets(str(obj), (1.0, 1.0, 1.0))
    assert names == ["big_part1", "big_part2"]
    sizes = [len(produce()) for _, produce in assets.files()]
    assert sizes == [84 + 50 * MAX_FACES, 84 + 50 * 10]


def test_cli_writes_the_file_and_its_meshes_and_refuses_what_it_must(
    tmp_path: Path, tiny: Path
) -> None:
    out = tmp_path / "out" / "tiny.xml"
    run = [sys.executable, "-m", "robotspec", "export", "mjcf", str(tiny), "-o"]
    done = subprocess.run([*run, str(out)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "exported by robotspec" in out.read_text() and "wrote" in done.stderr
    again = subprocess.run([*run, str(out)], capture_output=True, text=True, timeout=300)
    assert again.returncode == 1 and "--force" in again.stderr
    bad = subprocess.run([*run, str(tmp_path / "x.urdf")], capture_output=True, text=True)
    assert bad.returncode == 2
    assert "must end in .xml" in " ".join(bad.stderr.replace("\u2502", " ").split())
    assert "Traceback" not in again.stderr + bad.stderr


def test_cli_never_writes_meshes_through_a_planted_link(tmp_path: Path) -> None:
    erd_robots()  # the UR5 comes from example-robot-data
    out = tmp_path / "out"
    out.mkdir()
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (out / "ur5_meshes").symlink_to(elsewhere)
    run = [sys.executable, "-m", "robotspec", "export", "mjcf", "ur5", "-o", str(out / "ur5.xml")]
    done = subprocess.run(run, capture_output=True, text=True, timeout=300)
    assert done.returncode == 1, done.stderr
    assert list(elsewhere.iterdir()) == [] and not (out / "ur5.xml").exists()
