"""Input checks of the comfort functions: each refuses a bad argument in one sentence naming it."""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError


def _positive_float(value, arg: str) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{arg} must be a positive number; got {value!r}.") from None
    if not math.isfinite(out) or out <= 0.0:
        raise InputError(f"{arg} must be a positive finite number; got {value!r}.")
    return out


def _non_negative_float(value, arg: str, what: str = "number") -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{arg} must be a non-negative {what}; got {value!r}.") from None
    if not math.isfinite(out) or out < 0.0:
        raise InputError(f"{arg} must be a finite, non-negative {what}; got {value!r}.")
    return out


def _signal_1d(values, arg: str) -> np.ndarray:
    try:
        out = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{arg} must be a 1-D array of numbers; got {type(values).__name__}.") from None
    if out.ndim != 1:
        raise InputError(f"{arg} must be a 1-D array; got an array of shape {out.shape}.")
    if out.size == 0:
        raise InputError(f"{arg} must hold at least one sample; got an empty array.")
    if not np.all(np.isfinite(out)):
        bad = int(np.argmin(np.isfinite(out)))
        raise InputError(f"{arg} must be finite; got a non-finite value at sample {bad}.")
    return out
