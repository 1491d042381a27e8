"""Run commands: simulate, demo, assess and animate a person on a seat."""

from __future__ import annotations

import contextlib
import math
import time
from pathlib import Path

from ...errors import InputError
from ...files import write_json_atomic
from ...inputs.motion import random_vibration, sine, sweep
from ...outputs.outdir import RunFolder, check_output_file, check_output_folder
from ...outputs.runfiles import DEFAULT_OUTPUT_RATE_HZ
from .common import checked_band, human_from_args, input_files, read_motion_file
from .options import excitation_options, model_options, motion_file_options, parallel_options, progress_options
from .progress import end_progress_line, progress_bar, progress_count

#: The demo's transfer functions: Welch segments of 10 s (0.1 Hz resolution, as its peaks are printed), at least
#: four of them per run (seven averages with the 50 % overlap), so a run lasts at least 40 s.
DEMO_SEGMENT_S = 10.0
DEMO_MIN_SEGMENTS = 4


def _random_input(args, axis: str, dt: float):
    return random_vibration(axis, args.duration, args.rms, seed=args.seed, dt_s=dt, band_hz=checked_band(args.band))


def _motion(args, dt: float):
    if args.signal == "random":
        return _random_input(args, args.axis, dt)
    if args.signal == "sine":
        return sine(args.axis, args.duration, args.amplitude, args.freq, dt_s=dt)
    return sweep(args.axis, args.duration, args.amplitude, args.f0, args.f1, dt_s=dt)


# --- ehm simulate ---------------------------------------------------------------------------------------------------

def add_simulate(sub) -> None:
    p = sub.add_parser("simulate", help="run the model with a seat motion and write timeseries.csv, summary.json")
    model_options(p)
    excitation_options(p, 35.0)
    p.add_argument("--axis", default="z", help="excited seat axes: x, y, z or a combination (default z)")
    p.add_argument("--signal", choices=("random", "sine", "sweep"), default="random",
                   help="generated input (default random)")
    p.add_argument("--amplitude", type=float, default=0.5, help="sine or sweep peak acceleration [m/s^2]")
    p.add_argument("--freq", type=float, default=4.0, help="sine frequency [Hz]")
    p.add_argument("--f0", type=float, default=0.5, help="sweep start frequency [Hz]")
    p.add_argument("--f1", type=float, default=12.0, help="sweep end frequency [Hz]")
    motion_file_options(p, False, "seat motion file (.csv/.txt, .parquet, .mat, .mf4, or city / road): time_s, "
                                   "ax_mps2, ay_mps2, az_mps2 [, wx_radps, wy_radps, wz_radps] unless --channel says")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder (replaced whole: one run per folder)")
    p.add_argument("--output-rate", type=float, metavar="HZ",
                   help=f"rows per second of the time series, dividing the model's rate (default "
                        f"{DEFAULT_OUTPUT_RATE_HZ:g}, or every step when the model's rate is lower; summary values "
                        "use every step)")
    p.add_argument("--format", choices=("csv", "parquet", "both"), default="csv",
                   help="time-series file: timeseries.csv, timeseries.parquet (needs ehm[parquet]) or both "
                        "(default csv)")
    p.add_argument("--plot", action="store_true", help="also draw time_histories.png")
    _route_options(p)
    parallel_options(p)
    progress_options(p)
    p.set_defaults(func=cmd_simulate)


def _route_options(p) -> None:
    """--method and --tolerance of simulate and assess (ehm.routes.hybrid)."""
    p.add_argument("--method", choices=("auto", "nonlinear", "linear"), default="auto",
                   help="simulation route: auto (default: the linearised person, with the nonlinear model where a "
                        "contact reaches its friction limit or lifts off, and for the rest of the drive once those "
                        "windows cover more than half of it so far, or from the start for a drive whose manoeuvres "
                        "hold 1.5 m/s^2 for over 30 %% of it), nonlinear (MuJoCo throughout) or linear (the "
                        "linearised person throughout, checked against the nonlinear model there)")
    p.add_argument("--tolerance", type=float, default=None, metavar="PERCENT",
                   help="the linear route's tolerance: discrepancy from the nonlinear model in %% of each point "
                        "acceleration's rms, of the largest one's where a point's own is round-off (default 1)")


