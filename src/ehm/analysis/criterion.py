"""The paper's fitting criterion (Eqs. 2 and 3): how far model gains lie from measured ones.

For one curve with measured gains G_exp at frequencies f (limited to a band, default 0.1-12 Hz):

    Rel_Gain = G_exp + 0.05 * mean(G_exp)                              (Eq. 2)
    Crit     = RMS over f of (G_exp - G_model) / (Rel_Gain * f^2)       (Eq. 3)

The 1/f^2 factor gives low frequencies (0.1-3 Hz) priority, as the paper intends for comfort.  Model
gains are interpolated linearly onto the measured frequencies.  The total criterion is the mean of the
curves' criteria, weighted by the curves' ``weight`` (1 unless the data file gives one).

Measured curves that carry no signal would dominate it: Eq. 2's relative gain of a path that is zero by
symmetry (lateral response to fore-aft input) or buried in noise is tiny, so any model gain there makes a
huge criterion.  Such curves, whose peak in the band lies below :data:`SMALL_CURVE_FRACTION` of the largest
measured curve of the same kind (translational gains, rotational gains, apparent masses) for the same seat
axis, are left out, with a warning that lists them, unless ``keep_small=True`` (``--keep-small-curves``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import errors
from ..errors import EhmWarning, InputError, checked
from ..standards.transfer import band_select
from .frf import MASS_POINTS, FrfTable

DEFAULT_BAND_HZ = (0.1, 12.0)
#: A measured curve whose peak is below this fraction of the largest curve of its kind for the same seat axis
#: is left out of the criterion (unless kept): 10 %.
SMALL_CURVE_FRACTION = 0.1


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
    left_out: tuple = ()  #: keys of the measured curves left out as too small (see the module docstring)

    def as_dict(self) -> dict:
        """Plain data for JSON output."""
        return {
            "total": self.total,
            "left_out": [{"input_axis": a, "point": p, "dof": d} for a, p, d in self.left_out],
            "curves": [{"input_axis": c.input_axis, "point": c.point, "dof": c.dof, "crit": c.crit,
                        "n_freq": c.n_freq, "weight": c.weight} for c in self.curves],
        }


def relative_gain(gain_exp: np.ndarray) -> np.ndarray:
    """Eq. 2: the measured gain plus 5 % of its mean over the curve."""
    g = np.asarray(gain_exp, dtype=float)
    return g + 0.05 * g.mean()


def residuals(freq_hz: np.ndarray, gain_exp: np.ndarray, gain_model: np.ndarray,
              label: str = "a measured curve") -> np.ndarray:
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


def _kind(key: tuple) -> str:
    _, point, dof = key
    if point in MASS_POINTS:
        return "apparent mass"
    return "rotation" if dof in ("roll", "pitch", "yaw") else "translation"


def small_curves(measured: FrfTable, band_hz: tuple[float, float] = DEFAULT_BAND_HZ,
                 fraction: float = SMALL_CURVE_FRACTION) -> dict:
    """Measured curves whose peak in the band is below ``fraction`` of the largest curve of the same kind
    (translation, rotation, apparent mass) for the same seat axis: key -> (peak, largest peak)."""
    peaks = {}
    for key in measured.keys():
        c = measured.curves[key]
        sel = band_select(c.freq_hz, band_hz)
        if sel.any():
            peaks[key] = float(np.max(c.gain[sel]))
    largest = {}
    for key, pk in peaks.items():
        group = (key[0], _kind(key))
        largest[group] = max(largest.get(group, 0.0), pk)
    return {k: (pk, largest[(k[0], _kind(k))]) for k, pk in peaks.items()
            if pk < fraction * largest[(k[0], _kind(k))]}


def curves_to_compare(measured: FrfTable, band_hz: tuple[float, float] = DEFAULT_BAND_HZ, keep_small: bool = False,
                      warn: bool = True) -> tuple[list, tuple]:
    """The measured curves the criterion uses, and those left out as too small (with a warning listing them)."""
    small = {} if keep_small else small_curves(measured, band_hz)
    if small and warn:
        listed = "; ".join(f"seat {a} -> {p} {d} (peak {pk:.3g}, {100 * pk / big:.0f} % of {big:.3g})"
                           for (a, p, d), (pk, big) in small.items())
        errors.warn(f"left out of the criterion: {len(small)} measured curve{'s' * (len(small) > 1)} whose peak "
                    f"is below {100 * SMALL_CURVE_FRACTION:.0f} % of the largest curve of the same kind for the "
                    f"same seat axis (noise, or paths near zero by symmetry): {listed}; keep them with "
                    "keep_small=True (--keep-small-curves).", EhmWarning, stacklevel=3)
    return [k for k in measured.keys() if k not in small], tuple(small)


@checked
def compare(measured: FrfTable, model: FrfTable, band_hz: tuple[float, float] = DEFAULT_BAND_HZ,
            keep_small: bool = False, warn: bool = True) -> Comparison:
    """Criterion of every measured curve against the model table, and their weighted mean.

    Curves too small to carry signal are left out unless ``keep_small`` (see the module docstring); ``warn``
    lists them in a warning.  Raises :class:`InputError` when the model lacks a measured curve or does not
    cover its frequencies.
    """
    keys, left_out = curves_to_compare(measured, band_hz, keep_small, warn)
    out = []
    for key in keys:
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
    return Comparison(curves=tuple(out), total=total, left_out=left_out)
