"""Outside data in: seat motions and vehicle logs from files and DataFrames, in the logger's names and units.

The one door for outside data formats.  :func:`read_motion` reads

* ``.csv`` / ``.txt`` text tables (pandas; the dialect is sniffed: separator ``,`` ``;`` tab ``|`` or
  blanks, decimal comma, byte-order mark, ``#`` comment lines; the first comment line before the header
  describes the motion);
* ``.parquet`` tables (pyarrow; extra ``parquet``);
* MATLAB ``.mat`` files, v5 (``scipy.io``) and v7.3 (HDF5, ``pymatreader``; extra ``logs``): variables,
  struct fields as ``data.acc_x`` and matrix columns as ``name[2]`` (counting from 0);
* ASAM MDF ``.mf4`` / ``.mdf`` logs (asammdf; extra ``logs``): each channel's own time stamps and unit;
* a pandas ``DataFrame`` (the time channel may also be its index: seconds, or a datetime/timedelta index).

``channels`` maps the keys ``time, ax, ay, az, wx, wy, wz`` to the source's own names (defaults: the
motion CSV columns ``time_s, ax_mps2, ay_mps2, az_mps2, wx_radps, wy_radps, wz_radps``; the angular
velocities are optional, all three or none).  Units come from ``units`` (key -> unit string such as
``"g"``, ``"m/s^2"``, ``"deg/s"``, ``"rad/s"``, ``"ms"``), else from the file (MDF channel units, a
``[unit]`` at the end of a column name), else SI; they are converted with pint (``g`` of an acceleration
is standard gravity, 9.80665 m/s^2).  With ``imu=True`` the accelerations are an IMU's specific force
(gravity included, sensor axes) and the rates its gyro rates: :func:`ehm.imu.from_imu` turns them into
the seat's motion.

Time stamps must keep one sample rate (a log whose rate changes part way is refused, naming where and the
two rates: resampled as one rate it would alias) and have no gaps longer than :data:`GAP_STEPS` median steps
(refused, or bridged with a straight line and a warning with ``fill_gaps=True``, ``--fill-gaps``).

Bad input ends in one sentence naming the file, channel, line or row and the value; a channel that is not
in the source is named together with the channels that are.
"""

from __future__ import annotations

import csv
import functools
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import InputError
from .motion import SeatMotion

__all__ = ["CHANNEL_KEYS", "DEFAULT_CHANNELS", "SI_UNITS", "read_motion", "parse_assignments"]

#: The quantities a motion is made of.
CHANNEL_KEYS = ("time", "ax", "ay", "az", "wx", "wy", "wz")
#: Default source names: the motion CSV columns.
DEFAULT_CHANNELS = {"time": "time_s", "ax": "ax_mps2", "ay": "ay_mps2", "az": "az_mps2",
                    "wx": "wx_radps", "wy": "wy_radps", "wz": "wz_radps"}
#: Units inside ehm.
SI_UNITS = {"time": "s", "ax": "m/s^2", "ay": "m/s^2", "az": "m/s^2", "wx": "rad/s", "wy": "rad/s", "wz": "rad/s"}
_ACC, _RATES = ("ax", "ay", "az"), ("wx", "wy", "wz")
_KIND = {"time": ("a time", "'s' or 'ms'"), **{k: ("an acceleration", "'m/s^2' or 'g'") for k in _ACC},
         **{k: ("an angular rate", "'rad/s' or 'deg/s'") for k in _RATES}}
_TEXT_SUFFIXES = (".csv", ".txt", ".tsv", ".dat")
_MAT_SUFFIXES = (".mat",)
_MDF_SUFFIXES = (".mf4", ".mdf", ".dat4")
_PARQUET_SUFFIXES = (".parquet", ".pq")
_LISTED = 25  #: Most channel names listed in a message.
#: A step between time stamps longer than this many median steps is a gap (a logger's dropout), refused unless
#: ``fill_gaps``.  Loggers miss a sample or two now and then (a 100 Hz IMU log: steps of up to 3 median steps; a
#: phone's: up to 1.6), which a straight line bridges with little loss; a longer dropout is data that is not
#: there, and a straight line over it is a quiet seat that was never measured.
GAP_STEPS = 5
#: A stretch of the log whose local median step (over :data:`RATE_WINDOW` steps) differs from the whole log's
#: median step by this factor or more is at another sample rate.  Jitter leaves the local median within a
#: fraction of a per cent of the median (phone and IMU logs: 0.2 %); a rate change moves it by the ratio of
#: the rates.
RATE_CHANGE_RATIO = 2.0
#: Steps over which the local median step is taken: long enough that jitter and a dropped sample or two do not
#: move it, short against any stretch worth naming (a quarter second at 100 Hz).
RATE_WINDOW = 25
_ALL_COLUMNS = 32  #: Text tables up to this wide are read whole (so that pandas checks every row's field count).


# --------------------------------------------------------------------------
# Arguments
# --------------------------------------------------------------------------


