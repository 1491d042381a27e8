"""Spinal dose of vertical vibration with shocks after ISO 2631-5:2018 (clause 5 and Annex C).

The standard's route, from the seat's vertical acceleration ``a_z`` (m/s^2, gravity not included):

1. the lumbar spine's acceleration response ``A_z``: ``a_z`` (its mean removed: the standard takes a conditioned,
   zero-mean input, and its transfer function passes 0 Hz whole) through Formula 1
   (:func:`ehm.standards.references.iso2631_5_lumbar_tf`), realised as a causal digital filter at the record's own rate;
2. the peaks ``A_i``: the largest value of ``A_z`` between two zero crossings, positive peaks only (compression);
3. the acceleration dose ``D_z = 1.07 (sum A_i^6)^(1/6)`` (Formula 3) and the daily dose
   ``D_zd = D_z (t_d / t_m)^(1/6)`` for a daily exposure ``t_d`` of which the record covers ``t_m`` (Formula 4);
4. Annex C: the daily compressive stress ``S_d = m_z D_zd`` [MPa] (``m_z`` 0.029 MPa per m/s^2 for the standard's
   82 kg man, 0.025 for its 64 kg woman; the 2004 edition's ``S_ed``), the factor
   ``R = [sum_i (S_d N^(1/6) / (S_u,i - S_stat))^6]^(1/6)`` over the years of exposure ``i = 1..n`` with
   ``N`` days a year, the ultimate strength ``S_u,i = 6.75 - S_age (b + i - 1)`` [MPa] at the age reached
   (``b``: the age the exposure started; ``S_age`` 0.052 MPa a year for men, 0.039 for women) and the static
   stress ``S_stat = m_z 9.81 m/s^2``; and the probability of a lumbar injury ``P = 1 - exp(-(R / alpha)^beta)``
   (Weibull, Table C.1).  Table C.2's R for 10, 50 and 90 % risk are ``RISK_R_10_50_90``.

The body model's route enters at step 2: :func:`spinal_dose_from_lumbar` takes an acceleration that is
already the lumbar spine's (a model's lumbar point) and runs steps 2-4 alike.

Why this filter: Formula 1 has ten more poles than zeros.  The bilinear transform puts those ten zeros on the
Nyquist frequency (``|H|`` off by 0.39 up to 40 Hz at 100 Hz, 0.07 at 256 Hz, 0.017 at 500 Hz) and the matched-z
transform loses the phase (120 degrees at 20 Hz at 256 Hz) that sets where the response's peaks fall.  The
impulse-invariant realisation (the analog impulse response sampled; six parallel second-order sections from the
poles and their residues, scaled to 1 at 0 Hz) keeps both: at 128 Hz it follows Formula 1 up to 40 Hz within
0.001 in modulus (clause 5.2 allows 0.04) and 0.4 degrees (0.015 up to 20 Hz), from 200 Hz up within 1e-5 and
0.001 degrees.  A record
sampled below 128 Hz is first upsampled by a whole factor (``scipy.signal.resample_poly``) to at least that
rate.  Against the standard's own 256 Hz filter (Annex D) and the frequency-domain Formula 2 (phonometry's
route) the doses agree within 0.1 % (tests/test_spine.py).  Known limit: the peaks are the largest samples, so
at 128 Hz a 10 Hz peak may read up to 3 % low (0.2 % at 500 Hz).

Pure array functions: no engine, no files, nothing computed at import time.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy import signal as _sig

from ...errors import EhmWarning, InputError, warn
from ..references import ISO2631_5_POLES, ISO2631_5_ZERO
from .checks import positive_float, signal_1d

__all__ = [
    "SpineExposure", "SpinalDose", "LumbarResponse", "SpinalDoseAccumulator", "lumbar_sections",
    "lumbar_response", "spinal_dose", "spinal_dose_from_lumbar", "dose_from_peaks", "daily_dose",
    "compressive_stress", "r_factor", "injury_probability", "route_difference", "response_peaks", "iso2631_5_summary",
    "DOSE_FACTOR", "DOSE_EXPONENT", "M_Z_MPA_PER_MPS2", "RISK_R_10_50_90", "FILTER_MIN_RATE_HZ",
    "ROUTE_DIFFERENCE",
]

#: Formula 3: the spine's amplitude factor and the fatigue exponent of the dose.
DOSE_FACTOR = 1.07
DOSE_EXPONENT = 6.0
#: Formula C.2: compressive stress per lumbar acceleration [MPa per m/s^2], the standard's 82 kg man and 64 kg woman.
M_Z_MPA_PER_MPS2 = {"male": 0.029, "female": 0.025}
#: Formula C.4: the ultimate strength's value at age 0 [MPa] and its loss per year of age [MPa/year].
ULTIMATE_STRENGTH_MPA = 6.75
STRENGTH_LOSS_MPA_PER_YEAR = {"male": 0.052, "female": 0.039}
#: The acceleration of gravity of the static stress [m/s^2].
GRAVITY_MPS2 = 9.81
#: Table C.1: Weibull (alpha, beta) of the probability of a lumbar injury.
WEIBULL = {"male": (1.613, 2.799), "female": (0.959, 3.709)}
#: Table C.2: R for a 10, 50 and 90 % probability of an adverse health effect.
RISK_R_10_50_90 = {"male": (0.72, 1.42, 2.17), "female": (0.52, 0.87, 1.20)}
#: The lumbar filter runs at this rate or above (a slower record is upsampled by a whole factor first).
FILTER_MIN_RATE_HZ = 128.0
#: The two routes' daily compressive stresses differing by more than this share get a sentence.
ROUTE_DIFFERENCE = 0.10
#: Below this Nyquist frequency [Hz] a record misses part of the band where clause 5.2 holds Formula 1 to 0.04.
_TIGHT_BAND_HZ = 40.0
_SEXES = ("male", "female")


# --------------------------------------------------------------------------------------------------------------
# The exposure
# --------------------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class SpineExposure:
    """Who is exposed to the record's vibration, and how long: what the daily dose and R need.

    The defaults: 8 h a day (a working day, the reference day of ISO 2631-1's and Directive 2002/44/EC's
    A(8)), and the person of the standard's Annex C example: a man (82 kg) exposed from the age of 20 for
    20 years, 120 days a year.

    Attributes
    ----------
    daily_exposure_h : float
        Hours a day of vibration like the record's (``t_d``): more than 0, at most 24.
    start_age_years : float
        The age the exposure started (``b``): 14 to 80.
    exposure_years : int
        Years of exposure (``n``): 1 to 70, and at most to the age of 100.
    days_per_year : float
        Days of exposure a year (``N``): more than 0, at most 366.
    sex : str
        ``male`` or ``female``: the standard's stress factor ``m_z``, strength loss with age and injury model.
    """

    daily_exposure_h: float = 8.0
    start_age_years: float = 20.0
    exposure_years: int = 20
    days_per_year: float = 120.0
    sex: str = "male"

    def __post_init__(self):
        h = _number(self.daily_exposure_h, "the daily exposure (daily_exposure_h, --daily-exposure-h)", "h")
        if not 0.0 < h <= 24.0:
            raise InputError(f"the daily exposure (daily_exposure_h, --daily-exposure-h) is {h:g} h; give the hours "
                             "a day the person sits in vibration like this drive's, more than 0 and at most 24.")
        b = _number(self.start_age_years, "the age the exposure started (start_age_years, --exposure-start-age-years)",
                    "years")
        if not 14.0 <= b <= 80.0:
            raise InputError(f"the age the exposure started (start_age_years, --exposure-start-age-years) is {b:g} "
                             "years; ISO 2631-5's strength model is for working adults: give 14 to 80.")
        n = self.exposure_years
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= 70:
            raise InputError(f"the years of exposure (exposure_years, --exposure-years) are {n!r}; give a whole "
                             "number of years from 1 to 70.")
        if b + n - 1 > 100:
            raise InputError(f"an exposure from the age of {b:g} for {n} years reaches the age of {b + n - 1:g}; "
                             "ISO 2631-5's strength model is not meant beyond 100: give fewer years "
                             "(--exposure-years) or a younger start (--exposure-start-age-years).")
        d = _number(self.days_per_year, "the days of exposure a year (days_per_year, --exposure-days-per-year)", "days")
        if not 0.0 < d <= 366.0:
            raise InputError(f"the days of exposure a year (days_per_year, --exposure-days-per-year) are {d:g}; "
                             "give more than 0 and at most 366.")
        if self.sex not in _SEXES:
            raise InputError(f"sex (--sex) is {self.sex!r}; ISO 2631-5 has the factors of a man (82 kg) and a "
                             "woman (64 kg): give male or female.")

    @property
    def m_z(self) -> float:
        """The stress factor ``m_z`` [MPa per m/s^2] (Formula C.2)."""
        return M_Z_MPA_PER_MPS2[self.sex]

    def as_dict(self) -> dict:
        return {"daily_exposure_h": float(self.daily_exposure_h), "start_age_years": float(self.start_age_years),
                "exposure_years": int(self.exposure_years), "days_per_year": float(self.days_per_year),
                "sex": self.sex, "m_z_mpa_per_mps2": self.m_z}


def _exposure(exposure) -> SpineExposure:
    """``exposure``, or the default one for None; anything else is refused in a sentence."""
    if exposure is None:
        return SpineExposure()
    if not isinstance(exposure, SpineExposure):
        raise InputError(f"exposure must be an ehm.standards.comfort.SpineExposure (daily hours, age, years, days a "
                         f"year, sex), not {type(exposure).__name__}.")
    return exposure


def _number(value, what: str, unit: str) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be a number of {unit}; got {value!r}.") from None
    if not math.isfinite(out):
        raise InputError(f"{what} must be a finite number of {unit}; got {value!r}.")
    return out


# --------------------------------------------------------------------------------------------------------------
# Formula 1 as a digital filter
# --------------------------------------------------------------------------------------------------------------

def _analog_poles_and_residues() -> tuple[np.ndarray, np.ndarray]:
    """Formula 1's poles in the upper half plane [rad/s] and their residues (partial fractions of H(s))."""
    w1, z1 = ISO2631_5_ZERO
    poles = np.array([complex(-z * w, w * math.sqrt(1.0 - z * z)) for w, z in ISO2631_5_POLES])  # all zeta < 1
    every = np.concatenate([poles, poles.conj()])
    gain = np.prod([w * w for w, _ in ISO2631_5_POLES]) / (w1 * w1)  # H(s) = gain N(s) / prod (s - p), N monic
    residues = np.array([gain * (p * p + 2.0 * z1 * w1 * p + w1 * w1) / np.prod(p - every[every != p])
                         for p in poles])
    return poles, residues


