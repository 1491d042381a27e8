"""Handled loggers: a start and an end where the logger is in a hand, left out with a note; a pothole, a braking
vehicle and a log without handling left as they are.

Every log here is SYNTHETIC (band-limited noise, made-up turns and knocks), written for these tests.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd
import pytest

from ehm import read_motion
from ehm.analysis.assessment import handling_summary
from ehm.errors import EhmWarning, InputError
from ehm.inputs.handling import MAX_SHARE, find_handling

G = 9.80665
FS = 50.0
DURATION_S = 120.0
CHANNELS = {"time": None, "ax": "x", "ay": "y", "az": "z"}


def _vehicle(seed: int = 5) -> np.ndarray:
    """SYNTHETIC gravity-free vehicle motion (n, 3) [m/s^2]: band-limited noise of a few tenths of a m/s^2."""
    from scipy import signal

    rng = np.random.default_rng(seed)
    n = int(DURATION_S * FS)
    sos = signal.butter(2, [0.3, 20.0], btype="bandpass", fs=FS, output="sos")
    return signal.sosfilt(sos, rng.standard_normal((n, 3)), axis=0) * np.array([0.4, 0.3, 0.5])


def _time() -> np.ndarray:
    return np.arange(int(DURATION_S * FS)) / FS


def _sensor(a: np.ndarray, tilt_deg) -> np.ndarray:
    """What a sensor turned by tilt_deg(t) about x reads: R (a + g up), per sample."""
    th = np.radians(np.broadcast_to(np.asarray(tilt_deg, dtype=float), (a.shape[0],)))
    f = a + np.array([0.0, 0.0, G])
    c, s = np.cos(th), np.sin(th)
    return np.column_stack([f[:, 0], c * f[:, 1] - s * f[:, 2], s * f[:, 1] + c * f[:, 2]])


def _knock(a: np.ndarray, t_s: float, peak: float) -> None:
    """A knock: a 0.1 s half-sine of ``peak`` m/s^2 on every axis, at t_s."""
    t = _time()
    near = (t >= t_s) & (t < t_s + 0.1)
    a[near] += peak * np.sin(np.pi * (t[near] - t_s) / 0.1)[:, None]


def _handled() -> np.ndarray:
    """SYNTHETIC: a phone held at 35 deg for 4 s, turned into place over 1 s and knocked down at 5.3 s; at the end
    knocked at 115.5 s and picked up, turned to 30 deg from 116 s; the drive between lies at 2 deg."""
    t = _time()
    tilt = np.full(t.size, 2.0)
    tilt[t < 4.0] = 35.0
    turn = (t >= 4.0) & (t < 5.0)
    tilt[turn] = 35.0 - 33.0 * (t[turn] - 4.0)
    tail = t >= 116.0
    tilt[tail] = 2.0 + 28.0 * np.minimum(1.0, t[tail] - 116.0)
    a = _vehicle()
    rng = np.random.default_rng(1)
    a[t < 5.0] += rng.normal(0.0, 1.5, (int(np.sum(t < 5.0)), 3))  # the hand's own motion
    _knock(a, 5.3, 15.0)
    _knock(a, 115.5, 15.0)
    return _sensor(a, tilt)


def _frame(acc: np.ndarray) -> pd.DataFrame:
    return pd.DataFrame({"x": acc[:, 0], "y": acc[:, 1], "z": acc[:, 2]})


def _read(acc: np.ndarray, **kw):
    """read_motion of a SYNTHETIC frame; its warnings returned with it (the gravity note comes always)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        motion = read_motion(_frame(acc), CHANNELS, rate_hz=FS, label="synthetic.csv", **kw)
    assert all(issubclass(w.category, EhmWarning) for w in caught), [str(w.message) for w in caught]
    return motion, [str(w.message) for w in caught]


def test_a_handled_start_and_end_are_found_where_they_are():
    i0, i1, stretches = find_handling(_time(), _handled())
    start, end = stretches
    assert (start.where, end.where) == ("start", "end")
    # the turn ends at 5 s (plus the 1 s mean), the knock at 5.4 s: cut to 6-7 s; the end from 114.5-115.5 s
    assert 6.0 <= start.end_s <= 7.0 and start.start_s == 0.0
    assert 114.0 <= end.start_s <= 115.5 and end.end_s == pytest.approx(DURATION_S - 1 / FS)
    assert start.turn_deg == pytest.approx(33.0, abs=3.0) and end.turn_deg == pytest.approx(28.0, abs=3.0)
    assert start.peak_mps2 > 10.0
    assert _time()[i0] == pytest.approx(start.end_s, abs=1 / FS) and _time()[i1 - 1] == pytest.approx(end.start_s,
                                                                                                      abs=1 / FS)


def test_read_motion_leaves_a_handled_start_and_end_out_with_a_note_naming_the_cut_and_the_option():
    acc = _handled()
    motion, notes = _read(acc)
    said = [n for n in notes if "handled" in n]
    assert len(said) == 1
    assert "at the start 0.0-6." in said[0] and "--keep-handling (handling='keep')" in said[0]
    assert [h["where"] for h in motion.handling] == ["start", "end"]
    assert "handled start 0.0-6." in motion.description
    assert 107.0 < motion.duration_s < 109.5
    assert motion.time_s[0] == 0.0
    # kept, every sample is read and nothing is said about handling
    kept, notes = _read(acc, handling="keep")
    assert kept.n_samples == acc.shape[0] and kept.handling == () and not any("handled" in n for n in notes)
    # the figures: the cut log's seat values are the drive's, the kept one's are the hand's
    drive = _vehicle()[int(7 * FS):int(114 * FS)]
    assert np.std(motion.acc_mps2[:, 2]) == pytest.approx(np.std(drive[:, 2]), rel=0.1)
    assert np.std(kept.acc_mps2[:, 2]) > 1.3 * np.std(drive[:, 2])