def parse_assignments(values, option: str) -> dict:
    """``["ax=AccX", "az=AccZ"]`` (repeatable command-line options) -> ``{"ax": "AccX", "az": "AccZ"}``.

    An empty value (``time=``) gives None: for ``--channel time=``, a source without a time channel.
    """
    out = {}
    for text in values or []:
        key, sep, value = str(text).partition("=")
        key = key.strip()
        if not sep or key not in CHANNEL_KEYS:
            raise InputError(f"{option} {text!r}: use KEY=VALUE with KEY one of {', '.join(CHANNEL_KEYS)}.")
        if key in out:
            raise InputError(f"{option} {text!r}: {key} is given twice.")
        out[key] = value.strip() or None
    return out


def _mapping(value, arg: str) -> dict:
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise InputError(f"{arg} must map keys ({', '.join(CHANNEL_KEYS)}) to names; got {type(value).__name__}.")
    for key, v in value.items():
        if key not in CHANNEL_KEYS:
            raise InputError(f"{arg}: unknown key {key!r}; use {', '.join(CHANNEL_KEYS)}.")
        if v is not None and not isinstance(v, str):
            raise InputError(f"{arg}[{key!r}] must be a string; got {v!r}.")
    return dict(value)


# --------------------------------------------------------------------------
# Sources: one class per format, all answering the same few questions
# --------------------------------------------------------------------------


@dataclass
class _Source:
    """A table of named channels: what it holds and how to read one channel as floats."""

    label: str
    names: list
    kind: str = "columns"                       # what its channels are called in messages
    first_comment: str = ""
    per_channel_time: bool = False              # MDF: each channel has its own time stamps
    units: dict = field(default_factory=dict)   # name -> unit string the source gives

    def where(self, row: int) -> str:
        """Where a row is, for messages."""
        return f"row {row}"

    def raw(self, name: str, row: int) -> str:
        """The row's value as the source holds it, for messages."""
        value = self.values(name)[row]
        return repr(value.item() if hasattr(value, "item") else value)

    def has(self, name: str) -> bool:
        """Whether the source holds a channel of that name."""
        return name in self.names

    def values(self, name: str) -> np.ndarray:
        raise NotImplementedError

    def time_of(self, name: str) -> np.ndarray:
        raise NotImplementedError

    def close(self) -> None:
        """Release the file."""


def _listed(names) -> str:
    names = [str(n) for n in names]
    if len(names) > _LISTED:
        return ", ".join(names[:_LISTED]) + f" and {len(names) - _LISTED} more"
    return ", ".join(names) if names else "none"


def _as_floats(src: _Source, name: str, key: str, column) -> np.ndarray:
    """A column as float64; one sentence naming the first value that is not a number."""
    import pandas as pd

    arr = np.asarray(column)
    if arr.dtype.kind in "fiub":
        return arr.astype(float, copy=False)
    if arr.dtype.kind == "M":
        return arr.astype("datetime64[ns]").astype(np.int64) / 1e9
    if arr.dtype.kind == "m":
        return arr.astype("timedelta64[ns]").astype(np.int64) / 1e9
    numeric = pd.to_numeric(pd.Series(arr), errors="coerce").to_numpy(dtype=float)
    given = pd.Series(arr).notna().to_numpy() & (pd.Series(arr).astype(str).str.strip() != "").to_numpy()
    bad = np.flatnonzero(np.isnan(numeric) & given)
    if bad.size:
        i = int(bad[0])
        raise InputError(f"{src.label}, {src.where(i)}, {_column_words(src, name, key)}: {src.raw(name, i)} is not "
                         "a number.")
    return numeric


def _column_words(src: _Source, name: str, key: str) -> str:
    if src.kind == "columns":  # the channel is named when the column's name does not say it
        return f"column {name}" if name == DEFAULT_CHANNELS[key] else f"column {name} (channel {key})"
    return f"channel {key} ({name!r})"


class _TextSource(_Source):
    """A CSV or text table, read with pandas after sniffing its dialect."""

    def __init__(self, path: Path, label: str):
        super().__init__(label=label, names=[])
        self.path = path
        layout = _sniff(path, label)
        self.header_line, self.sep, self.decimal = layout["header_line"], layout["sep"], layout["decimal"]
        self.first_comment = layout["first_comment"]
        self.names = layout["header"]
        self._data = None
        self._lines = None

    def load(self, wanted: list) -> None:
        """Read the wanted columns (positions in the header) at once."""
        import pandas as pd

        for name in wanted:
            if self.names.count(name) > 1:
                raise InputError(f"{self.label}, line {self.header_line}: column {name} appears more than once in "
                                 "the header.")
        cols = sorted({self.names.index(n) for n in wanted})
        # pandas refuses a row with a field too many only when it reads every column: it does so for tables of
        # up to _ALL_COLUMNS columns (what is not wanted is dropped at once); wider ones are read column-wise
        # (a row with a surplus field at its end then still has its wanted fields where the header says)
        usecols = None if len(self.names) <= _ALL_COLUMNS else cols
        try:
            frame = pd.read_csv(self.path, sep=self.sep, decimal=self.decimal, comment="#", header=None,
                                skiprows=[self.header_line - 1], usecols=usecols, skip_blank_lines=True,
                                encoding="utf-8-sig", skipinitialspace=True,
                                engine="c" if self.sep != r"\s+" else "python", on_bad_lines="error")
        except UnicodeDecodeError:
            raise InputError(_not_utf8(self.path, self.label)) from None
        except pd.errors.EmptyDataError:  # a header and no rows
            frame = pd.DataFrame({c: np.zeros(0) for c in range(len(self.names))})
        except (pd.errors.ParserError, ValueError) as exc:
            line, found = self._field_count_problem()
            if line is not None:
                raise InputError(f"{self.label}, line {line}: expected {len(self.names)} fields as in the header "
                                 f"(line {self.header_line}), found {found}.") from None
            raise InputError(f"{self.label}: cannot be read as a table ({str(exc).splitlines()[0]}).") from None
        self._data = {self.names[c]: frame[c].to_numpy() if c in frame else np.zeros(0) for c in cols}
        self.n_rows = len(frame)

    def values(self, name: str) -> np.ndarray:
        return self._data[name]

    def _scan(self):
        """(file line, fields) of every data row, read again for messages (the slow, careful path)."""
        if self._lines is None:
            rows, header_seen = [], False
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
        return f"line {self._scan()[row][0]}"

    def raw(self, name: str, row: int) -> str:
        fields = self._scan()[row][1]
        j = self.names.index(name)
        return repr(fields[j].strip()) if j < len(fields) else "''"

    def field_text(self, name: str, row: int) -> str:
        fields = self._scan()[row][1]
        j = self.names.index(name)
        return fields[j].strip() if j < len(fields) else ""

    def row_field_count(self, row: int) -> int:
        return len(self._scan()[row][1])

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