@functools.lru_cache(maxsize=32)
def _sections(fs: float) -> tuple[np.ndarray, np.ndarray]:
    poles, residues = _analog_poles_and_residues()
    t = 1.0 / fs
    e = np.exp(poles * t)  # each pair p, p* and residues r, r*: T r / (1 - e z^-1) + T r* / (1 - e* z^-1)
    b = np.column_stack([2.0 * t * residues.real, -2.0 * t * (residues * e.conj()).real])
    a = np.column_stack([np.ones_like(e.real), -2.0 * e.real, np.abs(e) ** 2])
    b /= np.sum(b.sum(axis=1) / a.sum(axis=1))  # exactly 1 at 0 Hz, as Formula 1 (off by 1.3e-4 at 128 Hz)
    b.flags.writeable = a.flags.writeable = False
    return b, a


def lumbar_sections(fs_hz: float) -> tuple[np.ndarray, np.ndarray]:
    """The parallel second-order sections of Formula 1 at ``fs_hz``: the lumbar response is the sum of the six.

    Impulse-invariant (see the module docstring): section k is ``b[k] / a[k]`` in powers of ``z^-1``.

    Parameters
    ----------
    fs_hz : float
        Sampling rate [Hz], at least ``FILTER_MIN_RATE_HZ``.

    Returns
    -------
    b : (6, 2) ndarray
    a : (6, 3) ndarray
    """
    fs = _filter_rate(fs_hz)
    b, a = _sections(fs)
    return b.copy(), a.copy()


