"""Reading a motion: open the source in its format, resolve the channels, convert and check them, and hand the
result to :class:`ehm.inputs.motion.SeatMotion` (or, for an IMU log, to :func:`ehm.from_imu`)."""

from __future__ import annotations

import math
import numbers
import os
from pathlib import Path

import numpy as np

from ...errors import InputError, checked, describe
from ...standards.comfort import BAND_WARNING_SHARE, band_share_outside
from ..handling import check_handling, find_handling, handling_note
from ..imu import from_imu
from ..motion import SeatMotion
from ..resampling import PASS_FRACTION
from ..vocabulary import GYRO_UNIT
from ..vocabulary import fix as fix_words
from .base import Source, as_floats
from .channels import (
    ACC_KEYS,
    ASSUMED,
    CHANNEL_KEYS,
    DEFAULT_CHANNELS,
    RATE_KEYS,
    channel_candidates,
    guess_channel,
    listed_names,
    mapping_arg,
)
from .checks import (
    assumed_words,
    check_finite,
    check_not_flag,
    check_plausible,
    check_sampling,
    check_time_unit,
    check_times,
    common_time,
)
from .frames import FrameSource, ParquetSource
from .gravity import check_mode, handle_gravity
from .layout import (
    core_motion_signs,
    cut_rows,
    cut_window,
    held_note,
    held_rows,
    irregular_steps,
    join_gyro,
    mounting_matrix_of,
    parse_columns,
    reader_note,
    signed_channels,
)
from .matlab import MatSource
from .mdf import MdfSource
from .text import TextSource
from .units import MAX_STEP_S, MIN_STEP_S, channel_unit, time_seconds, unit_factor

_TEXT_SUFFIXES = (".csv", ".txt", ".tsv", ".dat")
_MAT_SUFFIXES = (".mat",)
_MDF_SUFFIXES = (".mf4", ".mdf", ".dat4")
_PARQUET_SUFFIXES = (".parquet", ".pq")


def _open(source, label: str | None, columns=None, encoding: str | None = None) -> Source:
    try:
        import pandas as pd
    except ImportError:  # pragma: no cover - pandas is a dependency
        raise InputError("reading motions needs pandas: pip install pandas.") from None
    if isinstance(source, pd.DataFrame):
        if columns is not None:
            raise InputError(f"{label or 'DataFrame'}: columns= names the columns of a text file without a header "
                             "row; a DataFrame has its own column names (name its channels with channels=).")
        if encoding is not None:
            raise InputError(f"{label or 'DataFrame'}: encoding= is the text encoding of a text file; a DataFrame "
                             "holds text already: leave it out.")
        return FrameSource(source, label or "DataFrame")
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
    if columns is not None and suffix in _PARQUET_SUFFIXES + _MAT_SUFFIXES + _MDF_SUFFIXES:
        raise InputError(f"{label}: --columns (columns=) names the columns of a text file without a header row; "
                         f"a {suffix} file names its own channels (name them with --channel KEY=NAME).")
    if encoding is not None and suffix in _PARQUET_SUFFIXES + _MAT_SUFFIXES + _MDF_SUFFIXES:
        raise InputError(f"{label}: --encoding (encoding=) is the text encoding of a text file; a {suffix} file is "
                         "not text: leave it out.")
    if suffix in _PARQUET_SUFFIXES:
        return ParquetSource(path, label)
    if suffix in _MAT_SUFFIXES:
        return MatSource(path, label)
    if suffix in _MDF_SUFFIXES:
        return MdfSource(path, label)
    return TextSource(path, label, columns, encoding)  # .csv, .txt and anything else: a text table


