"""Dask clusters for batch studies: a local cluster of single-threaded worker processes that leave Ctrl-C to ehm,
or an existing scheduler's address checked before use; closed quietly after an interrupt or an error.
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing
import time

from ..errors import InputError
from ..processes import ONE_THREAD, capped_workers, worker_limit
from ..processes import environ_default as _environ_default
from ..processes import sigint_ignored as _sigint_ignored


@contextlib.contextmanager
def dask_client(scheduler: str | None, workers: int | None):
    """A Dask client of the cluster at ``scheduler``, or of a local cluster of ``workers`` processes; closed on
    leaving, quietly when leaving on an interrupt or error.

    The local worker processes start with SIGINT ignored: a terminal's Ctrl-C goes to the whole process group,
    and only ehm itself should answer it (by closing the cluster), not every worker with its own traceback.
    """
    client = cluster = None
    try:
        if scheduler:
            client = _connect(check_scheduler(scheduler))
        else:
            # one thread per worker process: numerical libraries' own thread pools would oversubscribe the
            # cores (measured here: two workers ran no faster than one until this was set); the workers inherit
            # it when they start, and the calling process gets its own settings back
            with _environ_default(ONE_THREAD):
                cluster, client = _local_cluster(workers)
        yield client
    except BaseException:
        _close_quietly(client, cluster)
        raise
    else:
        _close(client, cluster)


def _local_cluster(workers: int | None):
    """A local Dask cluster of single-threaded worker processes (their own log silenced: a run's failure is
    recorded with the run, and a worker whose scheduler closes on Ctrl-C would otherwise print its heartbeat's
    traceback) and its client, once the workers have joined.

    The scheduler and the client start first, without workers; the worker processes are then spawned while
    ehm ignores SIGINT, which they inherit (processes cannot inherit a Python handler or a blocked signal), and
    ehm answers Ctrl-C again as soon as they exist (a few hundredths of a second), also while they start up.
    """
    from dask.distributed import Client, LocalCluster

    n = capped_workers(workers) if workers else worker_limit()[0]
    # no dashboard, and the scheduler's HTTP server (it runs one even so) on any free port: on its default, 8787,
    # a second cluster on the machine made distributed warn that the port is in use
    cluster = LocalCluster(n_workers=0, threads_per_worker=1, processes=True, dashboard_address=None,
                           scheduler_kwargs={"dashboard_address": ":0"}, silence_logs=logging.CRITICAL)
    client = None
    try:
        with _sigint_ignored():  # the client while there are no workers yet (it connects at once)
            client = Client(cluster)
            before = set(multiprocessing.active_children())
            cluster.scale(n)
            _wait_for_processes(before, n)
        client.wait_for_workers(n)
        return cluster, client
    except BaseException:
        _close_quietly(client, cluster)
        raise


def _wait_for_processes(before: set, n: int, timeout_s: float = 10.0) -> None:
    """Wait until ``n`` child processes besides ``before`` exist (the Dask workers just spawned), or the time is
    up (then any worker that comes later merely answers Ctrl-C itself)."""
    end = time.monotonic() + timeout_s
    while len(set(multiprocessing.active_children()) - before) < n and time.monotonic() < end:
        time.sleep(0.01)


def _close(client, cluster) -> None:
    if client is not None:
        client.close()
    if cluster is not None:
        cluster.close()


def _close_quietly(client, cluster) -> None:
    """Close after an interrupt or error: Dask's own log of the cancelled work and the closing workers (the
    study's records are complete up to here) stays out of the terminal; a second Ctrl-C meanwhile is ignored."""
    log = logging.getLogger("distributed")
    level = log.level
    log.setLevel(logging.CRITICAL)
    try:
        with _sigint_ignored(), contextlib.suppress(Exception):
            _close(client, cluster)
    finally:
        log.setLevel(level)


def check_scheduler(address: str) -> str:
    """A Dask scheduler address as ``tcp://HOST:PORT`` (or another Dask protocol), checked for its form."""
    from urllib.parse import urlsplit

    text = str(address).strip()
    try:
        parts = urlsplit(text if "://" in text else f"tcp://{text}")
        port = parts.port
    except ValueError:
        parts, port = None, None
    if parts is None or parts.scheme not in ("tcp", "tls", "inproc", "ucx", "ws", "wss") or not parts.hostname \
            or (port is None and parts.scheme != "inproc"):
        raise InputError(f"--scheduler {address!r}: give a Dask scheduler address such as tcp://HOST:PORT "
                         "(e.g. tcp://127.0.0.1:8786).")
    return text if "://" in text else f"tcp://{text}"


def _connect(address: str):
    """A client of the scheduler at ``address``, or one sentence saying why not."""
    from dask.distributed import Client

    try:
        return Client(address, timeout="10s")
    except (OSError, TimeoutError, ValueError) as exc:
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise InputError(f"cannot reach the Dask scheduler at {address} ({reason}); start one with "
                         "'dask scheduler' or leave out --scheduler for a local cluster.") from None
