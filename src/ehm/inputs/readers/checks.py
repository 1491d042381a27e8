"""Checks of the values read: finite numbers, increasing times, one sample rate, no gaps (or bridged ones), for
MDF channels with their own time stamps one common time base, and units that fit the values (a time step, an
acceleration and an angular velocity plausible in s, m/s^2 and rad/s)."""

from __future__ import annotations

import numpy as np

from ...errors import EhmWarning, InputError, warn
from ..resampling import Resampler
from .base import Source, column_words
from .channels import ACC_KEYS, ASSUMED, FILE, GIVEN, INFERRED, KEY_KINDS, NAME, RATE_KEYS, SI_UNITS
from .frames import FrameSource, ParquetSource
from .text import TextSource
from .units import MAX_STEP_S as _MAX_STEP_S
from .units import MIN_STEP_S as _MIN_STEP_S
from .units import unit_factor

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


def check_finite(src: Source, key: str, name: str, values: np.ndarray) -> None:
    """Refuse (InputError, naming the row and its time) a channel holding NaN or infinite values."""
    bad = np.flatnonzero(~np.isfinite(values))
    if not bad.size:
        return
    i = int(bad[0])
    where = column_words(src, name, key)
    if isinstance(src, TextSource):
        if src.row_field_count(i) != len(src.names):
            raise InputError(f"{src.label}, {src.where(i)}: expected {len(src.names)} fields {src.layout_words}, "
                             f"found {src.row_field_count(i)}.")
        if not src.field_text(name, i):
            raise InputError(f"{src.label}, {src.where(i)}, {where}: value is empty, expected a number.")
    elif np.isnan(values[i]) and isinstance(src, (ParquetSource, FrameSource)):
        raise InputError(f"{src.label}, {src.where(i)}, {where}: value is missing (NaN), expected a number.")
    raise InputError(f"{src.label}, {src.where(i)}, {where}: {src.raw(name, i)} is not a finite number (NaN or "
                     "infinite).")


#: A column whose filled cells hold only 0 and 1 while more than this share of its cells are empty is a flag
#: (an event marker, a button, a GPS fix), not a measured quantity: a logger's channel fills every row.
FLAG_EMPTY_SHARE = 0.5


def check_not_flag(src: Source, key: str, name: str, raw, values: np.ndarray) -> None:
    """Refuse, in one sentence naming the column, a boolean column (True/False) or a sparse 0/1 flag column
    (see :data:`FLAG_EMPTY_SHARE`) mapped to a channel of measured values."""
    import pandas as pd

    arr = np.asarray(raw)
    boolean = arr.dtype.kind == "b" or (arr.dtype.kind == "O" and arr.size and
                                         pd.api.types.infer_dtype(arr, skipna=True) == "boolean")
    if not boolean:
        filled = np.isfinite(values)
        if not values.size or filled.mean() >= 1.0 - FLAG_EMPTY_SHARE or not filled.any():
            return
        if not np.isin(values[filled], (0.0, 1.0)).all():
            return
    what = "True/False" if boolean else f"only 0 and 1 in {int(np.isfinite(values).sum())} of its {values.size} rows"
    raise InputError(f"{src.label}, {column_words(src, name, key)}: the column holds {what}, a flag, not "
                     f"{KEY_KINDS[key][0]}: map the channel to the column of its measured values "
                     f"(--channel {key}=NAME).")


def check_times(src: Source, name: str, t: np.ndarray) -> None:
    """Times strictly increasing, else one sentence with the rows and values (they may start below 0: the time
    axis is moved to start at 0)."""
    where = column_words(src, name, "time") if not isinstance(src, TextSource) else f"column {name}"
    text = (lambda i: src.field_text(name, i)) if isinstance(src, TextSource) else (lambda i: f"{t[i]:.9g}")
    bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise InputError(f"{src.label}, {src.where(i)}, {where}: time {text(i)} s is not after the time "
                         f"{text(i - 1)} s on {src.where(i - 1)}; times must be strictly increasing.")


def check_sampling(src: Source, name: str, t: np.ndarray, fill_gaps: bool, key: str = "time") -> None:
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


def _check_one_rate(src: Source, name: str, t: np.ndarray, steps: np.ndarray, median: float, key: str) -> None:
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
        f"{src.label}, {src.where(row)}, {column_words(src, name, key)}: the sample rate changes at t = "
        f"{t[row]:.6g} s from {1 / before:.6g} Hz to {1 / after:.6g} Hz; ehm resamples a log at one rate only: "
        "split the log at that row, or resample it to one rate (with an anti-alias filter) before reading it.")