def _sniff(path: Path, label: str) -> dict:
    """Header, separator, decimal mark and first comment of a text table, from its first lines."""
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
            raise InputError(f"{label}: motion file has only comments and no header row.")
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
    return {"header": names, "header_line": header_line, "sep": sep, "decimal": decimal,
            "first_comment": first_comment}


class _FrameSource(_Source):
    """A pandas DataFrame: columns by name; its index may be the time."""

    def __init__(self, frame, label: str = "DataFrame"):
        names = [str(c) for c in frame.columns]
        super().__init__(label=label, names=names)
        self.frame = frame
        self.units.update({str(k): v for k, v in (frame.attrs.get("units") or {}).items()})
        index = frame.index
        self._index_name = str(index.name) if index.name is not None else None
        self._time_index = index.dtype.kind in "Mm"

    def has_index_time(self, name: str) -> bool:
        return name not in self.names and (name == self._index_name or self._time_index)

    def values(self, name: str) -> np.ndarray:
        if name not in self.names:  # the index holds the time
            idx = self.frame.index
            if idx.dtype.kind == "M":
                return (idx - idx[0]).to_numpy().astype("timedelta64[ns]").astype(np.int64) / 1e9
            return idx.to_numpy()
        return self.frame[self.frame.columns[self.names.index(name)]].to_numpy()

    def where(self, row: int) -> str:
        return f"row {row} (index {self.frame.index[row]!r})"

    def raw(self, name: str, row: int) -> str:
        value = self.values(name)[row]
        return repr(value.item() if hasattr(value, "item") else value)


class _ParquetSource(_Source):
    def __init__(self, path: Path, label: str):
        try:
            import pyarrow.parquet as pq
        except ImportError:
            raise InputError(f"{label}: Parquet files need pyarrow: pip install 'ehm[parquet]'.") from None
        try:
            self.file = pq.ParquetFile(path)
        except Exception as exc:  # noqa: BLE001 - pyarrow raises several kinds for a file that is not Parquet
            raise InputError(f"{label}: not a readable Parquet file ({str(exc).splitlines()[0]}).") from None
        schema = self.file.schema_arrow
        super().__init__(label=label, names=list(schema.names))
        for f in schema:
            meta = f.metadata or {}
            if b"unit" in meta:
                self.units[f.name] = meta[b"unit"].decode()
        self._cache = {}

    def values(self, name: str) -> np.ndarray:
        if name not in self._cache:
            col = self.file.read(columns=[name]).column(0)
            arr = col.to_numpy(zero_copy_only=False)
            if arr.dtype.kind in "fiu" and col.null_count:
                arr = arr.astype(float)
            self._cache[name] = arr
        return self._cache[name]


class _MatSource(_Source):
    """MATLAB v5 (scipy.io) or v7.3 (pymatreader): numeric variables, struct fields and matrix columns."""

    def __init__(self, path: Path, label: str):
        from scipy import io as sio

        try:
            doc = sio.loadmat(path, simplify_cells=True)
        except NotImplementedError:  # v7.3 (HDF5)
            try:
                from pymatreader import read_mat
            except ImportError:
                raise InputError(f"{label}: MATLAB v7.3 files need pymatreader and h5py: pip install 'ehm[logs]'.") \
                    from None
            try:
                doc = read_mat(str(path))
            except Exception as exc:  # noqa: BLE001
                raise InputError(f"{label}: not a readable MATLAB v7.3 file ({str(exc).splitlines()[0]}).") from None
        except (ValueError, TypeError, OSError) as exc:
            raise InputError(f"{label}: not a readable MATLAB file ({str(exc).splitlines()[0]}).") from None
        self._arrays = {}
        self._flatten(doc, "")
        super().__init__(label=label, names=list(self._arrays), kind="variables")

    def _flatten(self, value, prefix: str) -> None:
        if isinstance(value, dict):
            for k, v in value.items():
                if not str(k).startswith("__"):
                    self._flatten(v, f"{prefix}.{k}" if prefix else str(k))
            return
        arr = np.asarray(value)
        if arr.dtype.kind not in "fiub" or arr.size < 2:
            return
        arr = np.squeeze(arr)
        if arr.ndim == 1:
            self._arrays[prefix] = arr
        elif arr.ndim == 2:
            if arr.shape[0] < arr.shape[1]:  # samples along the longer side
                arr = arr.T
            for j in range(arr.shape[1]):
                self._arrays[f"{prefix}[{j}]"] = arr[:, j]

    def values(self, name: str) -> np.ndarray:
        return self._arrays[name]


