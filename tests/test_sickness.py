"""Checks of the subjective vertical conflict (SVC) sickness model against published behaviour.

Sources: Bos and Bles (1998) (conflict theory, Hill function, 720 s second-order lag, sickness peak
near 0.2 Hz reproducing O'Hanlon and McCauley's seasickness data); Bos and Bles (2002) (vertical from
otolith-canal interaction); Kamiji et al. (2007) and Wada et al. (2015) (6-DOF model, head tilt
toward the centre of a curve lowers the MSI).
"""

from __future__ import annotations

import numpy as np
import pytest

from ehm.errors import EhmWarning, InputError
from ehm.standards.sickness import (
    MiscParameters,
    SicknessAccumulator,
    SicknessResult,
    SvcParameters,
    fit_misc,
    hill_percent,
    misc_rating,
    read_sickness_params,
    sickness_params_text,
    subjective_vertical_conflict,
)

G = 9.81
DT = 0.05  # s; coarse but resolves 1 Hz with 20 samples a cycle


def _time(duration_s: float, dt: float = DT) -> np.ndarray:
    return np.arange(0.0, duration_s + dt / 2, dt)


def _translation(duration_s: float, freq_hz: float, axis: int, amp_mps2: float = 1.0):
    """Upright head, sinusoidal linear acceleration along one head axis, no rotation."""
    t = _time(duration_s)
    gia = np.zeros((t.size, 3))
    gia[:, 2] = G
    gia[:, axis] += amp_mps2 * np.sin(2 * np.pi * freq_hz * t)
    return t, gia, np.zeros_like(gia)


@pytest.fixture(scope="module")
def two_hours_vertical_0p2hz() -> SicknessResult:
    return subjective_vertical_conflict(*_translation(7200.0, 0.2, axis=2))


# --- rest ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("pitch_deg", [0.0, 30.0])
def test_head_at_rest_has_no_conflict_and_no_sickness(pitch_deg):
    # SVC theory: with the head still, the sensed and the subjective vertical coincide, so no
    # conflict and no sickness arise, whatever the (constant) head orientation.
    t = _time(600.0)
    th = np.deg2rad(pitch_deg)
    gia = np.tile([-G * np.sin(th), 0.0, G * np.cos(th)], (t.size, 1))
    res = subjective_vertical_conflict(t, gia, np.zeros_like(gia))
    assert res.conflict_mps2.shape == (t.size, 3)
    assert np.max(np.abs(res.conflict_mps2)) < 1e-9
    assert np.max(res.msi_percent) < 1e-9
    assert res.final_msi_percent == pytest.approx(0.0, abs=1e-9)
    np.testing.assert_allclose(res.subjective_vertical, gia, atol=1e-9)


def test_rotation_about_the_earth_vertical_gives_no_conflict():
    # Yaw rotation of an upright head about the gravity axis leaves the vertical unchanged in head
    # axes: the canals' response (and its decay) does not tilt either vertical, so SVC predicts
    # no sickness (Bos and Bles 2002).
    t = _time(600.0)
    gia = np.tile([0.0, 0.0, G], (t.size, 1))
    omega = np.zeros_like(gia)
    omega[:, 2] = np.clip(t / 5.0, 0.0, 1.0) * np.deg2rad(60.0)
    res = subjective_vertical_conflict(t, gia, omega)
    assert np.max(np.abs(res.conflict_mps2)) < 1e-9
    assert res.final_msi_percent == pytest.approx(0.0, abs=1e-9)


# --- frequency dependence -------------------------------------------------------------------------------