def _gaps(src: Source, name: str, t: np.ndarray, gaps: np.ndarray, median: float, fill_gaps: bool,
          key: str) -> None:
    """Refuse the first gap in one sentence, or warn once (naming the first and counting the rest)."""
    i = int(gaps[0]) + 1
    length = float(t[i] - t[i - 1])
    where = (f"{src.label}, {src.where(i)}, {column_words(src, name, key)}: a gap of {length:.6g} s in the time "
             f"stamps, from t = {t[i - 1]:.6g} s to {t[i]:.6g} s ({length / median:.0f} median steps of {median:.6g} "
             "s)")
    if not fill_gaps:
        raise InputError(f"{where}; cut the log there, or give --fill-gaps (fill_gaps=True) to bridge "
                         f"{'it' if gaps.size == 1 else f'its {gaps.size} gaps'} with a straight line.")

    more = "" if gaps.size == 1 else f" (and {gaps.size - 1} more gaps, {float(np.sum(np.diff(t)[gaps])):.6g} s " \
        "in all)"
    warn(f"{where}{more} is bridged with a straight line (fill_gaps).", EhmWarning, stacklevel=4)


#: MDF channels are read over their common time span; it must cover at least this share of the span they
#: reach together.  Groups of one logger start and stop within moments of each other (a few samples cut); a
#: channel that covers much less of the drive than the others is another recording, and cutting every channel
#: to it would quietly drop most of the drive.
MIN_OVERLAP = 0.9


def _check_overlap(src: Source, use: dict, stamps: dict, start: float, stop: float, step: float) -> None:
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


def common_time(src: Source, use: dict, data: dict, stamps: dict, fill_gaps: bool = False):
    """MDF: one time base for channels that may come from groups with different time stamps."""
    keys = list(use)
    first = stamps[keys[0]]
    for key in keys:
        check_times(src, use[key], stamps[key])
        check_sampling(src, use[key], stamps[key], fill_gaps, key)
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


# --------------------------------------------------------------------------
# plausibility of the units: each channel's values, in ehm's units, against what a vehicle's log can hold
# --------------------------------------------------------------------------

#: The median time step [s] of a logger's recording lies between these: 100 kHz is above any logger of a
#: seat's motion, and a recording sampled below 2 Hz keeps under 0.8 Hz of the comfort band (0.5-80 Hz).
#: A log outside them is refused at any length: the time's unit is wrong.  The upper bound catches a log
#: stamped in ms read as seconds at every logger rate up to 2 kHz (steps of 0.5 ms and longer), and one
#: stamped in µs or ns (uptime, Unix time) at any rate.
MIN_STEP_S = _MIN_STEP_S
MAX_STEP_S = _MAX_STEP_S
#: A table written by hand (a step, a ramp: fewer than :data:`LOG_SAMPLES` rows) may step slowly, up to
#: :data:`TABLE_MAX_STEP_S`, but only where its time is said to be in seconds (``--unit time=s``, a name such
#: as ``time_s``, the file's unit): a time whose unit nobody gives is refused outside :data:`MIN_STEP_S` ..
#: :data:`MAX_STEP_S` at any length, as a short log stamped in ms (100 Hz: steps of "10 s") is no hand table; and
#: a table of :data:`LOG_SAMPLES` rows or more is a logger's whatever its name says (a 301-row ``time_s`` column
#: holding milliseconds ran as a 3000 s drive and wrote 509 MB).
LOG_SAMPLES = 100
TABLE_MAX_STEP_S = 10.0
#: A log sampled at :data:`FAST_STEP_S` or faster (10 kHz) that lasts less than :data:`MIN_FAST_DURATION_S` is
#: no logger's recording but a log in seconds read with a smaller unit (a 100 Hz log of 30 s read as ms: 100
#: kHz for 30 ms); a real 10 kHz or faster recording of a seat's motion lasts seconds at least.
FAST_STEP_S = 1e-4
MIN_FAST_DURATION_S = 1.0
#: An acceleration in g read as m/s^2: the median of its norm within this fraction of 1 while its steady part
#: (the norm of its mean) is at least :data:`G_STEADY_MIN` is gravity in g.  Consumer MEMS accelerometers read
#: gravity within about 4 % (sensitivity and offset: 2.5 % low and 3.9 % high in the logs of two phones and a
#: board tried), and a vehicle's own motion moves the median of the norm by well under 1 %; in m/s^2 gravity
#: is 9.81, and a log without gravity has a steady part near 0 (its velocity comes back), so a median of
#: 1 +- 0.05 m/s^2 with a steady 0.5 m/s^2 or more is nearly always a log in g.  Refused when the unit was
#: assumed (one flag, --unit ax=g ..., fixes it; a log really in m/s^2 says so with --unit ax=m/s^2 ...); a
#: warning when the name or the file gave m/s^2.
G_NORM_TOLERANCE = 0.05
G_STEADY_MIN = 0.5
#: The median norm of an acceleration above this [m/s^2] (5 g for half the log) is no vehicle's: a log in mg
#: (gravity alone reads 1000) or another unit.
MAX_ACC_MEDIAN_MPS2 = 50.0
#: Angular rates implausible in rad/s: a median norm above :data:`MAX_RATE_MEDIAN_RADPS` (115 deg/s for half
#: the log: no vehicle turns, rolls or pitches that long that fast; a car's median is about 0.1 rad/s) or a 99th
#: percentile above :data:`MAX_RATE_P99_RADPS` (2000 deg/s, the largest common MEMS gyro range: no gyro of a
#: vehicle log measures it).  A gyro in deg/s read as rad/s exceeds one or both (a car: median 6, 99th
#: percentile 37; an IMU moved by hand: 1 and 200).
MAX_RATE_MEDIAN_RADPS = 2.0
MAX_RATE_P99_RADPS = 35.0


