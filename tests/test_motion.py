"""Tests for ehm.inputs.motion: generated seat motions, resampling and CSV loading."""

from __future__ import annotations

import re

import numpy as np
import pytest
from scipy import signal

from ehm.errors import InputError
from ehm.inputs.motion import (
    SeatMotion,
    parse_axes,
    random_vibration,
    sine,
    sweep,
)
from ehm.inputs.readers import (
    load_motion_csv,  # outside data comes in through ehm.inputs.readers (also ehm.load_motion_csv)
)


def rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(values))))


# --------------------------------------------------------------------------
# parse_axes
# --------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("x", (0,)),
        ("y", (1,)),
        ("z", (2,)),
        ("xz", (0, 2)),
        ("zx", (0, 2)),
        ("xyz", (0, 1, 2)),
        ("all", (0, 1, 2)),
        (" Z ", (2,)),
    ],
)
def test_parse_axes_accepts(text, expected):
    assert parse_axes(text) == expected


@pytest.mark.parametrize("bad", ["", "w", "xw", "xx", "alll", 3, None])
def test_parse_axes_rejects_with_value_named(bad):
    with pytest.raises(InputError, match=re.escape(repr(bad))):
        parse_axes(bad)


# --------------------------------------------------------------------------
# random_vibration
# --------------------------------------------------------------------------


def test_random_rms_exact_and_other_axes_zero():
    motion = random_vibration("z", 20.0, 0.3, seed=1)
    assert rms(motion.axis("z")) == pytest.approx(0.3, rel=1e-12)
    assert not motion.axis("x").any()
    assert not motion.axis("y").any()
    assert motion.time_s[0] == 0.0
    assert motion.duration_s == pytest.approx(20.0)
    assert motion.acc_mps2.shape == (20001, 3)
    assert np.allclose(np.diff(motion.time_s), 0.001)
    assert "0.3 m/s^2 rms" in motion.description and "seed 1" in motion.description


def test_random_band_content():
    motion = random_vibration("z", 60.0, 1.0, seed=0)
    freq, psd = signal.welch(motion.axis("z"), fs=1000.0, nperseg=8192)
    total = psd.sum()
    assert psd[freq > 15.0].sum() / total < 0.01
    assert psd[(freq > 0.0) & (freq < 0.05)].sum() / total < 0.01


def test_random_fades_to_zero_at_ends():
    motion = random_vibration("xyz", 5.0, 0.5, seed=3)
    assert np.all(motion.acc_mps2[0] == 0.0)
    assert np.all(motion.acc_mps2[-1] == 0.0)
    # Fade lasts 0.5 s (10 % of 5 s): small acceleration just after the start.
    assert np.all(np.abs(motion.acc_mps2[:5]) < 0.01)


def test_random_seed_determinism():
    a = random_vibration("xz", 10.0, 0.4, seed=7)
    b = random_vibration("xz", 10.0, 0.4, seed=7)
    c = random_vibration("xz", 10.0, 0.4, seed=8)
    np.testing.assert_array_equal(a.acc_mps2, b.acc_mps2)
    np.testing.assert_array_equal(a.time_s, b.time_s)
    assert not np.allclose(a.axis("z"), c.axis("z"))


def test_random_axis_signal_independent_of_other_axes():
    alone = random_vibration("z", 5.0, 0.4, seed=2)
    together = random_vibration("all", 5.0, 0.4, seed=2)
    np.testing.assert_array_equal(alone.axis("z"), together.axis("z"))


def test_random_unseeded_runs():
    motion = random_vibration("y", 2.0, 0.2, seed=None)
    assert rms(motion.axis("y")) == pytest.approx(0.2, rel=1e-12)
    assert "unseeded" in motion.description


def test_random_zero_rms_gives_zeros():
    motion = random_vibration("xyz", 3.0, 0.0)
    assert motion.acc_mps2.shape == (3001, 3)
    assert not motion.acc_mps2.any()