@checked(only=("channels", "units", "mounting", "label", "columns", "gravity", "imu_options", "frame"))
def read_motion(source, channels: dict | None = None, units: dict | None = None, rate_hz: float | None = None,
                imu: bool = False, mounting=None, label: str | None = None, fill_gaps: bool = False, *,
                columns=None, gyro=None, start_s: float | None = None, end_s: float | None = None,
                gravity: str = "auto", imu_options: dict | None = None, frame: str = "seat", drop_held: bool = True,
                encoding: str | None = None, handling: str = "cut") -> SeatMotion:
    """Read a seat motion (or an IMU log) from a file or a pandas DataFrame.

    Parameters
    ----------
    source : str, os.PathLike or pandas.DataFrame
        ``.csv``/``.txt`` (any other suffix is read as text too), ``.parquet``, ``.mat`` (v5 or v7.3),
        ``.mf4``/``.mdf``, or a DataFrame.
    channels : dict, optional
        Key (``time, ax, ay, az, wx, wy, wz, dt``) -> the source's name; the others keep their defaults
        (``ehm.inputs.readers.DEFAULT_CHANNELS``).  ``time`` set to None: a source without a time channel (give
        ``rate_hz``).  ``wx, wy, wz`` all set to None: read the translation only, even where the source has
        angular velocities.  MDF channels carry their own time stamps: their ``time`` is not used.
        ``dt``: a channel of the time since the previous row, read instead of ``time`` (the time is its
        cumulative sum from 0 at the first row; give its unit, e.g. ``units={"dt": "ms"}``).  A name with a
        leading ``-`` (``"ax": "-AccX"``) reads that channel with its sign flipped.  A ``dt`` column's unit comes
        from its name as a time's does (``delay_ms`` is in ms), and its median step is checked as a time's.
    units : dict, optional
        Key -> unit string (``"g"``, ``"deg/s"``, ``"ns"``; for ``time`` also a strftime format of
        date-time strings, ``"%d/%m/%Y %H:%M:%S"``).  It wins over a unit in the channel's name; a file's
        own unit (MDF) and a different one here are refused.  Default: the name's unit (``Accelerometer X
        (g)``, ``time_ms``, ``uptimeNanos``; see :mod:`ehm.inputs.readers`), else SI: s, m/s^2, rad/s; a unit
        taken that does not fit the values is refused in one sentence naming the unit to give.
    rate_hz : float, optional
        Samples per second of the returned motion, a number from 2 Hz to 100 kHz (not a bool or a string): a
        source without a time channel is taken as sampled at this rate from t = 0; one with a time channel is
        resampled onto it (anti-aliased, as :meth:`ehm.SeatMotion.resample`), with a note when that cuts off
        ``ehm.standards.comfort.BAND_WARNING_SHARE`` (1 %) or more of the Wk or Wd band's power the log held.
    imu : bool
        The source is an IMU at the seat: ``ax, ay, az`` its specific force (gravity included) and
        ``wx, wy, wz`` its gyro rates, all required; see :func:`ehm.from_imu` (``mounting`` is passed on).
    mounting : (roll, pitch, yaw) in degrees, scipy.spatial.transform.Rotation or (3, 3) array, optional
        Rotation from the sensor's axes to the seat's (x forward, y left, z up), as :func:`ehm.from_imu`
        takes it; applied to the accelerations and the angular velocities alike, for an IMU log or not.  Three
        angles in degrees (or ``"ROLL,PITCH,YAW"``) as ``--mounting`` takes them, e.g. ``mounting=(0, 90, -180)``
        (:func:`ehm.inputs.readers.mounting_rotation`; in radians: ``mounting_rotation(..., degrees=False)``).
    label : str, optional
        How messages name the source (default: its path, or ``DataFrame``).
    fill_gaps : bool
        (True or False only, as ``imu`` and ``drop_held``.)  Bridge gaps in the time stamps (steps longer than
        ``ehm.inputs.readers.GAP_STEPS`` median steps) with a straight line, with a warning naming where; by default
        such
        a gap is refused.
    columns : list of str or str, optional
        Names of the columns of a text file without a header row, in order (``["x", "y", "z", "delay_ms"]`` or
        ``"x,y,z,delay_ms"``); its first row is then data.  A text file whose first row holds only numbers is
        refused without them.  The gyro file (``gyro``) is read with the same names.
    gyro : str, os.PathLike or pandas.DataFrame, optional
        A gyro logged in a file of its own, with its own time stamps: ``wx, wy, wz`` (and ``time`` or ``dt``,
        names and units as in ``channels`` and ``units``) are read from it, ``ax, ay, az`` from ``source``.  Its
        rates are interpolated (linearly) onto the accelerometer's time stamps over the span both cover, which
        must be at least ``ehm.inputs.readers.MIN_OVERLAP`` of the span they reach together; the time stamps of both
        files
        must come from one clock.
    start_s, end_s : float, optional
        Read the log from ``start_s`` to ``end_s`` seconds after its first sample only (either may be left
        out).  The cut comes before every check of the values (held samples, sampling, an IMU's rest), so a
        phone being put in place in the first seconds can be cut away; a cut outside the log, or holding fewer
        than 2 samples, is refused.
    imu_options : dict, optional
        Keyword arguments for :func:`ehm.from_imu` when ``imu`` is true: ``rest_s`` (the shortest rest whose
        gyro rate is taken as bias) and ``max_tilt_deg`` (the largest seat roll or pitch accepted).
    gravity : {"auto", "included", "removed"}
        Gravity in the accelerations of a seat or floor log (not an IMU log, whose route handles it):
        ``included`` levels the log (static tilt from its quietest 5 s near 1 g, rotated so that gravity is
        along z, g subtracted; refused where that window's mean is under half a g: no gravity to take out);
        ``removed`` takes it as it is but refuses a mean near 1 g or a mean z above 2 m/s^2; ``auto`` levels it,
        with a warning, when the quietest window's mean (its norm, or its z) is within 10 % of g, else takes it
        as it is but refuses what ``removed`` refuses, and a window mean of half a g or more in a log of 5 s or
        longer.  See :mod:`ehm.inputs.readers.gravity`.
    frame : {"seat", "earth"}
        The axes of the accelerations: ``seat`` (x forward, y left, z up) or ``earth`` (x east, y north, z up: a
        phone app's log turned into earth axes by the phone's own fusion).  Earth axes cannot be turned into the
        vehicle's without its heading, which such a log does not hold: an earth-axis log is read as it is, with
        one note saying that the seat's a_v, VDV and MSDV (which do not depend on the heading) are right and its
        x and y values and the body's response are given for x east and y north.  Angular rates about earth axes
        (not the seat's own) and ``imu`` (the phone levelled the log already) are refused.
    drop_held : bool
        Find held samples and drop their repeats (below, default); False (``--no-drop-held``) keeps every row.
    encoding : str, optional
        Text encoding of a text file (``"cp1252"`` for a Windows export; any name Python's codecs know).
        Default: from its byte-order mark (UTF-8, UTF-16, UTF-32), UTF-16 without one found by its zero bytes,
        else UTF-8; a file that does not decode is refused naming the option.
    handling : {"cut", "keep"}
        ``cut`` (default): a stretch at the start or end of a seat or floor log with gravity in it where the logger
        was handled rather than carried by the vehicle (turned against gravity for a second or more, with
        accelerations far above the drive's) is left out, with one note naming the seconds and why, and recorded in
        ``SeatMotion.handling``; never more than the first or last 20 % of the log, and never without a
        sustained turn (a pothole is not cut).  ``keep`` (``--keep-handling``): every sample is kept.  See
        ``ehm.inputs.handling``.

    Returns
    -------
    SeatMotion
        Seat acceleration [m/s^2] in seat axes (and angular velocity [rad/s] when the source has rates),
        on the source's own time stamps [s] moved to start at 0, unless ``rate_hz`` asks for a rate, or the
        time stamps are irregular (below).

    Notes
    -----
    Two layouts are mended, each with one note (:func:`warnings.warn`):

    * Held samples: when more than ``ehm.inputs.readers.HELD_SHARE`` of the rows repeat their predecessor exactly in
      every
      acceleration channel (a gyro file: every angular velocity), in regular runs (``ehm.inputs.readers.layout.
      HELD_RUN_SPREAD``) of 2 to ``ehm.inputs.readers.HELD_RUN_MAX`` rows at the median, and the rows between runs
      change
      the moving channels together (``HELD_TOGETHER``; a quantised smooth log steps one channel at a time), the
      sensor is slower than the log was written at (a 51 Hz sensor written at 200 Hz): only the first row of each
      run is kept, with its time stamp, and the note gives the sensor's own rate (``drop_held=False``: kept).
    * Irregular time stamps: when they depart from the uniform grid through the first and the last sample by
      more than :data:`ehm.inputs.resampling.UNIFORM_TOLERANCE` of a step, with no gap (gaps and changes of rate are
      refused, or bridged when asked), the motion is resampled onto a uniform grid at the median step (linear
      interpolation), or at ``rate_hz`` when given; the note gives the spread of the steps.
    """
    channels = mapping_arg(channels, "channels")
    units = mapping_arg(units, "units")
    rate_hz = _rate(rate_hz)
    imu, fill_gaps, drop_held = (_flag(v, name, option) for v, name, option in (
        (imu, "imu", "--imu"), (fill_gaps, "fill_gaps", "--fill-gaps"), (drop_held, "drop_held", "--no-drop-held")))
    gravity = check_mode(gravity)
    handling = check_handling(handling)
    if frame not in FRAMES:
        raise InputError(f"frame must be one of {', '.join(FRAMES)}; got {describe(frame)}.")
    named = label or (str(source) if isinstance(source, (str, os.PathLike)) else "DataFrame")
    if frame == "earth":
        _check_earth(named, bool(imu), mounting)
    columns = parse_columns(columns)
    window = cut_window(start_s, end_s)
    m = mounting_matrix_of(mounting, named)
    encoding = _encoding(encoding)
    src = _open(source, label, columns, encoding)
    gsrc = None
    try:
        if gyro is not None:
            gsrc = _open(gyro, None if isinstance(gyro, (str, os.PathLike)) else "gyro DataFrame", columns, encoding)
        return _read(src, channels, units, rate_hz, imu, m, source, fill_gaps, gsrc, window, gravity,
                     _imu_options(imu_options), frame, drop_held, handling)
    finally:
        src.close()
        if gsrc is not None:
            gsrc.close()


