"""Units: pint conversions to ehm's SI units (one registry for the readers), a channel's unit from the caller,
the file or its name, and time stamps in seconds from the first sample.

Time stamps may be numbers in s, ms, µs or ns (from any origin: a logger's clock, Unix time, uptime since boot),
date-time values (a DataFrame's or Parquet file's datetime column) or date-time strings (ISO 8601 such as
``2026-11-25T14:03:07.123Z``, or ``25/11/2026 14:03:07.123``, ``11/25/2026 ...``, ``25.11.2026 ...``,
``14:03:07.123``); a strftime format given as the time's unit (``--unit "time=%d/%m/%Y %H:%M:%S"``) reads
any other.  The time axis starts at 0 at the first sample.  A number's unit, when neither the caller, the file
nor the name gives it, is inferred only where nothing else fits (whole numbers under a name counting
nanoseconds, ``uptimeNanos``; whole numbers of the size of Unix time in ns); otherwise seconds are assumed, and
:func:`ehm.inputs.readers.checks.check_time_unit` refuses a step that is not plausible in seconds.
"""

from __future__ import annotations

import functools
import re

import numpy as np

from ...errors import InputError
from .base import Source, as_floats, column_words
from .channels import ACC_KEYS, ASSUMED, FILE, GIVEN, INFERRED, KEY_KINDS, NAME, RATE_KEYS, SI_UNITS, name_unit

#: The shortest and the longest plausible median time step [s] (100 kHz to 2 Hz) of a logger's recording: see
#: :func:`ehm.inputs.readers.checks.check_time_unit`.  Here they decide whether a unit inferred from a name fits.
MIN_STEP_S = 1e-5
MAX_STEP_S = 0.5
#: Unix time in ns from 2000 to 2100: whole numbers in this range are ns since 1970, as no other count of
#: time reaches it (in µs it would be 30 000 years since boot).
_EPOCH_NS = (9.46e17, 4.11e18)
_TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}


@functools.cache
def _registry():
    """The readers' one pint UnitRegistry."""
    import pint

    return pint.UnitRegistry()


def _unit_text(unit: str, key: str) -> str:
    """A unit as pint reads it for a channel of ``key``: a logger's ``g``/``G`` of an acceleration is standard
    gravity (pint's ``g`` is the gram, its ``G`` the gauss), ``mg`` a thousandth of it; ``m/s2``, ``m/s²``,
    ``dps``, ``°/s`` and ``µs`` as they are meant."""
    text = unit.strip().replace("²", "^2").replace("°", "deg").replace("º", "deg").replace("µ", "u") \
        .replace("μ", "u")
    if key in ACC_KEYS:  # loggers' g is standard gravity, not the gram
        if re.fullmatch(r"[gG][nN0]?", text):
            return "standard_gravity"
        if text in ("mg", "mG"):
            return "millistandard_gravity"
        text = re.sub(r"^m\s*/\s*s\s*\^?\s*2$", "m/s^2", text)
        if text.lower() in ("mps2", "ms2", "m/s/s", "ms^-2", "m s^-2", "m*s^-2", "m.s^-2", "m s-2", "m.s-2"):
            return "m/s^2"
    if key in RATE_KEYS:
        low = text.lower().replace(" ", "")
        if low in ("dps", "deg/sec", "degps", "degree/s", "degrees/s", "degrees/sec"):
            return "deg/s"
        if low in ("radps", "rad/sec", "rads"):
            return "rad/s"
    if key in ("time", "dt"):
        low = text.lower()
        return {"sec": "s", "secs": "s", "msec": "ms", "usec": "us", "nsec": "ns", "millis": "ms", "micros": "us",
                "nanos": "ns"}.get(low, text)
    return text


