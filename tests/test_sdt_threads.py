"""``to_sdt`` from several threads at once (issue 32, item 5).

SDT is not thread-safe (its worlds share krrood's global symbol graph): four threads building
robots at once failed about three times in eight, SDT's own ``from_world`` too. ``to_sdt``
serialises what SDT cannot share; each thread gets a whole robot in a world of its own. No
timing is asserted: a loaded machine makes this slower, never failed.
"""

from __future__ import annotations

import warnings
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import pytest

from tests.conftest import erd_robots
from tests.sdt_support import sdt  # noqa: F401

pytestmark = pytest.mark.usefixtures("sdt")

THREADS = 4
ROUNDS = 2


def _build(name: str) -> Any:
    from robotspec.interop.sdt import to_sdt
    from robotspec.robots import load

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load(name)
        return robot, to_sdt(robot)


def test_four_threads_build_whole_robots_in_worlds_of_their_own() -> None:
    from semantic_digital_twin.robots.pr2 import PR2
    from semantic_digital_twin.robots.tiago import Tiago

    erd_robots()
    names = ["pr2", "tiago"] * (THREADS * ROUNDS // 2)
    with ThreadPoolExecutor(THREADS) as pool:
        built = list(pool.map(_build, names))
    worlds = {id(sdt_robot._world) for _, sdt_robot in built}
    assert len(worlds) == len(names)  # a world each
    for name, (robot, sdt_robot) in zip(names, built, strict=True):
        assert type(sdt_robot) is (PR2 if name == "pr2" else Tiago)
        world = sdt_robot._world
        assert {b.name.name for b in world.bodies} == set(robot.world.body_names)
        assert len(sdt_robot._robot_parts) == (12 if name == "pr2" else 6)
        states = [s for p in sdt_robot._robot_parts for s in p.joint_states]
        assert all(s._robot is sdt_robot for s in states)
    # Every part class is one class per part, whichever thread made it first.
    pr2 = [r for n, (_, r) in zip(names, built, strict=True) if n == "pr2"]
    kinds = [sorted(type(p).__name__ for p in r._robot_parts) for r in pr2]
    assert all(k == kinds[0] for k in kinds)
