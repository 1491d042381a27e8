"""The files of a simulation run, written chunk by chunk while it runs, so that memory does not grow with its length.

* ``timeseries.csv`` (and/or ``timeseries.parquet``): one row per output sample.  At an output rate below the
  model's, every k-th model step is written (k = model rate / output rate, a whole number); the samples are
  the simulated values at those times, not filtered.  The shipped drives and random seat vibration put less
  than 0.01 % of the outputs' power above 100 Hz (measured), so 200 Hz loses nothing of them; use the model's
  rate for inputs with content above half the output rate.
* ``summary.json``: scalars of the run; means and rms values are taken over every model step, whatever the
  output rate.
* ``poses.npz``: segment poses for pictures (streamed to disk, assembled at the end block by block).

:class:`RunWriter` takes the chunks of :meth:`ehm.SeatedHuman.stream` (or one whole :class:`~ehm.RunResult`); it
writes into a folder that :class:`ehm.outputs.outdir.RunFolder` then puts in place as one unit.
"""

from __future__ import annotations

import contextlib
import math
import shutil
import zipfile
from pathlib import Path

import numpy as np

from ..errors import InputError, describe

DEFAULT_OUTPUT_RATE_HZ = 200.0  #: Rows per second of ``timeseries.csv`` written by ``ehm simulate`` by default.
FORMATS = ("csv", "parquet")  #: Time-series file formats.


def check_formats(formats) -> tuple[str, ...]:
    """``formats`` (one name or several) as a tuple of names of :data:`FORMATS`, or one sentence naming the first
    that is not one."""
    names = (formats,) if isinstance(formats, str) else formats
    if not isinstance(names, (tuple, list)) or not names:
        raise InputError(f"time-series formats must be csv and/or parquet (formats=('csv',), --format), not "
                         f"{describe(formats)}.")
    unknown = [f for f in names if f not in FORMATS]
    if unknown:
        raise InputError(f"time-series format {unknown[0]!r}: use csv and/or parquet (formats=('csv', 'parquet'), "
                         "--format).")
    return tuple(names)
PREVIEW_ROWS = 20000  #: Most rows kept in memory for the figure of a streamed run.
_ROW_GROUP_ROWS = 10000  #: Rows per Parquet row group (at most this many rows are held before they are written).
_CSV_FORMAT = "%.9g"  #: As :func:`ehm.files.write_csv_atomic`: 9 significant digits.
_POSE_KEYS = ("time_s", "pos", "quat")


def default_output_every(dt_s: float) -> int:
    """Model steps per output sample by default: :data:`DEFAULT_OUTPUT_RATE_HZ`, or the nearest whole fraction
    of the model's rate above it (every step when the model runs at less than that)."""
    return max(1, int(math.floor((1.0 / dt_s) / DEFAULT_OUTPUT_RATE_HZ + 1e-9)))


def output_every(rate_hz: float | None, dt_s: float) -> int:
    """Model steps per output sample for an output rate [Hz] (None: every step); the rate must divide the model's."""
    if rate_hz is None:
        return 1
    model_hz = 1.0 / dt_s
    if not (isinstance(rate_hz, (int, float)) and math.isfinite(rate_hz) and 0 < rate_hz <= model_hz * (1 + 1e-9)):
        raise InputError(f"--output-rate {rate_hz!r}: give a rate in Hz above 0 and at most the model's "
                         f"{model_hz:g} Hz (time step {dt_s:g} s).")
    k = max(1, int(round(model_hz / rate_hz)))
    if abs(k * rate_hz - model_hz) > 1e-6 * model_hz:
        options = [model_hz / n for n in range(1, 21) if abs(model_hz / n - round(model_hz / n, 6)) < 1e-9][:6]
        raise InputError(f"--output-rate {rate_hz:g} Hz does not divide the model's {model_hz:g} Hz (time step "
                         f"{dt_s:g} s); choose one that does, e.g. {', '.join(f'{o:g}' for o in options)}.")
    return k


def pyarrow_modules():
    """pyarrow and pyarrow.parquet, or one sentence naming the extra to install."""
    try:
        import pyarrow
        import pyarrow.parquet
    except ImportError:
        raise InputError("the Parquet format needs pyarrow: pip install 'ehm[parquet]' (or write --format csv)."
                         ) from None
    return pyarrow, pyarrow.parquet


