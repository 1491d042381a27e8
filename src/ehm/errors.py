"""Errors that reach users as one clear sentence.

Every problem with user input (a file, a parameter, a command-line value) or a
simulation that goes wrong raises :class:`EhmError` with a message that names
what is wrong and where.  The command-line interface prints that message and
exits with a non-zero code, without a traceback.
"""

from __future__ import annotations

import functools
import inspect
import math
import os
import sys
import warnings
from collections.abc import Iterable, Mapping
from numbers import Integral, Real

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
        raise InputError(f"{func}: {name} must be a number, got {describe(value)}.")
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


def frequency_grid(func: str, values: object, name: str = "freq_hz", positive: bool = False) -> np.ndarray:
    """``values`` as a 1-D array of at least one frequency [Hz], finite and non-negative (``positive``: above 0, as
    a frequency response needs, :func:`frequencies_hz`), or one sentence (:class:`InputError`) naming ``func`` and
    the argument ``name``."""
    try:
        f = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{func}: {name} must be frequencies in Hz (a list or array of numbers), not "
                         f"{describe(values)}.") from None
    if f.ndim != 1 or f.size == 0:
        raise InputError(f"{func}: {name} must be a list or 1-D array of at least one frequency in Hz, not "
                         f"{describe(values)}.")
    if positive and np.all(np.isfinite(f)) and np.any(f <= 0):
        frequencies_hz(f, f"{func}: {name}", positive=True)  # names the first at or below 0 Hz
    bad = np.flatnonzero(~np.isfinite(f) | (f < 0))
    if bad.size:
        raise InputError(f"{func}: {name} must be finite, non-negative frequencies in Hz; item {bad[0]} is "
                         f"{f[bad[0]]!r}.")
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


class ArgumentError(InputError, TypeError):
    """An argument of a public function of the wrong type (or a call with a missing or unknown argument): an
    :class:`InputError` (one sentence, printed by the command line without a traceback) that is also a
    :class:`TypeError`, as Python's own wrong-type errors are."""


# ---------------------------------------------------------------------------------------------- argument checks
def _is_float(v: object) -> bool:
    return isinstance(v, Real) and not isinstance(v, (bool, np.bool_))


def _is_int(v: object) -> bool:
    return isinstance(v, Integral) and not isinstance(v, (bool, np.bool_))


def _is_path(v: object) -> bool:
    return isinstance(v, (str, os.PathLike))


#: Annotations the checks read (the text of an annotation, each part of a ``|`` union): (accepts, what it is).
_SIMPLE = {
    "None": (lambda v: v is None, "None"),
    "float": (_is_float, "a number"),
    "int": (_is_int, "a whole number"),
    "bool": (lambda v: isinstance(v, (bool, np.bool_)), "True or False"),
    "str": (lambda v: isinstance(v, str), "a str"),
    "Path": (_is_path, "a path (str or pathlib.Path)"),
    "pathlib.Path": (_is_path, "a path (str or pathlib.Path)"),
    "os.PathLike": (_is_path, "a path (str or pathlib.Path)"),
    "dict": (lambda v: isinstance(v, Mapping), "a dict"),
    "Mapping": (lambda v: isinstance(v, Mapping), "a dict"),
    "tuple": (lambda v: isinstance(v, (tuple, list)), "a tuple"),
    "Callable": (callable, "a function"),
    "Iterable": (lambda v: isinstance(v, Iterable) and not isinstance(v, (str, bytes, Mapping)), "an iterable"),
    "list": (lambda v: isinstance(v, (tuple, list)), "a list"),
}
#: Array annotations are left to the function: each checks its samples itself and names the first bad one
#: (``finite_samples``), which says more than a type would.
_ARRAYS = ("np.ndarray", "numpy.ndarray", "ArrayLike")
_ANY = ("Any", "object")


def _plural(what: str) -> str:
    return {"a number": "numbers", "a whole number": "whole numbers", "a str": "strs"}.get(what, what)


