"""The paper's fitting criterion (Eqs. 2 and 3): how far model gains lie from measured ones.

For one curve with measured gains G_exp at frequencies f (limited to a band, default 0.1-12 Hz):

    Rel_Gain = G_exp + 0.05 * mean(G_exp)                              (Eq. 2)
    Crit     = RMS over f of (G_exp - G_model) / (Rel_Gain * f^2)       (Eq. 3)

The 1/f^2 factor gives low frequencies (0.1-3 Hz) priority, as the paper intends for comfort.  Model
gains are interpolated linearly onto the measured frequencies.  The total criterion is the mean of the
curves' criteria, weighted by the curves' ``weight`` (1 unless the data file gives one).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import InputError
from .frf import FrfTable
from .transfer import band_select

DEFAULT_BAND_HZ = (0.1, 12.0)


@dataclass(frozen=True)
class CurveCriterion:
    """Criterion of one measured curve against the model."""

    input_axis: str
    point: str
    dof: str
    crit: float
    n_freq: int
    weight: float


@dataclass(frozen=True)
class Comparison:
    """All curves' criteria and their weighted mean (``total``)."""

    curves: tuple
    total: float

    def as_dict(self) -> dict:
        """Plain data for JSON output."""
        return {
            "total": self.total,
            "curves": [{"input_axis": c.input_axis, "point": c.point, "dof": c.dof, "crit": c.crit,
                        "n_freq": c.n_freq, "weight": c.weight} for c in self.curves],
        }


def relative_gain(gain_exp: np.ndarray) -> np.ndarray:
    """Eq. 2: the measured gain plus 5 % of its mean over the curve."""
    g = np.asarray(gain_exp, dtype=float)
    return g + 0.05 * g.mean()


def residuals(freq_hz: np.ndarray, gain_exp: np.ndarray, gain_model: np.ndarray, label: str = "a measured curve") -> np.ndarray:
    """Eq. 3's terms (G_exp - G_model) / (Rel_Gain f^2), one per frequency."""
    f = np.asarray(freq_hz, dtype=float)
    g = np.asarray(gain_exp, dtype=float)
    rel = relative_gain(g)
    if np.any(rel <= 0):
        raise InputError(f"{label} has zero gain at every frequency; the relative gain (Eq. 2) would be zero.")
    return (g - np.asarray(gain_model, dtype=float)) / (rel * f ** 2)


def curve_criterion(freq_hz: np.ndarray, gain_exp: np.ndarray, gain_model: np.ndarray,
                    label: str = "a measured curve") -> float:
    """Eq. 3 for one curve: the RMS of :func:`residuals`."""
    r = residuals(freq_hz, gain_exp, gain_model, label)
    return float(np.sqrt(np.mean(r ** 2)))


def compare(measured: FrfTable, model: FrfTable, band_hz: tuple[float, float] = DEFAULT_BAND_HZ) -> Comparison:
    """Criterion of every measured curve against the model table, and their weighted mean.

    Raises :class:`InputError` when the model lacks a measured curve or does not cover its frequencies.
    """
    out = []
    for key in measured.keys():
        m = measured.curves[key]
        sel = band_select(m.freq_hz, band_hz)
        if not sel.any():
            continue
        mod = model.curve(*key)
        f = m.freq_hz[sel]
        if f[0] < mod.freq_hz[0] * (1 - 1e-9) or f[-1] > mod.freq_hz[-1] * (1 + 1e-9):
            raise InputError(
                f"the model curve seat {key[0]} -> {key[1]} {key[2]} covers {mod.freq_hz[0]:g}-{mod.freq_hz[-1]:g} Hz "
                f"but the measured one needs {f[0]:g}-{f[-1]:g} Hz."
            )
        g_model = np.interp(f, mod.freq_hz, mod.gain)
        label = f"the measured curve seat {key[0]} -> {key[1]} {key[2]}"
        out.append(CurveCriterion(*key, crit=curve_criterion(f, m.gain[sel], g_model, label), n_freq=int(f.size),
                                  weight=m.weight))
    if not out:
        raise InputError(f"no measured frequencies lie in {band_hz[0]:g}-{band_hz[1]:g} Hz.")
    w = np.array([c.weight for c in out])
    if w.sum() <= 0:
        raise InputError("all curve weights are zero.")
    total = float(np.sum(w * np.array([c.crit for c in out])) / w.sum())
    return Comparison(curves=tuple(out), total=total)
