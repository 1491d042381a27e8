"""Long runs and faithful records: simulate streams to disk in bounded memory, a run folder is one unit (no
stale or partial files after a failure, an interrupt or SIGTERM), and output locations are checked first.

All inputs are SYNTHETIC (generated random vibration or small hand-made drive files).
"""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

import ehm
from ehm.errors import InputError
from ehm.files import MANIFEST_NAME
from ehm.interfaces.cli import main
from ehm.outputs import outdir, runfiles
from ehm.outputs.outdir import RunFolder, check_output_folder, signals_held


def _one_error_line(err: str) -> str:
    lines = [ln for ln in err.replace("\r", "\n").splitlines() if ln.strip()]
    assert "Traceback" not in err
    assert lines[-1].startswith("ehm: error: "), err
    return lines[-1]


def _siblings(path: Path) -> list[str]:
    """Hidden staging leftovers of ``path`` in its parent."""
    return sorted(p.name for p in path.parent.iterdir() if p.name.startswith(f".{path.name}."))



# ------------------------------------------------------------------------------------------ run folders
def test_rerun_replaces_the_folder_whole(tmp_path, capsys):
    # a run with --plot, then one without: the old figure must not stay beside the new data
    out = tmp_path / "run"
    assert main(["simulate", "--duration", "1", "--plot", "--out", str(out)]) == 0
    assert (out / "time_histories.png").is_file()
    assert main(["simulate", "--duration", "2", "--method", "nonlinear", "--out", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST_NAME, "poses.npz", "summary.json", "timeseries.csv"]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["duration_s"] == pytest.approx(2.0)
    rows = np.loadtxt(out / "timeseries.csv", delimiter=",", skiprows=1)
    assert rows[-1, 0] == pytest.approx(2.0)  # every file describes the same (new) run
    assert np.load(out / "poses.npz")["time_s"][-1] <= 2.0 + 1e-9
    assert _siblings(out) == []


def test_failure_or_interrupt_inside_leaves_the_earlier_folder(tmp_path):
    out = tmp_path / "a" / "b" / "run"
    for exc in (InputError("bad"), KeyboardInterrupt()):
        with pytest.raises(type(exc)):
            with RunFolder(out) as tmp:
                (tmp / "summary.json").write_text("{}")
                raise exc
        assert not (tmp_path / "a").exists()  # neither the folder nor the parents made for it
    with RunFolder(out) as tmp:
        (tmp / "summary.json").write_text('{"run": 1}')
    with pytest.raises(KeyboardInterrupt):
        with RunFolder(out) as tmp:
            (tmp / "summary.json").write_text('{"run": 2}')
            (tmp / "timeseries.csv").write_text("time_s\n0\n")
            raise KeyboardInterrupt
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST_NAME, "summary.json"]
    assert json.loads((out / "summary.json").read_text()) == {"run": 1}
    assert _siblings(out) == []


def test_interrupted_simulate_keeps_the_earlier_run(tmp_path, human):
    out = tmp_path / "run"
    human.simulate_to(out, ehm.random_vibration("z", 1.0, 0.3, seed=0), chunk_s=0.5, method="nonlinear")
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    calls = []

    def interrupt(done_s, total_s):
        calls.append(done_s)
        if len(calls) == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        human.simulate_to(out, ehm.random_vibration("z", 3.0, 0.3, seed=1), chunk_s=0.5, progress=interrupt,
                          method="nonlinear")
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert _siblings(out) == []


@pytest.mark.parametrize("exchange", [True, False])
def test_swap_with_and_without_an_atomic_exchange(tmp_path, monkeypatch, exchange):
    # Linux exchanges the two folders in one step; elsewhere (or on file systems that cannot) two renames.

    if not exchange:
        monkeypatch.setattr(outdir, "_exchange", lambda a, b: False)
    out = tmp_path / "run"
    for n in (1, 2):
        with RunFolder(out) as tmp:
            (tmp / "summary.json").write_text(f'{{"run": {n}}}')
            (tmp / f"frf_{n}.csv").write_text("x")
        assert json.loads((out / "summary.json").read_text()) == {"run": n}
        assert sorted(p.name for p in out.iterdir()) == [MANIFEST_NAME, f"frf_{n}.csv", "summary.json"]
        assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]


