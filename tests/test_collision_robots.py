"""Self-collision of the PR2 and the HSR-B; agreement with pinocchio + coal on the same pairs."""

from __future__ import annotations

from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robotspec.collision import (
    CollisionRules,
    SelfCollisionChecker,
    random_configurations,
    state_configuration,
)
from robotspec.description.urdf import load_urdf
from robotspec.errors import CollisionError, NotFoundError
from robotspec.model.world import World
from robotspec.semantic import AbstractRobot
from tests.conftest import erd_robots, shared_path
from tests.pin_oracle import PinOracle

pin = pytest.importorskip("pinocchio")

#: The right arm swung across and down into the base.
PR2_FOLDED = {"r_shoulder_pan_joint": 0.7, "r_shoulder_lift_joint": 1.2, "r_elbow_flex_joint": -0.2}
#: The right gripper folded across the chest into the left shoulder.
PR2_ACROSS = {
    "r_shoulder_pan_joint": 0.5,
    "r_shoulder_lift_joint": 1.0,
    "r_elbow_flex_joint": -2.0,
    "r_upper_arm_roll_joint": -1.5,
}
#: HSR-B's arm up, rolled back and the wrist bent down into the torso.
HSRB_FOLDED = {
    "arm_lift_joint": 0.0,
    "arm_flex_joint": 0.0,
    "arm_roll_joint": 3.14,
    "wrist_flex_joint": -1.9,
}


@cache
def _pr2() -> AbstractRobot:
    from robotspec.compiler import check_spec

    erd_robots()
    robot = check_spec("pr2").robot
    assert robot is not None
    return robot


@cache
def _hsrb(root: str) -> AbstractRobot:
    from robotspec.compiler import check_spec

    robot = check_spec("hsrb", package_paths=[root]).robot
    assert robot is not None
    return robot


@pytest.fixture(scope="module")
def pr2() -> AbstractRobot:
    return _pr2()


@pytest.fixture(scope="module")
def pr2_checker(pr2: AbstractRobot) -> SelfCollisionChecker:
    return SelfCollisionChecker.from_robot(pr2)


@pytest.fixture(scope="module")
def hsrb() -> AbstractRobot:
    return _hsrb(str(shared_path("robots", "hsrb")))


def test_pr2_rules_come_from_srdf_and_spec(pr2: AbstractRobot) -> None:
    rules = CollisionRules.from_robot(pr2)
    assert rules.buffer_distance == pytest.approx(0.05)
    assert rules.why_disabled("l_shoulder_pan_link", "l_shoulder_lift_link") == "Adjacent"
    assert rules.why_disabled("base_link", "double_stereo_link") == "Never"
    assert len(rules.active_pairs()) == 239


def test_pr2_park_and_default_are_free_folded_arms_are_not(
    pr2_checker: SelfCollisionChecker,
) -> None:
    assert not pr2_checker.in_collision(pr2_checker.configuration())
    park = pr2_checker.configuration(["park"])
    assert not pr2_checker.in_collision(park)
    assert pr2_checker.buffer_violations(park) == ()
    folded = pr2_checker.configuration(["park"], PR2_FOLDED)
    assert ("base_link", "r_forearm_link") in pr2_checker.colliding_pairs(folded)
    across = pr2_checker.configuration([], PR2_ACROSS)
    assert ("r_gripper_palm_link", "l_shoulder_pan_link") in pr2_checker.colliding_pairs(across)
    assert pr2_checker.in_collision(across)


def test_named_states(pr2: AbstractRobot) -> None:
    q = state_configuration(pr2, ["left_arm.park"])
    j = pr2.world.get_degree_of_freedom_by_name("l_elbow_flex_joint").index
    r = pr2.world.get_degree_of_freedom_by_name("r_elbow_flex_joint").index
    assert q[j] == pytest.approx(-2.12) and q[r] == 0.0
    both = state_configuration(pr2, ["park"])
    assert both[j] == both[r] == pytest.approx(-2.12)
    with pytest.raises(NotFoundError) as err:
        state_configuration(pr2, ["parc"])
    assert "park" in err.value.suggestions
    with pytest.raises(CollisionError, match="mimics"):
        state_configuration(pr2, values={"l_gripper_r_finger_joint": 0.1})


def test_hsrb_park_is_free_folded_arm_is_not(hsrb: AbstractRobot) -> None:
    checker = SelfCollisionChecker.from_robot(hsrb)
    assert not checker.in_collision(checker.configuration())
    assert not checker.in_collision(checker.configuration(["park"]))
    folded = checker.configuration([], HSRB_FOLDED)
    assert ("torso_lift_link", "hand_palm_link") in checker.colliding_pairs(folded)


