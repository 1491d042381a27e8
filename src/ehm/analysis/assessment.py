"""Comfort and sickness assessment of a whole drive, at the seat and through the body.

:func:`~ehm.assess` runs the seated person through a drive chunk by chunk and evaluates, at the seat (the input)
and at the pelvis, trunk, head and lumbar spine:

* ISO 2631-1 comfort: frequency-weighted rms a_w, MTVV, VDV, crest factor per axis (Wd for x and y, Wk
  for z, seated, seat-surface axes), the vibration total value (k = 1, comfort) with the standard's
  comfort reaction, MSDV (Wf, vertical), the SEAT value (body over seat), weighted spectra and running rms;
* motion sickness: the subjective vertical conflict model driven by the head's angular velocity and
  gravito-inertial acceleration (and, for comparison, by the seat's, as if the head were rigidly fixed to
  the seat): the motion sickness incidence (MSI) and, from the same conflict, a predicted MISC rating (0-10) by
  an accumulation model (:class:`ehm.MiscParameters`: a group's, or a person's from
  :func:`ehm.fit_sickness`);
* ISO 2631-5 spinal dose (:mod:`ehm.standards.comfort.spine`): the lumbar response's peaks, the daily dose, S_d and R by
  the standard's transfer function from the seat's vertical acceleration, at the drive's own rate.

Output points are the segments' centres of gravity, and the L4-L5 joint centre for ``lumbar``; their
accelerations are in seat axes.

Memory: every figure is accumulated chunk by chunk (comfort: :class:`ehm.standards.comfort.ComfortAccumulator`;
sickness: :class:`ehm.standards.sickness.SicknessAccumulator`, the model run along on 20 Hz block means), so the working
memory is set by the chunk, not by the drive.  What grows with the drive is only what the figures draw: the
running rms of 15 signals at 10 Hz and the MSI, ``|conflict|`` and MISC of the two sickness runs at 20 Hz, about
8 MB of numbers per hour of drive (4.4 + 3.5 MB; the MISC trace added 1.2 MB), more with the overhead of the
per-chunk pieces they are gathered in (measured before the MISC trace, with 12 signals: 6 and 9 MB; a 200 Hz log's
own time and three channels take 23 MB per hour).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy import signal

from ..errors import EhmWarning, InputError, checked, checked_class, warn
from ..inputs.motion import SeatMotion, require_motion, seat_rotation_matrices
from ..inputs.resampling import PASS_FRACTION
from ..person import Person
from ..standards.comfort import (
    BAND_WARNING_SHARE,
    WEIGHTING_BANDS_HZ,
    ComfortAccumulator,
    band_share_outside,
    comfort_reaction,
)
from ..standards.comfort.spine import SpinalDoseAccumulator, SpineExposure, iso2631_5_summary, spinal_dose
from ..standards.sickness import MiscParameters, SicknessAccumulator

LOCATIONS = ("seat", "pelvis", "trunk", "head", "lumbar")
AXIS_WEIGHTING = {"x": "Wd", "y": "Wd", "z": "Wk"}  #: ISO 2631-1 seated, comfort/health axes
SICKNESS_RATE_HZ = 20.0  #: Sample rate of the sickness model's input (block means of the run)
TRACE_RATE_HZ = 10.0  #: Sample rate of the stored running rms and traces
def input_band(motion: SeatMotion, model_fs_hz: float) -> tuple[float, float]:
    """The band [Hz] a drive's seat input actually covers when run at ``model_fs_hz``
    (:meth:`ehm.SeatMotion.covered_band_hz`)."""
    return motion.covered_band_hz(model_fs_hz)


def band_coverage(band_hz: tuple[float, float]) -> dict:
    """Weighting -> share of its power (|W(f)|^2 over its band on a log-frequency axis) outside ``band_hz``."""
    return {w: band_share_outside(w, *band_hz) for w in ("Wd", "Wk", "Wf")}



def band_warnings(band_hz: tuple[float, float], shares: dict) -> list[str]:
    """One sentence per weighting with at least :data:`BAND_WARNING_SHARE` of its power outside the input's band."""
    lo, hi = band_hz
    out = []
    for w, share in shares.items():
        if share >= BAND_WARNING_SHARE:
            b_lo, b_hi = WEIGHTING_BANDS_HZ[w]
            fixes = ([f"a logger at {b_hi / PASS_FRACTION:g} Hz or faster"] if hi < b_hi else []) + (
                [f"a log of {1 / b_lo:g} s or longer"] if lo > b_lo else [])
            out.append(f"the input covers {lo:.3g}-{hi:.3g} Hz, not all of the {w} band ({b_lo:g}-{b_hi:g} Hz): "
                       f"{100 * share:.1f} % of {w}'s power (|W(f)|^2 on a log-frequency axis) lies outside, so "
                       f"the {w}-weighted values miss what the vehicle did there (for a weighted spectrum flat on "
                       f"that axis, a_w {100 * (1 - (1 - share) ** 0.5):.1f} % low); {' or '.join(fixes)} records "
                       "it.")
    return out