def test_random_multiple_axes_independent():
    motion = random_vibration("xyz", 120.0, 0.3, seed=0)
    for i in range(3):
        assert rms(motion.acc_mps2[:, i]) == pytest.approx(0.3, rel=1e-12)
    corr = np.corrcoef(motion.acc_mps2.T)
    off_diagonal = corr[np.triu_indices(3, k=1)]
    assert np.all(np.abs(off_diagonal) < 0.1)


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"duration_s": 0.0}, r"duration_s must be > 0, got 0\.0"),
        ({"duration_s": float("inf")}, r"duration_s must be finite, got inf"),
        ({"duration_s": "10"}, r"duration_s must be a number, got '10'"),
        ({"rms_mps2": -0.1}, r"rms_mps2 must be >= 0, got -0\.1"),
        ({"rms_mps2": float("nan")}, r"rms_mps2 must be finite, got nan"),
        ({"dt_s": 0.0}, r"dt_s must be > 0, got 0\.0"),
        ({"dt_s": -0.001}, r"dt_s must be > 0, got -0\.001"),
        ({"band_hz": (0.0, 12.0)}, r"band_hz low must be > 0, got 0\.0"),
        ({"band_hz": (12.0, 5.0)}, r"band_hz low \(12\.0 Hz\) must be below band_hz high \(5\.0 Hz\)"),
        ({"band_hz": (1.0, 500.0)}, r"band_hz high = 500\.0 Hz must be below the Nyquist"),
        ({"band_hz": (1.0, 30.0), "dt_s": 0.02}, r"band_hz high = 30\.0 Hz .* Nyquist frequency 25 Hz"),
        ({"band_hz": 5.0}, r"band_hz must be a pair"),
        ({"seed": -1}, r"seed must be >= 0, got -1"),
        ({"seed": 1.5}, r"seed must be a whole number or None, got 1\.5"),
        ({"axis": "q"}, r"Unknown axis 'q'"),
    ],
)
def test_random_validation(kwargs, pattern):
    args = {"axis": "z", "duration_s": 2.0, "rms_mps2": 0.3}
    args.update(kwargs)
    with pytest.raises(InputError, match=pattern):
        random_vibration(**args)


# --------------------------------------------------------------------------
# sine and sweep
# --------------------------------------------------------------------------


def test_sine_amplitude_and_frequency():
    motion = sine("y", 10.0, 0.8, 2.5)
    acc = motion.axis("y")
    t = motion.time_s
    middle = (t >= 1.0) & (t <= 9.0)  # outside the 1 s fades
    np.testing.assert_allclose(acc[middle], 0.8 * np.sin(2 * np.pi * 2.5 * t[middle]), atol=1e-12)
    assert np.max(np.abs(acc)) == pytest.approx(0.8, rel=1e-9)
    spectrum = np.abs(np.fft.rfft(acc))
    freq = np.fft.rfftfreq(acc.size, d=0.001)
    assert freq[np.argmax(spectrum)] == pytest.approx(2.5, abs=0.1)
    assert acc[0] == 0.0 and acc[-1] == 0.0
    assert not motion.axis("x").any() and not motion.axis("z").any()


def test_sine_short_record_fade_is_ten_percent():
    motion = sine("z", 2.0, 1.0, 5.0)
    t = motion.time_s
    middle = (t >= 0.2) & (t <= 1.8)
    np.testing.assert_allclose(motion.axis("z")[middle], np.sin(2 * np.pi * 5.0 * t[middle]), atol=1e-12)
    inside_fade = (t > 0.0) & (t < 0.2)
    assert np.all(np.abs(motion.axis("z")[inside_fade]) < np.abs(np.sin(2 * np.pi * 5.0 * t[inside_fade])) + 1e-15)


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"freq_hz": 0.0}, r"freq_hz must be > 0"),
        ({"freq_hz": 600.0}, r"freq_hz = 600\.0 Hz must be below the Nyquist"),
        ({"amplitude_mps2": -1.0}, r"amplitude_mps2 must be >= 0"),
        ({"duration_s": 0.0005}, r"shorter than one time step"),
    ],
)
def test_sine_validation(kwargs, pattern):
    args = {"axis": "z", "duration_s": 2.0, "amplitude_mps2": 1.0, "freq_hz": 2.0}
    args.update(kwargs)
    with pytest.raises(InputError, match=pattern):
        sine(**args)