def test_a_pothole_and_a_braking_near_the_start_and_in_the_middle_are_not_cut():
    # SYNTHETIC: no turn anywhere, but knocks of 2 g (potholes) at 3 s, 60 s and 118 s, and the vehicle braking at
    # 0.3 g for 4 s from 2 s (its specific force turns by 17 deg, its component along gravity stays g)
    a = _vehicle()
    for at in (3.0, 60.0, 118.0):
        _knock(a, at, 20.0)
    t = _time()
    a[(t >= 2.0) & (t < 6.0), 0] -= 0.3 * G
    assert find_handling(t, _sensor(a, 2.0)) == (0, t.size, ())
    motion, notes = _read(_sensor(a, 2.0))
    assert motion.n_samples == t.size and motion.handling == () and not any("handled" in n for n in notes)


def test_a_log_without_handling_reads_the_same_with_and_without_the_cut():
    acc = _sensor(_vehicle(), 3.0)
    cut, _ = _read(acc)
    kept, _ = _read(acc, handling="keep")
    np.testing.assert_array_equal(cut.acc_mps2, kept.acc_mps2)
    assert cut.description == kept.description


def test_a_cut_never_reaches_beyond_a_fifth_of_the_log():
    # SYNTHETIC: the logger turned for the first 30 % of the log: the cut stops at 20 %
    t = _time()
    i0, _, (start,) = find_handling(t, _sensor(_vehicle(), np.where(t < 36.0, 30.0, 2.0)))
    assert start.end_s <= MAX_SHARE * DURATION_S + 1e-9 and t[i0] <= MAX_SHARE * DURATION_S + 1 / FS


def test_a_turn_in_the_drive_away_from_the_edges_is_not_a_handled_start_or_end():
    # SYNTHETIC: the logger turned by 30 deg for 3 s at 10 s and at 105 s (inside the first and last fifth, but with
    # 10 and 12 s of drive between it and the log's edges): not a start or an end, so nothing is cut
    t = _time()
    tilt = np.where(((t > 10.0) & (t < 13.0)) | ((t > 105.0) & (t < 108.0)), 30.0, 2.0)
    assert find_handling(t, _sensor(_vehicle(), tilt)) == (0, t.size, ())


def test_logs_without_gravity_and_imu_and_earth_logs_are_not_looked_at():
    acc = _handled()
    free = acc - np.array([0.0, 0.0, G])  # no longer gravity: nothing to see the orientation by
    assert find_handling(_time(), free)[2] == ()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        motion = read_motion(_frame(acc), CHANNELS, rate_hz=FS, frame="earth")
    assert motion.handling == () and not any("handled" in str(w.message) for w in caught)


def test_the_note_and_option_reach_the_assessment_summary():
    summary = handling_summary(({"where": "start", "start_s": 0.0, "end_s": 6.2, "turn_deg": 33.0, "turned_s": 4.0,
                                 "peak_mps2": 16.0, "drive_peak_mps2": 1.0},))
    assert "the start (0.0-6.2 s) of the log left out" in summary["note"]
    assert summary["keep_with"] == "--keep-handling (read_motion(..., handling='keep'))"


def test_the_resampled_motion_keeps_what_was_cut():
    motion, _ = _read(_handled())
    assert motion.resample(0.01).handling == motion.handling


@pytest.mark.parametrize("bad", ["no", True, None, "Keep"])
def test_handling_takes_cut_or_keep_only(bad):
    with pytest.raises(InputError, match=r"handling must be 'cut' .* or 'keep' \(--keep-handling\)"):
        read_motion(_frame(_handled()), CHANNELS, rate_hz=FS, handling=bad)


def test_thresholds_are_what_the_docs_say():
    from ehm.inputs import handling

    assert handling.ALONG_TOLERANCE == 0.03 and math.degrees(math.acos(1 - handling.ALONG_TOLERANCE)) == \
        pytest.approx(14.1, abs=0.1)
    assert (handling.SUSTAIN_S, handling.MAX_SHARE, handling.SPIKE_MIN_MPS2) == (1.0, 0.2, 0.5 * G)


def test_assess_names_the_cut_in_the_console_the_json_and_the_report(tmp_path, capsys):
    import json

    from ehm.interfaces.cli import main

    acc = _handled()
    pd.DataFrame({"x": acc[:, 0], "y": acc[:, 1], "z": acc[:, 2]}).to_csv(tmp_path / "phone.csv", sep=" ",
                                                                          index=False)
    out = tmp_path / "a"
    with warnings.catch_warnings():
        warnings.simplefilter("always")  # the command prints its notes on stderr
        assert main(["assess", "--motion", str(tmp_path / "phone.csv"), "--channel", "time=", "--rate", "50",
                     "--channel", "ax=x", "--channel", "ay=y", "--channel", "az=z", "--method", "linear", "-q",
                     "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert "the logger was handled, not carried by the vehicle, at the start 0.0-6." in captured.err
    assert "  handled logger: the start (0.0-6." in captured.out and "--keep-handling" in captured.out
    cut = json.loads((out / "assessment.json").read_text())["handling_cut"]
    assert [h["where"] for h in cut["stretches"]] == ["start", "end"]
    assert "Handled logger:" in (out / "report.html").read_text()
