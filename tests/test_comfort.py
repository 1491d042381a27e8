"""Tests for ehm.standards.comfort: ISO 2631-1 weightings, their digital filters and the evaluation values."""

from __future__ import annotations

import contextlib
import math

import numpy as np
import pytest
from scipy import signal

from ehm.errors import EhmWarning, InputError
from ehm.standards.comfort import (
    WEIGHTINGS,
    ComfortMetrics,
    WeightingFilter,
    comfort_reaction,
    frequency_weighting,
    metrics,
    seat_value,
    total_value,
    weight,
    weighting_deviation_db,
    weighting_sos,
)

FS = 1000.0  # [Hz], the simulation rate of the package (dt = 1 ms)


def db(x) -> np.ndarray:
    return 20.0 * np.log10(np.abs(x))


def sine(freq_hz: float, amp: float, duration_s: float, fs_hz: float = FS) -> np.ndarray:
    t = np.arange(int(round(duration_s * fs_hz))) / fs_hz
    return amp * np.sin(2.0 * np.pi * freq_hz * t)


# --------------------------------------------------------------------------
# analog weightings against published values
# --------------------------------------------------------------------------

# ISO 2631-1:1997, Table 3: weighting factors x 1000 at the nominal one-third-octave frequencies,
# as printed (same values in ISO 8041).  The tables are computed at the nominal frequencies (at the
# exact base-10 frequencies 10^(n/10) the match is up to 0.3 dB worse), so they are checked there.
# Tolerance: half a unit of the last printed digit, in dB, plus 0.01 dB.
NOMINAL_HZ = [0.5, 0.63, 0.8, 1, 1.25, 1.6, 2, 2.5, 3.15, 4, 5, 6.3, 8, 10, 12.5, 16, 20, 25, 31.5,
              40, 50, 63, 80]
TABLE_WK = ["418", "459", "477", "482", "484", "494", "531", "631", "804", "967", "1039", "1054", "1036",
            "988", "902", "768", "636", "513", "405", "314", "246", "186", "132"]
# Wd at 10 Hz is left out: transcriptions of the table disagree (212 and 201); the transfer function
# gives 201.8, as do its neighbours 253 (8 Hz) and 161 (12.5 Hz) by geometric interpolation.
TABLE_WD = ["853", "944", "992", "1011", "1008", "968", "890", "776", "642", "512", "409", "323", "253",
            None, "161", "125", "100", "80.0", "63.2", "49.4", "38.8", "29.5", "21.1"]
NOMINAL_WF_HZ = [0.02, 0.025, 0.0315, 0.04, 0.05, 0.063, 0.08, 0.1, 0.125, 0.16, 0.2, 0.25, 0.315, 0.4,
                 0.5, 0.63, 0.8, 1, 1.25, 1.6, 2, 2.5, 3.15, 4]
TABLE_WF = ["24.2", "37.7", "59.7", "97.1", "157", "267", "461", "695", "895", "1006", "992", "854", "619",
            "384", "224", "116", "53.0", "23.5", "9.98", "3.77", "1.55", "0.64", "0.25", "0.097"]

TABLE_CASES = (
    [("Wk", f, v) for f, v in zip(NOMINAL_HZ, TABLE_WK)]
    + [("Wd", f, v) for f, v in zip(NOMINAL_HZ, TABLE_WD) if v is not None]
    + [("Wf", f, v) for f, v in zip(NOMINAL_WF_HZ, TABLE_WF)]
)


def printed_tolerance_db(text: str) -> float:
    """Half a unit of the last printed digit of ``text``, in dB, plus 0.01 dB."""
    decimals = len(text.split(".")[1]) if "." in text else 0
    half_ulp = 0.5 * 10.0 ** (-decimals)
    return 20.0 * math.log10(1.0 + half_ulp / float(text)) + 0.01


