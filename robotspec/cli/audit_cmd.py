"""``robotspec collisions audit``: what every SRDF ``disable_collisions`` entry actually does."""

from __future__ import annotations

import json
import sys
from typing import TYPE_CHECKING, Annotated, Any

import typer

from robotspec.cli.collisions_cmd import collisions_app
from robotspec.cli.options import JsonFlag, PackagePath, SkipMeshes, SpecArg, load_robot
from robotspec.cli.table import render_table

if TYPE_CHECKING:
    from robotspec.collision.audit import AuditEntry, SrdfAudit


@collisions_app.command("audit")
def audit(
    spec: SpecArg,
    samples: Annotated[
        int,
        typer.Option(
            "--samples", "-n", min=0, help="Random configurations for the regenerated matrix."
        ),
    ] = 10_000,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the sampler.")] = 0,
    jobs: Annotated[
        int | None, typer.Option("--jobs", "-j", min=1, help="Worker processes (default: CPUs).")
    ] = None,
    show_ok: Annotated[
        bool, typer.Option("--all", help="Also list the entries that are right.")
    ] = False,
    progress: Annotated[
        bool | None,
        typer.Option(
            "--progress/--no-progress", help="Progress bar on stderr (default: on a terminal)."
        ),
    ] = None,
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
    from robotspec.collision import Progress
    from robotspec.collision.audit import audit_srdf

    robot = load_robot(spec, package_path)
    bar = Progress(0, "audit", enabled=progress)

    def report(done: int, total: int) -> None:
        bar.total = total
        bar.update(done - bar.done)

    with bar:
        result = audit_srdf(
            robot,
            samples=samples,
            seed=seed,
            processes=jobs,
            progress=report,
            on_missing_mesh="skip" if skip_missing_meshes else "error",
        )
    if as_json:
        sys.stdout.write(json.dumps(_as_json(result), indent=2) + "\n")
    else:
        sys.stdout.write(_text(result, spec, show_ok))
    if result.wrong:
        raise typer.Exit(1)


def _summary(r: SrdfAudit) -> dict[str, int]:
    from robotspec.collision.audit import COLLIDES, DUPLICATE, INERT, NOT_ADJACENT, OK

    return {
        "entries": len(r.entries),
        "ok": r.count(OK),
        "inert": r.count(*INERT),
        "duplicate": r.count(DUPLICATE),
        "not_adjacent": r.count(NOT_ADJACENT),
        "collides": r.count(COLLIDES),
        "missing": len(r.missing),
    }


def _entry_json(e: AuditEntry) -> dict[str, Any]:
    return {
        "link1": e.link1,
        "link2": e.link2,
        "reason": e.reason,
        "line": e.line,
        "verdict": e.verdict,
        "detail": e.detail,
        "witness": dict(e.witness) or None,
        "witness_valid": e.valid if e.witness else None,
    }


def _as_json(r: SrdfAudit) -> dict[str, Any]:
    c = r.comparison
    return {
        "robot": r.robot,
        "srdf": r.srdf,
        "samples": r.samples,
        "seed": r.seed,
        "summary": _summary(r),
        "precision": None if c is None else c.precision,
        "recall": None if c is None else c.recall,
        "entries": [_entry_json(e) for e in r.entries],
        "missing": [
            {"link1": a, "link2": b, "reason": reason, "why": why}
            for a, b, reason, why in r.missing
        ],
    }


def _witness_cmd(spec: str, e: AuditEntry) -> str:
    qs = " ".join(f"--q {j}={v:.6g}" for j, v in e.witness.items())
    return f"robotspec collisions check {spec} --ignore-srdf {qs}"


def _text(r: SrdfAudit, spec: str, show_ok: bool) -> str:
    from robotspec.collision.audit import COLLIDES, INERT, OK

    s = _summary(r)
    name = r.srdf.rsplit("/", 1)[-1]
    lines = [
        f"{name}: {s['entries']} disable_collisions entries: {s['ok']} right, {s['inert']} "
        f"inert, {s['duplicate']} duplicate, {s['not_adjacent']} Adjacent but not adjacent, "
        f"{s['collides']} Never but colliding; {s['missing']} pairs a regenerated matrix "
        f"would disable are missing ({r.samples:,} samples, seed {r.seed}, {r.seconds:.1f} s)"
    ]
    if r.comparison is not None:
        lines.append(
            f"regenerated matrix against the SRDF: precision {r.comparison.precision:.3f}, "
            f"recall {r.comparison.recall:.3f}"
        )
    inert = [e for e in r.entries if e.verdict in INERT]
    if inert and not show_ok:
        by_body: dict[str, int] = {}
        for e in inert:
            for x in e.culprits:
                by_body[x] = by_body.get(x, 0) + 1
        top = sorted(by_body.items(), key=lambda kv: (-kv[1], kv[0]))
        shown = ", ".join(f"{b} ({n})" for b, n in top[:8])
        more = f", and {len(top) - 8} more bodies" if len(top) > 8 else ""
        lines.append(
            f"inert: {len(inert)} entries name unknown links or links without collision "
            f"geometry (entries per link): {shown}{more} (--all lists them)"
        )
    rows = [
        [e.line, e.link1, e.link2, e.reason, e.verdict, e.detail]
        for e in r.entries
        if show_ok or e.verdict not in (OK, *INERT)
    ]
    if rows:
        lines += ["", render_table(["line", "link1", "link2", "reason", "verdict", "why"], rows)]
    wrong = [e for e in r.entries if e.verdict == COLLIDES and e.witness]
    if wrong:
        lines += ["", "witnesses (joint values between the two bodies, over the default pose):"]
        for e in wrong:
            valid = "valid: no checked pair collides" if e.valid else "other pairs collide too"
            lines.append(f"  {e.link1} - {e.link2} ({valid}):")
            lines.append(f"    {_witness_cmd(spec, e)}")
    if r.missing:
        lines += ["", "missing (a regenerated matrix disables them, the SRDF does not):"]
        lines.append(
            render_table(["link1", "link2", "reason", "why"], [list(m) for m in r.missing])
        )
    return "\n".join(lines) + "\n"
