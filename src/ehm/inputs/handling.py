"""Handled loggers: the stretches at the start and end of a log where the logger is held in a hand, not carried by
the vehicle, found so that they can be left out of the figures.

A phone or a logger is picked up, switched on and put in place before a drive and taken away after it; its log
then starts and ends with seconds of a hand's motion (the acceleration norm of a phone put down reaches 2 g).  A
vehicle cannot do what a hand does:

* **its orientation against gravity**: a vehicle floor tilts by a few degrees (a road's grade, 10 % at most on
  public roads, is 5.7 deg; a bus kneeling or a tram on a cant a few degrees more), and a vehicle's own horizontal
  acceleration (below about 0.5 g sustained: braking, cornering) turns the specific force the sensor reads but
  does not shorten its component along the drive's gravity.  A logger turned by theta in a hand shortens that
  component by the factor cos(theta).  So a stretch is *turned* where the specific force, low-passed (the moving
  median over :data:`LOWPASS_S` of its means over :data:`BLOCK_S`, which a knock of a tenth of a second does not
  move), has a component along the drive's gravity direction (the median direction of the middle
  60 % of the log) that departs by more than :data:`ALONG_TOLERANCE` (3 %, a turn of 14 deg; a 10 % grade gives
  0.5 %) from the drive's, for :data:`SUSTAIN_S` or longer without a break (a bump's vertical acceleration, low-passed
  over a second, is a few hundredths of g and brief; on four real bus and tram logs the longest such run in the
  middle of a drive was 0.8 s, and at their starts 0.44 s, the first samples of a board's ADC);
* **its accelerations**: a vehicle's high-passed acceleration norm (the log minus its low-passed self) stays below
  a few m/s^2; a hand putting a phone down gives 13-20 m/s^2.  A *spike* is a norm above :data:`SPIKE_FACTOR` times
  the drive's 99.9th percentile and at least :data:`SPIKE_MIN_MPS2` (0.5 g).

A handled start is the leading stretch up to the end of the last of a chain of turned runs, the first beginning
within :data:`SETTLE_S` of the log's first sample and each within :data:`SETTLE_S` of the one before, in the first
:data:`MAX_SHARE` (20 %) of the log, extended over the spikes that follow it within :data:`SETTLE_S` (the logger
being put down after it is turned into place), plus :data:`MARGIN_S`; a handled end likewise from the back.  A
cut never reaches beyond the first or last :data:`MAX_SHARE` of the log, and never happens without a turned run:
a pothole (a spike with no turn) is never cut, wherever it lies, and nothing in the middle of a drive is cut.

Only a seat or floor log with gravity in it shows its orientation (a log without gravity, an earth-axis log or an
IMU log, whose own route follows the sensor's attitude with its gyro, is not looked at), and only one of
:data:`MIN_DURATION_S` or longer (the middle it is compared with must be a drive).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError

#: The low-pass of the specific force whose direction is the logger's orientation: a moving mean over this [s].
LOWPASS_S = 1.0
#: The orientation is the moving median over LOWPASS_S of block means of this [s].
BLOCK_S = 0.1
#: A turned stretch: the low-passed component along the drive's gravity departs from the drive's by more than
#: this share (3 %: a turn of 14 deg, cos 14 deg = 0.970; a road's 10 % grade, 5.7 deg, gives 0.5 %) ...
ALONG_TOLERANCE = 0.03
#: ... without a break for at least this long [s].
SUSTAIN_S = 1.0
#: A spike: a high-passed acceleration norm above this multiple of the drive's 99.9th percentile ...
SPIKE_FACTOR = 3.0
#: ... and above this [m/s^2] (half a g: a vehicle's sustained accelerations stay below it).
SPIKE_MIN_MPS2 = 0.5 * 9.80665
#: Spikes within this time [s] after a turned stretch (before it, at the end) belong to the handling.
SETTLE_S = 5.0
#: Left out beyond the last turned or spiking sample [s] (the low-pass's half width and the logger settling).
MARGIN_S = 1.0
#: A cut reaches at most this share of the log at either end.
MAX_SHARE = 0.2
#: Logs shorter than this [s] are not looked at.
MIN_DURATION_S = 20.0
#: The drive's gravity: the median low-passed specific force of the middle of the log must have a norm within
#: this share of g (else the log holds no gravity to see the orientation by).
G_SHARE = 0.1

HANDLING_MODES = ("cut", "keep")  #: read_motion's ``handling``


@dataclass(frozen=True)
class HandledStretch:
    """A stretch at the start or end of a log where the logger was handled, left out of the motion.

    ``start_s``, ``end_s``: seconds from the log's first sample (before any cut, counting a ``start_s`` given);
    ``where``: ``"start"`` or ``"end"``; ``turn_deg``: the largest turn of the logger against the drive's gravity
    in it; ``turned_s``: how long it was turned (the longest turned run); ``peak_mps2``: its largest high-passed
    acceleration norm; ``drive_peak_mps2``: the drive's 99.9th percentile of it."""

    where: str
    start_s: float
    end_s: float
    turn_deg: float
    turned_s: float
    peak_mps2: float
    drive_peak_mps2: float

    def as_dict(self) -> dict:
        return {"where": self.where, "start_s": round(self.start_s, 3), "end_s": round(self.end_s, 3),
                "turn_deg": round(self.turn_deg, 1), "turned_s": round(self.turned_s, 2),
                "peak_mps2": round(self.peak_mps2, 2), "drive_peak_mps2": round(self.drive_peak_mps2, 2)}

    def words(self) -> str:
        return (f"{self.where} {self.start_s:.1f}-{self.end_s:.1f} s (turned by up to {self.turn_deg:.0f} deg against "
                f"gravity for {self.turned_s:.1f} s, accelerations up to {self.peak_mps2:.3g} m/s^2 where the drive's "
                f"reach {self.drive_peak_mps2:.2g})")


