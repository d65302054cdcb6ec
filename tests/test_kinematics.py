"""Forward kinematics and Jacobians, checked against pinocchio and finite differences."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from robotspec.description.urdf import world_from_urdf_xml
from robotspec.errors import KinematicsError
from robotspec.files.xmlsafe import parse_xml_file
from robotspec.model.kinematics import Kinematics
from robotspec.model.world import World

from .conftest import erd_robots, shared_path
from .pin_oracle import PinOracle

pytest.importorskip("pinocchio")


def _load(path: Path) -> World:
    return world_from_urdf_xml(parse_xml_file(path), str(path))


@pytest.fixture(scope="module")
def pr2() -> tuple[World, Kinematics, PinOracle]:
    path = erd_robots() / "pr2_description/urdf/pr2.urdf"
    w = _load(path)
    return w, Kinematics(w), PinOracle(str(path), w)


@pytest.fixture(scope="module")
def hsrb() -> tuple[World, Kinematics, PinOracle]:
    path = shared_path("robots/hsrb/hsrb4s.urdf")
    w = _load(path)
    return w, Kinematics(w), PinOracle(str(path), w)


def _configs(n_dof: int) -> st.SearchStrategy[np.ndarray]:
    return arrays(np.float64, (n_dof,), elements=st.floats(-4.0, 4.0))


def _check_against_pin(setup: tuple[World, Kinematics, PinOracle], q: np.ndarray) -> None:
    w, k, oracle = setup
    mine = k.forward(q)
    ref = oracle.poses(q)
    for b in w.bodies:
        np.testing.assert_allclose(mine[b.index], ref[b.name], atol=1e-9, err_msg=b.name)


@given(data=st.data())
def test_pr2_fk_matches_pinocchio_for_every_body(pr2, data) -> None:
    q = data.draw(_configs(len(pr2[0].degrees_of_freedom)))
    _check_against_pin(pr2, q)


@given(data=st.data())
def test_hsrb_fk_with_mimic_joints_matches_pinocchio(hsrb, data) -> None:
    w = hsrb[0]
    assert any(c.is_mimic for c in w.connections)
    q = data.draw(_configs(len(w.degrees_of_freedom)))
    _check_against_pin(hsrb, q)


def test_batch_equals_single(pr2) -> None:
    w, k, _ = pr2
    rng = np.random.default_rng(7)
    qs = rng.uniform(-3, 3, (40, len(w.degrees_of_freedom)))
    batch = k.forward_batch(qs)
    assert batch.shape == (40, len(w.bodies), 4, 4)
    for i in (0, 13, 39):
        np.testing.assert_allclose(batch[i], k.forward(qs[i]), atol=1e-12)
    small = k.forward_batch(qs[:3])
    np.testing.assert_allclose(small, batch[:3], atol=1e-12)


def test_batch_threads_and_out_give_the_same_poses(pr2) -> None:
    world, k, _ = pr2
    rng = np.random.default_rng(4)
    qs = rng.uniform(-2, 2, (2100, len(world.degrees_of_freedom)))  # above PARALLEL_BATCH
    one = k.forward_batch(qs, threads=1)
    np.testing.assert_array_equal(k.forward_batch(qs), one)
    for threads in (2, 3, 64):
        np.testing.assert_array_equal(k.forward_batch(qs[:101], threads=threads), one[:101])
    out = np.full_like(one, np.nan)
    got = k.forward_batch(qs, out=out, threads=2)
    assert got is out
    np.testing.assert_array_equal(out, one)
    # Reusing the buffer for another batch overwrites every entry.
    k.forward_batch(qs[::-1], out=out)
    np.testing.assert_array_equal(out, one[::-1])
    with pytest.raises(KinematicsError, match="threads"):
        k.forward_batch(qs, threads=0)
    for bad in (out[:-1], out.astype(np.float32), out[:, ::-1], np.zeros(3), [[1.0]]):
        with pytest.raises(KinematicsError, match="out must be"):
            k.forward_batch(qs, out=bad)  # type: ignore[arg-type]
    frozen = out.copy()
    frozen.flags.writeable = False
    with pytest.raises(KinematicsError, match="writeable"):
        k.forward_batch(qs, out=frozen)


def test_chain_fk_equals_relative_pose(pr2) -> None:
    w, k, _ = pr2
    q = np.random.default_rng(3).uniform(-2, 2, len(w.degrees_of_freedom))
    chain = k.chain("torso_lift_link", "r_gripper_tool_frame")
    np.testing.assert_allclose(
        chain.fk(q), k.pose(q, "r_gripper_tool_frame", relative_to="torso_lift_link"), atol=1e-12
    )
    assert chain.dof_names[:2] == ("r_shoulder_pan_joint", "r_shoulder_lift_joint")


def _numeric_jacobian(chain, q: np.ndarray, eps: float = 1e-7) -> np.ndarray:
    t0 = chain.fk(q)
    jac = np.zeros((6, len(chain.dof_indices)))
    for i, d in enumerate(chain.dof_indices):
        dq = q.copy()
        dq[d] += eps
        t1 = chain.fk(dq)
        jac[:3, i] = (t1[:3, 3] - t0[:3, 3]) / eps
        dr = (t1[:3, :3] @ t0[:3, :3].T - np.eye(3)) / eps
        jac[3:, i] = (dr[2, 1], dr[0, 2], dr[1, 0])
    return jac


@given(data=st.data())
def test_jacobian_matches_finite_differences(pr2, data) -> None:
    w, k, _ = pr2
    q = data.draw(_configs(len(w.degrees_of_freedom)))
    for tip in ("r_gripper_tool_frame", "l_gripper_r_finger_tip_link"):
        chain = k.chain("base_footprint", tip)
        np.testing.assert_allclose(chain.jacobian(q), _numeric_jacobian(chain, q), atol=2e-5)


def test_jacobian_of_mimic_chain(hsrb) -> None:
    w, k, _ = hsrb
    chain = k.chain("base_footprint", "hand_l_distal_link")
    q = np.random.default_rng(1).uniform(-1, 1, len(w.degrees_of_freedom))
    np.testing.assert_allclose(chain.jacobian(q), _numeric_jacobian(chain, q), atol=2e-5)


def test_planar_and_floating_base(pr2) -> None:
    from robotspec.model.world import ConnectionType

    w = pr2[0]
    for kind, n in ((ConnectionType.PLANAR, 3), (ConnectionType.FLOATING, 6)):
        based = w.with_base_connection("odom_T_base", "odom", kind)
        k = Kinematics(based)
        q = based.configuration()
        q[:n] = np.linspace(0.3, 0.9, n)
        base = k.pose(q, "base_footprint")
        if kind is ConnectionType.PLANAR:
            c, s = np.cos(0.9), np.sin(0.9)
            np.testing.assert_allclose(base[:3, 3], [0.3, 0.6, 0.0], atol=1e-12)
            np.testing.assert_allclose(base[:2, :2], [[c, -s], [s, c]], atol=1e-12)
        else:
            from robotspec.model.geometry import pose_from_xyz_rpy

            x, y, z, roll, pitch, yaw = q[:6]
            expected = pose_from_xyz_rpy((x, y, z), (roll, pitch, yaw))
            np.testing.assert_allclose(base, expected, atol=1e-12)
        chain = k.chain("odom", "r_gripper_tool_frame")
        # The chain class composes the base motion elementary motion by elementary motion.
        np.testing.assert_allclose(chain.fk(q), k.pose(q, "r_gripper_tool_frame"), atol=1e-12)
        np.testing.assert_allclose(chain.jacobian(q), _numeric_jacobian(chain, q), atol=2e-5)
        np.testing.assert_allclose(k.forward_batch(np.stack([q] * 20))[5], k.forward(q), atol=1e-12)


def test_bad_configuration_is_refused(pr2) -> None:
    w, k, _ = pr2
    with pytest.raises(KinematicsError, match=r"configuration must have shape \(D,\) with D = "):
        k.forward(np.zeros(3))
    q = w.configuration()
    q[0] = np.nan
    with pytest.raises(KinematicsError, match="NaN or infinite"):
        k.forward(q)
    chain = k.chain("torso_lift_link", "r_wrist_roll_link")
    for call in (chain.fk, chain.jacobian, k.forward):
        with pytest.raises(KinematicsError, match="NaN or infinite"):
            call(q)
        with pytest.raises(KinematicsError, match="shape"):
            call(np.zeros((2, len(q))))
        with pytest.raises(KinematicsError, match="shape"):
            call([1.0, "x"])
    for batch in (chain.fk_batch, k.forward_batch):
        with pytest.raises(KinematicsError, match="shape"):
            batch(np.zeros(len(q)))
        with pytest.raises(KinematicsError, match="NaN or infinite"):
            batch(np.stack([w.configuration(), q]))


def test_chain_batch_equals_single(pr2) -> None:
    w, k, _ = pr2
    qs = np.random.default_rng(7).uniform(-2, 2, (20, len(w.degrees_of_freedom)))
    chain = k.chain("base_footprint", "l_gripper_tool_frame")
    batch = chain.fk_batch(qs)
    assert batch.shape == (20, 4, 4)
    for q, pose in zip(qs, batch, strict=True):
        np.testing.assert_allclose(pose, chain.fk(q), atol=1e-12)
        np.testing.assert_allclose(
            pose, k.forward(q)[w.get_body_by_name("l_gripper_tool_frame").index], atol=1e-12
        )
    assert chain.fk_batch(np.zeros((0, len(w.degrees_of_freedom)))).shape == (0, 4, 4)
