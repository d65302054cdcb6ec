"""Shared fixtures: where the real robot files are, and loaded worlds of the main robots."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

settings.register_profile(
    "ci",
    derandomize=True,
    deadline=None,
    max_examples=60,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile("explore", deadline=None, max_examples=500)
# Deterministic by default (the suite must not flake); HYPOTHESIS_PROFILE=explore searches wider.
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

#: The steering repo's shared folder sits beside the project checkout (absent in a user's clone).
SHARED = Path(__file__).resolve().parents[2] / "shared"
DATA = Path(__file__).resolve().parent / "data"


def shared_path(*parts: str) -> Path:
    """A path under ../shared, or skip the test with a reason when it is absent."""
    p = SHARED.joinpath(*parts)
    if not p.exists():
        pytest.skip(f"needs {p} (the shared robot files beside the checkout), which is absent")
    return p


def erd_robots() -> Path:
    """example-robot-data's robots folder, or skip when the package is not installed."""
    import importlib.metadata as md

    try:
        dist = md.distribution("example-robot-data")
    except md.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed (pip install robotspec[data])")
    share = Path(str(dist.locate_file("cmeel.prefix/share/example-robot-data")))
    if not share.is_dir():
        pytest.skip(f"example-robot-data's share folder {share} is missing")
    return share / "robots"


def all_pairs_checker(name: str) -> object:
    """A collision checker of every pair of a shipped robot's bodies with geometry, no rules.

    What the collision matrix checks; the tests that compare checkers (workers, mesh proofs) use
    it. Skips when example-robot-data is absent.
    """
    from robotspec.collision import CollisionRules, SelfCollisionChecker
    from robotspec.compiler import compile_robot

    erd_robots()
    robot = compile_robot(name)
    names = tuple(b.name for b in robot.bodies_with_collisions)
    pairs = [(a, b) for i, a in enumerate(names) for b in names[i + 1 :]]
    return SelfCollisionChecker(robot.world, CollisionRules(bodies=names), pairs=pairs)


#: YAML is read with libyaml where PyYAML has it, else in Python: tests of the reader run both.
PARSERS = ["libyaml", "python"]


@pytest.fixture(params=PARSERS)
def parser(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    """Which YAML parser robotspec's reader uses in this test (both, one after the other)."""
    import yaml

    from robotspec.files import yamlio

    if request.param == "libyaml":
        if not hasattr(yaml, "CSafeLoader"):
            pytest.skip("this PyYAML was built without libyaml")
    else:
        monkeypatch.setattr(yamlio, "_SafeComposer", yamlio._PySafeComposer)
    return str(request.param)
