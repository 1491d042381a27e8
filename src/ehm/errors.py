"""Errors that reach users as one clear sentence.

Every problem with user input (a file, a parameter, a command-line value) or a
simulation that goes wrong raises :class:`EhmError` with a message that names
what is wrong and where.  The command-line interface prints that message and
exits with a non-zero code, without a traceback.
"""

from __future__ import annotations

import math
from numbers import Real

import numpy as np


class EhmError(Exception):
    """A user-facing error: its message is one sentence naming what and where."""


class InputError(EhmError, ValueError):
    """Bad input: a malformed file, a value out of range, an unknown name."""


class DivergenceError(EhmError, RuntimeError):
    """A simulation became unstable; the message gives the simulated time, and ``time_s`` holds it [s] from the
    motion's first sample (None where it is not known, or while settling)."""

    time_s: float | None = None


class EhmWarning(UserWarning):
    """A warning of ehm's own, one sentence (the command line prints these, and only these, as ``ehm: warning:``)."""


#: The longest repr :func:`describe` shows as it is; a longer value is named by its type (and size).
_SHORT_REPR = 60


def describe(value: object) -> str:
    """``value`` in a few words for a message: the repr of a short scalar or string (``'abc'``, ``42``, ``None``);
    the type and size of an array, a table or a sequence (``a float64 array of shape (100, 3)``, ``a DataFrame of
    shape (10, 4)``, ``a list of 2 items ([1, 2])``, the items only when short); else the repr when short, or the
    type (never a multi-line repr cut off mid-way)."""
    kind = "array" if isinstance(value, np.ndarray) else type(value).__name__
    shape = getattr(value, "shape", None)
    if isinstance(shape, tuple) and shape:  # numpy arrays, pandas frames and series, xarray
        words = f"{value.dtype} {kind}" if isinstance(value, np.ndarray) else kind
        return f"{'an' if words[0] in 'aeio' else 'a'} {words} of shape {shape}"
    text = repr(value)
    short = len(text) <= _SHORT_REPR and "\n" not in text
    if isinstance(value, (list, tuple, set, frozenset, dict)):
        return f"a {kind} of {len(value)} item{'s' if len(value) != 1 else ''}" + (f" ({text})" if short else "")
    if short:
        return text
    if isinstance(value, str):
        return f"a str of {len(value)} characters"
    return f"{'an' if kind[0] in 'aeioAEIO' else 'a'} {kind}"


def finite_number(func: str, name: str, value: object) -> float:
    """``value`` as a finite float, or an :class:`InputError` naming ``func`` and the argument ``name`` (a bool is
    no number here)."""
    if isinstance(value, bool) or not isinstance(value, Real):  # (numpy.bool_ is no Real either)
        raise InputError(f"{func}: {name} must be a number, got {value!r}.")
    result = float(value)
    if not math.isfinite(result):
        raise InputError(f"{func}: {name} must be finite, got {result!r}.")
    return result


def positive_number(func: str, name: str, value: object) -> float:
    """``value`` as a finite float above 0, or an :class:`InputError` naming ``func`` and ``name``."""
    result = finite_number(func, name, value)
    if result <= 0.0:
        raise InputError(f"{func}: {name} must be > 0, got {result!r}.")
    return result


def frequencies_hz(values: object, name: str = "freq_hz", positive: bool = False) -> np.ndarray:
    """``values`` as an array of frequencies [Hz]; one sentence (:class:`InputError`) unless numbers, finite and
    non-negative (``positive``: above 0, as a frequency response needs: 0 Hz is the static gain, not a response,
    and a negative frequency is the mirror of a positive one)."""
    try:
        f = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be numbers in Hz; got {type(values).__name__}.") from None
    if positive and np.all(np.isfinite(f)) and np.any(f <= 0):
        bad = f.ravel()[np.flatnonzero(f.ravel() <= 0)[0]]
        raise InputError(f"{name} holds {bad:g} Hz: a frequency response needs frequencies above 0 Hz; "
                         "leave out 0 and below (e.g. start at 0.1 Hz).")
    if not np.all(np.isfinite(f)) or np.any(f < 0):
        raise InputError(f"{name} must be finite and non-negative frequencies in Hz; got {values!r}.")
    return f


def finite_samples(name: str, values: object, advice: str = "fill or cut the gap first") -> np.ndarray:
    """``values`` as a 1-D float array of at least one finite sample, or an :class:`InputError` naming ``name`` and
    the first bad sample (and ``advice``: what to do about it)."""
    try:
        arr = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a 1-D array of numbers, not {describe(values)}.") from None
    if arr.ndim != 1:
        raise InputError(f"{name} must be a 1-D array of samples, not of shape {arr.shape}.")
    if arr.size == 0:
        raise InputError(f"{name} must hold at least one sample; got an empty array.")
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        more = f" and {bad.size - 1} more" if bad.size > 1 else ""
        raise InputError(f"{name} has a non-finite value ({arr[bad[0]]}) at sample {bad[0]}{more}; {advice}.")
    return arr