@pytest.mark.parametrize(("name", "freq_hz", "printed"), TABLE_CASES)
def test_weighting_matches_iso_2631_table(name, freq_hz, printed):
    # Measured |error|: Wk <= 0.024 dB (80 Hz), Wd <= 0.028 dB (16 Hz), Wf <= 0.079 dB (3.15 Hz,
    # where the table prints two digits, 0.25 x 1000); all other Wf points <= 0.06 dB.
    err = db(frequency_weighting(name, freq_hz)) - db(float(printed) / 1000.0)
    assert abs(err) <= printed_tolerance_db(printed)


# ISO 8041:2005 values of each weighting at its reference frequency, 100 rad/s (15.915 Hz), as
# listed by ZETLAB, "Frequency weighting functions"
# (https://zetlab.com/en/shop/virtual-devices/frequency-weighting-functions).
@pytest.mark.parametrize(("name", "value"), [("Wc", 0.5145), ("Wd", 0.1261), ("We", 0.06287), ("Wj", 1.019)])
def test_weighting_matches_iso_8041_reference_value(name, value):
    err = db(frequency_weighting(name, 100.0 / (2.0 * np.pi))) - db(value)
    assert abs(err) <= 0.02  # measured: <= 0.0041 dB (Wj)


def test_weighting_key_points_from_the_brief():
    wk = np.abs(frequency_weighting("Wk", [1.0, 4.0, 6.3, 8.0]))
    assert wk[0] == pytest.approx(0.482, abs=0.001)      # -6.33 dB
    assert np.all((wk[1:] > 0.96) & (wk[1:] < 1.06))    # plateau about 1 from 4 to 8 Hz
    f = np.linspace(4.0, 8.0, 401)
    peak = np.abs(frequency_weighting("Wk", f))
    assert 1.02 < peak.max() < 1.06 and 5.0 < f[np.argmax(peak)] < 7.0
    assert abs(frequency_weighting("Wd", 1.0)) == pytest.approx(1.011, abs=0.001)
    assert abs(frequency_weighting("Wd", 2.0)) == pytest.approx(0.890, abs=0.001)
    f = np.linspace(0.1, 0.3, 401)
    wf = np.abs(frequency_weighting("Wf", f))
    assert 0.99 < wf.max() < 1.02 and 0.14 < f[np.argmax(wf)] < 0.2


def test_upward_step_has_unit_high_frequency_gain():
    # Wj is band limits and upward step only: between the band limits it goes from (f5/f6)^2 to 1.
    mid_low, mid_high = np.abs(frequency_weighting("Wj", [0.4 * 8, 100.0 / 8]))
    assert abs(frequency_weighting("Wj", 25.0)) == pytest.approx(1.0, abs=0.03)
    assert mid_high > mid_low
    assert abs(frequency_weighting("Wk", 0.0)) == 0.0


def test_frequency_weighting_shape_and_case():
    assert frequency_weighting("Wk", 5.0).shape == ()
    out = frequency_weighting("wk", np.ones((2, 3)))
    assert out.shape == (2, 3) and np.iscomplexobj(out)
    assert set(WEIGHTINGS) == {"Wk", "Wd", "Wf", "Wc", "We", "Wj"}


# --------------------------------------------------------------------------
# digital filters
# --------------------------------------------------------------------------


RATES_HZ = (50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0, 10000.0)


@pytest.mark.parametrize("fs", RATES_HZ)
@pytest.mark.parametrize("name", WEIGHTINGS)
def test_digital_response_follows_analog_up_to_0_4_fs(name, fs):
    """Within 1 dB of the analog magnitude from f1/10 to 0.4 fs wherever |W| > -100 dB (the issue's target).

    Measured (ehm.standards.comfort.weighting_sos docstring): at most 0.40 dB over 24 log-spaced rates from 50 Hz to 20
    kHz.
    """
    f1 = {"Wf": 0.08}.get(name, 0.4)
    f = np.union1d(np.geomspace(0.1 * f1, 0.4 * fs, 1500), np.linspace(0.1 * f1, 0.4 * fs, 1500))
    ha = frequency_weighting(name, f)
    sel = np.abs(ha) > 1e-5
    # below 200 Hz the weighting's band (up to 100 Hz) is cut at the Nyquist frequency, and ehm says so
    cut = fs < 200.0 and name != "Wf"  # Wf ends below 1 Hz
    with pytest.warns(EhmWarning, match="reaches up to") if cut else contextlib.nullcontext():
        sos = weighting_sos(name, fs)
    _, hd = signal.sosfreqz(sos, worN=f[sel], fs=fs)
    assert np.max(np.abs(db(hd) - db(ha[sel]))) < 1.0


