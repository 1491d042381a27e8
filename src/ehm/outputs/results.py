"""Run results: what every route (nonlinear, linear, step by step) produces and every consumer (files, figures,
assessment, transfer functions) reads, by name.

>>> import ehm
>>> human, motion = ehm.SeatedHuman(), ehm.random_vibration("z", duration_s=2, rms_mps2=0.3, seed=0)
>>> run = human.simulate(motion)                 # a RunResult
>>> run.point("head").acc_mps2.shape             # absolute head acceleration [m/s^2]: x, y, z of each sample
(2001, 3)

This module stands below everything that produces or consumes runs (:mod:`ehm.simulation`, :mod:`ehm.routes.linear`,
:mod:`ehm.outputs.plotting`, :mod:`ehm.analysis.frf`, ...); it imports only the engine's point names and, for
:meth:`RunResult.summary` and :meth:`RunResult.write`, the file writers below it (:mod:`ehm.outputs.runfiles`,
:mod:`ehm.outputs.outdir`).  ``ehm.RunResult`` and ``ehm.simulation.RunResult`` are the same class.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from numbers import Integral
from pathlib import Path

import numpy as np

from .. import engine
from ..errors import InputError, checked_class, describe

__all__ = ["POINT_NAMES", "PointMotion", "RunResult", "concatenate_runs"]

#: ``pelvis``, ``trunk`` (upper torso centre of gravity, T8 level), ``head`` (centres of gravity), ``lumbar`` (the
#: L4-L5 joint centre, on the lower torso).
POINT_NAMES = tuple(engine.POINTS)


@checked_class
@dataclass(frozen=True)
class PointMotion:
    """Motion of one output point (a segment's centre of gravity; ``lumbar``: the L4-L5 joint centre, a point of
    the lower torso).

    Attributes
    ----------
    name : str
        ``pelvis``, ``trunk``, ``head`` or ``lumbar``.
    acc_mps2 : (n, 3) array
        Absolute translational acceleration in seat axes (x, y, z) [m/s^2].
    disp_m : (n, 3) array
        Displacement relative to the settled posture, seat axes [m].
    rot_rad : (n, 3) array
        Rotation relative to the settled posture as roll, pitch, yaw (intrinsic z-y-x angles of
        R(t) R(0)^T, seat axes) [rad].
    angacc_radps2 : (n, 3) array
        Angular acceleration about the seat's x, y, z axes (roll, pitch, yaw) [rad/s^2].
    angvel_radps : (n, 3) array
        Angular velocity in the segment's own axes (what its vestibular organs sense, for the head) [rad/s].
    gia_mps2 : (n, 3) array
        Gravito-inertial acceleration (specific force a - g) in the segment's own axes [m/s^2]; +9.81 in z
        for an upright segment at rest.
    """

    name: str
    acc_mps2: np.ndarray
    disp_m: np.ndarray
    rot_rad: np.ndarray
    angacc_radps2: np.ndarray
    angvel_radps: np.ndarray
    gia_mps2: np.ndarray


_POINT_FIELDS = ("acc_mps2", "disp_m", "rot_rad", "angacc_radps2", "angvel_radps", "gia_mps2")


@checked_class
@dataclass(frozen=True)
class RunResult:
    """Result of one simulation, sampled every time step from t = 0.

    Attributes
    ----------
    time_s : (n,) array
    seat_acc_mps2 : (n, 3) array
        Seat acceleration input [m/s^2].
    points : dict of str -> PointMotion
    support_N : dict of str -> (n, 3) array
        Force that the seat pan, backrest (both pads) and floor exert on the body, seat axes [N].
    seat_acc_mps2 is the seat's translational acceleration in its own axes.
    mass_kg, dof, dt_s, wall_s : float / int
    description : str
        What the input was.
    locked : tuple of str
        Joints that were locked.
    """

    time_s: np.ndarray
    seat_acc_mps2: np.ndarray
    points: dict
    support_N: dict
    mass_kg: float
    dof: int
    dt_s: float
    wall_s: float
    description: str
    locked: tuple
    params_origin: str = "default"
    seat_angles_rad: np.ndarray | None = None  #: Seat yaw, pitch, roll (n, 3) when the seat rotates.
    poses: dict | None = None  #: Segment body poses for pictures: time_s (m,), pos (m, k, 3), quat (m, k, 4), geometry
    extra: dict = field(default_factory=dict)

    def point(self, name: str) -> PointMotion:
        """The motion of ``pelvis``, ``trunk``, ``head`` or ``lumbar``."""
        if name not in self.points:
            raise InputError(f"unknown point {name!r}; points are {', '.join(self.points)}.")
        return self.points[name]

    @property
    def duration_s(self) -> float:
        """Simulated time span of the samples, t[-1] - t[0] [s] (as :attr:`SeatMotion.duration_s`)."""
        return float((len(self.time_s) - 1) * self.dt_s)

    @property
    def realtime_factor(self) -> float:
        """Simulated time per wall-clock time of the run (settling excluded)."""
        return self.duration_s / self.wall_s if self.wall_s > 0 else float("inf")

    def support_total_N(self) -> np.ndarray:
        """Total force of all supports on the body, (n, 3) [N]."""
        return sum(self.support_N.values())

    def summary(self) -> dict:
        """Scalars describing the run (what ``summary.json`` holds)."""
        from .runfiles import SummaryAccumulator

        acc = SummaryAccumulator()
        acc.add(self)
        return acc.summary()

    def take(self, rows) -> RunResult:
        """The run at some rows only (a slice, an index array, a boolean mask or one index; poses left out), e.g. for
        a figure.  Rows that are not a selection of this run's samples (a step of 0, a string, an index out of
        range, no row at all) are refused in one sentence."""
        rows = self._rows(rows)
        pts = {p: PointMotion(p, *(getattr(m, f)[rows] for f in _POINT_FIELDS)) for p, m in self.points.items()}
        return replace(self, time_s=self.time_s[rows], seat_acc_mps2=self.seat_acc_mps2[rows], points=pts,
                       support_N={k: v[rows] for k, v in self.support_N.items()}, poses=None,
                       seat_angles_rad=None if self.seat_angles_rad is None else self.seat_angles_rad[rows])

    def _rows(self, rows):
        """``rows`` checked against this run's samples (one index becomes a list of one)."""
        n = len(self.time_s)
        hint = "e.g. run.take(slice(0, None, 10)) for every 10th sample"
        if isinstance(rows, slice):
            for part in ("start", "stop", "step"):
                v = getattr(rows, part)
                if v is not None and (isinstance(v, (bool, np.bool_)) or not isinstance(v, Integral)):
                    raise InputError(f"RunResult.take: the slice's {part} must be a whole number or None, got "
                                     f"{describe(v)} ({hint}).")
            if rows.step is not None and rows.step <= 0:
                raise InputError(f"RunResult.take: the slice's step must be 1 or more, got {rows.step} ({hint}).")
            chosen = range(n)[rows]
            if not len(chosen):
                raise InputError(f"RunResult.take: {rows} selects none of the run's {n} samples ({hint}).")
            return rows
        if isinstance(rows, Integral) and not isinstance(rows, (bool, np.bool_)):
            rows = [rows]
        try:
            index = np.asarray(rows)
        except (TypeError, ValueError):
            index = np.asarray(None)
        if index.ndim != 1 or index.dtype.kind not in "biu":
            raise InputError(f"RunResult.take: rows must be a slice, whole-number indices or a boolean mask of the "
                             f"run's samples, got {describe(rows)} ({hint}).")
        if index.dtype.kind == "b":
            if index.size != n:
                raise InputError(f"RunResult.take: a boolean mask must have one entry per sample ({n}), got "
                                 f"{index.size}.")
            if not index.any():
                raise InputError("RunResult.take: the boolean mask selects no sample.")
            return index
        if index.size == 0:
            raise InputError(f"RunResult.take: rows selects no sample ({hint}).")
        bad = index[(index < -n) | (index >= n)]
        if bad.size:
            raise InputError(f"RunResult.take: row {int(bad[0])} is outside the run's {n} samples (0 to {n - 1}).")
        return index

    def columns(self) -> tuple[list[str], np.ndarray]:
        """Header and (n, k) data of ``timeseries.csv``."""
        header = ["time_s", "seat_ax_mps2", "seat_ay_mps2", "seat_az_mps2"]
        cols = [self.time_s[:, None], self.seat_acc_mps2]
        for p, m in self.points.items():
            header += [f"{p}_a{a}_mps2" for a in "xyz"] + [f"{p}_{a}_m" for a in "xyz"]
            header += [f"{p}_{r}_rad" for r in ("roll", "pitch", "yaw")]
            header += [f"{p}_{r}_acc_radps2" for r in ("roll", "pitch", "yaw")]
            cols += [m.acc_mps2, m.disp_m, m.rot_rad, m.angacc_radps2]
        for s, f in self.support_N.items():
            header += [f"{s}_f{a}_N" for a in "xyz"]
            cols.append(f)
        return header, np.hstack(cols)

    @property
    def route(self) -> str:
        """The route that made the run: ``auto`` (the hybrid route) or ``linear`` as its report says
        (``extra["route"]``), ``linear`` for :mod:`ehm.routes.linear`'s own runs, else ``nonlinear``."""
        if "route" in self.extra:
            return str(self.extra["route"]["method"])
        return "linear" if self.description.endswith(", linear route") else "nonlinear"

    def _attrs(self) -> dict:
        return {"description": self.description, "route": self.route, "duration_s": self.duration_s,
                "dt_s": self.dt_s, "mass_kg": self.mass_kg, "dof": self.dof, "locked": self.locked,
                "params": self.params_origin}

    def to_dataframe(self, wide: bool = False):
        """The time series as a pandas DataFrame, the run's description, route, time step and person in
        ``DataFrame.attrs``.

        Long (default, tidy): one row per sample, location and axis, with the columns ``time_s``, ``location``
        (``seat``, the points ``pelvis``, ``trunk``, ``head``, ``lumbar``, then the support surfaces), ``axis`` (``x``,
        ``y``, ``z``; rotations about that axis: roll, pitch, yaw) and one column per quantity:
        ``acc_mps2`` (the seat's input, the points' absolute acceleration), ``disp_m``, ``rot_rad``,
        ``angacc_radps2`` (the points) and ``force_N`` (the supports' force on the body); a quantity a
        location does not have is NaN.  ``wide=True``: one row per sample, one column per signal, the columns
        of ``timeseries.csv`` (:meth:`columns`).  Both hold every sample: thin a long run first with
        :meth:`take` (e.g. ``run.take(slice(None, None, 5))``)."""
        from .dataframes import frame

        if wide:
            header, data = self.columns()
            return frame(dict(zip(header, data.T)), self._attrs())
        quantities = ("acc_mps2", "disp_m", "rot_rad", "angacc_radps2", "force_N")
        blocks = [("seat", {"acc_mps2": self.seat_acc_mps2})]
        blocks += [(p, {q: getattr(m, q) for q in quantities[:4]}) for p, m in self.points.items()]
        blocks += [(s, {"force_N": f}) for s, f in self.support_N.items()]
        n, k = len(self.time_s), 3 * len(blocks)
        columns = {"time_s": np.tile(self.time_s, k),
                   "location": np.repeat([loc for loc, _ in blocks], 3 * n),
                   "axis": np.tile(np.repeat(list("xyz"), n), len(blocks))}
        for q in quantities:
            values = np.full((len(blocks), 3, n), np.nan)
            for i, (_, held) in enumerate(blocks):
                if q in held:
                    values[i] = held[q].T
            columns[q] = values.reshape(-1)
        locations = ("seat", *POINT_NAMES, *self.support_N)
        return frame(columns, self._attrs(), labels={"location": locations, "axis": ("x", "y", "z")})

    def to_xarray(self):
        """The run as an xarray Dataset of labelled arrays: the points' ``acc_mps2``, ``disp_m``, ``rot_rad``,
        ``angacc_radps2``, ``angvel_radps`` and ``gia_mps2`` (point x axis x time_s, the frames of
        :class:`PointMotion`), ``seat_acc_mps2`` (axis x time_s) and ``force_N`` (support x axis x time_s);
        each variable's unit in its ``units`` attribute, the run's description and route in the Dataset's
        ``attrs``.  Needs xarray (``pip install 'ehm[xarray]'``)."""
        from .dataframes import dataset

        stack = lambda arrays: np.stack([a.T for a in arrays])  # noqa: E731  (n, 3) each -> (k, 3, n)
        units = {"acc_mps2": "m/s^2", "disp_m": "m", "rot_rad": "rad", "angacc_radps2": "rad/s^2",
                 "angvel_radps": "rad/s", "gia_mps2": "m/s^2"}
        variables = {q: (("point", "axis", "time_s"), stack([getattr(m, q) for m in self.points.values()]), u)
                     for q, u in units.items()}
        variables["seat_acc_mps2"] = (("axis", "time_s"), self.seat_acc_mps2.T, "m/s^2")
        variables["force_N"] = (("support", "axis", "time_s"), stack(list(self.support_N.values())), "N")
        coords = {"time_s": self.time_s, "point": list(self.points), "axis": ["x", "y", "z"],
                  "support": list(self.support_N)}
        return dataset(variables, coords, self._attrs(), "RunResult.to_xarray()")

    def __repr__(self) -> str:
        """One line: the input, route, span and step, the rms of the seat and the head along the most moved seat
        axis, and the person (the arrays are in the attributes; ``to_dataframe()`` gives them as a table)."""
        n = len(self.time_s)
        rms = np.sqrt(np.mean(np.square(self.seat_acc_mps2), axis=0)) if n else np.zeros(3)
        k = int(np.argmax(rms))
        head = self.points.get("head")
        head_rms = (f", head {float(np.sqrt(np.mean(np.square(head.acc_mps2[:, k])))):.3g}"
                    if head is not None and n else "")
        return (f"<RunResult {self.description!r} ({self.route} route): {self.duration_s:g} s at a "
                f"{1e3 * self.dt_s:g} ms step, {n} samples; rms a_{'xyz'[k]} seat {float(rms[k]):.3g}{head_rms} m/s^2; "
                f"{self.mass_kg:.1f} kg, {self.dof} dof, parameters {self.params_origin}>")

    def _repr_html_(self) -> str:
        from .dataframes import html_table

        rms = lambda a: np.sqrt(np.mean(np.square(a), axis=0))  # noqa: E731
        rows = [["seat", *rms(self.seat_acc_mps2)]] + [[p, *rms(m.acc_mps2)] for p, m in self.points.items()]
        facts = {"input": self.description, "route": self.route,
                 "duration": f"{self.duration_s:g} s at a {1e3 * self.dt_s:g} ms step, run in {self.wall_s:.3g} s",
                 "person": f"{self.mass_kg:.1f} kg, {self.dof} dof, locked: {', '.join(self.locked) or 'none'}, "
                           f"parameters: {self.params_origin}"}
        return html_table("ehm RunResult", facts, ["location", "rms a_x [m/s²]", "rms a_y [m/s²]", "rms a_z [m/s²]"],
                          rows)

    def write(self, out_dir: Path | str, output_rate_hz: float | None = None,
              formats: str | tuple | list = ("csv",)) -> dict:
        """Write the run folder ``out_dir`` (``timeseries.csv`` and/or ``.parquet``, ``summary.json``, ``poses.npz``
        when the run has poses) as one unit (:mod:`ehm.outputs.outdir`: an earlier run's folder there is replaced
        whole);
        ``output_rate_hz`` thins the time series (default: every step).  Returns the file paths."""
        from .outdir import RunFolder
        from .runfiles import check_formats, output_every, write_run

        formats = check_formats(formats)
        every = output_every(output_rate_hz, self.dt_s)
        out = Path(out_dir)
        with RunFolder(out) as tmp:
            write_run(tmp, [self], output_every=every, formats=formats)
        return _paths(out, formats, self.poses is not None)