def _tolerance(args) -> float | None:
    if args.tolerance is None:
        return None
    if not (0 < args.tolerance < 100):
        raise InputError(f"--tolerance is a percentage between 0 and 100, not {args.tolerance:g}.")
    return args.tolerance / 100.0


def cmd_simulate(args) -> int:
    from ...outputs.runfiles import pyarrow_modules

    formats = ("csv", "parquet") if args.format == "both" else (args.format,)
    if "parquet" in formats:
        pyarrow_modules()
    out = check_output_folder(args.out, inputs=input_files(args))
    if args.motion:  # a drive file with angular velocities needs the rotating seat
        motion = read_motion_file(args)
        from ...analysis.assessment import needs_rotating_seat

        human = human_from_args(args, rotating_seat=needs_rotating_seat(motion, args.method))
    else:
        human = human_from_args(args)
        motion = _motion(args, float(human.params.value("simulation.dt_s")))
    draw = None
    if args.plot:  # simulate_to computes; the figure is drawn here, into the folder before it is put in place
        from ...outputs.plotting import plot_run_preview as draw
    t0 = time.perf_counter()
    with _segments(args) as parallel:
        show = progress_bar("simulate", args.quiet)
        chunks = None if parallel is None else parallel(human, motion, progress=show, chunk_s=10.0, pose_rate_hz=25.0)
        s = human.simulate_to(out, motion, output_rate_hz=args.output_rate, formats=formats, progress=show,
                              plot=draw, method=args.method, tolerance=_tolerance(args), chunks=chunks,
                              workers=args.workers if parallel is None else None,
                              lead_in_s=args.lead_in if parallel is None else None)
    files = ", ".join(f"timeseries.{f}" for f in formats) + ", summary.json, poses.npz" + \
        (", time_histories.png" if args.plot else "")
    wall = time.perf_counter() - t0
    if parallel is None and s["wall_s"] <= wall:
        speed = f"in {s['wall_s']:.2f} s ({s['realtime_factor']:.0f}x real time)"
    else:  # the stepping's time summed over the processes is not the time it took
        where = "several processes" if parallel is None else parallel.describe()
        speed = (f"in {wall:.2f} s on {where} ({s['duration_s'] / wall:.0f}x real time, files "
                 f"included; {s['wall_s']:.2f} s of stepping in all)")
    print(f"simulated {s['duration_s']:.3g} s of '{s['input']}' {speed}; wrote {out}/ ({files}; "
          f"{s['output_rate_hz']:g} rows per s)")
    if "route" in s:
        print(f"  {s['route']['summary_line']}")
    if s.get("vibration_level"):
        print(f"  {s['vibration_level']['line']}")
    return 0


class _Parallel:
    """The nonlinear route in segments as the command line asked for it (:mod:`ehm.routes.parallel`)."""

    def __init__(self, workers: int, client, lead_in_s):
        self.workers, self.client, self.lead_in_s = workers, client, lead_in_s

    def describe(self) -> str:
        return "the Dask cluster's workers" if self.client is not None else f"{self.workers} processes"

    def __call__(self, human, motion, **kw):
        from ...routes.parallel import stream_parallel

        return stream_parallel(human, motion, workers=self.workers, client=self.client, lead_in_s=self.lead_in_s,
                               **kw)