@pytest.mark.parametrize(("axis", "factor"), [(2, 10.0), (1, 3.0)], ids=["vertical", "lateral"])
def test_0p2_hz_is_more_sickening_than_1_hz_at_equal_acceleration(axis, factor):
    # Bos and Bles (1998) reproduce O'Hanlon and McCauley's finding that, at equal acceleration
    # amplitude, vertical sickness peaks near 0.2 Hz and falls off steeply towards 1 Hz.  The horizontal
    # axes (the UNIPG model's broader band) fall off too, less steeply.  30 min exposure.
    low = subjective_vertical_conflict(*_translation(1800.0, 0.2, axis)).final_msi_percent
    high = subjective_vertical_conflict(*_translation(1800.0, 1.0, axis)).final_msi_percent
    assert high > 0.0
    assert low > factor * high, (low, high)


def test_sickness_peaks_near_0p2_hz():
    # Same source: the frequency of maximum sickness lies near 0.2 Hz (O'Hanlon and McCauley's peak
    # is at 0.167-0.2 Hz).  Octave-spaced sweep, 1 m/s^2, 30 min each.
    freqs = [0.05, 0.1, 0.2, 0.4, 0.8]
    msi = [subjective_vertical_conflict(*_translation(1800.0, f, axis=2)).final_msi_percent for f in freqs]
    assert freqs[int(np.argmax(msi))] == 0.2, dict(zip(freqs, msi))


def _minutes_to(level_percent: float, result: SicknessResult) -> float:
    """Minutes until the MSI first reaches ``level_percent`` (inf if it never does)."""
    reached = np.flatnonzero(result.msi_percent >= level_percent)
    return float(result.time_s[reached[0]] / 60.0) if reached.size else np.inf


@pytest.mark.parametrize("axis", [0, 1], ids=["fore-aft", "lateral"])
def test_horizontal_frequency_dependence_as_golding_measured(axis):
    # Golding, Mueller and Gresty (2001), fore-aft at 1.0 m/s^2 peak: moderate nausea after a mean 18.0 / 11.2
    # / 20.2 min at 0.1 / 0.2 / 0.4 Hz, about 1.6-1.8 times as long at 0.1 and 0.4 Hz as at 0.2 Hz.  The
    # check of issue 37: the level 0.2 Hz reaches after 11 min is reached within 30 min at 0.1 and 0.4 Hz,
    # after 1.3-2.5 times as long, and 0.2 Hz stays the most provocative; Griffin and Mills (2002) found
    # lateral and fore-aft alike, so the same holds laterally.
    runs = {f: subjective_vertical_conflict(*_translation(1800.0, f, axis)) for f in (0.1, 0.2, 0.4)}
    level = float(np.interp(660.0, runs[0.2].time_s, runs[0.2].msi_percent))
    minutes = {f: _minutes_to(level, r) for f, r in runs.items()}
    assert minutes[0.2] == pytest.approx(11.0, abs=DT / 60)
    for f in (0.1, 0.4):
        assert 1.3 <= minutes[f] / minutes[0.2] <= 2.5, minutes
        assert runs[f].final_msi_percent < runs[0.2].final_msi_percent


def test_vertical_behaviour_is_the_isotropic_models():
    # The horizontal parameters act on x and y alone: vertical oscillation gives what the model gave when
    # every axis had the vertical's time constant and gain (the published, McCauley-based behaviour).
    isotropic = SvcParameters(horizontal_time_constant_s=SvcParameters().vertical_time_constant_s,
                              k_vc_horizontal_per_s=SvcParameters().k_vc_per_s)
    for f in (0.1, 0.2, 0.5):
        motion = _translation(1800.0, f, axis=2)
        np.testing.assert_allclose(subjective_vertical_conflict(*motion).msi_percent,
                                   subjective_vertical_conflict(*motion, params=isotropic).msi_percent,
                                   rtol=1e-12, atol=1e-12)


