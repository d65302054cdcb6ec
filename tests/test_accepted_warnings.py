"""Warnings a correct spec can silence: by saying what a chain is, or accepting one."""

from __future__ import annotations

from pathlib import Path

import pytest

from robotspec.compiler import check_spec
from robotspec.errors import RobotSpecError

from .conftest import erd_robots

SPARE = "  spare: {root: torso_lift_link, tip: l_elbow_flex_link}\n"


@pytest.fixture(autouse=True)
def _needs_erd() -> None:
    erd_robots()


def warnings_of(tmp_path: Path, text: str, *, strict: bool = False) -> list[str]:
    spec = tmp_path / "robot.yaml"
    spec.write_text("robotspec: 1\nname: W\nextends: pr2\n" + text)
    return [w.message for w in check_spec(spec, strict=strict).warnings]


def test_a_leg_or_a_lift_is_no_arm_without_a_tool(tmp_path: Path) -> None:
    chains = "chains:\n  lift: {kind: chain, root: torso_lift_link, tip: l_shoulder_pan_link}\n"
    chains += "  leg: {kind: leg, root: torso_lift_link, tip: r_shoulder_pan_link}\n"
    assert warnings_of(tmp_path, chains + SPARE) == [
        "chains.spare: chain 'spare' has neither a manipulator nor a sensor (not an arm? say "
        "'kind: leg' or 'kind: chain')"
    ]


def test_an_accepted_warning_is_gone_even_in_strict_mode(tmp_path: Path) -> None:
    accept = (
        "accept_warnings:\n"
        "  - at: chains.spare\n    says: neither a manipulator nor a sensor\n"
        "    because: the elbow carries a strain gauge we do not model\n"
    )
    assert warnings_of(tmp_path, "chains:\n" + SPARE + accept, strict=True) == []


def test_an_acceptance_matches_its_place_and_its_words_only(tmp_path: Path) -> None:
    accept = (
        "accept_warnings:\n"
        "  - {at: chains.spar, says: neither, because: typo in the place}\n"
        "  - {at: chains.spare, says: cannot move, because: other words}\n"
    )
    found = warnings_of(tmp_path, "chains:\n" + SPARE + accept)
    assert found[0].startswith("chains.spare: chain 'spare' has neither")
    assert found[1:] == [
        "accept_warnings[0]: no warning at 'chains.spar' says 'neither' (any more?); "
        "remove this entry",
        "accept_warnings[1]: no warning at 'chains.spare' says 'cannot move' (any more?); "
        "remove this entry",
    ]
    with pytest.raises(RobotSpecError):
        warnings_of(tmp_path, "chains:\n" + SPARE + accept, strict=True)


def test_an_acceptance_needs_a_reason(tmp_path: Path) -> None:
    with pytest.raises(RobotSpecError, match="because"):
        warnings_of(tmp_path, "accept_warnings: [{at: chains.spare, says: neither}]\n")
