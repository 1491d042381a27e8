"""Errors that reach users as one clear sentence.

Every problem with user input (a file, a parameter, a command-line value) or a
simulation that goes wrong raises :class:`EhmError` with a message that names
what is wrong and where.  The command-line interface prints that message and
exits with a non-zero code, without a traceback.
"""

from __future__ import annotations


class EhmError(Exception):
    """A user-facing error: its message is one sentence naming what and where."""


class InputError(EhmError, ValueError):
    """Bad input: a malformed file, a value out of range, an unknown name."""


class DivergenceError(EhmError, RuntimeError):
    """A simulation became unstable; the message gives the simulated time, and ``time_s`` holds it [s] from the
    motion's first sample (None where it is not known, or while settling)."""

    time_s: float | None = None