class _MdfSource(_Source):
    """An ASAM MDF log: channels by name, each with its own time stamps (its group's master) and unit.

    A name that is in several data groups is refused unless it is given as ``GROUP/NAME``, GROUP the data
    group's index (as asammdf's ``MDF.get(name, group=...)`` counts them) or its acquisition name.
    """

    def __init__(self, path: Path, label: str):
        try:
            from asammdf import MDF
        except ImportError:
            raise InputError(f"{label}: MDF logs need asammdf: pip install 'ehm[logs]'.") from None
        self.mdf, failure = _open_mdf(MDF, path)
        if failure is not None:
            raise InputError(f"{label}: not a readable MDF file ({failure}).")
        masters = self.mdf.masters_db
        names = [n for n, places in self.mdf.channels_db.items()
                 if any(masters.get(g) != i for g, i in places)]  # the data channels, not the time stamps
        super().__init__(label=label, names=names, kind="channels", per_channel_time=True)
        self._masters = {}
        self.first_comment = self._comment()

    def _comment(self) -> str:
        """The file's or its first channel group's comment, as plain text (it describes the log); asammdf's
        default group comment "Python" says nothing about the log and is passed over."""
        for text in [getattr(self.mdf.header, "comment", "")] + [g.channel_group.comment for g in self.mdf.groups]:
            plain = re.sub(r"<[^>]*>", " ", str(text or "")).strip()
            if plain and plain != "Python":
                return " ".join(plain.split())
        return ""

    def _places(self, name: str) -> list:
        """(group, index) of every data channel of that name."""
        masters = self.mdf.masters_db
        return [(g, i) for g, i in self.mdf.channels_db.get(name, ()) if masters.get(g) != i]

    def _group_name(self, group: int) -> str:
        return str(getattr(self.mdf.groups[group].channel_group, "acq_name", "") or "")

    def _split(self, name: str):
        """``GROUP/NAME`` -> (group index, NAME) when NAME is in that group; else None."""
        head, sep, rest = name.partition("/")
        if not sep or not rest:
            return None
        groups = [g for g, _ in self._places(rest)]
        if head.strip().isdigit():
            chosen = [int(head)] if int(head) in groups else []
        else:
            chosen = [g for g in groups if self._group_name(g) == head.strip()]
        return (chosen[0], rest) if len(chosen) == 1 else None

    def has(self, name: str) -> bool:
        return name in self.names or self._split(name) is not None

    def check_unique(self, key: str, name: str) -> None:
        """Refuse a bare name that is in several data groups, naming them and the GROUP/NAME form."""
        places = self._places(name) if name in self.names else []
        if len(places) > 1:
            groups = [f"{g}" + (f" ({self._group_name(g)})" if self._group_name(g) else "") for g, _ in places]
            example = f"{key}={places[-1][0]}/{name}"
            raise InputError(f"{self.label}: channel {key} ({name!r}) is in data groups {', '.join(groups[:-1])} "
                             f"and {groups[-1]}; name one as GROUP/NAME, GROUP its index or name, e.g. --channel "
                             f"{example} (Python: channels={{{key!r}: '{example.split('=', 1)[1]}'}}).")

    def _where(self, name: str):
        if name not in self.names:  # GROUP/NAME
            group, rest = self._split(name)
            return next((g, i) for g, i in self._places(rest) if g == group), rest
        return self._places(name)[0], name

    def values(self, name: str) -> np.ndarray:
        (group, index), name = self._where(name)
        samples, _ = self.mdf.get(name, group, index, samples_only=True)
        return samples

    def time_of(self, name: str) -> np.ndarray:
        (group, _), _ = self._where(name)
        if group not in self._masters:
            self._masters[group] = np.asarray(self.mdf.get_master(group), dtype=float)
        return self._masters[group]

    def unit_of(self, name: str) -> str:
        (group, index), name = self._where(name)
        return (self.mdf.get_channel_unit(name, group, index) or "").strip()

    def close(self) -> None:
        self.mdf.close()


def _open_mdf(MDF, path: Path):
    """(asammdf's MDF of the file, None), or (None, the first line of why it cannot be read).

    asammdf's MDF4 object of a file it fails to read complains from its destructor (a traceback on stderr,
    after ehm's sentence); that object is let go and collected here, its destructor's complaint dropped."""
    import gc
    import sys

    failure = None
    hook = sys.unraisablehook

    def quiet(unraisable):
        where = getattr(unraisable.object, "__module__", "") or ""
        if not where.startswith("asammdf"):
            hook(unraisable)

    sys.unraisablehook = quiet
    try:
        try:
            return MDF(str(path)), None
        except Exception as exc:  # noqa: BLE001 - asammdf raises several kinds for a file that is not MDF
            failure = (str(exc).splitlines() or [type(exc).__name__])[0]
        gc.collect()  # the half-built object goes now, while its destructor's complaint is dropped
    finally:
        sys.unraisablehook = hook
    return None, failure


