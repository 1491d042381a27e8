"""Channel names and units: the keys a motion is made of, their default names, ``KEY=VALUE`` arguments, and unit
strings (a file's, a column's ``[unit]``, the caller's) converted to ehm's SI units with pint."""

from __future__ import annotations

import functools
import re

from ..errors import InputError

#: The quantities a motion is made of (``dt``: time since the previous row, read instead of ``time``).
CHANNEL_KEYS = ("time", "ax", "ay", "az", "wx", "wy", "wz", "dt")
#: Default source names: the motion CSV columns.
DEFAULT_CHANNELS = {"time": "time_s", "ax": "ax_mps2", "ay": "ay_mps2", "az": "az_mps2",
                    "wx": "wx_radps", "wy": "wy_radps", "wz": "wz_radps", "dt": None}
#: Units inside ehm.
SI_UNITS = {"time": "s", "ax": "m/s^2", "ay": "m/s^2", "az": "m/s^2", "wx": "rad/s", "wy": "rad/s", "wz": "rad/s",
            "dt": "s"}
_ACC, _RATES = ("ax", "ay", "az"), ("wx", "wy", "wz")
_KIND = {"time": ("a time", "'s' or 'ms'"), "dt": ("a time step", "'s' or 'ms'"), **{k: ("an acceleration", "'m/s^2' or 'g'") for k in _ACC},
         **{k: ("an angular rate", "'rad/s' or 'deg/s'") for k in _RATES}}
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


def _mapping(value, arg: str) -> dict:
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise InputError(f"{arg} must map keys ({', '.join(CHANNEL_KEYS)}) to names; got {type(value).__name__}.")
    for key, v in value.items():
        if key not in CHANNEL_KEYS:
            raise InputError(f"{arg}: unknown key {key!r}; use {', '.join(CHANNEL_KEYS)}.")
        if v is not None and not isinstance(v, str):
            raise InputError(f"{arg}[{key!r}] must be a string; got {v!r}.")
    return dict(value)


def _listed(names) -> str:
    names = [str(n) for n in names]
    if len(names) > _LISTED:
        return ", ".join(names[:_LISTED]) + f" and {len(names) - _LISTED} more"
    return ", ".join(names) if names else "none"


@functools.cache
def _registry():
    import pint

    return pint.UnitRegistry()


def _unit_text(unit: str, key: str) -> str:
    text = unit.strip().replace("²", "^2").replace("°", "deg").replace("µ", "u")
    if key in _ACC:  # loggers' g is standard gravity, not the gram
        if re.fullmatch(r"[gG][nN0]?", text):
            return "standard_gravity"
        if text in ("mg", "mG"):
            return "milli_standard_gravity"
        text = re.sub(r"^m/s\s*2$", "m/s^2", text)
    if key in _RATES and text.lower() in ("dps", "deg/sec"):
        return "deg/s"
    return text


def _factor(unit: str, key: str, label: str, name: str) -> float:
    """Multiplier from ``unit`` to ehm's SI unit of ``key`` (pint)."""
    text = _unit_text(unit, key)
    if text == SI_UNITS[key] or (key == "time" and text in ("s", "sec")):
        return 1.0
    import pint

    ureg = _registry()
    what, examples = _KIND[key]
    try:
        q = ureg.Quantity(1.0, text)
    except (pint.errors.UndefinedUnitError, pint.errors.DefinitionSyntaxError, AttributeError, TypeError,
            ValueError, AssertionError):
        raise InputError(f"{label}, channel {key} ({name!r}): {unit!r} is not a unit pint knows (use e.g. {examples})."
                         ) from None
    try:
        return float(q.to(SI_UNITS[key]).magnitude)
    except pint.errors.DimensionalityError:
        raise InputError(f"{label}, channel {key} ({name!r}): unit {unit!r} is not {what} (use e.g. {examples}).") \
            from None


def _bracket_unit(name: str) -> str:
    """The unit in brackets at the end of a name (``"acc_x [g]"`` -> ``"g"``); a whole number in brackets is
    a matrix column (``"acc[0]"``, MATLAB), not a unit, and gives ``""``."""
    m = re.search(r"\[([^\]]+)\]\s*$", name)
    text = m.group(1).strip() if m else ""
    return "" if re.fullmatch(r"\d+", text) else text
