"""Column tables held whole by another library: a pandas DataFrame (its index may be the time) and a Parquet file
(pyarrow; units from the fields' ``unit`` metadata)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import InputError
from .base import Source


class FrameSource(Source):
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
        if self.names.count(name) > 1:
            raise InputError(f"{self.label}: column {name!r} appears {self.names.count(name)} times in the DataFrame; "
                             "keep one of them (e.g. frame.loc[:, ~frame.columns.duplicated()]) or rename the others.")
        return self.frame.iloc[:, self.names.index(name)].to_numpy()

    def where(self, row: int) -> str:
        row = self.file_row(row)
        return f"row {row} (index {self.frame.index[row]!r})"

    def raw(self, name: str, row: int) -> str:
        value = self.values(name)[self.file_row(row)]
        return repr(value.item() if hasattr(value, "item") else value)


class ParquetSource(Source):
    """A Parquet file's columns (read with pyarrow) as a source of channels."""

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
