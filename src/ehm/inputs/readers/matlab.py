"""MATLAB ``.mat`` files: v5 with scipy.io, v7.3 (HDF5) with pymatreader (extra ``logs``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import InputError
from .base import Source


class MatSource(Source):
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
