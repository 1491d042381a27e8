"""Checks of the values read: finite numbers, increasing times, one sample rate, no gaps (or bridged ones), and for
MDF channels with their own time stamps one common time base."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..resampling import Resampler
from .base import _column_words, _Source
from .frames import _FrameSource, _ParquetSource
from .text import _TextSource

#: A step between time stamps longer than this many median steps is a gap (a logger's dropout), refused unless
#: ``fill_gaps``.  Loggers miss a sample or two now and then (a 100 Hz IMU log: steps of up to 3 median steps; a
#: phone's: up to 1.6), which a straight line bridges with little loss; a longer dropout is data that is not
#: there, and a straight line over it is a quiet seat that was never measured.
GAP_STEPS = 5
#: A stretch of the log whose local median step (over :data:`RATE_WINDOW` steps) differs from the whole log's
#: median step by this factor or more is at another sample rate.  Jitter leaves the local median within a
#: fraction of a per cent of the median (phone and IMU logs: 0.2 %); a rate change moves it by the ratio of
#: the rates.
RATE_CHANGE_RATIO = 2.0
#: Steps over which the local median step is taken: long enough that jitter and a dropped sample or two do not
#: move it, short against any stretch worth naming (a quarter second at 100 Hz).
RATE_WINDOW = 25


def _check_finite(src: _Source, key: str, name: str, values: np.ndarray) -> None:
    bad = np.flatnonzero(~np.isfinite(values))
    if not bad.size:
        return
    i = int(bad[0])
    where = _column_words(src, name, key)
    if isinstance(src, _TextSource):
        if src.row_field_count(i) != len(src.names):
            raise InputError(f"{src.label}, {src.where(i)}: expected {len(src.names)} fields {src.layout_words}, "
                             f"found {src.row_field_count(i)}.")
        if not src.field_text(name, i):
            raise InputError(f"{src.label}, {src.where(i)}, {where}: value is empty, expected a number.")
    elif np.isnan(values[i]) and isinstance(src, (_ParquetSource, _FrameSource)):
        raise InputError(f"{src.label}, {src.where(i)}, {where}: value is missing (NaN), expected a number.")
    raise InputError(f"{src.label}, {src.where(i)}, {where}: {src.raw(name, i)} is not a finite number (NaN or "
                     "infinite).")


def _check_times(src: _Source, name: str, t: np.ndarray) -> None:
    """Times >= 0 and strictly increasing, else one sentence with the rows and values."""
    where = _column_words(src, name, "time") if not isinstance(src, _TextSource) else f"column {name}"
    text = (lambda i: src.field_text(name, i)) if isinstance(src, _TextSource) else (lambda i: f"{t[i]:.9g}")
    if t.size and t[0] < 0:
        raise InputError(f"{src.label}, {src.where(0)}, {where}: time {text(0)} s is negative; times must be >= 0.")
    bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise InputError(f"{src.label}, {src.where(i)}, {where}: time {text(i)} s is not after the time "
                         f"{text(i - 1)} s on {src.where(i - 1)}; times must be strictly increasing.")


def _check_sampling(src: _Source, name: str, t: np.ndarray, fill_gaps: bool, key: str = "time") -> None:
    """One sample rate and no gaps, else one sentence naming where: a change of rate (the resampler would take
    the whole log at one rate, unfiltered) is refused; a gap (a step over :data:`GAP_STEPS` median steps) is
    refused, or bridged with a warning when ``fill_gaps``."""
    if t.size < 3:
        return
    steps = np.diff(t)
    median = float(np.median(steps))
    if steps.min() < median / RATE_CHANGE_RATIO or steps.max() > median * RATE_CHANGE_RATIO:
        _check_one_rate(src, name, t, steps, median, key)
    gaps = np.flatnonzero(steps > GAP_STEPS * median * (1 + 1e-6))  # (time stamps' round-off is no gap)
    if gaps.size:
        _gaps(src, name, t, gaps, median, fill_gaps, key)


def _check_one_rate(src: _Source, name: str, t: np.ndarray, steps: np.ndarray, median: float, key: str) -> None:
    """Refuse a log whose local median step leaves the median by :data:`RATE_CHANGE_RATIO` or more."""
    import pandas as pd

    local = pd.Series(steps).rolling(RATE_WINDOW, center=True, min_periods=1).median().to_numpy()
    other = (local <= median / RATE_CHANGE_RATIO) | (local >= median * RATE_CHANGE_RATIO)
    if not other.any() or other.all():
        return
    j = int(np.flatnonzero(other != other[0])[0])  # the first step of the second stretch, within the window
    lo, hi = max(0, j - RATE_WINDOW), min(steps.size, j + RATE_WINDOW)
    before, after = float(np.median(steps[lo:j])), float(np.median(steps[j:hi]))
    # the row where the second rate starts: the first step nearer (in ratio) to the second stretch's step
    near = np.abs(np.log(steps[lo:hi] / after)) < np.abs(np.log(steps[lo:hi] / before))
    row = lo + int(np.argmax(near))
    raise InputError(
        f"{src.label}, {src.where(row)}, {_column_words(src, name, key)}: the sample rate changes at t = "
        f"{t[row]:.6g} s from {1 / before:.6g} Hz to {1 / after:.6g} Hz; ehm resamples a log at one rate only: "
        "split the log at that row, or resample it to one rate (with an anti-alias filter) before reading it.")


def _gaps(src: _Source, name: str, t: np.ndarray, gaps: np.ndarray, median: float, fill_gaps: bool,
          key: str) -> None:
    """Refuse the first gap in one sentence, or warn once (naming the first and counting the rest)."""
    i = int(gaps[0]) + 1
    length = float(t[i] - t[i - 1])
    where = (f"{src.label}, {src.where(i)}, {_column_words(src, name, key)}: a gap of {length:.6g} s in the time "
             f"stamps, from t = {t[i - 1]:.6g} s to {t[i]:.6g} s ({length / median:.0f} median steps of {median:.6g} "
             "s)")
    if not fill_gaps:
        raise InputError(f"{where}; cut the log there, or give --fill-gaps (fill_gaps=True) to bridge "
                         f"{'it' if gaps.size == 1 else f'its {gaps.size} gaps'} with a straight line.")
    import warnings

    more = "" if gaps.size == 1 else f" (and {gaps.size - 1} more gaps, {float(np.sum(np.diff(t)[gaps])):.6g} s " \
        "in all)"
    warnings.warn(f"{where}{more} is bridged with a straight line (fill_gaps).", stacklevel=4)


#: MDF channels are read over their common time span; it must cover at least this share of the span they
#: reach together.  Groups of one logger start and stop within moments of each other (a few samples cut); a
#: channel that covers much less of the drive than the others is another recording, and cutting every channel
#: to it would quietly drop most of the drive.
MIN_OVERLAP = 0.9


def _check_overlap(src: _Source, use: dict, stamps: dict, start: float, stop: float, step: float) -> None:
    """Refuse MDF channels whose common span is less than :data:`MIN_OVERLAP` of their joint span."""
    first = min(float(stamps[k][0]) for k in use)
    last = max(float(stamps[k][-1]) for k in use)
    common = max(0.0, stop - start)
    if common >= step and common >= MIN_OVERLAP * (last - first):
        return
    spans = ", ".join(f"{k} ({use[k]!r}) {stamps[k][0]:.6g}-{stamps[k][-1]:.6g} s" for k in use)
    what = "do not overlap" if common < step else \
        f"overlap for {common:.6g} s of the {last - first:.6g} s they span ({100 * common / (last - first):.0f} %)"
    raise InputError(f"{src.label}: the channels' time stamps {what}: {spans}; ehm reads channels over their "
                     f"common span only, which must cover {100 * MIN_OVERLAP:.0f} % of theirs: pick channels "
                     "recorded together, or cut the log to the common span first (asammdf's MDF.cut).")


def _common_time(src: _Source, use: dict, data: dict, stamps: dict, fill_gaps: bool = False):
    """MDF: one time base for channels that may come from groups with different time stamps."""
    keys = list(use)
    first = stamps[keys[0]]
    for key in keys:
        _check_times(src, use[key], stamps[key])
        _check_sampling(src, use[key], stamps[key], fill_gaps, key)
    if all(stamps[k] is first or (stamps[k].shape == first.shape and np.array_equal(stamps[k], first))
           for k in keys):
        return first, data
    start = max(float(stamps[k][0]) for k in keys)
    stop = min(float(stamps[k][-1]) for k in keys)
    step = min(float(np.median(np.diff(stamps[k]))) for k in keys)
    _check_overlap(src, use, stamps, start, stop, step)
    out = {}
    n = int(np.floor((stop - start) / step + 1e-9)) + 1
    for k in keys:
        t = stamps[k]
        i0 = max(0, int(np.searchsorted(t, start, side="right")) - 1)
        r = Resampler(t[i0:] - t[i0], data[k][i0:], step)
        offset = int(round((start - t[i0]) / step))
        out[k] = r.block(offset, min(offset + n, r.n_samples))[:, 0]
    n = min(v.size for v in out.values())
    return start + np.arange(n) * step, {k: v[:n] for k, v in out.items()}