def _split(text: str, sep: str) -> list[str]:
    """``text`` split at ``sep`` outside brackets."""
    parts, depth, start = [], 0, 0
    for i, ch in enumerate(text):
        depth += ch == "["
        depth -= ch == "]"
        if ch == sep and depth == 0:
            parts.append(text[start:i].strip())
            start = i + 1
    parts.append(text[start:].strip())
    return parts


def _part(text: str, namespace: dict):
    """One part of an annotation as (accepts, what it is, the item checks of a fixed-size tuple), or None when the
    checks cannot read it (then the argument is not checked)."""
    base, _, inner = text.partition("[")
    base = base.strip()
    if base in _ANY or base in _ARRAYS:
        return None
    if base in _SIMPLE:
        accepts, what = _SIMPLE[base]
        items = None
        if base == "tuple" and inner:
            args = _split(inner[:-1], ",")
            if "..." not in args:
                items = [_annotation(a, namespace) for a in args]
                if any(i is None for i in items):
                    items = None
                else:
                    kinds = {" or ".join(w for _a, w, _i in i) for i in items}
                    what = (f"a pair (tuple) of {_plural(kinds.pop())}" if len(items) == 2 and len(kinds) == 1
                            else f"a tuple of {len(items)} items")
        return accepts, what, items
    try:
        obj = eval(base, namespace)  # a class named in the annotation, resolved where the function is defined
    except Exception:  # a name imported only for type checkers, or an annotation the checks do not read
        return None
    if obj is None:
        return _SIMPLE["None"] + (None,)
    if isinstance(obj, type):
        what = f"an ehm.{obj.__name__}" if obj.__module__.startswith("ehm") else f"a {obj.__name__}"
        hint = getattr(obj, "ARGUMENT_HINT", None)  # where to get one, as the class says
        return (lambda v: isinstance(v, obj)), what + (f" ({hint})" if hint else ""), None
    return None


def _annotation(text: object, namespace: dict):
    """An annotation as a list of its parts' checks, or None when any part is not read (no check)."""
    if not isinstance(text, str):
        text = getattr(text, "__name__", None) if isinstance(text, type) else None
        if text is None:
            return None
    parts = [_part(p, namespace) for p in _split(text, "|")]
    return None if any(p is None for p in parts) else parts


def _check_value(label: str, name: str, value: object, parts: list) -> None:
    for accepts, _what, items in parts:
        if accepts(value):
            if items is not None:  # a fixed-size tuple: its length and each item
                if len(value) != len(items):
                    raise ArgumentError(f"{label}: {name} must hold {len(items)} items, got {describe(value)}.")
                for i, (item, check) in enumerate(zip(value, items, strict=True)):
                    _check_value(label, f"{name}[{i}]", item, check)
            if _is_float(value) and not math.isfinite(float(value)):
                raise InputError(f"{label}: {name} must be finite, got {float(value)!r}.")
            return
    whats = list(dict.fromkeys(what for _a, what, _i in parts))
    if _SIMPLE["Path"][1] in whats and "a str" in whats:  # Path | str
        whats.remove("a str")
    expected = " or ".join(whats)
    raise ArgumentError(f"{label}: {name} must be {expected}, got {describe(value)}.")