@pytest.mark.parametrize("name", WEIGHTINGS)
def test_digital_response_in_the_iso_range_at_1khz(name):
    """At the simulation rate, over f1 to 80 Hz (the ISO 2631-1 range): within 0.1 dB and 2 degrees.

    Measured: at most 0.05 dB and 1.63 degrees; the bilinear design it replaced had 0.12 dB / 1.3 deg.
    """
    f1 = {"Wf": 0.08}.get(name, 0.4)
    f = np.geomspace(f1, 80.0, 800)
    ha = frequency_weighting(name, f)
    sel = np.abs(ha) > 1e-5
    _, hd = signal.sosfreqz(weighting_sos(name, FS), worN=f[sel], fs=FS)
    assert np.max(np.abs(db(hd) - db(ha[sel]))) < 0.1
    assert np.max(np.abs(np.degrees(np.angle(hd / ha[sel])))) < 2.0


def test_every_tabulated_design_is_a_converged_fit():
    """Green on every Python (issue 31): each weighting's fit at the tabulated rates stops because it met its
    tolerances, not because it ran out of evaluations.  A fit cut short stops where its path happens to be, and
    the path moves with rounding: cut at 100 evaluations, 9 of these 42 designs stopped short, and Wf at 10 Hz
    differed by 0.2 % at 0.2 Hz between scipy 1.17 and 1.18.  No tolerance: a yes/no per design."""
    from ehm.standards.comfort import weighting

    short = [(name, fs) for name in WEIGHTINGS for fs in RATES_HZ + (10.0,)
             if (name == "Wf" or fs > 10.0) and not weighting._design(name, fs).converged]
    assert short == []


def test_weighting_deviation_db_reports_the_measured_deviation():
    # the same check as above, through the public helper: below 1 dB, and the frequency lies inside 0.4 fs
    for name in WEIGHTINGS:
        dev, at_hz = weighting_deviation_db(name, 100.0)
        assert 0.0 <= dev < 1.0 and 0.0 < at_hz <= 40.0


@pytest.mark.parametrize("kind", ["noise", "shocks"])
@pytest.mark.parametrize("name", ["Wk", "Wd", "Wf", "Wj"])
def test_a_log_at_100_hz_rates_like_the_same_signal_at_1_khz(name, kind):
    """a_w within 2 % and VDV within 3 % of the 1 kHz values for content below 0.3 fs (the issue's target).

    The 100 Hz record is every tenth sample of the 1 kHz one, which holds nothing above 30 Hz (an 8th-order
    Butterworth band 0.2-30 Hz, forward-backward, faded in and out over 6 s so that no edge transient
    dominates VDV), so both hold the same signal over the same 119.99 s.  Measured: at most 0.29 % (a_w) and
    0.44 % (VDV).
    """
    rng = np.random.default_rng(1)
    n = 119_991
    if kind == "noise":
        x = rng.standard_normal(n)
    else:  # 40 isolated shocks: high crest factor, VDV >> a_w T^(1/4)
        x = np.zeros(n)
        x[rng.choice(n, 40, replace=False)] = 50.0 * rng.standard_normal(40)
    x = signal.sosfiltfilt(signal.butter(8, [0.2, 30.0], btype="band", fs=FS, output="sos"), x)
    x *= signal.windows.tukey(n, 0.1)
    fine, coarse = metrics(x, FS, name), metrics(x[::10], 100.0, name)
    assert coarse.a_w == pytest.approx(fine.a_w, rel=0.02)
    assert coarse.vdv == pytest.approx(fine.vdv, rel=0.03)


