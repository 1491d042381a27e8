"""Whole-drive assessment: rotations, sustained manoeuvres, streaming metrics, the report."""

from __future__ import annotations

import json

import numpy as np
import pytest

import ehm
from ehm.analysis.assessment import assess
from ehm.errors import EhmWarning, InputError
from ehm.inputs.drives import city_drive, rough_road
from ehm.inputs.motion import SeatMotion, seat_kinematics
from ehm.interfaces.cli import main
from ehm.standards.comfort import ComfortAccumulator, frequency_weighting, metrics


def test_accumulator_equals_batch_metrics():
    # Two routes to the same ISO 2631-1 values: block-by-block streaming and the whole record at once.
    x = np.random.default_rng(3).normal(size=30000) * 0.4
    batch = metrics(x, 1000.0, "Wk")
    acc = ComfortAccumulator("Wk", 1000.0, keep_every=1)
    for block in np.array_split(x, 11):
        acc.add(block)
    stream = acc.result()
    for name in ("a_w", "mtvv", "vdv", "crest_factor", "msdv"):
        assert getattr(stream, name) == pytest.approx(getattr(batch, name), rel=1e-12), name
    np.testing.assert_allclose(stream.running_rms, batch.running_rms, atol=1e-12)


def test_seat_kinematics_recovers_euler_angles():
    # Body rates made from known z-y-x angles (w = E(roll, pitch) (roll', pitch', yaw')) integrate back to
    # those angles: within 1e-4 rad after 60 s at 100 Hz.
    t = np.arange(0, 60, 0.01)
    yaw, pitch, roll = 0.3 * t, 0.05 * np.sin(0.5 * t), 0.04 * np.sin(0.3 * t + 1) - 0.04 * np.sin(1)
    dyaw, dpitch, droll = np.full_like(t, 0.3), 0.025 * np.cos(0.5 * t), 0.012 * np.cos(0.3 * t + 1)
    w = np.column_stack([droll - dyaw * np.sin(pitch),
                         dpitch * np.cos(roll) + dyaw * np.cos(pitch) * np.sin(roll),
                         -dpitch * np.sin(roll) + dyaw * np.cos(pitch) * np.cos(roll)])
    k = seat_kinematics(t, w)
    np.testing.assert_allclose(k.angles_rad, np.column_stack([yaw, pitch, roll]), atol=1e-4)
    np.testing.assert_allclose(k.rates_radps[10:-10], np.column_stack([dyaw, dpitch, droll])[10:-10], atol=1e-4)


def test_rotating_seat_build_matches_static_build_for_translation():
    # The rotating seat (heavy jointed body, boxes) with zero rotation must reproduce the static seat
    # (d'Alembert load, planes): head acceleration rms difference below 0.5 % of its rms (the seat's
    # tracking error and the box collider; measured 0.2 % with fore-aft input, 0.01 % vertical only).
    m = ehm.random_vibration("xz", 12.0, 0.3, seed=4)
    a = ehm.SeatedHuman().simulate(m, method="nonlinear").point("head").acc_mps2
    mr = SeatMotion(m.time_s, m.acc_mps2, "zero rotation", np.zeros_like(m.acc_mps2))
    rotating = ehm.SeatedHuman(rotating_seat=True)
    b = rotating.simulate(mr, method="nonlinear").point("head").acc_mps2
    assert np.sqrt(np.mean((a - b) ** 2)) < 5e-3 * np.sqrt(np.mean(a ** 2))
    # A motion without angular velocities on the same rotating-seat person: the seat stays level, same result.
    np.testing.assert_array_equal(rotating.simulate(m, method="nonlinear").point("head").acc_mps2, b)