def unit_factor(unit: str, key: str, label: str, name: str) -> float:
    """Multiplier from ``unit`` to ehm's SI unit of ``key`` (pint)."""
    text = _unit_text(unit, key)
    if text == SI_UNITS[key] or (key in ("time", "dt") and text in ("s", "sec")):
        return 1.0
    import pint

    what, examples = KEY_KINDS[key]
    try:
        q = _registry().Quantity(1.0, text)
    except (pint.errors.UndefinedUnitError, pint.errors.DefinitionSyntaxError, AttributeError, TypeError,
            ValueError, AssertionError):
        raise InputError(f"{label}, channel {key} ({name!r}): {unit!r} is not a unit pint knows (use e.g. {examples})."
                         ) from None
    try:
        return float(q.to(SI_UNITS[key]).magnitude)
    except pint.errors.DimensionalityError:
        raise InputError(f"{label}, channel {key} ({name!r}): unit {unit!r} is not {what} (use e.g. {examples}).") \
            from None


def _is_unit(text: str, key: str) -> bool:
    """Whether pint reads ``text`` as a unit with a dimension (a number or an unknown word is no unit)."""
    import pint

    try:
        q = _registry().Quantity(1.0, _unit_text(text, key))
    except Exception:  # noqa: BLE001 - pint raises several kinds for words that are not units
        return False
    return not q.dimensionless or isinstance(q.magnitude, pint.Quantity)


def channel_unit(src: Source, key: str, name: str, units: dict) -> tuple[str, str]:
    """(unit, where it came from: GIVEN, FILE, NAME or ASSUMED) of one channel.

    The caller's unit wins over the name's; a file's own unit (MDF, Parquet, DataFrame ``attrs``) and a
    different one from the caller are refused in one sentence.  A time count named inside a word
    (``uptimeNanos``) is left to :func:`time_seconds`, which checks its values (ASSUMED here).
    """
    own = src.unit_of(name) if hasattr(src, "unit_of") else src.units.get(name, "")
    given = units.get(key)
    if (own and given and "%" not in given
            and unit_factor(own, key, src.label, name) != unit_factor(given, key, src.label, name)):
        raise InputError(f"{src.label}, channel {key} ({name!r}): the file gives the unit {own!r}, the units argument "
                         f"{given!r}; leave the argument out.")
    if given:
        return given, GIVEN
    if own:
        return own, FILE
    text, form = name_unit(name, key)
    if form in ("brackets", "word") or (form in ("parens", "in") and _is_unit(text, key)):
        return text, NAME
    return SI_UNITS[key], ASSUMED


# --------------------------------------------------------------------------
# time stamps
# --------------------------------------------------------------------------


def time_seconds(src: Source, name: str, raw, units: dict) -> tuple[np.ndarray, str, str, float]:
    """A time channel as seconds from its first sample: (times, unit, where the unit came from, the first sample's
    own stamp in seconds on the file's clock: to join two files of one clock).

    Numbers are scaled by their unit (the caller's, the file's, the name's, inferred, or seconds assumed);
    whole numbers are shifted before they become floats, so that ns since 1970 keep their nanoseconds.
    Date-time values and strings are read as such (their unit is ``"date-time"``).
    """
    arr = np.asarray(raw)
    given = units.get("time")
    if given and "%" in given:  # a strftime format: date-time strings in that format
        arr = _date_times(src, name, arr, [given])
    elif arr.dtype.kind in "OSUT" and arr.size:
        arr = _numbers_or_dates(src, name, arr, given)
    if arr.dtype.kind in "Mm":
        arr = arr.astype("datetime64[ns]" if arr.dtype.kind == "M" else "timedelta64[ns]")
        ns = arr.view(np.int64)
        start = float(ns[0]) / 1e9 if ns.size and not np.isnat(arr[0]) else 0.0
        return _from_ns(ns, np.isnat(arr)), "date-time", GIVEN if given else FILE, start
    unit, origin = channel_unit(src, "time", name, units)
    if origin == ASSUMED:
        unit, origin = _inferred_time_unit(name, arr)
    factor = unit_factor(unit, "time", src.label, name)
    if arr.dtype.kind in "iu" and arr.size:
        return (arr.astype(np.int64) - np.int64(arr[0])).astype(float) * factor, unit, origin, float(arr[0]) * factor
    values = as_floats(src, name, "time", arr)
    start = 0.0
    if values.size and np.isfinite(values[0]):
        start = float(values[0]) * factor
        values = values - values[0]
    return (values * factor if factor != 1.0 else values), unit, origin, start


