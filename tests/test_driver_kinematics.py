"""H/P kinematics: FK at q = 0 matches the reference note's table; Jacobian matches FK."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robotspec.driver.chain_kinematics import HPChain
from robotspec.driver.conversions import tool_transform
from robotspec.driver.robot_info import Pose, load_robot_info
from robotspec.driver.sim import SimRobot
from robotspec.model.rotations import (
    matrix_to_quat_wxyz,
    matrix_to_quat_wxyz_tuple,
    quat_wxyz_to_matrix,
)
from tests.driver_support import RRP, robotinfo, shared_robotinfo_files

TABLE = {
    "abb_irb1200_5_90.yml": [(0.533, 0, 0.8891)],
    "abb_irb6640_180_255.yml": [(1.6625, 0, 2.055)],
    "abb_irb6700_235_265.yml": [(1.7025, 0, 2.115)],
    "ur5e.yml": [(-0.817, -0.234, 0.063)],
    "baxter_both_arms.yml": [(0.7975, 0.9925, 0.321), (0.7975, -0.9925, 0.321)],
}


def _chains(path: object) -> list[HPChain]:
    robot = SimRobot(load_robot_info(path))  # type: ignore[arg-type]
    return robot._hp


@pytest.mark.parametrize("name", sorted(TABLE))
def test_fk_at_zero_matches_reference(name: str) -> None:
    for hp, expected in zip(_chains(robotinfo(name)), TABLE[name], strict=True):
        r, p = hp.fk(np.zeros(hp.n))
        np.testing.assert_allclose(p, expected, atol=1e-3)


def test_abb_flange_orientation() -> None:
    (hp,) = _chains(robotinfo("abb_irb1200_5_90.yml"))
    r, _ = hp.fk(np.zeros(6))
    np.testing.assert_allclose(matrix_to_quat_wxyz(r), [0.7071, 0, 0.7071, 0], atol=1e-4)


def _random_chain(seed: int, coordinate_axes: bool = False) -> HPChain:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 8))
    h = rng.normal(size=(n, 3))
    h /= np.linalg.norm(h, axis=1)[:, None]
    offsets = rng.normal(size=(n + 1, 3)) * 0.3
    if coordinate_axes:
        # Mostly +-x/y/z axes (the fast path of tcp_state), some general ones; some zero offsets.
        for i in range(n):
            if rng.random() < 0.8:
                h[i] = 0.0
                h[i, rng.integers(3)] = rng.choice([-1.0, 1.0])
        offsets[rng.random(n + 1) < 0.3] = 0.0
    return HPChain(
        h,
        offsets,
        prismatic=list(rng.random(n) < 0.3),
        flange_rotation=quat_wxyz_to_matrix(rng.normal(size=4)),
        flange_position=rng.normal(size=3) * 0.1,
    )


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10_000))
def test_jacobian_matches_finite_differences(seed: int) -> None:
    hp = _random_chain(seed)
    rng = np.random.default_rng(seed + 1)
    q = rng.uniform(-2, 2, hp.n)
    tool_r, tool_p = quat_wxyz_to_matrix(rng.normal(size=4)), rng.normal(size=3) * 0.1
    r0, p0, jac = hp.fk_jacobian(q, tool_r, tool_p)
    eps = 1e-6
    for i in range(hp.n):
        dq = np.zeros(hp.n)
        dq[i] = eps
        r1, p1 = hp.fk(q + dq, tool_r, tool_p)
        np.testing.assert_allclose((p1 - p0) / eps, jac[3:, i], atol=1e-5)
        w = r1 @ r0.T
        omega = np.array([w[2, 1] - w[1, 2], w[0, 2] - w[2, 0], w[1, 0] - w[0, 1]]) / (2 * eps)
        np.testing.assert_allclose(omega, jac[:3, i], atol=1e-5)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 10_000), st.booleans())
def test_fast_path_equals_numpy_path(seed: int, coordinate_axes: bool) -> None:
    hp = _random_chain(seed, coordinate_axes)
    rng = np.random.default_rng(seed + 2)
    q = rng.uniform(-3, 3, hp.n)
    qd = rng.uniform(-1, 1, hp.n)
    tool_r, tool_p = quat_wxyz_to_matrix(rng.normal(size=4)), rng.normal(size=3) * 0.1
    r, p, jac = hp.fk_jacobian(q, tool_r, tool_p)
    rot, pos, twist = hp.tcp_state(
        q.tolist(), qd.tolist(), tool_r.reshape(9).tolist(), tool_p.tolist()
    )
    np.testing.assert_allclose(np.array(rot).reshape(3, 3), r, atol=1e-12)
    np.testing.assert_allclose(pos, p, atol=1e-12)
    np.testing.assert_allclose(twist, jac @ qd, atol=1e-12)
    np.testing.assert_allclose(matrix_to_quat_wxyz_tuple(rot), matrix_to_quat_wxyz(r), atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(
        lambda v: sum(x * x for x in v) > 0.01
    )
)
def test_quaternion_round_trip(v: list[float]) -> None:
    q = np.array(v) / np.linalg.norm(v)
    back = matrix_to_quat_wxyz(quat_wxyz_to_matrix(q))
    assert abs(float(np.dot(back, q))) == pytest.approx(1.0, abs=1e-9)  # q and -q are one rotation
    assert back[0] >= 0.0


def test_product_of_exponentials_convention() -> None:
    # A revolute joint about z through (0.5, 0, 0): the tip at (1, 0, 0) swings around it.
    hp = HPChain(np.array([[0, 0, 1.0]]), np.array([[0.5, 0, 0], [0.5, 0, 0]]))
    _, p = hp.fk(np.array([np.pi / 2]))
    np.testing.assert_allclose(p, [0.5, 0.5, 0], atol=1e-12)
    prismatic = HPChain(np.array([[1.0, 0, 0]]), np.zeros((2, 3)), prismatic=[True])
    _, p = prismatic.fk(np.array([0.2]))
    np.testing.assert_allclose(p, [0.2, 0, 0], atol=1e-12)


def test_fixture_fk_with_tool() -> None:
    robot = SimRobot(load_robot_info(RRP))
    (hp,) = robot._hp
    r, p = hp.fk(np.array([0.0, 0.0, 0.1]))
    np.testing.assert_allclose(p, [0.6, 0, 0.5], atol=1e-12)
    tool = tool_transform(
        robot.robot_info.chains[0].current_tool
        or __import__("robotspec.driver.robot_info", fromlist=["ToolInfo"]).ToolInfo.model_validate(
            {"tcp": {"translation": {"x": 0, "y": 0, "z": 0.2}}}
        )
    )
    assert tool is not None
    _, p = hp.fk(np.zeros(3), *tool)
    np.testing.assert_allclose(p, [0.5, 0, 0.7], atol=1e-12)
    assert Pose().orientation.w == 1.0


@pytest.mark.skipif(not shared_robotinfo_files(), reason="../shared/robotinfo is absent")
def test_every_shared_chain_has_consistent_fast_path() -> None:
    for path in shared_robotinfo_files():
        for hp in _chains(path):
            q = np.linspace(-0.5, 0.5, hp.n)
            r, p = hp.fk(q)
            rot, pos, _ = hp.tcp_state(q.tolist(), None)
            np.testing.assert_allclose(pos, p, atol=1e-12)