def test_sweep_frequency_rises_logarithmically():
    motion = sweep("x", 20.0, 1.0, 1.0, 16.0)
    acc = motion.axis("x")
    assert np.max(np.abs(acc)) <= 1.0 + 1e-12
    assert np.max(np.abs(acc)) > 0.99
    assert acc[0] == 0.0 and acc[-1] == 0.0
    # Instantaneous frequency from zero crossings: log sweep is at sqrt(1*16) = 4 Hz at mid-time.
    t = motion.time_s
    crossings = t[1:][np.diff(np.signbit(acc)) != 0]
    window = crossings[(crossings > 9.0) & (crossings < 11.0)]
    freq_mid = (window.size - 1) / (2.0 * (window[-1] - window[0]))
    assert freq_mid == pytest.approx(4.0, rel=0.1)


def test_sweep_validation():
    with pytest.raises(InputError, match=r"f1_hz = 800\.0 Hz must be below the Nyquist"):
        sweep("z", 10.0, 1.0, 1.0, 800.0)
    with pytest.raises(InputError, match=r"f0_hz must be > 0"):
        sweep("z", 10.0, 1.0, 0.0, 10.0)


# --------------------------------------------------------------------------
# SeatMotion
# --------------------------------------------------------------------------


def test_resample_follows_a_band_limited_signal():
    # A 3 Hz sine sampled at 100 Hz, on a record starting at 1 s, resampled to 1 ms (polyphase, x10): the
    # sine itself at the new times, away from the filter's reach at the ends (0.2 s).  Measured: 3e-5.
    time_s = 1.0 + np.arange(501) * 0.01
    wave = lambda t: np.sin(2 * np.pi * 3.0 * t)  # noqa: E731
    motion = SeatMotion(time_s, np.column_stack([wave(time_s), -wave(time_s), 0.5 * wave(time_s)]), "test")
    out = motion.resample(0.001)
    np.testing.assert_allclose(out.time_s, np.arange(5001) * 0.001, atol=1e-12)
    inner = (out.time_s > 0.2) & (out.time_s < 4.8)
    expected = wave(out.time_s + 1.0)
    np.testing.assert_allclose(out.acc_mps2[inner, 0], expected[inner], atol=2e-4)
    np.testing.assert_allclose(out.acc_mps2[inner, 2], 0.5 * expected[inner], atol=2e-4)
    assert "resampled" in out.description


def test_resample_irregular_record_goes_through_its_median_step():
    # Time steps 0.3, 0.7, 0.05, 1.45 s, then 0.5 s: first linearly onto a uniform grid at the median step
    # (0.5 s), then polyphase; a linear function stays linear beyond the filter's reach from the ends (20
    # samples of 0.5 s), to the Kaiser filter's ripple (measured 3e-4 on values up to 80).
    time_s = np.concatenate([[1.0, 1.3, 2.0, 2.05], np.arange(3.5, 41.0, 0.5)])
    acc = np.column_stack([2.0 * time_s + 1.0, -time_s, 0.5 * time_s - 3.0])
    out = SeatMotion(time_s, acc, "test").resample(0.1)
    np.testing.assert_allclose(out.time_s, np.arange(396) * 0.1, atol=1e-12)  # 39.5 s
    shifted = out.time_s + 1.0
    inner = (out.time_s > 10.5) & (out.time_s < 29.5)
    np.testing.assert_allclose(out.acc_mps2[inner, 0], (2.0 * shifted + 1.0)[inner], atol=2e-3)