def _filter_rate(fs_hz) -> float:
    fs = positive_float(fs_hz, "fs_hz")
    if fs < FILTER_MIN_RATE_HZ:
        raise InputError(f"the lumbar filter runs at {FILTER_MIN_RATE_HZ:g} Hz or faster, not {fs:g} Hz (the "
                         "analog poles reach 67 Hz); upsample the record, or use lumbar_response / spinal_dose, "
                         "which do.")
    return fs


# --------------------------------------------------------------------------------------------------------------
# Peaks and dose
# --------------------------------------------------------------------------------------------------------------

def response_peaks(response) -> np.ndarray:
    """The positive peaks of a lumbar response: the largest value between two zero crossings (clause 5.3).

    Parameters
    ----------
    response : (n,) array_like
        Lumbar acceleration response [m/s^2].

    Returns
    -------
    ndarray
        The peaks [m/s^2] in the order they occur (a run still positive at the end counts).
    """
    acc = SpinalDoseAccumulator(FILTER_MIN_RATE_HZ, lumbar=True)  # the rate only times the largest peak
    acc.add(signal_1d(response, "response"))
    return acc.peaks()


def dose_from_peaks(peaks) -> float:
    """The acceleration dose ``D_z = 1.07 (sum A_i^6)^(1/6)`` [m/s^2] of the peaks ``A_i`` (Formula 3)."""
    p = np.asarray(peaks, dtype=float).ravel()
    return float(DOSE_FACTOR * np.sum(p ** DOSE_EXPONENT) ** (1.0 / DOSE_EXPONENT)) if p.size else 0.0


