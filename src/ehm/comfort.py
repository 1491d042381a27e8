"""Whole-body vibration evaluation after ISO 2631-1:1997.

Frequency weightings, their causal digital filters and the evaluation values of the standard:
weighted rms, maximum transient vibration value, vibration dose value, crest factor, motion sickness
dose value, vibration total value and the comfort reactions of its Annex C.

Pure array functions: no engine, no plotting, no files, nothing computed at import time.

Public API
----------
WEIGHTINGS                              names of the weightings: Wk, Wd, Wf, Wc, We, Wj
frequency_weighting(name, freq_hz)      exact analog response (complex)
weighting_sos(name, fs_hz)              second-order sections of the causal digital filter
weight(name, signal, fs_hz)             causal weighting of a whole record
WeightingFilter(name, fs_hz)            the same filter sample by sample or block by block
ComfortMetrics, metrics(signal, fs_hz, weighting)
total_value(ax, ay, az, fs_hz, purpose="comfort", seated=True)
comfort_reaction(a_w)                   ISO 2631-1 Annex C label(s)
seat_value(a_w_body, a_w_seat)          SEAT-style ratio in %

Weighting definition (ISO 2631-1:1997 Annex A; ISO 8041 Table with the same parameters)
-------------------------------------------------------------------------------------------
With ``s = j 2 pi f`` and ``w_i = 2 pi f_i`` every weighting is the product of

* a high-pass at ``f1``: ``s^2 / (s^2 + s w1/Q1 + w1^2)`` with ``Q1 = 1/sqrt(2)``,
* a low-pass at ``f2``: ``w2^2 / (s^2 + s w2/Q2 + w2^2)`` with ``Q2 = 1/sqrt(2)``,
* an acceleration-velocity transition ``(1 + s/w3) / (1 + s/(Q4 w4) + (s/w4)^2)``
  (numerator 1 when ``f3`` is absent, the whole factor 1 when ``f4`` is absent too),
* an upward step ``(1 + s/(Q5 w5) + (s/w5)^2) / (1 + s/(Q6 w6) + (s/w6)^2) * (w5/w6)^2``,
  which equals ``(s^2 + s w5/Q5 + w5^2) / (s^2 + s w6/Q6 + w6^2)``: gain ``(f5/f6)^2`` well below
  ``f5`` and 1 well above ``f6``.  (Multiplying the monic form by ``(w6/w5)^2`` would double Wk
  above 4 Hz; the published Wk of 0.482 at 1 Hz and about 1.05 at 6.3 Hz rules that out.)

The overall gain factor K of ISO 8041 is 1 for all six weightings.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import signal as _sig

from .errors import InputError

__all__ = [
    "WEIGHTINGS", "frequency_weighting", "weighting_sos", "weight", "WeightingFilter", "ComfortMetrics",
    "metrics", "total_value", "comfort_reaction", "seat_value",
]

_Q_BAND = 1.0 / math.sqrt(2.0)

# name: (f1, f2, f3, f4, Q4, f5, Q5, f6, Q6) in Hz; None marks an absent factor (infinite frequency).
_PARAMETERS: dict[str, tuple[float | None, ...]] = {
    "Wk": (0.4, 100.0, 12.5, 12.5, 0.63, 2.37, 0.91, 3.35, 0.91),
    "Wd": (0.4, 100.0, 2.0, 2.0, 0.63, None, None, None, None),
    "Wf": (0.08, 0.63, None, 0.25, 0.86, 0.0625, 0.80, 0.10, 0.80),
    "Wc": (0.4, 100.0, 8.0, 8.0, 0.63, None, None, None, None),
    "We": (0.4, 100.0, 1.0, 1.0, 0.63, None, None, None, None),
    "Wj": (0.4, 100.0, None, None, None, 3.75, 0.91, 5.32, 0.91),
}

#: Names of the available frequency weightings (ISO 2631-1:1997, Tables 3 and 4).
WEIGHTINGS: tuple[str, ...] = tuple(_PARAMETERS)

_PURPOSES = ("comfort", "health")


# --------------------------------------------------------------------------
# input checks
# --------------------------------------------------------------------------


def _canonical_name(name, arg: str = "name") -> str:
    if isinstance(name, str):
        for key in _PARAMETERS:
            if key.lower() == name.strip().lower():
                return key
    raise InputError(f"{arg} must be one of {', '.join(WEIGHTINGS)}; got {name!r}.")


def _positive_float(value, arg: str) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{arg} must be a positive number; got {value!r}.") from None
    if not math.isfinite(out) or out <= 0.0:
        raise InputError(f"{arg} must be a positive finite number; got {value!r}.")
    return out


def _non_negative_float(value, arg: str, what: str = "number") -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{arg} must be a non-negative {what}; got {value!r}.") from None
    if not math.isfinite(out) or out < 0.0:
        raise InputError(f"{arg} must be a finite, non-negative {what}; got {value!r}.")
    return out


def _signal_1d(values, arg: str) -> np.ndarray:
    try:
        out = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{arg} must be a 1-D array of numbers; got {type(values).__name__}.") from None
    if out.ndim != 1:
        raise InputError(f"{arg} must be a 1-D array; got an array of shape {out.shape}.")
    if out.size == 0:
        raise InputError(f"{arg} must hold at least one sample; got an empty array.")
    if not np.all(np.isfinite(out)):
        bad = int(np.argmin(np.isfinite(out)))
        raise InputError(f"{arg} must be finite; got a non-finite value at sample {bad}.")
    return out


def _sample_rate(name: str, fs_hz) -> float:
    fs = _positive_float(fs_hz, "fs_hz")
    p = _PARAMETERS[name]
    f_top = max(f for f in (p[0], p[1], p[2], p[3], p[5], p[7]) if f is not None)
    if fs <= 2.0 * f_top:
        raise InputError(
            f"fs_hz must exceed twice the highest corner frequency of {name} ({f_top:g} Hz); got {fs_hz!r}."
        )
    return fs


# --------------------------------------------------------------------------
# analog weightings
# --------------------------------------------------------------------------


def _analog_factors(name: str, omega=lambda f: 2 * math.pi * f) -> list[tuple[np.ndarray, np.ndarray]]:
    """Factors (num, den) of the weighting as polynomials in s [rad/s], highest power first.

    ``omega(f)`` turns a corner frequency [Hz] into rad/s (exact by default; pre-warped for the digital filter).
    """
    f1, f2, f3, f4, q4, f5, q5, f6, q6 = _PARAMETERS[name]
    w1, w2 = omega(f1), omega(f2)
    factors = [
        (np.array([1.0, 0.0, 0.0]), np.array([1.0, w1 / _Q_BAND, w1 * w1])),   # high-pass
        (np.array([w2 * w2]), np.array([1.0, w2 / _Q_BAND, w2 * w2])),         # low-pass
    ]
    if f4 is not None:                                                        # a-v transition
        w4 = omega(f4)
        den = np.array([1.0, w4 / q4, w4 * w4])
        num = np.array([w4 * w4]) if f3 is None else np.array([w4 * w4 / omega(f3), w4 * w4])
        factors.append((num, den))
    if f5 is not None:                                                        # upward step
        w5, w6 = omega(f5), omega(f6)
        factors.append((np.array([1.0, w5 / q5, w5 * w5]), np.array([1.0, w6 / q6, w6 * w6])))
    return factors


def frequency_weighting(name: str, freq_hz) -> np.ndarray:
    """Exact analog frequency response of an ISO 2631-1 weighting.

    Parameters
    ----------
    name : str
        One of ``WEIGHTINGS`` (``"Wk"``, ``"Wd"``, ``"Wf"``, ``"Wc"``, ``"We"``, ``"Wj"``; case ignored).
    freq_hz : float or array_like
        Frequencies [Hz], finite and non-negative.

    Returns
    -------
    ndarray of complex
        Response W(j 2 pi f), same shape as ``freq_hz``; ``abs`` gives the weighting factor.
    """
    key = _canonical_name(name)
    try:
        f = np.asarray(freq_hz, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"freq_hz must be numbers in Hz; got {type(freq_hz).__name__}.") from None
    if not np.all(np.isfinite(f)) or np.any(f < 0):
        raise InputError(f"freq_hz must be finite and non-negative; got {freq_hz!r}.")
    s = 2j * np.pi * f
    out = np.ones(f.shape, dtype=complex)
    for num, den in _analog_factors(key):
        out = out * np.polyval(num, s) / np.polyval(den, s)
    return out


# --------------------------------------------------------------------------
# digital filters
# --------------------------------------------------------------------------


def _prewarp(w: float, fs: float) -> float:
    """Analog angular frequency that the bilinear transform maps onto ``w`` [rad/s]."""
    return 2.0 * fs * math.tan(w / (2.0 * fs))


def weighting_sos(name: str, fs_hz: float) -> np.ndarray:
    """Second-order sections of the causal digital weighting filter.

    Each analog factor (high-pass, low-pass, transition, upward step) becomes one section by the
    bilinear transform (``scipy.signal.bilinear_zpk``) with its characteristic frequencies pre-warped,
    so each corner frequency and Q is exact in the digital filter.  Working factor by factor in
    zeros, poles and gain keeps the 0.08 Hz poles of Wf well conditioned at high sampling rates.
    The response departs from the analog one only through the frequency compression of the
    bilinear transform near the Nyquist frequency (see the tests for the measured error).

    Parameters
    ----------
    name : str
        One of ``WEIGHTINGS``.
    fs_hz : float
        Sampling rate [Hz]; must exceed twice the highest corner frequency of the weighting
        (200 Hz for all but Wf, 1.26 Hz for Wf).

    Returns
    -------
    (n_sections, 6) ndarray
        ``[b0, b1, b2, 1, a1, a2]`` rows for ``scipy.signal.sosfilt``.
    """
    key = _canonical_name(name)
    fs = _sample_rate(key, fs_hz)
    sections = []
    for num, den in _analog_factors(key, lambda f: _prewarp(2.0 * math.pi * f, fs)):  # pre-warped corners
        z, p, k = _sig.tf2zpk(num, den)
        zd, pd, kd = _sig.bilinear_zpk(z, p, k, fs)
        sections.append(_sig.zpk2sos(zd, pd, kd))
    return np.vstack(sections)


def weight(name: str, signal, fs_hz: float) -> np.ndarray:
    """Frequency-weight an acceleration record with a causal filter.

    Uses ``scipy.signal.sosfilt`` from rest (zero initial state); never a forward-backward filter,
    which would apply the weighting's magnitude twice.  The output therefore holds the filter's
    start-up transient (a few seconds for Wf, under about 5 s for the others).

    Parameters
    ----------
    name : str
        One of ``WEIGHTINGS``.
    signal : (n,) array_like
        Acceleration [m/s^2] (or [rad/s^2] for rotational weightings) sampled at ``fs_hz``.
    fs_hz : float
        Sampling rate [Hz].

    Returns
    -------
    (n,) ndarray
        Weighted acceleration, same units as ``signal``.
    """
    sos = weighting_sos(name, fs_hz)
    x = _signal_1d(signal, "signal")
    return _sig.sosfilt(sos, x)


class WeightingFilter:
    """Streaming causal weighting filter that keeps its state between calls.

    Feeding a record in pieces through ``step`` and ``process`` gives the same output as
    ``weight(name, record, fs_hz)`` on the whole record.

    Parameters
    ----------
    name : str
        One of ``WEIGHTINGS``.
    fs_hz : float
        Sampling rate [Hz].
    """

    def __init__(self, name: str, fs_hz: float):
        self.sos = weighting_sos(name, fs_hz)
        self.name = _canonical_name(name)
        self.fs_hz = float(fs_hz)
        self._zi = np.zeros((self.sos.shape[0], 2))

    def reset(self) -> None:
        """Return the filter to rest (zero state)."""
        self._zi[:] = 0.0

    def process(self, block) -> np.ndarray:
        """Weight the next block of samples.

        Parameters
        ----------
        block : (m,) array_like
            The next ``m`` input samples; an empty block returns an empty array.

        Returns
        -------
        (m,) ndarray
            The weighted samples.
        """
        x = np.asarray(block, dtype=float)
        if x.ndim != 1:
            raise InputError(f"block must be a 1-D array; got an array of shape {x.shape}.")
        if x.size == 0:
            return np.zeros(0)
        if not np.all(np.isfinite(x)):
            raise InputError("block must be finite; got a non-finite sample.")
        y, self._zi = _sig.sosfilt(self.sos, x, zi=self._zi)
        return y

    def step(self, x: float) -> float:
        """Weight one sample and return the weighted sample."""
        try:
            value = float(x)
        except (TypeError, ValueError):
            raise InputError(f"x must be one number; got {x!r}.") from None
        return float(self.process(np.array([value]))[0])


# --------------------------------------------------------------------------
# evaluation values
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class ComfortMetrics:
    """Evaluation values of one weighted acceleration record (ISO 2631-1:1997, clauses 6 and 9).

    Attributes
    ----------
    a_w : float
        Weighted rms acceleration [m/s^2] over the whole record (6.1).
    mtvv : float
        Maximum transient vibration value [m/s^2]: the maximum of ``running_rms`` (6.3.1).
    vdv : float
        Fourth-power vibration dose value ``(integral a_w^4 dt)^(1/4)`` [m/s^1.75] (6.3.2).
    crest_factor : float
        ``max |a_w(t)| / a_w`` (6.2.1); nan for an all-zero record.
    msdv : float or None
        Motion sickness dose value ``sqrt(integral a_wf^2 dt)`` [m/s^1.5] with the Wf weighting
        (clause 9), None when the input was already weighted (``weighting=None``).
    running_rms : (n,) ndarray
        Running rms with a rectangular window of ``tau_s`` [m/s^2], one value per sample.
    duration_s : float
        Record duration ``n / fs_hz`` [s].
    """

    a_w: float
    mtvv: float
    vdv: float
    crest_factor: float
    msdv: float | None
    running_rms: np.ndarray
    duration_s: float

    @property
    def mtvv_ratio(self) -> float:
        """MTVV / a_w; ISO 2631-1 6.3.3 suggests the additional methods matter above 1.5."""
        return self.mtvv / self.a_w if self.a_w > 0 else float("nan")

    @property
    def vdv_ratio(self) -> float:
        """VDV / (a_w T^(1/4)); ISO 2631-1 6.3.3 suggests the additional methods matter above 1.75."""
        denom = self.a_w * self.duration_s ** 0.25
        return self.vdv / denom if denom > 0 else float("nan")


def _running_rms(aw: np.ndarray, fs: float, tau_s: float) -> np.ndarray:
    """Rectangular running rms: sqrt(1/tau * integral_{t-tau}^{t} a^2 dt), zero signal before t = 0."""
    n = int(round(tau_s * fs))
    if n < 1:
        raise InputError(f"tau_s must span at least one sample at {fs:g} Hz; got {tau_s!r}.")
    c = np.concatenate(([0.0], np.cumsum(aw * aw)))
    lagged = np.concatenate((np.zeros(min(n, c.size)), c))[: c.size]
    energy = np.maximum(c[1:] - lagged[1:], 0.0)
    return np.sqrt(energy / n)


def metrics(signal, fs_hz: float, weighting: str | None = "Wk", *, tau_s: float = 1.0) -> ComfortMetrics:
    """ISO 2631-1 evaluation values of an acceleration record.

    Parameters
    ----------
    signal : (n,) array_like
        Acceleration [m/s^2] sampled at ``fs_hz``; unweighted unless ``weighting`` is None.
    fs_hz : float
        Sampling rate [Hz].
    weighting : str or None
        Weighting applied causally before evaluation (one of ``WEIGHTINGS``); None when ``signal``
        is already weighted (then ``msdv`` is None, since the unweighted motion that Wf needs is
        unknown).
    tau_s : float
        Integration time of the running rms [s]; ISO 2631-1 6.3.1 recommends 1 s.

    Returns
    -------
    ComfortMetrics

    Notes
    -----
    Everything is evaluated over the whole record, including the weighting filter's start-up
    transient.  Integrals are sums times ``1/fs_hz``.  The running rms is the linear (rectangular)
    integration of ISO 2631-1 6.3.1,
    ``a_w(t0) = sqrt(1/tau * integral_{t0-tau}^{t0} a_w(t)^2 dt)``, evaluated at every sample with
    the signal taken as zero before the record starts (the window holds ``round(tau_s * fs_hz)``
    samples); the exponential-averaging alternative of 6.3.1 is not used.  MTVV is its maximum.
    """
    x = _signal_1d(signal, "signal")
    fs = _positive_float(fs_hz, "fs_hz")
    tau = _positive_float(tau_s, "tau_s")
    if weighting is None:
        aw = x
        msdv = None
    else:
        key = _canonical_name(weighting, "weighting")
        aw = _sig.sosfilt(weighting_sos(key, fs), x)
        awf = aw if key == "Wf" else _sig.sosfilt(weighting_sos("Wf", fs), x)
        msdv = float(np.sqrt(np.sum(awf * awf) / fs))
    a_w = float(np.sqrt(np.mean(aw * aw)))
    running = _running_rms(aw, fs, tau)
    peak = float(np.max(np.abs(aw)))
    return ComfortMetrics(
        a_w=a_w,
        mtvv=float(np.max(running)),
        vdv=float((np.sum(aw ** 4) / fs) ** 0.25),
        crest_factor=peak / a_w if a_w > 0 else float("nan"),
        msdv=msdv,
        running_rms=running,
        duration_s=x.size / fs,
    )


class ComfortAccumulator:
    """ISO 2631-1 evaluation values of a record fed block by block, in constant memory.

    Gives the same ``a_w``, ``mtvv``, ``vdv``, ``crest_factor`` and ``msdv`` as :func:`metrics` on the whole
    record; ``running_rms`` is kept only every ``keep_every`` samples (for plotting long drives).

    Parameters
    ----------
    weighting : str
        One of ``WEIGHTINGS``, applied causally.
    fs_hz : float
        Sampling rate [Hz].
    tau_s : float
        Running-rms integration time [s].
    keep_every : int
        Keep one running-rms value every this many samples.
    """

    def __init__(self, weighting: str, fs_hz: float, tau_s: float = 1.0, keep_every: int = 100):
        self.fs = _positive_float(fs_hz, "fs_hz")
        self._w = WeightingFilter(weighting, self.fs)
        self._wf = WeightingFilter("Wf", self.fs)
        self._n_tau = int(round(_positive_float(tau_s, "tau_s") * self.fs))
        if self._n_tau < 1:
            raise InputError(f"tau_s must span at least one sample at {self.fs:g} Hz; got {tau_s!r}.")
        self._keep = max(1, int(keep_every))
        self._tail = np.zeros(self._n_tau)  # the last tau of squared weighted samples
        self._n = 0
        self._sum2 = self._sum4 = self._sumf2 = 0.0
        self._peak = self._mtvv = 0.0
        self._kept: list[np.ndarray] = []
        self.last_running_rms = 0.0

    def add(self, block) -> np.ndarray:
        """Feed the next samples [m/s^2]; returns their weighted values."""
        x = _signal_1d(block, "block")
        aw = self._w.process(x)
        awf = self._wf.process(x)
        sq = aw * aw
        # window sum of the last tau for every new sample: c[n_tau + j] - c[j] over tail + block
        c = np.cumsum(np.concatenate((self._tail, sq)))
        window = c[self._n_tau:] - c[:sq.size]
        running = np.sqrt(np.maximum(window, 0.0) / self._n_tau)
        first = (-self._n) % self._keep
        self._kept.append(running[first::self._keep].copy())  # a copy: a view would keep the whole block
        self._tail = np.concatenate((self._tail, sq))[-self._n_tau:]
        self._n += x.size
        self._sum2 += float(sq.sum())
        self._sum4 += float(np.sum(sq * sq))
        self._sumf2 += float(np.sum(awf * awf))
        self._peak = max(self._peak, float(np.max(np.abs(aw))))
        self._mtvv = max(self._mtvv, float(running.max()))
        self.last_running_rms = float(running[-1])  #: running rms at the latest sample [m/s^2]
        return aw

    @property
    def a_w_so_far(self) -> float:
        """Weighted rms acceleration of everything added so far [m/s^2] (0 before any sample)."""
        return float(np.sqrt(self._sum2 / self._n)) if self._n else 0.0

    def result(self) -> ComfortMetrics:
        """The evaluation values so far (``running_rms`` decimated by ``keep_every``)."""
        if self._n == 0:
            raise InputError("no samples were added.")
        a_w = float(np.sqrt(self._sum2 / self._n))
        return ComfortMetrics(
            a_w=a_w, mtvv=self._mtvv, vdv=float((self._sum4 / self.fs) ** 0.25),
            crest_factor=self._peak / a_w if a_w > 0 else float("nan"),
            msdv=float(np.sqrt(self._sumf2 / self.fs)), running_rms=np.concatenate(self._kept),
            duration_s=self._n / self.fs,
        )


def total_value(ax, ay, az, fs_hz: float, purpose: str = "comfort", seated: bool = True) -> float:
    """Vibration total value ``a_v = sqrt(kx^2 a_wx^2 + ky^2 a_wy^2 + kz^2 a_wz^2)`` [m/s^2].

    The translational accelerations are weighted with Wd (x, y) and Wk (z) and their rms values
    combined with the multiplying factors k of ISO 2631-1:1997:

    * ``purpose="comfort"`` (clause 8, seat surface of seated persons, and the floor under
      standing persons): kx = ky = kz = 1;
    * ``purpose="health"`` (clause 7, seat surface of seated persons only): kx = ky = 1.4, kz = 1.

    Parameters
    ----------
    ax, ay, az : (n,) array_like
        Unweighted accelerations [m/s^2] along x (fore-aft), y (lateral) and z (vertical), sampled
        at ``fs_hz``, all of the same length.
    fs_hz : float
        Sampling rate [Hz].
    purpose : {"comfort", "health"}
        Which set of multiplying factors to use.
    seated : bool
        True for a seated person (seat surface), False for a standing person (floor).  The health
        guidance of the standard applies to seated persons only.

    Returns
    -------
    float
        a_v [m/s^2].
    """
    if purpose not in _PURPOSES:
        raise InputError(f"purpose must be 'comfort' or 'health'; got {purpose!r}.")
    if not isinstance(seated, (bool, np.bool_)):
        raise InputError(f"seated must be True or False; got {seated!r}.")
    if purpose == "health" and not seated:
        raise InputError(
            "purpose 'health' applies to seated persons only (ISO 2631-1 clause 7); got seated=False."
        )
    axes = [_signal_1d(a, n) for a, n in ((ax, "ax"), (ay, "ay"), (az, "az"))]
    if not axes[0].size == axes[1].size == axes[2].size:
        raise InputError(
            f"ax, ay and az must have the same length; got {axes[0].size}, {axes[1].size} and {axes[2].size}."
        )
    k = (1.4, 1.4, 1.0) if purpose == "health" else (1.0, 1.0, 1.0)
    total = 0.0
    for a, name, ki in zip(axes, ("Wd", "Wd", "Wk"), k):
        aw = weight(name, a, fs_hz)
        total += ki * ki * float(np.mean(aw * aw))
    return math.sqrt(total)


# ISO 2631-1:1997 Annex C: approximate indications of likely reactions to a_v or a_w [m/s^2].
_REACTIONS = (
    (0.0, 0.315, "not uncomfortable"),
    (0.315, 0.63, "a little uncomfortable"),
    (0.5, 1.0, "fairly uncomfortable"),
    (0.8, 1.6, "uncomfortable"),
    (1.25, 2.5, "very uncomfortable"),
    (2.0, math.inf, "extremely uncomfortable"),
)


def comfort_reaction(a_w: float) -> str:
    """Likely reaction to a weighted rms acceleration in public transport (ISO 2631-1 Annex C).

    The bands of the standard overlap; every band ``lo <= a_w < hi`` that contains ``a_w`` is
    named, mildest first, joined by ``" / "``:

    ====================  =========================
    a_w [m/s^2]           reaction
    ====================  =========================
    below 0.315           not uncomfortable
    0.315 to 0.63         a little uncomfortable
    0.5 to 1              fairly uncomfortable
    0.8 to 1.6            uncomfortable
    1.25 to 2.5           very uncomfortable
    2 and above           extremely uncomfortable
    ====================  =========================

    Parameters
    ----------
    a_w : float
        Weighted rms acceleration or vibration total value [m/s^2], finite and non-negative.

    Returns
    -------
    str
        e.g. ``"a little uncomfortable / fairly uncomfortable"`` for 0.55 m/s^2.
    """
    a = _non_negative_float(a_w, "a_w", "acceleration in m/s^2")
    return " / ".join(label for lo, hi, label in _REACTIONS if lo <= a < hi)


def seat_value(a_w_body: float, a_w_seat: float) -> float:
    """SEAT value [%]: ``100 * a_w_body / a_w_seat``.

    Griffin's Seat Effective Amplitude Transmissibility is the ratio of a weighted vibration
    magnitude where the vibration reaches the person to the one at the excitation, in percent.
    Here the excitation is the seat (the input of ``SeatedHuman.simulate``) and the response a point
    of the body, so the ratio is body over seat.  Use two rms values (``a_w``) or two vibration dose
    values, computed with the same weighting; above 100 % the body amplifies the seat vibration.

    Parameters
    ----------
    a_w_body : float
        Weighted magnitude at the body [m/s^2 or m/s^1.75], finite and non-negative.
    a_w_seat : float
        Weighted magnitude at the seat, same kind and units, finite and positive.

    Returns
    -------
    float
        SEAT [%].
    """
    body = _non_negative_float(a_w_body, "a_w_body")
    seat = _positive_float(a_w_seat, "a_w_seat")
    return 100.0 * body / seat
