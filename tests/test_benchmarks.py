"""Every benchmark can print its rows as JSON (``--json``), with the same keys (no timing here)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


@pytest.mark.parametrize("path", sorted(BENCHMARKS.glob("bench_*.py")), ids=lambda p: p.name)
def test_every_benchmark_offers_json(path: Path) -> None:
    text = path.read_text(encoding="utf-8")
    assert "add_json_flag(" in text and "print_rows(" in text, f"{path.name} lacks --json"


def test_row_json_keys(capsys: pytest.CaptureFixture[str]) -> None:
    sys.path.insert(0, str(BENCHMARKS))
    try:
        from rows import Row, print_rows
    finally:
        sys.path.remove(str(BENCHMARKS))
    print_rows([Row("a", 2.0, "peer", 4.0), Row("b", 1.0, "target", None)], True)
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [set(r) for r in lines] == [{"what", "ours_s", "peer", "peer_s", "ratio"}] * 2
    assert lines[0]["ratio"] == 2.0 and lines[1]["ratio"] is None
