"""Channel names and units: the keys a motion is made of, their default names, ``KEY=VALUE`` arguments, and the
unit a channel's name carries (``[g]``, ``(deg/s)``, `` in g``, ``_mps2``, ``uptimeNanos``); pint converts them in
:mod:`ehm.inputs.readers.units`."""

from __future__ import annotations

import re

from ...errors import InputError

#: The quantities a motion is made of (``dt``: time since the previous row, read instead of ``time``).
CHANNEL_KEYS = ("time", "ax", "ay", "az", "wx", "wy", "wz", "dt")
#: Default source names: the motion CSV columns.
DEFAULT_CHANNELS = {"time": "time_s", "ax": "ax_mps2", "ay": "ay_mps2", "az": "az_mps2",
                    "wx": "wx_radps", "wy": "wy_radps", "wz": "wz_radps", "dt": None}
#: Units inside ehm.
SI_UNITS = {"time": "s", "ax": "m/s^2", "ay": "m/s^2", "az": "m/s^2", "wx": "rad/s", "wy": "rad/s", "wz": "rad/s",
            "dt": "s"}
ACC_KEYS, RATE_KEYS = ("ax", "ay", "az"), ("wx", "wy", "wz")
KEY_KINDS = {"time": ("a time", "'s' or 'ms'"), "dt": ("a time step", "'s' or 'ms'"),
             **{k: ("an acceleration", "'m/s^2' or 'g'") for k in ACC_KEYS},
             **{k: ("an angular rate", "'rad/s' or 'deg/s'") for k in RATE_KEYS}}
_LISTED = 25  #: Most channel names listed in a message.


def parse_assignments(values, option: str) -> dict:
    """``["ax=AccX", "az=AccZ"]`` (repeatable command-line options) -> ``{"ax": "AccX", "az": "AccZ"}``.

    An empty value (``time=``) gives None: for ``--channel time=``, a source without a time channel.
    """
    out = {}
    for text in values or []:
        key, sep, value = str(text).partition("=")
        key = key.strip()
        if not sep or key not in CHANNEL_KEYS:
            raise InputError(f"{option} {text!r}: use KEY=VALUE with KEY one of {', '.join(CHANNEL_KEYS)}.")
        if key in out:
            raise InputError(f"{option} {text!r}: {key} is given twice.")
        out[key] = value.strip() or None
    return out


def mapping_arg(value, arg: str) -> dict:
    """A key -> channel name mapping argument (``channels``, ``units``) checked: known keys, string values."""
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise InputError(f"{arg} must map keys ({', '.join(CHANNEL_KEYS)}) to names; got {type(value).__name__}.")
    for key, v in value.items():
        if key not in CHANNEL_KEYS:
            raise InputError(f"{arg}: unknown key {key!r}; use {', '.join(CHANNEL_KEYS)}.")
        if v is not None and not isinstance(v, str):
            raise InputError(f"{arg}[{key!r}] must be a string; got {v!r}.")
        if v is None and arg == "channels" and key in ACC_KEYS:
            raise InputError(f"channels: {key} is set to None (--channel {key}=), but ax, ay and az cannot be left "
                             "out: name a column for each (for an axis the log lacks, a column of zeros).")
    return dict(value)


def listed_names(names) -> str:
    """Names joined by commas for a message, the first 25 of them (then "and N more")."""
    names = [str(n) for n in names]
    if len(names) > _LISTED:
        return ", ".join(names[:_LISTED]) + f" and {len(names) - _LISTED} more"
    return ", ".join(names) if names else "none"


#: Where a channel's unit came from, from the strongest word to the weakest: the caller (``units``, ``--unit``),
#: the file (an MDF channel's unit, a Parquet field's ``unit``, a DataFrame's ``attrs["units"]``), the channel's
#: name (``Accelerometer X (g)``, ``time_ms``), its values (``uptimeNanos`` counting whole nanoseconds), or
#: nothing (ehm's SI unit assumed).  The plausibility checks refuse what was assumed and warn about the rest.
GIVEN, FILE, NAME, INFERRED, ASSUMED = "given", "file", "name", "inferred", "assumed"