def daily_dose(dose_mps2: float, measured_s: float, daily_exposure_h: float) -> float:
    """The daily dose ``D_zd = D_z (t_d / t_m)^(1/6)`` [m/s^2] (Formula 4).

    Parameters
    ----------
    dose_mps2 : float
        ``D_z`` of the record [m/s^2].
    measured_s : float
        ``t_m``: the time the record covers [s].
    daily_exposure_h : float
        ``t_d``: the daily exposure [h].
    """
    t_m = positive_float(measured_s, "measured_s")
    t_d = 3600.0 * positive_float(daily_exposure_h, "daily_exposure_h")
    return float(dose_mps2 * (t_d / t_m) ** (1.0 / DOSE_EXPONENT))


def compressive_stress(daily_dose_mps2: float, sex: str = "male") -> float:
    """The daily compressive stress ``S_d = m_z D_zd`` [MPa] (Formula C.1)."""
    return M_Z_MPA_PER_MPS2[SpineExposure(sex=sex).sex] * float(daily_dose_mps2)


def r_factor(compressive_stress_mpa: float, exposure: SpineExposure | None = None) -> float:
    """The factor ``R`` of the daily compressive stress ``S_d`` [MPa] over the years of exposure (Formula C.3).

    ``R = [sum_{i=1..n} (S_d N^(1/6) / (S_u,i - S_stat))^6]^(1/6)`` with ``S_u,i = 6.75 - S_age (b + i - 1)``:
    the first year at the age ``b`` the exposure started (this gives the Annex C example's R = 1.22).
    """
    e = _exposure(exposure)
    ages = e.start_age_years + np.arange(e.exposure_years, dtype=float)
    margin = ULTIMATE_STRENGTH_MPA - STRENGTH_LOSS_MPA_PER_YEAR[e.sex] * ages - e.m_z * GRAVITY_MPS2
    per_year = float(compressive_stress_mpa) * e.days_per_year ** (1.0 / DOSE_EXPONENT) / margin
    return float(np.sum(per_year ** DOSE_EXPONENT) ** (1.0 / DOSE_EXPONENT))


def injury_probability(r: float, sex: str = "male") -> float:
    """The probability (0 to 1) of a lumbar injury for a factor ``R``: ``1 - exp(-(R / alpha)^beta)`` (Formula C.5)."""
    alpha, beta = WEIBULL[SpineExposure(sex=sex).sex]
    return float(1.0 - math.exp(-((max(float(r), 0.0) / alpha) ** beta)))


