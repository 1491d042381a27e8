"""Log layouts read with options instead of scripts: signs, a cut, held samples, irregular time stamps, the sensor's
mounting and a gyro logged in a file of its own.

* ``--channel KEY=-NAME`` (``channels={"ax": "-NAME"}``): the column NAME with its sign flipped (a source whose
  own channel is called ``-NAME`` keeps it as it is).
* ``--start S`` / ``--end S`` (``start_s``, ``end_s``): the log cut to S..E seconds from its first sample, before
  any check of its values, so that a phone being put in place can be cut away.
* Held samples (:data:`HELD_SHARE`, :data:`HELD_RUN_MAX`): a sensor slower than the rate its log is written at
  repeats each sample; the repeats are dropped, with a note giving the sensor's own rate.
* Irregular time stamps (departing from a uniform grid by more than :data:`ehm.inputs.resampling.UNIFORM_TOLERANCE` of a
  step, with no gap): resampled onto a uniform grid at the median step, with a note giving the spread of steps.
* ``--mounting ROLL,PITCH,YAW`` (``mounting``, as :func:`ehm.from_imu` takes it): sensor axes turned into
  seat axes, accelerations and angular velocities alike.
* ``--gyro FILE`` (``gyro``): angular velocities from another file with its own time stamps, joined onto the
  accelerometer's time stamps over their common span (at least :data:`ehm.inputs.readers.MIN_OVERLAP` of it).
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import EhmWarning, InputError, describe, warn
from ..imu import mounting_matrix, mounting_rotation  # noqa: F401 - mounting_rotation: ehm.inputs.readers'
from ..resampling import UNIFORM_TOLERANCE
from .checks import GAP_STEPS, MIN_OVERLAP

#: Held samples: a log in which more than this share of the rows repeat their predecessor exactly, in every
#: acceleration channel (a gyro file: every angular-velocity channel), and ...
#: A MEMS sensor's noise changes its last digit from one sample to the next, so in a log of measured samples three
#: channels all repeat together seldom; a sensor of about 51 Hz written at 200 Hz repeats 3 of 4 rows (75 %), one
#: of 100 Hz written at 200 Hz every second row (50 %).  Below 30 % (a sensor at more than 0.7 of the written
#: rate) the repeats are left as they are: most rows are then samples.
HELD_SHARE = 0.3
#: ... whose runs of identical rows are, at the median, 2 to this many rows long, is a held sensor.  A still,
#: coarse signal (a synthetic step, a file padded with zeros, a seat that only rotates) repeats rows in a few long
#: runs, and its median run is one row or very long; a held sensor's runs are all about the ratio of the rates.
HELD_RUN_MAX = 16
#: ... whose runs are regular (their standard deviation at most this share of their mean: a sensor's samples come
#: at its own period, so the runs are all the ratio of the rates rounded down or up, a phone's 51 Hz sensor
#: written at 200 Hz: 0.09; 80 Hz at 200 Hz, runs of 2 and 3: 0.2) ...
HELD_RUN_SPREAD = 0.35
#: ... and whose new samples change the moving channels together (at least this share of the rows that are no
#: repeat change every channel that changes at 10 % of them or more; a new reading of a noisy sensor changes
#: every axis: 0.6 to 1 in held logs).  A smooth log quantised coarsely (2 decimals) repeats rows too, but each
#: channel steps on its own, at irregular places: runs spread 0.6-0.7, channels together 0-0.02.
HELD_TOGETHER = 0.25


def signed_channels(channels: dict, has) -> tuple[dict, dict]:
    """``channels`` with each ``-NAME`` turned into NAME, and key -> -1.0 for those; ``has(key, name)``: whether
    the key's source has a channel called exactly ``name`` (then it is taken as it is)."""
    out, signs = dict(channels), {}
    for key, name in channels.items():
        if isinstance(name, str) and name.startswith("-") and len(name.strip()) > 1 and not has(key, name):
            if key in ("time", "dt"):
                raise InputError(f"--channel {key}={name} (channels[{key!r}]): a time cannot change its sign; a "
                                 "leading '-' flips the sign of an acceleration or angular velocity only.")
            out[key] = name[1:].strip()
            signs[key] = -1.0
    return out, signs


#: Column-name prefixes of Apple's Core Motion accelerations (iPhone apps such as SensorLog write
#: ``accelerometerAccelerationX(G)``, ``motionUserAccelerationX(G)``, ``motionGravityX(G)``): Core Motion reports
#: the negative of the specific force (-1 g on z for a phone lying face up), so they are read with their sign
#: flipped (:func:`core_motion_signs`).
CORE_MOTION_PREFIXES = ("accelerometerAcceleration", "motionUserAcceleration", "motionGravity")