@dataclass
class _Spectrum:
    """Welch PSD of a weighted signal fed in pieces: pieces are gathered until they hold 4 Welch segments (or
    the record ends), so that the segments do not depend on the chunk length; blocks are averaged by length."""

    BLOCK_SEGMENTS = 4

    fs: float
    nperseg: int
    total: np.ndarray | None = None
    count: int = 0
    freq: np.ndarray | None = None
    pending: list = field(default_factory=list)
    n_pending: int = 0

    def add(self, x: np.ndarray) -> None:
        self.pending.append(np.array(x, copy=True))
        self.n_pending += x.size
        if self.n_pending >= self.BLOCK_SEGMENTS * self.nperseg:
            self._flush()

    def _flush(self) -> None:
        x = np.concatenate(self.pending) if self.pending else np.zeros(0)
        self.pending, self.n_pending = [], 0
        if x.size < self.nperseg:
            return
        f, p = signal.welch(x, fs=self.fs, nperseg=self.nperseg)
        self.freq = f
        self.total = p * x.size if self.total is None else self.total + p * x.size
        self.count += x.size

    def result(self) -> tuple[np.ndarray, np.ndarray]:
        self._flush()
        if self.total is None:
            return np.zeros(0), np.zeros(0)
        return self.freq, self.total / self.count