# --------------------------------------------------------------------------------------------------------------
# Records
# --------------------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class SpinalDose:
    """The ISO 2631-5 figures of one record.

    Attributes
    ----------
    route : str
        How the lumbar response was had (the standard's transfer function from the seat, or a model's lumbar point).
    peaks_mps2 : ndarray
        The positive lumbar response peaks, in order [m/s^2].
    largest_peak_mps2, largest_peak_time_s : float
        The largest of them and when it occurred [s from the record's start].
    measured_s : float
        ``t_m``, the time the record covers [s].
    dose_mps2 : float
        ``D_z`` [m/s^2].
    daily_dose_mps2 : float
        ``D_zd`` for the exposure [m/s^2].
    compressive_stress_mpa : float
        ``S_d`` [MPa].
    r_factor : float
        ``R``.
    injury_probability : float
        ``P`` (0 to 1).
    exposure : SpineExposure
    """

    route: str
    peaks_mps2: np.ndarray
    largest_peak_mps2: float
    largest_peak_time_s: float
    measured_s: float
    dose_mps2: float
    daily_dose_mps2: float
    compressive_stress_mpa: float
    r_factor: float
    injury_probability: float
    exposure: SpineExposure

    def as_dict(self, largest: int = 5) -> dict:
        """The figures for ``assessment.json`` (the ``largest`` peaks, not all of them)."""
        top = np.sort(self.peaks_mps2)[::-1][:largest]
        return {"route": self.route, "lumbar_peak_count": int(self.peaks_mps2.size),
                "lumbar_peak_max_mps2": self.largest_peak_mps2, "lumbar_peak_max_time_s": self.largest_peak_time_s,
                "lumbar_peaks_largest_mps2": top.tolist(), "measured_s": self.measured_s,
                "dose_dz_mps2": self.dose_mps2, "daily_dose_dzd_mps2": self.daily_dose_mps2,
                "daily_compressive_stress_sd_mpa": self.compressive_stress_mpa, "r_factor": self.r_factor,
                "injury_probability": self.injury_probability,
                "r_for_risk_10_50_90_pct": list(RISK_R_10_50_90[self.exposure.sex])}


class SpinalDoseAccumulator:
    """The lumbar response's peaks of a record fed block by block, in the memory of its peaks.

    Feeding a record in pieces gives the same peaks as feeding it at once.  A seat record (``lumbar=False``)
    goes through Formula 1 (:func:`lumbar_sections`, started at rest: unlike the ISO 2631-1 weightings, not in
    the steady state for the record's start level, which would take a shock at the very start for a level held
    for ever); a lumbar one (``lumbar=True``: a model's lumbar point) is taken as it is.  Neither has its mean
    removed here: the standard's input is conditioned (zero-mean) before it comes in.

    Parameters
    ----------
    fs_hz : float
        Sampling rate [Hz]; at least ``FILTER_MIN_RATE_HZ`` for a seat record.
    lumbar : bool
        Whether the blocks are already the lumbar spine's acceleration (default False: the seat's).
    """

    def __init__(self, fs_hz: float, lumbar: bool = False):
        self.fs_hz = positive_float(fs_hz, "fs_hz") if lumbar else _filter_rate(fs_hz)
        self.lumbar = bool(lumbar)
        self._b, self._a = (None, None) if lumbar else _sections(self.fs_hz)
        self._zi = None
        self._n = 0
        self._peaks: list[np.ndarray] = []
        self._open: float | None = None  # the largest value of a positive run still going at the last block's end
        self._max = (-np.inf, 0)  # largest sample and its index

    def add(self, block) -> np.ndarray:
        """Feed the next block; returns its lumbar response [m/s^2] (the block itself when ``lumbar``)."""
        x = np.asarray(block, dtype=float)
        if x.size == 0:  # nothing to add (a block of a split may be empty)
            return np.zeros(0)
        x = signal_1d(x, "block")
        y = x if self.lumbar else self._filter(x)
        self._collect(y)
        self._n += y.size
        return y

    def _filter(self, x: np.ndarray) -> np.ndarray:
        if x.size == 0:
            return x
        if self._zi is None:  # at rest: the input is conditioned (zero-mean), and a shock at its start stays one
            self._zi = [np.zeros(2) for _ in self._b]
        y = np.zeros_like(x)
        for k, (b, a) in enumerate(zip(self._b, self._a)):
            part, self._zi[k] = _sig.lfilter(b, a, x, zi=self._zi[k])
            y += part
        return y

    def _collect(self, y: np.ndarray) -> None:
        """The peaks of the positive runs that end in ``y``; a run still going at its end is carried on."""
        if y.size == 0:
            return
        i = int(np.argmax(y))
        if y[i] > self._max[0]:
            self._max = (float(y[i]), self._n + i)
        carried = self._open is not None
        edges = np.diff(np.concatenate(([carried], y > 0.0, [False])).astype(np.int8))
        starts = np.flatnonzero(edges == 1)
        if carried:
            starts = np.concatenate(([0], starts))
        if starts.size == 0:
            return
        # from one run's start to the next run's start, the largest value is the run's own (the rest is <= 0)
        maxima = np.maximum.reduceat(y, starts)
        if carried:
            maxima[0] = max(maxima[0], self._open)
        self._open = float(maxima[-1]) if y[-1] > 0.0 else None
        done = maxima[:-1] if self._open is not None else maxima
        if done.size:
            self._peaks.append(done)

    def peaks(self) -> np.ndarray:
        """The peaks so far [m/s^2], a run still positive at the end included."""
        parts = self._peaks + ([np.array([self._open])] if self._open is not None else [])
        return np.concatenate(parts) if parts else np.zeros(0)

    def result(self, exposure: SpineExposure | None = None, measured_s: float | None = None,
               route: str = "") -> SpinalDose:
        """The figures of the record fed so far.

        Parameters
        ----------
        exposure : SpineExposure, optional
            Default: ``SpineExposure()``.
        measured_s : float, optional
            ``t_m`` [s]; default: the samples fed times the step.
        route : str
            How the lumbar response was had, for the record.
        """
        e = _exposure(exposure)
        t_m = self._n / self.fs_hz if measured_s is None else positive_float(measured_s, "measured_s")
        if self._n == 0:
            raise InputError("the ISO 2631-5 dose needs a record; no sample was fed.")
        peaks = self.peaks()
        dz = dose_from_peaks(peaks)
        dzd = daily_dose(dz, t_m, e.daily_exposure_h)
        sd = e.m_z * dzd
        r = r_factor(sd, e)
        largest = max(self._max[0], 0.0)
        return SpinalDose(route=route, peaks_mps2=peaks, largest_peak_mps2=largest,
                          largest_peak_time_s=self._max[1] / self.fs_hz, measured_s=t_m, dose_mps2=dz,
                          daily_dose_mps2=dzd, compressive_stress_mpa=sd, r_factor=r,
                          injury_probability=injury_probability(r, e.sex), exposure=e)


