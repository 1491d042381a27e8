"""Atomic output files: text, CSV and JSON.

Every writer first builds the complete file content in memory, then writes it
to a temporary file in the target's directory, flushes it to disk
(``fsync``) and renames it over the target with :func:`os.replace`.  A reader
therefore sees either the old file or the complete new one, never a partial
file, and a failure (including a value that cannot be serialised) leaves the
target untouched and no temporary file behind.  Missing parent directories
are created.

Problems raise :class:`ehm.errors.InputError` with one sentence naming the
file and what is wrong.
"""

from __future__ import annotations

import json
import math
import os
import stat
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ehm.errors import InputError

__all__ = ["write_csv_atomic", "write_json_atomic", "write_text_atomic"]


def _current_umask() -> int:
    """The process umask (read by setting and restoring it)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def replace_atomically(target: Path | str, write, what: str = "file") -> Path:
    """Write ``target`` whole or not at all: the one atomic writer of the package.

    ``write(tmp_path)`` fills a temporary file beside the target (same suffix), which is flushed to disk
    and renamed over the target.  A new file gets the usual permissions (``0o666`` less the umask); an
    existing file keeps its permissions.  On failure the temporary file is removed, the target is left as
    it was, and the problem becomes one InputError sentence ("<target>: cannot write <what> (reason)").
    """
    target = Path(target)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"{target}: cannot create directory {target.parent} ({exc.strerror or exc}).") from None
    try:
        mode = stat.S_IMODE(target.stat().st_mode)
    except OSError:
        mode = 0o666 & ~_current_umask()
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{target.stem}.", suffix=target.suffix, dir=target.parent)
        os.close(fd)
        write(tmp)
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.chmod(tmp, mode)
        os.replace(tmp, target)
        tmp = None
    except OSError as exc:
        raise InputError(f"{target}: cannot write {what} ({exc.strerror or exc}).") from None
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)
    fsync_directory(target.parent)
    return target


#: The manifest that marks a folder ehm wrote (:mod:`ehm.outputs.outdir`): the command, the ehm version, and every file
#: it
#: wrote with its size.  Hidden, like other tools' marks in folders they own.
MANIFEST_NAME = ".ehm-manifest.json"


def read_manifest(folder: Path | str) -> dict | None:
    """The ehm manifest of ``folder`` as a dict, or None when it carries none that ehm wrote."""
    return manifest_or_why(folder)[0]


def manifest_or_why(folder: Path | str) -> tuple[dict | None, str | None]:
    """The ehm manifest of ``folder`` and None; or None and why a manifest file there is not one ehm can read
    (words after "its manifest ... is"); or None, None when the folder has no manifest file."""
    path = Path(folder) / MANIFEST_NAME
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        return None, None
    except (OSError, UnicodeDecodeError) as exc:
        return None, f"unreadable ({getattr(exc, 'strerror', None) or exc})"
    try:
        data = json.loads(text)
    except ValueError:
        return None, "damaged (not valid JSON)"
    if not isinstance(data, dict) or data.get("written_by") != "ehm" or not isinstance(data.get("files"), dict):
        return None, "not one that ehm wrote"
    return data, None


def fsync_directory(directory: Path) -> None:
    """Flush a directory entry to disk where the platform allows it."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def write_text_atomic(path: str | os.PathLike[str], text: str) -> None:
    """Write `text` to `path` atomically, as UTF-8 with ``\\n`` line ends (see :func:`replace_atomically`).

    Parameters
    ----------
    path : str or os.PathLike
        Target file.  Missing parent directories are created.
    text : str
        Complete file content.

    Raises
    ------
    InputError
        If `text` is not a string or the file cannot be written (the message
        gives the operating-system reason).
    """
    target = Path(path)
    if not isinstance(text, str):
        raise InputError(f"{target}: text to write must be a str, got {type(text).__name__}.")

    def write(tmp: str) -> None:
        with open(tmp, "w", encoding="utf-8", newline="\n") as handle:
            handle.write(text)

    replace_atomically(target, write, "file")


