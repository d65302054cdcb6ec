"""Bounds on what a command line can ask of ``collisions generate`` and ``collisions audit``.

Why: ``--jobs 64`` forked 64 workers for two blocks of work and the summary printed 64;
``--seed -1`` was an internal error (numpy refuses negative seeds); ``-n 10**12`` drew every
sample at once (a MemoryError). Each is now a usage error naming the value, or bounded work.
"""

from __future__ import annotations

import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from robotspec.cli import collisions_cmd
from robotspec.cli.app import app
from robotspec.cli.output import run_app
from robotspec.collision import parallel, sampling
from robotspec.collision.audit import audit_srdf
from robotspec.collision.matrix import generate_for_robot
from robotspec.collision.parallel import used_processes
from robotspec.collision.sampling import RandomBlocks, random_configurations
from robotspec.compiler import check_spec
from robotspec.errors import CollisionError
from robotspec.semantic import AbstractRobot
from tests.conftest import DATA

ARM = DATA / "audit_arm" / "audit_arm.yaml"


@pytest.fixture(scope="module")
def arm() -> AbstractRobot:
    robot = check_spec(ARM).robot
    assert robot is not None
    return robot


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = run_app(app, list(argv))
    out = capsys.readouterr()
    return code, out.out, " ".join(out.err.replace("\u2502", " ").split())  # the box wraps lines


@pytest.mark.parametrize("command", ["generate", "audit"])
@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--seed", "-1"], "Invalid value for '--seed': -1 is not between 0 and 2^64-1"),
        (
            ["--seed", str(2**64)],
            f"Invalid value for '--seed': {2**64} is not between 0 and 2^64-1",
        ),
        (
            ["-n", str(10**12)],
            "Invalid value for '--samples' / '-n': 1000000000000 is not between 0 and "
            "1,000,000,000",
        ),
        (["-n", "-3"], "-3 is not between 0 and 1,000,000,000"),
        (["--jobs", "0"], "Invalid value for '--jobs' / '-j': 0 is not between 1 and 1,000,000"),
    ],
)
def test_out_of_range_options_are_usage_errors_naming_the_value(
    capsys: pytest.CaptureFixture[str], command: str, args: list[str], message: str
) -> None:
    code, _, err = _run(capsys, "collisions", command, str(ARM), *args)
    assert code == 2
    assert message in err
    assert "internal error" not in err


def test_cli_bounds_are_the_librarys() -> None:
    assert collisions_cmd.MAX_SAMPLES == sampling.MAX_SAMPLES
    assert collisions_cmd.MAX_SEED == sampling.MAX_SEED


def test_library_refuses_the_same_values(arm: AbstractRobot) -> None:
    with pytest.raises(CollisionError, match="seed must be between 0 and 2\\*\\*64 - 1, got -1"):
        generate_for_robot(arm, samples=10, seed=-1)
    with pytest.raises(CollisionError, match="got 1,000,000,000,000"):
        generate_for_robot(arm, samples=10**12)
    with pytest.raises(CollisionError, match="got -1"):
        audit_srdf(arm, samples=10, seed=-1)


def test_jobs_are_capped_by_the_work_and_the_cpus(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(parallel, "default_processes", lambda: 8)
    assert used_processes(64, 2) == 2  # two blocks of samples: two workers at most
    assert used_processes(64, 100) == 8  # never more than the CPUs
    assert used_processes(None, 100) == 8
    assert used_processes(3, 100) == 3
    assert used_processes(5, 0) == 1
    assert used_processes(0, 5) == 1


def test_summary_reports_the_processes_used(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    # One CPU here, so the run stays in this process; 1,000 samples are two blocks.
    monkeypatch.setattr(parallel, "default_processes", lambda: 1)
    code, _, err = _run(capsys, "collisions", "generate", str(ARM), "-n", "1000", "--jobs", "64")
    assert code == 0, err
    assert (
        "1000 samples, seed 0, 1 process (--jobs 64: at most the CPUs and one per block of "
        "500 samples)" in err
    )


def test_matrix_records_the_processes_used(
    arm: AbstractRobot, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(parallel, "default_processes", lambda: 1)
    assert generate_for_robot(arm, samples=600, processes=64).processes == 1


def test_blocks_are_the_samples_drawn_at_once(arm: AbstractRobot) -> None:
    # Drawing in blocks keeps a run reproducible: the same values as one big draw.
    world = arm.world
    whole = random_configurations(world, 1_234, np.random.default_rng(5))
    blocks = RandomBlocks(world, 1_234, np.random.default_rng(5), size=500)
    assert len(blocks) == 3
    parts = list(blocks)
    assert [len(p) for p in parts] == [500, 500, 234]
    assert np.array_equal(np.concatenate(parts), whole)
    assert len(RandomBlocks(world, 0, np.random.default_rng(0))) == 0


def test_memory_does_not_grow_with_the_sample_count(arm: AbstractRobot) -> None:
    # 500,000 samples of this arm drawn at once are 8 MB; in blocks the run's peak stays near
    # what a block and the checker need (about 1.7 MB, the same for 10^6 samples).
    tracemalloc.start()
    try:
        matrix = generate_for_robot(arm, samples=500_000, processes=1)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert matrix.samples == 500_000
    assert peak < 4 * 1024 * 1024, peak


def test_a_trillion_samples_is_a_usage_error_under_a_memory_fence(tmp_path: Path) -> None:
    # Before: every sample drawn at once, a MemoryError (an internal error, exit 3).
    from tests.test_hostile import run_cli

    (tmp_path / "work").mkdir()
    r = run_cli(tmp_path, "collisions", "generate", str(ARM), "-n", str(10**12), "--seed", "-1")
    assert r.code == 2, r.err
    assert "Invalid value for '--samples' / '-n': 1000000000000 is not between" in " ".join(
        r.err.replace("\u2502", " ").split()
    )