def _rate(rate_hz) -> float | None:
    """``rate_hz`` checked: a number (not a bool or a string) of samples per second from 2 Hz to 100 kHz, the
    rates :func:`ehm.inputs.readers.checks.check_time_unit` takes from a log's own time stamps (a rate below 2 Hz holds
    nothing of the comfort band; resampling to a few Hz is warned about by :func:`_rate_note`)."""
    if rate_hz is None:
        return None
    if isinstance(rate_hz, (bool, np.bool_)) or not isinstance(rate_hz, numbers.Real):
        raise InputError(f"rate_hz (--rate) must be a number of samples per second; got {describe(rate_hz)}.")
    rate = float(rate_hz)
    if not (math.isfinite(rate) and 1.0 / MAX_STEP_S <= rate <= 1.0 / MIN_STEP_S):
        raise InputError(f"rate_hz must be a positive number of samples per second from {1 / MAX_STEP_S:g} Hz to "
                         f"{1e-3 / MIN_STEP_S:g} kHz (--rate; a log keeps the comfort band, 0.5-80 Hz, up to "
                         f"{PASS_FRACTION:g} times its rate: at {1 / MAX_STEP_S:g} Hz "
                         f"0.5-{PASS_FRACTION / MAX_STEP_S:g} Hz of it, with a warning saying how much is lost); "
                         f"got {describe(rate_hz)}.")
    return rate


