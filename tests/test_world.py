"""The world model, the single source of truth: its tree queries agree with each other.

Properties checked on every URDF of example-robot-data that loads (robots nobody wrote a spec
for), and chain queries checked as properties with hypothesis on the PR2.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from robotspec.description.urdf import load_urdf
from robotspec.errors import KinematicsError, RobotSpecError
from robotspec.model.world import World
from tests.conftest import erd_robots

ROBOTS = [
    "pr2_description/urdf/pr2.urdf",
    "tiago_description/robots/tiago.urdf",
    "panda_description/urdf/panda.urdf",
    "ur_description/urdf/ur5_robot.urdf",
    "baxter_description/urdf/baxter.urdf",
    "talos_data/robots/talos_full_v2.urdf",
]


def _load(rel: str) -> World:
    path = erd_robots() / rel
    if not path.is_file():
        pytest.skip(f"{rel} is not in this example-robot-data")
    try:
        return load_urdf(path, meshes="keep")
    except RobotSpecError as exc:  # pragma: no cover - reported, not hidden
        pytest.skip(f"{rel} does not load: {exc}")


@pytest.fixture(scope="module")
def pr2() -> World:
    return _load(ROBOTS[0])


@pytest.mark.parametrize("rel", ROBOTS, ids=[r.split("/")[0] for r in ROBOTS])
def test_tree_queries_agree(rel: str) -> None:
    world = _load(rel)
    bodies = world.bodies
    assert [b.index for b in bodies] == list(range(len(bodies)))
    assert world.parent_connection(world.root) is None
    assert world.depth(world.root) == 0
    children_seen = 0
    for b in bodies:
        kids = world.child_bodies(b)
        children_seen += len(kids)
        for k in kids:
            parent = world.parent_connection(k)
            assert parent is not None and parent.parent == b.index and parent.child == k.index
            assert world.depth(k) == world.depth(b) + 1
        # the ancestors end at the root and are exactly depth + 1 bodies
        above = world.ancestors(b)
        assert above[0] == b and above[-1] == world.root and len(above) == world.depth(b) + 1
        # the subtree of the root holds every body once; a subtree starts with its own top
        assert world.subtree(b)[0] == b
    assert children_seen == len(bodies) - 1  # a tree: every body but the root has one parent
    assert sorted(x.index for x in world.subtree(world.root)) == list(range(len(bodies)))
    # bodies in topological order (pyroki's rule): a connection's parent comes before its child
    assert all(c.parent < c.child for c in world.connections)


@pytest.mark.parametrize("rel", ROBOTS, ids=[r.split("/")[0] for r in ROBOTS])
def test_default_configuration_is_inside_the_limits(rel: str) -> None:
    world = _load(rel)
    q = world.configuration()
    lower = np.array([d.lower for d in world.degrees_of_freedom])
    upper = np.array([d.upper for d in world.degrees_of_freedom])
    assert q.shape == (len(world.degrees_of_freedom),)
    assert np.all(lower <= q) and np.all(q <= upper)


@given(data=st.data())
def test_chain_between_an_ancestor_and_a_body(pr2: World, data: st.DataObject) -> None:
    tip = data.draw(st.sampled_from(pr2.bodies))
    above = pr2.ancestors(tip)
    root = data.draw(st.sampled_from(above))
    chain = pr2.compute_chain_of_kinematic_structure_entities(root, tip)
    assert chain[0] == root and chain[-1] == tip
    connections = pr2.compute_chain_of_connections(root, tip)
    assert len(connections) == len(chain) - 1
    assert all(
        c.parent == a.index and c.child == b.index
        for c, a, b in zip(connections, chain[:-1], chain[1:], strict=True)
    )


@given(data=st.data())
def test_split_chain_meets_at_the_common_ancestor(pr2: World, data: st.DataObject) -> None:
    a = data.draw(st.sampled_from(pr2.bodies))
    b = data.draw(st.sampled_from(pr2.bodies))
    up, (common,), down = pr2.compute_split_chain_of_kinematic_structure_entities(a, b)
    assert pr2.is_ancestor(common, a) and pr2.is_ancestor(common, b)
    assert (up[0] if up else common) == a and (down[-1] if down else common) == b
    # no deeper common ancestor: the two paths below it share no body
    assert not {x.index for x in up} & {x.index for x in down}
    if not pr2.is_ancestor(b, a) and not pr2.is_ancestor(a, b):
        with pytest.raises(KinematicsError, match="different branches"):
            pr2.compute_chain_of_kinematic_structure_entities(a, b)


def test_a_swapped_chain_says_to_swap(pr2: World) -> None:
    with pytest.raises(
        KinematicsError, match="'r_wrist_roll_link' is above 'r_gripper_palm_link'; swap"
    ):
        pr2.compute_chain_of_kinematic_structure_entities(
            "r_gripper_palm_link", "r_wrist_roll_link"
        )


def test_urdf_files_listed_exist() -> None:
    robots = erd_robots()
    missing = [r for r in ROBOTS if not (robots / r).is_file()]
    assert len(missing) < len(ROBOTS), f"none of {ROBOTS} in {robots}"
    assert isinstance(robots, Path)