def test_band_beyond_nyquist_warns_once():
    import warnings

    from ehm.standards.comfort import weighting

    weighting._WARNED.clear()  # the module tested: its record of warnings given
    with pytest.warns(UserWarning, match=r"Wk reaches up to 100 Hz but data sampled at 100 Hz hold nothing "
                                         r"above 50 Hz") as record:
        weight("Wk", np.ones(50), 100.0)
        metrics(np.ones(500), 100.0, "Wk")
        WeightingFilter("Wk", 100.0)
    assert len([w for w in record if "Wk reaches" in str(w.message)]) == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error")      # no warning where the band fits: Wk at 200 Hz, Wf at 10 Hz
        weighting_sos("Wk", 200.0)
        weighting_sos("Wf", 10.0)


def test_digital_wf_at_low_rate():
    f = np.logspace(np.log10(0.008), np.log10(4.0), 300)
    _, hd = signal.sosfreqz(weighting_sos("Wf", 100.0), worN=f, fs=100.0)
    assert np.max(np.abs(db(hd) - db(frequency_weighting("Wf", f)))) < 0.2  # measured 0.181 dB at 4 Hz


@pytest.mark.parametrize("name", WEIGHTINGS)
def test_digital_filter_is_stable(name):
    sos = weighting_sos(name, FS)
    assert sos.ndim == 2 and sos.shape[1] == 6
    for section in sos:
        assert np.all(np.abs(np.roots(section[3:])) < 1.0)


def test_weight_is_causal():
    k = 700
    x = np.zeros(3000)
    x[k] = 1.0
    for name in ("Wk", "Wd", "Wf"):
        y = weight(name, x, FS)
        assert np.all(y[:k] == 0.0)
        assert y[k] != 0.0


def test_weight_applies_the_weighting_once():
    # A forward-backward filter would give |W|^2; a causal one gives |W| (checked after the transient).
    for name, f in (("Wd", 1.0), ("Wk", 1.0), ("Wk", 20.0)):
        y = weight(name, sine(f, 1.0, 20.0), FS)[10_000:]
        gain = np.sqrt(2.0) * np.sqrt(np.mean(y ** 2))
        # |W| there is 0.48-1.01; the digital filter is within 0.05 dB (0.6 %) of it up to 80 Hz (measured 0.14 %)
        assert gain == pytest.approx(abs(frequency_weighting(name, f)), rel=6e-3)


def test_streaming_equals_batch():
    rng = np.random.default_rng(4)
    x = rng.standard_normal(5000)
    for name in ("Wk", "Wf"):
        batch = weight(name, x, FS)
        filt = WeightingFilter(name, FS)
        # the first block holds the record's first START_S (its start level, the median the filter starts from)
        pieces = [filt.process(x[:100]), np.array([filt.step(v) for v in x[100:150]])]
        edges = [150, 151, 400, 400, 1777, 3000, 5000]
        pieces += [filt.process(x[a:b]) for a, b in zip(edges[:-1], edges[1:])]
        np.testing.assert_allclose(np.concatenate(pieces), batch, rtol=0, atol=1e-12)
        filt.reset()
        np.testing.assert_allclose(filt.process(x[:100]), batch[:100], rtol=0, atol=1e-12)


# --------------------------------------------------------------------------
# evaluation values against closed forms
# --------------------------------------------------------------------------


