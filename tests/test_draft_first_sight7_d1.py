"""Drafts of shapes round 7 of the blind corpus asked about (issue 30), on small layouts.

Each layout is built here from boxes (never a copy of a robot's files) and named by numbers
only, so what the drafter finds comes from the tree's shape, not from a maker's names.
"""

from __future__ import annotations

from pathlib import Path

from tests.test_draft_blind import _draft, _joint, _link


def _quadruped(foot_drop: float) -> list[str]:
    """A trunk 0.45 m up carrying four 3-joint runs (about x, y, y) named by numbers only.

    Each run's last link ('c*', the knee's) carries a fixed frame 'e*' ``foot_drop`` below it.
    """
    parts = [_link("t0", size=0.3)]
    corners = ("0.2 0.1 0", "0.2 -0.1 0", "-0.2 0.1 0", "-0.2 -0.1 0")
    for n, at in enumerate(corners, 1):
        parts += [
            _link(f"a{n}", size=0.03),
            _joint(f"q{n}1", "t0", f"a{n}", xyz=at, axis="1 0 0"),
            _link(f"b{n}", size=0.03),
            _joint(f"q{n}2", f"a{n}", f"b{n}", xyz="0 0 0"),
            _link(f"c{n}", size=0.03),
            _joint(f"q{n}3", f"b{n}", f"c{n}", xyz="0 0 -0.2"),
            _link(f"e{n}", size=0.02),
            _joint(f"f{n}", f"c{n}", f"e{n}", "fixed", xyz=f"0 0 {-foot_drop}"),
        ]
    return parts


def test_runs_whose_fixed_ends_stand_on_the_ground_are_legs_whatever_their_names(
    tmp_path: Path,
) -> None:
    # A quadruped named by numbers (the shape of HyQ's, ANYmal's, Mini Cheetah's legs): each
    # knee link sits 25 cm above the ground, its fixed foot frame on it. Where the run ends is
    # the lowest frame it carries, so the four runs are legs ending at their feet.
    d = _draft(tmp_path, "numbered_quadruped", _quadruped(0.25))
    assert sorted(c.role for c in d.chains) == ["leg"] * 4
    assert sorted(c.tip for c in d.chains) == ["e1", "e2", "e3", "e4"]
    assert not d.manipulators
    assert d.drive is not None and d.drive.type == "floating"


def test_runs_hanging_above_the_ground_stay_arms(tmp_path: Path) -> None:
    # The same runs on a trunk whose lowest part is a box far below their ends: nothing stands
    # on them, so they are not legs.
    parts = [
        *_quadruped(0.02),
        _link("s0", size=0.05),
        _joint("s0_fix", "t0", "s0", "fixed", xyz="0 0 -0.9"),
    ]
    d = _draft(tmp_path, "hanging_runs", parts)
    assert all(c.role != "leg" for c in d.chains)