@contextlib.contextmanager
def _segments(args):
    """None for one continuous run, else a :class:`_Parallel` (with a Dask client for --scheduler, closed on
    leaving); --workers, --scheduler and --lead-in checked, one sentence each."""
    workers, scheduler, lead = args.workers, args.scheduler, args.lead_in
    if workers is not None and workers < 1:
        raise InputError(f"--workers {workers}: use 1 or more worker processes.")
    if lead is not None and not (math.isfinite(lead) and lead >= 0):
        raise InputError(f"--lead-in {lead}: give the lead-in in seconds, 0 or more.")
    if workers is not None and scheduler is not None:
        raise InputError("give --workers (local processes) or --scheduler (a Dask cluster's workers), not both.")
    if scheduler is None:
        if args.method == "linear" and ((workers or 1) > 1 or lead is not None):
            raise InputError("--workers and --lead-in split the nonlinear model's runs into segments; the linear route "
                             "runs in one process: leave them out, or use --method nonlinear or auto.")
        if args.method == "nonlinear" and (workers or 1) > 1:
            yield _Parallel(workers, None, lead)
            return
        # the route's own choice (--workers and --lead-in passed on): a long drive it runs on the nonlinear model goes
        # in segments on the machine's cores unless --workers says otherwise (ehm.routes.parallel.default_workers)
        yield None
        return
    if args.method != "nonlinear":
        which = "the auto route, the default," if args.method == "auto" else f"the {args.method} route"
        raise InputError(f"--scheduler runs the nonlinear route in segments on a Dask cluster; add --method nonlinear "
                         f"({which} runs in one process).")
    from ..cluster import check_scheduler, dask_client

    with dask_client(check_scheduler(scheduler), None) as client:
        yield _Parallel(1, client, lead)


# --- ehm demo -------------------------------------------------------------------------------------------------------

def add_demo(sub) -> None:
    p = sub.add_parser("demo", help="x, y and z random vibration of the default model, with plots")
    model_options(p)
    excitation_options(p, 60.0)
    p.add_argument("--axes", nargs="+", default=["x", "y", "z"], choices=("x", "y", "z"),
                   help="seat axes to run, one run each (default x y z)")
    p.add_argument("--out", default="ehm-demo", metavar="DIR", help="output folder (default ehm-demo)")
    p.set_defaults(func=cmd_demo)


def _check_demo_duration(duration_s: float) -> None:
    """Refuse a demo run too short for its 0.1 Hz transfer-function resolution."""
    need = DEMO_SEGMENT_S * DEMO_MIN_SEGMENTS
    if not duration_s >= need:
        raise InputError(f"--duration {duration_s:g}: the demo's transfer functions need at least {need:g} s per axis "
                         f"({DEMO_MIN_SEGMENTS} Welch segments of {DEMO_SEGMENT_S:g} s for their "
                         f"{1 / DEMO_SEGMENT_S:g} Hz resolution); use --duration {need:g} or more.")


def cmd_demo(args) -> int:
    _check_demo_duration(args.duration)
    final = check_output_folder(args.out, inputs=input_files(args))
    human = human_from_args(args)
    dt = float(human.params.value("simulation.dt_s"))
    print(f"ehm demo: default person ({human.mass_kg:.3f} kg, {human.dof} dof) on the validation seat; "
          f"{args.duration:g} s of {args.rms:g} m/s^2 rms random vibration per axis; output in {final}/")
    human.settle()
    with RunFolder(final) as out:
        peaks = _demo_runs(args, human, dt, out)
    print("  transmissibility peaks (seat axis -> same axis at the point):")
    for k, v in peaks.items():
        print(f"    {k:<12} {v['peak_gain']:.2f} at {v['peak_hz']:.1f} Hz (gain {v['gain_at_0.5_hz']:.2f} at 0.5 Hz)")
    print(f"wrote {final}/transmissibility.csv, transmissibility.png, demo_summary.json, per-axis "
          f"timeseries.csv, summary.json, time_histories.png, poses.npz, and {args.axes[-1]}/animation.gif")
    return 0


def _demo_runs(args, human, dt: float, out: Path) -> dict:
    """The demo's runs, tables and figures, written into ``out``; returns the transmissibility peaks."""
    from ...analysis.frf import FrfTable, run_curves
    from ...outputs.animation import animate
    from ...outputs.plotting import plot_time_histories, plot_transmissibility

    curves, summaries = {}, {}
    for axis in args.axes:
        run = human.simulate(_random_input(args, axis, dt), pose_rate_hz=25.0)
        run.write(out / axis)
        plot_time_histories(run, out / axis / "time_histories.png", title=f"seat {axis}: {run.description}")
        if axis == args.axes[-1]:  # one animation: the body's motion, exaggerated 20 times
            animate(out / axis, out / axis / "animation.gif", exaggerate=20.0, end_s=min(8.0, run.duration_s))
        curves.update(run_curves(run, axis, tuple(args.band), segment_s=DEMO_SEGMENT_S))
        summaries[axis] = run.summary()
        print(f"  {axis}: {run.duration_s:.0f} s simulated in {run.wall_s:.2f} s "
              f"({run.realtime_factor:.0f}x real time)")
    table = FrfTable(curves, method="time", meta={"input": "synthetic random vibration"})
    table.to_csv(out / "transmissibility.csv")
    plot_transmissibility(table, out / "transmissibility.png",
                          title="Seat-to-body transmissibility of the default model (H1 estimate; synthetic input)")
    peaks = _transmissibility_peaks(table)
    write_json_atomic(out / "demo_summary.json", {"runs": summaries, "transmissibility_peaks": peaks})
    return peaks


