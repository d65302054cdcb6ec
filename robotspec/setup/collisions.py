"""The self-collision matrix and its audit, run from the assistant on the spec being edited.

Why the Setup Assistant's way: MoveIt's assistant regenerates ``disable_collisions`` into the
robot's SRDF (its groups and states kept) and the spec then names that SRDF. The new SRDF is
kept in the session and written by "save", beside the spec, so the spec refers to it by a
relative path; its name is ``<spec>.srdf``, or ``<spec>.collisions.srdf`` when the former is the
robot's own SRDF (which is never replaced). The audit then reads what each entry does.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from robotspec.setup.session import SetupError, SetupSession

if TYPE_CHECKING:
    from robotspec.collision.audit import SrdfAudit
    from robotspec.semantic import AbstractRobot

__all__ = ["AuditReport", "MatrixResult", "audit_session", "generate_matrix", "plain_audit_report"]

Progress = Callable[[int, int], None]
#: Writes an audit as text: (the audit, the spec's path, whether to list the right entries).
AuditReport = Callable[["SrdfAudit", str, bool], str]


@dataclass(frozen=True)
class MatrixResult:
    """Where the SRDF went and the summary ``collisions generate`` prints."""

    srdf: Path
    summary: str


def _robot(session: SetupSession) -> AbstractRobot:
    robot = session.validation.robot
    if robot is None:
        raise SetupError("the spec has errors; fix them before the collision matrix", kind="spec")
    if not robot.bodies_with_collisions:
        raise SetupError(f"robot '{robot.name}' has no collision geometry", kind="robot")
    return robot


def generate_matrix(
    session: SetupSession, *, samples: int = 10_000, seed: int = 0, progress: Progress | None = None
) -> MatrixResult:
    """Generate the matrix into the robot's SRDF, keep it in the session, name it in the spec.

    Nothing is written: "save" writes the SRDF beside the spec (``MatrixResult.srdf``).
    """
    from robotspec.collision import generate_for_robot
    from robotspec.export.srdf import write_srdf

    robot = _robot(session)
    session.fence.srdf_name(session.output)  # no name for it: say so before the long wait
    matrix = generate_for_robot(
        robot, samples=samples, seed=seed, processes=1, progress=progress, on_missing_mesh="skip"
    )
    srdf = matrix.to_srdf(robot.srdf, merge=False) if robot.srdf else matrix.to_srdf()
    if session.pair_choices:  # a person's pairs outlive a rerun (setup/pairs.py)
        from robotspec.setup.pairs import apply_choices

        srdf = apply_choices(srdf, session.pair_choices)
    if session.extras.passive:  # and their passive joints (setup/passive.py)
        from robotspec.setup.passive import apply_passive

        srdf = apply_passive(srdf, dict(session.extras.passive))
    said = f"collision matrix generated ({len(matrix.disabled)} pairs not checked)"
    name, _ = session.keep_srdf(write_srdf(srdf), what=said)
    counts = ", ".join(f"{k} {v}" for k, v in matrix.reasons().items())
    summary = (
        f"{len(matrix.disabled)} pairs disabled ({counts}); {len(matrix.checked)} stay checked; "
        f"{matrix.samples} samples, seed {matrix.seed}, {matrix.seconds:.1f} s; the spec names "
        f"{name}, which save writes beside it (the robot's own SRDF is never replaced)"
    )
    return MatrixResult(session.output.parent / name, summary)


def plain_audit_report(result: SrdfAudit, spec: str, show_ok: bool) -> str:
    """A summary and one line per wrong entry (the CLI hands the page a richer report)."""
    lines = [
        f"{len(result.entries)} entries of {result.srdf.rsplit('/', 1)[-1]} audited "
        f"({result.samples} samples, seed {result.seed}); {len(result.wrong)} wrong"
    ]
    lines += [f"  {e.link1} - {e.link2}: {e.verdict}" for e in result.wrong]
    return "\n".join(lines)


def audit_session(
    session: SetupSession,
    *,
    samples: int = 10_000,
    seed: int = 0,
    progress: Progress | None = None,
    report: AuditReport = plain_audit_report,
) -> tuple[bool, str]:
    """What each ``disable_collisions`` entry of the spec's SRDF does: (all right, the report).

    ``report`` writes the text; the CLI hands in its own (``robotspec collisions audit``'s), so
    the page shows what the command prints without this room importing the CLI.
    """
    from robotspec.collision.audit import audit_srdf

    robot = _robot(session)
    if robot.srdf is None:
        raise SetupError("the spec names no SRDF; generate the collision matrix first", kind="srdf")
    result = audit_srdf(
        robot, samples=samples, seed=seed, processes=1, progress=progress, on_missing_mesh="skip"
    )
    text = report(result, str(session.output), False)
    kept = session.draft().srdf
    if robot.srdf.file and kept and ".setup-" in Path(robot.srdf.file).name:
        # The kept SRDF was checked as a hidden staged file: name it as it will be saved.
        text = text.replace(robot.srdf.file, kept).replace(Path(robot.srdf.file).name, kept)
    return not result.wrong, text