class SummaryAccumulator:
    """The scalars of ``summary.json``, accumulated chunk by chunk (sums over every model step)."""

    def __init__(self):
        self.n = 0
        self.wall_s = 0.0
        self.first = self.last = None
        self.sums: dict[str, np.ndarray] = {}

    def _add(self, key: str, value: np.ndarray) -> None:
        self.sums[key] = self.sums[key] + value if key in self.sums else value

    def add(self, chunk) -> None:
        if self.first is None:
            self.first = chunk
        self.last = chunk
        self.n += len(chunk.time_s)
        self.wall_s += chunk.wall_s
        self._add("seat_acc_sq", np.sum(chunk.seat_acc_mps2 ** 2, axis=0))
        for s, f in chunk.support_N.items():
            self._add(f"support:{s}", np.sum(f, axis=0))
        for p, m in chunk.points.items():
            self._add(f"{p}_acc_sq", np.sum(m.acc_mps2 ** 2, axis=0))
            self._add(f"{p}_rot_sq", np.sum(m.rot_rad ** 2, axis=0))

    def summary(self, output_rate_hz: float | None = None) -> dict:
        from .. import engine

        c, n = self.first, self.n
        duration = float((n - 1) * c.dt_s)
        by_surface = {s: self.sums[f"support:{s}"] / n for s in c.support_N}
        out = {
            "mass_kg": c.mass_kg,
            "dof": c.dof,
            "locked": list(c.locked),
            "duration_s": duration,
            "dt_s": c.dt_s,
            "wall_s": self.wall_s,
            "realtime_factor": duration / self.wall_s if self.wall_s > 0 else float("inf"),
            "input": c.description,
            "params": c.params_origin,
            "support_force_mean_N": sum(by_surface.values()).tolist(),
            "support_force_mean_by_surface_N": {k: v.tolist() for k, v in by_surface.items()},
            "body_weight_N": c.mass_kg * -engine.G0[2],
            "seat_acc_rms_mps2": np.sqrt(self.sums["seat_acc_sq"] / n).tolist(),
        }
        for p in c.points:
            out[f"{p}_acc_rms_mps2"] = np.sqrt(self.sums[f"{p}_acc_sq"] / n).tolist()
            out[f"{p}_rot_rms_rad"] = np.sqrt(self.sums[f"{p}_rot_sq"] / n).tolist()
        if output_rate_hz is not None:
            out["output_rate_hz"] = output_rate_hz
        out.update(c.extra)
        out.update(self.last.extra)  # the last chunk carries a route's report (ehm.routes.hybrid)
        return out


class _CsvStream:
    def __init__(self, path: Path):
        self.path = path
        self.fh = open(path, "w", encoding="utf-8", newline="\n")
        self.header = None

    def write(self, header: list[str], data: np.ndarray) -> None:
        if self.header is None:
            self.header = header
            self.fh.write(",".join(header) + "\n")
        if data.shape[0]:
            row = ",".join([_CSV_FORMAT] * data.shape[1])
            self.fh.write("\n".join([row] * data.shape[0]) % tuple(data.ravel().tolist()) + "\n")

    def close(self) -> None:
        self.fh.close()


class _ParquetStream:
    def __init__(self, path: Path):
        self.pa, self.pq = pyarrow_modules()
        self.path = path
        self.writer = None
        self.pending: list[np.ndarray] = []
        self.rows = 0

    def write(self, header: list[str], data: np.ndarray) -> None:
        if self.writer is None:
            schema = self.pa.schema([(h, self.pa.float64()) for h in header])
            self.writer = self.pq.ParquetWriter(str(self.path), schema)
            self.header = header
        self.pending.append(data)
        self.rows += data.shape[0]
        if self.rows >= _ROW_GROUP_ROWS:
            self.flush()

    def flush(self) -> None:
        if self.pending:
            self.writer.write_table(self.pa.table({h: self.pa.chunked_array([b[:, j] for b in self.pending])
                                                   for j, h in enumerate(self.header)}))
        self.pending, self.rows = [], 0

    def close(self) -> None:
        if self.writer is not None:
            self.flush()
            self.writer.close()


class _PoseStream:
    """Segment poses appended to raw files, assembled into ``poses.npz`` (as numpy.savez_compressed) at the end."""

    def __init__(self, folder: Path):
        self.folder = folder
        self.raw = {k: folder / f".poses_{k}.raw" for k in _POSE_KEYS}
        self.fh = {k: open(p, "wb") for k, p in self.raw.items()}
        self.shapes = {k: None for k in _POSE_KEYS}
        self.count = 0
        self.static: dict = {}

    def add(self, poses: dict) -> None:
        for k in _POSE_KEYS:
            a = np.ascontiguousarray(poses[k], dtype="<f8")
            self.shapes[k] = a.shape[1:]
            self.fh[k].write(a.tobytes())
        self.count += len(poses["time_s"])
        if not self.static:
            self.static = {k: np.asarray(v) for k, v in poses.items() if k not in _POSE_KEYS}

    def finish(self, path: Path) -> None:
        for f in self.fh.values():
            f.close()
        with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as zf:
            for k in _POSE_KEYS:
                header = {"descr": np.lib.format.dtype_to_descr(np.dtype("<f8")), "fortran_order": False,
                          "shape": (self.count, *self.shapes[k])}
                with zf.open(f"{k}.npy", "w", force_zip64=True) as out, open(self.raw[k], "rb") as src:
                    np.lib.format.write_array_header_2_0(out, header)
                    shutil.copyfileobj(src, out, 1 << 20)
            for k, v in self.static.items():
                with zf.open(f"{k}.npy", "w", force_zip64=True) as out:
                    np.lib.format.write_array(out, v, allow_pickle=False)
        self.remove_raw()

    def remove_raw(self) -> None:
        for f in self.fh.values():
            with contextlib.suppress(OSError):  # closing flushes: on a full disk that fails again
                f.close()
        for p in self.raw.values():
            with contextlib.suppress(OSError):
                p.unlink(missing_ok=True)