def _transmissibility_peaks(table) -> dict:
    """Peak and 0.5 Hz gain of each seat axis -> same axis at a point (the apparent masses are in the CSV too)."""
    from ...analysis.frf import POINTS

    peaks = {}
    for (a, p, dof), c in table.curves.items():
        if dof == a and p in POINTS:
            f_pk, g_pk = c.peak((0.5, 12.0))
            peaks[f"{a}->{p}"] = {"peak_hz": f_pk, "peak_gain": g_pk, "gain_at_0.5_hz": c.at(0.5)}
    return peaks


# --- ehm assess -----------------------------------------------------------------------------------------------------

def add_assess(sub) -> None:
    p = sub.add_parser("assess", help="comfort (ISO 2631-1) and motion sickness of a drive, at the seat and the body")
    model_options(p)
    motion_file_options(p, True, "drive file (.csv/.txt, .parquet, .mat, .mf4: time_s, ax_mps2, ay_mps2, az_mps2 "
                                  "[, wx_radps, wy_radps, wz_radps] unless --channel says) or 'city' / 'road' for the "
                                  "shipped SYNTHETIC drives")
    p.add_argument("--out", required=True, metavar="DIR",
                   help="output folder: assessment.json, assessment.npz (ehm.read_assessment reads the two back), "
                        "report.html and figures (replaced whole if ehm wrote it)")
    p.add_argument("--sickness-params", metavar="FILE",
                   help="a person's MISC parameters, the sickness_params.toml 'ehm fit-sickness' wrote (default: the "
                        "group's; in Python: assess(..., sickness_params=ehm.read_sickness_params(FILE)))")
    _route_options(p)
    _exposure_options(p)
    parallel_options(p)
    progress_options(p)
    p.set_defaults(func=cmd_assess)


def _exposure_options(p) -> None:
    """The daily exposure and the person of the ISO 2631-5 spinal dose (ehm.standards.comfort.spine.SpineExposure)."""
    g = p.add_argument_group("ISO 2631-5 spinal dose (defaults: 8 h a day, the standard's Annex C example's person)")
    g.add_argument("--daily-exposure-h", type=float, default=8.0, metavar="H",
                   help="hours a day the person sits in vibration like this drive's (default 8)")
    g.add_argument("--exposure-start-age-years", type=float, default=20.0, metavar="YEARS",
                   help="the age the exposure started (default 20)")
    g.add_argument("--exposure-years", type=int, default=20, metavar="N", help="years of exposure (default 20)")
    g.add_argument("--exposure-days-per-year", type=float, default=120.0, metavar="DAYS",
                   help="days of exposure a year (default 120)")
    g.add_argument("--sex", choices=("male", "female"), default="male",
                   help="the standard's person for the dose: its 82 kg man or 64 kg woman (stress per acceleration, "
                        "strength, injury risk; default male); the body model is set by --params, --mass and the rest")


def _sickness_params(path: str | None):
    """--sickness-params FILE: a person's MISC parameters (None: the group's)."""
    if path is None:
        return None
    from ...standards.sickness import read_sickness_params

    return read_sickness_params(path)


def _exposure(args):
    from ...standards.comfort.spine import SpineExposure

    return SpineExposure(daily_exposure_h=args.daily_exposure_h, start_age_years=args.exposure_start_age_years,
                         exposure_years=args.exposure_years, days_per_year=args.exposure_days_per_year, sex=args.sex)