def checked(func=None, *, label: str | None = None, namespace: dict | None = None, only: tuple | None = None):
    """Decorator: the public function ``func`` checks its arguments against their annotations before it runs.

    A call with a missing or unknown argument, or an argument whose type is not in its annotation, raises
    :class:`ArgumentError`: one sentence naming the function, the argument, what was given and what is expected.
    Read are ``float`` (a number, not a bool), ``int``, ``bool``, ``str``, ``Path`` (str or path-like),
    ``dict``/``Mapping``, ``tuple``/``list`` (a tuple or a list; each item of a ``tuple[float, float]``), a class
    (an instance; its ``ARGUMENT_HINT`` says where to get one) and ``None``, joined by ``|``; a number that is NaN
    or infinite is refused too.  An argument without an annotation, or whose annotation names what the checks do
    not read (``Any``, a protocol, an array: the function checks its samples and names the first bad one), is
    left to the function; so is every argument not named in ``only``, when given (a function whose own checks
    name more, such as the command-line option, for the rest).  The checks are read from the annotations at the
    first call, so names defined later in the module resolve.

    >>> @checked
    ... def scale(factor: float, name: str | None = None) -> float:
    ...     return 2 * factor
    >>> scale("3")
    Traceback (most recent call last):
    ...
    ehm.errors.ArgumentError: scale: factor must be a number, got '3'.
    """
    if func is None:
        return lambda f: checked(f, label=label, namespace=namespace, only=only)
    sig = inspect.signature(func)
    name = label or func.__qualname__.rpartition("<locals>.")[2].removesuffix(".__init__")
    params = [p for p in sig.parameters.values()
              if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD) and p.name not in ("self", "cls")]
    checks: dict = {}

    def read_checks() -> dict:
        ns = namespace if namespace is not None else getattr(func, "__globals__", {})
        for p in params:
            if p.annotation is not p.empty and (only is None or p.name in only):
                parts = _annotation(p.annotation, ns)
                if parts is not None:
                    checks[p.name] = parts
        checks[None] = True  # read
        return checks

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        table = checks or read_checks()
        try:
            bound = sig.bind(*args, **kwargs)
        except TypeError as exc:
            raise ArgumentError(f"{name}: {exc} (its arguments: {', '.join(p.name for p in params)}).") from None
        for key, value in bound.arguments.items():
            parts = table.get(key)
            if parts is not None:
                _check_value(name, key, value, parts)
        return func(*args, **kwargs)

    def described() -> dict:
        table = checks or read_checks()
        return {p.name: (" or ".join(w for _a, w, _i in table[p.name]) if p.name in table else None) for p in params}

    wrapper.argument_checks = described
    return wrapper


def argument_checks(func) -> dict:
    """What :func:`checked` checks of each argument of ``func`` (a function, a method or a class: its
    constructor): argument name -> what it must be, or None where it is left to the function (no annotation, or
    one the checks do not read); an empty dict when ``func`` is not checked."""
    target = func.__init__ if isinstance(func, type) else func
    target = getattr(target, "__func__", target)
    reader = getattr(target, "argument_checks", None)
    return reader() if reader is not None else {}


def checked_class(cls=None, *, skip: tuple = ()):
    """Class decorator: :func:`checked` over the constructor and every public method (classmethods and
    staticmethods too; not properties, nor the methods named in ``skip``: a per-step hot path checks its own).
    Put it above ``@dataclass``, so that it wraps the constructor the dataclass writes."""
    if cls is None:
        return lambda c: checked_class(c, skip=skip)
    namespace = vars(sys.modules[cls.__module__])
    for key, member in list(vars(cls).items()):
        if key in skip or (key.startswith("_") and key != "__init__"):
            continue
        label = cls.__name__ if key == "__init__" else f"{cls.__name__}.{key}"
        if isinstance(member, (classmethod, staticmethod)):
            setattr(cls, key, type(member)(checked(member.__func__, label=label, namespace=namespace)))
        elif inspect.isfunction(member):
            setattr(cls, key, checked(member, label=label, namespace=namespace))
    return cls


#: The code of every wrapper :func:`checked` makes (they share it): :func:`warn` does not count these frames.
_WRAPPER_CODE = checked(lambda: None).__code__


def warn(message: str, category: type[Warning] = EhmWarning, stacklevel: int = 1) -> None:
    """:func:`warnings.warn`, with ``stacklevel`` counted over the frames of ehm's argument checks (the wrappers
    :func:`checked` puts around the public functions), so that a warning meant for the caller of a public function
    points at the caller's line, not into this module."""
    frame = inspect.currentframe().f_back  # the caller of warn
    level, remaining = 1, stacklevel - 1
    while remaining > 0 and frame.f_back is not None:
        frame = frame.f_back
        level += 1
        if frame.f_code is not _WRAPPER_CODE:
            remaining -= 1
    while frame.f_code is _WRAPPER_CODE and frame.f_back is not None:  # never point at a wrapper itself
        frame = frame.f_back
        level += 1
    warnings.warn(message, category, stacklevel=level + 1)