def test_horizontal_parameters_set_the_horizontal_band():
    # The conflict of a horizontal axis is the band-pass of the module docstring with that axis's time constant
    # and gain: its steady amplitude at 0.1 Hz matches the formula (hand computation) for the horizontal values.
    p = SvcParameters()
    f, amp = 0.1, 1.0
    w = 2 * np.pi * f
    c = 1.0 / (1.0 + p.k_ac)
    expected = (1 - p.k_a) * c * w / abs(p.k_vc_horizontal_per_s * c - p.horizontal_time_constant_s * w**2 + 1j * w)
    res = subjective_vertical_conflict(*_translation(600.0, f, axis=0, amp_mps2=amp))
    steady = res.conflict_mps2[res.time_s > 300.0, 0]
    assert np.max(np.abs(steady)) == pytest.approx(expected * amp, rel=0.01)


# --- time course ------------------------------------------------------------------------------------


def test_msi_grows_monotonically_and_stays_below_p(two_hours_vertical_0p2hz):
    # The MSI is a second-order lag of a non-negative Hill output: under constant excitation it
    # accumulates without decreasing and can never exceed the Hill maximum P = 85 %.
    res = two_hours_vertical_0p2hz
    assert np.all(np.diff(res.msi_percent) >= -1e-9)
    assert res.final_msi_percent > 1.0
    assert np.max(res.msi_percent) < SvcParameters().msi_max_percent


def test_msi_approaches_hill_function_of_steady_conflict(two_hours_vertical_0p2hz):
    # The lag 1 / (tau_I s + 1)^2 has unit DC gain, so after many tau_I (2 h = 10 tau_I) the MSI
    # equals the time mean of P * Hill(|conflict|) over the steady (periodic) conflict.
    res = two_hours_vertical_0p2hz
    last = res.time_s > res.time_s[-1] - 100.0  # 20 periods of 5 s
    asymptote = float(np.mean(hill_percent(res.conflict_magnitude_mps2[last])))
    assert res.final_msi_percent == pytest.approx(asymptote, rel=2e-3)


def test_msi_follows_the_second_order_lag_step_response(two_hours_vertical_0p2hz):
    # For a steady Hill output H the second-order lag gives MSI(t) = H (1 - (1 + t/tau_I) exp(-t/tau_I)):
    # 1 - 2/e = 26.4 % of the asymptote after one tau_I = 720 s (Bos and Bles 1998).
    res = two_hours_vertical_0p2hz
    asymptote = res.final_msi_percent
    for t_s in (720.0, 1440.0, 3600.0):
        x = t_s / 720.0
        expected = asymptote * (1.0 - (1.0 + x) * np.exp(-x))
        got = float(np.interp(t_s, res.time_s, res.msi_percent))
        assert got == pytest.approx(expected, rel=0.02), (t_s, got, expected)


# --- six degrees of freedom ---------------------------------------------------------------------------


def _slalom_with_head_roll(tilt_fraction: float):
    """0.2 Hz lateral (centripetal) acceleration of 2 m/s^2; the head rolls by tilt_fraction of the
    GIA angle toward the centre of the curve (1: aligned with the GIA, negative: outward)."""
    t = _time(1800.0)
    ay = 2.0 * np.sin(2 * np.pi * 0.2 * t)  # +y (left) is the centre of the curve when ay > 0
    phi = -tilt_fraction * np.arctan2(ay, G)  # roll about x; negative roll leans the head to +y
    c, s = np.cos(phi), np.sin(phi)
    gia = np.column_stack([np.zeros_like(t), c * ay + s * G, -s * ay + c * G])  # world GIA in head axes
    omega = np.zeros_like(gia)
    omega[:, 0] = np.gradient(phi, t)
    return t, gia, omega


def test_head_tilt_toward_the_curve_centre_lowers_msi():
    # Kamiji et al. (2007), Wada et al. (2015): passengers who tilt the head toward the centripetal
    # direction, as drivers do, get a lower predicted MSI than with the head upright, and tilting
    # outward raises it.
    outward, upright, inward = (subjective_vertical_conflict(*_slalom_with_head_roll(k)).final_msi_percent
                                for k in (-0.5, 0.0, 1.0))
    assert inward < upright < outward, (inward, upright, outward)


