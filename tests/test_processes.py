"""ehm.processes: worker processes no more than the machine holds (issue 38, item 5)."""

from __future__ import annotations

import pytest

import ehm
from ehm import processes
from ehm.errors import EhmWarning


@pytest.fixture
def two_cores(monkeypatch):
    """A machine of 2 cores and 8 GB of available memory (SYNTHETIC: whatever this one has)."""
    monkeypatch.setattr(processes, "usable_cores", lambda: 2)
    monkeypatch.setattr(processes, "available_memory_bytes", lambda: 8 << 30)


def test_workers_beyond_the_cores_are_capped_with_a_warning(two_cores):
    # issue 38: --workers 1000 on 2 cores started about 130 processes and had to be killed
    assert processes.capped_workers(2) == 2 and processes.capped_workers(1) == 1
    with pytest.warns(EhmWarning, match=r"1000 worker processes asked for \(--workers, workers=\), but this machine "
                                        r"holds 2 \(2 cores, 8.6 GB of memory available .*\); running 2\."):
        assert processes.capped_workers(1000) == 2


def test_workers_beyond_the_memory_are_capped(monkeypatch):
    monkeypatch.setattr(processes, "usable_cores", lambda: 64)
    monkeypatch.setattr(processes, "available_memory_bytes", lambda: 3 * processes.WORKER_MEMORY_BYTES + 1)
    assert processes.worker_limit()[0] == 3
    monkeypatch.setattr(processes, "available_memory_bytes", lambda: 1)  # nearly none: still one
    assert processes.worker_limit()[0] == 1
    monkeypatch.setattr(processes, "available_memory_bytes", lambda: None)  # the system does not say: the cores
    assert processes.worker_limit() == (64, "64 cores")


def test_this_machine_has_a_limit():
    limit, why = processes.worker_limit()
    assert limit >= 1 and "core" in why


def test_a_parallel_run_asking_for_too_many_workers_runs_on_what_the_machine_holds(two_cores, human):
    from ehm.routes.parallel import simulate_parallel

    motion = ehm.random_vibration("z", 4.0, 0.3, dt_s=0.001)
    with pytest.warns(EhmWarning, match="1000 worker processes asked for"):
        run = simulate_parallel(human, motion, workers=1000, lead_in_s=1.0)
    assert run.time_s[-1] == pytest.approx(4.0, abs=0.002)


def _blas_threads() -> int:
    from threadpoolctl import threadpool_info

    return max((i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"), default=1)


def test_a_routes_chunks_run_on_one_blas_thread_and_the_callers_code_as_it_was():
    from threadpoolctl import threadpool_limits

    seen = []

    def chunks():
        for k in range(3):
            seen.append(_blas_threads())
            yield k

    with threadpool_limits(limits=2, user_api="blas"):  # the caller's own setting, whatever the machine
        caller = _blas_threads()
        between = [(_blas_threads(), k) for k in processes.on_one_blas_thread(chunks())]
    assert seen == [1, 1, 1]
    assert [b for b, _ in between] == [caller] * 3 and [k for _, k in between] == [0, 1, 2]


def test_simulate_computes_on_one_blas_thread(human, monkeypatch):
    from ehm.routes import hybrid

    seen = []
    original = hybrid.block_chunk

    def watched(*args, **kwargs):
        seen.append(_blas_threads())
        return original(*args, **kwargs)

    from threadpoolctl import threadpool_limits

    monkeypatch.setattr(hybrid, "block_chunk", watched)  # the linear model's time run
    with threadpool_limits(limits=2, user_api="blas"):  # two threads as the caller's setting, whatever the machine
        caller = _blas_threads()
        if caller < 2:
            pytest.skip("this machine's BLAS runs one thread at most: nothing to limit")
        human.simulate(ehm.random_vibration("z", 2.0, 0.3, seed=1), method="linear")  # SYNTHETIC
        after = _blas_threads()
    assert seen and set(seen) == {1}
    assert after == caller  # the caller's setting back


def test_overlapping_uses_leave_the_blas_as_it_was():
    # two runs (two threads' chunks) whose uses overlap and end out of order: the first to leave must not give the
    # BLAS its threads back while the other is inside, and the last to leave gives back the caller's setting
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=2, user_api="blas"):
        before = _blas_threads()
        first, second = processes.one_blas_thread(), processes.one_blas_thread()
        first.__enter__()
        second.__enter__()
        first.__exit__(None, None, None)
        assert _blas_threads() == 1
        second.__exit__(None, None, None)
        assert _blas_threads() == before
