"""``robotspec collisions``: self-collision checks and collision matrix generation."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Annotated, Any

import typer

from robotspec.cli.geometry import (
    check_missing_geometry,
    report_skipped,
    require_collision_geometry,
)
from robotspec.cli.options import (
    Force,
    JsonFlag,
    PackagePath,
    QOpt,
    SkipMeshes,
    SpecArg,
    StateOpt,
    joint_values,
    load_robot,
    write_output,
)
from robotspec.cli.table import render_table
from robotspec.errors import CollisionError

#: This module's commands; robotspec.cli.app adds them to the root app.
app = typer.Typer()


collisions_app = typer.Typer(
    help="Self-collision checks and collision matrices (coal).", no_args_is_help=True
)
app.add_typer(collisions_app, name="collisions")


@collisions_app.command("check")
def check(
    spec: SpecArg,
    state: StateOpt = None,
    q: QOpt = None,
    distances: Annotated[
        bool, typer.Option("--distances", help="Also list every checked pair's distance.")
    ] = False,
    ignore_srdf: Annotated[
        bool,
        typer.Option(
            "--ignore-srdf",
            help="Check the pairs the SRDF disables too (adjacent pairs stay unchecked); shows "
            "the witnesses of `collisions audit`.",
        ),
    ] = False,
    as_json: JsonFlag = False,
    skip_missing_meshes: SkipMeshes = False,
    package_path: PackagePath = None,
) -> None:
    """Is the robot in self-collision at a configuration? Exit code 1 when it is.

    The configuration is the default pose (0, or mid-range), then --state, then --q.
    Pairs closer than the spec's buffer distance are listed as warnings.
    """
    from robotspec.collision import SelfCollisionChecker

    robot = load_robot(spec, package_path)
    require_collision_geometry(robot, "check collisions")
    reported = check_missing_geometry(
        robot, skip=skip_missing_meshes, collision=True, command="check collisions"
    )
    checker = SelfCollisionChecker.from_robot(
        robot, on_missing_mesh="skip" if skip_missing_meshes else "error"
    )
    config = checker.configuration(state or (), joint_values(q))
    if ignore_srdf:
        from robotspec.collision import CollisionRules

        rules = checker.rules
        checker = SelfCollisionChecker(
            robot.world,
            CollisionRules(
                bodies=rules.bodies,
                adjacent=rules.adjacent,
                disabled_bodies=rules.disabled_bodies,
                buffer_distance=rules.buffer_distance,
            ),
            on_missing_mesh="skip" if skip_missing_meshes else "error",
        )
    colliding = checker.colliding_pairs(config)
    report_skipped(checker.skipped, reported)
    buffer = checker.rules.buffer_distance
    near = [p for p in checker.buffer_violations(config) if p not in colliding] if buffer else []
    pair_d = checker.distances(config) if distances else ()
    if as_json:
        doc: dict[str, Any] = {
            "in_collision": bool(colliding),
            "colliding_pairs": [list(p) for p in colliding],
            "within_buffer": [list(p) for p in near],
            "buffer_distance": buffer,
            "checked_pairs": len(checker.active_pairs),
        }
        if distances:
            doc["distances"] = [
                {
                    "link1": d.link1,
                    "link2": d.link2,
                    "distance": d.distance if math.isfinite(d.distance) else None,
                    "point1": list(d.point1),
                    "point2": list(d.point2),
                }
                for d in pair_d
            ]
        sys.stdout.write(json.dumps(doc, indent=2) + "\n")
    else:
        n = len(checker.active_pairs)
        if colliding:
            sys.stdout.write(f"IN COLLISION: {len(colliding)} of {n} checked pairs\n")
            sys.stdout.write(render_table(["link1", "link2"], [list(p) for p in colliding]) + "\n")
        else:
            sys.stdout.write(f"collision-free ({n} pairs checked)\n")
        if near:
            sys.stdout.write(f"within the buffer distance ({buffer:g} m):\n")
            sys.stdout.write(render_table(["link1", "link2"], [list(p) for p in near]) + "\n")
        if distances:
            rows = [[d.link1, d.link2, f"{d.distance:.6f}"] for d in pair_d]
            sys.stdout.write(render_table(["link1", "link2", "distance (m)"], rows) + "\n")
    if colliding:
        raise typer.Exit(1)


#: Bounds of ``--samples`` and ``--seed``: those of robotspec.collision.sampling (MAX_SAMPLES,
#: MAX_SEED), written out so that ``--help`` does not import numpy; a test keeps them equal.
MAX_SAMPLES = 1_000_000_000
MAX_SEED = 2**64 - 1


def _within(low: int, high: int, shown: str) -> Any:
    """A callback refusing a value outside ``[low, high]``: a usage error naming the value.

    Why not the option's own ``min``/``max``: their message names the bound, not the value
    given, and a script's user needs to see which value was wrong.
    """

    def check(value: int | None) -> int | None:
        if value is not None and not low <= value <= high:
            raise typer.BadParameter(f"{value} is not between {low} and {shown}")
        return value

    return check


_samples_range = _within(0, MAX_SAMPLES, f"{MAX_SAMPLES:,}")

#: The sampling options that ``collisions generate`` and ``collisions audit`` share.
SeedOpt = Annotated[
    int,
    typer.Option(
        "--seed", help="Seed of the sampler, 0 to 2^64-1.", callback=_within(0, MAX_SEED, "2^64-1")
    ),
]
JobsOpt = Annotated[
    int | None,
    typer.Option(
        "--jobs",
        "-j",
        help="Worker processes (default: CPUs); never more than the CPUs or the blocks of "
        "500 samples.",
        callback=_within(1, 1_000_000, "1,000,000"),
    ),
]
ProgressOpt = Annotated[
    bool | None,
    typer.Option(
        "--progress/--no-progress", help="Progress bar on stderr (default: on a terminal)."
    ),
]


def processes_text(used: int, asked: int | None) -> str:
    """``2 processes``, and what ``--jobs`` asked for when fewer ran (the CPUs or the work)."""
    text = f"{used} process{'' if used == 1 else 'es'}"
    if asked is not None and asked > used:
        text += f" (--jobs {asked}: at most the CPUs and one per block of 500 samples)"
    return text


@collisions_app.command("generate")
def generate(
    spec: SpecArg,
    samples: Annotated[
        int,
        typer.Option(
            "--samples",
            "-n",
            help="Random configurations to sample (at most 10^9).",
            callback=_samples_range,
        ),
    ] = 10_000,
    seed: SeedOpt = 0,
    output: Annotated[
        Path | None, typer.Option("--output", "-o", help="Write the SRDF here (default: stdout).")
    ] = None,
    merge: Annotated[
        bool,
        typer.Option(
            "--merge", help="Add the pairs to the robot's SRDF (its own entries are kept)."
        ),
    ] = False,
    jobs: JobsOpt = None,
    progress: ProgressOpt = None,
    compare: Annotated[
        Path | None,
        typer.Option(
            "--compare",
            help="An SRDF to compare with: precision, recall and each differing pair with its "
            "reason (on stderr).",
        ),
    ] = None,
    skip_missing_meshes: SkipMeshes = False,
    force: Force = False,
    package_path: PackagePath = None,
) -> None:
    """Compute the disabled collision pairs (Adjacent, Default, Always, Never) as SRDF.

    Without --merge the SRDF holds only the disable_collisions; with it, the robot's SRDF with
    the new pairs added. A summary (and, when the robot has an SRDF, precision and recall against
    it) and a convergence report (pairs first seen colliding in the last half of the samples)
    go to stderr.
    """
    from robotspec.cli.progress import Progress
    from robotspec.collision import compare_pairs, generate_for_robot
    from robotspec.collision.convergence import compare_with_srdf, convergence
    from robotspec.compiler.inputs import spec_inputs
    from robotspec.description.srdf_reader import load_srdf
    from robotspec.export.srdf import write_srdf
    from robotspec.files.writing import check_writable

    robot = load_robot(spec, package_path)
    inputs = spec_inputs(spec, package_paths=package_path or (), robot=robot)
    if output is not None:  # before the samples, as the write refuses it again
        check_writable(output, force=force, inputs=inputs)
    other = None if compare is None else load_srdf(compare, strict=False)
    if merge and robot.srdf is None:
        raise CollisionError(f"--merge: robot '{robot.name}' has no SRDF to merge into")
    require_collision_geometry(robot, "generate the matrix for")
    reported = check_missing_geometry(
        robot, skip=skip_missing_meshes, collision=True, command="generate the matrix"
    )
    bar = Progress(0, "collision matrix", enabled=progress)

    with bar:
        matrix = generate_for_robot(
            robot,
            samples=samples,
            seed=seed,
            processes=jobs,
            progress=bar.report,
            on_missing_mesh="skip" if skip_missing_meshes else "error",
        )
    report_skipped(matrix.skipped, reported)
    text = write_srdf(matrix.to_srdf(robot.srdf if merge else None, merge=True))
    write_output(text, output, force=force, inputs=inputs)
    counts = ", ".join(f"{k} {v}" for k, v in matrix.reasons().items())
    lines = [
        f"{len(matrix.disabled)} pairs disabled ({counts}); {len(matrix.checked)} stay checked; "
        f"{matrix.samples} samples, seed {matrix.seed}, {processes_text(matrix.processes, jobs)}, "
        f"{matrix.seconds:.1f} s"
    ]
    if robot.srdf is not None:
        geometry = set(matrix.bodies)
        reference = frozenset(
            frozenset((d.link1, d.link2))
            for d in robot.srdf.disabled_collisions
            if d.link1 in geometry and d.link2 in geometry and d.link1 != d.link2
        )
        precision, recall = compare_pairs(matrix.disabled_pairs(), reference)
        lines.append(
            f"against {Path(robot.srdf.file or 'the SRDF').name}: precision {precision:.3f}, "
            f"recall {recall:.3f} ({len(reference)} pairs there)"
        )
    lines += convergence(matrix).lines()
    if other is not None and compare is not None:
        lines += compare_with_srdf(matrix, other, compare.name).lines()
    if output is not None:
        lines.append(f"wrote {output}")
    sys.stderr.write("\n".join(lines) + "\n")


@collisions_app.command("audit")
def audit(
    spec: SpecArg,
    samples: Annotated[
        int,
        typer.Option(
            "--samples",
            "-n",
            help="Random configurations for the regenerated matrix (at most 10^9).",
            callback=_samples_range,
        ),
    ] = 10_000,
    seed: SeedOpt = 0,
    jobs: JobsOpt = None,
    show_ok: Annotated[
        bool, typer.Option("--all", help="Also list the entries that are right.")
    ] = False,
    progress: ProgressOpt = None,
    as_json: JsonFlag = False,
    skip_missing_meshes: SkipMeshes = False,
    package_path: PackagePath = None,
) -> None:
    """What each SRDF disable_collisions entry does. Exit code 1 when an entry is wrong.

    Inert entries (unknown links, bodies without collision geometry, a link paired with
    itself), duplicates, Adjacent entries whose bodies are not adjacent, Never entries whose
    bodies collide in sampled configurations (each with a witness: joint values to pass to
    `collisions check --q` or `render --q`), and the pairs a regenerated matrix would disable
    that the SRDF does not.
    """
    from robotspec.cli.audit_report import audit_json, audit_text
    from robotspec.cli.progress import Progress
    from robotspec.collision.audit import audit_srdf

    robot = load_robot(spec, package_path)
    require_collision_geometry(robot, "audit")
    bar = Progress(0, "audit", enabled=progress)

    with bar:
        result = audit_srdf(
            robot,
            samples=samples,
            seed=seed,
            processes=jobs,
            progress=bar.report,
            on_missing_mesh="skip" if skip_missing_meshes else "error",
        )
    if as_json:
        sys.stdout.write(json.dumps(audit_json(result), indent=2) + "\n")
    else:
        sys.stdout.write(audit_text(result, spec, show_ok))
    if result.wrong:
        raise typer.Exit(1)
