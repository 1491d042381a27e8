"""Progress on stderr that fits where it goes.

On a terminal a bar rewritten in place (carriage returns), ended before anything else is printed.  On a pipe or a
file (a CI log, ``2> log.txt``) plain lines, at most one every :data:`PLAIN_EVERY_S` and only at a new tenth of the
work, and a last one only when an earlier one was printed: a short run prints none, a 342 s assessment a handful.
``--quiet`` (:func:`ehm.interfaces.cli.options.progress_options`) prints none.  Library calls print nothing unless given
a
``progress=`` function.
"""

from __future__ import annotations

import sys
import time

#: On a pipe or a file: at most one progress line this often [s of wall time].
PLAIN_EVERY_S = 10.0

_OPEN_LINE = {"open": False}  #: Whether a progress line on stderr waits for its end.


def _progress_line(text: str, last: bool) -> None:
    """Rewrite the progress line on stderr; ``last`` ends it."""
    print(f"\r{text}", end="\n" if last else "", file=sys.stderr, flush=True)
    _OPEN_LINE["open"] = not last


def end_progress_line() -> None:
    """End an unfinished progress line, so that what follows starts a line of its own."""
    if _OPEN_LINE["open"]:
        print(file=sys.stderr, flush=True)
        _OPEN_LINE["open"] = False


class _Progress:
    """``show(done, total)`` for one command: ``text(done, total, frac, tty)`` is the line to show."""

    def __init__(self, text):
        self.text = text
        self.tty = sys.stderr.isatty()
        self.finished = self.printed = False
        self.tenth, self.last = 0, time.monotonic()

    def __call__(self, done, total) -> None:
        if self.finished:
            return
        frac = min(1.0, done / total) if total > 0 else 1.0
        self.finished = frac >= 1.0
        if self.tty:
            _progress_line(self.text(done, total, frac, True), self.finished)
            return
        now, tenth = time.monotonic(), int(10 * frac)
        due = tenth > self.tenth and now - self.last >= PLAIN_EVERY_S
        if (self.finished and self.printed) or (not self.finished and due):
            print(self.text(done, total, frac, False), file=sys.stderr, flush=True)
            self.tenth, self.last, self.printed = tenth, now, True


def progress_bar(label: str, quiet: bool = False):
    """Progress of a run through a drive, ``show(done_s, total_s)``; None when ``quiet``."""
    def text(done_s, total_s, frac, tty):
        if tty:
            return f"{label} [{'#' * int(30 * frac):<30}] {done_s:6.0f} / {total_s:.0f} s"
        return f"{label}: {100 * frac:3.0f} % ({done_s:.0f} / {total_s:.0f} s of the drive)"
    return None if quiet else _Progress(text)


def progress_count(what: str, quiet: bool = False):
    """Progress counted in items, ``show(done, total)`` ("3 / 10 runs done"); None when ``quiet``."""
    return None if quiet else _Progress(lambda done, total, frac, tty: f"  {done} / {total} {what} done")
