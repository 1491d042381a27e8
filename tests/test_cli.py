"""The ``ehm`` command as a user meets it: outputs on disk, one-sentence errors, exit codes."""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import numpy as np
import pytest

import ehm
from ehm.body.params import Parameters, default_params_path
from ehm.interfaces.cli import main

REQUIRED_COLUMNS = ["time_s", "seat_ax_mps2", "seat_ay_mps2", "seat_az_mps2"] + [
    f"{p}_{q}" for p in ("pelvis", "trunk", "head", "lumbar")
    for q in ("ax_mps2", "ay_mps2", "az_mps2", "x_m", "y_m", "z_m", "roll_rad", "pitch_rad", "yaw_rad")
]


def _error_line(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err
    # a coarse --dt adds its own one-sentence warning line before the error
    err = "\n".join(line for line in err.splitlines() if not line.startswith("ehm: warning: the time step"))
    assert err.count("\n") == 0, f"expected one line, got: {err!r}"
    assert err.startswith("ehm: error: ")
    return err


def test_info_json_counts_and_locks(capsys):
    assert main(["info", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["dof"] == 28 and abs(info["mass_kg"] - 70.882) < 1e-9
    assert {s["name"] for s in info["segments"]} >= {"head", "pelvis", "foot_l"}
    assert all(set(s) >= {"name", "mass_kg", "com_m"} for s in info["segments"])
    waist = [j for j in info["joints"] if j["name"] == "waist"][0]
    assert waist["locked"] and waist["dof"] == 0 and waist["type"] == "spherical"
    assert main(["info", "--json", "--unlock", "waist", "--lock", "lower_neck"]) == 0
    info = json.loads(capsys.readouterr().out)
    # 28 + 3 (waist spherical) - 2 (universal lower neck)
    assert info["dof"] == 29
    assert [j for j in info["joints"] if j["name"] == "lower_neck"][0]["locked"]


def test_simulate_writes_timeseries_and_summary(tmp_path, capsys):
    out = tmp_path / "z"
    assert main(["simulate", "--axis", "z", "--duration", "3", "--rms", "0.3", "--seed", "0", "--out", str(out)]) == 0
    with open(out / "timeseries.csv") as fh:
        header = next(csv.reader(fh))
    assert all(c in header for c in REQUIRED_COLUMNS)
    data = np.loadtxt(out / "timeseries.csv", delimiter=",", skiprows=1)
    summary = json.loads((out / "summary.json").read_text())
    rate = summary["output_rate_hz"]  # 200 Hz by default
    assert data.shape[0] == round(3 * rate) + 1  # t = 0, 1 / rate, ..., 3.0 s
    assert np.allclose(np.diff(data[:, 0]), 1 / rate) and data[-1, 0] == pytest.approx(3.0)
    assert np.isfinite(data).all()
    for key in ("mass_kg", "dof", "duration_s", "dt_s", "wall_s", "realtime_factor", "support_force_mean_N"):
        assert key in summary
    assert summary["dof"] == 28 and summary["dt_s"] == 0.001 and summary["duration_s"] == pytest.approx(3.0)
    assert rate == 200.0
    # The summary's rms values use every model step, whatever the output rate: the seat input is the input asked
    # for, 0.3 m/s^2 rms on z only (before resampling it is exact; measured 3e-11).
    assert summary["seat_acc_rms_mps2"][2] == pytest.approx(0.3, rel=1e-6)
    assert summary["seat_acc_rms_mps2"][:2] == [0.0, 0.0]
    # every model step at the model's rate (1 kHz at the default 1 ms step)
    assert main(["simulate", "--axis", "z", "--duration", "3", "--output-rate", "1000", "--out", str(out)]) == 0
    data = np.loadtxt(out / "timeseries.csv", delimiter=",", skiprows=1)
    assert data.shape[0] == 3001
    seat = data[:, 1:4]
    assert np.sqrt(np.mean(seat[:, 2] ** 2)) == pytest.approx(0.3, rel=1e-6)  # the CSV has 9 digits
    assert np.abs(seat[:, :2]).max() == 0.0


def test_motion_csv_input(tmp_path, capsys):
    t = np.arange(0, 2.0, 0.002)
    path = tmp_path / "drive.csv"
    rows = ["time_s,ax_mps2,ay_mps2,az_mps2"] + [f"{a},{0.2 * np.sin(2 * np.pi * 2 * a)},0,0" for a in t]
    path.write_text("\n".join(rows) + "\n")
    assert main(["simulate", "--motion", str(path), "--out", str(tmp_path / "run")]) == 0
    data = np.loadtxt(tmp_path / "run" / "timeseries.csv", delimiter=",", skiprows=1)
    assert np.abs(data[:, 1]).max() == pytest.approx(0.2, rel=0.01)


@pytest.mark.parametrize("content, expected", [
    ("time_s,ax_mps2,ay_mps2,az_mps2\n0,0,0,0\n0.1,abc,0,0\n", r"line 3.*ax_mps2.*abc"),
    ("time_s,ax_mps2,ay_mps2\n0,0,0\n0.1,0,0\n", r"az_mps2"),
    ("time_s,ax_mps2,ay_mps2,az_mps2\n0,0,0,0\n0.1,nan,0,0\n", r"line 3.*ax_mps2"),
    ("time_s,ax_mps2,ay_mps2,az_mps2\n0,0,0,0\n0.1,inf,0,0\n", r"line 3.*ax_mps2"),
])
def test_bad_motion_csv_one_sentence_and_no_output(tmp_path, capsys, content, expected):
    path = tmp_path / "bad.csv"
    path.write_text(content)
    out = tmp_path / "run"
    assert main(["simulate", "--motion", str(path), "--out", str(out)]) == 2
    err = _error_line(capsys)
    assert "bad.csv" in err
    assert re.search(expected, err), err
    assert not out.exists() or not any(out.iterdir())


def test_unknown_joint(capsys):
    assert main(["info", "--lock", "elbow"]) == 2
    assert "elbow" in _error_line(capsys)


def test_bad_segment_table_via_params_file(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    text = default_params_path().read_text()
    head, tail = text.split("[joints.upper_neck]", 1)
    tail = re.sub(r"stiffness_Nm_per_rad = [0-9.]+", "stiffness_Nm_per_rad = -90.0", tail, count=1)
    bad.write_text(head + "[joints.upper_neck]" + tail)
    assert main(["info", "--params", str(bad)]) == 2
    err = _error_line(capsys)
    assert "bad.toml" in err and "upper_neck" in err and "-90" in err


@pytest.mark.filterwarnings("always::ehm.errors.EhmWarning")  # the command line prints them: read on stderr
def test_divergence_is_reported_with_time_and_no_output(tmp_path, capsys):
    # contacts 30x as stiff at the longest step taken (10 ms): diverges while settling (measured at t = 0.61 s)
    p = Parameters.load()
    p.with_values({x: 30 * p.value(x) for x in p.numeric_paths()
                   if x.startswith("contacts.") and x.endswith(".stiffness_N_per_m")}).export(tmp_path / "stiff.toml")
    out = tmp_path / "run"
    assert main(["simulate", "--params", str(tmp_path / "stiff.toml"), "--axis", "z", "--duration", "2", "--dt", "0.01",
                 "--band", "0.1", "4", "--out", str(out)]) == 2
    err = _error_line(capsys)
    assert "diverged at t =" in err and "dt = 0.01 s" in err
    assert not (out / "timeseries.csv").exists() and not (out / "summary.json").exists()


def test_params_export_and_reuse(tmp_path, capsys):
    exported = tmp_path / "mine.toml"
    assert main(["params", "--export", str(exported)]) == 0
    text = exported.read_text()
    assert text.count("stiffness_N_per_m = 37490.0") == 1  # the T12 compression spring
    exported.write_text(text.replace("stiffness_N_per_m = 37490.0", "stiffness_N_per_m = 12000.0"))
    assert main(["info", "--json", "--params", str(exported)]) == 0
    info = json.loads(capsys.readouterr().out.split("\n", 1)[1])
    assert info["params"] == str(exported)
    assert Parameters.load(exported).value("joints.t12.z.stiffness_N_per_m") == 12000.0


def test_demo_writes_files(tmp_path, capsys):
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "--duration", "40", "--axes", "z"]) == 0
    for name in ("transmissibility.csv", "transmissibility.png", "demo_summary.json",
                 "z/timeseries.csv", "z/summary.json", "z/time_histories.png"):
        assert (out / name).stat().st_size > 0, name
    summary = json.loads((out / "demo_summary.json").read_text())
    peak = summary["transmissibility_peaks"]["z->head"]
    # Quasi-static limit: at 0.5 Hz, far below the vertical mode, the head follows the seat (gain 1; 10 % for the
    # estimate from 40 s of data), and the peak lies where the linear route puts it for the person at the run's
    # vibration level (the demo's person takes its input's level), within 0.5 Hz (the estimate's 0.1 Hz
    # resolution and scatter).
    assert peak["gain_at_0.5_hz"] == pytest.approx(1.0, abs=0.1)
    level = json.loads((out / "z" / "summary.json").read_text())["vibration_level"]["rms_mps2"]
    f = np.arange(2.0, 10.0, 0.05)
    linear = ehm.linear_frf(ehm.Person(vibration_rms_mps2=level), "z", freq_hz=f).curve("z", "head", "z")
    assert peak["peak_hz"] == pytest.approx(f[np.argmax(linear.gain)], abs=0.5)


@pytest.mark.parametrize("duration", ["5", "39.9", "nan"])
def test_demo_refuses_a_duration_too_short_for_its_resolution(tmp_path, capsys, duration):
    from ehm.interfaces.cli import DEMO_MIN_SEGMENTS, DEMO_SEGMENT_S

    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "--duration", duration, "--axes", "z"]) == 2
    err = _error_line(capsys)
    need = DEMO_SEGMENT_S * DEMO_MIN_SEGMENTS
    assert f"--duration {float(duration):g}" in err and f"at least {need:g} s" in err, err
    assert not out.exists()