def test_resample_removes_what_would_alias():
    # The case: a 10 kHz file holding a 1010 Hz component (amplitude 1) and a 10 Hz one (0.1).  Plain
    # interpolation onto 1 ms would turn the 1010 Hz into a full-strength 10 Hz input; the anti-alias filter
    # leaves 0.1 sin(2 pi 10 t) within 1e-4 (measured 6e-6).
    t = np.arange(100_000) / 10_000.0
    x = np.sin(2 * np.pi * 1010.0 * t) + 0.1 * np.sin(2 * np.pi * 10.0 * t)
    out = SeatMotion(t, np.column_stack([x, 0 * x, 0 * x]), "10 kHz").resample(0.001)
    inner = slice(500, -500)
    resid = out.acc_mps2[inner, 0] - 0.1 * np.sin(2 * np.pi * 10.0 * out.time_s[inner])
    assert rms(resid) < 1e-4
    plain = np.interp(out.time_s, t, x) - 0.1 * np.sin(2 * np.pi * 10.0 * out.time_s)
    assert rms(plain[inner]) > 0.5  # what interpolation would have fed the model


def test_resample_keeps_the_weighted_rms_of_a_100_hz_log():
    # A 100 Hz log of content up to 40 Hz (0.4 fs), brought to the model's 1 kHz: the Wk-weighted rms equals
    # the original 1 kHz signal's within 0.5 % (measured 0.001 %); linear interpolation loses 6.8 % (measured).
    from ehm.standards.comfort import metrics

    rng = np.random.default_rng(2)
    fine = signal.sosfiltfilt(signal.butter(8, [0.5, 40.0], btype="band", fs=1000.0, output="sos"),
                              rng.standard_normal(60_000))
    t = np.arange(fine.size) / 1000.0
    log = SeatMotion(t[::10], np.column_stack([0 * fine[::10], 0 * fine[::10], fine[::10]]), "100 Hz log")
    up = log.resample(0.001).acc_mps2[:, 2]
    truth = metrics(fine[: up.size], 1000.0, "Wk").a_w
    assert metrics(up, 1000.0, "Wk").a_w == pytest.approx(truth, rel=5e-3)
    linear = np.interp(t[: up.size], t[::10], fine[::10])
    assert metrics(linear, 1000.0, "Wk").a_w < 0.97 * truth


def test_resample_chunk_by_chunk_equals_whole():
    # Resampler blocks read the record with the filter's margin: any split gives the whole-record samples.
    from ehm.inputs.motion import Resampler

    rng = np.random.default_rng(0)
    for fs_in, dt in ((100.0, 0.001), (1024.0, 0.001), (10_000.0, 0.0005)):
        t = 3.0 + np.arange(int(20 * fs_in)) / fs_in
        r = Resampler(t, rng.standard_normal((t.size, 4)), dt)
        whole = r.block(0, r.n_samples)
        parts = np.vstack([r.block(a, min(a + 777, r.n_samples)) for a in range(0, r.n_samples, 777)])
        np.testing.assert_array_equal(parts, whole)


def test_resample_non_multiple_duration_stays_inside():
    motion = SeatMotion(np.array([0.0, 1.0]), np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]]), "ramp")
    out = motion.resample(0.3)
    np.testing.assert_allclose(out.time_s, [0.0, 0.3, 0.6, 0.9])


@pytest.mark.parametrize(
    ("dt", "pattern"),
    [
        (0.0, r"dt_s must be > 0"),
        (-0.1, r"dt_s must be > 0"),
        (float("nan"), r"dt_s must be finite"),
        (5.0, r"dt_s = 5\.0 s is longer than the motion duration"),
    ],
)
def test_resample_validation(dt, pattern):
    motion = SeatMotion(np.array([0.0, 1.0]), np.zeros((2, 3)), "flat")
    with pytest.raises(InputError, match=pattern):
        motion.resample(dt)


