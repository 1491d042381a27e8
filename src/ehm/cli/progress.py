"""The progress line on stderr: rewritten in place while a command runs, ended before anything else is printed."""

from __future__ import annotations

import sys

_OPEN_LINE = {"open": False}  #: Whether a progress line on stderr waits for its end.


def _progress_line(text: str, last: bool) -> None:
    """Rewrite the progress line on stderr; ``last`` ends it."""
    print(f"\r{text}", end="\n" if last else "", file=sys.stderr, flush=True)
    _OPEN_LINE["open"] = not last


def _end_progress_line() -> None:
    """End an unfinished progress line, so that what follows starts a line of its own."""
    if _OPEN_LINE["open"]:
        print(file=sys.stderr, flush=True)
        _OPEN_LINE["open"] = False


def _progress_bar(label: str):
    finished = []

    def show(done_s: float, total_s: float) -> None:
        if finished:
            return
        frac = min(1.0, done_s / total_s) if total_s > 0 else 1.0
        bar = "#" * int(30 * frac)
        _progress_line(f"{label} [{bar:<30}] {done_s:6.0f} / {total_s:.0f} s", frac >= 1.0)
        if frac >= 1.0:
            finished.append(True)
    return show