def check_handling(handling) -> str:
    """``handling`` checked: "cut" (default) or "keep"."""
    if not isinstance(handling, str) or handling not in HANDLING_MODES:
        got = repr(handling[:40]) if isinstance(handling, str) else f"a value of type {type(handling).__name__}"
        raise InputError(f"handling must be 'cut' (leave a handled start and end out, the default) or 'keep' "
                         f"(--keep-handling); got {got}.")
    return handling


def _runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(first, one past the last) index of each run of True."""
    d = np.diff(np.concatenate(([0], mask.astype(np.int8), [0])))
    return np.flatnonzero(d == 1), np.flatnonzero(d == -1)


def find_handling(time_s: np.ndarray, acc_mps2: np.ndarray, g_mps2: float = 9.80665,
                  offset_s: float = 0.0) -> tuple[int, int, tuple[HandledStretch, ...]]:
    """(first row kept, one past the last row kept, the handled stretches) of a log with gravity in it, in the
    sensor's axes (see the module docstring); ``offset_s`` is added to the times the stretches give (a cut made
    before).  A log without handling gives ``(0, n, ())``."""
    t = np.asarray(time_s, dtype=float)
    a = np.asarray(acc_mps2, dtype=float)
    n = t.size
    if n < 4 or float(t[-1] - t[0]) < MIN_DURATION_S:
        return 0, n, ()
    from scipy.ndimage import median_filter, uniform_filter1d

    dt = float(np.median(np.diff(t)))
    lp = uniform_filter1d(a, max(1, int(round(LOWPASS_S / dt))), axis=0, mode="nearest")  # for the spikes
    # the orientation: block means of BLOCK_S, then their moving median over LOWPASS_S (a knock's tenth of a second
    # does not move it, as it would move a moving mean)
    k = max(1, int(round(BLOCK_S / dt)))
    nb = n // k
    blocks = a[:nb * k].reshape(nb, k, 3).mean(axis=1)
    tb = t[:nb * k:k]
    mb = max(1, int(round(LOWPASS_S / (k * dt)))) | 1
    orient = median_filter(blocks, size=(mb, 1), mode="nearest")
    t0, duration = float(t[0]), float(t[-1] - t[0])
    rel, relb = t - t0, tb - t0
    mid = (rel >= MAX_SHARE * duration) & (rel <= (1 - MAX_SHARE) * duration)
    midb = (relb >= MAX_SHARE * duration) & (relb <= (1 - MAX_SHARE) * duration)
    ref = np.median(orient[midb], axis=0)
    g = float(np.linalg.norm(ref))
    if not math.isfinite(g) or abs(g - g_mps2) > G_SHARE * g_mps2:
        return 0, n, ()  # no gravity to see the orientation by
    along = orient @ (ref / g)
    along_drive = float(np.median(along[midb]))
    turned = np.abs(along / along_drive - 1.0) > ALONG_TOLERANCE
    cos = np.clip(along / np.maximum(np.linalg.norm(orient, axis=1), 1e-12), -1.0, 1.0)
    turn_deg = np.degrees(np.arccos(cos))
    hp = np.linalg.norm(a - lp, axis=1)
    drive_peak = float(np.percentile(hp[mid], 99.9))
    spikes = hp > max(SPIKE_FACTOR * drive_peak, SPIKE_MIN_MPS2)
    fb, lb = _runs(turned)
    long = (lb - fb) * k * dt >= SUSTAIN_S - 0.5 * dt
    fb, lb = fb[long], lb[long]
    # the runs in rows of the log: the first row of the first block, one past the last row of the last block
    first, last = fb * k, np.minimum(lb * k, n)
    turn_rows = np.repeat(turn_deg, k)
    turn_rows = np.concatenate((turn_rows, np.full(n - turn_rows.size, turn_deg[-1] if nb else 0.0)))
    limit = MAX_SHARE * duration
    i0, i1, out = 0, n, []
    head = _chained(t, first, last, forward=True, limit=limit)
    if head.size:
        end = int(last[head][-1]) - 1  # the last turned row of the last run of the chain
        after = np.flatnonzero(spikes[end:] & (t[end:] <= t[end] + SETTLE_S))
        end_t = min(float(t[end + after[-1]] if after.size else t[end]) + MARGIN_S, t0 + limit)
        i0 = int(np.searchsorted(t, end_t, side="left"))
        out.append(_stretch("start", t, slice(0, i0), turn_rows, first[head], last[head], hp, drive_peak, offset_s, t0))
    tail = _chained(t, first, last, forward=False, limit=limit)
    if tail.size:
        begin = int(first[tail][0])  # the first turned row of the first run of the chain
        before = np.flatnonzero(spikes[:begin + 1] & (t[:begin + 1] >= t[begin] - SETTLE_S))
        begin_t = max(float(t[before[0]] if before.size else t[begin]) - MARGIN_S, t0 + duration - limit)
        i1 = int(np.searchsorted(t, begin_t, side="right"))
        out.append(_stretch("end", t, slice(i1, n), turn_rows, first[tail], last[tail], hp, drive_peak, offset_s, t0))
    if i1 - i0 < 2:  # (cannot happen with MAX_SHARE < 0.5; kept as a guard)
        return 0, n, ()
    return i0, i1, tuple(out)


def _chained(t: np.ndarray, first: np.ndarray, last: np.ndarray, forward: bool, limit: float) -> np.ndarray:
    """Indices (in time order) of the turned runs that lead from the log's start (``forward``) or end, each within
    :data:`SETTLE_S` of the log's edge or of the run before it, and reaching into the first (last) ``limit`` seconds:
    a turned run in the middle of a drive, with the drive between it and the edge, is not a handled start or end."""
    order = range(first.size) if forward else range(first.size - 1, -1, -1)
    edge = float(t[0]) if forward else float(t[-1])
    chain = []
    for i in order:
        near, far = (float(t[first[i]]), float(t[last[i] - 1])) if forward else (float(t[last[i] - 1]),
                                                                                float(t[first[i]]))
        if abs(near - edge) > SETTLE_S or abs(near - (float(t[0]) if forward else float(t[-1]))) >= limit:
            break
        chain.append(i)
        edge = far
    return np.array(sorted(chain), dtype=int)


def _stretch(where: str, t: np.ndarray, rows: slice, turn_deg: np.ndarray, firsts, lasts, hp: np.ndarray,
             drive_peak: float, offset_s: float, t0: float) -> HandledStretch:
    start = rows.start if rows.start is not None else 0
    stop = rows.stop if rows.stop is not None else t.size
    # the stretch in seconds from the first sample: the start's to the first kept sample, the end's from the last
    # kept sample to the log's end
    s = float(t[0] if where == "start" else t[start - 1]) - t0 + offset_s
    e = float(t[stop] if where == "start" and stop < t.size else t[stop - 1]) - t0 + offset_s
    turned = float(max(t[min(b, t.size) - 1] - t[a] for a, b in zip(firsts, lasts)))
    return HandledStretch(where, s, e, float(np.max(turn_deg[start:stop])), turned, float(np.max(hp[start:stop])),
                          drive_peak)


def handling_note(label: str, stretches) -> str:
    """The one warning of a cut."""
    parts = " and ".join(s.words() for s in stretches)
    return (f"{label}: the logger was handled, not carried by the vehicle, at the {parts}: a vehicle floor tilts by a "
            "few degrees and a vehicle's own accelerations stay below about half a g, so these seconds are a hand's "
            "and are left out of the figures; to keep them give --keep-handling (handling='keep'), to cut elsewhere "
            "--start/--end (start_s=, end_s=).")