def test_axis_names():
    motion = SeatMotion(np.array([0.0, 1.0]), np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]), "m")
    np.testing.assert_array_equal(motion.axis("x"), [1.0, 4.0])
    np.testing.assert_array_equal(motion.axis("y"), [2.0, 5.0])
    np.testing.assert_array_equal(motion.axis("Z"), [3.0, 6.0])
    for bad in ["w", "xy", "", 0]:
        with pytest.raises(InputError, match=re.escape(repr(bad))):
            motion.axis(bad)


def test_seat_motion_is_immutable_and_validated():
    motion = SeatMotion([0.0, 0.5, 1.0], np.zeros((3, 3)), "m")
    with pytest.raises(ValueError):
        motion.acc_mps2[0, 0] = 1.0
    with pytest.raises(InputError, match=r"time_s\[2\] = 0\.5 s is not after time_s\[1\] = 0\.5 s"):
        SeatMotion([0.0, 0.5, 0.5], np.zeros((3, 3)), "m")
    with pytest.raises(InputError, match=r"shape \(3, 3\)"):
        SeatMotion([0.0, 0.5, 1.0], np.zeros((3, 2)), "m")
    with pytest.raises(InputError, match=r"acc_mps2\[1, 2\] \(z\) is nan"):
        SeatMotion([0.0, 0.5, 1.0], [[0, 0, 0], [0, 0, np.nan], [0, 0, 0]], "m")
    with pytest.raises(InputError, match=r"start at or after 0 s"):
        SeatMotion([-1.0, 0.5], np.zeros((2, 3)), "m")
    with pytest.raises(InputError, match=r"at least 2 samples"):
        SeatMotion([0.0], np.zeros((1, 3)), "m")


# --------------------------------------------------------------------------
# load_motion_csv
# --------------------------------------------------------------------------
# (The hand tables here keep a mean z within 2 m/s^2: a larger one is refused on reading as an offset.)

GOOD_CSV = """\
# seat rig, run 4
time_s,ax_mps2,ay_mps2,az_mps2,comment_col
0.0,0.1,0.2,0.3,a
0.01,0.4,0.5,0.6,b

# a comment in the middle
0.02,-1e-3,2.5E2,-1,c
"""


def write(tmp_path, text: str, name: str = "motion.csv"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_csv_good_file(tmp_path):
    motion = load_motion_csv(write(tmp_path, GOOD_CSV))
    np.testing.assert_array_equal(motion.time_s, [0.0, 0.01, 0.02])
    np.testing.assert_array_equal(
        motion.acc_mps2, [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6], [-1e-3, 250.0, -1.0]]
    )
    assert "motion.csv" in motion.description


def test_csv_columns_in_any_order_and_str_path(tmp_path):
    text = "az_mps2,time_s,ay_mps2,ax_mps2\n-3,1.0,2,1\n6,1.5,5,4\n"
    motion = load_motion_csv(str(write(tmp_path, text)))
    np.testing.assert_array_equal(motion.time_s, [0.0, 0.5])  # the time axis starts at 0 at the first sample
    np.testing.assert_array_equal(motion.acc_mps2, [[1, 2, -3], [4, 5, 6]])
    assert motion.duration_s == pytest.approx(0.5)
    np.testing.assert_allclose(motion.resample(0.25).time_s, [0.0, 0.25, 0.5])