def _flag(value, name: str, option: str) -> bool:
    """A yes/no argument: True or False only (a string such as "no" is true in Python, and refused here)."""
    if not isinstance(value, (bool, np.bool_)):
        raise InputError(f"{name} ({option}) must be True or False; got {describe(value)}.")
    return bool(value)


def _encoding(encoding) -> str | None:
    """The text encoding asked for, checked with Python's codecs; None: found from the file."""
    if encoding is None:
        return None
    import codecs

    try:
        if not isinstance(encoding, str):
            raise LookupError(encoding)
        return codecs.lookup(encoding).name
    except LookupError:
        raise InputError(f"encoding (--encoding) {describe(encoding)} is not a text encoding Python knows (e.g. utf-8, "
                         "cp1252, latin-1, utf-16).") from None


def _rate_note(label: str, motion: SeatMotion, rate_hz: float) -> None:
    """One note when resampling to ``rate_hz`` cuts off at least ``BAND_WARNING_SHARE`` of a weighting's power
    that the log held (as an assessment warns about the band an input covers)."""
    own_hz = 1.0 / float(np.median(np.diff(motion.time_s)))
    if rate_hz >= own_hz:  # nothing downsampled: the log keeps what it held
        return
    held = min(motion.content_limit_hz if motion.content_limit_hz is not None else own_hz / 2.0,
               PASS_FRACTION * own_hz)  # (the log's own pass band, as the resampler keeps it)
    low = 1.0 / motion.duration_s
    kept = min(held, PASS_FRACTION * rate_hz)
    if kept >= held:
        return
    lost = {w: band_share_outside(w, low, kept) - band_share_outside(w, low, held) for w in ("Wk", "Wd")}
    if max(lost.values()) < BAND_WARNING_SHARE:
        return
    reader_note(f"{label}: resampled to {rate_hz:g} Hz (rate_hz, --rate), below the log's own {own_hz:.4g} Hz, "
                f"it covers up to {kept:.3g} Hz instead of {held:.3g} Hz: {100 * lost['Wk']:.1f} % of Wk's power and "
                f"{100 * lost['Wd']:.1f} % of Wd's (|W(f)|^2 on a log-frequency axis) are lost; leave --rate out to "
                "keep the log's own rate.", 3)


_IMU_OPTIONS = ("rest_s", "max_tilt_deg")


def _imu_options(options: dict | None) -> dict:
    """The IMU route's options, checked: only :data:`_IMU_OPTIONS`, each a positive number (or left out)."""
    out = {}
    for key, value in (options or {}).items():
        if key not in _IMU_OPTIONS:
            raise InputError(f"imu_options: {key!r} is not an option of the IMU route; they are "
                             f"{', '.join(_IMU_OPTIONS)}.")
        if value is None:
            continue
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value < float("inf"):
            raise InputError(f"imu_options: {key} = {describe(value)}; give a positive number.")
        out[key] = float(value)
    return out