def _from_ns(ns: np.ndarray, missing: np.ndarray) -> np.ndarray:
    t = np.full(ns.size, np.nan)
    if ns.size and not missing[0]:
        t[~missing] = (ns[~missing] - ns[0]).astype(float) / 1e9
    return t


def _whole(arr: np.ndarray) -> bool:
    """Whether the values are whole numbers (an integer column, or floats without fractions)."""
    if arr.dtype.kind in "iu":
        return True
    if arr.dtype.kind != "f" or not arr.size or not np.isfinite(arr).all():
        return False
    return bool(np.all(arr == np.round(arr)))


def _inferred_time_unit(name: str, arr: np.ndarray) -> tuple[str, str]:
    """The unit of a time count whose unit nobody gives: ``(unit, INFERRED)`` where only one fits, else
    ``("s", ASSUMED)``.

    One fits when the values are whole numbers at a median step that is plausible in that unit and not in
    seconds, and either the name counts that unit inside a word (``uptimeNanos``, ``timestampMillis``) or the
    numbers are of the size of Unix time in ns (nothing else counts that high).
    """
    if arr.size < 3 or not _whole(arr):
        return "s", ASSUMED
    steps = np.diff(arr.astype(np.int64) if arr.dtype.kind in "iu" else arr)
    step = float(np.median(steps))
    text, form = name_unit(name, "time")
    candidates = [text] if form == "hint" else ["ns"] if _EPOCH_NS[0] <= float(arr[0]) <= _EPOCH_NS[1] else []
    for unit in candidates:
        if MIN_STEP_S <= step * _TIME_UNITS[unit] <= MAX_STEP_S and not MIN_STEP_S <= step <= MAX_STEP_S:
            return unit, INFERRED
    return "s", ASSUMED


def _numbers_or_dates(src: Source, name: str, arr: np.ndarray, given) -> np.ndarray:
    """Strings (or objects) of a time column: numbers as floats, else date-times as datetime64[ns]."""
    import pandas as pd

    series = pd.Series(arr, dtype=object)
    text = series.astype(str).str.strip()
    filled = series.notna().to_numpy() & (text != "").to_numpy() & (text.str.lower() != "nan").to_numpy()
    numeric = pd.to_numeric(series.where(filled), errors="coerce").isna().to_numpy()
    if not np.any(filled & numeric) or (filled.any() and not numeric[np.flatnonzero(filled)[0]]):
        return as_floats(src, name, "time", arr)  # numbers (one of them maybe not): the number's messages
    if given:
        i = int(np.flatnonzero(filled)[0])
        raise InputError(f"{src.label}, {src.where(i)}, {column_words(src, name, 'time')}: the time stamps are "
                         f"dates and times ({text.iloc[i]!r}), the units argument {given!r}; give their format, e.g. "
                         "--unit 'time=%d/%m/%Y %H:%M:%S', or leave the argument out.")
    first = series[filled].iloc[0]
    if hasattr(first, "year") and hasattr(first, "hour"):  # datetime objects (a tz-aware column)
        try:
            stamps = pd.to_datetime(series.where(filled), utc=True)
            return _naive_ns(stamps)
        except (ValueError, TypeError):
            pass
    return _date_times(src, name, text.where(filled, None).to_numpy(dtype=object), None)


#: Date-time layouts tried after ISO 8601, day before month first; all times of day with or without fractions.
_DATES = ("%d/%m/%Y", "%m/%d/%Y", "%Y/%m/%d", "%d.%m.%Y", "%d-%m-%Y", "%d/%m/%y", "%m/%d/%y", "")
_CLOCKS = ("%H:%M:%S.%f", "%H:%M:%S", "%H:%M:%S,%f")


