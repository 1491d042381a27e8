"""Worker processes that leave Ctrl-C to ehm: SIGINT ignored while they are started (they inherit it), and one
thread each for the numerical libraries (their own thread pools would oversubscribe the cores).

Used by :mod:`ehm.interfaces.cluster` (Dask's local workers) and :mod:`ehm.routes.parallel` (a long run in segments on
local
processes); a leaf module, importing nothing of ehm.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading

#: Environment variables that keep the numerical libraries of a worker process to one thread each.
ONE_THREAD = {v: "1" for v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}


@contextlib.contextmanager
def environ_default(values: dict):
    """Environment variables set (where unset) while inside, as they were again on leaving."""

    added = [k for k in values if k not in os.environ]
    for k in added:
        os.environ[k] = values[k]
    try:
        yield
    finally:
        for k in added:
            os.environ.pop(k, None)


#: The terminal's signals, which it sends to the whole process group: Ctrl-C (SIGINT) and a closed terminal
#: (SIGHUP, where the system has it).  Worker processes ignore them: ehm's own process answers them and ends its
#: workers (a worker dying on its own left the pool's resource tracker printing tracebacks).
TERMINAL_SIGNALS = (signal.SIGINT,) + ((signal.SIGHUP,) if hasattr(signal, "SIGHUP") else ())


@contextlib.contextmanager
def sigint_ignored():
    """SIGINT (Ctrl-C) and SIGHUP (:data:`TERMINAL_SIGNALS`) ignored while inside; processes started inside keep
    ignoring them.  Outside the main thread (where signal handlers cannot be set) this does nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {s: signal.signal(s, signal.SIG_IGN) for s in TERMINAL_SIGNALS}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler if handler is not None else signal.SIG_DFL)


def ignore_sigint() -> None:
    """Ignore SIGINT and SIGHUP in this process (a worker's initialiser: ehm's own process answers them)."""
    for s in TERMINAL_SIGNALS:
        signal.signal(s, signal.SIG_IGN)