def test_slow_static_head_tilt_leaves_no_lasting_conflict():
    # A real tilt (GIA turning with the head, canals sensing the roll) is resolved by the
    # otolith-canal interaction: once the head is still, both verticals agree again.
    t = _time(300.0)
    phi = np.deg2rad(20.0) * np.clip((t - 5.0) / 10.0, 0.0, 1.0)
    gia = np.column_stack([np.zeros_like(t), G * np.sin(phi), G * np.cos(phi)])
    omega = np.zeros_like(gia)
    omega[:, 0] = np.gradient(phi, t)
    res = subjective_vertical_conflict(t, gia, omega)
    assert res.conflict_magnitude_mps2[-1] < 1e-3
    np.testing.assert_allclose(res.subjective_vertical[-1], gia[-1], atol=1e-3)
    assert res.final_msi_percent < 0.1


# --- streaming -----------------------------------------------------------------------------------------


def _tilting_drive(duration_s: float = 400.0):
    """Head pitching and rolling while the GIA sways: every state of the model moves (20 Hz)."""
    t = _time(duration_s)
    rng = np.random.default_rng(7)
    roll = 0.15 * np.sin(2 * np.pi * 0.13 * t) + 0.002 * np.cumsum(rng.normal(size=t.size)) * np.sqrt(DT)
    pitch = 0.1 * np.sin(2 * np.pi * 0.05 * t + 1.0)
    gia = np.column_stack([-G * np.sin(pitch) + 0.8 * np.sin(2 * np.pi * 0.21 * t),
                           G * np.sin(roll) + 1.5 * np.sin(2 * np.pi * 0.17 * t),
                           G * np.cos(roll) * np.cos(pitch) + 0.5 * rng.normal(size=t.size)])
    omega = np.column_stack([np.gradient(roll, t), np.gradient(pitch, t), 0.3 * np.sin(2 * np.pi * 0.02 * t)])
    return t, gia, omega