class RunWriter:
    """Write a run's files into ``folder`` chunk by chunk: :meth:`add` each chunk, then :meth:`close`.

    Parameters
    ----------
    folder : Path
        An existing folder (usually the staging folder of a :class:`ehm.outputs.outdir.RunFolder`).
    output_every : int
        Write every this many model steps (counted from t = 0 across chunks).
    formats : tuple of str
        ``"csv"`` and/or ``"parquet"``.
    preview_rows : int
        Keep at most about this many rows in memory (evenly spread over the run, ``n_steps`` long) for a
        figure; 0 keeps none.
    """

    def __init__(self, folder: Path | str, output_every: int = 1, formats=("csv",), preview_rows: int = 0,
                 n_steps: int | None = None):
        self.folder = Path(folder)
        formats = check_formats(formats)
        self.every = int(output_every)
        self.streams = {}
        self.poses: _PoseStream | None = None
        try:
            if "parquet" in formats:
                self.streams["parquet"] = _ParquetStream(self.folder / "timeseries.parquet")
            if "csv" in formats:
                self.streams["csv"] = _CsvStream(self.folder / "timeseries.csv")
        except OSError as exc:
            self.abort()
            raise InputError(f"{self.folder}: cannot write the time series ({exc.strerror or exc}).") from None
        self.summary = SummaryAccumulator()
        self.preview_every = max(1, -(-n_steps // preview_rows)) if preview_rows and n_steps else 0
        self.preview: list = []
        self.dt_s = None

    def add(self, chunk) -> None:
        """Append one chunk (a :class:`ehm.outputs.results.RunResult` with absolute times)."""
        dt = self.dt_s = chunk.dt_s
        first = int(round(chunk.time_s[0] / dt)) if len(chunk.time_s) else 0
        header, data = chunk.columns()
        rows = data[(-first) % self.every::self.every]
        for s in self.streams.values():
            s.write(header, rows)
        self.summary.add(chunk)
        if chunk.poses is not None:
            if self.poses is None:
                self.poses = _PoseStream(self.folder)
            self.poses.add(chunk.poses)
        if self.preview_every:
            self.preview.append(chunk.take(slice((-first) % self.preview_every, None, self.preview_every)))

    def close(self) -> tuple[dict, list]:
        """Finish the files and write ``summary.json``; returns (summary, preview pieces: thinned chunks, in order,
        for ``ehm.outputs.results.concatenate_runs``; empty without a preview)."""
        from ..files import write_json_atomic

        if self.summary.first is None:
            raise InputError("the run has no samples to write.")
        for s in self.streams.values():
            s.close()
        if self.poses is not None:
            self.poses.finish(self.folder / "poses.npz")
        summary = self.summary.summary(output_rate_hz=1.0 / (self.every * self.dt_s))
        write_json_atomic(self.folder / "summary.json", summary)
        return summary, list(self.preview)

    def abort(self) -> None:
        """Close open files (the folder is discarded by its RunFolder)."""
        for s in self.streams.values():
            try:
                s.close()
            except Exception:  # noqa: BLE001 - closing after a failure: the folder is removed anyway
                pass
        if self.poses is not None:
            self.poses.remove_raw()


def write_run(folder: Path | str, chunks, output_every: int = 1, formats=("csv",), preview_rows: int = 0,
              n_steps: int | None = None) -> tuple[dict, list]:
    """Write the chunks of one run into ``folder`` as they come; returns (summary, preview pieces): the pieces are
    the chunks thinned to at most ``preview_rows`` rows in all (none when 0), for the caller to join with
    ``ehm.outputs.results.concatenate_runs``.  This module reads runs by duck typing and imports no run class."""
    writer = RunWriter(folder, output_every, formats, preview_rows, n_steps)
    try:
        for chunk in chunks:
            writer.add(chunk)
        return writer.close()
    except OSError as exc:  # a full disk, a folder removed under the run
        writer.abort()
        raise InputError(f"{folder}: cannot write the run's files ({exc.strerror or exc}).") from None
    except BaseException:
        writer.abort()
        raise