def assumed_words(origin: str, unit: str) -> str:
    """How a channel's unit was found, in words: ``in deg/s, as its name says``."""
    return {ASSUMED: f"in {unit}, as no unit is given", NAME: f"in {unit}, as its name says",
            FILE: f"in {unit}, as the file says", INFERRED: f"in {unit}, as its name and whole-number steps suggest",
            GIVEN: f"in {unit}, as given"}[origin]


def check_time_unit(src: Source, name: str, t: np.ndarray, unit: str, origin: str, key: str = "time") -> None:
    """Refuse, in one sentence naming the unit taken and the ``--unit`` that would fix it, time stamps (``key``
    ``"time"``) or steps (``"dt"``) whose median step is outside :data:`MIN_STEP_S` .. :data:`MAX_STEP_S`
    (:data:`TABLE_MAX_STEP_S` for a short table said to be in seconds), or that step at 10 kHz or faster for
    less than :data:`MIN_FAST_DURATION_S` in all; whatever gave the unit (the caller's too)."""
    if t.size < 2:
        return
    step = float(np.median(np.diff(t)))
    duration = float(t[-1] - t[0])
    said = origin in (GIVEN, NAME, FILE) and unit != "date-time"
    longest = TABLE_MAX_STEP_S if said and t.size < LOG_SAMPLES else MAX_STEP_S
    too_fast = step <= FAST_STEP_S and duration < MIN_FAST_DURATION_S
    if MIN_STEP_S <= step <= longest and not too_fast:
        return
    seconds = step / unit_factor(unit, key, src.label, name) if unit != "date-time" else step
    fits = {u: seconds * f for u, f in (("s", 1.0), ("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9))
            if MIN_STEP_S <= seconds * f <= MAX_STEP_S and u != unit}
    fix = min(fits, key=lambda u: abs(np.log(fits[u] / 0.01))) if fits else None  # nearest to a 100 Hz logger
    column = "dt column" if key == "dt" else "time column"
    what = "the time stamps" if unit == "date-time" else f"the {column} is {assumed_words(origin, unit)}"
    finding = f"the median time step is {step:.3g} s" + (
        f" and the log lasts {duration:.3g} s ({1 / step:.6g} Hz for {duration * 1e3:.3g} ms)" if too_fast else "")
    if fix and unit != "date-time":
        hint = (f"give its unit, e.g. --unit {key}={fix} (units={{{key!r}: {fix!r}}}), which makes it "
                f"{fits[fix]:.3g} s")
        if step > MAX_STEP_S and not said and step <= TABLE_MAX_STEP_S and t.size < LOG_SAMPLES:
            hint += f", or --unit {key}=s for a table written by hand in seconds"
    elif too_fast and step >= MIN_STEP_S:
        hint = (f"a log at {1e-3 / FAST_STEP_S:g} kHz or faster must last at least {MIN_FAST_DURATION_S:g} s (a "
                "shorter one is most often a log in seconds read in a smaller unit): give a longer stretch of the "
                "log, or resample it below that rate")
    else:
        hint = (f"ehm reads logs sampled between {1 / MAX_STEP_S:g} Hz and {1e-3 / MIN_STEP_S:g} kHz: resample it, or "
                "give the time's unit")
    raise InputError(f"{src.label}, {column_words(src, name, key)}: {finding} if {what}; {hint}.")


def check_plausible(src: Source, use: dict, data: dict, origins: dict, acc: bool = True) -> None:
    """Refuse (unit assumed) or warn (unit from the name or the file) about accelerations and angular rates that
    are implausible in m/s^2 and rad/s; channels whose unit the caller gave are checked by
    :func:`_check_given_units`. ``acc=False``: the accelerations are left to the caller (an IMU log's specific
    force is checked against gravity by :func:`ehm.from_imu`)."""
    if min((v.size for k, v in data.items() if k != "time"), default=0) < 2:
        return  # too short to judge (and refused as such)
    _check_given_units(src, use, data, origins)
    acc = [k for k in ACC_KEYS if acc and k in data and origins[k] != GIVEN]
    if acc:
        norm = np.linalg.norm(np.column_stack([data[k] for k in acc]), axis=1)
        median = float(np.median(norm))
        steady = float(np.linalg.norm([np.mean(data[k]) for k in acc]))
        if abs(median - 1.0) <= G_NORM_TOLERANCE and steady >= G_STEADY_MIN:
            _implausible(src, use, origins, acc, "g", f"the norm of the acceleration has a median of {median:.3g} "
                         f"and a steady part of {steady:.3g}: gravity in g")
        elif median > MAX_ACC_MEDIAN_MPS2:
            _implausible(src, use, origins, acc, "mg", f"the norm of the acceleration has a median of {median:.4g} "
                         "m/s^2, over 5 g for half the log")
    rates = [k for k in RATE_KEYS if k in data and origins[k] != GIVEN]
    if rates:
        norm = np.linalg.norm(np.column_stack([data[k] for k in rates]), axis=1)
        median, p99 = float(np.median(norm)), float(np.percentile(norm, 99))
        if median > MAX_RATE_MEDIAN_RADPS or p99 > MAX_RATE_P99_RADPS:
            _implausible(src, use, origins, rates, "deg/s", f"the norm of the angular velocity has a median of "
                         f"{median:.3g} rad/s and a 99th percentile of {p99:.3g} rad/s, beyond a vehicle's (and "
                         f"above {MAX_RATE_P99_RADPS:g} rad/s, 2000 deg/s, no common gyro measures)" if
                         p99 > MAX_RATE_P99_RADPS else f"the norm of the angular velocity has a median of "
                         f"{median:.3g} rad/s ({np.degrees(median):.0f} deg/s), beyond a vehicle's")


def _check_given_units(src: Source, use: dict, data: dict, origins: dict) -> None:
    """Refuse a channel whose unit the caller gave when the converted values are beyond any vehicle's: a median
    acceleration over 5 g for half the log, or an angular rate over 2000 deg/s (a unit given for data that is
    already in SI, say ``--unit ax=g`` on m/s^2)."""
    for key in [k for k in (*ACC_KEYS, *RATE_KEYS) if k in data and origins.get(k) == GIVEN]:
        values = np.abs(data[key])
        acc = key in ACC_KEYS
        level = float(np.median(values)) if acc else float(np.percentile(values, 99))
        if level <= (MAX_ACC_MEDIAN_MPS2 if acc else MAX_RATE_P99_RADPS):
            continue
        si = SI_UNITS[key]
        what = (f"its median is {level:.4g} m/s^2 ({level / 9.80665:.3g} g), over 5 g for half the log" if acc else
                f"its 99th percentile is {level:.4g} rad/s, beyond the 2000 deg/s of any common gyro")
        raise InputError(f"{src.label}, column {use[key]!r} (channel {key}): read in the unit given for it, {what}; "
                         f"check that unit (is the column already in {si}? then give --unit {key}={si} or leave "
                         f"the unit out).")


def _implausible(src: Source, use: dict, origins: dict, keys: list, fix: str, finding: str) -> None:
    """One sentence: what the values are in the unit taken, and the ``--unit`` that fixes it; refused when a
    channel's unit was assumed, a warning when the name or the file gave it."""
    kinds = {origins[k] for k in keys}
    si = SI_UNITS[keys[0]]
    channels = ", ".join(f"{k} ({use[k]!r})" for k in keys)
    how = "as no unit is given" if ASSUMED in kinds else \
        "as their names say" if kinds == {NAME} else "as the file says" if kinds == {FILE} else \
        "as the file and their names say"
    flags = " ".join(f"--unit {k}={fix}" for k in keys)
    argument = "{" + ", ".join(f"{k!r}: {fix!r}" for k in keys) + "}"
    sentence = (f"{src.label}: if {channels} {'is' if len(keys) == 1 else 'are'} in {si}, {how}, {finding}; give "
                f"the unit, e.g. {flags} (units={argument}), or {si} if that is what it is")
    if ASSUMED in kinds:
        raise InputError(sentence + ".")

    warn(sentence + " (read as it is).", EhmWarning, stacklevel=5)
