"""Delimited text tables (``.csv``, ``.txt``, ...): the dialect sniffed from the first lines, then read with pandas;
the file is read again, line by line, only to name a bad line in a message."""

from __future__ import annotations

import csv
import re
from pathlib import Path

import numpy as np

from ..errors import InputError
from .base import _Source

_ALL_COLUMNS = 32  #: Text tables up to this wide are read whole (so that pandas checks every row's field count).


class _TextSource(_Source):
    """A CSV or text table, read with pandas after sniffing its dialect."""

    def __init__(self, path: Path, label: str, columns=None):
        super().__init__(label=label, names=[])
        self.path = path
        layout = _sniff(path, label, columns)
        self.header_line, self.sep, self.decimal = layout["header_line"], layout["sep"], layout["decimal"]
        self.first_comment = layout["first_comment"]
        self.names = layout["header"]
        self._data = None
        self._lines = None

    @property
    def layout_words(self) -> str:
        """Where the number of fields comes from, for messages: the header row, or the names given."""
        if self.header_line:
            return f"as in the header (line {self.header_line})"
        return "as --columns (columns=) names"

    def load(self, wanted: list) -> None:
        """Read the wanted columns (positions in the header) at once."""
        import pandas as pd

        for name in wanted:
            if self.names.count(name) > 1:  # (names given with columns= are distinct: checked in _sniff)
                raise InputError(f"{self.label}, line {self.header_line}: column {name} appears more than once in "
                                 "the header.")
        cols = sorted({self.names.index(n) for n in wanted})
        # pandas refuses a row with a field too many only when it reads every column: it does so for tables of
        # up to _ALL_COLUMNS columns (what is not wanted is dropped at once); wider ones are read column-wise
        # (a row with a surplus field at its end then still has its wanted fields where the header says)
        usecols = None if len(self.names) <= _ALL_COLUMNS else cols
        try:
            frame = pd.read_csv(self.path, sep=self.sep, decimal=self.decimal, comment="#", header=None,
                                skiprows=[self.header_line - 1] if self.header_line else None, usecols=usecols, skip_blank_lines=True,
                                encoding="utf-8-sig", skipinitialspace=True,
                                engine="c" if self.sep != r"\s+" else "python", on_bad_lines="error")
        except UnicodeDecodeError:
            raise InputError(_not_utf8(self.path, self.label)) from None
        except pd.errors.EmptyDataError:  # a header and no rows
            frame = pd.DataFrame({c: np.zeros(0) for c in range(len(self.names))})
        except (pd.errors.ParserError, ValueError) as exc:
            line, found = self._field_count_problem()
            if line is not None:
                raise InputError(f"{self.label}, line {line}: expected {len(self.names)} fields {self.layout_words}, "
                                 f"found {found}.") from None
            raise InputError(f"{self.label}: cannot be read as a table ({str(exc).splitlines()[0]}).") from None
        self._data = {self.names[c]: frame[c].to_numpy() if c in frame else np.zeros(0) for c in cols}
        self.n_rows = len(frame)

    def values(self, name: str) -> np.ndarray:
        return self._data[name]

    def _scan(self):
        """(file line, fields) of every data row, read again for messages (the slow, careful path)."""
        if self._lines is None:
            rows, header_seen = [], not self.header_line  # a file read with columns= has no header row
            with open(self.path, encoding="utf-8-sig", newline="") as fh:
                for line_no, line in enumerate(fh, start=1):
                    text = line.rstrip("\r\n")
                    if not text.strip() or text.lstrip().startswith("#"):
                        continue
                    if not header_seen:
                        header_seen = True
                        continue
                    rows.append((line_no, _split(text, self.sep)))
            self._lines = rows
        return self._lines

    def where(self, row: int) -> str:
        return f"line {self._scan()[self.file_row(row)][0]}"

    def raw(self, name: str, row: int) -> str:
        fields = self._scan()[self.file_row(row)][1]
        j = self.names.index(name)
        return repr(fields[j].strip()) if j < len(fields) else "''"

    def field_text(self, name: str, row: int) -> str:
        fields = self._scan()[self.file_row(row)][1]
        j = self.names.index(name)
        return fields[j].strip() if j < len(fields) else ""

    def row_field_count(self, row: int) -> int:
        return len(self._scan()[self.file_row(row)][1])

    def _field_count_problem(self):
        for line_no, fields in self._scan():
            if len(fields) != len(self.names):
                return line_no, len(fields)
        return None, None