def core_motion_signs(label: str, channels: dict, signs: dict) -> dict:
    """``signs`` with each acceleration read from a Core Motion column (:data:`CORE_MOTION_PREFIXES`) flipped,
    and one note naming them; a ``-`` the caller put before such a name flips it back to the file's sign."""
    flipped = [k for k in ("ax", "ay", "az")
               if isinstance(channels.get(k), str) and channels[k].startswith(CORE_MOTION_PREFIXES)]
    if not flipped:
        return signs
    signs = dict(signs)
    for k in flipped:
        signs[k] = -signs.get(k, 1.0)
    now = [k for k in flipped if signs[k] < 0]
    kept = [k for k in flipped if signs[k] > 0]
    names = ", ".join(f"{k} ({channels[k]!r})" for k in flipped)
    what = "are Apple Core Motion columns" if len(flipped) > 1 else "is an Apple Core Motion column"
    done = []
    if now:
        done.append(f"{', '.join(now)} read with the sign flipped (a '-' before a name keeps the file's sign)")
    if kept:
        done.append(f"{', '.join(kept)} with the file's sign, as the '-' before the name asks")
    verb = "hold" if len(flipped) > 1 else "holds"
    reader_note(f"{label}: {names} {what}, which {verb} the negative of the specific force (-1 g on z for a phone "
                f"lying face up): {'; '.join(done)}.", 3)
    return signs


def cut_window(start_s, end_s):
    """(start, end) of a cut [s from the first sample], either None, or None for no cut; bad values refused."""
    out = []
    for name, option, value in (("start_s", "--start", start_s), ("end_s", "--end", end_s)):
        if value is None:
            out.append(None)
            continue
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise InputError(f"{name} ({option}) must be a number of seconds from the log's first sample; got "
                             f"{describe(value)}.") from None
        if isinstance(value, bool) or not math.isfinite(v) or v < 0:
            raise InputError(f"{name} ({option}) must be a number of seconds >= 0 from the log's first sample; "
                             f"got {value!r}.")
        out.append(v)
    if out == [None, None]:
        return None
    if out[0] is not None and out[1] is not None and out[1] <= out[0]:
        raise InputError(f"end_s ({out[1]:g} s, --end) must be after start_s ({out[0]:g} s, --start).")
    return tuple(out)


def cut_rows(label: str, t: np.ndarray, window, origin=None, strict: bool = True) -> tuple[int, int]:
    """Rows i0:i1 of the samples within the cut ``window`` (seconds after ``origin``, default the first sample);
    ``strict``: a cut reaching outside the log, or holding fewer than 2 samples, is refused."""
    if window is None or t.size == 0:
        return 0, t.size
    start, end = window
    t0 = float(t[0]) if origin is None else float(origin)
    length = float(t[-1]) - t0
    tol = 1e-9 * max(1.0, abs(t0))  # round-off of time stamps far from 0 (a clock since boot)
    if strict and start is not None and start >= length:
        raise InputError(f"{label}: --start {start:g} s (start_s) is not within the log, which lasts {length:.6g} s "
                         "from its first sample.")
    if strict and end is not None and end > length + tol:
        raise InputError(f"{label}: --end {end:g} s (end_s) is after the end of the log, which lasts {length:.6g} s "
                         "from its first sample; leave --end out to read to the end.")
    i0 = 0 if start is None else int(np.searchsorted(t, t0 + start - tol, side="left"))
    i1 = t.size if end is None else int(np.searchsorted(t, t0 + end + tol, side="right"))
    if strict and i1 - i0 < 2:
        raise InputError(f"{label}: the cut from {start or 0:g} s to {length if end is None else end:g} s holds "
                         f"{max(0, i1 - i0)} sample(s); at least 2 are needed.")
    return i0, i1


def held_rows(columns: list) -> tuple[np.ndarray, float, float] | None:
    """(first row of each run, share of rows repeating their predecessor, median run length) of a held sensor
    (see :data:`HELD_SHARE`, :data:`HELD_RUN_MAX`, :data:`HELD_RUN_SPREAD` and :data:`HELD_TOGETHER`), or None."""
    n = columns[0].size
    if n < 3:
        return None
    changed = np.column_stack([c[1:] != c[:-1] for c in columns])
    same = ~changed.any(axis=1)
    share = float(same.mean())
    if share <= HELD_SHARE:
        return None
    starts = np.flatnonzero(np.concatenate([[True], ~same]))
    runs = np.diff(np.concatenate([starts, [n]]))
    run = float(np.median(runs))
    if not 2 <= run <= HELD_RUN_MAX or starts.size < 2 or float(np.std(runs)) > HELD_RUN_SPREAD * float(np.mean(runs)):
        return None
    new = changed[~same]  # the rows that bring a new sample
    moving = new.mean(axis=0) >= 0.1
    if float(new[:, moving].all(axis=1).mean()) < HELD_TOGETHER:
        return None
    return starts, share, run