def test_a_linked_run_folder_is_replaced_behind_its_link(tmp_path):
    real = tmp_path / "real"
    with RunFolder(real) as tmp:
        (tmp / "summary.json").write_text('{"run": 1}')
    (tmp_path / "link").symlink_to(real)
    with RunFolder(tmp_path / "link") as tmp:
        (tmp / "summary.json").write_text('{"run": 2}')
    assert (tmp_path / "link").is_symlink()
    assert json.loads((tmp_path / "link" / "summary.json").read_text()) == {"run": 2}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link", "real"]


def test_signals_are_held_while_a_folder_is_swapped():
    got = []
    previous = signal.signal(signal.SIGTERM, lambda *a: got.append("term"))
    try:
        with signals_held():
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.05)
            assert got == []  # not delivered inside
        time.sleep(0.05)
        assert got == ["term"]  # delivered on leaving
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_sigterm_during_a_file_write_leaves_no_temporary_file(tmp_path):
    # SIGTERM becomes cli.Terminated (a KeyboardInterrupt) in the command, so the atomic writer's clean-up runs
    from ehm.files import replace_atomically
    from ehm.interfaces.cli import Terminated

    def half_then_terminated(tmp):
        with open(tmp, "w") as fh:
            fh.write("x" * 100_000)
        raise Terminated()

    with pytest.raises(Terminated):
        replace_atomically(tmp_path / "drive.csv", half_then_terminated, "the drive file")
    assert list(tmp_path.iterdir()) == []


def test_stale_staging_of_a_dead_process_is_removed(tmp_path):
    # the staging folder is made and marked by a process that then ends (as a killed run leaves it)
    made = subprocess.run([sys.executable, "-c", "import os, sys, tempfile; from pathlib import Path; "
                           "from ehm import outdir; p = Path(tempfile.mkdtemp(prefix=f'.run.partial-{os.getpid()}-', "
                           "dir=sys.argv[1])); outdir._write_manifest(p, 'output', 'staging'); print(os.getpid(), p)",
                           str(tmp_path)], capture_output=True, text=True, check=True)
    pid, stale = made.stdout.split()
    (Path(stale) / "timeseries.csv").write_text("half a file")
    # an empty folder of that kind of name: no mark, kept (names prove nothing)
    empty = tmp_path / f".run.old-{pid}-def"
    empty.mkdir()
    lookalike = tmp_path / f".run.partial-{pid}-xyz"  # the same kind of name, but not ehm's: kept
    lookalike.mkdir()
    (lookalike / "notes.txt").write_text("keep me")
    with RunFolder(tmp_path / "run") as tmp:
        (tmp / "summary.json").write_text("{}")
    assert sorted(p.name for p in tmp_path.iterdir()) == [empty.name, lookalike.name, "run"]
    assert (lookalike / "notes.txt").read_text() == "keep me"


def test_output_location_is_checked_before_the_run(tmp_path, capsys):
    foreign = tmp_path / "mine"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("keep me")
    t0 = time.perf_counter()
    assert main(["simulate", "--duration", "600", "--out", str(foreign)]) == 2
    assert time.perf_counter() - t0 < 5  # refused before building, settling and running 600 s
    err = _one_error_line(capsys.readouterr().err)
    assert "notes.txt" in err and "ehm did not write" in err
    assert (foreign / "notes.txt").read_text() == "keep me"
    a_file = tmp_path / "file.txt"
    a_file.write_text("x")
    assert main(["simulate", "--duration", "600", "--out", str(a_file)]) == 2
    assert "is a file" in _one_error_line(capsys.readouterr().err)
    assert main(["assess", "--motion", "road", "--out", str(a_file / "sub")]) == 2
    assert "file.txt is a file, not a folder" in _one_error_line(capsys.readouterr().err)
    with pytest.raises(InputError, match="current folder"):
        check_output_folder(Path.cwd())


