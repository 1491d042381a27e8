"""Batch studies on Dask: a tidy table, recorded failures, resuming."""

from __future__ import annotations

import json
import os

import pytest

pytest.importorskip("dask.distributed")
pq = pytest.importorskip("pyarrow.parquet")

from ehm.errors import InputError  # noqa: E402
from ehm.interfaces.batch import load_study, run_study  # noqa: E402
from ehm.interfaces.cli import main  # noqa: E402
from ehm.outputs.outdir import record_in_manifest  # noqa: E402

STUDY = """
[study]
name = "small"
compute = ["transmissibility"]
[people]
stature_m = [1.60, 1.85]
mass_kg = [55.0, 90.0]
[grid]
"joints.t12.z.stiffness_N_per_m" = [15000.0, -1.0]
[input]
axes = ["z"]
"""


def test_study_runs_records_failures_and_resumes(tmp_path, capsys):
    path = tmp_path / "study.toml"
    path.write_text(STUDY)
    name, specs = load_study(path)
    assert name == "small" and len(specs) == 4 and len({s.run_id for s in specs}) == 4
    out = tmp_path / "res"
    res = run_study(specs, out, workers=2)
    assert res["ran"] == 4 and res["failed"] == 2  # the negative stiffness fails, the study goes on
    table = pq.read_table(out / "results.parquet").to_pylist()
    errors = [r for r in table if r["output"] == "error"]
    assert len(errors) == 2 and all("must not be negative" in r["error"] for r in errors)
    ok = [r for r in table if r["output"] == "seat_z->head_z.peak_hz"]
    assert len(ok) == 2 and {r["stature_m"] for r in ok} == {1.60, 1.85}
    # the taller person's vertical mode is lower (Hof scaling: f ~ 1 / sqrt(L))
    by_height = {r["stature_m"]: r["value"] for r in ok}
    assert by_height[1.85] < by_height[1.60]
    # resume: nothing is redone; a lost record is redone alone
    assert run_study(specs, out, workers=1)["ran"] == 0
    (out / "runs" / f"{specs[0].point_id}.json").unlink()
    assert run_study(specs, out, workers=1)["ran"] == 1
    assert len(pq.read_table(out / "results.parquet").to_pylist()) == len(table)
    # failures are kept on resume unless retried; a lost worker's run is always redone
    res = run_study(specs, out, workers=1, retry_failed=True)
    assert res["ran"] == 2 and res["failed"] == 2
    failed = next(s for s in specs if s.run_id == errors[0]["run_id"])
    rec_path = out / "runs" / f"{failed.point_id}.json"
    rec = json.loads(rec_path.read_text())
    rec_path.write_text(json.dumps({**rec, "error": "worker failed: connection lost"}))
    record_in_manifest(rec_path, out)  # as ehm records a lost worker (a file changed by hand would be refused)
    assert run_study(specs, out, workers=1)["ran"] == 1
    assert "must not be negative" in json.loads(rec_path.read_text())["error"]