@checked_class
@dataclass
class Assessment:
    """Results of :func:`assess` (plain data; ``summary()`` is what ``assessment.json`` holds)."""

    description: str
    duration_s: float
    wall_s: float
    metrics: dict                    # location -> axis -> ComfortMetrics
    spectra: dict                    # location -> axis -> (freq_hz, psd (m/s^2)^2/Hz) of the weighted signal
    sickness: dict                   # "head" / "seat" -> SicknessTrace (MSI, |conflict| and MISC at 20 Hz)
    trace_time_s: np.ndarray         # for the running rms traces
    max_displacement_m: dict = field(default_factory=dict)  # point -> (3,) largest |displacement|
    final_displacement_m: dict = field(default_factory=dict)
    input_band_hz: tuple | None = None  # (low, high) the seat input covers, see input_band
    band_outside_share: dict = field(default_factory=dict)  # weighting -> share of its power outside that band
    route: dict | None = None  # how the drive was run and checked (ehm.routes.hybrid.RouteReport.as_dict)
    iso2631_5: dict | None = None  # ISO 2631-5 spinal dose (ehm.standards.comfort.spine.iso2631_5_summary)
    handling: tuple = ()  # the handled stretches read_motion left out of the drive (ehm.SeatMotion.handling)
    #: the vibration level the person ran at (ehm.routes.built.BuiltPerson.level_record: rms_mps2, origin, line)
    vibration_level: dict | None = None
    misc_params: dict | None = None  # the MISC accumulation model's parameters and whose they are (misc_summary)

    def total_value(self, location: str) -> float:
        """Vibration total value a_v = sqrt(a_wx^2 + a_wy^2 + a_wz^2), k = 1 (comfort) [m/s^2]."""
        if location not in self.metrics:
            raise InputError(f"Assessment.total_value: no location {location!r}; the assessment has "
                             f"{', '.join(self.metrics)}.")
        return float(np.sqrt(sum(self.metrics[location][a].a_w ** 2 for a in "xyz")))

    def summary(self) -> dict:
        out = {"input": self.description, "duration_s": self.duration_s, "wall_s": self.wall_s,
               "realtime_factor": self.duration_s / self.wall_s if self.wall_s > 0 else None,
               "weightings": {**AXIS_WEIGHTING, "msdv": "Wf (z)"},
               "input_band_hz": list(self.input_band_hz) if self.input_band_hz else None,
               "band_outside_share": dict(self.band_outside_share),
               **({"route": self.route} if self.route else {}),
               **({"vibration_level": self.vibration_level} if self.vibration_level else {}),
               **({"handling_cut": handling_summary(self.handling)} if self.handling else {}),
               "locations": {}}
        seat_av = self.total_value("seat")
        for loc in LOCATIONS:
            per_axis = {}
            for a in "xyz":
                m = self.metrics[loc][a]
                per_axis[a] = {"a_w_mps2": m.a_w, "mtvv_mps2": m.mtvv, "vdv_mps175": m.vdv,
                               "crest_factor": _finite(m.crest_factor), "mtvv_ratio": _finite(m.mtvv_ratio),
                               "vdv_ratio": _finite(m.vdv_ratio)}
                if loc != "seat":
                    seat_aw = self.metrics["seat"][a].a_w
                    per_axis[a]["seat_value_pct"] = 100 * m.a_w / seat_aw if seat_aw > 0 else None
            a_v = self.total_value(loc)
            out["locations"][loc] = {
                "axes": per_axis, "total_value_mps2": a_v, "comfort_reaction": comfort_reaction(a_v),
                "msdv_z_mps15": self.metrics[loc]["z"].msdv,
                **({"seat_value_total_pct": 100 * a_v / seat_av if seat_av > 0 else None} if loc != "seat" else {}),
            }
        out["sickness"] = {k: {"final_msi_percent": r.final_msi_percent,
                               "max_conflict_mps2": float(np.max(r.conflict_magnitude_mps2)),
                               **({} if r.misc is None else {"final_misc": r.final_misc,
                                                             "max_misc": float(np.max(r.misc))})}
                           for k, r in self.sickness.items()}
        if self.misc_params:
            out["sickness_misc_params"] = self.misc_params
        out["body_displacement_max_m"] = {k: v.tolist() for k, v in self.max_displacement_m.items()}
        out["body_displacement_final_m"] = {k: v.tolist() for k, v in self.final_displacement_m.items()}
        if self.iso2631_5:
            out["iso2631_5"] = self.iso2631_5
        return out


    def _attrs(self) -> dict:
        return {"description": self.description, "route": (self.route or {}).get("method", "nonlinear"),
                "duration_s": self.duration_s, "weightings": "Wd (x, y), Wk (z), Wf (MSDV)"}

    def to_dataframe(self):
        """The figures of ``summary()`` (what ``assessment.json`` holds) as a long pandas DataFrame: one row per
        figure with the columns ``location`` (``seat``, ``pelvis``, ``trunk``, ``head``, ``lumbar``), ``axis``
        (``x``, ``y``, ``z``, or ``xyz`` for the total value and the sickness model), ``metric`` (``a_w``, ``mtvv``,
        ``vdv``, ``crest_factor``, ``mtvv_ratio``, ``vdv_ratio``, ``seat_value``; ``total_value``, ``msdv``,
        ``displacement_max``; the sickness model driven by the head and by the seat: ``msi_final``,
        ``conflict_max``, ``misc_final`` (the predicted MISC rating at the end, 0-10, unit ``MISC``); and ISO
        2631-5 at ``seat`` z by the standard's route and at ``lumbar`` z by the body model's lumbar point:
        ``iso2631_5_peak_max``, ``iso2631_5_dz``, ``iso2631_5_dzd``, ``iso2631_5_sd``, ``iso2631_5_r``,
        ``iso2631_5_p``), ``value`` and ``unit`` (``m/s^2``, ``m/s^1.75``, ``m/s^1.5``, ``m``, ``%``, ``MPa``,
        ``1``, ``MISC``);
        an undefined figure (the crest factor of an axis without motion) is NaN.  The drive's description, route
        and duration are in ``DataFrame.attrs``."""
        from ..outputs.dataframes import frame

        rows = _summary_rows(self.summary())
        columns = {c: [r[i] for r in rows] for i, c in enumerate(("location", "axis", "metric", "value", "unit"))}
        columns["value"] = np.array([np.nan if v is None else v for v in columns["value"]], dtype=float)
        return frame(columns, self._attrs(), labels={"location": LOCATIONS, "axis": ("x", "y", "z", "xyz")})

    def __repr__(self) -> str:
        """One line with the headline figures: the seat's and the head's total value and comfort reaction, the
        seat's VDV_z, the motion sickness incidence from the head, the route (``summary()`` has every figure)."""
        seat, head = self.total_value("seat"), self.total_value("head")
        msi = getattr(self.sickness.get("head"), "final_msi_percent", float("nan"))
        route = (self.route or {}).get("method", "nonlinear")
        return (f"<Assessment {self.description!r} ({route} route): {self.duration_s:g} s; a_v seat {seat:.3g} m/s^2 "
                f"({comfort_reaction(seat)}), head {head:.3g} m/s^2; VDV_z seat "
                f"{self.metrics['seat']['z'].vdv:.3g} m/s^1.75; motion sickness (head) {msi:.3g} %>")

    def _repr_html_(self) -> str:
        from ..outputs.dataframes import html_table

        s = self.summary()
        rows = []
        for loc, v in s["locations"].items():
            ax = v["axes"]
            rows.append([loc, *(ax[a]["a_w_mps2"] for a in "xyz"), v["total_value_mps2"], v["comfort_reaction"],
                         ax["z"]["vdv_mps175"], v["msdv_z_mps15"]])
        sick = s["sickness"]
        facts = {"input": self.description, "route": self._attrs()["route"],
                 "duration": f"{self.duration_s:g} s, assessed in {self.wall_s:.3g} s",
                 "motion sickness (MSI at the end)": ", ".join(f"{k} {v['final_msi_percent']:.4g} %"
                                                               for k, v in sick.items()),
                 "predicted MISC at the end (0-10)": ", ".join(f"{k} {v['final_misc']:.3g}" for k, v in sick.items()
                                                              if "final_misc" in v)}
        for route, label in (("standard_route", "the standard's route"), ("model_route", "the model's lumbar point")):
            v = (self.iso2631_5 or {}).get(route)
            if v:
                facts[f"ISO 2631-5 ({label})"] = (f"S_d {v['daily_compressive_stress_sd_mpa']:.3g} MPa, "
                                                  f"R {v['r_factor']:.3g}")
        return html_table("ehm Assessment (ISO 2631-1)", facts,
                          ["location", "a_w,x [m/s²]", "a_w,y [m/s²]", "a_w,z [m/s²]", "a_v [m/s²]",
                           "comfort reaction", "VDV_z [m/s^1.75]", "MSDV_z [m/s^1.5]"], rows)


