"""``robotspec annotate mjcf``: the spec's semantics on a model the user already has.

The "foreign" models are made here the way a user gets one: MuJoCo's own URDF reader on
example-robot-data's Panda and UR5 (it fuses the fixed links, the tool frames with them, and
cannot read ``package://`` meshes, so the meshes are left out), names prefixed as robosuite
does. The annotated file is read back by MuJoCo and checked against robotspec's forward
kinematics at random configurations (1e-6 m), its keyframes against the named states, and the
model's own elements against the original. Skipped without MuJoCo (the ``mujoco`` extra).
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from lxml import etree

from robotspec.compiler import compile_robot
from robotspec.errors import RobotSpecError
from robotspec.interop.mujoco_annotate import annotate_mjcf
from robotspec.semantic import AbstractRobot
from tests.conftest import erd_robots
from tests.test_cli import run

mujoco = pytest.importorskip("mujoco", reason="annotating needs MuJoCo (pip install '.[mujoco]')")

URDFS = {
    "panda": "panda_description/urdf/panda.urdf",
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "pr2": "pr2_description/urdf/pr2.urdf",
}


def foreign(tmp: Path, robot: str, prefix: str, edit: Any = None, name: str = "model.xml") -> Path:
    """MuJoCo's MJCF of example-robot-data's URDF: meshes left out, every name prefixed."""
    root = etree.parse(str(erd_robots() / URDFS[robot])).getroot()
    for el in list(root.iter("visual", "collision")):
        if el.find(".//mesh") is not None:
            el.getparent().remove(el)
    for el in root.iter("link", "joint"):
        el.set("name", prefix + el.get("name", ""))
    for el in root.iter("parent", "child"):
        el.set("link", prefix + el.get("link", ""))
    for el in root.iter("mimic"):
        el.set("joint", prefix + el.get("joint", ""))
    spec = mujoco.MjSpec.from_string(etree.tostring(root, encoding="unicode"))
    spec.compiler.balanceinertia = True  # the PR2's sensor mount breaks the triangle rule
    spec.compile()
    xml = spec.to_xml()
    if edit is not None:
        tree = etree.fromstring(xml.encode())
        edit(tree)
        xml = etree.tostring(tree, encoding="unicode")
    path = tmp / name
    path.write_text(xml)
    return path


@pytest.fixture(scope="module")
def panda() -> AbstractRobot:
    return compile_robot("panda")


@pytest.fixture(scope="module")
def ur5() -> AbstractRobot:
    return compile_robot("ur5")


def _random(robot: AbstractRobot, n: int, seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        q = robot.world.default_configuration().copy()
        for dof in robot.world.degrees_of_freedom:
            lo = dof.lower if math.isfinite(dof.lower) else -math.pi
            hi = dof.upper if math.isfinite(dof.upper) else math.pi
            q[dof.index] = rng.uniform(lo, hi)
        out.append(q)
    return out


def _qpos(model: Any, robot: AbstractRobot, q: np.ndarray, prefix: str) -> np.ndarray:
    qpos = np.array(model.qpos0)
    for c in robot.world.connections:
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, prefix + c.name)
        if j >= 0:
            value = q[c.dofs[0]]
            if c.mimic is not None:
                value = c.mimic.multiplier * value + c.mimic.offset
            qpos[model.jnt_qposadr[j]] = value
    return qpos


def _names(model: Any, kind: Any, n: int) -> list[str]:
    return [mujoco.mj_id2name(model, kind, i) for i in range(n)]


@pytest.mark.parametrize(("name", "prefix"), [("panda", "robot0_"), ("ur5", "ur5_")])
def test_sites_keyframes_and_their_model_kept(
    tmp_path: Path, request: pytest.FixtureRequest, name: str, prefix: str
) -> None:
    robot: AbstractRobot = request.getfixturevalue(name)
    model_path = foreign(tmp_path, name, prefix)
    before = mujoco.MjModel.from_xml_path(str(model_path))
    out_path = tmp_path / "annotated.xml"
    out = annotate_mjcf(robot, model_path, output=out_path, excludes=True)
    out_path.write_text(out.xml)
    assert out.check_file(out_path) <= 1e-6
    assert all(m.how == "prefix" for m in out.joints.pairs)
    after = mujoco.MjModel.from_xml_path(str(out_path))

    # their model's own elements: the same names, counts and numbers
    obj = mujoco.mjtObj
    for kind, count in (
        (obj.mjOBJ_BODY, "nbody"),
        (obj.mjOBJ_JOINT, "njnt"),
        (obj.mjOBJ_GEOM, "ngeom"),
        (obj.mjOBJ_ACTUATOR, "nu"),
    ):
        n = getattr(before, count)
        assert getattr(after, count) == n
        assert _names(after, kind, n) == _names(before, kind, n)
    for array in ("body_pos", "body_quat", "jnt_range", "jnt_axis", "geom_size", "body_mass"):
        assert np.array_equal(getattr(after, array), getattr(before, array)), array
    assert before.nsite == 0 and after.nsite == len(robot.manipulators)

    # every tool frame's site where robotspec's FK puts it, at random configurations
    data = mujoco.MjData(after)
    for q in _random(robot, 12, seed=3):
        data.qpos[:] = _qpos(after, robot, q, prefix)
        mujoco.mj_kinematics(after, data)
        poses = robot.kinematics.forward(q)
        for m in robot.manipulators:
            s = mujoco.mj_name2id(after, obj.mjOBJ_SITE, m.tool_frame.name)
            pose = poses[m.tool_frame.index]
            assert np.allclose(data.site_xpos[s], pose[:3, 3], atol=1e-6, rtol=0)
            assert np.allclose(data.site_xmat[s].reshape(3, 3), pose[:3, :3], atol=1e-6, rtol=0)

    # a keyframe per named state: its joints at the state, the others at qpos0
    states = dict(robot.joint_states)
    for m in robot.manipulators:
        states.update({f"{m.name}.{k}": v for k, v in m.states.items()})
    assert set(out.keys) == set(states) and after.nkey == len(states)
    for key in out.keys:
        k = mujoco.mj_name2id(after, obj.mjOBJ_KEY, key)
        values = states[key].as_dict()
        want = _qpos(after, robot, robot.world.configuration(values), prefix)
        held = np.array(after.qpos0)
        for c in robot.world.connections:
            j = mujoco.mj_name2id(after, obj.mjOBJ_JOINT, prefix + c.name)
            named = robot.world.degrees_of_freedom[c.dofs[0]].name in values if c.dofs else False
            if j >= 0 and named:
                held[after.jnt_qposadr[j]] = want[after.jnt_qposadr[j]]
        assert np.array_equal(after.key_qpos[k], held), key
    assert after.nexclude == before.nexclude + len(out.excludes)


def test_a_name_already_taken_is_suffixed(tmp_path: Path, panda: AbstractRobot) -> None:
    def add_site(tree: Any) -> None:
        body = next(b for b in tree.iter("body") if b.get("name") == "robot0_panda_link1")
        etree.SubElement(body, "site", name="panda_hand_tcp")

    path = foreign(tmp_path, "panda", "robot0_", add_site)
    out = annotate_mjcf(panda, path)
    assert [s.name for s in out.sites] == ["panda_hand_tcp_robotspec"]
    assert any("already has a site named 'panda_hand_tcp'" in n for n in out.notes)


def _flip_joint3(tree: Any) -> None:
    joint = next(j for j in tree.iter("joint") if j.get("name") == "robot0_panda_joint3")
    joint.set("axis", "0 0 -1")


def test_a_joint_turning_the_other_way_is_refused(tmp_path: Path, panda: AbstractRobot) -> None:
    path = foreign(tmp_path, "panda", "robot0_", _flip_joint3)
    with pytest.raises(RobotSpecError) as err:
        annotate_mjcf(panda, path)
    assert err.value.name == "robot0_panda_joint3"
    assert "turns the opposite way to the robot's 'panda_joint3'" in err.value.message


def _rename_joint4(tree: Any) -> None:
    joint = next(j for j in tree.iter("joint") if j.get("name") == "robot0_panda_joint4")
    joint.set("name", "robot0_elbow")


def test_an_unmatched_joint_names_the_closest(tmp_path: Path, panda: AbstractRobot) -> None:
    path = foreign(tmp_path, "panda", "robot0_", _rename_joint4)
    with pytest.raises(RobotSpecError) as err:
        annotate_mjcf(panda, path)
    assert err.value.name == "panda_joint4"
    assert err.value.message.startswith(
        "joint 'panda_joint4' (of chain 'arm') has no joint of the same name in "
    )
    assert err.value.message.endswith(
        "; closest in the model: 'robot0_elbow' (add --map robot0_elbow=panda_joint4)"
    )
    # the user's word settles it
    out = annotate_mjcf(panda, path, mapping={"robot0_elbow": "panda_joint4"})
    assert [m.ours for m in out.joints.pairs if m.how == "map"] == ["panda_joint4"]


def test_cli_exit_codes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    path = foreign(tmp_path, "panda", "robot0_")
    out = tmp_path / "out.xml"
    code, stdout, err = run(capsys, "annotate", "mjcf", "panda", str(path), "-o", str(out))
    assert code == 0 and stdout == "" and out.is_file(), err
    assert "sites panda_hand_tcp on robot0_panda_link7" in err
    code, _, err = run(capsys, "annotate", "mjcf", "panda", str(path), "-o", str(out))
    assert code == 1 and "--force" in err  # an existing file is kept
    code, _, err = run(capsys, "annotate", "mjcf", "panda", str(path), "-o", str(path), "--force")
    assert code == 1 and "the model being annotated" in err  # never their model itself
    flipped = foreign(tmp_path, "panda", "robot0_", _flip_joint3, name="flipped.xml")
    code, _, err = run(capsys, "annotate", "mjcf", "panda", str(flipped), "-o", str(out), "--force")
    assert code == 1 and "robot0_panda_joint3" in err and "Traceback" not in err
    code, _, err = run(capsys, "annotate", "mjcf", "panda", str(path), "-o", str(out), "--map", "x")
    assert code == 1 and "--map 'x' is not THEIRS=OURS" in err
    code, _, err = run(
        capsys, "annotate", "mjcf", "panda", str(path), "-o", str(tmp_path / "o.txt")
    )
    assert code == 2
    code, _, err = run(capsys, "annotate", "mjcf", "panda", str(path))
    assert code == 2  # -o is required
    code, _, err = run(
        capsys,
        "annotate",
        "mjcf",
        "panda",
        str(tmp_path / "nope.xml"),
        "-o",
        str(tmp_path / "n.xml"),
    )
    assert code == 1 and "file not found" in err

    real = importlib.util.find_spec

    def find_spec(name: str, *args: Any, **kwargs: Any) -> Any:
        return None if name == "mujoco" else real(name, *args, **kwargs)

    monkeypatch.setattr(importlib.util, "find_spec", find_spec)
    code, stdout, err = run(capsys, "annotate", "mjcf", "panda", str(path), "-o", str(out))
    assert code == 1 and stdout == ""
    assert err == (
        "error: robotspec annotate mjcf needs MuJoCo; install it with "
        "`pip install 'robotspec[mujoco]'`\n"
    )


def _without_fingers(tree: Any) -> None:
    for el in list(tree.iter("joint", "equality")):
        if el.tag == "equality" or "finger" in el.get("name", ""):
            el.getparent().remove(el)


def test_a_model_without_the_part_says_so(tmp_path: Path, panda: AbstractRobot) -> None:
    path = foreign(tmp_path, "panda", "robot0_", _without_fingers)
    with pytest.raises(RobotSpecError) as err:
        annotate_mjcf(panda, path)
    assert err.value.message.endswith(
        "each joint of the model is matched to another one of the robot, so the model has no "
        "such part (an arm without its gripper?)"
    )


def test_a_looser_tolerance_accepts_a_rounded_model(tmp_path: Path, panda: AbstractRobot) -> None:
    def round_joint2(tree: Any) -> None:  # a mount rounded by hand, as robosuite's 0.924
        body = next(b for b in tree.iter("body") if b.get("name") == "robot0_panda_link3")
        body.set("quat", "0.7072 0.7070 0 0")

    path = foreign(tmp_path, "panda", "robot0_", round_joint2)
    with pytest.raises(RobotSpecError) as err:
        annotate_mjcf(panda, path)
    assert "does not move as the robot's" in err.value.message
    out = annotate_mjcf(panda, path, tolerance=1e-3)
    assert 1e-6 < out.body_error <= 1e-3 and out.site_error <= 1e-3


def test_cameras_look_where_the_spec_says(tmp_path: Path) -> None:
    """The PR2's camera (on a frame MuJoCo fused away) at its frame, looking along its axis."""
    pr2 = compile_robot("pr2")
    path = foreign(tmp_path, "pr2", "")
    out_path = tmp_path / "annotated.xml"
    out = annotate_mjcf(pr2, path, output=out_path)
    out_path.write_text(out.xml)
    assert [c.of for c in out.cameras] == [c.name for c in pr2.cameras] != []
    model = mujoco.MjModel.from_xml_path(str(out_path))
    data = mujoco.MjData(model)
    drive = set(pr2.drive.dofs) if pr2.drive is not None else set()
    for q in _random(pr2, 4, seed=5):
        q[list(drive)] = 0.0  # their model has no base joint: the base stays at the origin
        data.qpos[:] = _qpos(model, pr2, q, "")
        mujoco.mj_kinematics(model, data)
        mujoco.mj_camlight(model, data)
        poses = pr2.kinematics.forward(q)
        for cam in pr2.cameras:
            c = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, cam.name)
            frame = poses[cam.root.index]
            assert np.allclose(data.cam_xpos[c], frame[:3, 3], atol=1e-6, rtol=0)
            looks = -data.cam_xmat[c].reshape(3, 3)[:, 2]  # MuJoCo's cameras look along -z
            assert looks @ (frame[:3, :3] @ cam.forward_facing_axis) == pytest.approx(1.0)
            fovy = math.degrees(cam.field_of_view.vertical_angle)
            assert model.cam_fovy[c] == pytest.approx(fovy, abs=1e-9)


