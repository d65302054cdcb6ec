"""The report of `robotspec collisions audit`, as text and as JSON (the command: collisions_cmd)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from robotspec.cli.table import render_table

if TYPE_CHECKING:
    from robotspec.collision.audit import AuditEntry, SrdfAudit

__all__ = ["audit_json", "audit_text"]


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


def audit_json(r: SrdfAudit) -> dict[str, Any]:
    """The audit as JSON: summary, precision and recall, every entry, the missing pairs."""
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


def audit_text(r: SrdfAudit, spec: str, show_ok: bool) -> str:
    """The audit for a terminal: summary, the wrong entries, witnesses, missing pairs."""
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