#: summary key of a figure per axis -> (metric, unit)
_AXIS_FIGURES = {"a_w_mps2": ("a_w", "m/s^2"), "mtvv_mps2": ("mtvv", "m/s^2"), "vdv_mps175": ("vdv", "m/s^1.75"),
                 "crest_factor": ("crest_factor", "1"), "mtvv_ratio": ("mtvv_ratio", "1"),
                 "vdv_ratio": ("vdv_ratio", "1"), "seat_value_pct": ("seat_value", "%")}


def _summary_rows(summary: dict) -> list:
    """(location, axis, metric, value, unit) of every figure of an assessment's summary."""
    rows = []
    for loc, v in summary["locations"].items():
        for a, figures in v["axes"].items():
            rows += [(loc, a, _AXIS_FIGURES[k][0], x, _AXIS_FIGURES[k][1]) for k, x in figures.items()]
        rows.append((loc, "xyz", "total_value", v["total_value_mps2"], "m/s^2"))
        if "seat_value_total_pct" in v:
            rows.append((loc, "xyz", "seat_value", v["seat_value_total_pct"], "%"))
        rows.append((loc, "z", "msdv", v["msdv_z_mps15"], "m/s^1.5"))
    for point, d in summary["body_displacement_max_m"].items():
        rows += [(point, a, "displacement_max", x, "m") for a, x in zip("xyz", d)]
    for by, v in summary["sickness"].items():
        rows += [(by, "xyz", "msi_final", v["final_msi_percent"], "%"),
                 (by, "xyz", "conflict_max", v["max_conflict_mps2"], "m/s^2")]
        if "final_misc" in v:
            rows.append((by, "xyz", "misc_final", v["final_misc"], "MISC"))
    spine = summary.get("iso2631_5") or {}
    for loc, route in (("seat", "standard_route"), ("lumbar", "model_route")):  # the standard's, the model's
        if spine.get(route):
            v = spine[route]
            rows += [(loc, "z", f"iso2631_5_{metric}", v[key], unit) for metric, key, unit in _ISO2631_5_FIGURES]
    return rows


#: ISO 2631-5 figures of the dataframe: (metric, key in the summary's standard route, unit)
_ISO2631_5_FIGURES = (("peak_max", "lumbar_peak_max_mps2", "m/s^2"), ("dz", "dose_dz_mps2", "m/s^2"),
                      ("dzd", "daily_dose_dzd_mps2", "m/s^2"), ("sd", "daily_compressive_stress_sd_mpa", "MPa"),
                      ("r", "r_factor", "1"), ("p", "injury_probability", "1"))


def _finite(x: float) -> float | None:
    """A number for JSON: None where it is undefined (e.g. the crest factor of an axis without motion)."""
    return float(x) if x is not None and np.isfinite(x) else None