@checked
def load_motion_csv(path: str | os.PathLike[str]) -> SeatMotion:
    """Read a seat motion from a file with the default channel names; the same as
    :func:`ehm.read_motion` ``(path)`` (kept for existing code).

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


def _resolve(src: Source, channels: dict, imu: bool, rate_hz, part: str = "all") -> dict:
    """Key -> source name of every channel to read; missing ones named with what the source has.  ``part``:
    ``"all"`` (one source), ``"acc"`` (the accelerometer's file of two) or ``"rates"`` (the gyro's file)."""
    names = {k: channels.get(k, DEFAULT_CHANNELS[k]) for k in CHANNEL_KEYS}

    def present(key):
        name = names[key]
        if name is None:
            return False
        return src.has(name) or (isinstance(src, FrameSource) and key == "time" and src.has_index_time(name))

    left_out = [k for k in RATE_KEYS if k in channels and channels[k] is None]
    if part == "rates":
        wanted = list(RATE_KEYS)
        if left_out:
            raise InputError(f"{src.label}: {', '.join(left_out)} {'is' if len(left_out) == 1 else 'are'} left out "
                             "(given empty); a gyro file gives all three angular velocities.")
    else:
        # an IMU log with all three rates left out (wx= wy= wz=) is accelerometer-only: from_imu levels it
        wanted = list(ACC_KEYS) + list(RATE_KEYS if imu and part == "all" and not left_out else [])
    if part == "all" and left_out and len(left_out) < 3:
        raise InputError(f"{src.label}: {', '.join(left_out)} {'is' if len(left_out) == 1 else 'are'} left out (given "
                         "empty); leave out all three angular velocities (wx=, wy=, wz=) or none.")
    if part == "all" and not imu and len(left_out) < 3:
        rates_found = [k for k in RATE_KEYS if present(k)]
        explicit = [k for k in RATE_KEYS if k in channels]
        if explicit or rates_found:
            if rates_found and len(rates_found) < 3 and not explicit:
                absent = ", ".join(names[k] for k in RATE_KEYS if not present(k))
                raise InputError(f"{src.label}: it has {', '.join(names[k] for k in rates_found)} but not {absent}; "
                                 "give all three angular velocities or none.")
            wanted += list(RATE_KEYS)
    time_needed = not src.per_channel_time
    rate_missing = False
    if names["dt"] is not None:
        if not time_needed:
            raise InputError(f"{src.label}: MDF channels carry their own time stamps; leave out the dt channel "
                             f"({names['dt']!r}).")
        if channels.get("time") is not None:
            raise InputError(f"{src.label}: give the time channel ({channels['time']!r}) or the dt channel "
                             f"({names['dt']!r}, the time since the previous row), not both.")
        wanted.insert(0, "dt")
    elif time_needed:
        if names["time"] is None or ("time" not in channels and rate_hz is not None and not present("time")):
            names["time"] = None
            rate_missing = rate_hz is None
        else:
            wanted.insert(0, "time")
    elif "time" in channels and channels["time"] is not None:
        raise InputError(f"{src.label}: MDF channels carry their own time stamps; leave out the time channel "
                         f"({channels['time']!r}).")
    missing = [k for k in wanted if not present(k)]
    if missing or rate_missing:
        raise InputError(_missing_sentence(src, names, missing, rate_missing, channels))
    return {k: names[k] for k in wanted}


def _missing_sentence(src: Source, names: dict, missing: list, rate_missing: bool, channels: dict) -> str:
    """One sentence for every channel the source lacks and a sample rate it needs, with the whole fix at once:
    ``--channel KEY=NAME`` for each (its column guessed where one name fits, :func:`guess_channel`), ``--channel
    time= --rate HZ`` for a source without time stamps (in the Python words, ``channels=``/``rate_hz=``, outside the
    command line)."""
    where = "file" if not isinstance(src, FrameSource) else "DataFrame"
    found = []
    if missing:
        parts = [f"{k} ({names[k]!r})" for k in missing]
        what = parts[0] if len(parts) == 1 else ", ".join(parts[:-1]) + " and " + parts[-1]
        verb = "is" if len(missing) == 1 else "are"
        found.append(f"channel{'s' * (len(missing) > 1)} {what} {verb} not in the {where}; its {src.kind} are "
                     f"{listed_names(src.names)}")
    given = {}  # key -> name (None: no time column) of the fix
    notes = []
    if "time" in missing or rate_missing:
        stamps = [] if rate_missing else channel_candidates("time", src.names)
        steps = [] if stamps or rate_missing else channel_candidates("dt", src.names)
        if stamps or steps:
            key, names_found = ("time", stamps) if stamps else ("dt", steps)
            given[key] = names_found[0] if len(names_found) == 1 else "NAME"
            if len(names_found) > 1:
                notes.append(f"NAME for {key}: one of {', '.join(names_found)}")
            if key == "dt":
                notes.append("dt: a column of the time since the previous row")
        else:
            given["time"] = None
            notes.append("HZ: the logger's sample rate, as " + ("the file has no time column" if not rate_missing
                                                                 else "there is no time channel"))
    for k in missing:
        if k != "time":
            given[k] = guess_channel(k, src.names) or "NAME"
            if given[k] == "NAME":
                notes.append(f"NAME for {k}: one of its {src.kind}")
    cli = " ".join(f"--channel {k}={'' if v is None else _quoted(v)}" + (" --rate HZ" if k == "time" and v is None
                                                                          else "") for k, v in given.items())
    kept = {k: v for k, v in channels.items() if k not in given}
    merged = {**kept, **given}
    python = "channels={" + ", ".join(f"{k!r}: {merged[k]!r}" for k in CHANNEL_KEYS if k in merged) + "}"
    if given.get("time", "") is None:
        python += ", rate_hz=HZ"
    if any(v not in (None, "NAME") for v in given.values()):
        notes.append("the columns guessed from their names: check them")
    fix = f"read it with {fix_words(cli, python)}" + (f" ({'; '.join(notes)})" if notes else "")
    return f"{src.label}: {'; '.join(found) + ': ' if found else ''}{fix}."


def _quoted(name: str) -> str:
    """A column name as a shell word (quoted when it holds blanks or shell characters)."""
    import shlex

    return shlex.quote(str(name))


def _read(src: Source, channels: dict, units: dict, rate_hz, imu: bool, mounting, source,
          fill_gaps: bool = False, gsrc: Source | None = None, window=None,
          gravity: str = "auto", imu_options: dict | None = None, frame: str = "seat",
          drop_held: bool = True, handling: str = "cut") -> SeatMotion:
    def has(key, name):
        return (gsrc if gsrc is not None and key in RATE_KEYS else src).has(name)

    channels, signs = signed_channels(channels, has)
    signs = core_motion_signs(src.label, channels, signs)
    use = _resolve(src, channels, imu, rate_hz, "all" if gsrc is None else "acc")
    taken: dict = {}  # channel -> where its unit came from (given, the file, the name, assumed)
    held_keys = ACC_KEYS if drop_held else None
    time_s, data, origin, clock = _table(src, use, units, signs, rate_hz, window, None, fill_gaps, held_keys, taken)
    check_plausible(src, use, data, taken, acc=not imu)  # (from_imu checks an IMU's gravity itself)
    if "time" not in use and "dt" not in use and not src.per_channel_time:
        rate_hz = None  # the source is at this rate already
    if gsrc is not None:
        guse = _resolve(gsrc, channels, imu, rate_hz, "rates")
        tg, gdata, _, _ = _table(gsrc, guse, units, signs, rate_hz, window, origin, fill_gaps,
                                 RATE_KEYS if drop_held else None, taken, clock)
        check_plausible(gsrc, guse, gdata, taken, acc=False)
        if tg.size < 2 or time_s.size < 2:
            raise InputError(f"{gsrc.label}: the gyro file holds {tg.size} sample(s) within the accelerometer's "
                             f"{'cut of the ' if window is not None else ''}log ({time_s.size} sample(s)); at least "
                             "2 of each are needed to join them: check the cut (--start, --end) and that both files "
                             "come from one recording.")
        time_s, data = join_gyro(src.label, gsrc.label, time_s, data, tg, gdata, RATE_KEYS)
    if time_s.size:
        time_s = time_s - time_s[0]  # the time axis starts at 0 (epoch and uptime stamps, a file's own clock)
    if time_s.size < 2:
        where = f", line {src.header_line}" if isinstance(src, TextSource) and src.header_line else ""
        raise InputError(f"{src.label}{where}: motion file has {time_s.size} data row(s)"
                         f"{' after the header' if where else ''}; at least 2 are needed.")
    acc = _stack(data, ACC_KEYS)
    rates = _stack(data, RATE_KEYS) if all(k in data for k in RATE_KEYS) else None
    stretches = ()
    if handling == "cut" and not imu and frame == "seat" and gravity != "removed":
        time_s, acc, rates, stretches = _cut_handling(src.label, time_s, acc, rates, window)
    description = _describe(src, source, time_s, gsrc, window, stretches)
    irregular = irregular_steps(time_s)
    if frame == "earth" and rates is not None:
        raise InputError(f"{src.label}: angular rates in earth axes are not the seat's own roll, pitch and yaw rates: "
                         "leave them out (--channel wx= --channel wy= --channel wz=; channels wx, wy, wz set to None).")
    time_s = _frozen(np.asarray(time_s, dtype=float))  # (a new array: moved to start at 0 above)
    if mounting is not None and not imu:  # (from_imu turns its own inputs)
        acc = _frozen(acc @ mounting.T)
        rates = None if rates is None else _frozen(rates @ mounting.T)
    if imu:
        token = GYRO_UNIT.set(_gyro_unit_words(gsrc or src, use if gsrc is None else guse, units, taken)
                              if rates is not None else None)
        try:
            motion = from_imu(time_s, acc, rates, mounting=mounting, description=f"IMU log {description}",
                              label=src.label, **(imu_options or {}))
        finally:
            GYRO_UNIT.reset(token)
    else:
        acc, rates, levelled = handle_gravity(time_s, acc, rates, gravity, src.label,  # ehm.inputs.readers.gravity
                                              earth=frame == "earth")
        description = f"{description}, {levelled}" if levelled else description
        if frame == "earth":
            description += ", earth axes (x east, y north, z up)"
            reader_note(f"{src.label}: earth axes (x east, y north, z up) are not the vehicle's, and the log holds no "
                        "heading to turn them: the seat's a_v, VDV and MSDV do not depend on it and are right, but "
                        "its x and y values and the body's response do, and are given for x east and y north (a log "
                        "in the vehicle's axes gives them).", 2)
        motion = SeatMotion(time_s, acc, description, rates,  # takes the read-only arrays as they are
                            handling=tuple(h.as_dict() for h in stretches))
    if irregular is not None:
        step, spread = irregular
        to = f"{rate_hz:g} Hz (rate_hz)" if rate_hz is not None else \
            f"a uniform grid at the median step, {1 / step:.6g} Hz, by linear interpolation"
        reader_note(f"{src.label}: the time stamps are irregular ({spread}); the motion is resampled to {to}.", 2)
        if rate_hz is None:
            motion = motion.resample(step)
    if rate_hz is not None:
        _rate_note(src.label, motion, rate_hz)
        motion = motion.resample(1.0 / rate_hz)
    return motion


FRAMES = ("seat", "earth")  #: the axes a log's accelerations may be in (read_motion's ``frame``)


def _check_earth(label: str, imu: bool, mounting) -> None:
    """Refuse, in one sentence, the options an earth-axis log cannot be read with (its angular rates are refused
    once they are read)."""
    if imu:
        raise InputError(f"{label}: a log in earth axes was levelled by the phone already and is no IMU log: read it "
                         "without --imu (imu=False).")
    if mounting is not None:
        raise InputError(f"{label}: a mounting turns the log's axes into the seat's, so they are no longer earth "
                         "axes: give either --frame earth or --mounting, not both.")


def _table(src: Source, use: dict, units: dict, signs: dict, rate_hz, window, origin, fill_gaps: bool,
           held_keys, taken: dict, clock: float | None = None) -> tuple:
    """(time [s], key -> values in SI with their signs, the first sample's time before the cut, the first
    sample's stamp on the file's own clock [s]) of the channels ``use`` of one source: the time read (or summed
    from ``dt``), checked and cut to ``window`` first; then each channel of the cut, checked; held samples
    dropped; the sampling checked.  A time column counts from its first sample; with ``clock`` (the other
    file's first stamp, for a gyro file of the same clock) it counts from that instead."""
    if isinstance(src, TextSource):
        src.load(list(use.values()))
    if isinstance(src, MdfSource):
        for key, name in use.items():
            src.check_unique(key, name)
    strict = origin is None  # (the gyro file of two is cut to the accelerometer's window, and joined after)
    if src.per_channel_time:
        return _mdf_table(src, use, units, signs, window, origin, fill_gaps, strict, held_keys, taken)
    tkey = "dt" if "dt" in use else "time" if "time" in use else None
    sizes = {}
    start = 0.0
    if tkey == "time":  # seconds (numbers in their unit, date-times), on the file's own clock
        t, t_unit, t_origin, start = time_seconds(src, use["time"], src.values(use["time"]), units)
        check_finite(src, "time", use["time"], t)
        if clock is not None:  # a gyro file: on the accelerometer file's time axis, by their common clock
            t = t + (start - clock)
        sizes["time"] = t.size
        check_times(src, use["time"], t)
        check_time_unit(src, use["time"], t, t_unit, t_origin)
    elif tkey == "dt":
        t = _channel(src, "dt", use["dt"], units, signs, taken=taken)
        sizes["dt"] = t.size
        t = _from_steps(src, use["dt"], t)
        check_time_unit(src, use["dt"], t, channel_unit(src, "dt", use["dt"], units)[0], taken["dt"], "dt")
    else:
        t = np.arange(np.shape(src.values(next(iter(use.values()))))[0]) / rate_hz
    first = float(t[0]) if t.size else 0.0
    i0, i1 = cut_rows(src.label, t, window, origin, strict)
    if (i0, i1) != (0, t.size):
        t = t[i0:i1]
        src.rows = i0 if i0 else None  # messages name the source's own rows
    data = {}
    for key, name in use.items():  # one channel at a time: checked, in SI, each held once
        if key == tkey:
            continue
        sizes[key] = np.shape(src.values(name))[0]
        data[key] = _channel(src, key, name, units, signs, i0, i1, taken)
    if len(set(sizes.values())) > 1:
        raise InputError(f"{src.label}: the channels have different lengths "
                         f"({', '.join(f'{k} {v}' for k, v in sizes.items())}).")
    t, data = _drop_held(src, t, data, held_keys, i0)
    if tkey is not None:
        check_sampling(src, use[tkey], t, fill_gaps, tkey)
    return t, data, first, start


def _mdf_table(src: Source, use: dict, units: dict, signs: dict, window, origin, fill_gaps: bool, strict: bool,
               held_keys, taken: dict) -> tuple:
    """As :func:`_table` for channels with their own time stamps: each cut to the window (seconds after the
    earliest channel's first sample), then all put on one time base."""
    data, stamps = {}, {}
    for key, name in use.items():
        stamps[key] = np.asarray(src.time_of(name), dtype=float)
    first = min(float(s[0]) for s in stamps.values() if s.size) if any(s.size for s in stamps.values()) else 0.0
    for key, name in use.items():
        i0, i1 = cut_rows(src.label, stamps[key], window, first if origin is None else origin,
                          strict and key == next(iter(use)))
        stamps[key] = stamps[key][i0:i1]
        data[key] = _channel(src, key, name, units, signs, i0, i1, taken)
    time_s, data = common_time(src, use, data, stamps, fill_gaps)
    time_s, data = _drop_held(src, time_s, data, held_keys, 0)
    return time_s, data, first, first


def _channel(src: Source, key: str, name: str, units: dict, signs: dict, i0: int = 0, i1=None,
             taken: dict | None = None) -> np.ndarray:
    """Rows i0:i1 of one channel as floats in SI (its sign flipped when asked), checked to be finite; where its
    unit came from (given, the file, the name, assumed) goes into ``taken``."""
    raw = src.values(name)
    if i0 or i1 is not None:
        raw = raw[i0:i1]
    values = as_floats(src, name, key, raw)
    check_not_flag(src, key, name, raw, values)
    check_finite(src, key, name, values)
    unit, origin = channel_unit(src, key, name, units)
    if taken is not None:
        taken[key] = origin
    factor = unit_factor(unit, key, src.label, name) * signs.get(key, 1.0)
    if factor != 1.0:
        owned = values is not raw or not isinstance(src, FrameSource)  # never change a caller's DataFrame
        values = np.multiply(values, factor, out=values if owned and values.flags.writeable else None)
    return values


def _from_steps(src: Source, name: str, dt: np.ndarray) -> np.ndarray:
    """Time stamps from the time since the previous row: 0 at the first row (whose own step is not used), then
    the cumulative sum; a step that is not positive is refused, naming its row."""
    bad = np.flatnonzero(dt[1:] <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise InputError(f"{src.label}, {src.where(i)}, column {name} (channel dt): time step {src.raw(name, i)} is "
                         "not positive; each row's time since the previous row must be > 0.")
    t = np.empty(dt.size)
    if dt.size:
        t[0] = 0.0
        np.cumsum(dt[1:], out=t[1:])
    return t


def _drop_held(src: Source, t: np.ndarray, data: dict, keys, i0: int):
    """Drop held repeats (see ``ehm.inputs.readers.HELD_SHARE``), with a note; the source's rows kept for messages.
    ``keys`` None: held samples are not looked for (``drop_held=False``)."""
    if keys is None or not all(k in data for k in keys):
        return t, data
    held = held_rows([data[k] for k in keys])
    if held is None:
        return t, data
    starts, share, run = held
    reader_note(held_note(src.label, keys, t, starts, share, run), 4 if not src.per_channel_time else 5)
    if not src.per_channel_time:
        src.rows = starts + i0
    return t[starts], {k: v[starts] for k, v in data.items()}


def _stack(data: dict, keys) -> np.ndarray:
    """Columns into one (n, 3) read-only array, each channel's own array let go as soon as it is copied in."""
    out = np.empty((data[keys[0]].size, len(keys)))
    for j, k in enumerate(keys):
        out[:, j] = data.pop(k)
    return _frozen(out)


def _frozen(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


def _gyro_unit_words(src: Source, use: dict, units: dict, taken: dict) -> str | None:
    """How the gyro's unit was found, for the IMU route's messages ("in deg/s, as their names say")."""
    if "wx" not in use:
        return None
    unit = channel_unit(src, "wx", use["wx"], units)[0]
    return assumed_words(taken.get("wx", ASSUMED), unit or "rad/s")


def _cut_handling(label: str, time_s: np.ndarray, acc: np.ndarray, rates, window):
    """The log without a handled start and end (:func:`ehm.inputs.handling.find_handling`), with one note naming
    the cut; its time axis starts at 0 again."""
    offset = float(window[0] or 0.0) if window is not None else 0.0
    i0, i1, stretches = find_handling(time_s, acc, offset_s=offset)
    if not stretches:
        return time_s, acc, rates, ()
    reader_note(handling_note(label, stretches), 3)
    time_s = _frozen(time_s[i0:i1] - time_s[i0])
    acc = _frozen(acc[i0:i1].copy())
    rates = None if rates is None else _frozen(rates[i0:i1].copy())
    return time_s, acc, rates, stretches


def _describe(src: Source, source, time_s: np.ndarray, gsrc=None, window=None, stretches=()) -> str:
    base = os.path.basename(str(source)) if not isinstance(src, FrameSource) else src.label
    if gsrc is not None:
        base += f" with the gyro of {os.path.basename(gsrc.label)}"
    if window is not None:
        start, end = window
        base += f" (cut from {start or 0:g} s" + (f" to {end:g} s)" if end is not None else " to the end)")
    if stretches:
        cuts = " and ".join(f"{h.where} {h.start_s:.1f}-{h.end_s:.1f} s" for h in stretches)
        base += f" (handled {cuts} left out)"
    description = f"from {base}, {time_s.size} samples, {float(time_s[-1] - time_s[0]):g} s"
    if src.first_comment:  # a file's first comment line describes it (e.g. "SYNTHETIC city drive ...")
        description = f"{src.first_comment} ({description})"
    return description
