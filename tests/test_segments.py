"""A long nonlinear run in segments on local processes (ehm.routes.parallel), against one continuous run.

Every motion here is SYNTHETIC (generated random vibration and the generated city drive).
"""

from __future__ import annotations

import numpy as np
import pytest

import ehm
from ehm.errors import InputError
from ehm.interfaces.cli import main
from ehm.outputs.results import concatenate_runs
from ehm.routes import parallel as segments
from ehm.routes.parallel import Span, plan_segments, simulate_parallel, stream_parallel
from ehm.standards.comfort import total_value

POINTS = tuple(ehm.engine.POINTS)


@pytest.fixture(autouse=True)
def no_start_up(monkeypatch):
    """Segments of equal work on these short motions (the first segment is not made longer by a worker's start-up,
    which would make it the whole run)."""
    monkeypatch.setattr(segments, "WORKER_START_S", 0.0)



@pytest.fixture(scope="module")
def vibration():
    return ehm.random_vibration("xyz", 12.0, 0.5, seed=3)  # SYNTHETIC


@pytest.fixture(scope="module")
def continuous(human, vibration):
    return human.simulate(vibration, method="nonlinear")


def _share(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean((a - b) ** 2)) / np.sqrt(np.mean(a ** 2)))


def test_plan_covers_the_run_in_aligned_segments_of_equal_work():
    segs = plan_segments(100_001, 2, 5_000, align_steps=2_000)
    assert segs[0] == Span(0, segs[0].stop, 0) and segs[-1].stop == 100_001
    assert all(a.stop == b.first for a, b in zip(segs, segs[1:]))  # no gap, no overlap
    assert all(s.first % 2_000 == 0 for s in segs) and segs[1].lead_steps == 5_000
    assert abs(segs[0].work_steps - segs[1].work_steps) <= 2_000  # the first is longer by about the lead-in
    assert len(plan_segments(3_000, 4, 1_000, align_steps=2_000)) == 2  # never more segments than chunks
    assert plan_segments(10_000, 2, 8_000, align_steps=1_000)[1].lead_steps <= 8_000
    longer = plan_segments(100_001, 2, 5_000, align_steps=1_000, first_extra_steps=10_000)
    assert longer[0].stop - segs[0].stop in (4_000, 5_000, 6_000)  # half the start-up's steps more


def test_a_short_motion_runs_as_one_segment_here(human, vibration, continuous, monkeypatch):
    monkeypatch.setattr(segments, "WORKER_START_S", 1.5)  # 12 s: fewer steps than this process makes meanwhile
    stats = {}
    run = concatenate_runs(list(stream_parallel(human, vibration, workers=2, _stats=stats)))
    assert len(stats["segments"]) == 1
    np.testing.assert_array_equal(run.point("head").acc_mps2, continuous.point("head").acc_mps2)


def test_segmented_run_joins_onto_the_continuous_time_axis(human, vibration, continuous):
    stats = {}
    seg = concatenate_runs(list(stream_parallel(human, vibration, workers=2, lead_in_s=2.0, chunk_s=2.0,
                                                _stats=stats)))
    first, second = stats["segments"]
    assert second.first > 0 and second.lead_steps == 2000
    np.testing.assert_array_equal(seg.time_s, continuous.time_s)  # same axis: no gap, no repeated sample
    assert np.all(np.diff(seg.time_s) > 0)
    np.testing.assert_array_equal(seg.seat_acc_mps2, continuous.seat_acc_mps2)
    assert set(seg.points) == set(continuous.points) and set(seg.support_N) == set(continuous.support_N)
    k = second.first
    for p in POINTS:  # the first segment is the continuous run's start bit for bit, the rest close to it
        np.testing.assert_array_equal(seg.point(p).acc_mps2[:k], continuous.point(p).acc_mps2[:k])
        assert _share(continuous.point(p).acc_mps2, seg.point(p).acc_mps2) < 0.02


def test_one_worker_is_the_continuous_run_bit_for_bit(human, vibration, continuous):
    one = simulate_parallel(human, vibration, workers=1)
    np.testing.assert_array_equal(one.time_s, continuous.time_s)
    for p in POINTS:
        for f in ("acc_mps2", "disp_m", "rot_rad", "gia_mps2"):
            np.testing.assert_array_equal(getattr(one.point(p), f), getattr(continuous.point(p), f))


def test_rotating_seat_segment_starts_level_and_joins():
    drive = ehm.city_drive(16.0, seed=2)  # SYNTHETIC, with yaw, pitch and roll of the seat
    human = ehm.SeatedHuman(rotating_seat=True)
    cont = human.simulate(drive, method="nonlinear")
    seg = simulate_parallel(human, drive, workers=2, lead_in_s=3.0)
    np.testing.assert_array_equal(seg.time_s, cont.time_s)
    np.testing.assert_array_equal(seg.seat_angles_rad, cont.seat_angles_rad)  # the drive's attitude, reported
    for p in POINTS:
        assert _share(cont.point(p).acc_mps2, seg.point(p).acc_mps2) < 0.05