@pytest.mark.parametrize("column, value, expected", [
    ("mass_kg", "-6.23", r"line \d+, column mass_kg: -6.23 must be positive"),
    ("ixx_kgm2", "0", r"line \d+, column ixx_kgm2: 0 must be positive"),
])
def test_bad_segment_file_one_sentence(tmp_path, capsys, column, value, expected):
    from importlib import resources
    src = Path(str(resources.files("ehm") / "data" / "segments.csv")).read_text().splitlines()
    header_i = next(i for i, ln in enumerate(src) if ln.startswith("name,"))
    col = src[header_i].split(",").index(column)
    fields = src[header_i + 1].split(",")  # the head
    fields[col] = value
    src[header_i + 1] = ",".join(fields)
    bad = tmp_path / "segments_bad.csv"
    bad.write_text("\n".join(src) + "\n")
    out = tmp_path / "run"
    assert main(["simulate", "--segments", str(bad), "--duration", "1", "--out", str(out)]) == 2
    err = _error_line(capsys)
    assert "segments_bad.csv" in err and re.search(expected, err), err
    assert not out.exists()


@pytest.mark.parametrize("argv, option", [
    (["simulate", "--motion", "", "--duration", "1"], "--motion"),  # issue 38: simulated the generated vibration
    (["assess", "--motion", " "], "--motion"),
    (["simulate", "--params", "", "--duration", "1"], "--params"),
    (["frf", "--motion", "", "--method", "time"], "--motion"),
    (["fit-sickness", "--motion", "road", "--ratings", " "], "--ratings"),
    (["assess", "--motion", "road", "--sickness-params", ""], "--sickness-params"),
])
def test_an_empty_path_option_is_refused(tmp_path, capsys, argv, option):
    out = tmp_path / "run"
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"ehm: error: {option} is empty (") and "unset shell variable" in err, err
    assert err.count("\n") == 1 and not out.exists()
    assert main(["simulate", "--duration", "1", "--out", ""]) == 2
    assert "--out is empty ('': an unset shell variable?); give where to write" in capsys.readouterr().err


