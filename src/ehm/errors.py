"""Errors that reach users as one clear sentence.

Every problem with user input (a file, a parameter, a command-line value) or a
simulation that goes wrong raises :class:`EhmError` with a message that names
what is wrong and where.  The command-line interface prints that message and
exits with a non-zero code, without a traceback.
"""

from __future__ import annotations

import math
from numbers import Real


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
