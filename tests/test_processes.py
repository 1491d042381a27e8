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
