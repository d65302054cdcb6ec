"""SDT builds one at a time, and never on a thread that will exit.

Why: SDT is not thread-safe (its worlds share krrood's global symbol graph; four threads
building robots at once failed about three times in eight, SDT's own ``from_world`` too), so
builds are serialised by one lock. And the first SDT build of a process leaves the thread it
ran on unable to finish: the thread's Python code returns, but its ``join()`` never does (some
native library's per-thread state, measured with SDT 26.7: four worker threads, each
``to_sdt`` done, every join hanging; with one build in the main thread first, none hangs). So a
build asked for by any thread but the main thread runs on one long-lived daemon thread of this
module, which never exits before the process does; the caller waits for its result.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any, TypeVar

__all__ = ["run"]

T = TypeVar("T")

#: Serialises every SDT build (re-entrant: a build may build classes inside it).
_LOCK = threading.RLock()
#: The builder thread and its queue, made on first use (guarded by ``_LOCK``).
_BUILDER: list[tuple[threading.Thread, queue.SimpleQueue[Any]]] = []


def _serve(jobs: queue.SimpleQueue[Any]) -> None:
    while True:
        fn, future = jobs.get()
        if not future.set_running_or_notify_cancel():
            continue
        try:
            with _LOCK:
                result = fn()
        except BaseException as exc:  # noqa: BLE001 - handed to the caller, who re-raises it
            future.set_exception(exc)
        else:
            future.set_result(result)


def _builder() -> tuple[threading.Thread, queue.SimpleQueue[Any]]:
    with _LOCK:
        if not _BUILDER:
            jobs: queue.SimpleQueue[Any] = queue.SimpleQueue()
            thread = threading.Thread(
                target=_serve, args=(jobs,), name="robotspec-sdt-builder", daemon=True
            )
            thread.start()
            _BUILDER.append((thread, jobs))
        return _BUILDER[0]


def run(fn: Callable[[], T]) -> T:
    """``fn()`` under the SDT lock: in this thread if it is the main one, else on the builder."""
    current = threading.current_thread()
    if current is threading.main_thread() or (_BUILDER and current is _BUILDER[0][0]):
        with _LOCK:
            return fn()
    _, jobs = _builder()
    future: Future[T] = Future()
    jobs.put((fn, future))
    return future.result()
