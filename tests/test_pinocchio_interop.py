"""robot.to_pinocchio() and robotspec's own queries against pinocchio, on every shipped robot.

pinocchio is the oracle here: FK of every body, one frame, each chain's tip pose and Jacobian,
and self-collision (any hit, all pairs, distances) computed by pinocchio on the exported model
must equal what robotspec's public API answers.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from robotspec.collision import SelfCollisionChecker, random_configurations
from robotspec.collision.rules import pair_key
from robotspec.errors import KinematicsError
from robotspec.model.kinematics import Kinematics
from robotspec.model.pinocchio import PinocchioRobot
from robotspec.semantic import AbstractRobot
from tests.conftest import erd_robots, shared_path

pin = pytest.importorskip("pinocchio")

ROBOTS = ("pr2", "hsrb", "tiago", "panda", "ur5", "b1_ur5_allegro", "dual_panda")


@cache
def _compiled(name: str) -> tuple[AbstractRobot, PinocchioRobot]:
    from robotspec.compiler import compile_robot

    paths = [shared_path("robots", "hsrb")] if name == "hsrb" else []
    robot = compile_robot(name, package_paths=paths)
    return robot, robot.to_pinocchio()


@pytest.fixture(params=ROBOTS)
def compiled(request: pytest.FixtureRequest) -> tuple[AbstractRobot, PinocchioRobot]:
    erd_robots()
    if request.param == "hsrb":
        shared_path("robots", "hsrb")
    return _compiled(request.param)


def _samples(robot: AbstractRobot, n: int, seed: int) -> np.ndarray:
    qs = random_configurations(robot.world, n, seed=seed)
    # Base DOFs are unlimited, so the sampler leaves them at 0: move them too.
    rng = np.random.default_rng(seed)
    for d in robot.world.degrees_of_freedom:
        if not d.is_bounded:
            qs[:, d.index] = rng.uniform(-2.0, 2.0, n)
    return qs


def test_fk_of_every_body_and_one_frame(compiled: tuple[AbstractRobot, PinocchioRobot]) -> None:
    robot, pr = compiled
    kin = Kinematics(robot.world)
    data = pr.model.createData()
    for q in _samples(robot, 5, seed=1):
        pin.framesForwardKinematics(pr.model, data, pr.configuration(q))
        ours = kin.forward(q)
        for body in robot.world.bodies:
            theirs = data.oMf[pr.frames[body.name]].homogeneous
            np.testing.assert_allclose(ours[body.index], theirs, atol=1e-9, err_msg=body.name)
            np.testing.assert_allclose(kin.pose(q, body.name), theirs, atol=1e-9)


def test_semantic_frame_ids(compiled: tuple[AbstractRobot, PinocchioRobot]) -> None:
    robot, pr = compiled
    names = {f.name for f in pr.model.frames}
    assert {b.name for b in robot.world.bodies} <= names
    assert set(pr.chain_tips) == {c.name for c in robot.all_chains}
    for c in robot.all_chains:
        assert pr.model.frames[pr.chain_tips[c.name]].name == c.tip.name
    for m in robot.manipulators:
        assert pr.model.frames[pr.tool_frames[m.name]].name == m.tool_frame.name
    assert set(pr.cameras) == {s.name for s in robot.cameras}
    assert pr.model.nq == len(robot.world.degrees_of_freedom)


def test_chain_tip_and_jacobian(compiled: tuple[AbstractRobot, PinocchioRobot]) -> None:
    robot, pr = compiled
    kin = Kinematics(robot.world)
    data = pr.model.createData()
    for q in _samples(robot, 3, seed=2):
        qp = pr.configuration(q)
        pin.computeJointJacobians(pr.model, data, qp)
        pin.updateFramePlacements(pr.model, data)
        for c in robot.all_chains:
            chain = kin.chain(c.root, c.tip)
            root_pose = data.oMf[pr.frames[c.root.name]].homogeneous
            tip_pose = data.oMf[pr.chain_tips[c.name]].homogeneous
            np.testing.assert_allclose(
                chain.fk(q), np.linalg.solve(root_pose, tip_pose), atol=1e-9, err_msg=c.name
            )
            jac = pin.getFrameJacobian(
                pr.model, data, pr.chain_tips[c.name], pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
            )
            # pinocchio: world-aligned axes, velocity columns in its configuration order.
            cols = [pr.q_index.index(d) for d in chain.dof_indices]
            r = root_pose[:3, :3]
            expected = np.vstack([r.T @ jac[:3, cols], r.T @ jac[3:, cols]])
            leaders_outside = any(
                conn.mimic is not None
                and robot.world.get_connection_by_name(conn.mimic.leader) not in chain.connections
                for conn in chain.connections
            )
            if leaders_outside:  # pinocchio's leader column also moves the chain's root
                continue
            np.testing.assert_allclose(chain.jacobian(q), expected, atol=1e-9, err_msg=c.name)


def test_collision_model_has_the_checked_pairs(
    compiled: tuple[AbstractRobot, PinocchioRobot],
) -> None:
    robot, pr = compiled
    checker = SelfCollisionChecker.from_robot(robot)
    assert set(pr.pair_bodies) == {pair_key(a, b) for a, b in checker.active_pairs}
    assert len(pr.pair_bodies) == len(pr.collision_model.collisionPairs)
    for a, b in pr.pair_bodies:
        assert robot.world.has_body(a) and robot.world.has_body(b)
        assert not checker.rules.why_disabled(a, b)


def test_self_collision_any_all_and_distances(
    compiled: tuple[AbstractRobot, PinocchioRobot],
) -> None:
    robot, pr = compiled
    checker = SelfCollisionChecker.from_robot(robot)
    if not checker.active_pairs:
        pytest.skip(f"{robot.name} has no checked pair")
    data = pr.model.createData()
    gdata = pin.GeometryData(pr.collision_model)
    index = {p: k for k, p in enumerate(checker.active_pairs)}
    key = {tuple(sorted(p)): p for p in checker.active_pairs}
    qs = _samples(robot, 12, seed=3)
    qs[0] = robot.world.configuration()
    some_hit = False
    for q in qs:
        qp = pr.configuration(q)
        any_hit = pin.computeCollisions(pr.model, data, pr.collision_model, gdata, qp, True)
        assert checker.in_collision(q) == any_hit
        pin.computeCollisions(pr.model, data, pr.collision_model, gdata, qp, False)
        theirs = {
            key[tuple(sorted(b))]
            for b, res in zip(pr.pair_bodies, gdata.collisionResults, strict=True)
            if res.isCollision()
        }
        assert set(checker.colliding_pairs(q)) == theirs
        some_hit |= bool(theirs)
    # Distances: the minimum over each body pair's geometry pairs.
    q = qs[1]
    pin.computeDistances(pr.model, data, pr.collision_model, gdata, pr.configuration(q))
    theirs_d = np.full(len(index), np.inf)
    for b, res in zip(pr.pair_bodies, gdata.distanceResults, strict=True):
        k = index[key[tuple(sorted(b))]]
        theirs_d[k] = min(theirs_d[k], res.min_distance)
    ours_d = np.array([d.distance for d in checker.distances(q)])
    # GJK stops within its tolerance (1e-6), which a different float path can land on.
    np.testing.assert_allclose(ours_d, theirs_d, atol=1e-5)


def test_configuration_shape_is_checked() -> None:
    erd_robots()
    _, pr = _compiled("ur5")
    with pytest.raises(KinematicsError, match="shape"):
        pr.configuration(np.zeros(3))


def test_floating_and_planar_bases_match() -> None:
    """A planar drive (the PR2's) and a floating one on the same tree agree with pinocchio."""
    erd_robots()
    from robotspec.model.entities import ConnectionType

    robot, _ = _compiled("ur5")
    world = robot.world
    root = world.bodies[0].name
    for kind, axis in (
        (ConnectionType.FLOATING, (0.0, 0.0, 1.0)),
        (ConnectionType.PLANAR, (0.0, 0.6, 0.8)),
    ):
        moved = world.with_base_connection("base_joint", "odom", kind, axis=axis)
        from robotspec.model.pinocchio import world_to_pinocchio

        model, frames, order = world_to_pinocchio(moved)
        data = model.createData()
        kin = Kinematics(moved)
        rng = np.random.default_rng(4)
        for _ in range(3):
            q = rng.uniform(-1.5, 1.5, len(moved.degrees_of_freedom))
            pin.framesForwardKinematics(model, data, q[list(order)])
            ours = kin.forward(q)
            for body in moved.bodies:
                theirs = data.oMf[frames[body.name]].homogeneous
                np.testing.assert_allclose(ours[body.index], theirs, atol=1e-9, err_msg=root)


def test_robot_level_queries() -> None:
    """The robot's own entry points: cached kinematics, chain kinematics by name."""
    erd_robots()
    robot, pr = _compiled("pr2")
    assert robot.kinematics is robot.kinematics
    chain = robot.chain_kinematics("right_arm")
    q = _samples(robot, 1, seed=5)[0]
    data = pr.model.createData()
    pin.framesForwardKinematics(pr.model, data, pr.configuration(q))
    tip = data.oMf[pr.chain_tips["right_arm"]].homogeneous
    root = data.oMf[pr.frames[robot.get_chain("right_arm").root.name]].homogeneous
    np.testing.assert_allclose(chain.fk(q), np.linalg.solve(root, tip), atol=1e-9)