def test_another_folder_and_an_include(tmp_path: Path, panda: AbstractRobot) -> None:
    def meshdir(tree: Any) -> None:
        tree.find("compiler").set("meshdir", "assets")

    path = foreign(tmp_path, "panda", "robot0_", meshdir)
    out = annotate_mjcf(panda, path, output=tmp_path / "sub" / "out.xml")
    compiler = etree.fromstring(out.xml.encode()).find("compiler")
    assert compiler.get("meshdir") == "../assets" and compiler.get("texturedir") == ".."
    assert any("re-pointed to .." in n for n in out.notes)

    scene = tmp_path / "scene.xml"  # Menagerie's scene.xml includes the robot's file
    scene.write_text('<mujoco model="scene">\n  <include file="model.xml"/>\n</mujoco>\n')
    with pytest.raises(RobotSpecError) as err:
        annotate_mjcf(panda, scene)
    assert err.value.message == (
        "body 'robot0_panda_link7' is not written in this file (it comes from an <include> or "
        "an attached model): annotate the file that defines it"
    )


def test_mujocos_complaint_is_one_line_at_its_line(tmp_path: Path, panda: AbstractRobot) -> None:
    """MuJoCo's two-line complaint (what, then where) reads as one line at the model's line."""

    def unbalanced(tree: Any) -> None:  # a hand-edited inertia that breaks A + B >= C
        body = next(b for b in tree.iter("body") if b.get("name") == "robot0_panda_link3")
        inertial = body.find("inertial")
        inertial.attrib.pop("fullinertia", None)
        inertial.set("diaginertia", "1 0.1 0.1")
        tree.find("compiler").attrib.pop("balanceinertia", None)

    path = foreign(tmp_path, "panda", "robot0_", unbalanced)
    with pytest.raises(RobotSpecError) as err:
        annotate_mjcf(panda, path)
    text = path.read_text().splitlines()
    line = next(i for i, t in enumerate(text, 1) if 'name="robot0_panda_link3"' in t)
    assert err.value.line == line and "\n" not in err.value.message
    assert err.value.message.startswith("MuJoCo cannot load it: inertia must satisfy A + B >= C")
    assert "element 'robot0_panda_link3'" in err.value.message