def _open(source, label: str | None) -> _Source:
    try:
        import pandas as pd
    except ImportError:  # pragma: no cover - pandas is a dependency
        raise InputError("reading motions needs pandas: pip install pandas.") from None
    if isinstance(source, pd.DataFrame):
        return _FrameSource(source, label or "DataFrame")
    if not isinstance(source, (str, os.PathLike)):
        raise InputError(f"read_motion: source must be a file path or a pandas DataFrame; got {type(source).__name__}.")
    path = Path(source)
    label = label or str(source)
    if not path.exists():
        raise InputError(f"{label}: motion file not found.")
    if path.is_dir():
        raise InputError(f"{label}: is a directory, not a motion file.")
    if not os.access(path, os.R_OK):
        raise InputError(f"{label}: motion file cannot be read (permission denied).")
    suffix = path.suffix.lower()
    if suffix in _PARQUET_SUFFIXES:
        return _ParquetSource(path, label)
    if suffix in _MAT_SUFFIXES:
        return _MatSource(path, label)
    if suffix in _MDF_SUFFIXES:
        return _MdfSource(path, label)
    return _TextSource(path, label)  # .csv, .txt and anything else: a text table


# --------------------------------------------------------------------------
# Units
# --------------------------------------------------------------------------


@functools.cache
def _registry():
    import pint

    return pint.UnitRegistry()


def _unit_text(unit: str, key: str) -> str:
    text = unit.strip().replace("²", "^2").replace("°", "deg").replace("µ", "u")
    if key in _ACC:  # loggers' g is standard gravity, not the gram
        if re.fullmatch(r"[gG][nN0]?", text):
            return "standard_gravity"
        if text in ("mg", "mG"):
            return "milli_standard_gravity"
        text = re.sub(r"^m/s\s*2$", "m/s^2", text)
    if key in _RATES and text.lower() in ("dps", "deg/sec"):
        return "deg/s"
    return text


def _factor(unit: str, key: str, label: str, name: str) -> float:
    """Multiplier from ``unit`` to ehm's SI unit of ``key`` (pint)."""
    text = _unit_text(unit, key)
    if text == SI_UNITS[key] or (key == "time" and text in ("s", "sec")):
        return 1.0
    import pint

    ureg = _registry()
    what, examples = _KIND[key]
    try:
        q = ureg.Quantity(1.0, text)
    except (pint.errors.UndefinedUnitError, pint.errors.DefinitionSyntaxError, AttributeError, TypeError,
            ValueError, AssertionError):
        raise InputError(f"{label}, channel {key} ({name!r}): {unit!r} is not a unit pint knows (use e.g. {examples})."
                         ) from None
    try:
        return float(q.to(SI_UNITS[key]).magnitude)
    except pint.errors.DimensionalityError:
        raise InputError(f"{label}, channel {key} ({name!r}): unit {unit!r} is not {what} (use e.g. {examples}).") \
            from None


# --------------------------------------------------------------------------
# Reading
# --------------------------------------------------------------------------


def read_motion(source, channels: dict | None = None, units: dict | None = None, rate_hz: float | None = None,
                imu: bool = False, mounting=None, label: str | None = None, fill_gaps: bool = False) -> SeatMotion:
    """Read a seat motion (or an IMU log) from a file or a pandas DataFrame.

    Parameters
    ----------
    source : str, os.PathLike or pandas.DataFrame
        ``.csv``/``.txt`` (any other suffix is read as text too), ``.parquet``, ``.mat`` (v5 or v7.3),
        ``.mf4``/``.mdf``, or a DataFrame.
    channels : dict, optional
        Key (``time, ax, ay, az, wx, wy, wz``) -> the source's name; the others keep their defaults
        (:data:`DEFAULT_CHANNELS`).  ``time`` set to None: a source without a time channel (give
        ``rate_hz``).  ``wx, wy, wz`` all set to None: read the translation only, even where the source has
        angular velocities.  MDF channels carry their own time stamps: their ``time`` is not used.
    units : dict, optional
        Key -> unit string, where the source does not carry the unit (an MDF channel's own unit wins;
        a different one here is refused).  Default SI: s, m/s^2, rad/s.
    rate_hz : float, optional
        Samples per second of the returned motion: a source without a time channel is taken as sampled
        at this rate from t = 0; one with a time channel is resampled onto it (anti-aliased, as
        :meth:`ehm.motion.SeatMotion.resample`).
    imu : bool
        The source is an IMU at the seat: ``ax, ay, az`` its specific force (gravity included) and
        ``wx, wy, wz`` its gyro rates, all required; see :func:`ehm.imu.from_imu` (``mounting`` is passed on).
    label : str, optional
        How messages name the source (default: its path, or ``DataFrame``).
    fill_gaps : bool
        Bridge gaps in the time stamps (steps longer than :data:`GAP_STEPS` median steps) with a straight line,
        with a warning naming where; by default such a gap is refused.

    Returns
    -------
    SeatMotion
        Seat acceleration [m/s^2] in seat axes (and angular velocity [rad/s] when the source has rates),
        on the source's own time stamps [s] unless ``rate_hz`` asks for a rate.
    """
    channels = _mapping(channels, "channels")
    units = _mapping(units, "units")
    if rate_hz is not None:
        try:
            rate_hz = float(rate_hz)
        except (TypeError, ValueError):
            raise InputError(f"rate_hz must be a number of samples per second; got {rate_hz!r}.") from None
        if not (math.isfinite(rate_hz) and rate_hz > 0):
            raise InputError(f"rate_hz must be a positive number of samples per second; got {rate_hz!r}.")
    src = _open(source, label)
    try:
        return _read(src, channels, units, rate_hz, bool(imu), mounting, source, bool(fill_gaps))
    finally:
        src.close()