def signalled(session, argv: list[str], folder: Path, sig, group: bool, processes: int = 1,
              timeout_s: float = 60.0):
    """Run ``ehm argv`` in a session of its own, send it ``sig`` (to its whole group with ``group``: a closed
    terminal or Ctrl-C) once it has ``processes`` processes (more than one: its workers, running) or else a staging
    folder in ``folder``; returns its exit code and stderr after checking that nothing is left: no process of its
    session, no hidden folder or lock file."""
    import os
    import signal  # noqa: F401
    import subprocess
    import sys
    import time

    import ehm

    env = {**os.environ, "PYTHONPATH": str(Path(ehm.__file__).parents[1]), "MPLBACKEND": "Agg"}
    proc = subprocess.Popen([sys.executable, "-m", "ehm.interfaces.cli", *argv], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True, env=env, start_new_session=True)
    try:
        end = time.monotonic() + timeout_s
        while time.monotonic() < end and proc.poll() is None and not (
                len(session(proc.pid)) >= processes if processes > 1
                else any(p.name.startswith(".") for p in folder.iterdir())):
            time.sleep(0.1)
        time.sleep(1.0 if processes > 1 else 0.0)  # the workers at work
        assert proc.poll() is None, proc.communicate()[1]
        (os.killpg if group else os.kill)(proc.pid, sig)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, 9)
            proc.communicate()
    end = time.monotonic() + 10.0
    while session(proc.pid) and time.monotonic() < end:
        time.sleep(0.1)
    assert not session(proc.pid), "processes left"
    assert not [p.name for p in folder.iterdir() if p.name.startswith(".")], "hidden staging or lock left"
    return proc.returncode, err