# ------------------------------------------------------------------------- pinocchio oracle
class PinCollisions:
    """pinocchio's model and GeometryModel of the same URDF, with the checker's pairs added."""

    def __init__(self, urdf: Path, package_dirs: list[str], world: World, pairs: Any) -> None:
        self.model, self.gmodel, _ = pin.buildModelsFromUrdf(str(urdf), package_dirs=package_dirs)
        self.data = self.model.createData()
        self.oracle = PinOracle(str(urdf), world)
        link = [self.model.frames[g.parentFrame].name for g in self.gmodel.geometryObjects]
        index = {frozenset(p): k for k, p in enumerate(pairs)}
        self.owner: list[int] = []
        for i in range(len(link)):
            for j in range(i + 1, len(link)):
                k = index.get(frozenset((link[i], link[j])))
                if k is not None:
                    self.gmodel.addCollisionPair(pin.CollisionPair(i, j))
                    self.owner.append(k)
        self.gdata = pin.GeometryData(self.gmodel)
        self.npairs = len(pairs)

    def collisions(self, q: np.ndarray) -> np.ndarray:
        pin.computeCollisions(self.model, self.data, self.gmodel, self.gdata, self.oracle.q(q))
        out = np.zeros(self.npairs, dtype=bool)
        for k, res in zip(self.owner, self.gdata.collisionResults, strict=True):
            out[k] |= res.isCollision()
        return out

    def distances(self, q: np.ndarray) -> np.ndarray:
        pin.computeDistances(self.model, self.data, self.gmodel, self.gdata, self.oracle.q(q))
        out = np.full(self.npairs, np.inf)
        for k, res in zip(self.owner, self.gdata.distanceResults, strict=True):
            out[k] = min(out[k], res.min_distance)
        return out


@pytest.fixture(scope="module")
def pr2_pair(pr2: AbstractRobot) -> tuple[SelfCollisionChecker, PinCollisions]:
    """Our checker and pinocchio's, both on the bare URDF world (no virtual joint)."""
    urdf = erd_robots() / "pr2_description/urdf/pr2.urdf"
    world = load_urdf(urdf)
    rules = CollisionRules.for_world(world, srdf=pr2.srdf)
    checker = SelfCollisionChecker(world, rules)
    oracle = PinCollisions(urdf, [str(erd_robots().parents[1])], world, checker.active_pairs)
    return checker, oracle


def test_pr2_collisions_agree_with_pinocchio(
    pr2_pair: tuple[SelfCollisionChecker, PinCollisions],
) -> None:
    checker, oracle = pr2_pair
    qs = random_configurations(checker.world, 300, seed=7)
    ours = checker.collisions_batch(qs)
    theirs = np.array([oracle.collisions(q) for q in qs])
    assert ours.sum() > 50  # the sample does exercise collisions
    np.testing.assert_array_equal(ours, theirs)


def test_pr2_distances_agree_with_pinocchio(
    pr2_pair: tuple[SelfCollisionChecker, PinCollisions],
) -> None:
    checker, oracle = pr2_pair
    qs = random_configurations(checker.world, 3, seed=11)
    for q in qs:
        ours = checker.distances(q)
        theirs = oracle.distances(q)
        got = np.array([d.distance for d in ours])
        np.testing.assert_allclose(got, theirs, atol=1e-6, rtol=0)
        for d in ours[:20]:
            if d.distance > 0:  # closest points are as far apart as the distance says
                gap = np.linalg.norm(np.subtract(d.point1, d.point2))
                assert gap == pytest.approx(d.distance, abs=1e-6)


@settings(max_examples=15)
@given(st.integers(0, 2**31 - 1))
def test_pair_order_and_batching_do_not_change_answers(seed: int) -> None:
    checker = SelfCollisionChecker.from_robot(_pr2())
    flipped = SelfCollisionChecker(
        checker.world, checker.rules, pairs=[(b, a) for a, b in reversed(checker.active_pairs)]
    )
    qs = random_configurations(checker.world, 4, seed)
    batch = checker.collisions_batch(qs)
    other = flipped.collisions_batch(qs)
    order = [flipped.pair_index(a, b) for a, b in checker.active_pairs]
    np.testing.assert_array_equal(batch, other[:, order])
    for q, row in zip(qs, batch, strict=True):
        assert set(checker.colliding_pairs(q)) == {
            p for p, hit in zip(checker.active_pairs, row, strict=True) if hit
        }
        assert checker.in_collision(q) == bool(row.any())


def test_unchecked_pair_is_an_error(pr2_checker: SelfCollisionChecker) -> None:
    with pytest.raises(CollisionError, match="Adjacent"):
        pr2_checker.pair_index("l_shoulder_pan_link", "l_shoulder_lift_link")
