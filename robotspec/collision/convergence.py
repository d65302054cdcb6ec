"""Has a generated collision matrix converged? And how does it differ from an existing SRDF?

Why: a "Never" verdict only means "not seen colliding in N samples". If pairs were still being
seen colliding for the first time late in the run, more samples would likely move more pairs out
of "Never", so the matrix is not to be trusted yet. The generator records, per pair, the first
sample it collided in (:attr:`CollisionMatrix.first_collision`); this module reads it.
"""

from __future__ import annotations

from dataclasses import dataclass

from robotspec.collision.matrix import CollisionMatrix, MatrixEntry, compare_pairs
from robotspec.collision.rules import pair_key
from robotspec.description.srdf import Srdf

__all__ = ["Convergence", "PairDifference", "SrdfComparison", "compare_with_srdf", "convergence"]


@dataclass(frozen=True)
class Convergence:
    """Pairs first seen colliding in the last half of the "Never" pass's samples."""

    samples: int
    late: tuple[tuple[str, str, int], ...]
    last_change: int | None

    @property
    def converged(self) -> bool:
        """No pair changed status in the last half of the samples."""
        return not self.late

    def lines(self) -> list[str]:
        """The report ``collisions generate`` prints."""
        half = self.samples // 2
        if self.samples == 0:
            return ["convergence: no samples drawn, every undecided pair is 'Never' unchecked"]
        if self.converged:
            last = (
                "no pair collided at all"
                if self.last_change is None
                else f"the last first collision was in samples from {self.last_change:,}"
            )
            return [
                f"convergence: no pair changed status in the last half of the {self.samples:,} "
                f"samples ({last})"
            ]
        out = [
            f"convergence: {len(self.late)} pairs changed status (first collided) in the last "
            f"half of the {self.samples:,} samples (after sample {half:,}); the matrix has not "
            f"converged: run again with more samples, e.g. -n {2 * self.samples:,}"
        ]
        out += [f"  {a} - {b}: first collided in samples from {s:,}" for a, b, s in self.late]
        return out


def convergence(matrix: CollisionMatrix) -> Convergence:
    """The convergence of ``matrix``'s "Never" pass (chunk resolution: 500 samples)."""
    half = matrix.samples // 2
    late = tuple(e for e in matrix.first_collision if e[2] >= half and matrix.samples > 0)
    last = max((s for _, _, s in matrix.first_collision), default=None)
    return Convergence(matrix.samples, late, last)


@dataclass(frozen=True)
class PairDifference:
    """A pair the matrix and the SRDF disagree on, and why."""

    link1: str
    link2: str
    side: str  # "matrix only" or "SRDF only"
    reason: str  # the reason of the side that disables it
    why: str  # what the other side saw


@dataclass(frozen=True)
class SrdfComparison:
    """Precision and recall of a matrix against an SRDF, with every differing pair."""

    srdf: str
    precision: float
    recall: float
    reference_pairs: int
    generated_pairs: int
    ignored: int  # SRDF entries naming unknown links or links without geometry
    differences: tuple[PairDifference, ...]

    def lines(self) -> list[str]:
        """The report ``collisions generate --compare`` prints."""
        only_m = [d for d in self.differences if d.side == "matrix only"]
        only_s = [d for d in self.differences if d.side == "SRDF only"]
        out = [
            f"against {self.srdf}: precision {self.precision:.3f}, recall {self.recall:.3f} "
            f"({self.generated_pairs} pairs generated, {self.reference_pairs} in the SRDF, "
            f"{self.ignored} SRDF entries ignored: links without geometry or unknown)",
            f"disabled by the matrix only: {len(only_m)}",
        ]
        out += [f"  {d.link1} - {d.link2}: {d.reason}: {d.why}" for d in only_m]
        out.append(f"disabled by the SRDF only: {len(only_s)}")
        out += [f"  {d.link1} - {d.link2}: {d.reason}: {d.why}" for d in only_s]
        return out


def _matrix_why(e: MatrixEntry) -> str:
    if e.reason == "Never":
        return f"no collision in {e.samples:,} samples; the SRDF checks it"
    if e.reason == "Always":
        return f"in collision in {e.collisions} of {e.samples} samples; the SRDF checks it"
    if e.reason == "Default":
        return "in collision at the default configuration; the SRDF checks it"
    return "joined by a joint (or through bodies without geometry); the SRDF checks it"


def compare_with_srdf(matrix: CollisionMatrix, srdf: Srdf, name: str) -> SrdfComparison:
    """Precision, recall and each differing pair of ``matrix`` against ``srdf``."""
    geometry = set(matrix.bodies)
    reference: dict[tuple[str, str], str] = {}
    ignored = 0
    for d in srdf.disabled_collisions:
        if d.link1 in geometry and d.link2 in geometry and d.link1 != d.link2:
            reference.setdefault(pair_key(d.link1, d.link2), d.reason or "(no reason)")
        else:
            ignored += 1
    generated = {pair_key(e.link1, e.link2): e for e in matrix.disabled}
    precision, recall = compare_pairs(
        frozenset(frozenset(p) for p in generated), frozenset(frozenset(p) for p in reference)
    )
    first = {(a, b): s for a, b, s in matrix.first_collision}
    diffs: list[PairDifference] = []
    for key in sorted(generated.keys() - reference.keys()):
        e = generated[key]
        diffs.append(PairDifference(*key, "matrix only", e.reason, _matrix_why(e)))
    for key in sorted(reference.keys() - generated.keys()):
        start = first.get(key)
        why = (
            f"the matrix checks it: it collided (first in samples from {start:,})"
            if start is not None
            else "the matrix checks it: it collided in the sampled configurations"
        )
        diffs.append(PairDifference(*key, "SRDF only", reference[key], why))
    return SrdfComparison(
        srdf=name,
        precision=precision,
        recall=recall,
        reference_pairs=len(reference),
        generated_pairs=len(generated),
        ignored=ignored,
        differences=tuple(diffs),
    )