def test_bad_study_files(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[study]\ncompute = ['dance']\n")
    with pytest.raises(InputError, match="compute names 'dance'"):
        load_study(bad)
    bad.write_text("[people]\nstature_m = [1.6, 1.7]\nmass_kg = [60.0]\n")
    with pytest.raises(InputError, match="equal length"):
        load_study(bad)
    bad.write_text('[grid]\n"joints.t12.q" = [1.0]\n')  # refused before any cluster starts
    with pytest.raises(InputError, match="not a parameter"):
        load_study(bad)
    for text, words in (('[study]\ncompute = "comfort"\n', "compute must be a list"),
                        ('[input]\nmethod = "tim"\n', "method 'tim'"),
                        ('[input]\naxes = ["x", "w"]\n', "axes"),
                        ('[input]\ndrive = "nowhere.csv"\n', "drive 'nowhere.csv'"),
                        ('[input]\nduration_s = -2\n', "duration_s -2"),
                        ('[input]\nroute = "hybrid"\n', "use \"nonlinear\", \"auto\" or \"linear\"")):
        bad.write_text(text)
        with pytest.raises(InputError, match=words):
            load_study(bad)
    bad.write_text("[input]\nduration = 3\n")
    with pytest.raises(InputError, match="unknown key 'duration'"):
        load_study(bad)


def test_cli_batch(tmp_path, capsys, monkeypatch):
    path = tmp_path / "study.toml"
    path.write_text(STUDY.replace(", -1.0", ""))
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        monkeypatch.delenv(var, raising=False)
    assert main(["batch", str(path), "--out", str(tmp_path / "r"), "--workers", "1", "--csv"]) == 0
    # the workers ran single-threaded; the calling process keeps its own thread settings
    assert "OMP_NUM_THREADS" not in os.environ and "OPENBLAS_NUM_THREADS" not in os.environ
    lines = (tmp_path / "r" / "results.csv").read_text().splitlines()
    # the shape of Assessment.to_dataframe (issue 32): each output's location, axis, metric and unit beside it
    assert lines[0].startswith("\"run_id\",\"output\",\"location\",\"axis\",\"metric\",\"value\",\"unit\",\"error\"")
    # 2 people x 1 parameter value x 8 outputs (peak frequency and gain of pelvis, trunk, head, lumbar on seat z)
    assert len(lines) == 1 + 2 * 8 and not any("error" in ln.split(",")[1] for ln in lines[1:])


def test_fit_evaluates_candidates_on_a_dask_cluster():
    # The transfer-function fit takes an executor: here a local Dask cluster's.  SYNTHETIC gains made by
    # the model with the T12 compression stiffness at 21 kN/m are fitted from the default 15 kN/m.
    import numpy as np
    from dask.distributed import Client, LocalCluster

    import ehm
    from ehm.analysis.fit import fit
    from ehm.analysis.frf import FrfTable, linear_frf
    from ehm.body.params import Parameters

    human = ehm.SeatedHuman(params=Parameters.load().with_values({"joints.t12.z.stiffness_N_per_m": 21000.0}))
    human.settle()
    table = linear_frf(human, "z", freq_hz=np.arange(0.5, 12.01, 0.5))
    data = FrfTable({k: v for k, v in table.curves.items() if k[2] in ("z", "pitch")}, method="measured")
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        result = fit(data, free=["joints.t12.z.stiffness_N_per_m"], time_check=False,
                     executor=client.get_executor())
    assert result.final["joints.t12.z.stiffness_N_per_m"] == pytest.approx(21000.0, rel=0.01)


def _drive_file(path, amplitude_mps2: float) -> None:
    """A SYNTHETIC 4 s vertical drive at 100 Hz (2 Hz sine)."""
    import numpy as np

    t = np.round(np.arange(0, 4.0001, 0.01), 2)
    rows = "".join(f"{a:g},0,0,{amplitude_mps2 * np.sin(2 * np.pi * 2 * a):.6g}\n" for a in t)
    path.write_text("time_s,ax_mps2,ay_mps2,az_mps2\n" + rows)


@pytest.mark.filterwarnings("always::ehm.errors.EhmWarning")  # the command line prints them: read on stderr
def test_changed_drive_file_reruns_and_is_counted(tmp_path, capsys):
    drive = tmp_path / "drive.csv"
    _drive_file(drive, 0.2)
    study = tmp_path / "study.toml"
    study.write_text(f'[study]\ncompute = ["comfort"]\n[input]\ndrive = "{drive}"\nduration_s = 3.0\n')
    out = tmp_path / "res"
    assert main(["batch", str(study), "--out", str(out), "--workers", "1"]) == 0
    first = {r["output"]: r["value"] for r in pq.read_table(out / "results.parquet").to_pylist()}
    assert "ran 1 runs (0 already done, 0 failed)" in capsys.readouterr().out
    assert main(["batch", str(study), "--out", str(out), "--workers", "1"]) == 0  # nothing changed: nothing reruns
    assert "ran 0 runs (1 already done, 0 failed)" in capsys.readouterr().out
    _drive_file(drive, 0.8)  # the same file name, four times the vibration
    assert main(["batch", str(study), "--out", str(out), "--workers", "1"]) == 0
    said = capsys.readouterr().out
    assert "ran 1 runs (0 already done, 1 rerun because an input changed (drive file content), 0 failed)" in said
    second = {r["output"]: r["value"] for r in pq.read_table(out / "results.parquet").to_pylist()}
    # the seat's a_w follows the input: four times the amplitude (a linear weighting filter of the seat input)
    assert second["seat.a_w_z_mps2"] == pytest.approx(4 * first["seat.a_w_z_mps2"], rel=1e-6)


def test_run_id_covers_inputs_versions_and_parameter_values(tmp_path, monkeypatch):
    import importlib.metadata

    import ehm

    drive = tmp_path / "drive.csv"
    _drive_file(drive, 0.2)
    study = tmp_path / "study.toml"
    study.write_text(f'[study]\ncompute = ["comfort"]\n[grid]\n"joints.t12.z.stiffness_N_per_m" = [15000.0]\n'
                     f'[input]\ndrive = "{drive}"\n')
    _, (base,) = load_study(study)

    def changed(what: str):
        _, (spec,) = load_study(study)
        assert spec.point_id == base.point_id and spec.run_id != base.run_id, what
        assert [k for k in spec.fingerprint if spec.fingerprint[k] != base.fingerprint[k]] == [what]

    _drive_file(drive, 0.3)
    changed("drive file content")
    _drive_file(drive, 0.2)
    monkeypatch.setattr(ehm, "__version__", "99.0")
    changed("ehm version")
    monkeypatch.undo()
    real = importlib.metadata.version
    monkeypatch.setattr(importlib.metadata, "version", lambda name: "0.0.1" if name == "mujoco" else real(name))
    changed("MuJoCo version")
    monkeypatch.undo()
    # the parameter values actually used: the defaults with the grid's values (here a default changed under it)
    from ehm.body.params import Parameters
    from ehm.interfaces import batch

    batch._parameters_digest.cache_clear()
    loaded = Parameters.load()
    monkeypatch.setattr(Parameters, "load", classmethod(
        lambda cls, path=None: loaded.with_values({"joints.t12.z.damping_Ns_per_m": 123.0})))
    changed("parameter values")
    batch._parameters_digest.cache_clear()


def test_drives_are_cut_by_time_not_by_sample_count():
    import numpy as np

    from ehm.inputs.motion import SeatMotion
    from ehm.interfaces.batch import cut_by_time

    # first interval 0.59 s, then 10 ms: a cut by the first interval's sample count kept 20 s for a 5 s request
    t = np.concatenate([[0.0], np.round(np.arange(0.59, 20.0001, 0.01), 2)])
    az = np.sin(t)
    m = SeatMotion(t, np.column_stack([0 * t, 0 * t, az]), "synthetic", np.column_stack([0 * t, 0 * t, 0.1 * az]))
    cut = cut_by_time(m, 5.0)
    assert cut.duration_s == pytest.approx(5.0) and cut.time_s[-1] == pytest.approx(5.0)
    assert np.array_equal(cut.time_s[:-1], t[t <= 5.0 + 1e-9][:-1])
    cut = cut_by_time(m, 5.005)  # between two samples: one interpolated at exactly 5.005 s
    assert cut.time_s[-1] == pytest.approx(5.005) and cut.acc_mps2[-1, 2] == pytest.approx(np.sin(5.005), abs=1e-4)
    assert cut.angvel_radps[-1, 2] == pytest.approx(0.1 * np.sin(5.005), abs=1e-5)
    assert cut_by_time(m, 30.0) is m  # shorter than asked: the whole drive
    # a drive whose first interval is short ran for 0.59 s instead of 20 s
    t2 = np.concatenate([[0.0, 0.001], np.round(np.arange(0.59, 20.0001, 0.59), 2)])
    m2 = SeatMotion(t2, np.zeros((t2.size, 3)), "synthetic")
    assert cut_by_time(m2, 10.0).duration_s == pytest.approx(10.0)


def test_scheduler_address_and_reachability_are_one_sentence(tmp_path, capsys):
    path = tmp_path / "study.toml"
    path.write_text(STUDY.replace(", -1.0", ""))
    out = tmp_path / "res"
    assert main(["batch", str(path), "--out", str(out), "--scheduler", "nonsense"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "--scheduler 'nonsense'" in err and "tcp://HOST:PORT" in err
    assert main(["batch", str(path), "--out", str(out), "--scheduler", "tcp://127.0.0.1:9"]) == 2  # nothing listens
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith("ehm: error: cannot reach the Dask scheduler at tcp://127.0.0.1:9")
    assert not out.exists()  # a failed study leaves no empty folder behind


@pytest.mark.filterwarnings("always::ehm.errors.EhmWarning")  # the command line prints them: read on stderr
def test_relative_drive_path_starts_from_the_study_files_folder(tmp_path, monkeypatch, capsys):
    folder = tmp_path / "studies"
    folder.mkdir()
    _drive_file(folder / "drive.csv", 0.2)
    study = folder / "study.toml"
    study.write_text('[study]\ncompute = ["comfort"]\n[input]\ndrive = "drive.csv"\nduration_s = 3.0\n')
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)  # no drive.csv here: only the study file's folder has it
    _, specs = load_study(study)
    assert specs[0].input["drive"] == str(folder / "drive.csv")
    assert main(["batch", str(study), "--out", str(tmp_path / "res"), "--workers", "1"]) == 0
    assert "ran 1 runs (0 already done, 0 failed)" in capsys.readouterr().out
    # an absolute path stays as it is; a missing relative file names where it was looked for
    absolute = tmp_path / "abs.csv"
    _drive_file(absolute, 0.2)
    study.write_text(f'[study]\ncompute = ["comfort"]\n[input]\ndrive = "{absolute}"\nduration_s = 3.0\n')
    assert load_study(study)[1][0].input["drive"] == str(absolute)
    study.write_text('[study]\ncompute = ["comfort"]\n[input]\ndrive = "gone.csv"\nduration_s = 3.0\n')
    with pytest.raises(InputError, match=r"drive 'gone.csv' \(no file .*studies.gone\.csv\)"):
        load_study(study)


@pytest.mark.skipif(not hasattr(__import__("os"), "killpg"), reason="needs POSIX process groups")
def test_ctrl_c_ends_a_batch_with_one_line_and_no_worker_tracebacks(tmp_path):
    # A terminal's Ctrl-C sends SIGINT to the whole process group: ehm and its Dask workers.  Here the group of
    # an 'ehm batch' subprocess gets it while its (long) runs are under way.
    import os
    import signal
    import subprocess
    import sys
    import time
    from pathlib import Path

    import ehm

    study = tmp_path / "study.toml"
    study.write_text('[study]\ncompute = ["comfort"]\n[grid]\n"joints.t12.z.stiffness_N_per_m" = [14000.0, 16000.0]\n'
                     '[input]\ndrive = "random"\naxes = ["z"]\nduration_s = 600.0\n'
                     'route = "nonlinear"\n')  # runs long enough to be interrupted
    env = {**os.environ, "PYTHONPATH": str(Path(ehm.__file__).parents[1]), "PYTHONUNBUFFERED": "1", "MPLBACKEND": "Agg"}
    proc = subprocess.Popen([sys.executable, "-m", "ehm.interfaces.cli", "batch", str(study), "--out",
                             str(tmp_path / "res"), "--workers", "2"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        assert proc.stdout.readline().startswith("study ")  # the study file is read: the cluster starts next
        time.sleep(4.0)  # workers started (about 2 s here) and running
        os.killpg(proc.pid, signal.SIGINT)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130
    assert "Traceback" not in err and "distributed" not in err and "WARNING" not in err, err
    assert err.strip().splitlines()[-1] == "ehm: interrupted"


def test_a_study_file_says_how_to_take_gravity_in_its_drive(tmp_path):
    # SYNTHETIC drive file of a floor board: 1 g on z, small vibration
    import numpy as np

    t = np.arange(0.0, 20.0, 0.01)
    rng = np.random.default_rng(0)
    acc = 0.2 * rng.standard_normal((t.size, 3)) + [0.0, 0.0, 9.80665]
    (tmp_path / "board.csv").write_text("time_s,ax_mps2,ay_mps2,az_mps2\n" + "".join(
        f"{a:.3f},{b:.5f},{c:.5f},{d:.5f}\n" for a, (b, c, d) in zip(t, acc)))
    study = tmp_path / "study.toml"
    study.write_text('[study]\ncompute = ["comfort"]\n[input]\ndrive = "board.csv"\ngravity = "removed"\n')
    with pytest.raises(InputError, match="cannot be a vehicle.s"):  # "removed" refuses a mean of 1 g, before any run
        load_study(study)
    study.write_text('[study]\ncompute = ["comfort"]\n[input]\ndrive = "board.csv"\ngravity = "sideways"\n')
    with pytest.raises(InputError, match="sideways"):
        load_study(study)
    study.write_text('[study]\ncompute = ["comfort"]\n[input]\ndrive = "board.csv"\ngravity = "included"\n')
    name, specs = load_study(study)
    assert len(specs) == 1


def test_a_comfort_study_on_the_hybrid_route_records_its_linear_share(tmp_path):
    path = tmp_path / "hybrid.toml"
    path.write_text('[study]\nname = "hybrid"\ncompute = ["comfort"]\n'
                    '[input]\naxes = ["x", "y", "z"]\nrms_mps2 = 0.5\nduration_s = 12.0\nroute = "auto"\n')
    _, specs = load_study(path)
    res = run_study(specs, tmp_path / "res", workers=1)
    assert res["ran"] == 1 and res["failed"] == 0
    rows = {r["output"]: r["value"] for r in pq.read_table(tmp_path / "res" / "results.parquet").to_pylist()}
    assert 0 < rows["route.linear_share"] <= 1 and rows["head.a_v_mps2"] > 0


def test_a_second_study_into_a_folder_in_use_is_refused(tmp_path, capsys):
    # issue 38: two studies started into one folder at once both exited 0; the second's table replaced the first's
    import subprocess
    import sys
    from pathlib import Path

    import ehm

    path = tmp_path / "study.toml"
    path.write_text(STUDY.replace(", -1.0", ""))
    code = ("import sys, time; from ehm.outputs.outdir import folder_lock\n"
            "with folder_lock(sys.argv[1]):\n    print('held', flush=True); time.sleep(60)\n")
    env = {**os.environ, "PYTHONPATH": str(Path(ehm.__file__).parents[1])}
    first = subprocess.Popen([sys.executable, "-c", code, str(tmp_path / "r")], stdout=subprocess.PIPE, text=True,
                             env=env)
    try:
        assert first.stdout.readline().strip() == "held"  # the first study holds the folder
        assert main(["batch", str(path), "--out", str(tmp_path / "r"), "--workers", "1"]) == 2
    finally:
        first.kill()
        first.wait()
        first.stdout.close()
    err = capsys.readouterr().err
    assert err.startswith(f"ehm: error: {tmp_path / 'r'} is being written by another ehm command (process "
                          f"{first.pid} on ") and "give another folder (--out" in err and err.count("\n") == 1, err
    with pytest.raises(InputError, match="is being written by another ehm command"):  # the Python API too
        first = subprocess.Popen([sys.executable, "-c", code, str(tmp_path / "r")], stdout=subprocess.PIPE,
                                 text=True, env=env)
        try:
            assert first.stdout.readline().strip() == "held"
            run_study(load_study(path)[1], tmp_path / "r", workers=1)
        finally:
            first.kill()
            first.wait()
            first.stdout.close()


def test_sigterm_to_ehm_alone_ends_a_batch_with_its_cluster(tmp_path, session_processes):
    # issue 38: SIGTERM to the main process was ignored whenever a Dask cluster ran.  Sent to ehm alone (a service
    # manager, kill PID): exit 143, one line, no process of its session left, no lock or hidden folder.
    import signal
    import subprocess
    import sys
    import time
    from pathlib import Path

    import ehm

    session = session_processes

    study = tmp_path / "study.toml"
    study.write_text('[study]\ncompute = ["comfort"]\n[grid]\n"joints.t12.z.stiffness_N_per_m" = [14000.0, 16000.0]\n'
                     '[input]\ndrive = "random"\naxes = ["z"]\nduration_s = 600.0\nroute = "nonlinear"\n')
    env = {**os.environ, "PYTHONPATH": str(Path(ehm.__file__).parents[1]), "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen([sys.executable, "-m", "ehm.interfaces.cli", "batch", str(study), "--out",
                             str(tmp_path / "res"), "--workers", "2"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, start_new_session=True)
    try:
        assert proc.stdout.readline().startswith("study ")
        end = time.monotonic() + 60
        while len(session(proc.pid)) < 4 and time.monotonic() < end:  # ehm, the tracker and two workers
            time.sleep(0.2)
        time.sleep(2.0)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
    end = time.monotonic() + 10
    while session(proc.pid) and time.monotonic() < end:
        time.sleep(0.2)
    assert proc.returncode == 143 and err.strip().splitlines()[-1] == "ehm: terminated", err
    assert "Traceback" not in err
    assert not session(proc.pid)
    assert not [p.name for p in tmp_path.iterdir() if p.name.startswith(".")]


@pytest.mark.filterwarnings("always::ehm.errors.EhmWarning")  # the command line prints them: read on stderr
def test_a_comfort_study_reads_a_persons_sickness_parameters(tmp_path, capsys):
    """[input] sickness_params: a person's MISC parameters (the file 'ehm fit-sickness' writes), beside the study
    file; the runs record the head's MISC, a changed file reruns them, and a bad one is refused before any run."""
    _drive_file(tmp_path / "drive.csv", 0.5)  # SYNTHETIC
    (tmp_path / "person.toml").write_text("[misc]\nfast_gain = 100.0\n", encoding="utf-8")
    study = tmp_path / "study.toml"
    study.write_text('[study]\ncompute = ["comfort"]\n[input]\ndrive = "drive.csv"\nduration_s = 3.0\n'
                     'route = "linear"\nsickness_params = "person.toml"\n')
    out = tmp_path / "res"
    assert main(["batch", str(study), "--out", str(out), "--workers", "1"]) == 0
    first = {r["output"]: r["value"] for r in pq.read_table(out / "results.parquet").to_pylist()}
    assert 0.0 < first["head.misc"] <= 10.0
    (tmp_path / "person.toml").write_text("[misc]\nfast_gain = 10000.0\n", encoding="utf-8")
    assert main(["batch", str(study), "--out", str(out), "--workers", "1"]) == 0
    assert "rerun because an input changed (sickness parameter file content)" in capsys.readouterr().out
    second = {r["output"]: r["value"] for r in pq.read_table(out / "results.parquet").to_pylist()}
    assert second["head.misc"] > first["head.misc"]
    (tmp_path / "person.toml").write_text("[misc]\nspeed = 1.0\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"person.toml: \[misc\] has no parameter 'speed'"):
        load_study(study)
