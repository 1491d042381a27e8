"""Input checks of the comfort functions: each refuses a bad argument in one sentence naming it."""

from __future__ import annotations

import math

from ...errors import InputError, finite_samples


def positive_float(value, arg: str) -> float:
    """``value`` as a positive finite float; InputError naming ``arg`` otherwise."""
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{arg} must be a positive number; got {value!r}.") from None
    if not math.isfinite(out) or out <= 0.0:
        raise InputError(f"{arg} must be a positive finite number; got {value!r}.")
    return out


def non_negative_float(value, arg: str, what: str = "number") -> float:
    """``value`` as a finite float >= 0; InputError naming ``arg`` (a ``what``) otherwise."""
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{arg} must be a non-negative {what}; got {value!r}.") from None
    if not math.isfinite(out) or out < 0.0:
        raise InputError(f"{arg} must be a finite, non-negative {what}; got {value!r}.")
    return out


def signal_1d(values, arg: str):
    """``values`` as a 1-D array of finite samples (:func:`ehm.errors.finite_samples`), named ``arg``."""
    return finite_samples(arg, values)