def cmd_assess(args) -> int:
    from ...analysis.assessment import assess, needs_rotating_seat

    final = check_output_folder(args.out, inputs=input_files(args) + (
        [args.sickness_params] if args.sickness_params else []))
    exposure = _exposure(args)
    misc_params = _sickness_params(args.sickness_params)
    with _warnings_shown() as shown:  # what the console prints goes into assessment.json and the report too
        motion = read_motion_file(args)
        human = human_from_args(args, rotating_seat=needs_rotating_seat(motion, args.method))
        with _segments(args) as parallel:
            kw = ({"workers": args.workers, "lead_in_s": args.lead_in} if parallel is None else
                  {"workers": parallel.workers, "client": parallel.client, "lead_in_s": parallel.lead_in_s})
            result = assess(motion, human, progress=progress_bar("assess", args.quiet), method=args.method,
                            tolerance=_tolerance(args), exposure=exposure, sickness_params=misc_params, **kw)
    if args.sickness_params:
        from ...analysis.assessment import misc_summary

        result.misc_params = misc_summary(misc_params, whose=f"person ({args.sickness_params})")
    summary = _assessment_summary(result, human)
    summary["warnings"] = list(dict.fromkeys(shown))
    with RunFolder(final) as out:
        _write_assessment(result, summary, out)
    _print_assessment(result, summary, final)
    return 0


@contextlib.contextmanager
def _warnings_shown():
    """The texts of ehm's warnings (:class:`ehm.errors.EhmWarning`) shown while the block runs, each as the console
    prints it (the command's warning display is kept and called)."""
    import warnings

    from ...errors import EhmWarning

    shown: list[str] = []
    previous = warnings.showwarning

    def show(message, category, *rest, **kw):
        if issubclass(category, EhmWarning):
            shown.append(str(message))
        previous(message, category, *rest, **kw)

    warnings.showwarning = show
    try:
        yield shown
    finally:
        warnings.showwarning = previous


def _assessment_summary(result, human) -> dict:
    """The assessment's summary with the person it ran: parameter file, locked joints, scaling."""
    summary = result.summary()
    summary["params"] = human.params.origin
    summary["locked"] = sorted(human.locked)
    if human.size is not None:
        summary["scaled"] = human.params.data["about"].get("scaled", "")
    return summary


def _write_assessment(result, summary: dict, out: Path) -> None:
    """assessment.json, assessment.npz (the arrays: ehm.read_assessment gives the Assessment back), the three
    figures and report.html, written into ``out``."""
    from ...analysis.assessment import ARRAYS_FILE, write_assessment_arrays, write_sickness_csv
    from ...outputs.plotting import plot_running_rms, plot_sickness, plot_weighted_spectra
    from ...outputs.report import write_report

    write_json_atomic(out / "assessment.json", summary)
    write_assessment_arrays(result, out / ARRAYS_FILE)
    write_sickness_csv(result, out)
    figures = {"spectra": out / "weighted_spectra.png", "running_rms": out / "running_rms.png",
               "sickness": out / "sickness.png"}
    plot_weighted_spectra(result, figures["spectra"])
    plot_running_rms(result, figures["running_rms"])
    plot_sickness(result, figures["sickness"])
    write_report(summary, figures, out / "report.html")