def _paths(out: Path, formats, poses: bool) -> dict:
    paths = {"summary": out / "summary.json"}
    if "csv" in formats:
        paths["timeseries"] = out / "timeseries.csv"
    if "parquet" in formats:
        paths["parquet"] = out / "timeseries.parquet"
    if poses:
        paths["poses"] = out / "poses.npz"
    return paths


def concatenate_runs(chunks: list) -> RunResult:
    """One :class:`RunResult` from consecutive chunks (as :meth:`ehm.SeatedHuman.stream` yields them); ``extra``
    is the first chunk's, updated by the last one's (which carries a route's report), with the linear route's
    estimates of what it leaves out (``linear_check``) merged over the chunks that have one."""
    first = chunks[0]
    cat = lambda get: np.concatenate([get(c) for c in chunks])  # noqa: E731
    points = {p: PointMotion(p, *(cat(lambda c, f=f, p=p: getattr(c.points[p], f)) for f in _POINT_FIELDS))
              for p in first.points}
    extra = {**first.extra, **chunks[-1].extra}  # the last chunk carries a route's report (ehm.routes.hybrid)
    checks = [c.extra["linear_check"] for c in chunks if "linear_check" in c.extra]  # the linear route's pieces
    if checks:
        extra["linear_check"] = merge_linear_checks(checks) if len(checks) > 1 else checks[0]
    return replace(first, time_s=cat(lambda c: c.time_s), seat_acc_mps2=cat(lambda c: c.seat_acc_mps2), points=points,
                   extra=extra,
                   support_N={k: cat(lambda c, k=k: c.support_N[k]) for k in first.support_N},
                   wall_s=sum(c.wall_s for c in chunks),
                   seat_angles_rad=None if first.seat_angles_rad is None else cat(lambda c: c.seat_angles_rad),
                   poses=None if first.poses is None else {
                       **{k: v for k, v in first.poses.items() if k not in ("time_s", "pos", "quat")},
                       **{k: cat(lambda c, k=k: c.poses[k]) for k in ("time_s", "pos", "quat")}})


