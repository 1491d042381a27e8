"""ISO 2631-1 evaluation values of a whole record: weighted rms, MTVV, VDV, crest factor, MSDV (``metrics``),
the vibration total value, the comfort reactions of Annex C and the SEAT value."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import signal as _sig

from ...errors import InputError
from .checks import non_negative_float, positive_float, signal_1d
from .weighting import canonical_name, start_level, steady_state, weight, weighting_sos

_PURPOSES = ("comfort", "health")


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
    Everything is evaluated over the whole record; the weighting filters start in the steady state
    for the record's start level (see :func:`ehm.standards.comfort.weight`), so a record that starts at a non-zero level
    has no start-up transient.  Integrals are sums times ``1/fs_hz``.  The running rms is the linear (rectangular)
    integration of ISO 2631-1 6.3.1,
    ``a_w(t0) = sqrt(1/tau * integral_{t0-tau}^{t0} a_w(t)^2 dt)``, evaluated at every sample with
    the signal taken as zero before the record starts (the window holds ``round(tau_s * fs_hz)``
    samples); the exponential-averaging alternative of 6.3.1 is not used.  MTVV is its maximum.
    """
    x = signal_1d(signal, "signal")
    fs = positive_float(fs_hz, "fs_hz")
    tau = positive_float(tau_s, "tau_s")
    if weighting is None:
        aw = x
        msdv = None
    else:
        key = canonical_name(weighting, "weighting")
        sos, sos_f = weighting_sos(key, fs), weighting_sos("Wf", fs)
        level = start_level(x, fs)
        aw = _sig.sosfilt(sos, x, zi=steady_state(sos, level))[0]
        awf = aw if key == "Wf" else _sig.sosfilt(sos_f, x, zi=steady_state(sos_f, level))[0]
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
    axes = [signal_1d(a, n) for a, n in ((ax, "ax"), (ay, "ay"), (az, "az"))]
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
    a = non_negative_float(a_w, "a_w", "acceleration in m/s^2")
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
    body = non_negative_float(a_w_body, "a_w_body")
    seat = positive_float(a_w_seat, "a_w_seat")
    return 100.0 * body / seat