class LumbarResponse(NamedTuple):
    """A lumbar acceleration response and its sampling rate (the record's, or the rate it was upsampled to)."""

    acc_mps2: np.ndarray
    fs_hz: float


def lumbar_response(seat_az_mps2, fs_hz: float, remove_mean: bool = True) -> LumbarResponse:
    """The lumbar spine's acceleration response to a vertical seat acceleration (Formula 1, causal).

    Parameters
    ----------
    seat_az_mps2 : (n,) array_like
        The seat's vertical acceleration [m/s^2], gravity not included, uniformly sampled.
    fs_hz : float
        Its sampling rate [Hz].  Below ``FILTER_MIN_RATE_HZ`` the record is upsampled by the smallest whole
        factor that reaches it; a record whose Nyquist frequency lies below 40 Hz gets a warning (it misses part
        of the band the standard's transfer function is held to).
    remove_mean : bool
        Subtract the record's mean first (default; the standard's input is conditioned, zero-mean).

    Returns
    -------
    LumbarResponse
        ``acc_mps2`` [m/s^2] and ``fs_hz``: the record's rate, or the rate it was upsampled to.
    """
    x = signal_1d(seat_az_mps2, "seat_az_mps2")
    fs = positive_float(fs_hz, "fs_hz")
    if x.size == 0:
        raise InputError("seat_az_mps2 is empty; the lumbar response needs a record.")
    if fs / 2.0 < _TIGHT_BAND_HZ:
        warn(f"a record sampled at {fs:g} Hz holds nothing above {fs / 2:g} Hz; ISO 2631-5's transfer "
             f"function reaches to 80 Hz (0.33 at 40 Hz), so the lumbar response misses what the seat did "
             f"above {fs / 2:g} Hz and the dose (D, S_d, R) may be low by that part; a log at 160 Hz or "
             "faster holds it.", EhmWarning, stacklevel=2)
    if remove_mean:
        x = x - np.mean(x)
    factor = math.ceil(FILTER_MIN_RATE_HZ / fs - 1e-9)
    if factor > 1:
        x = _sig.resample_poly(x, factor, 1, padtype="line")
        fs *= factor
    acc = SpinalDoseAccumulator(fs)
    return LumbarResponse(acc.add(x), fs)