def test_pieces_give_the_whole_run():
    # The accumulator carries every filter and state across pieces, so uneven pieces (down to one sample,
    # across the step-map batches of 2048 samples) reproduce the whole-record run to round-off.
    t, gia, omega = _tilting_drive()
    whole = subjective_vertical_conflict(t, gia, omega)
    assert whole.final_msi_percent > 0.01 and np.max(np.abs(omega)) > 0.1  # the states really move
    acc = SicknessAccumulator(DT, start_s=t[0])
    cuts = [0, 1, 2, 5, 40, 41, 2047, 2049, 2050, 4100, 6001, t.size - 1, t.size]
    parts = [acc.add(gia[a:b], omega[a:b]) for a, b in zip(cuts[:-1], cuts[1:])]
    for name in ("time_s", "msi_percent", "conflict_mps2", "subjective_vertical", "sensed_vertical_mps2"):
        streamed = np.concatenate([getattr(r, name) for r in parts])
        reference = getattr(whole, name)
        scale = np.max(np.abs(reference))
        np.testing.assert_allclose(streamed, reference, rtol=0, atol=1e-10 * scale, err_msg=name)
    trace = acc.result()
    assert acc.n_samples == t.size
    np.testing.assert_allclose(trace.time_s, t, rtol=0, atol=1e-9)
    np.testing.assert_allclose(trace.msi_percent, whole.msi_percent, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(trace.conflict_magnitude_mps2, whole.conflict_magnitude_mps2, rtol=1e-10)
    assert trace.final_msi_percent == pytest.approx(whole.final_msi_percent, rel=1e-10)
    assert acc.last_msi_percent == pytest.approx(whole.final_msi_percent, rel=1e-10)
    assert acc.max_conflict_mps2 == pytest.approx(float(np.max(whole.conflict_magnitude_mps2)), rel=1e-10)


def test_a_refused_piece_leaves_the_accumulator_unchanged():
    t, gia, omega = _tilting_drive(60.0)
    whole = subjective_vertical_conflict(t, gia, omega)
    acc = SicknessAccumulator(DT)
    acc.add(gia[:500], omega[:500])
    fast = omega[500:600].copy()
    fast[:, 2] = 20.0  # 1 rad per sample
    with pytest.raises(InputError, match="dt_s"):
        acc.add(gia[500:600], fast)
    with pytest.raises(InputError, match="omega_radps"):
        acc.add(gia[500:600], omega[500:599])
    acc.add(gia[500:], omega[500:])
    np.testing.assert_allclose(acc.result().msi_percent, whole.msi_percent, rtol=1e-10, atol=1e-14)


def test_accumulator_bad_arguments():
    with pytest.raises(InputError, match="dt_s"):
        SicknessAccumulator(0.0)
    with pytest.raises(InputError, match="dt_s"):
        SicknessAccumulator(1.0)  # too coarse for the 0.77 s time scale
    with pytest.raises(InputError, match="no samples"):
        SicknessAccumulator(DT).result()
    with pytest.raises(InputError, match="gia_mps2"):
        SicknessAccumulator(DT).add(np.zeros((4, 2)), np.zeros((4, 3)))


# --- input checks ------------------------------------------------------------------------------------


def _good(n: int = 50):
    t = np.arange(n) * 0.05
    gia = np.tile([0.0, 0.0, G], (n, 1))
    return t, gia, np.zeros((n, 3))


def test_small_timing_jitter_is_accepted():
    t, gia, omega = _good()
    t = t + 0.002 * 0.05 * np.sin(np.arange(t.size))  # 0.4 % jitter
    assert subjective_vertical_conflict(t, gia, omega).msi_percent.shape == (t.size,)


def _bad_cases():
    t, gia, omega = _good()
    nan_gia = gia.copy()
    nan_gia[3, 1] = np.nan
    inf_omega = omega.copy()
    inf_omega[7, 2] = np.inf
    t_back = t.copy()
    t_back[10] = t_back[9]
    t_uneven = t.copy()
    t_uneven[20:] += 0.01
    t_nan = t.copy()
    t_nan[5] = np.nan
    return {
        "time 2-D": ((t[:, None], gia, omega), "time_s"),
        "time too short": ((t[:1], gia[:1], omega[:1]), "time_s"),
        "time not increasing": ((t_back, gia, omega), "time_s"),
        "time not uniform": ((t_uneven, gia, omega), "time_s"),
        "time NaN": ((t_nan, gia, omega), "time_s"),
        "gia wrong shape": ((t, gia[:, :2], omega), "gia_mps2"),
        "gia wrong length": ((t, gia[:-1], omega), "gia_mps2"),
        "gia NaN": ((t, nan_gia, omega), "gia_mps2"),
        "gia text": ((t, "up", omega), "gia_mps2"),
        "omega wrong shape": ((t, gia, omega.T), "omega_radps"),
        "omega inf": ((t, gia, inf_omega), "omega_radps"),
        "sampling too coarse": ((np.arange(50) * 1.0, gia, omega), "time_s"),
    }


@pytest.mark.parametrize("case", list(_bad_cases()))
def test_bad_inputs_raise_input_error_naming_the_argument(case):
    args, name = _bad_cases()[case]
    with pytest.raises(InputError, match=name):
        subjective_vertical_conflict(*args)


def test_fast_rotation_for_the_sample_interval_is_refused():
    t, gia, omega = _good()
    omega[:, 0] = 20.0  # 1 rad per 0.05 s sample
    with pytest.raises(InputError, match="time_s"):
        subjective_vertical_conflict(t, gia, omega)


def test_bad_parameters_raise_input_error():
    t, gia, omega = _good()
    with pytest.raises(InputError, match="params"):
        subjective_vertical_conflict(t, gia, omega, params={"k_a": 0.1})
    with pytest.raises(InputError, match="hill_b_mps2"):
        SvcParameters(hill_b_mps2=0.0)
    with pytest.raises(InputError, match="k_vc_per_s"):
        SvcParameters(k_vc_per_s=-1.0)
    with pytest.raises(InputError, match="msi_max_percent"):
        SvcParameters(msi_max_percent=120.0)
    with pytest.raises(InputError, match="tau|time_constant"):
        SvcParameters(msi_time_constant_s=float("nan"))


# --- MISC: the accumulation model ----------------------------------------------------------------------


def test_misc_of_a_constant_conflict_follows_the_two_lags_by_hand():
    # The accumulation model by hand: a conflict that steps to c at t = 0 gives y(t) = sum K c (1 - e^(-t/T)(1 + t/T))
    # (the step response of 1/(T s + 1)^2) and MISC = min(y^p, 10).
    p = MiscParameters(fast_gain=2.0, fast_time_constant_s=50.0, slow_gain=1.0, slow_time_constant_s=400.0,
                       exponent=0.5)
    dt, c = 0.5, 3.0
    t = np.arange(0.0, 8000.0, dt)
    misc = misc_rating(np.full(t.size, c), dt, p)

    # the discretisation takes the step as a ramp over the sample before t = 0: half a sample earlier
    te = t + dt / 2

    def step(tau):
        return 1 - np.exp(-te / tau) * (1 + te / tau)

    y = 2.0 * c * step(50.0) + 1.0 * c * step(400.0)
    late = t > 10.0
    np.testing.assert_allclose(misc[late], np.minimum(y**0.5, 10.0)[late], rtol=5e-4)
    assert misc[-1] == pytest.approx(np.sqrt(9.0), rel=1e-3)  # steady: (K1 + K2) c = 9


def test_misc_is_capped_at_10_and_grows_with_the_gain():
    t = _time(1200.0)
    res = subjective_vertical_conflict(*_translation(1200.0, 0.2, axis=0))
    c = res.conflict_magnitude_mps2
    low, high = (misc_rating(c, DT, MiscParameters(fast_gain=k, slow_gain=k)) for k in (50.0, 5e5))
    assert np.all(low <= high) and np.all(np.diff(low)[t[1:] > 10.0] > -1e-6)  # grows under steady motion
    assert high.max() == 10.0 and low.max() < 10.0
    np.testing.assert_allclose(res.misc, misc_rating(c, DT))  # the run carries the group's MISC


def test_misc_in_pieces_equals_the_whole_run():
    t, gia, w = _translation(600.0, 0.3, axis=1)
    whole = subjective_vertical_conflict(t, gia, w)
    acc = SicknessAccumulator(DT)
    for i in range(0, t.size, 777):
        acc.add(gia[i:i + 777], w[i:i + 777])
    np.testing.assert_allclose(acc.result().misc, whole.misc, rtol=1e-10, atol=1e-10)
    assert acc.last_misc == pytest.approx(whole.final_misc)


def test_misc_parameters_are_checked():
    with pytest.raises(InputError, match="MiscParameters.fast_time_constant_s must be positive"):
        MiscParameters(fast_time_constant_s=0.0)
    with pytest.raises(InputError, match="MiscParameters.slow_gain must not be negative"):
        MiscParameters(slow_gain=-1.0)
    with pytest.raises(InputError, match="misc_params must be a MiscParameters"):
        SicknessAccumulator(DT, misc_params={"fast_gain": 1.0})


# --- a person's K1 and T1 ---------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def foreaft_half_hour() -> SicknessResult:
    return subjective_vertical_conflict(*_translation(1800.0, 0.2, axis=0))


@pytest.mark.parametrize(("k1", "t1"), [(120.0, 150.0), (600.0, 40.0)])
def test_fit_recovers_synthetic_k1_and_t1_within_their_stated_uncertainty(foreaft_half_hour, k1, t1):
    # SYNTHETIC ratings: the model's MISC of a known person once a minute, with rating noise (0.3 MISC), rounded to
    # whole numbers as people rate, 30 sets; the fit gives K1 and T1 back within 2 stated standard errors in at
    # least 80 % of them (measured: 87-97 %), with standard errors well below the values.  The conflict at 0.5 s
    # (block means) keeps the 60 fits short.
    r = foreaft_half_hour
    k = 10
    n = r.time_s.size // k
    t, c = r.time_s[::k][:n], r.conflict_magnitude_mps2[: n * k].reshape(-1, k).mean(1)
    true = MiscParameters(fast_gain=k1, fast_time_constant_s=t1)
    times = np.arange(60.0, 1740.0, 60.0)
    exact = np.interp(times, t, misc_rating(c, k * DT, true))
    inside, last = [], None
    for seed in range(30):
        noise = 0.3 * np.random.default_rng(seed).standard_normal(times.size)
        last = fit_misc(t, c, times, np.clip(np.round(exact + noise), 0, 10))
        inside.append([lo <= value <= hi for lo, hi, value in ((*last.interval("fast_gain"), k1),
                                                               (*last.interval("fast_time_constant_s"), t1))])
        assert last.std["fast_gain"] < 0.5 * k1 and last.std["fast_time_constant_s"] < 0.5 * t1
    assert np.mean(inside, axis=0).min() >= 0.8, np.mean(inside, axis=0)
    assert last.rms_misc < last.rms_misc_group
    assert last.params.slow_gain == MiscParameters().slow_gain  # the rest the group's


def test_fit_refuses_ratings_it_cannot_use(foreaft_half_hour):
    r = foreaft_half_hour
    t, c = r.time_s, r.conflict_magnitude_mps2
    with pytest.raises(InputError, match="rating 1 at 2000 s lies outside the drive's 0-1800 s"):
        fit_misc(t, c, [60.0, 2000.0, 2100.0], [1.0, 2.0, 3.0])
    with pytest.raises(InputError, match="rating 2 is MISC 11, outside the scale's 0-10"):
        fit_misc(t, c, [60.0, 120.0, 180.0], [1.0, 2.0, 11.0])
    with pytest.raises(InputError, match="2 rating.*at least 3"):
        fit_misc(t, c, [60.0, 120.0], [1.0, 2.0])


def test_a_fit_the_ratings_do_not_determine_says_so(foreaft_half_hour):
    # SYNTHETIC ratings that climb straight for half an hour: a fast path slower than the drive fits them best.
    r = foreaft_half_hour
    times = np.arange(60.0, 1800.0, 60.0)
    with pytest.warns(EhmWarning, match="do not determine fast_gain and fast_time_constant_s.*not the person's"):
        fit_misc(r.time_s, r.conflict_magnitude_mps2, times, times / 200.0)


def test_sickness_params_file_round_trip(foreaft_half_hour, tmp_path):
    r = foreaft_half_hour
    times = np.arange(60.0, 1800.0, 60.0)
    rated = np.interp(times, r.time_s, misc_rating(r.conflict_magnitude_mps2, DT, MiscParameters(fast_gain=120.0)))
    fit = fit_misc(r.time_s, r.conflict_magnitude_mps2, times, rated)
    path = tmp_path / "p.toml"
    path.write_text(sickness_params_text(fit, {"drive": "SYNTHETIC"}), encoding="utf-8")
    assert read_sickness_params(path) == fit.params
    path.write_text("[misc]\nfast_gain = 10.0\nspeed = 3\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"p.toml: \[misc\] has no parameter 'speed'"):
        read_sickness_params(path)
    path.write_text("[misc]\nfast_gain = -10.0\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"p.toml: MiscParameters.fast_gain must not be negative, got -10.0; correct"):
        read_sickness_params(path)
    path.write_text("[other]\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"p.toml: no \[misc\] table"):
        read_sickness_params(path)
    with pytest.raises(InputError, match="no such sickness parameter file"):
        read_sickness_params(tmp_path / "none.toml")
