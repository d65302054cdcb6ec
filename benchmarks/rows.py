"""One benchmark row, printed as text or as JSON (``--json``), and the interleaved timing
shared by every benchmark.

JSON: one object per line with keys ``what``, ``ours_s``, ``peer``, ``peer_s``, ``ratio`` (peer
time / robotspec time; above 1 means robotspec is faster), so figures can be compared across
versions. ``peer_s`` and ``ratio`` are ``null`` for a row without a peer (a target, say).
"""

from __future__ import annotations

import argparse
import importlib.metadata as md
import json
import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Row:
    what: str
    ours_s: float
    peer: str
    peer_s: float | None

    @property
    def ratio(self) -> float | None:
        if self.peer_s is None or self.ours_s <= 0:
            return None
        return self.peer_s / self.ours_s

    def as_json(self) -> str:
        return json.dumps(
            {
                "what": self.what,
                "ours_s": self.ours_s,
                "peer": self.peer,
                "peer_s": self.peer_s,
                "ratio": self.ratio,
            }
        )


def add_json_flag(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--json", action="store_true", help="print each row as one JSON object per line"
    )


def fmt(t: float | None) -> str:
    if t is None:
        return "-"
    if t < 1e-3:
        return f"{t * 1e6:.2f} us"
    if t < 1:
        return f"{t * 1e3:.2f} ms"
    return f"{t:.2f} s"


def print_rows(rows: list[Row], as_json: bool, *, width: int = 44, peer_width: int = 48) -> None:
    """The rows as a table (or JSON lines)."""
    if as_json:
        for r in rows:
            print(r.as_json())
        return
    print(f"{'robotspec':{width}} {'time':>10}   {'peer':{peer_width}} {'time':>10}  {'ratio':>6}")
    for r in rows:
        ratio = "-" if r.ratio is None else f"{r.ratio:.2f}"
        print(
            f"{r.what:{width}} {fmt(r.ours_s):>10}   {r.peer:{peer_width}} "
            f"{fmt(r.peer_s):>10}  {ratio:>6}"
        )


def median_times(fns: Sequence[Callable[[], object]], repeat: int) -> list[float]:
    """Median wall time (seconds) of each function over ``repeat`` rounds, after a warm-up.

    Why rounds: the functions take turns (one call each per round), so a slow spell of this
    shared machine hits both sides of a ratio alike instead of one side's whole series.
    """
    for fn in fns:
        fn()
    times: list[list[float]] = [[] for _ in fns]
    for _ in range(repeat):
        for fn, out in zip(fns, times, strict=True):
            t = time.perf_counter()
            fn()
            out.append(time.perf_counter() - t)
    return [statistics.median(t) for t in times]


def erd_share() -> Path:
    """example-robot-data's share folder (``robots/`` inside); the benchmarks' real robot files."""
    share = md.distribution("example-robot-data").locate_file(
        "cmeel.prefix/share/example-robot-data"
    )
    return Path(str(share))