def test_cli_simulate_takes_a_drive_file(tmp_path, capsys):
    # `ehm drive` writes angular velocities; `ehm simulate --motion` builds the rotating seat for them.
    drive = tmp_path / "d.csv"
    assert main(["drive", "city", "--duration", "12", "--out", str(drive)]) == 0
    assert main(["simulate", "--motion", str(drive), "--out", str(tmp_path / "run")]) == 0
    assert (tmp_path / "run" / "timeseries.csv").exists()


def test_bad_drive_arguments_are_one_sentence():
    for kw, words in ((dict(duration_s="abc"), "duration_s must be a number"),
                      (dict(seed=None), "seed must be a whole number")):
        with pytest.raises(InputError, match=words):
            city_drive(**kw)
    with pytest.raises(InputError, match="wheelbase_m must be a number above 0.5"):
        rough_road(duration_s=2, wheelbase_m=-3)


def test_sustained_cornering_leans_without_collapse_or_drift():
    # 8 s of 3.5 m/s^2 lateral acceleration with the matching yaw rate at 10 m/s: the body leans on the
    # side bolsters and comes back.  Limits (engineering, not measured): pelvis within 20 mm and 5 deg
    # during the manoeuvre, back within 5 mm and 1.5 deg of its posture 8 s afterwards.
    dt = 0.01
    t = np.arange(0, 20, dt)
    ay = 3.5 * (np.clip((t - 1) / 2, 0, 1) - np.clip((t - 9) / 2, 0, 1))
    zeros = np.zeros_like(t)
    m = SeatMotion(t, np.column_stack([zeros, ay, zeros]), "cornering", np.column_stack([zeros, zeros, ay / 10]))
    run = ehm.SeatedHuman(rotating_seat=True).simulate(m, method="nonlinear")
    pelvis = run.point("pelvis")
    assert np.abs(pelvis.disp_m).max() < 0.020
    assert np.degrees(np.abs(pelvis.rot_rad).max()) < 5.0
    assert np.abs(pelvis.disp_m[-1]).max() < 0.005
    assert np.degrees(np.abs(pelvis.rot_rad[-1]).max()) < 1.5
    # Newton for the whole body in seat axes during the steady corner: supports carry m (0, ay, g).
    i = (run.time_s > 5) & (run.time_s < 8)
    total = run.support_total_N()[i].mean(axis=0)
    np.testing.assert_allclose(total, 70.882 * np.array([0.0, 3.5, 9.81]), atol=0.01 * 70.882 * 9.81)


def test_sine_drive_metrics_closed_form():
    # A 4 Hz vertical sine of 1 m/s^2 amplitude at the seat: a_w = |Wk(4 Hz)| / sqrt(2) (ISO 2631-1 closed
    # form); 1 % for the filter start-up and the fades over 20 s.
    m = ehm.sine("z", 20.0, 1.0, 4.0)
    res = assess(m)
    fade = np.sqrt(np.mean(m.acc_mps2[:, 2] ** 2)) * np.sqrt(2)  # the fades lower the rms slightly
    expected = abs(frequency_weighting("Wk", 4.0)) / np.sqrt(2) * fade
    assert res.metrics["seat"]["z"].a_w == pytest.approx(expected, rel=0.01)
    # the body amplifies 4 Hz vertical vibration (below the 5 Hz mode): head above seat
    assert res.metrics["head"]["z"].a_w > res.metrics["seat"]["z"].a_w


def test_city_drive_assessment(tmp_path):
    drive = city_drive(40.0, seed=1)
    with pytest.warns(EhmWarning, match="not all of the Wk band"):  # a 100 Hz drive: up to 40 Hz
        res = assess(drive)
    s = res.summary()
    assert "SYNTHETIC" in s["input"]
    # the seat metrics equal the ISO metrics of the input itself (independent route: the whole drive resampled
    # onto the model's step at once by the runs' resampler, then evaluated as one record)
    dt = float(ehm.Parameters.load().value("simulation.dt_s"))
    ay = drive.resample(dt).acc_mps2[:, 1]
    assert res.metrics["seat"]["y"].a_w == pytest.approx(metrics(ay, 1 / dt, "Wd").a_w, rel=1e-6)
    for loc in ("seat", "pelvis", "trunk", "head", "lumbar"):
        assert s["locations"][loc]["total_value_mps2"] > 0
    # 40 s of city driving makes a little sickness (measured 0.03 %), far below the model's 85 % ceiling
    assert 0.001 < s["sickness"]["head"]["final_msi_percent"] < 1.0
    assert max(s["body_displacement_max_m"]["pelvis"]) < 0.03


