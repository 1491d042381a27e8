"""Worker processes that leave Ctrl-C to ehm: SIGINT ignored while they are started (they inherit it), one
thread each for the numerical libraries (their own thread pools would oversubscribe the cores), and no more of them
than the machine holds (:func:`capped_workers`); and the routes' own work on one BLAS thread (:func:`one_blas_thread`).

Used by :mod:`ehm.interfaces.cluster` (Dask's local workers) and :mod:`ehm.routes.parallel` (a long run in segments on
local
processes); a leaf module, importing nothing of ehm.
"""

from __future__ import annotations

import ast
import contextlib
import functools
import inspect
import os
import signal
import sys
import threading
import warnings

from threadpoolctl import ThreadpoolController

from .errors import EhmWarning

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


#: What one worker process holds, about [bytes]: Python, numpy, MuJoCo and ehm with a segment's run (measured: 150 MB
#: at the peak of a 10 s run of the default person, 170 MB with Dask loaded), with room for longer segments.
WORKER_MEMORY_BYTES = 400 << 20


def usable_cores() -> int:
    """The cores this process may run on (its CPU affinity where the system has one, else every core)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


def available_memory_bytes() -> int | None:
    """The memory the system can give without swapping [bytes] (Linux's MemAvailable, else the free physical
    pages), or None where it does not say."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (AttributeError, ValueError, OSError):
        return None


def worker_limit() -> tuple[int, str]:
    """How many worker processes this machine holds: its usable cores, and no more than its available memory at
    :data:`WORKER_MEMORY_BYTES` each (at least one); with the reason as words."""
    cores = usable_cores()
    memory = available_memory_bytes()
    by_memory = cores if memory is None else max(1, memory // WORKER_MEMORY_BYTES)
    why = f"{cores} core{'s' if cores != 1 else ''}"
    if memory is not None:
        why += (f", {memory / 1e9:.1f} GB of memory available at about {WORKER_MEMORY_BYTES / 1e9:.1f} GB per "
                "worker")
    return int(min(cores, by_memory)), why


def capped_workers(n: int) -> int:
    """``n`` worker processes, or as many as the machine holds (:func:`worker_limit`) when fewer, with a warning
    saying so (``--workers 1000`` on 2 cores started about 130 processes and had to be killed)."""
    limit, why = worker_limit()
    if n <= limit:
        return n
    warnings.warn(f"{n} worker processes asked for (--workers, workers=), but this machine holds {limit} ({why}); "
                  f"running {limit}.", EhmWarning, stacklevel=3)
    return limit


@functools.lru_cache(maxsize=1)
def _blas_controller() -> ThreadpoolController:
    """The thread pools of the BLAS libraries loaded (found once per process: a scan of the loaded libraries)."""
    return ThreadpoolController()


_blas_lock = threading.Lock()
_blas_users = [0, None]  # how many are inside one_blas_thread, and the limiter that restores the BLAS on leaving


@contextlib.contextmanager
def one_blas_thread():
    """The BLAS libraries (numpy's and scipy's OpenBLAS, MKL, ...) on one thread while inside, as they were once the
    last thread inside has left (threadpoolctl; the setting is the whole process's, so overlapping uses from
    several threads are counted).  The routes multiply small matrices (a linear model of about 60 states by a block
    of a few hundred samples), which a threaded BLAS spreads over threads that wait on each other and on whatever
    else runs: on this project's 2-core machine, 35 s of three-axis vibration on the linear route took 29.6 ms
    (median of 10) on one thread and 187 ms on two with the other core busy."""
    with _blas_lock:
        if _blas_users[0] == 0:
            _blas_users[1] = _blas_controller().limit(limits=1, user_api="blas")
        _blas_users[0] += 1
    try:
        yield
    finally:
        with _blas_lock:
            _blas_users[0] -= 1
            if _blas_users[0] == 0:
                _blas_users[1].restore_original_limits()
                _blas_users[1] = None


def on_one_blas_thread(chunks):
    """The chunks of a route's generator, each computed on one BLAS thread (:func:`one_blas_thread`); the caller's
    own code between chunks runs with the BLAS as it was."""
    chunks = iter(chunks)
    while True:
        with one_blas_thread():
            try:
                chunk = next(chunks)
            except StopIteration:
                return
        yield chunk


def _guarded_lines(path: str) -> list[tuple[int, int]]:
    """The line ranges of a script's ``if __name__ == "__main__":`` blocks."""
    try:
        with open(path, encoding="utf-8") as f:
            tree = ast.parse(f.read(), filename=path)
    except (OSError, SyntaxError, UnicodeDecodeError, ValueError):
        return []
    out = []
    for node in tree.body:
        if isinstance(node, ast.If) and isinstance(node.test, ast.Compare):
            names = [node.test.left, *node.test.comparators]
            if (any(isinstance(n, ast.Name) and n.id == "__name__" for n in names)
                    and any(isinstance(n, ast.Constant) and n.value == "__main__" for n in names)):
                out.append((node.lineno, node.end_lineno or node.lineno))
    return out


def unguarded_script_line() -> int | None:
    """The line of the ``__main__`` script's top-level code that is running now, when it runs outside an ``if
    __name__ == "__main__":`` block (else None: an interactive session, a notebook, a guarded call, a test runner).

    Worker processes are spawned: each imports the ``__main__`` script again, and so runs that line again (and
    whatever it starts) before doing its work.  ehm starts workers of its own accord only where that cannot happen."""
    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    if not path or main is None:
        return None
    frame = inspect.currentframe()
    while frame is not None:
        if frame.f_globals is vars(main) and frame.f_code.co_name == "<module>":
            line = frame.f_lineno
            if any(lo <= line <= hi for lo, hi in _guarded_lines(path)):
                return None
            return line
        frame = frame.f_back
    return None
