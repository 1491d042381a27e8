"""Gravity in a seat/floor log, weighting filters that start at the steady state, and the band a log covers.

Every fixture here is SYNTHETIC (random noise, a made-up tilt), written for these tests.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd
import pytest

from ehm import read_motion
from ehm.errors import InputError
from ehm.inputs.motion import SeatMotion
from ehm.standards.comfort import metrics

G = 9.80665
FS = 200.0
CHANNELS = {"time": None, "ax": "x", "ay": "y", "az": "z"}


def _vehicle(duration_s: float = 60.0, seed: int = 3) -> np.ndarray:
    """SYNTHETIC gravity-free vehicle motion (n, 3) [m/s^2]: band-limited noise, quiet from 20 to 27 s."""
    from scipy import signal

    rng = np.random.default_rng(seed)
    n = int(duration_s * FS)
    sos = signal.butter(2, [0.2, 20.0], btype="bandpass", fs=FS, output="sos")
    a = signal.sosfilt(sos, rng.standard_normal((n, 3)), axis=0) * np.array([0.6, 0.4, 0.8])
    t = np.arange(n) / FS
    a[(t > 20) & (t < 27)] *= 0.02  # the vehicle standing: only the sensor's noise
    return a


def _tilted_with_gravity(a: np.ndarray, tilt_deg: float) -> np.ndarray:
    """What a sensor tilted by tilt_deg about x reads: R (a + g up), R the tilt."""
    c, s = math.cos(math.radians(tilt_deg)), math.sin(math.radians(tilt_deg))
    rot = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    return (a + np.array([0.0, 0.0, G])) @ rot.T


def _figures(acc: np.ndarray) -> dict:
    out = {}
    for j, (axis, w) in enumerate(zip("xyz", ("Wd", "Wd", "Wk"))):
        m = metrics(acc[:, j], FS, w)
        out[f"a_w_{axis}"], out[f"vdv_{axis}"] = m.a_w, m.vdv
    out["a_v"] = math.sqrt(sum(out[f"a_w_{a}"] ** 2 for a in "xyz"))
    out["msdv_z"] = metrics(acc[:, 2], FS, "Wk").msdv
    return out


def _frame(acc: np.ndarray) -> pd.DataFrame:
    return pd.DataFrame({"x": acc[:, 0], "y": acc[:, 1], "z": acc[:, 2]})


def test_a_tilted_log_with_gravity_gives_the_figures_of_the_level_log():
    # SYNTHETIC: the same vehicle motion, once gravity-free and level, once read by a sensor tilted 3 deg with
    # gravity in it (read with the default gravity="auto").  On the code before gravity handling the second one
    # kept its +9.81 (a step at t = 0) and its tilt: MSDV_z several times too large.
    a = _vehicle()
    level = read_motion(_frame(a), CHANNELS, rate_hz=FS)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tilted = read_motion(_frame(_tilted_with_gravity(a, 3.0)), CHANNELS, rate_hz=FS)
    ref, got = _figures(level.acc_mps2), _figures(tilted.acc_mps2)
    for key in ref:
        assert got[key] == pytest.approx(ref[key], rel=0.01), key


def test_auto_says_what_it_did_and_included_levels_whatever_the_mean():
    raw = _tilted_with_gravity(_vehicle(), 3.0)
    with pytest.warns(UserWarning, match=r"within 10% of g.*levelled: tilt 3\.0\d deg, g 9\.8\d* m/s\^2 removed, "
                                         r"from the quietest window 2\d"):
        m = read_motion(_frame(raw), CHANNELS, rate_hz=FS)
    assert "levelled: tilt 3.0" in m.description
    assert abs(np.mean(m.acc_mps2[:, 2])) < 0.05
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # "included" levels without a warning: it was asked for
        m2 = read_motion(_frame(raw), CHANNELS, rate_hz=FS, gravity="included")
    np.testing.assert_allclose(m2.acc_mps2, m.acc_mps2)
    # a gravity-free log is taken as it is by auto, without a word
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        free = read_motion(_frame(_vehicle()), CHANNELS, rate_hz=FS)
    assert "levelled" not in free.description


def test_removed_refuses_one_g_and_a_mean_vertical_offset():
    raw = _tilted_with_gravity(_vehicle(), 3.0)
    with pytest.raises(InputError, match=r"gravity removed.*cannot be a vehicle's.*within 10% of g"):
        read_motion(_frame(raw), CHANNELS, rate_hz=FS, gravity="removed")
    offset = _vehicle() + np.array([0.0, 0.0, 3.0])
    with pytest.raises(InputError, match="mean z above 2 m/s"):
        read_motion(_frame(offset), CHANNELS, rate_hz=FS, gravity="removed")
    ok = read_motion(_frame(_vehicle()), CHANNELS, rate_hz=FS, gravity="removed")
    assert "levelled" not in ok.description
    with pytest.raises(InputError, match="gravity must be one of auto, included, removed"):
        read_motion(_frame(_vehicle()), CHANNELS, rate_hz=FS, gravity="yes")


def test_imu_logs_are_left_to_the_imu_route():
    # SYNTHETIC IMU at rest then shaken a little: gravity handled by from_imu, not levelled by the reader
    n = int(10 * FS)
    rng = np.random.default_rng(1)
    acc = np.tile([0.0, 0.0, G], (n, 1)) + 0.01 * rng.standard_normal((n, 3))
    df = pd.DataFrame({"x": acc[:, 0], "y": acc[:, 1], "z": acc[:, 2], "p": np.zeros(n), "q": np.zeros(n),
                       "r": np.zeros(n)})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = read_motion(df, {**CHANNELS, "wx": "p", "wy": "q", "wz": "r"}, rate_hz=FS, imu=True)
    assert "levelled" not in m.description


def test_a_log_that_starts_at_a_level_has_no_start_up_transient():
    # SYNTHETIC: noise on a 1 m/s^2 offset from t = 0.  The weighting filters start in the steady state for the
    # start level, so MSDV (and a_w, VDV) equal those of the same signal minus its mean; from rest (the old
    # code) the offset was a step at t = 0 and MSDV_z counted its transient (about 3 times too large here).
    x = _vehicle(120.0, seed=5)[:, 2]
    for w in ("Wk", "Wd", "Wf"):
        a, b = metrics(x + 1.0, FS, w), metrics(x - x.mean(), FS, w)
        assert a.msdv == pytest.approx(b.msdv, rel=0.01), w
        assert a.a_w == pytest.approx(b.a_w, rel=0.01), w
        assert a.vdv == pytest.approx(b.vdv, rel=0.01), w


def test_the_band_of_a_20_hz_log_warns_about_wk():
    from ehm.analysis.assessment import band_coverage, band_warnings, input_band

    n = int(60 * 20)
    motion = SeatMotion(np.arange(n) / 20.0, np.zeros((n, 3)), "SYNTHETIC 20 Hz log")
    band = input_band(motion, 1000.0)
    assert band[0] == pytest.approx(1 / motion.duration_s)
    assert band[1] == pytest.approx(8.0)  # 0.4 x 20 Hz: where the resampling to the model's rate starts to cut
    shares = band_coverage(band)
    assert shares["Wf"] == 0.0
    assert 0.2 < shares["Wk"] < 0.6 and 0.0 < shares["Wd"] < shares["Wk"]
    sentences = band_warnings(band, shares)
    assert any(s.startswith("the input covers 0.0167-8 Hz, not all of the Wk band (0.5-80 Hz):") for s in sentences)
    # a 500 Hz log covers every band
    m500 = SeatMotion(np.arange(30000) / 500.0, np.zeros((30000, 3)), "SYNTHETIC 500 Hz log")
    assert band_warnings(input_band(m500, 1000.0), band_coverage(input_band(m500, 1000.0))) == []


def test_a_log_resampled_by_the_reader_reports_the_band_of_its_own_rate():
    # SYNTHETIC 100 Hz log read onto a 500 Hz grid (--rate 500): it holds nothing above 40 Hz, 0.4 x 100 Hz
    import pandas as pd

    from ehm import read_motion
    from ehm.analysis.assessment import input_band

    rng = np.random.default_rng(4)
    t = np.arange(0.0, 30.0, 0.01)
    acc = 0.3 * rng.standard_normal((t.size, 3))
    frame = pd.DataFrame({"time_s": t, "ax_mps2": acc[:, 0], "ay_mps2": acc[:, 1], "az_mps2": acc[:, 2]})
    fast = read_motion(frame, rate_hz=500.0)
    assert fast.content_limit_hz == pytest.approx(40.0)
    assert input_band(fast, 1000.0)[1] == pytest.approx(40.0)  # not 0.4 x 500 Hz
    own = read_motion(frame)
    assert own.content_limit_hz is None and input_band(own, 1000.0)[1] == pytest.approx(40.0)
    assert own.resample(0.02).content_limit_hz == pytest.approx(20.0)  # down to 50 Hz: 0.4 x 50 Hz