def test_rough_road_is_labelled_and_has_the_class_level():
    road = rough_road(30.0, speed_mps=15.0, road_class="C", seed=0)
    assert road.description.startswith("SYNTHETIC")
    rms = np.sqrt(np.mean(road.acc_mps2[:, 2] ** 2))
    # A class C road at 15 m/s through a 1.2 Hz car body gives seat accelerations of a few tenths of
    # m/s^2 (ISO 2631-1 comfort: 'a little' to 'fairly uncomfortable' for rough roads).
    assert 0.1 < rms < 1.5
    with pytest.raises(InputError, match="ISO 8608"):
        rough_road(10.0, road_class="Z")


@pytest.mark.filterwarnings("always::ehm.errors.EhmWarning")  # the command line prints them: read on stderr
def test_cli_assess_writes_report(tmp_path, capsys):
    drive = tmp_path / "drive.csv"
    assert main(["drive", "city", "--duration", "20", "--seed", "2", "--out", str(drive)]) == 0
    out = tmp_path / "assess"
    assert main(["assess", "--motion", str(drive), "--out", str(out)]) == 0
    assert "not all of the Wk band" in capsys.readouterr().err  # the drive's 100 Hz: up to 40 Hz
    for name in ("assessment.json", "report.html", "weighted_spectra.png", "running_rms.png", "sickness.png"):
        assert (out / name).stat().st_size > 0, name
    summary = json.loads((out / "assessment.json").read_text())
    assert set(summary["locations"]) == {"seat", "pelvis", "trunk", "head", "lumbar"}
    html = (out / "report.html").read_text()
    assert "data:image/png;base64," in html and "SYNTHETIC city drive" in html


