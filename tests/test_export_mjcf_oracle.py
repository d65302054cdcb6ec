"""``robotspec export mjcf`` against MuJoCo itself: the same bodies, sites, states and servos.

At random configurations every body and every tool-frame site is where robotspec's forward
kinematics puts it (1e-9 m), each keyframe is its named state, no two bodies touch at the
default state once the excluded pairs apply, and the servos and couplings hold under MuJoCo's
physics. Robots: the shipped Panda, UR5, PR2 and the composed dual Panda, example-robot-data's
Solo-12 drafted by ``robotspec init`` (nobody wrote its spec), and the small layout of
``test_export_mjcf``. Skipped without MuJoCo (the ``mujoco`` extra).
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from robotspec.semantic import AbstractRobot
from tests.conftest import erd_robots
from tests.test_export_mjcf import _export
from tests.test_export_mjcf import tiny as tiny  # the fixture, used by name

mujoco = pytest.importorskip("mujoco", reason="the oracle is MuJoCo (pip install '.[mujoco]')")


def _load(ex: object, folder: Path, name: str = "robot") -> object:
    (folder / f"{name}_meshes").mkdir(parents=True, exist_ok=True)
    for rel, produce in ex.meshes:  # type: ignore[attr-defined]
        (folder / rel).write_bytes(produce())
    path = folder / f"{name}.xml"
    path.write_text(ex.xml)  # type: ignore[attr-defined]
    return mujoco.MjModel.from_xml_path(str(path))


def _random_configurations(robot: AbstractRobot, n: int, seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        q = robot.world.default_configuration().copy()
        for dof in robot.world.degrees_of_freedom:
            lo = dof.lower if math.isfinite(dof.lower) else -3.0
            hi = dof.upper if math.isfinite(dof.upper) else 3.0
            q[dof.index] = rng.uniform(lo, hi)
        out.append(q)
    return out


def _check_against_fk(robot: AbstractRobot, ex: object, model: object) -> None:
    data = mujoco.MjData(model)
    for q in _random_configurations(robot, 6, seed=7):
        data.qpos[:] = ex.qpos(robot, q)  # type: ignore[attr-defined]
        mujoco.mj_kinematics(model, data)
        poses = robot.kinematics.forward(q)
        for body in robot.world.bodies:
            i = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body.name)
            if i < 0:
                assert body.index == 0 and body.name == "world"  # MuJoCo's world body
                continue
            assert np.allclose(data.xpos[i], poses[body.index][:3, 3], atol=1e-9), body.name
            assert np.allclose(data.xmat[i].reshape(3, 3), poses[body.index][:3, :3], atol=1e-9)
        for m in robot.manipulators:
            s = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, m.tool_frame.name)
            assert np.allclose(data.site_xpos[s], poses[m.tool_frame.index][:3, 3], atol=1e-9)


def _check_keyframes(robot: AbstractRobot, ex: object, model: object) -> None:
    data = mujoco.MjData(model)
    states = dict(robot.joint_states)
    for k in range(model.nkey):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_KEY, k)
        values = {} if name == "default" else states[name].as_dict()
        q = robot.world.configuration(values)
        mujoco.mj_resetDataKeyframe(model, data, k)
        assert np.allclose(data.qpos, ex.qpos(robot, q), atol=1e-12), name  # type: ignore[attr-defined]
        for joint, value in values.items():
            j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
            assert data.qpos[model.jnt_qposadr[j]] == pytest.approx(value, abs=1e-12)
    assert model.nkey == 1 + len(states)


def _contacts_at_default(model: object) -> list[tuple[str, str]]:
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    name = lambda g: mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, model.geom_bodyid[g])  # noqa: E731
    return [(name(c.geom1), name(c.geom2)) for c in data.contact[: data.ncon]]


@pytest.mark.parametrize("ref", ["panda", "ur5", "pr2", "dual_panda"])
def test_shipped_robots_agree_with_mujoco(ref: str, tmp_path: Path) -> None:
    erd_robots()  # the shipped robots' files, or a skip with the reason
    robot, ex = _export(ref)
    model = _load(ex, tmp_path)
    _check_against_fk(robot, ex, model)
    _check_keyframes(robot, ex, model)
    assert _contacts_at_default(model) == []
    assert model.nu == len(ex.actuated)  # type: ignore[attr-defined]


def test_the_small_layout_agrees_with_mujoco_and_its_servos_hold(
    tiny: Path, tmp_path: Path
) -> None:
    robot, ex = _export(tiny)
    model = _load(ex, tmp_path)
    _check_against_fk(robot, ex, model)
    _check_keyframes(robot, ex, model)
    # The mimic coupling holds under physics; the servos bring the arm to 'ready'.
    model.opt.gravity[:] = 0.0
    data = mujoco.MjData(model)
    k = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "arm.ready")
    mujoco.mj_resetDataKeyframe(model, data, k)
    data.ctrl[:] = [0.2, 0.3, 0.03]
    for _ in range(1500):
        mujoco.mj_step(model, data)
    adr = {
        n: model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n)]
        for n in ("j1", "j2", "finger_left_joint", "finger_right_joint")
    }
    assert data.qpos[adr["j1"]] == pytest.approx(0.2, abs=2e-3)
    assert data.qpos[adr["j2"]] == pytest.approx(0.3, abs=2e-3)
    assert data.qpos[adr["finger_right_joint"]] == pytest.approx(
        -data.qpos[adr["finger_left_joint"]], abs=1e-3
    )


def test_a_fixed_base_touching_its_first_link_is_no_contact(tiny: Path, tmp_path: Path) -> None:
    """Adjacent links never collide in robotspec; MuJoCo filters a parent only when it moves.

    The small layout on a fixed base, its first link's hull reaching into the base's box (as
    Go2's hips reach into its trunk): the pair is excluded, so nothing touches at rest.
    """
    from tests.test_export_mjcf import TINY_SPEC, TINY_URDF

    overlap = TINY_URDF.replace(
        '<collision><origin xyz="0 0 0.15"/>', '<collision><origin xyz="0 0 0.0"/>', 1
    )
    assert overlap != TINY_URDF
    (tmp_path / "tiny.urdf").write_text(overlap)
    tiny.write_text(TINY_SPEC.replace("drive: {type: floating}", "drive: {type: fixed}"))
    robot, ex = _export(tiny)
    model = _load(ex, tmp_path / "out")
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    body = model.geom_bodyid
    touching = {
        tuple(sorted(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body[g]) for g in pair))
        for pair in ((c.geom1, c.geom2) for c in data.contact[: data.ncon])
    }
    assert touching == set()


def test_a_drafted_robot_nobody_specified_exports(tmp_path: Path) -> None:
    """example-robot-data's Solo-12 (floating base, four legs): drafted by init, then exported."""
    urdf = erd_robots() / "solo_description" / "robots" / "solo12.urdf"
    spec = tmp_path / "solo.yaml"
    init = [sys.executable, "-m", "robotspec", "init", str(urdf), "-o", str(spec)]
    done = subprocess.run(init, capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    robot, ex = _export(spec)
    model = _load(ex, tmp_path)
    _check_against_fk(robot, ex, model)
    _check_keyframes(robot, ex, model)
