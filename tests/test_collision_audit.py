"""The SRDF audit, the matrix's convergence report and its comparison with an SRDF.

A small fixture arm (tests/data/audit_arm) holds one SRDF entry of every kind the audit tells
apart; the PR2 of example-robot-data shows the audit finds the ``Never`` entries of a real SRDF
that collide, each with a witness an independent checker confirms.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from robotspec.cli.app import app
from robotspec.collision import CollisionRules, SelfCollisionChecker, default_configuration
from robotspec.collision.audit import (
    COLLIDES,
    DUPLICATE,
    NO_GEOMETRY,
    NOT_ADJACENT,
    OK,
    UNKNOWN,
    SrdfAudit,
    audit_srdf,
)
from robotspec.collision.convergence import compare_with_srdf, convergence
from robotspec.collision.matrix import CollisionMatrix, generate_for_robot
from robotspec.compiler import check_spec
from robotspec.semantic import AbstractRobot
from tests.conftest import DATA, erd_robots

ARM = DATA / "audit_arm" / "audit_arm.yaml"


def _collides_at(robot: AbstractRobot, a: str, b: str, witness: dict[str, float]) -> bool:
    """An independent check of one pair at the default pose plus the witness's joint values."""
    w = robot.world
    q = default_configuration(w)
    for joint, v in witness.items():
        q[w.get_connection_by_name(joint).dofs[0]] = v
    checker = SelfCollisionChecker(w, CollisionRules(bodies=(a, b)), pairs=[(a, b)])
    return bool(checker.in_collision(q))


@pytest.fixture(scope="module")
def arm() -> AbstractRobot:
    robot = check_spec(ARM).robot
    assert robot is not None
    return robot


@pytest.fixture(scope="module")
def arm_audit(arm: AbstractRobot) -> SrdfAudit:
    return audit_srdf(arm, samples=300, seed=0, processes=1)


def test_every_entry_of_the_fixture_gets_its_verdict(
    arm: AbstractRobot, arm_audit: SrdfAudit
) -> None:
    verdicts = [(e.line, e.link1, e.link2, e.verdict) for e in arm_audit.entries]
    assert verdicts == [
        (4, "base_link", "turret", OK),
        (5, "turret", "arm", OK),
        (6, "base_link", "arm", COLLIDES),
        (7, "arm", "base_link", DUPLICATE),
        (8, "base_link", "ghost", UNKNOWN),
        (9, "base_link", "marker", NO_GEOMETRY),
        (10, "base_link", "camera_box", NOT_ADJACENT),
    ]
    by_line = {e.line: e for e in arm_audit.entries}
    assert by_line[7].detail == "the pair is already disabled on line 6"
    assert by_line[8].detail == "'ghost' not in the URDF: the entry is inert"
    assert by_line[9].detail == "'marker' has no collision geometry: the entry is inert"
    assert by_line[10].detail == (
        "no joint joins them (directly or through bodies without geometry); 2 joints lie "
        "between them"
    )
    wrong = by_line[6]
    # The rod swings into the base: the witness tilts it past ~2.4 rad, and nothing else collides.
    assert set(wrong.witness) == {"pan", "swing"} and abs(wrong.witness["swing"]) > 2.3
    assert wrong.valid
    assert _collides_at(arm, "base_link", "arm", dict(wrong.witness))
    assert [(a, b, r) for a, b, r, _ in arm_audit.missing] == [
        ("arm", "camera_box", "Adjacent"),
        ("camera_box", "turret", "Never"),
    ]


def test_pr2_srdf_marks_colliding_pairs_never() -> None:
    erd_robots()
    pr2 = check_spec("pr2").robot
    assert pr2 is not None
    audit = audit_srdf(pr2, samples=500, seed=0, processes=1)
    assert len(audit.entries) == 1163
    # example-robot-data's PR2 has no collision geometry on the casters, wheels, sensors, ...
    assert audit.count(UNKNOWN, NO_GEOMETRY) == 906
    colliding = {(e.link1, e.link2) for e in audit.entries if e.verdict == COLLIDES}
    # Shoulder pan against upper-arm roll collides in ~2.5 % of random configurations.
    assert {
        ("l_shoulder_pan_link", "l_upper_arm_roll_link"),
        ("r_shoulder_pan_link", "r_upper_arm_roll_link"),
    } <= colliding
    for e in audit.entries:
        if e.verdict == COLLIDES and e.witness:
            assert e.reason == "Never"
            assert _collides_at(pr2, e.link1, e.link2, dict(e.witness)), (e.link1, e.link2)
    assert audit.count(NOT_ADJACENT, DUPLICATE) == 0


def _matrix(first: tuple[tuple[str, str, int], ...], samples: int = 1000) -> CollisionMatrix:
    return CollisionMatrix(
        robot_name="r",
        bodies=("a", "b", "c"),
        disabled=(),
        checked=(),
        samples=samples,
        seed=0,
        always_samples=200,
        processes=1,
        seconds=0.0,
        first_collision=first,
    )