def _print_assessment(result, summary: dict, out: Path) -> None:
    from ...analysis.assessment import LOCATIONS

    loc = summary["locations"]
    print(f"{result.duration_s:.0f} s of '{result.description}' in {result.wall_s:.0f} s")
    band = summary.get("input_band_hz")
    if band:
        outside = {w: v for w, v in summary.get("band_outside_share", {}).items() if v > 0}
        print(f"  input covers {band[0]:.3g}-{band[1]:.3g} Hz" + (
            "; outside it: " + ", ".join(f"{100 * v:.1f} % of {w}'s power" for w, v in outside.items())
            if outside else " (the Wd, Wk and Wf bands whole)"))
    for name in LOCATIONS:
        v = loc[name]
        ax = v["axes"]
        print(f"  {name:<7} a_v {v['total_value_mps2']:.3f} m/s^2 ({v['comfort_reaction']}), "
              f"a_w x/y/z {ax['x']['a_w_mps2']:.4f}/{ax['y']['a_w_mps2']:.4f}/{ax['z']['a_w_mps2']:.4f} m/s^2, "
              f"VDV_z {ax['z']['vdv_mps175']:.3f} m/s^1.75, MSDV_z {v['msdv_z_mps15']:.3f} m/s^1.5")
    if summary.get("handling_cut"):
        print(f"  handled logger: {summary['handling_cut']['note']}")
    if summary.get("route"):
        print(f"  {summary['route']['summary_line']}")
    if summary.get("vibration_level"):
        print(f"  {summary['vibration_level']['line']}")
    sick = summary["sickness"]
    print(f"  motion sickness incidence at the end: head {sick['head']['final_msi_percent']:.2f} %, "
          f"head fixed to the seat {sick['seat']['final_msi_percent']:.2f} %")
    if "final_misc" in sick["head"]:
        whose = (summary.get("sickness_misc_params") or {}).get("whose", "group")
        print(f"  predicted MISC rating at the end (0-10, {whose} parameters): head {sick['head']['final_misc']:.2f}, "
              f"head fixed to the seat {sick['seat']['final_misc']:.2f} (highest: head "
              f"{sick['head']['max_misc']:.2f})")
    for line in _iso2631_5_lines(summary.get("iso2631_5")):
        print(f"  {line}")
    print(f"wrote {out}/assessment.json, assessment.npz, report.html, weighted_spectra.png, running_rms.png, "
          "sickness.png, sickness_head.csv, sickness_seat.csv (in Python: ehm.read_assessment(folder))")


def _iso2631_5_lines(section: dict | None) -> list[str]:
    """The ISO 2631-5 figures of an assessment's summary, for the console."""
    if not section:
        return []
    e = section["exposure"]
    lines = []
    for name, label in (("standard_route", "by the standard's transfer function from the seat"),
                        ("model_route", "by the body model's lumbar point")):
        v = section.get(name)
        if v:
            lines.append(f"ISO 2631-5 {label}: largest lumbar peak {v['lumbar_peak_max_mps2']:.3g} m/s^2 at "
                         f"{v['lumbar_peak_max_time_s']:.1f} s ({v['lumbar_peak_count']} peaks), D_z "
                         f"{v['dose_dz_mps2']:.3g} m/s^2; {e['daily_exposure_h']:g} h a day: D_zd "
                         f"{v['daily_dose_dzd_mps2']:.3g} m/s^2, S_d {v['daily_compressive_stress_sd_mpa']:.3g} MPa, "
                         f"R {v['r_factor']:.3g} ({e['exposure_years']} years from age {e['start_age_years']:g}, "
                         f"{e['days_per_year']:g} days a year, {e['sex']}; R {v['r_for_risk_10_50_90_pct'][0]:g} "
                         f"is a 10 % risk)")
    if section.get("routes_differ"):
        lines.append(section["routes_differ"])
    return lines


# --- ehm fit-sickness ----------------------------------------------------------------------------------------------

def add_fit_sickness(sub) -> None:
    p = sub.add_parser("fit-sickness", help="one person's MISC parameters (K1, T1) from their ratings of a drive")
    model_options(p)
    motion_file_options(p, True, "the drive the person rated (as for 'ehm assess'; 'city' / 'road' for the shipped "
                                  "SYNTHETIC drives)")
    p.add_argument("--ratings", required=True, metavar="RATINGS.csv",
                   help="the person's MISC ratings: columns time_s (seconds from the drive's start) and misc (0-10)")
    p.add_argument("--out", required=True, metavar="DIR",
                   help="output folder: sickness_params.toml (for 'ehm assess --sickness-params' and batch studies), "
                        "sickness_fit.csv and sickness_fit.png (replaced whole if ehm wrote it)")
    p.add_argument("--location", choices=("head", "seat"), default="head",
                   help="whose conflict the ratings are fitted to: the head's through the body (default) or a head "
                        "fixed to the seat")
    _route_options(p)
    progress_options(p)
    p.set_defaults(func=cmd_fit_sickness)


