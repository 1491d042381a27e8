"""Seat-to-body transfer functions estimated from time histories (paper Eq. 1).

Pure array functions: no engine, no plotting.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal

from ..errors import InputError, checked, checked_class, finite_samples, positive_number


def band_select(freq_hz: np.ndarray, band_hz: tuple[float, float]) -> np.ndarray:
    """Boolean mask of the frequencies inside a band (inclusive)."""
    return (freq_hz >= band_hz[0]) & (freq_hz <= band_hz[1])


@checked_class
@dataclass(frozen=True)
class Curve:
    """One frequency response curve (an estimate, an exact response or measured gains).

    Attributes
    ----------
    freq_hz : (m,) array
    gain : (m,) array
        ``|H|`` (output units per input unit).
    phase_deg : (m,) array
        Phase [deg] (NaN where not known).
    coherence : (m,) array
        Magnitude-squared coherence, 0 to 1 (NaN where not known).
    gain_sd : (m,) array
        Standard deviation of measured gains (NaN where not known).
    weight : float
        Weight of the curve in a total criterion.
    """

    freq_hz: np.ndarray
    gain: np.ndarray
    phase_deg: np.ndarray
    coherence: np.ndarray
    gain_sd: np.ndarray | None = None
    weight: float = 1.0

    def __post_init__(self) -> None:
        if self.gain_sd is None:
            object.__setattr__(self, "gain_sd", np.full(np.shape(self.freq_hz), np.nan))

    def _band(self, band_hz: tuple[float, float], at_least: int) -> np.ndarray:
        sel = band_select(self.freq_hz, band_hz)
        if sel.sum() < at_least:
            raise InputError(f"the curve has fewer than {at_least} frequencies in {band_hz[0]:g}-{band_hz[1]:g} Hz.")
        return sel

    def peak(self, band_hz: tuple[float, float] = (0.5, 12.0)) -> tuple[float, float]:
        """(frequency [Hz], gain) of the largest gain within a band."""
        sel = self._band(band_hz, 1)
        i = int(np.argmax(np.where(sel, self.gain, -np.inf)))
        return float(self.freq_hz[i]), float(self.gain[i])

    def mean_gain(self, band_hz: tuple[float, float]) -> float:
        """Mean gain over a band (trapezoidal, per Hz)."""
        sel = self._band(band_hz, 2)
        f, g = self.freq_hz[sel], self.gain[sel]
        return float(np.trapezoid(g, f) / (f[-1] - f[0]))

    def at(self, freq_hz: float) -> float:
        """Gain linearly interpolated at one frequency."""
        return float(np.interp(freq_hz, self.freq_hz, self.gain))


@checked
def h1_estimate(x: np.ndarray, y: np.ndarray, fs_hz: float, segment_s: float = 10.0,
                lowpass_hz: float | None = 12.0) -> Curve:
    """H1 transfer-function estimate y/x with Welch averaging (Hann windows, 50 % overlap).

    Parameters
    ----------
    x, y : (n,) arrays
        Input and output time histories sampled at ``fs_hz``.
    segment_s : float
        Welch segment length [s]; the frequency resolution is 1 / segment_s.
    lowpass_hz : float or None
        Cut-off of the paper's Butterworth filter (4th order, zero phase) applied to input and output alike
        before estimation; None skips it.
    """
    fs_hz = positive_number("h1_estimate", "fs_hz", fs_hz)
    segment_s = positive_number("h1_estimate", "segment_s", segment_s)
    if lowpass_hz is not None:
        lowpass_hz = positive_number("h1_estimate", "lowpass_hz", lowpass_hz)
    x, y = _samples("x (the input)", x), _samples("y (the output)", y)
    if x.shape != y.shape:
        raise InputError(f"h1_estimate: x and y must be of the same length, not {x.size} and {y.size} samples.")
    nper = int(round(segment_s * fs_hz))
    if nper < 8 or nper > x.size:
        raise InputError(
            f"a {segment_s:g} s estimation segment needs at least {segment_s:g} s of data; the record is "
            f"{x.size / fs_hz:.3g} s long."
        )
    if lowpass_hz is not None and lowpass_hz < fs_hz / 2:
        sos = signal.butter(4, lowpass_hz, btype="low", fs=fs_hz, output="sos")
        x = signal.sosfiltfilt(sos, x)
        y = signal.sosfiltfilt(sos, y)
    f, pxx = signal.welch(x, fs=fs_hz, nperseg=nper)
    _, pxy = signal.csd(x, y, fs=fs_hz, nperseg=nper)
    _, pyy = signal.welch(y, fs=fs_hz, nperseg=nper)
    with np.errstate(divide="ignore", invalid="ignore"):
        h = pxy / pxx
        coh = np.abs(pxy) ** 2 / (pxx * pyy)
    ok = pxx > 0
    return Curve(freq_hz=f[ok], gain=np.abs(h[ok]), phase_deg=np.degrees(np.angle(h[ok])),
                            coherence=np.nan_to_num(coh[ok]))


def _samples(name: str, values) -> np.ndarray:
    """A time history as a 1-D float array of finite samples, or one sentence naming the first bad sample."""
    return finite_samples(f"h1_estimate: {name}", values, "fill or cut the gap before estimating (Welch averages "
                          "would spread it over every frequency)")


def discrete_frequency_response(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray, dt_s: float,
                                freq_hz: np.ndarray) -> np.ndarray:
    """Frequency response H(f) = C (z I - A)^-1 B + D, z = exp(j 2 pi f dt), of a discrete state-space model.

    Returns a complex array of shape (n_freq, n_outputs, n_inputs).  Uses the eigen-decomposition of A, so
    the cost is one decomposition plus O(n_freq n_state (n_out + n_in)).
    """
    freq_hz = np.asarray(freq_hz, dtype=float)
    lam, V = np.linalg.eig(A)
    CV = C @ V
    VinvB = np.linalg.solve(V, B)
    z = np.exp(2j * np.pi * freq_hz * dt_s)
    inv = 1.0 / (z[:, None] - lam[None, :])  # (n_freq, n_state)
    H = np.einsum("os,fs,si->foi", CV, inv, VinvB) + D[None, :, :]
    return H
