"""``main``: parse the command line, run the subcommand, and end every failure in one sentence and an exit code."""

from __future__ import annotations

import contextlib
import sys

from ...errors import EhmError, EhmWarning
from .common import check_empty_paths
from .parser import build_parser
from .progress import end_progress_line

EXIT_ERROR = 2


_SHOWN: set[str] = set()  #: The warnings this command has shown: each sentence once (a batch's runs repeat theirs).


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """ehm's own warnings (:class:`ehm.errors.EhmWarning`) as one sentence on a line of their own on stderr (an open
    progress line is ended first), without the source line, each sentence once per command (a batch's runs repeat
    theirs); any other (numpy's, matplotlib's, Python's) as a note that keeps its origin: its category and where it
    was raised."""
    text = str(message)
    if text in _SHOWN:
        return
    _SHOWN.add(text)
    end_progress_line()
    out = sys.stderr if file is None else file
    if issubclass(category, EhmWarning):
        print(f"ehm: warning: {text}", file=out, flush=True)
    else:
        print(f"ehm: note: {category.__name__} from {_short_path(filename)}:{lineno}: {text}", file=out, flush=True)


def _short_path(filename: str) -> str:
    """A source file's path from its package on (``numpy/lib/_function_base_impl.py``,
    ``ehm/standards/transfer.py``)."""
    parts = filename.replace("\\", "/").split("/")
    for marker in ("site-packages", "dist-packages", "src"):
        if marker in parts:
            return "/".join(parts[len(parts) - parts[::-1].index(marker):])
    return "/".join(parts[-2:])


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP (a closed terminal), raised like Ctrl-C so that every clean-up (temporary files, staging
    folders, worker processes) runs; ``signum`` says which (the exit code is 128 + it)."""

    signum = 15


def _on_sigterm(signum, frame):
    exc = Terminated()
    exc.signum = int(signum)
    raise exc


def _ending_signals() -> tuple:
    """The signals that end a command like Ctrl-C: SIGTERM, and SIGHUP where the system has it."""
    import signal

    return (signal.SIGTERM,) + ((signal.SIGHUP,) if hasattr(signal, "SIGHUP") else ())


def main(argv: list[str] | None = None) -> int:
    """Run the ``ehm`` command; returns the exit code."""
    import warnings

    parser = build_parser()
    args = parser.parse_args(argv)
    warnings.showwarning = _show_warning
    _SHOWN.clear()
    import shlex
    import signal
    import threading

    from ...outputs.outdir import set_command

    previous = {}
    if threading.current_thread() is threading.main_thread():
        previous = {s: signal.signal(s, _on_sigterm) for s in _ending_signals()}
    set_command(shlex.join(["ehm", *(sys.argv[1:] if argv is None else argv)]))
    try:
        check_empty_paths(args)
        return args.func(args)
    except (EhmError, MemoryError, OSError, KeyboardInterrupt) as exc:
        end_progress_line()
        return _report_failure(exc)
    finally:
        set_command(None)
        end_progress_line()
        _report_mujoco_warnings()
        for s, handler in previous.items():
            signal.signal(s, handler if handler is not None else signal.SIG_DFL)


def _report_failure(exc: BaseException) -> int:
    """One sentence on stderr for a command that failed; returns its exit code."""
    if isinstance(exc, EhmError):
        print(f"ehm: error: {exc}", file=sys.stderr)
        return EXIT_ERROR
    if isinstance(exc, MemoryError):
        print("ehm: error: out of memory; ehm simulate and ehm assess stream long drives in bounded memory, other "
              "commands hold their whole run: shorten --duration or use a machine with more memory.", file=sys.stderr)
        return EXIT_ERROR
    if isinstance(exc, OSError):  # a failure of the system that no command foresaw (a full disk, a removed folder)
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"ehm: error: {where}{exc.strerror or exc} (check the disk and the folder, then "
              "run the command again).", file=sys.stderr)
        return EXIT_ERROR
    if isinstance(exc, Terminated):
        with contextlib.suppress(OSError):  # after SIGHUP the terminal may be gone
            print("ehm: terminated" if exc.signum != 1 else "ehm: hung up (SIGHUP: its terminal closed)",
                  file=sys.stderr)
        return 128 + exc.signum
    print("ehm: interrupted", file=sys.stderr)
    return 130


def _report_mujoco_warnings() -> None:
    """MuJoCo's warnings that did not end a run (those that did are in the error sentence), one line each."""
    from ...engine import take_warnings

    for text in dict.fromkeys(take_warnings()):
        print(f"ehm: note: MuJoCo warned: {text}", file=sys.stderr)
