"""``ComfortAccumulator``: the evaluation values of a record fed block by block, in constant memory."""

from __future__ import annotations

import numpy as np

from ...errors import InputError
from .checks import positive_float, signal_1d
from .values import ComfortMetrics
from .weighting import WeightingFilter


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
        self.fs = positive_float(fs_hz, "fs_hz")
        self._w = WeightingFilter(weighting, self.fs)
        self._wf = WeightingFilter("Wf", self.fs)
        self._n_tau = int(round(positive_float(tau_s, "tau_s") * self.fs))
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
        x = signal_1d(block, "block")
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