def _resolve(src: _Source, channels: dict, imu: bool, rate_hz) -> dict:
    """Key -> source name of every channel to read; missing ones named with what the source has."""
    names = {k: channels.get(k, DEFAULT_CHANNELS[k]) for k in CHANNEL_KEYS}

    def present(key):
        name = names[key]
        if name is None:
            return False
        return src.has(name) or (isinstance(src, _FrameSource) and key == "time" and src.has_index_time(name))

    wanted = list(_ACC) + list(_RATES if imu else [])
    left_out = [k for k in _RATES if k in channels and channels[k] is None]
    if left_out and (imu or len(left_out) < 3):
        raise InputError(f"{src.label}: {', '.join(left_out)} {'is' if len(left_out) == 1 else 'are'} left out (given "
                         "empty); " + ("an IMU log needs all three angular velocities." if imu else
                                       "leave out all three angular velocities (wx=, wy=, wz=) or none."))
    if not imu and len(left_out) < 3:
        rates_found = [k for k in _RATES if present(k)]
        explicit = [k for k in _RATES if k in channels]
        if explicit or rates_found:
            if rates_found and len(rates_found) < 3 and not explicit:
                absent = ", ".join(names[k] for k in _RATES if not present(k))
                raise InputError(f"{src.label}: it has {', '.join(names[k] for k in rates_found)} but not {absent}; "
                                 "give all three angular velocities or none.")
            wanted += list(_RATES)
    time_needed = not src.per_channel_time
    if time_needed:
        if names["time"] is None or ("time" not in channels and rate_hz is not None and not present("time")):
            names["time"] = None
            if rate_hz is None:
                raise InputError(f"{src.label}: without a time channel the sample rate is needed (rate_hz, --rate).")
        else:
            wanted.insert(0, "time")
    elif "time" in channels and channels["time"] is not None:
        raise InputError(f"{src.label}: MDF channels carry their own time stamps; leave out the time channel "
                         f"({channels['time']!r}).")
    missing = [k for k in wanted if not present(k)]
    if missing:
        parts = [f"{k} ({names[k]!r})" for k in missing]
        what = parts[0] if len(parts) == 1 else ", ".join(parts[:-1]) + " and " + parts[-1]
        verb = "is" if len(missing) == 1 else "are"
        raise InputError(f"{src.label}: channel{'s' * (len(missing) > 1)} {what} {verb} not in the "
                         f"{'file' if not isinstance(src, _FrameSource) else 'DataFrame'}; its {src.kind} are "
                         f"{_listed(src.names)}.")
    return {k: names[k] for k in wanted}


def _read(src: _Source, channels: dict, units: dict, rate_hz, imu: bool, mounting, source,
          fill_gaps: bool = False) -> SeatMotion:
    use = _resolve(src, channels, imu, rate_hz)
    if isinstance(src, _TextSource):
        src.load(list(use.values()))
    if isinstance(src, _MdfSource):
        for key, name in use.items():
            src.check_unique(key, name)
    data, stamps = {}, {}
    for key, name in use.items():  # one channel at a time: checked, in SI, each held once
        raw = src.values(name)
        values = _as_floats(src, name, key, raw)
        _check_finite(src, key, name, values)
        factor = _factor(_unit_of(src, key, name, units), key, src.label, name)
        if factor != 1.0:
            owned = values is not raw or not isinstance(src, _FrameSource)  # never change a caller's DataFrame
            values = np.multiply(values, factor, out=values if owned and values.flags.writeable else None)
        data[key] = values
        del raw, values
        if src.per_channel_time:
            stamps[key] = src.time_of(name)
    n = min(v.size for v in data.values())
    if any(v.size != n for v in data.values()) and not src.per_channel_time:
        raise InputError(f"{src.label}: the channels have different lengths "
                         f"({', '.join(f'{k} {v.size}' for k, v in data.items())}).")
    if src.per_channel_time:
        time_s, data = _common_time(src, use, data, stamps, fill_gaps)
    elif "time" in data:
        time_s = data.pop("time")
        _check_times(src, use["time"], time_s)
        _check_sampling(src, use["time"], time_s, fill_gaps)
    else:
        time_s = np.arange(n) / rate_hz
        rate_hz = None  # the source is at this rate already
    if time_s.size < 2:
        where = f", line {src.header_line}" if isinstance(src, _TextSource) else ""
        raise InputError(f"{src.label}{where}: motion file has {time_s.size} data row(s) after the header; at least 2 "
                         "are needed.")
    description = _describe(src, source, time_s)
    acc = _stack(data, _ACC)
    rates = _stack(data, _RATES) if all(k in data for k in _RATES) else None
    time_s = _frozen(np.array(time_s, dtype=float) if isinstance(src, _FrameSource) else time_s)
    if imu:
        from .imu import from_imu

        motion = from_imu(time_s, acc, rates, mounting=mounting, description=f"IMU log {description}",
                          label=src.label)
    else:
        motion = SeatMotion(time_s, acc, description, rates)  # takes the read-only arrays as they are
    if rate_hz is not None:
        motion = motion.resample(1.0 / rate_hz)
    return motion