def _block_means(x: np.ndarray, k: int) -> np.ndarray:
    """Means of consecutive blocks of k rows (the last partial block dropped)."""
    n = (x.shape[0] // k) * k
    return x[:n].reshape(n // k, k, *x.shape[1:]).mean(axis=1)


@dataclass
class _Running:
    """What :func:`assess` accumulates over a drive's chunks: comfort metrics and weighted spectra per location
    and axis, the sickness model driven by the head and by the seat, and the body's displacement.  Nothing of
    the chunks is kept but the traces the figures draw (running rms at 10 Hz, MSI and |conflict| at 20 Hz)."""

    comfort: dict
    spectra: dict
    sickness: dict
    spine: SpinalDoseAccumulator  # ISO 2631-5: the body model's lumbar point, z
    k_sick: int
    max_disp: dict
    final_disp: dict = field(default_factory=dict)
    partial: dict = field(default_factory=dict)  # sickness input -> the samples of its unfinished block

    @classmethod
    def start(cls, fs: float, keep: int, nper: int, k_sick: int, dt: float,
              misc_params: MiscParameters | None = None) -> _Running:
        from ..outputs.results import POINT_NAMES

        return cls(comfort={loc: {a: ComfortAccumulator(AXIS_WEIGHTING[a], fs, keep_every=keep) for a in "xyz"}
                            for loc in LOCATIONS},
                   spectra={loc: {a: _Spectrum(fs, nper) for a in "xyz"} for loc in LOCATIONS},
                   # the sickness model runs along, piece by piece, on 20 Hz block means of the chunks
                   sickness={key: SicknessAccumulator(k_sick * dt, misc_params=misc_params)
                             for key in ("head", "seat")},
                   spine=SpinalDoseAccumulator(fs, lumbar=True), k_sick=k_sick,
                   max_disp={p: np.zeros(3) for p in POINT_NAMES})

    def add(self, chunk, seat_angvel: np.ndarray | None) -> None:
        """One chunk of the run; ``seat_angvel`` (n, 3) [rad/s] at its samples, None for a seat that does not turn."""
        self._comfort(chunk)
        self._sickness(chunk, seat_angvel)
        self._displacement(chunk)
        self.spine.add(chunk.point("lumbar").acc_mps2[:, 2])

    def _comfort(self, chunk) -> None:
        from ..outputs.results import POINT_NAMES

        signals = {"seat": chunk.seat_acc_mps2, **{p: chunk.point(p).acc_mps2 for p in POINT_NAMES}}
        for loc, a_xyz in signals.items():
            for j, a in enumerate("xyz"):
                self.spectra[loc][a].add(self.comfort[loc][a].add(a_xyz[:, j]))

    def _sickness(self, chunk, seat_angvel: np.ndarray | None) -> None:
        head = chunk.point("head")
        self._feed("head", head.gia_mps2, head.angvel_radps)
        # The seat's own GIA and rotation: specific force in seat axes, seat angular velocity.
        g_seat = np.array([0.0, 0.0, 9.81])
        if seat_angvel is not None:
            R = seat_rotation_matrices(chunk.seat_angles_rad)
            gia_seat = chunk.seat_acc_mps2 + np.einsum("nji,j->ni", R, g_seat)
            w_seat = seat_angvel
        else:
            gia_seat = chunk.seat_acc_mps2 + g_seat
            w_seat = np.zeros_like(gia_seat)
        self._feed("seat", gia_seat, w_seat)

    def _feed(self, key: str, gia: np.ndarray, w: np.ndarray) -> None:
        """Block means of k_sick samples into the sickness model, the samples of an unfinished block carried to the
        next chunk (the hybrid route's pieces have any length)."""
        if key in self.partial:
            gia, w = (np.concatenate([a, b]) for a, b in zip(self.partial[key], (gia, w)))
        n = (gia.shape[0] // self.k_sick) * self.k_sick
        self.partial[key] = (gia[n:].copy(), w[n:].copy())
        if n:
            self.sickness[key].add(_block_means(gia[:n], self.k_sick), _block_means(w[:n], self.k_sick))

    def _displacement(self, chunk) -> None:
        for p in self.max_disp:
            d = chunk.point(p).disp_m
            self.max_disp[p] = np.maximum(self.max_disp[p], np.abs(d).max(axis=0))
            self.final_disp[p] = d[-1].copy()


def _seat_angvel(motion: SeatMotion, t_rel: np.ndarray) -> np.ndarray:
    """The drive's angular velocity (n, 3) [rad/s] linearly interpolated at ``t_rel`` [s from the drive's start],
    from the window of its samples around those times (no array as long as the drive)."""
    t = motion.time_s
    lo = max(0, int(np.searchsorted(t, t[0] + t_rel[0])) - 2)
    hi = min(t.size, int(np.searchsorted(t, t[0] + t_rel[-1])) + 2)
    window = t[lo:hi] - t[0]
    return np.column_stack([np.interp(t_rel, window, motion.angvel_radps[lo:hi, j]) for j in range(3)])


def needs_rotating_seat(motion: SeatMotion, method: str) -> bool:
    """Whether a run of ``motion`` by ``method`` needs a person built with ``rotating_seat=True``: a motion that
    turns the seat (the linear and hybrid routes run its linear model on a static-seat copy, and the nonlinear
    windows on the rotating seat); for the nonlinear route any motion with angular velocities, zero or not
    (its seat then stays level).  A motion whose angular velocities are all zero runs the linear and hybrid
    routes on the translation alone."""
    if motion.angvel_radps is None:
        return False
    return method == "nonlinear" or bool(np.any(motion.angvel_radps != 0))


@checked
def assess(motion: SeatMotion, human=None, chunk_s: float = 10.0, progress: Callable | None = None,
           method: str = "auto", tolerance: float | None = None, workers: int | None = None, client=None,
           lead_in_s: float | None = None, exposure: SpineExposure | None = None,
           sickness_params: MiscParameters | None = None) -> Assessment:
    """Assess a drive at the seat and through the body (see the module docstring).

    Parameters
    ----------
    motion : SeatMotion
        The drive: seat acceleration in seat axes and, optionally, angular velocity.
    human : SeatedHuman or Person, optional
        The person (default: the default person): a :class:`ehm.Person` is built here, with a rotating seat when
        the drive rotates (as the default person is).
    chunk_s : float
        Length of the pieces the drive is simulated and evaluated in [s]: the working memory is about 5 MB per
        second of chunk at a 0.5 ms step (measured; in proportion to the steps per second, so about half at
        the default 1 ms), whatever the drive's length.  Longer pieces cost fewer calls: the metrics of 200 s
        took 0.84 s in 2 s pieces, 0.59 s in 10 s pieces (the default) and 0.44 s in 40 s pieces.
    progress : callable(done_s, total_s), optional
    method : str
        ``auto`` (default: the hybrid route, :mod:`ehm.routes.hybrid`: the linearised person, with the nonlinear model
        through the windows where a contact reaches its friction limit or lifts off, and for the rest of the drive
        once those windows cover more than half of it so far, or from the start when the drive's manoeuvres hold
        the contacts at their limit, :func:`ehm.routes.hybrid.sustained_share`), ``nonlinear`` (MuJoCo throughout) or
        ``linear`` (the linearised person throughout, checked against the nonlinear model in those windows, with a
        warning above ``tolerance``).  A drive that turns the seat runs the linear model of the seat's rotation and the
        rotating seat in the windows.
    tolerance : float, optional
        The linear route's tolerance: share of each point acceleration's rms (default 1 %).
    workers, client, lead_in_s
        The nonlinear route in segments on ``workers`` local processes or a Dask ``client``'s cluster, each
        segment after a lead-in of ``lead_in_s``: the options of the parallel route, passed through to
        :meth:`ehm.SeatedHuman.stream` (:mod:`ehm.routes.registry`, :func:`ehm.routes.parallel.stream_parallel`; the
        comfort and sickness figures within 1 % of the continuous run with the default lead-in).  ``workers=None``
        (the default): a drive of three minutes or more that runs on the nonlinear model from its start goes in
        segments on the machine's cores (:func:`ehm.routes.parallel.default_workers`); ``workers=1`` and no client:
        the continuous run.
    exposure : SpineExposure, optional
        The daily exposure and the person of the ISO 2631-5 dose (default ``SpineExposure()``: 8 h a day, the
        standard's Annex C example's man).
    sickness_params : MiscParameters, optional
        The MISC accumulation model's parameters: a person's (:func:`ehm.fit_sickness`, or
        :func:`ehm.read_sickness_params` of its file); default the group's.
    """
    from ..simulation import SeatedHuman

    rotating = needs_rotating_seat(require_motion("assess()", motion), method)
    if motion.duration_s < 2.0:
        raise InputError(f"the drive '{motion.description}' lasts {motion.duration_s:g} s; an assessment needs at "
                         "least 2 s (the running rms alone spans 1 s).")
    if human is None or isinstance(human, Person):
        human = SeatedHuman(human, rotating_seat=rotating)
    elif not isinstance(human, SeatedHuman):
        raise InputError(f"assess: human is {type(human).__name__}; give an ehm.Person, an ehm.SeatedHuman or None "
                         "(the default person).")
    dt = float(human.params.value("simulation.dt_s"))
    fs = 1.0 / dt
    keep = max(1, int(round(fs / TRACE_RATE_HZ)))
    k_sick = max(1, int(round(fs / SICKNESS_RATE_HZ)))
    # whole sickness blocks per chunk, so that the block means of consecutive chunks sit back to back in time
    chunk_s = max(1, round(chunk_s * fs / k_sick)) * k_sick * dt
    # Welch segments of about 4 s (0.25 Hz resolution), at most half the drive
    nper = int(2 ** np.floor(np.log2(min(4 * fs, motion.duration_s * fs / 2))))
    running = _Running.start(fs, keep, nper, k_sick, dt, sickness_params)
    band = motion.covered_band_hz(fs)
    shares = band_coverage(band)
    for sentence in band_warnings(band, shares):
        warn(f"{motion.description}: {sentence}", EhmWarning, stacklevel=2)
    # ISO 2631-5 by the standard's route, before the run: a drive it cannot take fails at once
    standard = spinal_dose(motion.acc_mps2[:, 2], motion.rate_hz, exposure, measured_s=motion.duration_s)
    description, duration = motion.description, motion.duration_s
    t0 = time.perf_counter()
    # the route by name (ehm.routes.registry); workers, client and lead_in_s are the parallel route's options
    chunks = human.stream(motion, chunk_s=chunk_s, progress=progress, method=method, tolerance=tolerance,
                          workers=workers, client=client, lead_in_s=lead_in_s)
    if method != "nonlinear":  # on the model's step, resampled a chunk at a time (the grid t = 0, dt, ...)
        description = f"{motion.description}, resampled to dt {dt:g} s"
        duration = int(np.floor(motion.duration_s / dt + 1e-9)) * dt
    result = _evaluate(running, chunks, motion if rotating else None, description, duration, band, shares, keep, dt,
                       t0)
    model = running.spine.result(exposure, measured_s=duration,
                                 route=f"the body model's lumbar point (L4-L5 joint centre), z, at {1 / dt:g} Hz")
    result.iso2631_5 = iso2631_5_summary(standard, model)
    result.handling = tuple(motion.handling)
    result.misc_params = misc_summary(sickness_params)
    return result


def misc_summary(params: MiscParameters | None, whose: str | None = None) -> dict:
    """``assessment.json``'s ``sickness_misc_params``: the MISC accumulation model's values and whose they are
    (``whose``; default ``group`` for the group's values, ``given`` for others)."""
    from dataclasses import asdict

    p = MiscParameters() if params is None else params
    return {"whose": whose or ("group" if p == MiscParameters() else "given"), **asdict(p)}


#: How a handled start or end that read_motion left out is kept instead.
KEEP_HANDLING = "--keep-handling (read_motion(..., handling='keep'))"


def handling_summary(stretches) -> dict:
    """``assessment.json``'s ``handling_cut``: the stretches left out, one sentence saying so, and the option that
    keeps them."""
    stretches = [dict(h) for h in stretches]
    words = " and ".join(f"the {h['where']} ({h['start_s']:.1f}-{h['end_s']:.1f} s)" for h in stretches)
    return {"stretches": stretches,
            "note": (f"{words} of the log left out: the logger was handled there, not carried by the vehicle (turned "
                     f"against gravity, accelerations far above the drive's); the figures are the drive's without "
                     f"them; {KEEP_HANDLING} keeps them."),
            "keep_with": KEEP_HANDLING}


def spinal_dose_of_seat(motion: SeatMotion, exposure: SpineExposure | None = None):
    """ISO 2631-5 by the standard's route: Formula 1 on the drive's own vertical seat acceleration at its own rate
    (:func:`ehm.standards.comfort.spine.spinal_dose`)."""
    return spinal_dose(motion.acc_mps2[:, 2], motion.rate_hz, exposure, measured_s=motion.duration_s)


def iso2631_5(motion: SeatMotion, exposure: SpineExposure | None = None, model_lumbar=None) -> dict:
    """The ISO 2631-5 section of an assessment (:func:`ehm.standards.comfort.spine.iso2631_5_summary`): the standard's
    route (:func:`spinal_dose_of_seat`) and, when given, the body model's (``model_lumbar``: a
    :class:`ehm.standards.comfort.spine.SpinalDose` of its lumbar point's vertical acceleration, as :func:`assess` makes
    it from the run)."""
    return iso2631_5_summary(spinal_dose_of_seat(motion, exposure), model_lumbar)


def _evaluate(running: _Running, chunks, rotating_motion, description: str, duration: float, band, shares,
              keep: int, dt: float, t0: float) -> Assessment:
    """The assessment of a run's chunks, accumulated in ``running``; ``rotating_motion``: the drive when its seat
    turns (its angular velocity drives the seat's sickness run).  The last chunk of the linear and hybrid routes
    carries their report (``extra["route"]``)."""
    route = level = None
    for chunk in chunks:
        running.add(chunk, None if rotating_motion is None else _seat_angvel(rotating_motion, chunk.time_s))
        route = chunk.extra.get("route", route)
        level = chunk.extra.get("vibration_level", level)
        del chunk  # the next chunk is made without this one held
    wall = time.perf_counter() - t0
    metrics = {loc: {a: running.comfort[loc][a].result() for a in "xyz"} for loc in LOCATIONS}
    n_trace = metrics["seat"]["z"].running_rms.size
    return Assessment(
        description=description, duration_s=duration, wall_s=wall, metrics=metrics,
        spectra={loc: {a: running.spectra[loc][a].result() for a in "xyz"} for loc in LOCATIONS},
        sickness={key: acc.result() for key, acc in running.sickness.items()},
        trace_time_s=np.arange(n_trace) * keep * dt, max_displacement_m=running.max_disp,
        final_displacement_m=running.final_disp, input_band_hz=band, band_outside_share=shares, route=route,
        vibration_level=level,
    )


# --- an assessment on disk and back ------------------------------------------------------------------------------

#: The arrays of an assessment beside its ``assessment.json``: the comfort values, running rms, weighted spectra and
#: sickness traces, what :func:`read_assessment` needs to give the whole Assessment back.
ARRAYS_FILE = "assessment.npz"
_METRIC_FIELDS = ("a_w", "mtvv", "vdv", "crest_factor", "msdv", "duration_s")


def write_assessment_arrays(result: Assessment, path) -> None:
    """Write an assessment's arrays (``assessment.npz``: comfort values, running rms, weighted spectra, sickness
    traces) whole or not at all; with ``assessment.json`` (its ``summary()``) they are the Assessment."""
    from ..files import replace_atomically

    arrays = {"trace_time_s": np.asarray(result.trace_time_s, dtype=float)}
    for loc, by_axis in result.metrics.items():
        for a, m in by_axis.items():
            arrays[f"metrics/{loc}/{a}"] = np.array([np.nan if getattr(m, f) is None else getattr(m, f)
                                                     for f in _METRIC_FIELDS], dtype=float)
            arrays[f"running_rms/{loc}/{a}"] = np.asarray(m.running_rms, dtype=float)
    for loc, by_axis in result.spectra.items():
        for a, (f, psd) in by_axis.items():
            arrays[f"spectra/{loc}/{a}"] = np.vstack([f, psd]).astype(float)
    for key, trace in result.sickness.items():
        rows = [trace.time_s, trace.msi_percent, trace.conflict_magnitude_mps2]
        arrays[f"sickness/{key}"] = np.vstack(rows + ([] if trace.misc is None else [trace.misc])).astype(float)

    def write(tmp):
        with open(tmp, "wb") as fh:  # a file object: numpy adds no .npz to the temporary name
            np.savez_compressed(fh, **arrays)

    replace_atomically(path, write, "the assessment's arrays")


#: The sickness time course beside an assessment: one CSV per location the model was driven by.
SICKNESS_CSV = "sickness_{location}.csv"


def write_sickness_csv(result: Assessment, folder) -> list:
    """``sickness_head.csv`` and ``sickness_seat.csv`` in ``folder``: ``time_s,msi_percent,conflict_mps2,misc`` at
    the sickness model's 20 Hz (``misc``: the predicted MISC rating, the column a person's ratings file has);
    returns the paths written."""
    from pathlib import Path

    from ..files import write_csv_atomic

    paths = []
    for key, trace in result.sickness.items():
        path = Path(folder) / SICKNESS_CSV.format(location=key)
        names = ["time_s", "msi_percent", "conflict_mps2"] + ([] if trace.misc is None else ["misc"])
        columns = [trace.time_s, trace.msi_percent, trace.conflict_magnitude_mps2] + (
            [] if trace.misc is None else [trace.misc])
        write_csv_atomic(path, names, np.column_stack(columns))
        paths.append(path)
    return paths


@checked
def read_assessment(folder, as_frame: bool = False):
    """The :class:`Assessment` of an ``ehm assess --out FOLDER`` run folder, back in Python.

    From ``assessment.json`` (the figures, the drive, the route, the ISO 2631-5 dose) and ``assessment.npz`` (the
    running rms, weighted spectra and sickness traces the figures are drawn from): ``summary()``, ``to_dataframe()``
    and the plotting functions give what they gave for the run.  ``as_frame=True``: the figures as
    ``Assessment.to_dataframe()`` gives them (location, axis, metric, value, unit), read from ``assessment.json``
    alone (so also from a folder written before ``assessment.npz`` was).  A folder that is not an assessment's is
    refused in one sentence."""
    import json
    import os
    import zipfile
    from pathlib import Path

    from ..standards.comfort import ComfortMetrics
    from ..standards.sickness import SicknessTrace

    if not isinstance(folder, (str, os.PathLike)):
        raise InputError(f"read_assessment: give the folder of an 'ehm assess --out FOLDER' run as a path, not "
                         f"{type(folder).__name__} {str(folder)[:40]!r}.")
    if not isinstance(as_frame, (bool, np.bool_)):
        raise InputError(f"read_assessment: as_frame is True (a DataFrame) or False (an Assessment), not "
                         f"{type(as_frame).__name__} {str(as_frame)[:40]!r}.")
    folder = Path(folder)
    path = folder / "assessment.json"
    if not path.is_file():
        raise InputError(f"{folder} holds no assessment.json: give the folder an 'ehm assess --out FOLDER' run "
                         "wrote.")
    try:
        summary = json.loads(path.read_text(encoding="utf-8"))
        locations = summary["locations"]
        description, duration = str(summary["input"]), float(summary["duration_s"])
    except (OSError, UnicodeDecodeError, ValueError, KeyError, TypeError) as exc:
        raise InputError(f"{path}: not an assessment ehm wrote ({type(exc).__name__}: {exc}); run 'ehm assess' "
                         "again.") from None
    if as_frame:
        from ..outputs.dataframes import frame

        rows = _summary_rows(summary)
        columns = {c: [r[i] for r in rows] for i, c in enumerate(("location", "axis", "metric", "value", "unit"))}
        columns["value"] = np.array([np.nan if v is None else v for v in columns["value"]], dtype=float)
        attrs = {"description": description, "route": (summary.get("route") or {}).get("method", "nonlinear"),
                 "duration_s": duration, "weightings": "Wd (x, y), Wk (z), Wf (MSDV)", "folder": str(folder)}
        return frame(columns, attrs, labels={"location": LOCATIONS, "axis": ("x", "y", "z", "xyz")})
    arrays_path = folder / ARRAYS_FILE
    if not arrays_path.is_file():
        raise InputError(f"{folder} holds no {ARRAYS_FILE} (an older ehm wrote it): read its figures with "
                         "read_assessment(folder, as_frame=True), or run 'ehm assess' again for the whole assessment.")
    try:
        with np.load(arrays_path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}

        def metric(loc, a):
            v = arrays[f"metrics/{loc}/{a}"]
            fields = dict(zip(_METRIC_FIELDS, (float(x) for x in v)))
            fields["msdv"] = None if np.isnan(fields["msdv"]) else fields["msdv"]
            return ComfortMetrics(running_rms=arrays[f"running_rms/{loc}/{a}"], **fields)

        metrics = {loc: {a: metric(loc, a) for a in "xyz"} for loc in locations}
        spectra = {loc: {a: tuple(arrays[f"spectra/{loc}/{a}"]) for a in "xyz"} for loc in locations}
        sickness = {k[len("sickness/"):]: SicknessTrace(*arrays[k]) for k in arrays if k.startswith("sickness/")}
        band = summary.get("input_band_hz")
        return Assessment(
            description=description, duration_s=duration, wall_s=float(summary["wall_s"]), metrics=metrics,
            spectra=spectra, sickness=sickness, trace_time_s=arrays["trace_time_s"],
            max_displacement_m={k: np.asarray(v, float) for k, v in summary["body_displacement_max_m"].items()},
            final_displacement_m={k: np.asarray(v, float) for k, v in summary["body_displacement_final_m"].items()},
            input_band_hz=None if band is None else tuple(band),
            band_outside_share=dict(summary.get("band_outside_share") or {}), route=summary.get("route"),
            iso2631_5=summary.get("iso2631_5"), vibration_level=summary.get("vibration_level"),
            misc_params=summary.get("sickness_misc_params"))
    except (OSError, ValueError, KeyError, TypeError, zipfile.BadZipFile) as exc:
        raise InputError(f"{arrays_path}: not the arrays of this assessment ({type(exc).__name__}: {exc}); run "
                         "'ehm assess' again.") from None