def cmd_fit_sickness(args) -> int:
    from ...analysis.assessment import assess, needs_rotating_seat
    from ...analysis.sickness_fit import FIT_FIGURE, fit_sickness, rating_rows
    from ...outputs.plotting import plot_sickness_fit

    final = check_output_folder(args.out, inputs=input_files(args) + [args.ratings])
    times, _, lines = rating_rows(args.ratings)  # a bad ratings file is refused before the drive is run
    motion = read_motion_file(args)
    late = [k for k, t in enumerate(times) if t > motion.duration_s]
    if late:
        raise InputError(f"{args.ratings} row {lines[late[0]]}: time_s {times[late[0]]:g} s lies after the end of the "
                         f"drive '{motion.description}' ({motion.duration_s:g} s); ratings are seconds from the "
                         "drive's start (--ratings).")
    human = human_from_args(args, rotating_seat=needs_rotating_seat(motion, args.method))
    assessment = assess(motion, human, progress=progress_bar("assess", args.quiet), method=args.method,
                        tolerance=_tolerance(args))
    result = fit_sickness(assessment, args.ratings, location=args.location)
    with RunFolder(final) as out:
        result.write(out)
        plot_sickness_fit(result, out / FIT_FIGURE)
    print(f"{len(result.fit.time_s)} ratings of '{result.drive}' fitted ({args.location}'s conflict):")
    for line in result.summary_lines():
        print(f"  {line}")
    print(f"wrote {final}/sickness_params.toml, sickness_fit.csv, {FIT_FIGURE} (ehm assess --sickness-params "
          f"{final}/sickness_params.toml)")
    return 0


# --- ehm animate ----------------------------------------------------------------------------------------------------

def add_animate(sub) -> None:
    p = sub.add_parser("animate", help="draw a run's person and seat into a .gif or .mp4 (offscreen, no display)")
    p.add_argument("run_dir", metavar="RUN_DIR", help="run folder with poses.npz (from 'ehm simulate --out RUN_DIR')")
    p.add_argument("--out", metavar="FILE.gif|FILE.mp4",
                   help="animation file (default RUN_DIR/animation.gif; .mp4 needs ehm[animate])")
    p.add_argument("--exaggerate", default="auto", metavar="F|auto",
                   help="scale the motion from the settled posture by F (1: true scale); default auto: the factor "
                        "that makes the motion visible (the segment that moves most travels 4 %% of the view), "
                        "stated on the picture")
    p.add_argument("--fps", type=float, default=25.0, help="frames per second (default 25; poses are stored at 25 Hz)")
    p.add_argument("--start", type=float, metavar="S", help="first time drawn [s] (default: the start)")
    p.add_argument("--end", type=float, metavar="S", help="last time drawn [s] (default: the end)")
    p.add_argument("--max-frames", type=int, metavar="N", help="stop after N frames")
    progress_options(p)
    p.set_defaults(func=cmd_animate)


def _exaggeration(text: str):
    """--exaggerate: ``auto`` or a number (checked by the animation)."""
    if text.strip().lower() == "auto":
        return "auto"
    try:
        return float(text)
    except ValueError:
        raise InputError(f"--exaggerate {text!r}: give a factor such as 20 (1: true scale) or auto.") from None


def cmd_animate(args) -> int:
    from ...outputs.animation import DEFAULT_NAME, animate, pick_exaggeration

    out = args.out if args.out is not None else str(Path(args.run_dir) / DEFAULT_NAME)
    check_output_file(out, "animation", part_of=args.run_dir)  # drawn into its own run folder: listed
    asked = _exaggeration(args.exaggerate)
    t0 = time.perf_counter()
    window = {"fps": args.fps, "start_s": args.start, "end_s": args.end, "max_frames": args.max_frames}
    factor, why = pick_exaggeration(args.run_dir, **window) if asked == "auto" else (asked, "")
    path = animate(args.run_dir, out, exaggerate=factor, progress=progress_count("frames", args.quiet), **window)
    end_progress_line()
    how = ("true scale" if factor == 1 else f"motion x{factor:g}") + (f", {why}" if why else "") + (
        " (--exaggerate 1: true scale)" if why and factor != 1 else "")
    print(f"wrote {path} in {time.perf_counter() - t0:.1f} s; {how}")
    return 0