@pytest.mark.parametrize("kw, words", [
    ({"workers": 0}, "workers must be a whole number"),
    ({"workers": 1.5}, "workers must be a whole number"),
    ({"lead_in_s": -1.0}, "lead_in_s must be a time"),
    ({"segment_s": 0.0}, "segment_s must be a positive time"),
    ({"lead_in_s": float("nan")}, "lead_in_s must be a time"),
])
def test_bad_arguments_are_one_sentence(human, vibration, kw, words):
    with pytest.raises(InputError, match=words) as err:
        simulate_parallel(human, vibration, **kw)
    assert str(err.value).count(". ") == 0 and str(err.value).endswith(".")


def test_wrong_motion_or_seat_is_refused(human):
    with pytest.raises(InputError, match="needs a SeatMotion"):
        simulate_parallel(human, np.zeros((10, 3)))
    with pytest.raises(InputError, match="rotating_seat=True"):
        simulate_parallel(human, ehm.city_drive(12.0))  # SYNTHETIC drive with rates, static seat


@pytest.mark.parametrize("extra, words", [
    (["--workers", "0"], "--workers 0: use 1 or more"),
    (["--lead-in", "5", "--method", "linear"], "the linear route runs in one process"),
    (["--workers", "2", "--method", "linear"], "the linear route runs in one process"),
    (["--scheduler", "tcp://127.0.0.1:1", "--method", "linear"], "add --method nonlinear (the linear route runs"),
    (["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "not both"),
    (["--workers", "2", "--method", "nonlinear", "--lead-in", "-1"], "--lead-in -1.0: give the lead-in in seconds"),
    (["--scheduler", "tcp://127.0.0.1:1"], "add --method nonlinear (the auto route, the default, runs in one process)"),
])
def test_cli_parallel_options_are_checked_in_one_sentence(tmp_path, capsys, extra, words):
    code = main(["simulate", "--duration", "2", "--out", str(tmp_path / "run"), *extra])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "Traceback" not in err and err.count("\n") == 0 and words in err
    assert not (tmp_path / "run").exists()


def test_assess_in_segments_keeps_the_figures(human, vibration):
    one = ehm.assess(vibration, human, method="nonlinear")
    two = ehm.assess(vibration, human, method="nonlinear", workers=2, lead_in_s=2.0)
    with pytest.raises(InputError, match="a Dask client runs the nonlinear route in segments"):
        ehm.assess(vibration, human, client=object())  # the hybrid route, the default, runs in one process
    for p in POINTS:
        assert abs(two.total_value(p) / one.total_value(p) - 1) < 0.01
        assert abs(two.metrics[p]["z"].vdv / one.metrics[p]["z"].vdv - 1) < 0.01
    assert two.trace_time_s.size == one.trace_time_s.size


def test_a_rebuilt_person_is_the_same_person(human):
    # A worker's person, rebuilt from the recipe, has the same settled state and linearises as the original.
    from ehm import SeatedHuman

    again = SeatedHuman.from_recipe(human.recipe())
    np.testing.assert_array_equal(again.model.settled["qpos"], human.model.settled["qpos"])
    np.testing.assert_array_equal(again.linear_model().A, human.linear_model().A)


def test_the_default_number_of_processes_follows_the_drive_and_the_machine(monkeypatch):
    from ehm.routes import parallel

    monkeypatch.setattr(parallel, "worker_limit", lambda: (16, "16 cores"))
    assert parallel.default_workers(parallel.DEFAULT_SEGMENTS_FROM_S - 1) == 1  # a short drive: one process
    assert parallel.default_workers(parallel.DEFAULT_SEGMENTS_FROM_S) == parallel.MAX_DEFAULT_WORKERS
    monkeypatch.setattr(parallel, "worker_limit", lambda: (2, "2 cores"))
    assert parallel.default_workers(600.0) == 2
    monkeypatch.setattr(parallel, "worker_limit", lambda: (1, "1 core"))
    assert parallel.default_workers(600.0) == 1


def _in_a_child_process(queue):
    from ehm.routes import parallel

    queue.put(parallel.default_workers(3600.0))


def test_inside_a_worker_process_a_long_drive_stays_in_that_process():
    import multiprocessing

    ctx = multiprocessing.get_context("spawn")
    queue = ctx.Queue()
    p = ctx.Process(target=_in_a_child_process, args=(queue,))
    p.start()
    got = queue.get(timeout=120)
    p.join(30)
    assert got == 1


@pytest.mark.parametrize("method, workers, expected", [
    ("nonlinear", None, 2),  # a long drive: the machine's cores
    ("nonlinear", 1, None),  # workers=1: one process
    ("auto", None, 2),       # the hybrid route's drive that runs nonlinear from its start: the same
    ("auto", 1, None),
])
def test_a_long_drive_goes_on_the_cores_unless_told_otherwise(human, monkeypatch, method, workers, expected):
    from ehm.routes import hybrid, nonlinear, parallel, registry

    calls = []

    def spy(person, motion, workers=2, chunk_s=10.0, progress=None, pose_rate_hz=None, **kw):
        calls.append(workers)  # then the continuous run, so that no process is started here
        return nonlinear.stream_span(person, motion, chunk_s=chunk_s, pose_rate_hz=pose_rate_hz)

    monkeypatch.setattr(parallel, "DEFAULT_SEGMENTS_FROM_S", 10.0)
    monkeypatch.setattr(parallel, "worker_limit", lambda: (2, "2 cores"))
    monkeypatch.setattr(registry.parallel, "stream_parallel", spy)
    monkeypatch.setattr(hybrid, "stream_parallel", spy)
    from dataclasses import replace

    # SYNTHETIC; its manoeuvres send the hybrid route nonlinear from the start (the seat's turns left out)
    drive = replace(ehm.city_drive(20.0, seed=0), angvel_radps=None)
    run = human.simulate(drive, method=method, workers=workers)
    assert calls == ([] if expected is None else [expected])
    assert run.time_s[-1] == pytest.approx(20.0, abs=0.002)
    if method == "auto":
        assert run.extra["route"]["nonlinear_from_start"]
        assert ("in segments on 2 processes" in run.extra["route"]["fallback"]) == (expected is not None)


def test_the_hybrid_routes_rest_of_a_drive_goes_on_the_cores(human, monkeypatch):
    # 1 m/s^2 on three axes: the windows cover most of the drive, and after a third of it the rest goes to the
    # nonlinear model; asked for two processes, this one goes on from its state and a worker takes the last part
    monkeypatch.setattr(segments, "WORKER_START_S", 0.0)  # segments of equal work, so that there are two here
    motion = ehm.random_vibration("xyz", 45.0, 1.0, seed=0, dt_s=0.001)  # SYNTHETIC
    one = human.simulate(motion, workers=1)
    two = human.simulate(motion, workers=2)
    assert "in segments on 2 processes" in two.extra["route"]["fallback"]
    assert "in segments" not in one.extra["route"]["fallback"]
    np.testing.assert_array_equal(one.time_s, two.time_s)
    assert two.extra["route"]["nonlinear_s"] == pytest.approx(one.extra["route"]["nonlinear_s"], abs=0.002)
    for p in POINTS:
        assert total_value(*two.point(p).acc_mps2.T, 1000.0) == pytest.approx(
            total_value(*one.point(p).acc_mps2.T, 1000.0), rel=0.01), p


_SCRIPT = """
import ehm
from ehm.routes import parallel
parallel.worker_limit = lambda: (2, "2 cores")
parallel.DEFAULT_SEGMENTS_FROM_S = 1.0
{body}
"""


@pytest.mark.parametrize("guarded", [False, True])
def test_a_script_without_a_main_guard_keeps_one_process_and_says_why(tmp_path, guarded):
    import subprocess
    import sys

    body = "print('workers', parallel.default_workers(5.0))"
    if guarded:
        body = "if __name__ == '__main__':\n    " + body
    script = tmp_path / "drive.py"
    script.write_text(_SCRIPT.format(body=body))
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    if guarded:
        assert "workers 2" in done.stdout and "EhmWarning" not in done.stderr
    else:
        assert "workers 1" in done.stdout
        assert "calls ehm at its top level (line 6 of" in done.stderr and "if __name__ == " in done.stderr


def test_the_environment_caps_the_default_and_a_bad_value_is_one_sentence(monkeypatch):
    monkeypatch.setattr(segments, "worker_limit", lambda: (16, "16 cores"))
    monkeypatch.setenv("EHM_WORKERS", "3")
    assert segments.default_workers(3600.0) == 3
    monkeypatch.setenv("EHM_WORKERS", "1")
    assert segments.default_workers(3600.0) == 1
    monkeypatch.setenv("EHM_WORKERS", "many")
    with pytest.raises(InputError, match=r"EHM_WORKERS='many' in the environment: give the most processes"):
        segments.default_workers(3600.0)


def test_workers_as_numpy_integers_and_the_linear_routes_refusal():
    from ehm.routes.registry import choose

    route, options = choose("nonlinear", workers=np.int64(2))
    assert route.name == "parallel" and options["workers"] == 2
    with pytest.raises(InputError, match="the linear route runs in one process"):
        choose("linear", workers=2)
    with pytest.raises(InputError, match="the linear route runs in one process"):
        choose("linear", lead_in_s=5.0)
    assert choose("auto", lead_in_s=5.0)[1]["lead_in_s"] == 5.0