def spinal_dose(seat_az_mps2, fs_hz: float, exposure: SpineExposure | None = None,
                measured_s: float | None = None) -> SpinalDose:
    """ISO 2631-5's figures of a vertical seat acceleration, by the standard's route (module docstring).

    Parameters
    ----------
    seat_az_mps2 : (n,) array_like
        The seat's vertical acceleration [m/s^2], gravity not included, uniformly sampled (its mean is removed).
    fs_hz : float
        Its sampling rate [Hz].
    exposure : SpineExposure, optional
        Daily exposure and the person (default: ``SpineExposure()``: 8 h a day, the Annex C example's man).
    measured_s : float, optional
        ``t_m``, the time the record covers [s] (default: its samples times the step).

    Returns
    -------
    SpinalDose
    """
    response = lumbar_response(seat_az_mps2, fs_hz)
    fs = positive_float(fs_hz, "fs_hz")
    route = (f"ISO 2631-5 Formula 1 from the seat's z acceleration at {fs:g} Hz, mean removed" +
             (f", upsampled to {response.fs_hz:g} Hz" if response.fs_hz != fs else ""))
    t_m = measured_s if measured_s is not None else response.acc_mps2.size / response.fs_hz
    return spinal_dose_from_lumbar(response.acc_mps2, response.fs_hz, exposure, t_m, route)


def spinal_dose_from_lumbar(lumbar_az_mps2, fs_hz: float, exposure: SpineExposure | None = None,
                            measured_s: float | None = None, route: str = "a lumbar acceleration") -> SpinalDose:
    """ISO 2631-5's figures of an acceleration that is already the lumbar spine's (e.g. a body model's lumbar point).

    Steps 2-4 of the module docstring: the peaks, the doses, S_d, R and P.  The signal is taken as it is (no mean
    removed: the response of a body about its settled posture has none).

    Parameters
    ----------
    lumbar_az_mps2 : (n,) array_like
        The lumbar spine's vertical acceleration [m/s^2], gravity not included.
    fs_hz : float
        Its sampling rate [Hz].
    exposure : SpineExposure, optional
    measured_s : float, optional
        ``t_m`` [s] (default: its samples times the step).
    route : str
        Where the signal comes from, for the record.

    Returns
    -------
    SpinalDose
    """
    acc = SpinalDoseAccumulator(fs_hz, lumbar=True)
    acc.add(lumbar_az_mps2)
    return acc.result(exposure, measured_s, route)


def route_difference(standard: SpinalDose, model: SpinalDose) -> str | None:
    """A sentence where the two routes' daily compressive stresses differ by more than ``ROUTE_DIFFERENCE``
    of the standard's; None where they agree."""
    ref = standard.compressive_stress_mpa
    if ref <= 0.0 or abs(model.compressive_stress_mpa - ref) <= ROUTE_DIFFERENCE * ref:
        return None
    return (f"the body model's lumbar point gives S_d {model.compressive_stress_mpa:.3g} MPa, "
            f"{100 * (model.compressive_stress_mpa / ref - 1):+.0f} % from the {ref:.3g} MPa of ISO 2631-5's "
            "transfer function: the model's vertical response departs from the standard's people here.")


def iso2631_5_summary(standard: SpinalDose, model: SpinalDose | None = None) -> dict:
    """The ISO 2631-5 figures for ``assessment.json``: the exposure, the standard's route from the seat, and the body
    model's route from its lumbar point (``None`` until a model's lumbar response is given), with a sentence where
    the two differ (:func:`route_difference`)."""
    return {"standard": "ISO 2631-5:2018, vertical (clause 5 and Annex C)",
            "exposure": standard.exposure.as_dict(),
            "standard_route": standard.as_dict(),
            "model_route": None if model is None else model.as_dict(),
            "routes_differ": None if model is None else route_difference(standard, model)}