def test_motion_file_with_partial_rotation_is_refused(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("time_s,ax_mps2,ay_mps2,az_mps2,wz_radps\n0,0,0,0,0\n0.1,0,0,0,0\n")
    assert main(["assess", "--motion", str(bad), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "bad.csv: it has wz_radps but not wx_radps, wy_radps" in err


def test_city_drive_sign_conventions():
    # A left turn accelerates the seat to the left (+y) and yaws it positively about z (up); the car
    # rolls outward (to the right: positive roll about x lifts the left side); braking pitches it nose
    # down (positive pitch about y, which points left).  ehm.inputs.drives docstring.
    drive = city_drive(60.0, seed=0)
    k = seat_kinematics(drive.time_s, drive.angvel_radps)
    left = drive.acc_mps2[:, 1] > 1.5
    assert np.all(drive.angvel_radps[left, 2] > 0) and np.mean(k.angles_rad[left, 2]) > 0
    braking = drive.acc_mps2[:, 0] < -1.0
    assert np.mean(k.angles_rad[braking, 1]) > 0
    speed = 8.0 + np.cumsum(drive.acc_mps2[:, 0]) * (drive.time_s[1] - drive.time_s[0])
    assert speed.min() > 2.0  # the brakes bring the car back to city speeds, never backwards


@pytest.mark.filterwarnings("always::ehm.errors.EhmWarning")  # the command line prints them: read on stderr
def test_cli_assess_z_only_drive_and_drive_command(tmp_path, capsys):
    # A drive with motion on one axis only (the shipped rough road has none in x and y): undefined ratios
    # are written as null, not NaN.
    drive = tmp_path / "road.csv"
    assert main(["drive", "road", "--duration", "6", "--out", str(drive)]) == 0
    out = tmp_path / "a"
    assert main(["assess", "--motion", str(drive), "--out", str(out)]) == 0
    assert "not all of the Wf band" in capsys.readouterr().err  # 6 s: short of motion sickness's band
    summary = json.loads((out / "assessment.json").read_text())
    assert summary["locations"]["seat"]["axes"]["x"]["crest_factor"] is None
    assert summary["locations"]["head"]["total_value_mps2"] > 0
    assert main(["drive", "city", "--seed", "-1", "--out", str(tmp_path / "c.csv")]) == 2
    assert "seed" in capsys.readouterr().err


def test_cli_realtime(tmp_path, capsys):
    assert main(["realtime", "--motion", "road", "--ignore-rotation", "--duration", "0.2", "--no-pace"]) == 0
    out = capsys.readouterr().out
    n = int(round(0.2 / ehm.Parameters.load().value("simulation.dt_s"))) + 1  # samples at t = 0 ... 0.2 s
    assert "step latency: median" in out and f"overruns 0 of {n} steps" in out
    assert main(["realtime", "--motion", "road", "--ignore-rotation", "--duration", "-1"]) == 2
    assert "--duration -1" in capsys.readouterr().err
    assert main(["realtime", "--motion", "road", "--duration", "1"]) == 2  # rotation not ignored
    assert "rotates the seat" in capsys.readouterr().err


def test_linear_assessment_resamples_chunk_by_chunk():
    # `assess(method="linear")` resamples the drive onto the model's step a chunk at a time; the independent route
    # resamples the whole drive at once first.  Same polyphase filter, so the same figures to round-off.  The
    # drive carries all-zero angular velocities (a log with rate channels on a straight, level road): the
    # linear route takes it, and its seat does not turn.
    drive = ehm.random_vibration("xyz", 6.0, 0.3, seed=3, dt_s=0.005)  # 200 Hz, like a logger's
    acc = drive.acc_mps2
    motion = SeatMotion(drive.time_s, acc, "SYNTHETIC small drive", np.zeros_like(acc))
    human = ehm.SeatedHuman()
    with pytest.warns(EhmWarning, match="not all of the Wf band"):  # 6 s: short of motion sickness's band
        streamed = assess(motion, human, method="linear")
    dt = float(human.params.value("simulation.dt_s"))
    with pytest.warns(EhmWarning, match="not all of the Wf band"):
        whole = assess(SeatMotion(drive.time_s, acc, "SYNTHETIC small drive").resample(dt), human, method="linear")
    assert streamed.description == f"SYNTHETIC small drive, resampled to dt {dt:g} s"
    assert streamed.duration_s == pytest.approx(whole.duration_s, abs=1e-12)
    for loc in ("seat", "pelvis", "trunk", "head", "lumbar"):
        for a in "xyz":
            s, w = streamed.metrics[loc][a], whole.metrics[loc][a]
            assert s.a_w > 1e-3 and s.a_w == pytest.approx(w.a_w, rel=1e-9), (loc, a)
            assert s.vdv == pytest.approx(w.vdv, rel=1e-9), (loc, a)
    for key in ("head", "seat"):
        np.testing.assert_allclose(streamed.sickness[key].msi_percent, whole.sickness[key].msi_percent,
                                   rtol=1e-9, atol=1e-12 * whole.sickness[key].final_msi_percent)


def test_read_assessment_gives_the_assessment_back(tmp_path):
    """ehm.read_assessment(folder) round trip (issue 38, item 4): the arrays and figures written are read back
    exactly (comfort values, running rms, spectra, sickness traces, summary), and as_frame gives to_dataframe()."""
    from ehm.analysis.assessment import ARRAYS_FILE, write_assessment_arrays
    from ehm.files import write_json_atomic

    with pytest.warns(EhmWarning):  # 20 s at 100 Hz: not the whole Wk and Wf bands
        a = assess(city_drive(20.0, seed=1), method="linear")
    write_json_atomic(tmp_path / "assessment.json", a.summary())
    write_assessment_arrays(a, tmp_path / ARRAYS_FILE)
    b = ehm.read_assessment(tmp_path)
    assert json.dumps(b.summary(), sort_keys=True) == json.dumps(a.summary(), sort_keys=True)
    np.testing.assert_array_equal(b.trace_time_s, a.trace_time_s)
    for loc in a.metrics:
        for ax in "xyz":
            m, n = a.metrics[loc][ax], b.metrics[loc][ax]
            assert (m.a_w, m.mtvv, m.vdv, m.msdv, m.duration_s) == (n.a_w, n.mtvv, n.vdv, n.msdv, n.duration_s)
            np.testing.assert_array_equal(m.running_rms, n.running_rms)
            for x, y in zip(a.spectra[loc][ax], b.spectra[loc][ax]):
                np.testing.assert_array_equal(x, y)
    for key, trace in a.sickness.items():
        np.testing.assert_array_equal(b.sickness[key].msi_percent, trace.msi_percent)
        np.testing.assert_array_equal(b.sickness[key].conflict_magnitude_mps2, trace.conflict_magnitude_mps2)
    frame = ehm.read_assessment(tmp_path, as_frame=True)
    expected = a.to_dataframe()
    assert list(frame.columns) == list(expected.columns)
    np.testing.assert_array_equal(frame["value"], expected["value"])
    assert list(frame["metric"]) == list(expected["metric"]) and frame.attrs["description"] == a.description
    (tmp_path / ARRAYS_FILE).unlink()  # a folder of an older ehm: the figures only
    assert len(ehm.read_assessment(tmp_path, as_frame=True)) == len(expected)
    with pytest.raises(InputError, match=r"holds no assessment.npz.*as_frame=True"):
        ehm.read_assessment(tmp_path)
    with pytest.raises(InputError, match=r"holds no assessment.json: give the folder an 'ehm assess"):
        ehm.read_assessment(tmp_path / "nothing")
    with pytest.raises(InputError, match=r"read_assessment: give the folder"):
        ehm.read_assessment(1)
    (tmp_path / "assessment.json").write_text("{not json")
    with pytest.raises(InputError, match=r"not an assessment ehm wrote"):
        ehm.read_assessment(tmp_path, as_frame=True)


@pytest.mark.filterwarnings("always::ehm.errors.EhmWarning")  # the command line prints them: read on stderr
def test_cli_assess_folder_reads_back_and_its_report_says_what_the_console_said(tmp_path, capsys):
    """The folder of `ehm assess` reads back with read_assessment; the report carries the route line and every
    warning the console printed, and points to the documentation pages."""
    from ehm.outputs.report import DOC_PAGES

    drive = tmp_path / "drive.csv"
    assert main(["drive", "city", "--duration", "20", "--seed", "2", "--out", str(drive)]) == 0
    out = tmp_path / "assess"
    assert main(["assess", "--motion", str(drive), "--out", str(out)]) == 0
    captured = capsys.readouterr()
    warnings = [line[len("ehm: warning: "):] for line in captured.err.splitlines()
                if line.startswith("ehm: warning: ")]
    assert warnings and "ehm.read_assessment(folder)" in captured.out
    summary = json.loads((out / "assessment.json").read_text())
    assert summary["warnings"] == warnings
    back = ehm.read_assessment(out)
    assert back.total_value("seat") == pytest.approx(summary["locations"]["seat"]["total_value_mps2"], rel=1e-15)
    import html

    page = (out / "report.html").read_text()
    assert all(html.escape(w) in page for w in warnings)
    route_line = summary["route"]["summary_line"]
    assert route_line in captured.out and html.escape(route_line.removeprefix("route: ")) in page
    assert all(f"docs/{p}" in page for p, _ in DOC_PAGES)