def write_csv_atomic(
    path: str | os.PathLike[str],
    header: list[str],
    columns: np.ndarray,
    *,
    fmt: str = "%.9g",
) -> None:
    """Write a numeric table as CSV, atomically.

    The first line is the comma-separated `header`; then one line per row of
    `columns`, each value formatted with `fmt`.

    Parameters
    ----------
    path : str or os.PathLike
        Target file.  Missing parent directories are created.
    header : list of str
        Column names; one per column of `columns`, non-empty, without commas,
        quotes or line breaks.
    columns : array_like, shape (n_rows, n_columns)
        Finite numbers, one row per sample.  ``n_rows`` may be 0 (header
        only).
    fmt : str, optional
        printf-style format of each value.  The default ``"%.9g"`` keeps 9
        significant digits (single-precision round trip); use ``"%.17g"``
        for an exact float64 round trip.

    Raises
    ------
    InputError
        If the header and the array do not match, a value is not a finite
        number, or the file cannot be written.  Nothing is written then.
    """
    target = Path(path)
    if isinstance(header, str) or not isinstance(header, Sequence):
        raise InputError(f"{target}: CSV header must be a list of column names, got {header!r}.")
    names = list(header)
    for name in names:
        if not isinstance(name, str) or not name.strip():
            raise InputError(f"{target}: CSV column name {name!r} must be a non-empty string.")
        if any(c in name for c in ',"\r\n'):
            raise InputError(
                f"{target}: CSV column name {name!r} must not contain a comma, quote or "
                "line break."
            )
    try:
        table = np.asarray(columns, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{target}: CSV data must be a numeric 2-D array.") from None
    if table.ndim != 2:
        raise InputError(
            f"{target}: CSV data must be a 2-D array (rows x columns), got shape {table.shape}."
        )
    if table.shape[1] != len(names):
        raise InputError(
            f"{target}: CSV header has {len(names)} column(s) but the data has "
            f"{table.shape[1]}."
        )
    bad_rows, bad_cols = np.nonzero(~np.isfinite(table))
    if bad_rows.size:
        i, j = int(bad_rows[0]), int(bad_cols[0])
        raise InputError(
            f"{target}: CSV data row {i}, column {names[j]} is {float(table[i, j])!r}, "
            "not a finite number."
        )
    row_format = ",".join([fmt] * len(names))
    try:
        lines = [row_format % tuple(row) for row in table.tolist()]
    except (TypeError, ValueError):
        raise InputError(f"{target}: CSV number format {fmt!r} is not a valid format.") from None
    write_text_atomic(target, "\n".join([",".join(names), *lines]) + "\n")


def _plain(value: object, where: str, target: Path) -> object:
    """Convert numpy values to Python ones and check JSON compatibility."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, np.ndarray):
        return [_plain(item, f"{where}[{k}]", target) for k, item in enumerate(value.tolist())]
    if isinstance(value, np.generic):
        value = value.item()
        if isinstance(value, (bytes, complex)) or not isinstance(
            value, (bool, int, float, str)
        ):
            raise InputError(
                f"{target}: value at {where} has numpy type {type(value).__name__}, "
                "which cannot be written as JSON."
            )
        return _plain(value, where, target)
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise InputError(
                f"{target}: value at {where} is {value!r}; JSON allows only finite numbers."
            )
        return float(value)
    if isinstance(value, Mapping):
        result = {}
        for key, item in value.items():
            if isinstance(key, np.generic):
                key = key.item()
            if isinstance(key, bool) or key is None or isinstance(key, (int, float)):
                key_text = json.dumps(key)
            elif isinstance(key, str):
                key_text = key
            else:
                raise InputError(
                    f"{target}: key {key!r} at {where} is not a string or number, so it "
                    "cannot be a JSON object key."
                )
            result[key_text] = _plain(item, f"{where}[{key_text!r}]", target)
        return result
    if isinstance(value, (list, tuple)):
        return [_plain(item, f"{where}[{k}]", target) for k, item in enumerate(value)]
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    raise InputError(
        f"{target}: value at {where} has type {type(value).__name__}, which cannot be "
        "written as JSON."
    )


def write_json_atomic(path: str | os.PathLike[str], obj: object) -> None:
    """Write `obj` as indented JSON, atomically.

    numpy scalars become Python numbers and numpy arrays nested lists;
    tuples become lists and path objects strings.  The text is
    ``json.dumps(obj, indent=2, allow_nan=False)`` plus a final newline.

    Parameters
    ----------
    path : str or os.PathLike
        Target file.  Missing parent directories are created.
    obj : object
        Dicts (string or number keys), lists, tuples, str, int, float, bool,
        None, numpy scalars and arrays, nested freely.

    Raises
    ------
    InputError
        If `obj` holds NaN, an infinity or a value JSON cannot represent (the
        message gives where in `obj`), or the file cannot be written.
        Nothing is written then.
    """
    target = Path(path)
    try:
        plain = _plain(obj, "obj", target)
    except RecursionError:
        raise InputError(f"{target}: object is nested too deeply or refers to itself.") from None
    try:
        text = json.dumps(plain, indent=2, allow_nan=False)
    except (TypeError, ValueError) as exc:  # e.g. a circular reference
        raise InputError(f"{target}: cannot be written as JSON ({exc}).") from None
    write_text_atomic(target, text + "\n")
