"""The robot zoo: every robot of example-robot-data loads, matches pinocchio, drafts, validates.

One row per robot is computed once (``_row``) and shared by the tests of that robot and by the
page's staleness test, so the whole zoo costs one load, one draft and one validation per robot.
"""

from __future__ import annotations

import functools
import tempfile
from pathlib import Path

import numpy as np
import pytest

from robotspec.description.load import load_description
from tools.zoo import (
    COMMAND,
    PAGE,
    SHIPPED_COMPARED,
    ZooEntry,
    ZooRow,
    erd_robots_folder,
    zoo_entries,
    zoo_page,
    zoo_row,
)

from .pin_oracle import PinOracle

ROBOTS = erd_robots_folder()
ENTRIES = zoo_entries(ROBOTS) if ROBOTS is not None else []
NAMES = [e.name for e in ENTRIES]

#: Robots whose drafts do not validate, and why (the first problem, as the page shows it): files
#: that do not load. A robot here that starts to validate fails the test, to be removed here.
KNOWN_INVALID = {
    # Broken files: a <robot> without links; mimic joints that name joints the URDF lacks.
    "ur_description/ur3": "does not load: ur3.urdf: 2 problems",
    "alex_description/alex_psyonic_hands": "does not load: alex_psyonic_hands.urdf: 8 problems",
}

_TMP = Path(tempfile.mkdtemp(prefix="robotspec-zoo-test-"))


@functools.cache
def _row(name: str) -> ZooRow:
    entry = next(e for e in ENTRIES if e.name == name)
    return zoo_row(entry, _TMP)


def _entry(name: str) -> ZooEntry:
    return next(e for e in ENTRIES if e.name == name)


pytestmark = pytest.mark.skipif(ROBOTS is None, reason="example-robot-data is not installed")


@pytest.mark.parametrize("name", NAMES)
def test_draft_validates_as_written(name: str) -> None:
    row = _row(name)
    if name in KNOWN_INVALID:
        assert not row.valid, f"{name} validates now: remove it from KNOWN_INVALID"
        assert KNOWN_INVALID[name] in row.problem, row.problem
        return
    assert row.valid, f"{name}: {row.errors} errors, first: {row.problem}\n{row.draft}"


@pytest.mark.parametrize("name", NAMES)
def test_draft_decisions_hold(name: str) -> None:
    # Never two manipulators on one tool frame; every tool frame in its chain's own subtree.
    row = _row(name)
    if not row.bodies:
        pytest.skip("the files do not load")
    import yaml

    data = yaml.safe_load(row.draft)
    manips = data.get("manipulators") or {}
    tools = [m["tool_frame"] for m in manips.values()]
    assert len(tools) == len(set(tools))
    chains = data.get("chains") or {}
    carriers = [c["manipulator"] for c in chains.values() if "manipulator" in c]
    assert len(carriers) == len(set(carriers))
    # Every chain that is drafted comes with its reason.
    for c in chains:
        line = next(li for li in row.draft.splitlines() if li.startswith(f"  {c}:"))
        assert "# from" in line


@pytest.mark.parametrize("name", NAMES)
def test_world_matches_pinocchio(name: str) -> None:
    entry = _entry(name)
    if not _row(name).bodies:
        pytest.skip("the files do not load")
    world = load_description(entry.urdf, meshes="keep").world
    oracle = PinOracle(str(entry.urdf), world)
    from robotspec.model.kinematics import Kinematics

    kin = Kinematics(world)
    rng = np.random.default_rng(7)
    for _ in range(3):
        q = np.array(
            [
                rng.uniform(d.lower, d.upper) if d.is_bounded else rng.uniform(-np.pi, np.pi)
                for d in world.degrees_of_freedom
            ]
        )
        ours = kin.forward(q)
        theirs = oracle.poses(q)
        for b in world.bodies:
            np.testing.assert_allclose(ours[b.index], theirs[b.name], atol=1e-9, err_msg=b.name)


def test_shipped_robots_are_compared() -> None:
    for name in SHIPPED_COMPARED.values():
        row = _row(name)
        assert row.compared is not None
        got, of, missed = row.compared
        assert of > 0 and got + len(missed) == of


def test_zoo_page_is_current() -> None:
    text = zoo_page([_row(n) for n in NAMES])
    assert PAGE.is_file() and PAGE.read_text(encoding="utf-8") == text, (
        f"{PAGE} is stale: run `{COMMAND}`"
    )