def _stack(data: dict, keys) -> np.ndarray:
    """Columns into one (n, 3) read-only array, each channel's own array let go as soon as it is copied in."""
    out = np.empty((data[keys[0]].size, len(keys)))
    for j, k in enumerate(keys):
        out[:, j] = data.pop(k)
    return _frozen(out)


def _frozen(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


def _unit_of(src: _Source, key: str, name: str, units: dict) -> str:
    own = src.unit_of(name) if isinstance(src, _MdfSource) else src.units.get(name, "")
    if not own:
        own = _bracket_unit(name)
    given = units.get(key)
    if own and given and _factor(own, key, src.label, name) != _factor(given, key, src.label, name):
        raise InputError(f"{src.label}, channel {key} ({name!r}): the file gives the unit {own!r}, the units argument "
                         f"{given!r}; leave the argument out.")
    return given or own or SI_UNITS[key]


def _bracket_unit(name: str) -> str:
    """The unit in brackets at the end of a name (``"acc_x [g]"`` -> ``"g"``); a whole number in brackets is
    a matrix column (``"acc[0]"``, MATLAB), not a unit, and gives ``""``."""
    m = re.search(r"\[([^\]]+)\]\s*$", name)
    text = m.group(1).strip() if m else ""
    return "" if re.fullmatch(r"\d+", text) else text


def _check_finite(src: _Source, key: str, name: str, values: np.ndarray) -> None:
    bad = np.flatnonzero(~np.isfinite(values))
    if not bad.size:
        return
    i = int(bad[0])
    where = _column_words(src, name, key)
    if isinstance(src, _TextSource):
        if src.row_field_count(i) != len(src.names):
            raise InputError(f"{src.label}, {src.where(i)}: expected {len(src.names)} fields as in the header (line "
                             f"{src.header_line}), found {src.row_field_count(i)}.")
        if not src.field_text(name, i):
            raise InputError(f"{src.label}, {src.where(i)}, {where}: value is empty, expected a number.")
    elif np.isnan(values[i]) and isinstance(src, (_ParquetSource, _FrameSource)):
        raise InputError(f"{src.label}, {src.where(i)}, {where}: value is missing (NaN), expected a number.")
    raise InputError(f"{src.label}, {src.where(i)}, {where}: {src.raw(name, i)} is not a finite number (NaN or "
                     "infinite).")


def _check_times(src: _Source, name: str, t: np.ndarray) -> None:
    """Times >= 0 and strictly increasing, else one sentence with the rows and values."""
    where = _column_words(src, name, "time") if not isinstance(src, _TextSource) else f"column {name}"
    text = (lambda i: src.field_text(name, i)) if isinstance(src, _TextSource) else (lambda i: f"{t[i]:.9g}")
    if t.size and t[0] < 0:
        raise InputError(f"{src.label}, {src.where(0)}, {where}: time {text(0)} s is negative; times must be >= 0.")
    bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise InputError(f"{src.label}, {src.where(i)}, {where}: time {text(i)} s is not after the time "
                         f"{text(i - 1)} s on {src.where(i - 1)}; times must be strictly increasing.")


def _check_sampling(src: _Source, name: str, t: np.ndarray, fill_gaps: bool, key: str = "time") -> None:
    """One sample rate and no gaps, else one sentence naming where: a change of rate (the resampler would take
    the whole log at one rate, unfiltered) is refused; a gap (a step over :data:`GAP_STEPS` median steps) is
    refused, or bridged with a warning when ``fill_gaps``."""
    if t.size < 3:
        return
    steps = np.diff(t)
    median = float(np.median(steps))
    if steps.min() < median / RATE_CHANGE_RATIO or steps.max() > median * RATE_CHANGE_RATIO:
        _check_one_rate(src, name, t, steps, median, key)
    gaps = np.flatnonzero(steps > GAP_STEPS * median * (1 + 1e-6))  # (time stamps' round-off is no gap)
    if gaps.size:
        _gaps(src, name, t, gaps, median, fill_gaps, key)


def _check_one_rate(src: _Source, name: str, t: np.ndarray, steps: np.ndarray, median: float, key: str) -> None:
    """Refuse a log whose local median step leaves the median by :data:`RATE_CHANGE_RATIO` or more."""
    import pandas as pd

    local = pd.Series(steps).rolling(RATE_WINDOW, center=True, min_periods=1).median().to_numpy()
    other = (local <= median / RATE_CHANGE_RATIO) | (local >= median * RATE_CHANGE_RATIO)
    if not other.any() or other.all():
        return
    j = int(np.flatnonzero(other != other[0])[0])  # the first step of the second stretch, within the window
    lo, hi = max(0, j - RATE_WINDOW), min(steps.size, j + RATE_WINDOW)
    before, after = float(np.median(steps[lo:j])), float(np.median(steps[j:hi]))
    # the row where the second rate starts: the first step nearer (in ratio) to the second stretch's step
    near = np.abs(np.log(steps[lo:hi] / after)) < np.abs(np.log(steps[lo:hi] / before))
    row = lo + int(np.argmax(near))
    raise InputError(
        f"{src.label}, {src.where(row)}, {_column_words(src, name, key)}: the sample rate changes at t = "
        f"{t[row]:.6g} s from {1 / before:.6g} Hz to {1 / after:.6g} Hz; ehm resamples a log at one rate only: "
        "split the log at that row, or resample it to one rate (with an anti-alias filter) before reading it.")


def _gaps(src: _Source, name: str, t: np.ndarray, gaps: np.ndarray, median: float, fill_gaps: bool,
          key: str) -> None:
    """Refuse the first gap in one sentence, or warn once (naming the first and counting the rest)."""
    i = int(gaps[0]) + 1
    length = float(t[i] - t[i - 1])
    where = (f"{src.label}, {src.where(i)}, {_column_words(src, name, key)}: a gap of {length:.6g} s in the time "
             f"stamps, from t = {t[i - 1]:.6g} s to {t[i]:.6g} s ({length / median:.0f} median steps of {median:.6g} "
             "s)")
    if not fill_gaps:
        raise InputError(f"{where}; cut the log there, or give --fill-gaps (fill_gaps=True) to bridge "
                         f"{'it' if gaps.size == 1 else f'its {gaps.size} gaps'} with a straight line.")
    import warnings

    more = "" if gaps.size == 1 else f" (and {gaps.size - 1} more gaps, {float(np.sum(np.diff(t)[gaps])):.6g} s " \
        "in all)"
    warnings.warn(f"{where}{more} is bridged with a straight line (fill_gaps).", stacklevel=4)


#: MDF channels are read over their common time span; it must cover at least this share of the span they
#: reach together.  Groups of one logger start and stop within moments of each other (a few samples cut); a
#: channel that covers much less of the drive than the others is another recording, and cutting every channel
#: to it would quietly drop most of the drive.
MIN_OVERLAP = 0.9


def _check_overlap(src: _Source, use: dict, stamps: dict, start: float, stop: float, step: float) -> None:
    """Refuse MDF channels whose common span is less than :data:`MIN_OVERLAP` of their joint span."""
    first = min(float(stamps[k][0]) for k in use)
    last = max(float(stamps[k][-1]) for k in use)
    common = max(0.0, stop - start)
    if common >= step and common >= MIN_OVERLAP * (last - first):
        return
    spans = ", ".join(f"{k} ({use[k]!r}) {stamps[k][0]:.6g}-{stamps[k][-1]:.6g} s" for k in use)
    what = "do not overlap" if common < step else \
        f"overlap for {common:.6g} s of the {last - first:.6g} s they span ({100 * common / (last - first):.0f} %)"
    raise InputError(f"{src.label}: the channels' time stamps {what}: {spans}; ehm reads channels over their "
                     f"common span only, which must cover {100 * MIN_OVERLAP:.0f} % of theirs: pick channels "
                     "recorded together, or cut the log to the common span first (asammdf's MDF.cut).")


def _common_time(src: _Source, use: dict, data: dict, stamps: dict, fill_gaps: bool = False):
    """MDF: one time base for channels that may come from groups with different time stamps."""
    keys = list(use)
    first = stamps[keys[0]]
    for key in keys:
        _check_times(src, use[key], stamps[key])
        _check_sampling(src, use[key], stamps[key], fill_gaps, key)
    if all(stamps[k] is first or (stamps[k].shape == first.shape and np.array_equal(stamps[k], first))
           for k in keys):
        return first, data
    from .motion import Resampler

    start = max(float(stamps[k][0]) for k in keys)
    stop = min(float(stamps[k][-1]) for k in keys)
    step = min(float(np.median(np.diff(stamps[k]))) for k in keys)
    _check_overlap(src, use, stamps, start, stop, step)
    out = {}
    n = int(np.floor((stop - start) / step + 1e-9)) + 1
    for k in keys:
        t = stamps[k]
        i0 = max(0, int(np.searchsorted(t, start, side="right")) - 1)
        r = Resampler(t[i0:] - t[i0], data[k][i0:], step)
        offset = int(round((start - t[i0]) / step))
        out[k] = r.block(offset, min(offset + n, r.n_samples))[:, 0]
    n = min(v.size for v in out.values())
    return start + np.arange(n) * step, {k: v[:n] for k, v in out.items()}


def _describe(src: _Source, source, time_s: np.ndarray) -> str:
    base = os.path.basename(str(source)) if not isinstance(src, _FrameSource) else src.label
    description = f"from {base}, {time_s.size} samples, {float(time_s[-1] - time_s[0]):g} s"
    if src.first_comment:  # a file's first comment line describes it (e.g. "SYNTHETIC city drive ...")
        description = f"{src.first_comment} ({description})"
    return description