def merge_linear_checks(checks: list) -> dict:
    """One estimate of what the linear route leaves out (``extra["linear_check"]``, see
    :func:`ehm.routes.linear.left_out`) from those of consecutive chunks: the largest terms over all chunks, the rms
    over all samples, and the shares (rms over rms) recomputed from them."""
    out, worst = {}, 0.0
    for p in (k for k in checks[0] if k != "share"):
        parts = [ck[p] for ck in checks]
        n = sum(c["n"] for c in parts)
        rms = lambda key, parts=parts, n=n: float(np.sqrt(sum(c["n"] * c[key] ** 2 for c in parts) / n))  # noqa: E731
        acc_rms, angacc_rms = rms("acc_rms_mps2"), rms("angacc_rms_radps2")
        left, gyro = rms("left_out_rms_mps2"), rms("gyro_rms_radps2")
        share = left / acc_rms if acc_rms > 0 else 0.0
        angular = gyro / angacc_rms if angacc_rms > 0 else 0.0
        out[p] = {"coriolis_mps2": max(c["coriolis_mps2"] for c in parts),
                  "offset_mps2": max(c["offset_mps2"] for c in parts), "left_out_rms_mps2": left,
                  "acc_rms_mps2": acc_rms, "share": share, "gyro_radps2": max(c["gyro_radps2"] for c in parts),
                  "gyro_rms_radps2": gyro, "angacc_rms_radps2": angacc_rms, "angular_share": angular, "n": n}
        worst = max(worst, share, angular)
    out["share"] = worst
    return out