@pytest.mark.skipif(hasattr(os, "geteuid") and os.geteuid() == 0, reason="root may write anywhere")
def test_unwritable_output_folder_refused_before_the_run(tmp_path, capsys):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        assert main(["simulate", "--duration", "600", "--out", str(locked / "run")]) == 2
        assert "not writable" in _one_error_line(capsys.readouterr().err)
    finally:
        locked.chmod(0o700)


def test_failed_assess_leaves_no_folder(tmp_path, capsys):
    short = tmp_path / "short.csv"
    short.write_text("time_s,ax_mps2,ay_mps2,az_mps2\n0,0,0,0\n0.5,0,0,0.1\n1.0,0,0,0\n")
    out = tmp_path / "new" / "assessment"
    assert main(["assess", "--motion", str(short), "--out", str(out)]) == 2
    assert "at least 2 s" in _one_error_line(capsys.readouterr().err)
    assert not (tmp_path / "new").exists()


def test_sigterm_removes_temporary_files_and_keeps_the_earlier_run(tmp_path):
    out = tmp_path / "run"
    with RunFolder(out) as tmp:
        (tmp / "summary.json").write_text('{"earlier": true}\n')
    env = {**os.environ, "PYTHONPATH": str(Path(ehm.__file__).parents[1])}
    proc = subprocess.Popen([sys.executable, "-m", "ehm.interfaces.cli", "simulate", "--duration", "120", "--method",
                             "nonlinear", "--output-rate", "1000",
                             "--out", str(out)], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 120
    grown = False
    while time.time() < deadline and not grown:  # wait until the run is writing its time series
        time.sleep(0.2)
        staged = [p for p in tmp_path.iterdir() if p.name.startswith(".run.partial-")]
        grown = bool(staged) and (staged[0] / "timeseries.csv").is_file() and \
            (staged[0] / "timeseries.csv").stat().st_size > 100_000
    assert grown, "the run never started writing"
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    assert err.splitlines()[-1] == "ehm: terminated"  # on a line of its own, after the progress line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]  # no staging folder, no temporary file
    assert json.loads((out / "summary.json").read_text()) == {"earlier": True}


# ------------------------------------------------------------------------------------------- streaming
def _csv(path: Path) -> tuple[list[str], np.ndarray]:
    with open(path) as fh:
        header = next(csv.reader(fh))
    return header, np.loadtxt(path, delimiter=",", skiprows=1)


def _same(a, b, where: str, scale: float = 0.0) -> None:
    """Equal, floats to summation round-off: 1e-12 of the value or of ``scale`` (the largest component of the
    vector a float belongs to).  The summaries are means over ~3000 steps summed in another order (by chunks):
    error <= n eps max|term| = 3000 x 2.2e-16 = 6.7e-13 of the terms' size.  A component can be far smaller
    than its terms (the mean x support force, -1.08 N, is -74 + 101 - 27 N from the surfaces: measured error
    4.2e-13 N, 3.9e-13 of itself), so its size is not the right yardstick, the vector's is."""
    if isinstance(b, dict):
        assert set(a) == set(b), where
        for k in b:
            _same(a[k], b[k], f"{where}.{k}")
    elif isinstance(b, list):
        assert len(a) == len(b), where
        floats = [abs(y) for y in b if isinstance(y, float)]
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{where}[{i}]", max(floats, default=0.0))
    elif isinstance(b, float):
        assert a == pytest.approx(b, rel=1e-12, abs=1e-15 + 1e-12 * scale), where
    else:
        assert a == b, where


def test_streamed_run_equals_the_in_memory_run(tmp_path, human):
    motion = ehm.random_vibration("xz", 3.0, 0.3, seed=2)
    run = human.simulate(motion, pose_rate_hz=25.0, method="nonlinear")
    run.write(tmp_path / "memory")
    every_step_hz = 1 / human.model.mj.opt.timestep  # the in-memory run writes every step
    summary = human.simulate_to(tmp_path / "stream", motion, output_rate_hz=every_step_hz, chunk_s=0.25,
                                formats=("csv", "parquet"), method="nonlinear")
    streamed, in_memory = (tmp_path / "stream" / "timeseries.csv"), (tmp_path / "memory" / "timeseries.csv")
    assert streamed.read_bytes() == in_memory.read_bytes()
    pq = pytest.importorskip("pyarrow.parquet")
    table = pq.read_table(tmp_path / "stream" / "timeseries.parquet")
    header, data = run.columns()
    assert table.column_names == header
    assert np.array_equal(np.column_stack([table.column(h).to_numpy() for h in header]), data)  # exact
    with np.load(tmp_path / "memory" / "poses.npz") as a, np.load(tmp_path / "stream" / "poses.npz") as b:
        assert sorted(a.files) == sorted(b.files)
        for k in a.files:
            assert np.array_equal(a[k], b[k]), k
    expected = json.loads((tmp_path / "memory" / "summary.json").read_text())
    assert set(summary) == set(expected)
    for key, value in expected.items():
        if key not in ("wall_s", "realtime_factor"):  # sums over chunks in another order: equal to rounding
            _same(summary[key], value, key)
    # a lower output rate writes every k-th row; the summary still uses every step
    summary5 = human.simulate_to(tmp_path / "thin", motion, chunk_s=0.33, method="nonlinear")
    header, thin = _csv(tmp_path / "thin" / "timeseries.csv")
    k = runfiles.default_output_every(run.dt_s)
    assert summary5["output_rate_hz"] == pytest.approx(1 / (k * run.dt_s))
    assert summary5["output_rate_hz"] >= runfiles.DEFAULT_OUTPUT_RATE_HZ
    assert np.array_equal(thin, np.loadtxt(tmp_path / "memory" / "timeseries.csv", delimiter=",", skiprows=1)[::k])
    assert summary5["head_acc_rms_mps2"] == pytest.approx(expected["head_acc_rms_mps2"], rel=1e-12)


def test_chunks_reach_the_disk_as_they_are_computed(tmp_path, human):
    out = tmp_path / "run"
    sizes = []

    def look(done_s, total_s):
        staged = [p for p in tmp_path.iterdir() if p.name.startswith(".run.partial-")]
        sizes.append((staged[0] / "timeseries.csv").stat().st_size)
        assert not out.exists()  # the folder appears only when the run is whole

    human.simulate_to(out, ehm.random_vibration("z", 2.0, 0.3, seed=0), chunk_s=0.25, progress=look, method="nonlinear")
    assert len(sizes) == 9 and all(b > a for a, b in zip(sizes, sizes[1:]))  # t = 0 ... 2 s in 0.25 s chunks


def test_memory_does_not_grow_with_the_run(tmp_path, human, monkeypatch):
    # Bounded chunking with a small chunk (0.25 s) and Parquet row group (1000 rows): the peak of Python/numpy
    # allocations of a run 4 times longer stays within 25 % (the motion itself, made before, is not counted),
    # while the in-memory run grows with it (checked, so that the measure can tell).
    pytest.importorskip("pyarrow")
    monkeypatch.setattr(runfiles, "_ROW_GROUP_ROWS", 1000)
    human.simulate_to(tmp_path / "warm", ehm.random_vibration("z", 1.0, 0.3, seed=0), formats=("csv", "parquet"),
                      method="nonlinear")
    peaks = {}
    for how in ("stream", "memory"):
        for dur in (4.0, 16.0):
            motion = ehm.random_vibration("z", dur, 0.3, seed=0)
            tracemalloc.start()
            if how == "stream":
                human.simulate_to(tmp_path / f"r{dur:g}", motion, output_rate_hz=1000, chunk_s=0.25,
                                  formats=("csv", "parquet"), method="nonlinear")
            else:
                human.simulate(motion, pose_rate_hz=25.0, method="nonlinear")
            peaks[how, dur] = tracemalloc.get_traced_memory()[1]
            tracemalloc.stop()
    assert peaks["stream", 16.0] < 1.25 * peaks["stream", 4.0], peaks
    assert peaks["memory", 16.0] > 2 * peaks["memory", 4.0], peaks


@pytest.mark.filterwarnings("always::ehm.errors.EhmWarning")  # the command line prints them: read on stderr
def test_output_rate_must_divide_the_model_rate(tmp_path, capsys):
    for rate, words in (("300", "does not divide the model's 1000 Hz"), ("0", "above 0"), ("2000", "at most")):
        assert main(["simulate", "--duration", "1", "--dt", "0.001", "--output-rate", rate,
                     "--out", str(tmp_path / "r")]) == 2
        assert words in _one_error_line(capsys.readouterr().err)
    assert not (tmp_path / "r").exists()
    assert main(["simulate", "--duration", "1", "--dt", "0.002", "--out", str(tmp_path / "r")]) == 0
    capsys.readouterr()
    assert json.loads((tmp_path / "r" / "summary.json").read_text())["output_rate_hz"] == 250.0  # 500 Hz / 2


def test_plot_of_a_long_run_uses_a_bounded_preview(tmp_path, human, monkeypatch):
    from ehm.outputs import plotting

    monkeypatch.setattr(runfiles, "PREVIEW_ROWS", 200)
    drawn = {}
    real = plotting.plot_time_histories

    def spy(run, path=None, title=None):
        drawn.update(rows=len(run.time_s), title=title)
        return real(run, path, title=title)

    monkeypatch.setattr(plotting, "plot_time_histories", spy)
    human.simulate_to(tmp_path / "run", ehm.random_vibration("z", 2.0, 0.3, seed=0), chunk_s=0.5,
                      plot=plotting.plot_run_preview, method="nonlinear")
    dt = float(human.params.value("simulation.dt_s"))
    every = -(-(int(round(2.0 / dt)) + 1) // 200)  # ceil(steps / rows): 11 at 1 ms
    assert drawn["rows"] <= 200 and f"figure: every {every * dt:g} s" in drawn["title"]
    assert (tmp_path / "run" / "time_histories.png").stat().st_size > 0


def test_progress_line_ends_before_an_error(tmp_path, capsys, monkeypatch):
    # A drive that is calm for 10.5 s and then shakes the seat far beyond anything seated: the run diverges in its
    # second 10 s chunk, after the progress line has started (on a terminal: a pipe gets no bar, issue 32).  (400
    # m/s^2 at 4 Hz, six whole periods: a constant 400 m/s^2 for 1.5 s, a mean z of 50 m/s^2, is refused on reading
    # as an offset.)
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    t = np.round(np.arange(0, 12.0001, 0.01), 2)
    az = np.where(t > 10.5, 400.0 * np.sin(2 * np.pi * 4.0 * (t - 10.5)), 0.0)
    path = tmp_path / "violent.csv"
    path.write_text("time_s,ax_mps2,ay_mps2,az_mps2\n" + "".join(f"{a:g},0,0,{z:g}\n" for a, z in zip(t, az)))
    assert main(["simulate", "--motion", str(path), "--out", str(tmp_path / "run")]) == 2
    err = capsys.readouterr().err
    assert "simulate [" in err  # the progress line was shown
    line = _one_error_line(err)
    assert "\r" not in err.splitlines()[-1] and "diverged at t = 1" in line
    assert not (tmp_path / "run").exists()