@pytest.mark.parametrize(("name", "freq_hz", "amp"), [("Wk", 5.0, 0.8), ("Wk", 1.0, 2.0), ("Wd", 2.0, 1.5)])
def test_weighted_rms_and_vdv_of_a_sinusoid(name, freq_hz, amp):
    x = sine(freq_hz, amp, 30.0)
    steady = weight(name, x, FS)[10_000:]             # 20 s after discarding 10 s of transient
    gain = abs(signal.sosfreqz(weighting_sos(name, FS), worN=[freq_hz], fs=FS)[1][0])  # the digital filter's
    m = metrics(steady, FS, weighting=None)
    t = steady.size / FS
    assert m.duration_s == pytest.approx(20.0)
    # measured relative errors: <= 4e-5 (rms and VDV), crest factor <= 6e-5
    assert m.a_w == pytest.approx(gain * amp / np.sqrt(2.0), rel=1e-3)
    assert m.vdv == pytest.approx((3.0 / 8.0) ** 0.25 * gain * amp * t ** 0.25, rel=1e-3)
    assert m.mtvv == pytest.approx(m.a_w, rel=1e-3)
    assert m.crest_factor == pytest.approx(np.sqrt(2.0), rel=2e-3)
    assert m.msdv is None
    # the same record weighted inside metrics: only the transient differs; and the analog gain is within 0.6 %
    full = metrics(x, FS, name)
    assert full.a_w == pytest.approx(gain * amp / np.sqrt(2.0), rel=1e-2)  # measured <= 0.34 %
    assert gain == pytest.approx(abs(frequency_weighting(name, freq_hz)), rel=6e-3)


def test_msdv_of_a_sinusoid():
    """MSDV of a sinusoid: |W(f)| A sqrt(T/2) (ISO 2631-1 clause 9.2.2), Wf at a 10 Hz log rate.

    Two parts with their own errors.  Once the filter's start-up transient has died away, MSDV^2 grows by
    exactly |H(f)|^2 A^2 dT / 2 (H: the digital filter actually used; whole periods, so the sum of sin^2 is
    exact): rel 1e-9 is rounding of 10^5-term sums (measured 5e-14; the impulse response's tail after 1000 s is
    below 1e-200).  The whole record differs from the analog closed form by the filter's own error at f
    (|H(f) / W(f)| - 1, measured -6.5e-4) plus the start-up transient e, bounded through the impulse response
    h: |e(t)| <= A sum(|h_j|, j > t fs), so e changes MSDV^2 by at most 2 |H| A^2 sum(j |h_j|) / fs (cross term)
    + A^2 sum((sum(|h_j|, j > n))^2) / fs (its own energy); over 20000 s that is 7.8e-4 of MSDV (measured
    -6.6e-5).

    Issue 31: this once asserted 1e-3 over 2000 s ("measured: 3e-5") and failed at 1.7e-3 on scipy 1.18: the
    filter's fit stopped at 100 evaluations before converging, and where it stopped moved with rounding (scipy
    1.18's MINPACK takes a first step 3e-9 away from 1.17's from identical residuals and Jacobian; numpy 2.5
    changes a residual in its last bit), so MSDV over 2000 s was 31.343 / 31.357 / 31.422 on numpy 2.4 + scipy
    1.17 / numpy 2.5 + scipy 1.17 / numpy 2.5 + scipy 1.18.  The fit now runs to convergence: 31.32900 on all
    three (transient -6.6e-4 and filter -6.5e-4 of it; the old 3e-5 was the two cancelling by chance).
    """
    fs, f, amp, t = 10.0, 0.2, 1.0, 20000.0
    sos = weighting_sos("Wf", fs)
    h_f = abs(signal.sosfreqz(sos, worN=[f], fs=fs)[1][0])
    w_f = abs(frequency_weighting("Wf", f))
    half, whole = metrics(sine(f, amp, t / 2, fs), fs, "Wf"), metrics(sine(f, amp, t, fs), fs, "Wf")
    assert whole.msdv ** 2 - half.msdv ** 2 == pytest.approx(h_f ** 2 * amp ** 2 * t / 4.0, rel=1e-9)
    impulse = signal.sosfilt(sos, np.r_[1.0, np.zeros(int(200 * fs))])      # below 1e-22 by 200 s
    tail = np.cumsum(np.abs(impulse)[::-1])[::-1][1:]                       # sum(|h_j|, j > n)
    transient = (2.0 * h_f * np.sum(np.arange(impulse.size) * np.abs(impulse)) + np.sum(tail ** 2)) * amp ** 2 / fs
    closed = w_f * amp * np.sqrt(t / 2.0)
    assert whole.msdv == pytest.approx(closed, rel=abs(h_f / w_f - 1.0) + transient / (2.0 * closed ** 2))
    assert whole.msdv == pytest.approx(whole.a_w * np.sqrt(t), rel=1e-12)
    # Wf is used for MSDV whatever the main weighting
    m_wk = metrics(sine(f, amp, 300.0, 250.0), 250.0, "Wk")
    wf = weight("Wf", sine(f, amp, 300.0, 250.0), 250.0)
    assert m_wk.msdv == pytest.approx(np.sqrt(np.sum(wf ** 2) / 250.0), rel=1e-12)


