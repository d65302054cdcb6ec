"""``robotspec drive --sim`` (not served) ends on SIGTERM as it does on Ctrl-C.

Before: the default SIGTERM killed the process on the spot, so the summary was never printed and
a ``--log`` could end mid-row. The drive runs as a subprocess (signals are process-wide) and the
signal goes to that child by its handle.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from .driver_support import RRP


@pytest.mark.parametrize(("sig", "said"), [(signal.SIGTERM, "SIGTERM"), (signal.SIGINT, "Ctrl-C")])
def test_signal_ends_a_drive_with_its_summary_and_a_whole_log(
    tmp_path: Path, sig: signal.Signals, said: str
) -> None:
    log = tmp_path / "states.jsonl"
    proc = subprocess.Popen(
        [sys.executable, "-m", "robotspec", "drive", "--sim", str(RRP), "--log", str(log)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        # Bounds for a hang only (a busy machine takes seconds to start Python; issue 31).
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and (not log.exists() or log.stat().st_size < 4096):
            time.sleep(0.05)  # running: the log grows
        assert proc.poll() is None, proc.communicate()
        proc.send_signal(sig)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()  # only our own child, by its handle
            proc.communicate()
    assert proc.returncode == 0, err
    assert f"stopped by {said} after" in out
    assert "Traceback" not in err
    rows = [json.loads(line) for line in log.read_text(encoding="utf-8").splitlines()]
    assert rows and f"wrote {len(rows)} states to" in out  # every row whole, the count told


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_inside_a_logged_state_waits_until_the_row_is_written(
    tmp_path: Path, sig: signal.Signals
) -> None:
    """The race of the old log, made certain: the signal arrives while a row is being logged."""
    import os

    from robotspec.cli.driving import _Guarded, _StopSignals

    written: list[int] = []

    def listener(state: object) -> None:
        os.kill(os.getpid(), sig)  # delivered at the next bytecode, inside the listener
        written.append(1)  # the row completes all the same

    with _StopSignals() as signals:
        guarded = _Guarded(listener, signals)  # type: ignore[arg-type]
        with pytest.raises(KeyboardInterrupt):
            guarded(None)  # type: ignore[arg-type]
        assert written == [1]
        if sig == signal.SIGINT:
            with pytest.raises(KeyboardInterrupt):  # outside a row: at once, as before
                os.kill(os.getpid(), sig)
                time.sleep(1)
        else:  # a second SIGTERM would kill, as SIGTERM does
            assert signal.getsignal(sig) == signal.SIG_DFL
    said = "SIGTERM" if sig == signal.SIGTERM else "Ctrl-C"
    assert signals.received == [said] * (2 if sig == signal.SIGINT else 1)
    assert signal.getsignal(sig) is not signals._on_signal  # handlers given back