#: A unit at the end of a name: in brackets (``acc_x [g]``), in parentheses (``Accelerometer X (g)``,
#: ``accelerometerAccelerationX(G)``), after " in " (``Acceleration in m/s^2``).
_IN_BRACKETS = re.compile(r"\[([^\[\]]+)\]\s*$")
_IN_PARENS = re.compile(r"\(([^()]+)\)\s*$")
_AFTER_IN = re.compile(r"\s+in\s+(\S+)\s*$", re.IGNORECASE)
#: The last word of a name after ``_``, ``-``, ``.`` or a blank (``time_ms``, ``ax_mps2``, ``Gyro X °/s``) is
#: a unit only when it is one of these for the channel's kind (words folded as :func:`_folded`): a short
#: word such as ``s`` or ``g`` is read as a unit of a time or an acceleration only.
_LAST_WORD = re.compile(r"(?:^|[_\s.\-])([^_\s.\-]+)\s*$")
_WORDS = {
    "time": {"s": "s", "sec": "s", "secs": "s", "second": "s", "seconds": "s", "ms": "ms", "msec": "ms",
             "millis": "ms", "milliseconds": "ms", "us": "us", "usec": "us", "micros": "us", "microseconds": "us",
             "ns": "ns", "nsec": "ns", "nanos": "ns", "nanoseconds": "ns"},
    "acc": {"g": "g", "mg": "mg", "mps2": "m/s^2", "ms2": "m/s^2", "m/s2": "m/s^2", "m/s/s": "m/s^2",
            "mpss": "m/s^2"},
    "rate": {"dps": "deg/s", "degps": "deg/s", "degs": "deg/s", "deg/s": "deg/s", "deg/sec": "deg/s",
             "radps": "rad/s", "rads": "rad/s", "rad/s": "rad/s", "rad/sec": "rad/s"},
}
#: A time count whose name says what it counts, inside a word (``uptimeNanos``, ``elapsedRealtimeNanos``,
#: ``timestampMillis``): a hint, taken only when the values are whole numbers at a plausible step in that unit.
_HINTS = (("ns", re.compile(r"nano", re.IGNORECASE)), ("us", re.compile(r"micro", re.IGNORECASE)),
          ("ms", re.compile(r"milli", re.IGNORECASE)))


def _kind(key: str) -> str:
    return "time" if key in ("time", "dt") else "acc" if key in ACC_KEYS else "rate"


def _folded(text: str) -> str:
    """A unit word as the tables hold it: lower case, no blanks or ``^``, ``²`` as 2, ``°`` as deg."""
    text = text.strip()
    for sign, word in (("²", "2"), ("°", "deg"), ("º", "deg"), ("µ", "u"), ("μ", "u")):
        text = text.replace(sign, word)
    return re.sub(r"[\s^]", "", text).lower()


def name_unit(name: str, key: str) -> tuple[str, str]:
    """The unit a channel's name carries, and how (``"brackets"``, ``"parens"``, ``"in"``, ``"word"``, or
    ``"hint"`` for a time count named inside a word); ``("", "")`` when it carries none.

    Whole numbers in brackets or parentheses are a matrix column (``acc[0]``, ``acc(1)``), not a unit.  What
    is in parentheses or after " in " may be words (``Acc (seat pad)``): the caller takes it as a unit only
    when pint knows it (``"parens"``, ``"in"``); a unit in brackets is always meant as one (``"brackets"``).
    """
    name = str(name)
    for form, pattern in (("brackets", _IN_BRACKETS), ("parens", _IN_PARENS), ("in", _AFTER_IN)):
        m = pattern.search(name)
        if m:
            text = m.group(1).strip()
            if text and not re.fullmatch(r"\d+", text):
                return text, form
            if form == "brackets":
                return "", ""
    m = _LAST_WORD.search(name)
    if m:
        folded = _folded(m.group(1))
        if m.group(1) == "G" and _kind(key) == "acc":
            folded = "g"
        unit = _WORDS[_kind(key)].get(folded)
        if unit:
            return unit, "word"
    if key == "time":
        for unit, pattern in _HINTS:
            if pattern.search(name):
                return unit, "hint"
    return "", ""


def bare_name(name) -> str:
    """A column's name without its unit, folded to lower-case letters and digits (``Accelerometer X (g)`` ->
    ``accelerometerx``), for guessing which channel it holds."""
    name = str(name)
    for pattern in (_IN_BRACKETS, _IN_PARENS, _AFTER_IN):
        name = pattern.sub("", name)
    return re.sub(r"[^a-z0-9]", "", name.lower())


def channel_candidates(key: str, names) -> list:
    """The columns of ``names`` that look like channel ``key`` (``x`` or ``AccX`` for ax, ``Gyroscope X (deg/s)``
    for wx, ``Time (s)``, ``timestamp`` or ``uptimeNanos`` for time, ``delay_ms`` for dt): for a message's suggested
    fix, never used to read."""
    bare = {n: bare_name(n) for n in names}
    if key == "time":
        return [n for n, b in bare.items() if b in ("t", "sec", "seconds") or "time" in b or b.endswith("nanos")]
    if key == "dt":
        return [n for n, b in bare.items() if b in ("dt", "deltat", "interval") or "delay" in b]
    axis = key[1]
    gyro = ("gyr", "rot", "rate", "angvel", "omega")
    is_gyro = {n: any(w in b for w in gyro) or b in (f"w{axis}", f"g{axis}") for n, b in bare.items()}
    if key in ACC_KEYS:
        return [n for n, b in bare.items() if not is_gyro[n] and (b in (axis, f"a{axis}") or (
            b.endswith(axis) and "acc" in b))]
    return [n for n, b in bare.items() if is_gyro[n] and b.endswith(axis)]


def guess_channel(key: str, names) -> str | None:
    """The one column :func:`channel_candidates` finds for ``key``, or None when none or several do."""
    found = channel_candidates(key, names)
    return found[0] if len(found) == 1 else None