def _not_utf8(path: Path, label: str) -> str:
    """The sentence for a text file that is not UTF-8, naming the first line that is not."""
    with open(path, "rb") as fh:
        for line_no, line in enumerate(fh, start=1):
            try:
                line.decode("utf-8")
            except UnicodeDecodeError as exc:
                return (f"{label}, line {line_no}: the file is not UTF-8 text (byte {line[exc.start]:#04x} cannot be "
                        "decoded).")
    return f"{label}: the file is not UTF-8 text."


def _split(text: str, sep: str) -> list:
    if sep == r"\s+":
        return text.split()
    return next(csv.reader([text], delimiter=sep))


def _sniff(path: Path, label: str, columns=None) -> dict:
    """Header, separator, decimal mark and first comment of a text table, from its first lines; with ``columns``
    (names for a file without a header row) the first row is data and the names are ``columns``."""
    first_comment, header, header_line, sample = "", None, 0, []
    try:
        with open(path, encoding="utf-8-sig", newline="") as fh:
            line_no = 0
            for line_no, line in enumerate(fh, start=1):
                text = line.rstrip("\r\n")
                stripped = text.strip()
                if not stripped or stripped.startswith("#"):
                    if header is None and not first_comment and stripped.startswith("#"):
                        first_comment = stripped.lstrip("#").strip()
                    continue
                if header is None:
                    header, header_line = text, line_no
                else:
                    sample.append(text)
                    if len(sample) >= 50:
                        break
    except UnicodeDecodeError:
        raise InputError(_not_utf8(path, label)) from None
    if header is None:
        if first_comment:
            raise InputError(f"{label}: motion file has only comments and no "
                             f"{'header row' if columns is None else 'data rows'}.")
        raise InputError(f"{label}: motion file is empty.")
    sep = None
    for cand in (",", ";", "\t", "|"):
        n = len(_split(header, cand))
        if n > 1 and all(len(_split(s, cand)) == n for s in sample[:20] if s.strip()):
            sep = cand
            break
    if sep is None:
        sep = r"\s+" if len(header.split()) > 1 else ","
    decimal = "."
    if sep != ",":
        fields = [f.strip() for s in sample for f in _split(s, sep)]
        if any(re.fullmatch(r"[+-]?\d+,\d+([eE][+-]?\d+)?", f) for f in fields):
            decimal = ","
    names = [f.strip() for f in _split(header, sep)]
    numbers = [_is_number(f, decimal) for f in names]
    if columns is None:
        if all(numbers) and not _default_names(names):
            example = ",".join(f"c{i}" for i in range(1, len(names) + 1))
            raise InputError(f"{label}, line {header_line}: the first row holds {len(names)} numbers, not column "
                             "names; for a file without a header row, name its columns with --columns NAME,NAME,... "
                             f"(columns=[...] in Python), e.g. --columns {example}.")
        return {"header": names, "header_line": header_line, "sep": sep, "decimal": decimal,
                "first_comment": first_comment}
    if not any(numbers):
        raise InputError(f"{label}, line {header_line}: the file has a header row ({_short(header)}); columns= "
                         "(--columns) is for a file without one: name its channels with --channel KEY=NAME.")
    if len(columns) != len(names):
        raise InputError(f"{label}, line {header_line}: --columns (columns=) names {len(columns)} column"
                         f"{'s' * (len(columns) != 1)} but the row has {len(names)} field{'s' * (len(names) != 1)}.")
    return {"header": list(columns), "header_line": 0, "sep": sep, "decimal": decimal, "first_comment": first_comment}


def _is_number(text: str, decimal: str) -> bool:
    text = text.strip()
    if decimal == ",":
        text = text.replace(",", ".")
    try:
        float(text)
    except ValueError:
        return False
    return bool(text)


def _default_names(names: list) -> bool:
    """Whether the names are 0, 1, 2, ... or 1, 2, 3, ...: the column names a DataFrame or array gets by default
    (a header row, though every name is a number)."""
    return names in ([str(i) for i in range(len(names))], [str(i) for i in range(1, len(names) + 1)])


def _short(text: str, limit: int = 60) -> str:
    text = text.strip()
    return repr(text if len(text) <= limit else text[:limit - 3] + "...")