def test_csv_round_trip_with_generated_motion(tmp_path):
    from ehm.files import write_csv_atomic

    original = random_vibration("xyz", 2.0, 0.3, seed=5, dt_s=0.01)
    path = tmp_path / "out" / "rt.csv"
    write_csv_atomic(
        path,
        ["time_s", "ax_mps2", "ay_mps2", "az_mps2"],
        np.column_stack([original.time_s, original.acc_mps2]),
    )
    loaded = load_motion_csv(path)
    np.testing.assert_allclose(loaded.time_s, original.time_s, rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(loaded.acc_mps2, original.acc_mps2, rtol=1e-8, atol=1e-12)


HEADER = "time_s,ax_mps2,ay_mps2,az_mps2\n"


@pytest.mark.parametrize(
    ("text", "pattern"),
    [
        # wrong number of fields (line 3; the header is line 1)
        (HEADER + "0,0,0,0\n0.1,0,0\n", r"motion\.csv, line 3: expected 4 fields .* found 3"),
        # non-numeric value, quoted, after a comment line
        (
            "# comment\n" + HEADER + "0,0,0,0\n0.1,0,0,abc\n",
            r"motion\.csv, line 4, column az_mps2: 'abc' is not a number\.",
        ),
        # empty value
        (HEADER + "0,0,,0\n0.1,0,0,0\n", r"motion\.csv, line 2, column ay_mps2: value is empty"),
        # NaN and infinity
        (HEADER + "0,nan,0,0\n0.1,0,0,0\n", r"motion\.csv, line 2, column ax_mps2: 'nan' is not a finite"),
        (HEADER + "0,0,0,0\n0.1,0,-inf,0\n", r"motion\.csv, line 3, column ay_mps2: '-inf' is not a finite"),
        (HEADER + "inf,0,0,0\n0.1,0,0,0\n", r"motion\.csv, line 2, column time_s: 'inf' is not a finite"),
        # time not strictly increasing: names both times and the previous line
        (
            HEADER + "0,0,0,0\n0.2,0,0,0\n\n0.2,0,0,0\n",
            r"motion\.csv, line 5, column time_s: time 0\.2 s is not after the time 0\.2 s on line 3",
        ),
        (
            HEADER + "0,0,0,0\n0.2,0,0,0\n0.1,0,0,0\n",
            r"motion\.csv, line 4, column time_s: time 0\.1 s is not after the time 0\.2 s on line 3",
        ),
        # missing columns, named with the columns the file has
        (
            "time_s,ax_mps2,ay_mps2\n0,0,0\n0.1,0,0\n",
            r"motion\.csv: channel az \('az_mps2'\) is not in the file; its columns are time_s, ax_mps2, ay_mps2: read "
            r"it with channels=\{'az': 'NAME'\} \(NAME for az: one of its columns\)\.",
        ),
        (
            "# first\ntime,ax_mps2,ay_mps2\n0,0,0\n",
            r"motion\.csv: channels time \('time_s'\) and az \('az_mps2'\) are not in the file; its columns are "
            r"time, ax_mps2, ay_mps2: read it with channels=\{'time': 'time', 'az': 'NAME'\} \(NAME for az: one of its "
            r"columns; the columns guessed from their names: check them\)\.",
        ),
        (
            "time_s,ax_mps2,ay_mps2,az_mps2,az_mps2\n0,0,0,0,0\n",
            r"motion\.csv, line 1: column az_mps2 appears more than once",
        ),
        # fewer than 2 rows
        (HEADER + "0,0,0,0\n", r"motion\.csv, line 1: motion file has 1 data row\(s\) .* at least 2"),
        (HEADER, r"motion\.csv, line 1: motion file has 0 data row\(s\)"),
        # empty and comment-only files
        ("", r"motion\.csv: motion file is empty\."),
        ("\n  \n", r"motion\.csv: motion file is empty\."),
        ("# nothing\n# here\n", r"motion\.csv: motion file has only comments and no header row\."),
    ],
)
def test_csv_errors(tmp_path, text, pattern):
    path = write(tmp_path, text)
    with pytest.raises(InputError, match=pattern) as info:
        load_motion_csv(path)
    assert str(path) in str(info.value)
    assert info.value.__cause__ is None


def test_csv_file_not_found(tmp_path):
    path = tmp_path / "missing.csv"
    with pytest.raises(InputError, match=r"missing\.csv: motion file not found\."):
        load_motion_csv(path)


def test_csv_directory_not_readable(tmp_path):
    with pytest.raises(InputError, match=r"is a directory"):
        load_motion_csv(tmp_path)


def test_csv_not_utf8(tmp_path):
    path = tmp_path / "motion.csv"
    path.write_bytes(HEADER.encode() + b"0,0,0,0\n0.1,0,\xff\xfe,0\n")
    with pytest.raises(InputError, match=r"motion\.csv, line 3: the file is not UTF-8 text"):
        load_motion_csv(path)


def test_csv_crlf_and_bom(tmp_path):
    path = tmp_path / "motion.csv"
    path.write_bytes(b"\xef\xbb\xbf" + b"time_s,ax_mps2,ay_mps2,az_mps2\r\n0,1,2,-3\r\n1,4,5,6\r\n")
    motion = load_motion_csv(path)
    np.testing.assert_array_equal(motion.acc_mps2, [[1, 2, -3], [4, 5, 6]])


def _long_csv(n: int = 2000, quoted: bool = False) -> tuple[str, np.ndarray]:
    rng = np.random.default_rng(3)
    table = np.column_stack([np.arange(n) * 0.01, rng.normal(size=(n, 3))])
    q = '"' if quoted else ""
    rows = "\n".join(",".join(f"{q}{v!r}{q}" for v in row) for row in table.tolist())
    return "# a long file\ntime_s,ax_mps2,ay_mps2,az_mps2\n" + rows + "\n", table


def test_csv_long_file_bulk_and_row_by_row_agree(tmp_path):
    # Plain files are read in bulk (numpy); anything unusual (here: quoted numbers) row by row.  Both routes
    # give the same arrays, equal to the numbers written (repr round-trips floats exactly).
    plain, table = _long_csv()
    quoted, _ = _long_csv(quoted=True)
    a = load_motion_csv(write(tmp_path, plain, "plain.csv"))
    b = load_motion_csv(write(tmp_path, quoted, "quoted.csv"))
    for m in (a, b):
        np.testing.assert_array_equal(m.time_s, table[:, 0])
        np.testing.assert_array_equal(m.acc_mps2, table[:, 1:])


@pytest.mark.parametrize("row, column, value, words", [
    (1500, 2, "nan", "line 1503, column ay_mps2: 'nan' is not a finite number"),
    (700, 0, "6.985", "line 703, column time_s: time 6.985 s is not after the time 6.99 s on line 702"),
    (900, 3, "", "line 903, column az_mps2: value is empty"),
])
def test_csv_long_file_errors_name_the_line(tmp_path, row, column, value, words):
    # A bad value deep in a long file: the bulk reader declines and the row-by-row reader names line and column
    # (file line = row + 3: a comment line and the header come first, rows count from 0, lines from 1).
    text, _ = _long_csv()
    lines = text.split("\n")
    fields = lines[row + 2].split(",")
    fields[column] = value
    lines[row + 2] = ",".join(fields)
    with pytest.raises(InputError) as exc:
        load_motion_csv(write(tmp_path, "\n".join(lines)))
    assert words in str(exc.value), str(exc.value)


def test_csv_long_file_with_a_field_too_many_is_refused(tmp_path):
    text, _ = _long_csv()
    lines = text.split("\n")
    lines[1202] += ",9"
    with pytest.raises(InputError, match=r"line 1203: expected 4 fields as in the header \(line 2\), found 5"):
        load_motion_csv(write(tmp_path, "\n".join(lines)))


def test_seat_motion_non_numeric_angular_velocity_is_one_sentence():
    with pytest.raises(InputError, match="angvel_radps must be a numeric array"):
        SeatMotion(np.array([0.0, 1.0]), np.zeros((2, 3)), "x", [["a", 0, 0], [0, 0, 0]])


def test_csv_repeated_rotation_column_is_refused(tmp_path):
    text = "time_s,ax_mps2,ay_mps2,az_mps2,wx_radps,wy_radps,wz_radps,wx_radps\n0,0,0,0,0,0,0,1\n1,0,0,0,0,0,0,1\n"
    with pytest.raises(InputError, match="column wx_radps appears more than once"):
        load_motion_csv(write(tmp_path, text))