@pytest.mark.parametrize("sig, group, code, words", [
    ("SIGHUP", False, 129, "ehm: hung up (SIGHUP: its terminal closed)"),  # issue 38: ended silently, 35 MB left
    ("SIGTERM", False, 143, "ehm: terminated"),
])
def test_simulate_ends_on_sighup_and_sigterm_leaving_nothing(tmp_path, session_processes, sig, group, code, words):
    import signal

    argv = ["simulate", "--duration", "600", "--out", str(tmp_path / "run"), "-q"]
    rc, err = signalled(session_processes, argv, tmp_path, getattr(signal, sig), group)
    assert rc == code and err.strip().splitlines()[-1] == words, err
    assert "Traceback" not in err and not (tmp_path / "run").exists()


def test_assess_with_workers_ends_on_a_closed_terminal_with_its_workers(tmp_path, session_processes):
    # The terminal's SIGHUP goes to the whole group: ehm ends its workers, which ignore it (as they do Ctrl-C).
    import signal

    drive = tmp_path / "drive.csv"  # SYNTHETIC: 300 s of random seat vibration at 100 Hz
    t = np.arange(30000) / 100.0
    acc = 0.3 * np.random.default_rng(0).standard_normal((t.size, 3))
    np.savetxt(drive, np.column_stack([t, acc]), delimiter=",", header="time_s,ax_mps2,ay_mps2,az_mps2",
               comments="", fmt="%.5f")
    argv = ["assess", "--motion", str(drive), "--method", "nonlinear", "--workers", "2", "--out", str(tmp_path / "a"),
            "-q"]
    rc, err = signalled(session_processes, argv, tmp_path, signal.SIGHUP, True, processes=3)
    assert rc == 129 and err.strip().splitlines()[-1] == "ehm: hung up (SIGHUP: its terminal closed)", err
    assert "Traceback" not in err
