"""Seat-to-body frequency response functions (paper Eq. 1), in the long format the tools exchange.

A :class:`FrfTable` holds curves addressed by ``(input_axis, point, dof)``: input axis ``x``, ``y`` or
``z``; point ``pelvis``, ``trunk``, ``head`` or ``lumbar`` (the L4-L5 joint centre); dof ``x``, ``y``, ``z``
(translational gain, (m/s^2)/(m/s^2)) or ``roll``, ``pitch``, ``yaw`` (rotational gain, (rad/s^2)/(m/s^2)).
Apparent mass (ISO 5982), the force on the body per unit seat acceleration [kg], has the points ``support``
(all surfaces: seat pan, backrest and floor together) and ``seat_pan`` (the seat pan alone, with its cushion
bolsters), dof the input axis: ``(axis, "support", axis)``, ``(axis, "seat_pan", axis)``.  At low
frequencies, where the body moves with the seat, the vertical apparent mass is the mass the surfaces
carry.  Its CSV (or Parquet) form has the columns ``input_axis, point, dof, freq_hz, gain, phase_deg,
coherence`` (plus ``gain_sd`` and ``weight`` in measured data).

Two routes compute a model's table: :func:`~ehm.time_domain_frf` (random seat vibration, the paper's 0-12 Hz
Butterworth filter on input and output, Welch H1 estimate) and :func:`~ehm.linear_frf` (exact frequency
response of the model linearised around its settled posture).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..engine.linearisation import LinearModel
from ..errors import InputError, checked, checked_class, frequencies_hz, frequency_grid
from ..files import write_text_atomic
from ..inputs.motion import SeatMotion
from ..standards.transfer import Curve, band_select

AXES = ("x", "y", "z")
POINTS = ("pelvis", "trunk", "head", "lumbar")  #: as ``ehm.engine.POINTS``
#: Apparent-mass "points": all support surfaces together, and the seat pan alone [kg].
MASS_POINTS = ("support", "seat_pan")
ALL_POINTS = POINTS + MASS_POINTS
DOFS = ("x", "y", "z", "roll", "pitch", "yaw")
COLUMNS = ("input_axis", "point", "dof", "freq_hz", "gain", "phase_deg", "coherence")
#: Linear-model output holding each FRF dof.
_LINEAR_OUTPUT = {"x": "ax", "y": "ay", "z": "az", "roll": "roll_acc", "pitch": "pitch_acc", "yaw": "yaw_acc"}


@checked_class
@dataclass(frozen=True)
class FrfTable:
    """Frequency response curves by ``(input_axis, point, dof)``.

    Attributes
    ----------
    curves : dict
        ``(input_axis, point, dof) -> Curve``.
    method : str
        ``time``, ``linear`` or ``measured``.
    meta : dict
        What produced it (input, locks, parameter file).
    """

    curves: dict
    method: str = "measured"
    meta: dict = field(default_factory=dict)

    def curve(self, input_axis: str, point: str, dof: str) -> Curve:
        """The curve of one path; :class:`InputError` if the table lacks it."""
        key = (input_axis, point, dof)
        if key not in self.curves:
            where = self.meta.get("file", f"the {self.method} table")
            raise InputError(f"{where} has no curve for seat {input_axis} -> {point} {dof}.")
        return self.curves[key]

    def keys(self) -> list:
        """Curve keys in the canonical order (axis, point, dof)."""
        return sorted(self.curves, key=lambda k: (AXES.index(k[0]), ALL_POINTS.index(k[1]), DOFS.index(k[2])))

    def peaks(self) -> list[tuple[tuple, float, float, str]]:
        """The peak of every path along its input axis (seat x -> point x, ..., and the apparent masses):
        ``[((input_axis, point, dof), peak_hz, peak_gain, unit), ...]`` in :meth:`keys` order, what ``ehm frf``
        prints and the reprs show."""
        out = []
        for key in self.keys():
            c = self.curves[key]
            if key[2] == key[0] and c.freq_hz.size:
                f, g = c.peak((float(c.freq_hz[0]), float(c.freq_hz[-1])))
                out.append((key, float(f), float(g), gain_unit(key[1], key[2])))
        return out

    def __repr__(self) -> str:
        f = np.concatenate([c.freq_hz for c in self.curves.values()]) if self.curves else np.zeros(0)
        axes = sorted({k[0] for k in self.curves}, key=AXES.index)
        band = f", {f.min():.3g}-{f.max():.3g} Hz" if f.size else ""
        head = [f"{k[0]}: {g:.3g} at {fp:.3g} Hz" for k, fp, g, _ in self.peaks() if k[1] == "head"]
        seated = self.meta.get("seated")
        who = "" if not isinstance(seated, dict) else (
            f", {seated.get('posture')}, back support {seated.get('back_support')}, head control "
            f"{'on' if seated.get('head_control') else 'off'}")
        return (f"<FrfTable {self.method}{who}: {len(self.curves)} curves, seat {'/'.join(axes) or '-'}{band}"
                + (f"; head peaks {', '.join(head)}" if head else "") + ">")

    def _optional_columns(self) -> tuple[bool, bool]:
        """Whether ``gain_sd`` and ``weight`` carry data (measured tables), so the long forms hold them."""
        curves = self.curves.values()
        return any(np.isfinite(c.gain_sd).any() for c in curves), any(c.weight != 1.0 for c in curves)

    def _long_columns(self) -> dict:
        """The long table as columns (the CSV's and Parquet's, every one), the rows in :meth:`keys` order."""
        keys = self.keys()
        curves = [self.curves[k] for k in keys]
        cat = lambda get: np.concatenate([get(c) for c in curves]) if curves else np.zeros(0)  # noqa: E731
        labels = {col: [k[i] for k, c in zip(keys, curves) for _ in c.freq_hz]
                  for i, col in enumerate(("input_axis", "point", "dof"))}
        return {**labels, "freq_hz": cat(lambda c: c.freq_hz), "gain": cat(lambda c: c.gain),
                "phase_deg": cat(lambda c: c.phase_deg), "coherence": cat(lambda c: c.coherence),
                "gain_sd": cat(lambda c: c.gain_sd), "weight": cat(lambda c: np.full(c.freq_hz.size, c.weight)),
                "gain_unit": [gain_unit(p, d) for p, d in zip(labels["point"], labels["dof"])]}

    def _attrs(self) -> dict:
        meta = {k: v for k, v in self.meta.items() if isinstance(v, (str, int, float, tuple, list))}
        description = self.meta.get("input") or self.meta.get("file") or {
            "linear": "the person linearised at rest (exact response)",
            "time": "random seat vibration"}.get(self.method, self.method)
        route = self.meta.get("route", "linear" if self.method == "linear" else None)
        return {**meta, "description": description, "route": route, "method": self.method}

    def to_dataframe(self):
        """The long table as a pandas DataFrame, one row per curve and frequency: the CSV's columns
        (``input_axis, point, dof, freq_hz, gain, phase_deg, coherence``, plus ``gain_sd`` and ``weight`` when
        they carry data) and ``gain_unit`` (``(m/s^2)/(m/s^2)``, ``(rad/s^2)/(m/s^2)`` or ``kg``, see
        :func:`ehm.analysis.frf.gain_unit`); what produced it (description, route, method, settings) in
        ``DataFrame.attrs``."""
        from ..outputs.dataframes import frame

        with_sd, with_w = self._optional_columns()
        cols = self._long_columns()
        keep = COLUMNS + ("gain_sd",) * with_sd + ("weight",) * with_w + ("gain_unit",)
        return frame({c: cols[c] for c in keep}, self._attrs(),
                     labels={"input_axis": AXES, "point": ALL_POINTS, "dof": DOFS})

    def _repr_html_(self) -> str:
        from ..outputs.dataframes import html_table

        rows = [[f"seat {k[0]} -> {k[1]} {k[2]}", f, g, unit] for k, f, g, unit in self.peaks()]
        attrs = self._attrs()
        f = np.concatenate([c.freq_hz for c in self.curves.values()]) if self.curves else np.zeros(0)
        facts = {"input": attrs["description"], "route": attrs.get("route") or "", "method": self.method,
                 "curves": f"{len(self.curves)}" + (f", {f.min():.3g}-{f.max():.3g} Hz" if f.size else "")}
        return html_table("ehm FrfTable", facts, ["path (along the input axis)", "peak [Hz]", "peak gain", "unit"],
                          rows)

    def record(self) -> dict:
        """What the file records of the table besides its curves: the method and what produced it (the person as
        :meth:`ehm.Person.to_dict` gives it, the route and the excitation), JSON-ready."""
        keep = {k: v for k, v in self.meta.items() if k != "file" and _json_ready(v)}
        return {"method": self.method, **keep}

    def to_csv(self, path: Path | str) -> None:
        """Write the long-format CSV (whole or not at all); ``gain_sd`` and ``weight`` only when they carry data.

        Two comment lines (``#``) come first: what wrote the file and, as JSON after ``# ehm:``, the method and
        the person (:meth:`record`), so :func:`read_frf` tells ehm's own tables from measured ones (with pandas:
        ``pandas.read_csv(path, comment="#")``)."""
        curves = [self.curves[k] for k in self.keys()]
        with_sd, with_w = self._optional_columns()
        banner = _CSV_MEASURED if self.method == "measured" else _CSV_BANNER.format(method=self.method)
        lines = [banner, _RECORD_PREFIX + json.dumps(self.record())]
        lines.append(",".join(COLUMNS + ("gain_sd",) * with_sd + ("weight",) * with_w))
        for key, c in zip(self.keys(), curves):
            for f, g, ph, coh, sd in zip(c.freq_hz, c.gain, c.phase_deg, c.coherence, c.gain_sd):
                row = [*key, f"{f:.6g}", f"{g:.8g}", _fmt(ph), _fmt(coh)]
                row += [_fmt(sd)] * with_sd + [f"{c.weight:g}"] * with_w
                lines.append(",".join(row))
        write_text_atomic(path, "\n".join(lines) + "\n")

    def to_parquet(self, path: Path | str) -> None:
        """Write the same long table as Parquet (pyarrow; whole or not at all)."""
        from ..files import replace_atomically
        from ..outputs.runfiles import pyarrow_modules

        pa, pq = pyarrow_modules()
        cols = self._long_columns()
        table = pa.table({c: cols[c] for c in COLUMNS + ("gain_sd", "weight")})
        table = table.replace_schema_metadata({**(table.schema.metadata or {}),
                                               _PARQUET_KEY: json.dumps(self.record())})
        replace_atomically(path, lambda tmp: pq.write_table(table, tmp), "the FRF table")

    def write(self, path: Path | str) -> None:
        """Write as Parquet when ``path`` ends in ``.parquet``, else as CSV."""
        (self.to_parquet if str(path).lower().endswith(".parquet") else self.to_csv)(path)


def gain_unit(point: str, dof: str) -> str:
    """The unit of a curve's gain: ``kg`` for apparent mass (points ``support``, ``seat_pan``),
    ``(rad/s^2)/(m/s^2)`` for a rotation (roll, pitch, yaw), ``(m/s^2)/(m/s^2)`` for a translation."""
    if point in MASS_POINTS:
        return "kg"
    return "(rad/s^2)/(m/s^2)" if dof in ("roll", "pitch", "yaw") else "(m/s^2)/(m/s^2)"


#: The first line of an FRF CSV that ehm writes, and the prefix of the second (the table's record, JSON).
_CSV_BANNER = "# ehm FRF table ({method} method): written by ehm, not measured; the line below records how (JSON)"
_CSV_MEASURED = "# measured gains, written out by ehm; the line below records how (JSON)"
_RECORD_PREFIX = "# ehm: "
#: The key of the record in a Parquet file's schema metadata.
_PARQUET_KEY = b"ehm"


def _json_ready(value) -> bool:
    try:
        json.dumps(value)
    except (TypeError, ValueError):
        return False
    return True


def _csv_record(path: Path | str) -> dict | None:
    """The record of an FRF CSV that ehm wrote (its ``# ehm:`` comment line before the header), else None."""
    try:
        with open(path, encoding="utf-8-sig") as f:
            for line in f:
                if not line.lstrip().startswith("#"):
                    return None
                if line.startswith(_RECORD_PREFIX):
                    record = json.loads(line[len(_RECORD_PREFIX):])
                    return record if isinstance(record, dict) else None
    except (OSError, UnicodeDecodeError, ValueError):
        return None  # the table reader says what is wrong with the file
    return None


def _from_record(record: dict | None, label: str) -> tuple[str, dict]:
    """The method and meta of a table read back: ehm's own (its record) or measured."""
    if not record or record.get("method") not in ("linear", "time", "measured", "model"):
        return "measured", {"file": label}
    meta = {k: v for k, v in record.items() if k != "method"}
    return record["method"], {**meta, "file": label, "written_by": "ehm"}


def _fmt(v: float) -> str:
    return "" if not np.isfinite(v) else f"{v:.6g}"


def read_frf_csv(path: Path | str) -> FrfTable:
    """Read a long-format FRF or measured-gain CSV.

    Required columns: ``input_axis``, ``point``, ``dof``, ``freq_hz``, ``gain``; optional: ``phase_deg``,
    ``coherence``, ``gain_sd``, ``weight`` (per curve; the same on every row of a curve).  Lines starting with
    ``#`` are comments.  A table ehm wrote (``FrfTable.to_csv``: a ``# ehm:`` line with its record before the
    header) comes back with its method and record (``meta["person"]``, ``meta["written_by"]``); any other is
    ``measured``.  Rejects, with file and line: unknown axis, point or dof, a non-positive or repeated
    frequency, a NaN, infinite or negative gain, a non-numeric value, a missing column.
    """
    from ..body.tables import CsvTable

    label = str(path)
    table = CsvTable(path, label=label)
    for col in ("input_axis", "point", "dof", "freq_hz", "gain"):
        if col not in table.header:
            raise InputError(f"{label}: missing column {col!r}.")
    data: dict = {}
    weights: dict = {}
    for lineno, get in table.rows:
        key = tuple(table.choice(lineno, get, col, allowed, col.replace("_", " "))
                    for col, allowed in (("input_axis", AXES), ("point", ALL_POINTS), ("dof", DOFS)))

        def number(col: str, optional: bool = False, get=get, lineno=lineno) -> float:
            """A number; NaN for an optional column that is absent or empty."""
            if optional and get.get(col, "") == "":
                return math.nan
            return table.number(lineno, get, col, None)

        f = number("freq_hz")
        if f <= 0:
            raise InputError(f"{label}, line {lineno}, column freq_hz: frequency {f:g} Hz must be positive.")
        g = number("gain")
        if g < 0:
            raise InputError(f"{label}, line {lineno}, column gain: gain {g:g} must not be negative.")
        w = number("weight", optional=True)
        if math.isnan(w):
            w = 1.0
        if w < 0:
            raise InputError(f"{label}, line {lineno}, column weight: weight {w:g} must not be negative.")
        if key in weights and weights[key] != w:
            raise InputError(f"{label}, line {lineno}, column weight: the curve {'/'.join(key)} has two weights.")
        weights[key] = w
        data.setdefault(key, []).append((lineno, f, g, number("phase_deg", True), number("coherence", True),
                                         number("gain_sd", True)))
    curves = {}
    for key, rows_ in data.items():
        rows_.sort(key=lambda r: r[1])
        arr = np.array([r[1:] for r in rows_], dtype=float)
        dup = np.nonzero(np.diff(arr[:, 0]) == 0)[0]
        if dup.size:
            raise InputError(f"{label}, line {rows_[dup[0] + 1][0]}, column freq_hz: frequency {arr[dup[0], 0]:g} Hz "
                             f"appears twice in the curve {'/'.join(key)}.")
        curves[key] = Curve(freq_hz=arr[:, 0], gain=arr[:, 1], phase_deg=arr[:, 2], coherence=arr[:, 3],
                            gain_sd=arr[:, 4], weight=weights[key])
    method, meta = _from_record(_csv_record(path), label)
    return FrfTable(curves=curves, method=method, meta=meta)


@checked
def read_frf(path: Path | str) -> FrfTable:
    """An FRF table from CSV (:func:`~ehm.analysis.frf.read_frf_csv`) or from Parquet written by
    :meth:`FrfTable.to_parquet`: ehm's own tables with their method and the person they were computed for
    (``meta["person"]``, :meth:`ehm.Person.to_dict`), any other table as ``measured``."""
    if not str(path).lower().endswith(".parquet"):
        return read_frf_csv(path)
    from ..inputs.readers.frames import ParquetSource

    src = ParquetSource(Path(path), str(path))
    missing = [c for c in COLUMNS[:5] if c not in src.names]
    if missing:
        raise InputError(f"{path}: missing column {missing[0]!r}.")
    cols = {c: src.values(c) for c in src.names if c in COLUMNS + ("gain_sd", "weight")}
    n = len(cols["gain"])
    curves: dict = {}
    for i in range(n):
        key = (str(cols["input_axis"][i]), str(cols["point"][i]), str(cols["dof"][i]))
        for name, value, allowed in zip(("input_axis", "point", "dof"), key, (AXES, ALL_POINTS, DOFS)):
            if value not in allowed:
                raise InputError(f"{path}, row {i}, column {name}: {value!r} is not one of {', '.join(allowed)}.")
        curves.setdefault(key, []).append(i)
    method, meta = _from_record(_parquet_record(path), str(path))
    get = lambda c, rows: (np.asarray(cols[c], dtype=float)[rows] if c in cols  # noqa: E731
                           else np.full(len(rows), np.nan))
    out = {}
    for key, rows in curves.items():
        rows = np.array(rows)
        w = get("weight", rows)
        out[key] = Curve(get("freq_hz", rows), get("gain", rows), get("phase_deg", rows), get("coherence", rows),
                         get("gain_sd", rows), float(w[0]) if np.isfinite(w[0]) else 1.0)
    return FrfTable(curves=out, method=method, meta=meta)


def _parquet_record(path: Path | str) -> dict | None:
    """The record of an FRF Parquet file that ehm wrote (its schema metadata), else None."""
    try:
        from ..outputs.runfiles import pyarrow_modules

        _, pq = pyarrow_modules()
        raw = (pq.read_schema(path).metadata or {}).get(_PARQUET_KEY)
        record = json.loads(raw) if raw else None
    except Exception:  # no pyarrow, or unreadable metadata: the table is read as measured
        return None
    return record if isinstance(record, dict) else None


def _axes(axis: str) -> tuple[str, ...]:
    if axis == "all":
        return AXES
    if axis not in AXES:
        raise InputError(f"unknown input axis {axis!r}; use x, y, z or all.")
    return (axis,)


def run_curves(run, axis: str, band_hz: tuple[float, float] = (0.1, 12.0), segment_s: float = 10.0) -> dict:
    """Curves of one run that excited seat axis ``axis``: H1 estimates of every point and dof (Eq. 1), and the
    apparent masses along ``axis`` of all supports and of the seat pan [kg].

    Input and outputs pass the paper's 12 Hz Butterworth low-pass; gains are kept within ``band_hz``.
    """
    from ..standards.transfer import h1_estimate

    k = AXES.index(axis)
    x = run.seat_acc_mps2[:, k]
    curves = {}
    for p in POINTS:
        pm = run.point(p)
        for j, dof in enumerate(DOFS):
            y = pm.acc_mps2[:, j] if j < 3 else pm.angacc_radps2[:, j - 3]
            e = h1_estimate(x, y, 1.0 / run.dt_s, segment_s=segment_s, lowpass_hz=12.0)
            sel = band_select(e.freq_hz, band_hz)
            curves[(axis, p, dof)] = Curve(e.freq_hz[sel], e.gain[sel], e.phase_deg[sel], e.coherence[sel])
    # apparent mass: force of the supports on the body per unit seat acceleration [kg]
    for p, force in (("support", run.support_total_N()), ("seat_pan", run.support_N["seat_pan"])):
        e = h1_estimate(x, force[:, k], 1.0 / run.dt_s, segment_s=segment_s, lowpass_hz=12.0)
        sel = band_select(e.freq_hz, band_hz)
        curves[(axis, p, axis)] = Curve(e.freq_hz[sel], e.gain[sel], e.phase_deg[sel], e.coherence[sel])
    return curves


def _seated(human):
    """A SeatedHuman for ``human`` (an :class:`ehm.Person` is built; a SeatedHuman is used as it is)."""
    from ..person import Person
    from ..simulation import SeatedHuman

    if isinstance(human, Person):
        return SeatedHuman(human)
    if not isinstance(human, SeatedHuman):
        raise InputError(f"the person is {type(human).__name__}; give an ehm.Person or an ehm.SeatedHuman.")
    return human


@checked
def time_domain_frf(human, axis: str = "all", duration_s: float = 60.0, rms_mps2: float = 0.3, seed: int = 0,
                    band_hz: tuple[float, float] = (0.1, 12.0), segment_s: float = 10.0,
                    route: str = "nonlinear", motion: SeatMotion | None = None) -> FrfTable:
    """Transfer functions from random-vibration runs, one run per input axis (paper Eq. 1, H1 estimate).

    Each run excites one seat axis with band-limited random acceleration (``band_hz``, ``rms_mps2``).
    ``route`` is the simulation route of the runs: ``nonlinear`` (MuJoCo, the default) or ``linear`` (the
    linearised person, :mod:`ehm.routes.linear`: milliseconds per run; refuses inputs that make a contact slide).

    ``human`` is an :class:`ehm.SeatedHuman` or an :class:`ehm.Person` (built here).

    With ``motion`` (a measured seat motion, e.g. from :func:`ehm.read_motion`) the person runs that
    motion once instead, and each requested seat axis that it moves gives its curves (single-input H1:
    when the motion moves several axes at once, correlated inputs bias each other's estimates).
    """
    from ..inputs.motion import random_vibration

    band = np.ravel(frequencies_hz(band_hz, "band_hz", positive=True))
    if band.size != 2 or not band[0] < band[1]:
        raise InputError(f"band_hz must be two frequencies (low, high) in Hz with low < high; got {band_hz!r}.")
    human = _seated(human)
    if motion is not None:
        if motion.duration_s < segment_s:
            raise InputError(f"the motion '{motion.description}' lasts {motion.duration_s:g} s: it must last at "
                             f"least one {segment_s:g} s estimation segment.")
        run = human.simulate(motion, method=route)
        moved = [a for a in _axes(axis) if np.any(run.seat_acc_mps2[:, AXES.index(a)] != 0)]
        if not moved:
            raise InputError(f"the motion '{motion.description}' does not move the seat along "
                             f"{' or '.join(_axes(axis))}.")
        curves = {}
        for a in moved:
            curves.update(run_curves(run, a, band_hz, segment_s))
        meta = {"input": motion.description, "segment_s": segment_s, "route": route,
                **_person_record(human), "vibration_level": run.extra.get("vibration_level")}
        return FrfTable(curves=curves, method="time", meta=meta)

    if not duration_s >= segment_s:
        raise InputError(f"duration_s = {duration_s:g} s: a run must last at least one {segment_s:g} s estimation "
                         "segment.")
    dt = float(human.params.value("simulation.dt_s"))
    curves, levels = {}, []
    for axis_name in _axes(axis):
        run = human.simulate(random_vibration(axis_name, duration_s, rms_mps2, seed=seed, dt_s=dt, band_hz=band_hz),
                             method=route)
        curves.update(run_curves(run, axis_name, band_hz, segment_s))
        levels.append(run.extra.get("vibration_level"))
    meta = {"duration_s": duration_s, "rms_mps2": rms_mps2, "seed": seed, "segment_s": segment_s, "route": route,
            **_person_record(human), "vibration_level": levels[0] if len(levels) == 1 else levels}
    return FrfTable(curves=curves, method="time", meta=meta)


@checked
def linear_frf(human, axis: str = "all", freq_hz: np.ndarray | None = None, linear_model: LinearModel | None = None,
               discrete: bool = False) -> FrfTable:
    """Exact frequency response of the model linearised around its settled posture.

    ``freq_hz`` defaults to 0.1 to 12 Hz in 0.05 Hz steps.  Contacts are linearised as stuck.  By default
    the continuous-time model of the linear route (:meth:`ehm.SeatedHuman.linear_model`, no step error);
    ``discrete=True`` (or an ``ehm.engine.LinearModel`` as ``linear_model``) gives the response of one
    MuJoCo step at the person's own time step, with that step's error (what ``ehm check-step`` compares).
    ``human`` is an :class:`ehm.SeatedHuman` or an :class:`ehm.Person` (built here).
    """
    from .. import engine
    from ..routes.linear import frequency_response
    from ..standards.transfer import discrete_frequency_response

    if freq_hz is None:
        f = np.arange(0.1, 12.0 + 1e-9, 0.05)
    else:  # one number or a 1-D list of them, each above 0 Hz
        f = frequency_grid("linear_frf", [freq_hz] if isinstance(freq_hz, int | float) else freq_hz, positive=True)
    human = _seated(human)
    axes = _axes(axis)
    cols = [AXES.index(a) for a in axes]
    if discrete or linear_model is not None:
        lm = linear_model if linear_model is not None else engine.closed_linear_model(
            human.model, engine.linearize(human.model))
        names = list(lm.output_names)
        H = discrete_frequency_response(lm.A, lm.B[:, cols], lm.C, lm.D[:, cols], lm.dt_s, f)
    else:
        ss = human.linear_model()
        names = list(ss.output_names)
        H = frequency_response(ss, f)[:, :, cols]
    nan = np.full(f.size, np.nan)
    curves = {}
    groups = {"support": [g for g in _support_groups()], "seat_pan": ["seat_pan"]}
    for i, a in enumerate(axes):
        for p in POINTS:
            for dof in DOFS:
                h = H[:, names.index(f"{p}.{_LINEAR_OUTPUT[dof]}"), i]
                curves[(a, p, dof)] = Curve(f, np.abs(h), np.degrees(np.angle(h)), nan)
        for p, members in groups.items():  # apparent mass [kg]: support forces per unit seat acceleration
            h = sum(H[:, names.index(f"support.{g}.f{a}"), i] for g in members)
            curves[(a, p, a)] = Curve(f, np.abs(h), np.degrees(np.angle(h)), nan)
    return FrfTable(curves=curves, method="linear", meta={**_person_record(human),
                                                         "model": "discrete" if discrete or linear_model is not None
                                                         else "continuous"})


def _person_record(human) -> dict:
    """What an FRF table records of the person: :meth:`ehm.Person.to_dict` (``person``), and as it sits (``seated``:
    the posture, back support and head control in effect, the parameter file's where the person keeps them) with
    :meth:`ehm.Person.describe` (``person_description``)."""
    person = human.person
    p = person.seated_params()
    seated = {"posture": p.posture, "back_support": p.back_support,
              "head_control": bool(p.value("head_control.enabled"))}
    return {"person": person.to_dict(), "seated": seated, "person_description": person.describe()}


def _support_groups() -> tuple:
    from ..engine import SUPPORT_GROUPS

    return tuple(SUPPORT_GROUPS)