def held_note(label: str, keys, t: np.ndarray, starts: np.ndarray, share: float, run: float) -> str:
    """The note on a held sensor: the share of repeated rows, the sensor's own rate and the rows kept."""
    written = (t.size - 1) / float(t[-1] - t[0])
    own = (starts.size - 1) / float(t[starts[-1]] - t[starts[0]])
    return (f"{label}: {100 * share:.0f} % of the rows repeat the previous row's {', '.join(keys)} exactly (runs of "
            f"{run:g} rows at the median): a sensor of about {own:.4g} Hz held in a log written at {written:.4g} Hz; "
            f"the repeats are dropped, the first row of each run is kept with its time stamp ({starts.size} of "
            f"{t.size} rows), so the figures are the sensor's own samples; nothing to do (--no-drop-held, "
            "drop_held=False, keeps every row).")


def irregular_steps(t: np.ndarray):
    """(median step, spread words) of time stamps departing from the uniform grid through their first and last
    samples by more than :data:`~ehm.inputs.resampling.UNIFORM_TOLERANCE` of a step, with no gap; else None."""
    if t.size < 3:
        return None
    steps = np.diff(t)
    median = float(np.median(steps))
    if np.any(steps > GAP_STEPS * median * (1 + 1e-6)):
        return None  # a gap: refused, or bridged with its own warning (fill_gaps)
    step = float(t[-1] - t[0]) / (t.size - 1)
    if float(np.max(np.abs(t - t[0] - np.arange(t.size) * step))) <= UNIFORM_TOLERANCE * step:
        return None
    p5, p95 = np.percentile(steps, [5, 95])
    ms = 1e3
    spread = (f"steps from {steps.min() * ms:.3g} to {steps.max() * ms:.3g} ms, 90 % of them within {p5 * ms:.3g}-"
              f"{p95 * ms:.3g} ms, median {median * ms:.3g} ms")
    return median, spread


def mounting_matrix_of(mounting, label: str) -> np.ndarray | None:
    """A mounting (sensor axes -> seat axes) as a 3x3 rotation matrix, checked as :func:`ehm.from_imu` checks it;
    None when there is none."""
    return None if mounting is None else mounting_matrix(mounting, label)


def parse_columns(columns) -> list | None:
    """``--columns x,y,z,delay_ms`` (or a list of names) -> ``["x", "y", "z", "delay_ms"]``: the names of a text
    file's columns when it has no header row; None stays None."""
    if columns is None:
        return None
    names = [c.strip() for c in columns.split(",")] if isinstance(columns, str) else columns
    if not isinstance(names, (list, tuple)) or not names or not all(isinstance(c, str) and c.strip() for c in names):
        raise InputError(f"columns {describe(columns)} (--columns): give the names of the file's columns, in order, "
                         "e.g. --columns x,y,z,delay_ms (columns=['x', 'y', 'z', 'delay_ms']).")
    names = [c.strip() for c in names]
    twice = sorted({c for c in names if names.count(c) > 1})
    if twice:
        raise InputError(f"columns {columns!r} (--columns): {twice[0]} is named twice; each column needs its own name.")
    return names


def join_gyro(label: str, glabel: str, t: np.ndarray, data: dict, tg: np.ndarray, gdata: dict, rate_keys):
    """The gyro's channels interpolated (linearly) onto the accelerometer's time stamps over their common span,
    which must cover :data:`MIN_OVERLAP` of the span they reach together; the accelerometer cut to it."""
    first, last = min(t[0], tg[0]), max(t[-1], tg[-1])
    start, stop = max(t[0], tg[0]), min(t[-1], tg[-1])
    common = float(stop - start)
    if common <= 0 or common < MIN_OVERLAP * float(last - first):
        what = "do not overlap" if common <= 0 else \
            f"overlap for {common:.6g} s of the {last - first:.6g} s they span ({100 * common / (last - first):.0f} %)"
        t0 = t[0]
        raise InputError(f"{label} and gyro file {glabel}: their time stamps {what}: the accelerometer's run from 0 "
                         f"to {t[-1] - t0:.4g} s, the gyro's from {tg[0] - t0:.4g} to {tg[-1] - t0:.4g} s after the "
                         "accelerometer's first sample; ehm joins them over their common span, "
                         f"which must cover {100 * MIN_OVERLAP:.0f} % of theirs: give files of one recording, with "
                         "the time channel of one clock (same --channel time and --unit time).")
    i0 = int(np.searchsorted(t, start, side="left"))
    i1 = int(np.searchsorted(t, stop, side="right"))
    t = t[i0:i1]
    out = {k: v[i0:i1] for k, v in data.items()}
    for k in rate_keys:
        out[k] = np.interp(t, tg, gdata[k])
    return t, out


def reader_note(text: str, depth: int) -> None:
    """One note (a warning) pointing at the caller of read_motion, ``depth`` calls above the caller of reader_note."""
    warn(text, EhmWarning, stacklevel=depth + 2)
