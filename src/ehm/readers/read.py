"""Reading a motion: open the source in its format, resolve the channels, convert and check them, and hand the
result to :class:`ehm.motion.SeatMotion` (or, for an IMU log, to :func:`ehm.imu.from_imu`)."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..imu import from_imu
from ..motion import SeatMotion
from .base import _as_floats, _Source
from .channels import _ACC, _RATES, CHANNEL_KEYS, DEFAULT_CHANNELS, _listed, _mapping
from .checks import _check_finite, _check_plausible, _check_sampling, _check_time_unit, _check_times, _common_time
from .frames import _FrameSource, _ParquetSource
from .matlab import _MatSource
from .mdf import _MdfSource
from .text import _TextSource
from .units import _factor, _time_seconds, _unit_of

_TEXT_SUFFIXES = (".csv", ".txt", ".tsv", ".dat")
_MAT_SUFFIXES = (".mat",)
_MDF_SUFFIXES = (".mf4", ".mdf", ".dat4")
_PARQUET_SUFFIXES = (".parquet", ".pq")


def _open(source, label: str | None) -> _Source:
    try:
        import pandas as pd
    except ImportError:  # pragma: no cover - pandas is a dependency
        raise InputError("reading motions needs pandas: pip install pandas.") from None
    if isinstance(source, pd.DataFrame):
        return _FrameSource(source, label or "DataFrame")
    if not isinstance(source, (str, os.PathLike)):
        raise InputError(f"read_motion: source must be a file path or a pandas DataFrame; got {type(source).__name__}.")
    path = Path(source)
    label = label or str(source)
    if not path.exists():
        raise InputError(f"{label}: motion file not found.")
    if path.is_dir():
        raise InputError(f"{label}: is a directory, not a motion file.")
    if not os.access(path, os.R_OK):
        raise InputError(f"{label}: motion file cannot be read (permission denied).")
    suffix = path.suffix.lower()
    if suffix in _PARQUET_SUFFIXES:
        return _ParquetSource(path, label)
    if suffix in _MAT_SUFFIXES:
        return _MatSource(path, label)
    if suffix in _MDF_SUFFIXES:
        return _MdfSource(path, label)
    return _TextSource(path, label)  # .csv, .txt and anything else: a text table


def read_motion(source, channels: dict | None = None, units: dict | None = None, rate_hz: float | None = None,
                imu: bool = False, mounting=None, label: str | None = None, fill_gaps: bool = False) -> SeatMotion:
    """Read a seat motion (or an IMU log) from a file or a pandas DataFrame.

    Parameters
    ----------
    source : str, os.PathLike or pandas.DataFrame
        ``.csv``/``.txt`` (any other suffix is read as text too), ``.parquet``, ``.mat`` (v5 or v7.3),
        ``.mf4``/``.mdf``, or a DataFrame.
    channels : dict, optional
        Key (``time, ax, ay, az, wx, wy, wz``) -> the source's name; the others keep their defaults
        (:data:`DEFAULT_CHANNELS`).  ``time`` set to None: a source without a time channel (give
        ``rate_hz``).  ``wx, wy, wz`` all set to None: read the translation only, even where the source has
        angular velocities.  MDF channels carry their own time stamps: their ``time`` is not used.
    units : dict, optional
        Key -> unit string (``"g"``, ``"deg/s"``, ``"ns"``; for ``time`` also a strftime format of
        date-time strings, ``"%d/%m/%Y %H:%M:%S"``).  It wins over a unit in the channel's name; a file's
        own unit (MDF) and a different one here are refused.  Default: the name's unit (``Accelerometer X
        (g)``, ``time_ms``, ``uptimeNanos``; see :mod:`ehm.readers`), else SI: s, m/s^2, rad/s; a unit
        taken that does not fit the values is refused in one sentence naming the unit to give.
    rate_hz : float, optional
        Samples per second of the returned motion: a source without a time channel is taken as sampled
        at this rate from t = 0; one with a time channel is resampled onto it (anti-aliased, as
        :meth:`ehm.motion.SeatMotion.resample`).
    imu : bool
        The source is an IMU at the seat: ``ax, ay, az`` its specific force (gravity included) and
        ``wx, wy, wz`` its gyro rates, all required; see :func:`ehm.imu.from_imu` (``mounting`` is passed on).
    label : str, optional
        How messages name the source (default: its path, or ``DataFrame``).
    fill_gaps : bool
        Bridge gaps in the time stamps (steps longer than :data:`GAP_STEPS` median steps) with a straight line,
        with a warning naming where; by default such a gap is refused.

    Returns
    -------
    SeatMotion
        Seat acceleration [m/s^2] in seat axes (and angular velocity [rad/s] when the source has rates),
        on the source's own time stamps [s] moved to start at 0, unless ``rate_hz`` asks for a rate.
    """
    channels = _mapping(channels, "channels")
    units = _mapping(units, "units")
    if rate_hz is not None:
        try:
            rate_hz = float(rate_hz)
        except (TypeError, ValueError):
            raise InputError(f"rate_hz must be a number of samples per second; got {rate_hz!r}.") from None
        if not (math.isfinite(rate_hz) and rate_hz > 0):
            raise InputError(f"rate_hz must be a positive number of samples per second; got {rate_hz!r}.")
    src = _open(source, label)
    try:
        return _read(src, channels, units, rate_hz, bool(imu), mounting, source, bool(fill_gaps))
    finally:
        src.close()


def load_motion_csv(path: str | os.PathLike[str]) -> SeatMotion:
    """Read a seat motion from a file with the default channel names; the same as
    :func:`ehm.readers.read_motion` ``(path)`` (kept for existing code).

    The default columns are ``time_s``, ``ax_mps2``, ``ay_mps2``, ``az_mps2``
    and optionally all of ``wx_radps``, ``wy_radps``, ``wz_radps`` (roll,
    pitch and yaw rates of the seat about its own axes).  Times [s] must be
    finite, >= 0 and strictly increasing; the sample interval may vary.  A
    comment line before the header describes the motion.

    Raises
    ------
    InputError
        One sentence naming the file, line (or row), column and value.

    Examples
    --------
    A file::

        # measured on the test rig
        time_s,ax_mps2,ay_mps2,az_mps2
        0.000,0.0,0.0,0.00
        0.001,0.0,0.0,0.12
    """
    return read_motion(path)


def _resolve(src: _Source, channels: dict, imu: bool, rate_hz) -> dict:
    """Key -> source name of every channel to read; missing ones named with what the source has."""
    names = {k: channels.get(k, DEFAULT_CHANNELS[k]) for k in CHANNEL_KEYS}

    def present(key):
        name = names[key]
        if name is None:
            return False
        return src.has(name) or (isinstance(src, _FrameSource) and key == "time" and src.has_index_time(name))

    wanted = list(_ACC) + list(_RATES if imu else [])
    left_out = [k for k in _RATES if k in channels and channels[k] is None]
    if left_out and (imu or len(left_out) < 3):
        raise InputError(f"{src.label}: {', '.join(left_out)} {'is' if len(left_out) == 1 else 'are'} left out (given "
                         "empty); " + ("an IMU log needs all three angular velocities." if imu else
                                       "leave out all three angular velocities (wx=, wy=, wz=) or none."))
    if not imu and len(left_out) < 3:
        rates_found = [k for k in _RATES if present(k)]
        explicit = [k for k in _RATES if k in channels]
        if explicit or rates_found:
            if rates_found and len(rates_found) < 3 and not explicit:
                absent = ", ".join(names[k] for k in _RATES if not present(k))
                raise InputError(f"{src.label}: it has {', '.join(names[k] for k in rates_found)} but not {absent}; "
                                 "give all three angular velocities or none.")
            wanted += list(_RATES)
    time_needed = not src.per_channel_time
    if time_needed:
        if names["time"] is None or ("time" not in channels and rate_hz is not None and not present("time")):
            names["time"] = None
            if rate_hz is None:
                raise InputError(f"{src.label}: without a time channel the sample rate is needed (rate_hz, --rate).")
        else:
            wanted.insert(0, "time")
    elif "time" in channels and channels["time"] is not None:
        raise InputError(f"{src.label}: MDF channels carry their own time stamps; leave out the time channel "
                         f"({channels['time']!r}).")
    missing = [k for k in wanted if not present(k)]
    if missing:
        parts = [f"{k} ({names[k]!r})" for k in missing]
        what = parts[0] if len(parts) == 1 else ", ".join(parts[:-1]) + " and " + parts[-1]
        verb = "is" if len(missing) == 1 else "are"
        raise InputError(f"{src.label}: channel{'s' * (len(missing) > 1)} {what} {verb} not in the "
                         f"{'file' if not isinstance(src, _FrameSource) else 'DataFrame'}; its {src.kind} are "
                         f"{_listed(src.names)}.")
    return {k: names[k] for k in wanted}


def _read(src: _Source, channels: dict, units: dict, rate_hz, imu: bool, mounting, source,
          fill_gaps: bool = False) -> SeatMotion:
    use = _resolve(src, channels, imu, rate_hz)
    if isinstance(src, _TextSource):
        src.load(list(use.values()))
    if isinstance(src, _MdfSource):
        for key, name in use.items():
            src.check_unique(key, name)
    data, stamps, taken = {}, {}, {}
    for key, name in use.items():  # one channel at a time: checked, in SI, each held once
        raw = src.values(name)
        if key == "time":  # seconds from the first sample (numbers in their unit, date-times)
            values, *taken[key] = _time_seconds(src, name, raw, units)
            _check_finite(src, key, name, values)
            data[key] = values
            continue
        values = _as_floats(src, name, key, raw)
        _check_finite(src, key, name, values)
        taken[key] = _unit_of(src, key, name, units)
        factor = _factor(taken[key][0], key, src.label, name)
        if factor != 1.0:
            owned = values is not raw or not isinstance(src, _FrameSource)  # never change a caller's DataFrame
            values = np.multiply(values, factor, out=values if owned and values.flags.writeable else None)
        data[key] = values
        del raw, values
        if src.per_channel_time:
            stamps[key] = src.time_of(name)
    n = min(v.size for v in data.values())
    if any(v.size != n for v in data.values()) and not src.per_channel_time:
        raise InputError(f"{src.label}: the channels have different lengths "
                         f"({', '.join(f'{k} {v.size}' for k, v in data.items())}).")
    if src.per_channel_time:
        time_s, data = _common_time(src, use, data, stamps, fill_gaps)
        time_s = time_s - time_s[0] if time_s.size else time_s  # the time axis starts at 0
    elif "time" in data:
        time_s = data.pop("time")
        _check_times(src, use["time"], time_s)
        _check_time_unit(src, use["time"], time_s, *taken["time"])
        _check_sampling(src, use["time"], time_s, fill_gaps)
    else:
        time_s = np.arange(n) / rate_hz
        rate_hz = None  # the source is at this rate already
    _check_plausible(src, use, data, {k: o for k, (_, o) in taken.items()}, acc=not imu)  # (from_imu: gravity)
    if time_s.size < 2:
        where = f", line {src.header_line}" if isinstance(src, _TextSource) else ""
        raise InputError(f"{src.label}{where}: motion file has {time_s.size} data row(s) after the header; at least 2 "
                         "are needed.")
    description = _describe(src, source, time_s)
    acc = _stack(data, _ACC)
    rates = _stack(data, _RATES) if all(k in data for k in _RATES) else None
    time_s = _frozen(np.array(time_s, dtype=float) if isinstance(src, _FrameSource) else time_s)
    if imu:
        motion = from_imu(time_s, acc, rates, mounting=mounting, description=f"IMU log {description}",
                          label=src.label)
    else:
        motion = SeatMotion(time_s, acc, description, rates)  # takes the read-only arrays as they are
    if rate_hz is not None:
        motion = motion.resample(1.0 / rate_hz)
    return motion


def _stack(data: dict, keys) -> np.ndarray:
    """Columns into one (n, 3) read-only array, each channel's own array let go as soon as it is copied in."""
    out = np.empty((data[keys[0]].size, len(keys)))
    for j, k in enumerate(keys):
        out[:, j] = data.pop(k)
    return _frozen(out)


def _frozen(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


def _describe(src: _Source, source, time_s: np.ndarray) -> str:
    base = os.path.basename(str(source)) if not isinstance(src, _FrameSource) else src.label
    description = f"from {base}, {time_s.size} samples, {float(time_s[-1] - time_s[0]):g} s"
    if src.first_comment:  # a file's first comment line describes it (e.g. "SYNTHETIC city drive ...")
        description = f"{src.first_comment} ({description})"
    return description
