"""Resampling of a record onto a uniform time grid, anti-aliased (polyphase), a block at a time.

:class:`Resampler` is what :meth:`ehm.SeatMotion.resample`, the nonlinear and linear routes and the
readers' common time base use; ``ehm.inputs.motion.Resampler`` is the same class.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
from scipy import signal

from ..errors import InputError

__all__ = ["UNIFORM_TOLERANCE", "Resampler"]


#: A record counts as uniformly sampled when every sample time lies within this fraction of a step of the
#: uniform grid through its first and last samples (loggers' time stamps jitter; their samples do not).
UNIFORM_TOLERANCE = 0.1
#: Half-length of the polyphase filter, in samples of the slower rate, and its Kaiser window parameter:
#: within 0.001 dB up to 0.4 times the slower rate, at least 80 dB down from 0.6 times it.
_POLY_HALF_LENGTH = 20
#: Content below this fraction of the slower of two rates passes the resampler (within 0.001 dB): a record
#: resampled from a slower one holds nothing above it.
PASS_FRACTION = 0.4
_POLY_KAISER_BETA = 8.0
#: Largest denominator of the rational rate ratio (whole-number rates in Hz are exact).
_POLY_MAX_DENOMINATOR = 1000


class Resampler:
    """Samples of a record on the uniform grid ``t = k dt_s`` (from the record's start), a block at a time.

    Polyphase resampling (``scipy.signal.resample_poly`` with a Kaiser-windowed sinc of
    ``_POLY_HALF_LENGTH`` samples of the slower rate either side, edges extended with the edge values):
    an anti-alias filter when the record is faster than the grid, an interpolation filter when slower.
    The rate ratio is the nearest fraction with a denominator of at most 1000 (exact for whole-number rates
    in Hz; otherwise the time scale is off by less than 1e-6 of the duration, typically).  A block computed
    here equals the same samples of the whole record resampled at once: each block reads the record with
    a margin of the filter's length.

    A record whose time stamps depart from a uniform grid by more than :data:`UNIFORM_TOLERANCE` of a step
    (jitter, gaps, varying rates) is first interpolated linearly onto a uniform grid at its median step, with
    no anti-alias filter; :func:`ehm.read_motion` therefore refuses logs whose rate changes and
    refuses (or, asked, bridges) gaps, so that from files this step meets jitter and dropped samples only.

    Parameters
    ----------
    time_s : (n,) array
        Sample times [s], strictly increasing.
    values : (n, k) array, or a list of such arrays (kept apart, not copied into one)
        The samples; blocks hold their columns side by side.
    dt_s : float
        Interval of the grid [s].
    """

    def __init__(self, time_s, values, dt_s: float):
        t = np.asarray(time_s, dtype=float)
        xs = [np.asarray(v, dtype=float) for v in (values if isinstance(values, (list, tuple)) else [values])]
        xs = [x[:, None] if x.ndim == 1 else x for x in xs]
        self.dt_s = float(dt_s)
        duration = float(t[-1] - t[0])
        #: Number of grid samples within the record: t = 0, dt_s, ... up to its duration.
        self.n_samples = int(np.floor(duration / self.dt_s + 1e-9)) + 1
        step = duration / (t.size - 1)
        if _largest_departure(t, step) > UNIFORM_TOLERANCE * step:
            step = float(np.median(np.diff(t)))
            grid = np.arange(int(np.floor(duration / step + 1e-9)) + 1) * step
            xs = [np.column_stack([np.interp(grid, t - t[0], x[:, j]) for j in range(x.shape[1])]) for x in xs]
        self._xs = xs  # the record's arrays as given (not copied into one)
        ratio = Fraction(step / self.dt_s).limit_denominator(_POLY_MAX_DENOMINATOR)
        self.up, self.down = ratio.numerator, ratio.denominator
        if self.up == self.down == 1:
            self._h = None
            return
        if self.up < 1:
            raise InputError(f"resample: dt_s = {dt_s!r} s is too long for a record sampled every {step:g} s.")
        widest = max(self.up, self.down)
        self._h = signal.firwin(2 * _POLY_HALF_LENGTH * widest + 1, 1.0 / widest,
                                window=("kaiser", _POLY_KAISER_BETA))
        self._margin = _POLY_HALF_LENGTH * widest // self.up + 2  # record samples the filter reaches

    @classmethod
    def of_motion(cls, motion, dt_s: float) -> Resampler:
        """A resampler of a :class:`ehm.inputs.motion.SeatMotion`'s acceleration (columns 0-2) and angular velocity
        (3-5,
        when it has one)."""
        cols = [motion.acc_mps2] + ([motion.angvel_radps] if motion.angvel_radps is not None else [])
        return cls(motion.time_s, cols, dt_s)

    def block(self, start: int, stop: int) -> np.ndarray:
        """Grid samples ``start`` to ``stop - 1`` (``0 <= start < stop <= n_samples``), shape (stop - start, k)."""
        if self._h is None:
            return np.hstack([x[start:stop] for x in self._xs])
        up, down = self.up, self.down
        # first record sample used: a multiple of `down`, so that the block's output falls on the grid
        first = max(0, (start * down // up - self._margin) // down) * down
        last = min(self._xs[0].shape[0], (stop - 1) * down // up + self._margin + 2)
        seg = np.hstack([x[first:last] for x in self._xs])
        y = signal.resample_poly(seg, up, down, axis=0, window=self._h, padtype="edge")
        offset = first * up // down
        out = y[start - offset: stop - offset]
        if out.shape[0] < stop - start:  # the grid's last sample at the record's very end (round-off)
            out = np.vstack([out, np.repeat(y[-1:], stop - start - out.shape[0], axis=0)])
        return out


def _largest_departure(t: np.ndarray, step: float, block: int = 65536) -> float:
    """Largest |t[i] - t[0] - i step| [s], a block at a time (no temporary array as long as a long record)."""
    worst = 0.0
    for start in range(0, t.size, block):
        seg = t[start:start + block]
        worst = max(worst, float(np.max(np.abs(seg - t[0] - np.arange(start, start + seg.size) * step))))
    return worst
