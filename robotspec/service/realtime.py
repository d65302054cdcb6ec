"""The served driver's process, set up so that other threads disturb its loop the least.

``robotspec drive --serve`` owns its process, and in it one thread matters most: the driver
loop, which needs Python's interpreter lock for a moment every period. Everything else (Robot
Raconteur decoding a client's upload, the service converting and planning it, the publisher)
shares that lock. Two process-wide settings bound how long they can keep it from the loop:

* the garbage collector's full passes: everything loaded at start (numpy, pydantic, Robot
  Raconteur, the robot) is frozen out of its reach, so a pass only walks what was made since
  (a full pass over all of it took tens of milliseconds, holding the lock);
* the interpreter's switch interval: a thread running Python hands the lock to a waiting one
  after this long. The default, 5 ms, is half a period at 100 Hz and more than one at 250 Hz;
  it is set to a quarter of the loop's period (at least 0.5 ms), so a busy thread delays the
  loop by a fraction of a period, not by periods. Measured on 35,000 decoded waypoints: the
  99th percentile of the decoding thread's runs between two of another thread's turns fell
  from 6.4 ms to 2.3 ms at 1 ms (``benchmarks/bench_trajectory_upload.py`` measures the loop).
"""

from __future__ import annotations

import gc
import sys

__all__ = ["MIN_SWITCH_INTERVAL_S", "prepare_process"]

#: The shortest switch interval set (below it, handing the lock over costs more than it saves).
MIN_SWITCH_INTERVAL_S = 0.0005


def prepare_process(period: float) -> None:
    """Freeze what is loaded out of the collector's reach; switch interval <= period / 4.

    Only for a process that serves one driver (the CLI's own): both settings are global.
    Never raises the switch interval above what it already is.
    """
    gc.collect()
    gc.freeze()
    target = max(period / 4.0, MIN_SWITCH_INTERVAL_S)
    if target < sys.getswitchinterval():
        sys.setswitchinterval(target)
