"""What every source format answers: a table of named channels (:class:`Source`), and a channel as floats."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError
from .channels import DEFAULT_CHANNELS


@dataclass
class Source:
    """A table of named channels: what it holds and how to read one channel as floats."""

    label: str
    names: list
    kind: str = "columns"                       # what its channels are called in messages
    first_comment: str = ""
    per_channel_time: bool = False              # MDF: each channel has its own time stamps
    units: dict = field(default_factory=dict)   # name -> unit string the source gives
    rows: object = None                         # the source's rows of the values read, once cut (the first row's
    #                                             index) or thinned (an array of rows); None: the same rows

    def file_row(self, row: int) -> int:
        """The source's own row of row ``row`` of the values read (they may be cut, or held repeats dropped)."""
        if self.rows is None:
            return row
        return row + self.rows if isinstance(self.rows, int) else int(self.rows[row])

    def where(self, row: int) -> str:
        """Where a row is, for messages."""
        return f"row {self.file_row(row)}"

    def raw(self, name: str, row: int) -> str:
        """The row's value as the source holds it, for messages."""
        value = self.values(name)[self.file_row(row)]
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


def as_floats(src: Source, name: str, key: str, column) -> np.ndarray:
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
        raise InputError(f"{src.label}, {src.where(i)}, {column_words(src, name, key)}: {src.raw(name, i)} is not "
                         "a number.")
    return numeric


def column_words(src: Source, name: str, key: str) -> str:
    """How a message names channel ``key`` read as ``name`` from ``src`` (a column, or a named channel)."""
    if src.kind == "columns":  # the channel is named when the column's name does not say it
        return f"column {name}" if name == DEFAULT_CHANNELS[key] else f"column {name} (channel {key})"
    return f"channel {key} ({name!r})"