def _naive_ns(stamps) -> np.ndarray:
    """pandas date-times (tz-aware in UTC, or naive) as datetime64[ns], NaT kept."""
    if getattr(stamps.dt, "tz", None) is not None:
        stamps = stamps.dt.tz_convert(None)
    return stamps.to_numpy().astype("datetime64[ns]")


def _date_times(src: Source, name: str, arr: np.ndarray, formats) -> np.ndarray:
    """Date-time strings as seconds from the first (``formats`` given) or as datetime64[ns] (tried: ISO 8601,
    then :data:`_DATES` x :data:`_CLOCKS`); one sentence when none reads them all, when day-first and
    month-first both do and disagree, or when the stamps repeat (whole seconds at a faster rate)."""
    import pandas as pd

    series = pd.Series(arr, dtype=object)
    filled = series.notna().to_numpy() & (series.astype(str).str.strip() != "").to_numpy()
    where_words = column_words(src, name, "time")
    i0 = int(np.flatnonzero(filled)[0]) if filled.any() else 0
    tries = formats or ["ISO8601"] + [f"{d}{sep}{c}" if d else c for d in _DATES
                                       for sep in ((" ", "T", ", ") if d else ("",)) for c in _CLOCKS]
    read = {}

    def attempt(fmt):
        try:
            pd.to_datetime(series[filled].iloc[:1], format=fmt, utc=True)  # the first stamp, then all
            read[fmt] = _naive_ns(pd.to_datetime(series.where(filled), format=fmt, utc=True))
        except (ValueError, TypeError, OverflowError):
            return False
        return True

    for fmt in tries:
        if attempt(fmt):
            break
    if not read:
        value = series.iloc[i0]
        how = f"in the format {formats[0]!r}" if formats else \
            "a number or a date and time ehm reads (ISO 8601, or e.g. 25/11/2026 14:03:07.123)"
        hint = "" if formats else "; give its format, e.g. --unit 'time=%Y/%d/%m %H:%M:%S'"
        raise InputError(f"{src.label}, {src.where(i0)}, {where_words}: {value!r} is not "
                         f"{'a date and time ' if formats else ''}{how}{hint}.")
    chosen, stamps = next(iter(read.items()))
    base = stamps.view(np.int64)
    swapped = chosen.replace("%d", "%X").replace("%m", "%d").replace("%X", "%m")
    if not formats and swapped != chosen and attempt(swapped):  # day-first and month-first both read every stamp
        alt = read[swapped].view(np.int64)
        if not np.array_equal(base - base[i0], alt - alt[i0]):
            raise InputError(f"{src.label}, {where_words}: the dates read as {chosen!r} and as {swapped!r} give "
                             f"different times (day and month swapped); give their format, e.g. --unit "
                             f"'time={chosen}'.")
    _check_repeats(src, name, series, stamps)
    return stamps


def _check_repeats(src: Source, name: str, series, stamps: np.ndarray) -> None:
    """Refuse date-time stamps that repeat (a logger writing whole seconds at a faster rate) in one sentence."""
    ok = ~np.isnat(stamps)
    ns = stamps[ok].view(np.int64)
    if ns.size < 2:
        return
    same = np.flatnonzero(np.diff(ns) == 0)
    if not same.size:
        return
    rows = np.flatnonzero(ok)
    i = int(rows[same[0] + 1])
    whole = "whole seconds, " if np.all(ns % 1_000_000_000 == 0) else ""
    raise InputError(f"{src.label}, {src.where(i)}, {column_words(src, name, 'time')}: {same.size} of {ns.size} time "
                     f"stamps repeat the one before ({series.iloc[i]!r}): they are {whole}coarser than the "
                     "samples; take a finer time column (e.g. an uptime in ns) with --channel time=NAME, or none with "
                     "--channel time= and --rate HZ.")