def test_running_rms_and_mtvv_of_a_burst():
    fs, amp = 1000.0, 3.0
    x = np.zeros(10_000)
    x[4000:6000] = sine(5.0, amp, 2.0, fs)              # a 2 s burst in a 10 s record
    m = metrics(x, fs, weighting=None)
    assert m.mtvv == pytest.approx(amp / np.sqrt(2.0), rel=1e-9)
    assert m.a_w == pytest.approx(amp / np.sqrt(2.0) * np.sqrt(2.0 / 10.0), rel=1e-9)
    assert m.vdv == pytest.approx((3.0 / 8.0) ** 0.25 * amp * 2.0 ** 0.25, rel=1e-9)
    assert m.crest_factor == pytest.approx(np.sqrt(10.0 / 2.0) * np.sqrt(2.0), rel=1e-9)
    assert m.running_rms.shape == x.shape
    assert m.running_rms[3999] == 0.0 and m.running_rms[-1] == pytest.approx(0.0, abs=1e-6)
    assert m.mtvv_ratio == pytest.approx(m.mtvv / m.a_w)


def test_running_rms_is_the_rectangular_one_second_window():
    rng = np.random.default_rng(1)
    x = rng.standard_normal(3000)
    m = metrics(x, 1000.0, weighting=None)
    for i in (0, 10, 999, 1000, 2999):
        window = x[max(0, i - 999): i + 1]
        assert m.running_rms[i] == pytest.approx(np.sqrt(np.sum(window ** 2) / 1000.0), rel=1e-9)
    assert m.mtvv == pytest.approx(m.running_rms.max())
    short = metrics(x, 1000.0, weighting=None, tau_s=0.5)
    assert short.running_rms[2999] == pytest.approx(np.sqrt(np.mean(x[2500:] ** 2)), rel=1e-9)


def test_metrics_is_frozen_and_handles_silence():
    m = metrics(np.zeros(100), 1000.0, weighting=None)
    assert isinstance(m, ComfortMetrics)
    assert m.a_w == 0.0 and m.vdv == 0.0 and math.isnan(m.crest_factor)
    with pytest.raises(AttributeError):
        m.a_w = 1.0  # type: ignore[misc]


# --------------------------------------------------------------------------
# total value, reactions, SEAT
# --------------------------------------------------------------------------


def test_total_value_factors():
    ax = sine(3.0, 1.0, 20.0)
    ay = sine(1.0, 0.5, 20.0)
    az = sine(6.0, 2.0, 20.0)
    zero = np.zeros_like(ax)
    awx = metrics(ax, FS, "Wd").a_w
    awy = metrics(ay, FS, "Wd").a_w
    awz = metrics(az, FS, "Wk").a_w
    assert total_value(zero, zero, az, FS) == pytest.approx(awz, rel=1e-12)
    assert total_value(ax, zero, zero, FS, purpose="health") == pytest.approx(1.4 * awx, rel=1e-12)
    assert total_value(ax, ay, az, FS) == pytest.approx(np.sqrt(awx ** 2 + awy ** 2 + awz ** 2), rel=1e-12)
    assert total_value(ax, ay, az, FS, purpose="health") == pytest.approx(
        np.sqrt(1.4 ** 2 * (awx ** 2 + awy ** 2) + awz ** 2), rel=1e-12)
    assert total_value(ax, ay, az, FS, seated=False) == pytest.approx(total_value(ax, ay, az, FS))


