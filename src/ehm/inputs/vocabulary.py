"""Which words a message about an input uses for its fix: the command line's options or the Python arguments.

The readers and the IMU route are called from Python (``ehm.read_motion(..., rate_hz=500)``) and from the command
line (``ehm assess --rate 500``); a refusal names the fix in the words of the caller.  The command line reads its
motion inside :func:`command_line`; everywhere else the Python words are used:

>>> from ehm.inputs.vocabulary import command_line, fix
>>> fix("--rate 500", "rate_hz=500")
'rate_hz=500'
>>> with command_line():
...     fix("--rate 500", "rate_hz=500")
'--rate 500'
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

_COMMAND_LINE: ContextVar[bool] = ContextVar("ehm_command_line", default=False)
#: How the gyro's unit was found for the log being read (``"deg/s, as their names say"``), for the IMU route's
#: messages; None when no reader set it.
GYRO_UNIT: ContextVar[str | None] = ContextVar("ehm_gyro_unit", default=None)


@contextmanager
def command_line() -> Iterator[None]:
    """Messages inside name the command line's options."""
    token = _COMMAND_LINE.set(True)
    try:
        yield
    finally:
        _COMMAND_LINE.reset(token)


def on_command_line() -> bool:
    """Whether the input is read for the command line."""
    return _COMMAND_LINE.get()


def fix(cli: str, python: str) -> str:
    """The command line's words ``cli`` inside :func:`command_line`, else the Python words ``python``."""
    return cli if _COMMAND_LINE.get() else python