def test_convergence_report_counts_late_first_collisions() -> None:
    done = convergence(_matrix((("a", "b", 0), ("a", "c", 0))))
    assert done.converged
    assert done.lines() == [
        "convergence: no pair changed status in the last half of the 1,000 samples (the last "
        "first collision was in samples from 0)"
    ]
    late = convergence(_matrix((("a", "b", 0), ("b", "c", 500))))
    assert not late.converged
    assert late.lines() == [
        "convergence: 1 pairs changed status (first collided) in the last half of the 1,000 "
        "samples (after sample 500); the matrix has not converged: run again with more samples, "
        "e.g. -n 2,000",
        "  b - c: first collided in samples from 500",
    ]


def test_generator_records_first_collisions_and_compares_with_the_srdf(
    arm: AbstractRobot,
) -> None:
    m = generate_for_robot(arm, samples=1000, seed=1, processes=1)
    first = {(a, b): s for a, b, s in m.first_collision}
    # The rod hits the base in ~13 % of samples: seen in the first chunk.
    assert first[("arm", "base_link")] == 0
    assert {frozenset(p) for p in m.checked} >= {frozenset(("arm", "base_link"))}
    assert arm.srdf is not None
    cmp = compare_with_srdf(m, arm.srdf, "audit_arm.srdf")
    assert (cmp.reference_pairs, cmp.ignored) == (4, 2)  # ghost, marker; the duplicate counts once
    assert [(d.link1, d.link2, d.side, d.reason) for d in cmp.differences] == [
        ("arm", "camera_box", "matrix only", "Adjacent"),
        ("camera_box", "turret", "matrix only", "Never"),
        ("arm", "base_link", "SRDF only", "Never"),
        ("base_link", "camera_box", "SRDF only", "Adjacent"),
    ]
    assert cmp.differences[2].why == "the matrix checks it: it collided (first in samples from 0)"


runner = CliRunner()


def test_cli_audit_json_and_exit_code() -> None:
    res = runner.invoke(app, ["collisions", "audit", str(ARM), "-n", "300", "-j", "1", "--json"])
    assert res.exit_code == 1, res.output  # an entry is wrong
    doc = json.loads(res.stdout)
    assert doc["summary"] == {
        "entries": 7,
        "ok": 2,
        "inert": 2,
        "duplicate": 1,
        "not_adjacent": 1,
        "collides": 1,
        "missing": 2,
    }
    wrong = [e for e in doc["entries"] if e["verdict"] == "collides"]
    assert wrong[0]["witness_valid"] is True


def test_cli_audit_witness_loads_in_collisions_check() -> None:
    res = runner.invoke(app, ["collisions", "audit", str(ARM), "-n", "300", "-j", "1"])
    lines = res.stdout.splitlines()
    cmd = next(ln.strip() for ln in lines if ln.strip().startswith("robotspec collisions check"))
    argv = cmd.split()[1:]
    assert "--ignore-srdf" in argv
    shown = runner.invoke(app, argv)
    assert shown.exit_code == 1 and "IN COLLISION" in shown.stdout
    assert "base_link  arm" in shown.stdout or "arm        base_link" in shown.stdout
    # Under the SRDF's rules the same configuration passes: the entry hides the collision.
    argv.remove("--ignore-srdf")
    assert runner.invoke(app, argv).exit_code == 0


def test_cli_generate_prints_convergence_and_comparison(tmp_path: Path) -> None:
    srdf = ARM.parent / "audit_arm.srdf"
    out = tmp_path / "m.srdf"
    res = runner.invoke(
        app,
        ["collisions", "generate", str(ARM), "-n", "1000", "-j", "1", "-o", str(out)]
        + ["--compare", str(srdf)],
    )
    assert res.exit_code == 0, res.output
    err = res.stderr
    assert "convergence: no pair changed status in the last half of the 1,000 samples" in err
    assert "against audit_arm.srdf: precision 0.500, recall 0.500" in err
    assert "  arm - base_link: Never: the matrix checks it: it collided" in err
    assert "disabled by the matrix only: 2" in err


def test_audit_is_deterministic(arm: AbstractRobot, arm_audit: SrdfAudit) -> None:
    again = audit_srdf(arm, samples=300, seed=0, processes=1)
    a = [dict(e.witness) for e in arm_audit.entries]
    b = [dict(e.witness) for e in again.entries]
    assert a == b
    assert np.isfinite([v for w in a for v in w.values()]).all()


def test_cli_audit_without_srdf_and_compare_with_a_missing_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from robotspec.cli.output import run_app

    erd_robots()
    code = run_app(app, ["collisions", "audit", "tiago", "-n", "10", "-j", "1"])
    err = capsys.readouterr().err
    assert code == 1
    assert "error: robot 'Tiago' has no SRDF to audit" in err
    missing = tmp_path / "nowhere.srdf"
    argv = ["collisions", "generate", str(ARM), "-n", "10", "-j", "1", "--compare", str(missing)]
    code = run_app(app, argv)
    err = capsys.readouterr().err
    assert code == 1
    assert "nowhere.srdf" in err and "Traceback" not in err