@pytest.mark.parametrize(
    ("a_w", "expected"),
    [
        (0.0, "not uncomfortable"),
        (0.2, "not uncomfortable"),
        (0.315, "a little uncomfortable"),
        (0.55, "a little uncomfortable / fairly uncomfortable"),
        (0.7, "fairly uncomfortable"),
        (0.9, "fairly uncomfortable / uncomfortable"),
        (1.3, "uncomfortable / very uncomfortable"),
        (2.2, "very uncomfortable / extremely uncomfortable"),
        (3.0, "extremely uncomfortable"),
    ],
)
def test_comfort_reaction(a_w, expected):
    assert comfort_reaction(a_w) == expected


def test_seat_value():
    assert seat_value(0.5, 0.4) == pytest.approx(125.0)
    assert seat_value(0.0, 0.4) == 0.0


# --------------------------------------------------------------------------
# bad input
# --------------------------------------------------------------------------


def one_sentence(exc: pytest.ExceptionInfo, word: str) -> None:
    msg = str(exc.value)
    assert word in msg and msg.endswith(".") and "\n" not in msg


@pytest.mark.parametrize(
    ("call", "word"),
    [
        (lambda: frequency_weighting("Wx", 1.0), "name"),
        (lambda: frequency_weighting(3, 1.0), "name"),
        (lambda: frequency_weighting("Wk", -1.0), "freq_hz"),
        (lambda: frequency_weighting("Wk", np.nan), "freq_hz"),
        (lambda: weighting_sos("Wb", FS), "name"),
        (lambda: weighting_sos("Wk", 0.0), "fs_hz"),
        (lambda: weighting_sos("Wk", float("nan")), "fs_hz"),
        (lambda: weighting_sos("Wk", "fast"), "fs_hz"),
        (lambda: weighting_sos("Wk", 1.9), "fs_hz"),     # below 5 f1 = 2 Hz
        (lambda: weighting_sos("Wf", 0.3), "fs_hz"),     # below 5 f1 = 0.4 Hz
        (lambda: weight("Wk", np.ones((2, 5)), FS), "signal"),
        (lambda: weight("Wk", [], FS), "signal"),
        (lambda: weight("Wk", [0.0, np.inf], FS), "signal"),
        (lambda: WeightingFilter("W", FS), "name"),
        (lambda: WeightingFilter("Wk", FS).process(np.ones((2, 2))), "block"),
        (lambda: WeightingFilter("Wk", FS).step("a"), "x"),
        (lambda: metrics(np.ones(10), FS, "Wz"), "weighting"),
        (lambda: metrics(np.ones(10), -5.0, None), "fs_hz"),
        (lambda: metrics(np.ones(10), FS, None, tau_s=0.0), "tau_s"),
        (lambda: metrics(np.ones(10), 1.0, None, tau_s=0.1), "tau_s"),
        (lambda: total_value(np.ones(5), np.ones(5), np.ones(5), FS, purpose="fun"), "purpose"),
        (lambda: total_value(*[np.ones(5)] * 3, FS, purpose="health", seated=False), "seated"),
        (lambda: total_value(np.ones(5), np.ones(4), np.ones(5), FS), "ay"),
        (lambda: total_value(np.ones(5), np.ones(5), np.ones(5), FS, seated="yes"), "seated"),
        (lambda: comfort_reaction(-0.1), "a_w"),
        (lambda: comfort_reaction("loud"), "a_w"),
        (lambda: seat_value(1.0, 0.0), "a_w_seat"),
        (lambda: seat_value(-1.0, 1.0), "a_w_body"),
    ],
)
def test_bad_input_raises_input_error(call, word):
    with pytest.raises(InputError) as exc:
        call()
    one_sentence(exc, word)
