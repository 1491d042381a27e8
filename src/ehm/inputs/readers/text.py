"""Delimited text tables (``.csv``, ``.txt``, ...): the dialect sniffed from the first lines, then read with pandas;
the file is read again, line by line, only to name a bad line in a message.

The text encoding is the caller's (``encoding=``, ``--encoding``), else found from the file: a byte-order mark
(UTF-8, UTF-16, UTF-32), or UTF-16 without one (every other byte of ASCII text is 0), else UTF-8.  Text that
does not decode is refused in one sentence naming the line and the option (a Windows export in cp1252)."""

from __future__ import annotations

import codecs
import csv
import re
from pathlib import Path

import numpy as np

from ...errors import InputError
from .base import Source

_ALL_COLUMNS = 32  #: Text tables up to this wide are read whole (so that pandas checks every row's field count).


class TextSource(Source):
    """A CSV or text table, read with pandas after sniffing its dialect."""

    def __init__(self, path: Path, label: str, columns=None, encoding: str | None = None):
        super().__init__(label=label, names=[])
        self.path = path
        self.given_encoding = encoding
        self.encoding = ("utf-8-sig" if encoding == "utf-8" else encoding) or _found_encoding(path)
        layout = _sniff(path, label, columns, self.encoding, encoding is not None)
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
                                skiprows=[self.header_line - 1] if self.header_line else None, usecols=usecols,
                                skip_blank_lines=True, encoding=self.encoding, skipinitialspace=True,
                                engine="c" if self.sep != r"\s+" else "python", on_bad_lines="error")
        except UnicodeError as exc:
            raise InputError(_undecodable(self.path, self.label, self.encoding, self.given_encoding is not None, exc)
                             ) from None
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
            with open(self.path, encoding=self.encoding, newline="") as fh:
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


#: Byte-order marks and the encodings Python reads them with (the mark dropped), longest first.
_BOMS = ((codecs.BOM_UTF32_LE, "utf-32"), (codecs.BOM_UTF32_BE, "utf-32"), (codecs.BOM_UTF8, "utf-8-sig"),
         (codecs.BOM_UTF16_LE, "utf-16"), (codecs.BOM_UTF16_BE, "utf-16"))


def _found_encoding(path: Path) -> str:
    """The encoding of a text file nobody names: its byte-order mark's; UTF-16 without one when every other byte
    of its start is 0 (ASCII text in UTF-16); else UTF-8 (``utf-8-sig``: a mark, if any, is dropped)."""
    with open(path, "rb") as fh:
        head = fh.read(4096)
    for bom, name in _BOMS:
        if head.startswith(bom):
            return name
    pairs = head[: len(head) // 2 * 2]
    if len(pairs) >= 4:
        even, odd = pairs[0::2], pairs[1::2]
        if odd.count(0) > 0.9 * len(odd) and not even.count(0):
            return "utf-16-le"
        if even.count(0) > 0.9 * len(even) and not odd.count(0):
            return "utf-16-be"
    return "utf-8-sig"


def _undecodable(path: Path, label: str, encoding: str, given: bool, exc: UnicodeError | None = None) -> str:
    """The sentence for a text file that does not decode: where (UTF-8: the first line that does not), and the
    option that names its encoding."""
    if given or not encoding.startswith("utf-8"):
        what = f"the file is not {encoding} text ({str(exc).splitlines()[0] if exc else 'it does not decode'})"
        return f"{label}: {what}; give its encoding with --encoding NAME (encoding=NAME), e.g. cp1252 or utf-16."
    hint = ("give its encoding, e.g. --encoding cp1252 (encoding='cp1252') for a Windows export, or latin-1")
    with open(path, "rb") as fh:
        for line_no, line in enumerate(fh, start=1):
            try:
                line.decode("utf-8")
            except UnicodeDecodeError as err:
                return (f"{label}, line {line_no}: the file is not UTF-8 text (byte {line[err.start]:#04x} cannot be "
                        f"decoded); {hint}.")
    return f"{label}: the file is not UTF-8 text; {hint}."


def _split(text: str, sep: str) -> list:
    if sep == r"\s+":
        return text.split()
    return next(csv.reader([text], delimiter=sep))


def _sniff(path: Path, label: str, columns=None, encoding: str = "utf-8-sig", given: bool = False) -> dict:
    """Header, separator, decimal mark and first comment of a text table, from its first lines; with ``columns``
    (names for a file without a header row) the first row is data and the names are ``columns``."""
    first_comment, header, header_line, sample = "", None, 0, []
    try:
        with open(path, encoding=encoding, newline="") as fh:
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
    except UnicodeError as exc:
        raise InputError(_undecodable(path, label, encoding, given, exc)) from None
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
