"""The ``ehm`` command: a thin layer over the library.

Every subcommand maps onto library calls; problems with input end in one sentence on stderr and exit
code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from . import __version__
from .errors import EhmError, InputError
from .io import write_json_atomic
from .outdir import RunFolder, check_output_file, check_output_folder, folder_kept_tidy
from .motion import random_vibration, sine, sweep
from .params import Parameters, refuse_defaults
from .simulation import SeatedHuman
from .drives import drive_path
from .runfiles import DEFAULT_OUTPUT_RATE_HZ
from .tables import load_body

EXIT_ERROR = 2
#: ehm fit: stopped on its budget, did not lower the criterion, its check disagreed, or a value ended on its
#: search bound (then the file is still written, that value graded "at bound").
EXIT_NOT_IDENTIFIED = 3


def _joint_list(values: list[str] | None) -> list[str]:
    out: list[str] = []
    for v in values or []:
        out += [x.strip() for x in v.split(",") if x.strip()]
    return out


def _human(args, rotating_seat: bool = False) -> SeatedHuman:
    params = Parameters.load(args.params)
    if getattr(args, "dt", None) is not None:
        if not args.dt > 0:
            raise InputError(f"--dt must be a positive time step in seconds, not {args.dt}.")
        params = params.with_values({"simulation.dt_s": args.dt})
    body = load_body(args.segments, args.joints, args.contacts)
    return SeatedHuman(params=params, lock=_joint_list(args.lock), unlock=_joint_list(args.unlock), body=body,
                       rotating_seat=rotating_seat, size=_size(args))


def _size(args):
    """A BodySize from --stature / --mass / --sitting-height, or None for the reference person."""
    if args.stature is None and args.mass is None and args.sitting_height is None:
        return None
    from .scaling import REFERENCE_MASS_KG, REFERENCE_STATURE_M, BodySize

    return BodySize(args.stature if args.stature is not None else REFERENCE_STATURE_M,
                    args.mass if args.mass is not None else REFERENCE_MASS_KG, args.sitting_height)


def _band(values) -> tuple[float, float]:
    lo, hi = values
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo < hi):
        raise InputError(f"--band {lo:g} {hi:g}: the band needs two finite frequencies with 0 < low < high [Hz].")
    return float(lo), float(hi)


def _model_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--params", metavar="FILE.toml", help="parameter file (default: the shipped defaults)")
    p.add_argument("--lock", action="append", metavar="JOINT", help="lock a joint (repeat or comma-separate)")
    p.add_argument("--unlock", action="append", metavar="JOINT", help="unlock a joint, e.g. waist")
    p.add_argument("--segments", metavar="FILE.csv", help="segment table (default: the paper's Table 2)")
    p.add_argument("--joints", metavar="FILE.csv", help="joint table (default: the paper's Table 1)")
    p.add_argument("--contacts", metavar="FILE.csv", help="contact ellipsoid table (default: shipped)")
    p.add_argument("--stature", type=float, metavar="M", help="scale the person to this standing height [m]")
    p.add_argument("--mass", type=float, metavar="KG", help="scale the person to this body mass [kg]")
    p.add_argument("--sitting-height", type=float, metavar="M", help="sitting height [m] (default: in proportion)")


def _excitation_options(p: argparse.ArgumentParser, duration: float) -> None:
    p.add_argument("--duration", type=float, default=duration, help=f"simulated time [s] (default {duration:g})")
    p.add_argument("--rms", type=float, default=0.3, help="rms seat acceleration of random input [m/s^2] (default 0.3)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--band", type=float, nargs=2, default=(0.1, 12.0), metavar=("LOW_HZ", "HIGH_HZ"),
                   help="band of the random input [Hz] (default 0.1 12)")
    p.add_argument("--dt", type=float, help="time step [s] (default from the parameter file: 0.001)")


def cmd_info(args) -> int:
    human = _human(args)
    info = human.info()
    if args.json:
        print(json.dumps(info, indent=2))
        return 0
    print(f"ehm {__version__}: seated human, {info['mass_kg']:.3f} kg, {info['dof']} degrees of freedom, "
          f"time step {info['dt_s'] * 1000:g} ms, parameters: {info['params']}")
    print("segments (centre of gravity in m, x forward, y left, z up):")
    for s in info["segments"]:
        x, y, z = s["com_m"]
        print(f"  {s['name']:<13} {s['mass_kg']:7.3f} kg  ({x:+.4f}, {y:+.4f}, {z:+.4f})")
    print("joints:")
    for j in info["joints"]:
        state = "locked" if j["locked"] else f"{j['dof']} dof ({', '.join(j['dofs'])})"
        print(f"  {j['name']:<11} {j['type']:<19} {j['parent']} -> {j['child']}: {state}")
    return 0


def _random_input(args, axis: str, dt: float):
    return random_vibration(axis, args.duration, args.rms, seed=args.seed, dt_s=dt, band_hz=_band(args.band))


def _motion(args, dt: float):
    if args.signal == "random":
        return _random_input(args, args.axis, dt)
    if args.signal == "sine":
        return sine(args.axis, args.duration, args.amplitude, args.freq, dt_s=dt)
    return sweep(args.axis, args.duration, args.amplitude, args.f0, args.f1, dt_s=dt)


def _motion_file_options(p: argparse.ArgumentParser, required: bool, help_text: str) -> None:
    """--motion FILE and how to read it: --channel, --unit (both repeatable), --imu, --rate."""
    p.add_argument("--motion", required=required, metavar="FILE", help=help_text)
    p.add_argument("--channel", action="append", metavar="KEY=NAME",
                   help="the file's name for a channel (KEY: time, ax, ay, az, wx, wy, wz; repeat; --channel time= "
                        "for a file without time stamps; --channel wx= --channel wy= --channel wz= to leave its "
                        "angular velocities out; MDF: GROUP/NAME for a name in several groups, GROUP its index); "
                        "default: time_s, ax_mps2, ..., wx_radps, ...")
    p.add_argument("--unit", action="append", metavar="KEY=UNIT",
                   help="unit of a channel, e.g. ax=g, wx=deg/s, time=ns, or a date-time format such as "
                        "'time=%%d/%%m/%%Y %%H:%%M:%%S' (repeat; wins over a unit in the channel's name; default: the "
                        "name's unit, as in 'Accelerometer X (g)' or time_ms, else SI)")
    p.add_argument("--imu", action="store_true",
                   help="the file is an IMU at the seat: ax, ay, az its specific force (gravity included), wx, wy, wz "
                        "its gyro rates; the log must start with 1 s at rest")
    p.add_argument("--fill-gaps", action="store_true",
                   help="bridge gaps in the file's time stamps (steps over 5 median steps: a logger's dropout) with a "
                        "straight line, with a warning naming where (default: refuse them)")
    p.add_argument("--rate", type=float, metavar="HZ",
                   help="sample rate of a file without time stamps (otherwise: resample the file to this rate)")


def _read_motion_file(args):
    """The --motion file (or a shipped SYNTHETIC drive) through ehm.readers.read_motion."""
    from .readers import parse_assignments, read_motion

    return read_motion(drive_path(args.motion), channels=parse_assignments(args.channel, "--channel"),
                       units=parse_assignments(args.unit, "--unit"), rate_hz=args.rate, imu=args.imu,
                       fill_gaps=args.fill_gaps)


def cmd_simulate(args) -> int:
    from .runfiles import pyarrow_modules

    formats = ("csv", "parquet") if args.format == "both" else (args.format,)
    if "parquet" in formats:
        pyarrow_modules()
    out = check_output_folder(args.out)
    if args.motion:  # a drive file with angular velocities needs the rotating seat
        motion = _read_motion_file(args)
        # the linear route's seat does not turn: it takes translation (all-zero rates) or refuses, in one sentence
        human = _human(args, rotating_seat=motion.angvel_radps is not None and args.method != "linear")
    else:
        human = _human(args)
        motion = _motion(args, float(human.params.value("simulation.dt_s")))
    draw = None
    if args.plot:  # simulate_to computes; the figure is drawn here, into the folder before it is put in place
        from .plotting import plot_run_preview as draw
    s = human.simulate_to(out, motion, output_rate_hz=args.output_rate, formats=formats,
                          progress=_progress_bar("simulate"), plot=draw, method=args.method)
    files = ", ".join(f"timeseries.{f}" for f in formats) + ", summary.json" + \
        (", poses.npz" if args.method != "linear" else "") + \
        (", time_histories.png" if args.plot else "")
    print(f"simulated {s['duration_s']:.3g} s of '{s['input']}' in {s['wall_s']:.2f} s "
          f"({s['realtime_factor']:.0f}x real time); wrote {out}/ ({files}; {s['output_rate_hz']:g} rows per s)")
    return 0


#: The demo's transfer functions: Welch segments of 10 s (0.1 Hz resolution, as its peaks are printed), at least
#: four of them per run (seven averages with the 50 % overlap), so a run lasts at least 40 s.
DEMO_SEGMENT_S = 10.0
DEMO_MIN_SEGMENTS = 4


def _check_demo_duration(duration_s: float) -> None:
    """Refuse a demo run too short for its 0.1 Hz transfer-function resolution."""
    need = DEMO_SEGMENT_S * DEMO_MIN_SEGMENTS
    if not duration_s >= need:
        raise InputError(f"--duration {duration_s:g}: the demo's transfer functions need at least {need:g} s per axis "
                         f"({DEMO_MIN_SEGMENTS} Welch segments of {DEMO_SEGMENT_S:g} s for their "
                         f"{1 / DEMO_SEGMENT_S:g} Hz resolution); use --duration {need:g} or more.")


def cmd_demo(args) -> int:
    _check_demo_duration(args.duration)
    final = check_output_folder(args.out)
    human = _human(args)
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
    from .animation import animate
    from .frf import POINTS, FrfTable, run_curves
    from .plotting import plot_time_histories, plot_transmissibility

    curves, summaries = {}, {}
    for axis in args.axes:
        run = human.simulate(_random_input(args, axis, dt), pose_rate_hz=25.0)
        run.write(out / axis)
        plot_time_histories(run, out / axis / "time_histories.png", title=f"seat {axis}: {run.description}")
        if axis == args.axes[-1]:  # one animation: the body's motion, exaggerated 20 times
            animate(out / axis, out / axis / "animation.gif", exaggerate=20.0, end_s=min(8.0, run.duration_s))
        curves.update(run_curves(run, axis, tuple(args.band), segment_s=DEMO_SEGMENT_S))
        summaries[axis] = run.summary()
        print(f"  {axis}: {run.duration_s:.0f} s simulated in {run.wall_s:.2f} s ({run.realtime_factor:.0f}x real time)")
    table = FrfTable(curves, method="time", meta={"input": "synthetic random vibration"})
    table.to_csv(out / "transmissibility.csv")
    plot_transmissibility(table, out / "transmissibility.png",
                          title="Seat-to-body transmissibility of the default model (H1 estimate; synthetic input)")
    peaks = {}
    for (a, p, dof), c in table.curves.items():
        if dof == a and p in POINTS:  # transmissibility (the apparent masses are in the CSV too)
            f_pk, g_pk = c.peak((0.5, 12.0))
            peaks[f"{a}->{p}"] = {"peak_hz": f_pk, "peak_gain": g_pk, "gain_at_0.5_hz": c.at(0.5)}
    write_json_atomic(out / "demo_summary.json", {"runs": summaries, "transmissibility_peaks": peaks})
    return peaks


def cmd_frf(args) -> int:
    from .frf import linear_frf, time_domain_frf

    band = _band(args.band)
    check_output_file(args.out, "FRF table")
    human = _human(args)
    if args.motion and args.method == "linear":
        raise InputError("--motion: a measured seat motion needs the time method (--method time).")
    if args.method == "linear":
        if not (np.isfinite(args.df) and args.df > 0) or (band[1] - band[0]) / args.df > 1e5:
            raise InputError(f"--df {args.df:g}: the frequency step must be positive and give at most 100000 "
                             "frequencies in the band.")
        table = linear_frf(human, args.axis, freq_hz=np.arange(band[0], band[1] + 1e-9, args.df))
    else:
        table = time_domain_frf(human, args.axis, duration_s=args.duration, rms_mps2=args.rms, seed=args.seed,
                                band_hz=band, route=args.route, motion=_read_motion_file(args) if args.motion else None)
    table.write(args.out)  # CSV, or Parquet for a .parquet name
    print(f"wrote {args.out}: {len(table.curves)} curves ({args.method} method)")
    return 0


def cmd_compare(args) -> int:
    from .criterion import compare
    from .frf import read_frf

    result = compare(read_frf(args.data), read_frf(args.frf), _band(args.band), keep_small=args.keep_small_curves)
    if args.json:
        print(json.dumps(result.as_dict(), indent=2))
    else:
        for c in result.curves:
            print(f"seat {c.input_axis} -> {c.point:<6} {c.dof:<5} crit {c.crit:.5g} ({c.n_freq} frequencies)")
        print(f"total criterion {result.total:.5g}")
    return 0


def cmd_fit(args) -> int:
    from .fit import fit, print_progress, write_identified
    from .frf import read_frf

    if _size(args) is not None:
        raise InputError("--stature/--mass/--sitting-height: ehm fit identifies the reference person's parameters; "
                         "fit without them (body sizes scale a parameter file when it is used).")
    check_output_file(args.out, "parameter file")
    refuse_defaults(args.out)
    band = _band(args.band)
    data = read_frf(args.data)
    params = Parameters.load(args.params)
    body = load_body(args.segments, args.joints, args.contacts)
    if args.workers is not None and args.workers < 1:
        raise InputError(f"--workers {args.workers}: use 1 or more processes.")
    result = fit(data, params=params, free=args.free, lock=_joint_list(args.lock), unlock=_joint_list(args.unlock),
                 body=body, band_hz=band, max_evals=args.max_evals, workers=args.workers,
                 time_check=not args.no_time_check, progress=print_progress,
                 keep_small_curves=args.keep_small_curves)
    written = result.moved and result.crit_after < result.crit_before
    if written:
        write_identified(result, args.data, args.out)
    print(f"criterion {result.crit_before:.5g} -> {result.crit_after:.5g} (linear model)"
          + (f", {result.crit_before_time:.5g} -> {result.crit_after_time:.5g} (time-domain check)"
             if result.crit_after_time is not None else "")
          + f"; {result.n_eval} of {result.max_evals} evaluations in {result.wall_s:.0f} s; {result.message}")
    for p in result.free:
        print(f"  {p}: {result.start[p]:.5g} -> {result.final[p]:.5g} ({_fit_state(result, p)})")
    print(f"wrote {args.out}" if written else f"no parameter file written ({args.out} left as it was)")
    if not result.identified:
        _end_progress_line()
        print(f"ehm: fit: {result.verdict}", file=sys.stderr)
        return EXIT_NOT_IDENTIFIED
    return 0


def _fit_state(result, path: str) -> str:
    """How one free value of a fit ended, in a few words."""
    side = next((f"at its {s} bound" for p, s, _ in result.at_bound if p == path), None)
    if side is not None:
        return side
    return ("identified" if path in result.identified else "moved, not identified" if path in result.moved
            else "not moved")


def cmd_plot_frf(args) -> int:
    from .frf import AXES, read_frf
    from .plotting import plot_frf_grid

    check_output_file(args.out, "figure")
    tables = []
    for path in args.frf:
        t = read_frf(path)
        tables.append((Path(path).stem, t.__class__(t.curves, method="model")))
    if args.data:
        tables.append(("measured", read_frf(args.data)))
    axes = [a for a in AXES if any(k[0] == a for _, t in tables for k in t.curves)]
    out = Path(args.out)
    written = []
    for a in axes:
        path = out if len(axes) == 1 else out.with_name(f"{out.stem}_{a}{out.suffix}")
        plot_frf_grid(tables, a, path)
        written.append(str(path))
    print("wrote " + ", ".join(written))
    return 0


def cmd_study_locking(args) -> int:
    from .study import PAPER_VARIANTS, locking_study, parse_variant

    variants = dict(PAPER_VARIANTS)
    for v in args.variant or []:
        name, joints = parse_variant(v)
        variants[name] = joints
    band = _band(args.band)
    params = Parameters.load(args.params)
    final = check_output_folder(args.out)
    study = locking_study(params=params, variants=variants, method=args.method, band_hz=band,
                          duration_s=args.duration, progress=print)
    with RunFolder(final) as out:
        findings = _write_locking_study(study, variants, out)
    print("findings (baseline -> variant, or change from baseline):")
    for k, v in findings.items():
        if isinstance(v, list):
            print(f"  {k}: {v[0]:.2f} -> {v[1]:.2f}")
        else:
            print(f"  {k}: peak {v['peak_gain_change_pct']:+.0f} %, mean over "
                  f"{study.band_hz[0]:g}-{study.band_hz[1]:g} Hz {v['band_mean_gain_change_pct']:+.0f} %")
    print(f"wrote {final}/locking.csv, locking.json, locking.png and frf_<variant>.csv")
    return 0


def _write_locking_study(study, variants: dict, out: Path) -> dict:
    """The locking study's tables and figure, written into ``out``; returns its findings."""
    from .io import write_text_atomic
    from .plotting import plot_locking_study

    header = ["variant", "locked", "input_axis", "point", "dof", "peak_hz", "peak_gain", "band_mean_gain",
              "peak_hz_change_pct", "peak_gain_change_pct", "band_mean_change_pct"]
    lines = [",".join(header)]
    for r in study.rows:
        lines.append(",".join([r.variant, "+".join(r.locked), r.input_axis, r.point, r.dof]
                              + [f"{v:.6g}" for v in (r.peak_hz, r.peak_gain, r.band_mean_gain, r.peak_hz_change_pct,
                                                     r.peak_gain_change_pct, r.band_mean_change_pct)]))
    write_text_atomic(out / "locking.csv", "\n".join(lines) + "\n")
    findings = study.findings()
    write_json_atomic(out / "locking.json", {"method": study.method, "band_hz": list(study.band_hz),
                                             "variants": {k: list(v) for k, v in variants.items()},
                                             "findings": findings})
    for name, table in study.tables.items():
        table.to_csv(out / f"frf_{name}.csv")
    plot_locking_study(study, out / "locking.png")
    return findings


_OPEN_LINE = {"open": False}  #: Whether a progress line on stderr waits for its end.


def _progress_line(text: str, last: bool) -> None:
    """Rewrite the progress line on stderr; ``last`` ends it."""
    print(f"\r{text}", end="\n" if last else "", file=sys.stderr, flush=True)
    _OPEN_LINE["open"] = not last


def _end_progress_line() -> None:
    """End an unfinished progress line, so that what follows starts a line of its own."""
    if _OPEN_LINE["open"]:
        print(file=sys.stderr, flush=True)
        _OPEN_LINE["open"] = False


def _progress_bar(label: str):
    finished = []

    def show(done_s: float, total_s: float) -> None:
        if finished:
            return
        frac = min(1.0, done_s / total_s) if total_s > 0 else 1.0
        bar = "#" * int(30 * frac)
        _progress_line(f"{label} [{bar:<30}] {done_s:6.0f} / {total_s:.0f} s", frac >= 1.0)
        if frac >= 1.0:
            finished.append(True)
    return show


def cmd_assess(args) -> int:
    from .assessment import assess
    from .plotting import plot_running_rms, plot_sickness, plot_weighted_spectra
    from .report import write_report

    final = check_output_folder(args.out)
    motion = _read_motion_file(args)
    human = _human(args, rotating_seat=motion.angvel_radps is not None and args.method != "linear")
    params = human.params
    result = assess(motion, human, progress=_progress_bar("assess"), method=args.method)
    summary = result.summary()
    summary["params"] = params.origin
    summary["locked"] = sorted(human.locked)
    if human.size is not None:
        summary["scaled"] = human.params.data["about"].get("scaled", "")
    with RunFolder(final) as out:
        write_json_atomic(out / "assessment.json", summary)
        figures = {"spectra": out / "weighted_spectra.png", "running_rms": out / "running_rms.png",
                   "sickness": out / "sickness.png"}
        plot_weighted_spectra(result, figures["spectra"])
        plot_running_rms(result, figures["running_rms"])
        plot_sickness(result, figures["sickness"])
        write_report(summary, figures, out / "report.html")
    out = final
    loc = summary["locations"]
    print(f"{result.duration_s:.0f} s of '{result.description}' in {result.wall_s:.0f} s")
    for name in ("seat", "pelvis", "trunk", "head"):
        v = loc[name]
        print(f"  {name:<7} a_v {v['total_value_mps2']:.3f} m/s^2 ({v['comfort_reaction']}), "
              f"MSDV_z {v['msdv_z_mps15']:.3f} m/s^1.5")
    print(f"  motion sickness incidence at the end: head {summary['sickness']['head']['final_msi_percent']:.2f} %, "
          f"head fixed to the seat {summary['sickness']['seat']['final_msi_percent']:.2f} %")
    print(f"wrote {out}/assessment.json, report.html, weighted_spectra.png, running_rms.png, sickness.png")
    return 0


def cmd_realtime(args) -> int:
    from .stepping import Simulator, run_realtime

    motion = _read_motion_file(args)
    if motion.angvel_radps is not None and np.any(motion.angvel_radps != 0):
        if not args.ignore_rotation:
            raise InputError(f"{args.motion} rotates the seat; real-time stepping supports seat translation only "
                             "(use --ignore-rotation to drop the rotation, or 'ehm assess' for the whole drive).")
    if args.duration is not None and not (np.isfinite(args.duration) and args.duration > 0):
        raise InputError(f"--duration {args.duration}: give a positive number of seconds.")
    params = Parameters.load(args.params)
    sim = Simulator(params=params, lock=_joint_list(args.lock), unlock=_joint_list(args.unlock),
                    comfort=not args.no_comfort, body=load_body(args.segments, args.joints, args.contacts),
                    size=_size(args))
    m = motion.resample(sim.dt_s)
    acc = m.acc_mps2 if args.duration is None else m.acc_mps2[: int(round(args.duration / sim.dt_s)) + 1]
    print(f"real-time run of {acc.shape[0] * sim.dt_s:.1f} s of '{motion.description}', one {sim.dt_s * 1000:g} ms "
          f"step per {sim.dt_s * 1000:g} ms of wall clock" + ("" if not args.no_pace else " (not paced)"))
    last = {}
    report = run_realtime(sim, acc, pace=not args.no_pace, on_step=lambda s: last.update(state=s))
    print(f"step latency: median {report.median_s * 1e6:.0f} us, 99th percentile {report.p99_s * 1e6:.0f} us, "
          f"worst {report.worst_s * 1e6:.0f} us; overruns {report.overruns} of {report.n_steps} steps; "
          f"wall {report.wall_s:.1f} s")
    if last and last["state"].comfort:
        c = last["state"].comfort
        print("running a_w so far [m/s^2]: " + ", ".join(
            f"{loc} z {c[loc]['z'][1]:.3f}" for loc in ("seat", "pelvis", "trunk", "head")))
    return 0


def cmd_batch(args) -> int:
    try:
        from .batch import check_scheduler, load_study, run_study
        import dask.distributed  # noqa: F401
        import pyarrow  # noqa: F401
    except ImportError:
        raise InputError("batch studies need Dask and pyarrow: pip install 'ehm[batch]'.") from None
    if args.workers is not None and args.workers < 1:
        raise InputError(f"--workers {args.workers}: use 1 or more worker processes.")
    scheduler = check_scheduler(args.scheduler) if args.scheduler else None
    name, specs = load_study(args.study)
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise InputError(f"{out} is a file; give a folder for the study's results.")
    check_output_file(out / "results.parquet", "results table")
    print(f"study '{name}': {len(specs)} runs" + (f" on {scheduler}" if scheduler else ""))

    def show(done, total):
        _progress_line(f"  {done} / {total} runs done", done == total)

    with folder_kept_tidy(out):
        res = run_study(specs, out, scheduler=scheduler, workers=args.workers, csv=args.csv, progress=show,
                        retry_failed=args.retry_failed)
    if res["ran"] and res["failed"] == res["ran"]:
        raise InputError(f"all {res['ran']} runs failed; their errors are in {out}/results.parquet (output 'error').")
    tp = res["throughput_simulated_s_per_s"]
    changed = res["changed"]
    print(f"ran {res['ran']} runs ({res['skipped']} already done, "
          + (f"{changed['count']} rerun because an input changed ({', '.join(changed['inputs'])}), "
             if changed["count"] else "")
          + f"{res['failed']} failed) in {res['wall_s']:.1f} s"
          + (f"; {tp:.1f} simulated s per wall s" if tp else "") + f"; wrote {out}/results.parquet"
          + (" and results.csv" if args.csv else ""))
    return 0


def cmd_drive(args) -> int:
    from .drives import city_drive, rough_road, write_drive_csv

    check_output_file(args.out, "drive file")
    motion = (city_drive(args.duration, seed=args.seed) if args.kind == "city"
              else rough_road(args.duration, speed_mps=args.speed, road_class=args.road_class, seed=args.seed))
    write_drive_csv(motion, args.out)
    print(f"wrote {args.out}: {motion.description}")
    return 0


def cmd_export_fmu(args) -> int:
    import time

    t0 = time.perf_counter()
    if args.python:
        from .fmu import INPUTS, OUTPUTS, export_fmu

        extra = [o for o, v in (("--segments", args.segments), ("--joints", args.joints), ("--contacts", args.contacts),
                                ("--stature", args.stature), ("--mass", args.mass),
                                ("--sitting-height", args.sitting_height), ("--dt", args.dt),
                                ("--rotating-seat", args.rotating_seat or None)) if v is not None]
        if extra:
            raise InputError(f"export-fmu --python takes only --params, --lock and --unlock, not {', '.join(extra)}; "
                             "export the native unit (without --python) for these.")
        path = export_fmu(args.out, params=args.params, lock=_joint_list(args.lock), unlock=_joint_list(args.unlock),
                          python=True)
        print(f"wrote {path} in {time.perf_counter() - t0:.1f} s: FMI 2.0 co-simulation unit (pythonfmu), "
              f"{len(INPUTS)} inputs ({', '.join(INPUTS[:3])}; seat angular velocity must stay 0), "
              f"{len(OUTPUTS)} outputs (pelvis, trunk, head); the host's Python must be able to import ehm")
        return 0
    from .fmu_native import INPUTS, OUTPUTS, PLATFORM, export_native_fmu

    human = _human(args, rotating_seat=args.rotating_seat)
    path = export_native_fmu(args.out, human)
    turning = "the seat turns with them" if args.rotating_seat else "seat angular velocity must stay 0"
    print(f"wrote {path} in {time.perf_counter() - t0:.1f} s: FMI 2.0 co-simulation unit (native C on MuJoCo, "
          f"{PLATFORM}), {human.mass_kg:.1f} kg, {human.dof} degrees of freedom, model step "
          f"{human.model.mj.opt.timestep * 1000:g} ms; {len(INPUTS)} inputs (seat acceleration and angular velocity; "
          f"{turning}), {len(OUTPUTS)} outputs (pelvis, trunk, head, support forces); no Python needed to run it")
    return 0


def cmd_animate(args) -> int:
    import time

    from .animation import animate

    check_output_file(args.out, "animation")
    t0 = time.perf_counter()
    path = animate(args.run_dir, args.out, exaggerate=args.exaggerate, fps=args.fps, start_s=args.start,
                   end_s=args.end, max_frames=args.max_frames)
    print(f"wrote {path} in {time.perf_counter() - t0:.1f} s (motion x{args.exaggerate:g})")
    return 0


def cmd_check_step(args) -> int:
    from .convergence import TOLERANCE, check_step

    if args.dt is not None and not args.dt > 0:
        raise InputError(f"--dt must be a positive time step in seconds, not {args.dt}.")
    body_args = (args.segments, args.joints, args.contacts)
    if any(body_args):
        raise InputError("check-step uses the shipped body tables; --segments, --joints and --contacts are not "
                         "supported here.")
    check = check_step(args.params, dt_s=args.dt, lock=_joint_list(args.lock), unlock=_joint_list(args.unlock),
                       size=_size(args), ratios=args.ratio)
    rows = check.rows()
    ratios = sorted(check.errors, reverse=True)
    if args.json:
        print(json.dumps({"dt_s": check.dt_s, "tolerance_pct": 100 * TOLERANCE, "paths": rows,
                          "worst": {f"step_over_{r}": {"path": list(check.worst(r)[0]),
                                                       "error_pct": 100 * check.worst(r)[1]} for r in ratios}},
                         indent=1))
        return 0
    head = "".join(f"  vs dt/{r:<3d}" for r in ratios)
    print(f"time step {check.dt_s * 1e3:g} ms; error = largest |gain difference| / peak gain, 0.2-12 Hz")
    print(f"{'path':<24s}{'peak':>14s}{head}")
    for row in rows:
        path = f"seat {row['input_axis']} -> {row['point']} {row['dof']}"
        errs = "".join(f"  {row[f'error_vs_step_over_{r}_pct']:6.2f} %  " for r in ratios)
        print(f"{path:<24s}{row['peak_gain']:7.3g} @{row['peak_hz']:5.2f}{errs}")
    (k, e) = check.worst(ratios[0])
    verdict = "converged" if e <= TOLERANCE else "NOT converged"
    print(f"worst: seat {k[0]} -> {k[1]} {k[2]}, {100 * e:.2f} % against dt/{ratios[0]}: {verdict} "
          f"(tolerance {100 * TOLERANCE:g} %)")
    return 0


def cmd_params(args) -> int:
    params = Parameters.load(args.params)
    if args.export:
        params.export(args.export)
        print(f"wrote {args.export}")
    else:
        sys.stdout.write(params.to_toml())
    return 0


_KEEP_SMALL_HELP = ("keep measured curves whose peak is below 10 %% of the largest of their kind for the same seat "
                    "axis (left out of the criterion, with a warning listing them, by default)")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="ehm", description="Efficient seated human model on MuJoCo.")
    parser.add_argument("--version", action="version", version=f"ehm {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("info", help="describe the model (segments, joints, degrees of freedom)")
    _model_options(p)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=cmd_info)

    p = sub.add_parser("simulate", help="run the model with a seat motion and write timeseries.csv, summary.json")
    _model_options(p)
    _excitation_options(p, 35.0)
    p.add_argument("--axis", default="z", help="excited seat axes: x, y, z or a combination (default z)")
    p.add_argument("--signal", choices=("random", "sine", "sweep"), default="random", help="generated input (default random)")
    p.add_argument("--amplitude", type=float, default=0.5, help="sine or sweep peak acceleration [m/s^2]")
    p.add_argument("--freq", type=float, default=4.0, help="sine frequency [Hz]")
    p.add_argument("--f0", type=float, default=0.5, help="sweep start frequency [Hz]")
    p.add_argument("--f1", type=float, default=12.0, help="sweep end frequency [Hz]")
    _motion_file_options(p, False, "seat motion file (.csv/.txt, .parquet, .mat, .mf4, or city / road): time_s, "
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
    p.add_argument("--method", choices=("nonlinear", "linear"), default="nonlinear",
                   help="simulation route: nonlinear (MuJoCo, default) or linear (the linearised person: about 1000x "
                        "faster, translation only, refuses inputs that make a contact lift off or slide)")
    p.set_defaults(func=cmd_simulate)

    p = sub.add_parser("demo", help="x, y and z random vibration of the default model, with plots")
    _model_options(p)
    _excitation_options(p, 60.0)
    p.add_argument("--axes", nargs="+", default=["x", "y", "z"], choices=("x", "y", "z"))
    p.add_argument("--out", default="ehm-demo", metavar="DIR", help="output folder (default ehm-demo)")
    p.set_defaults(func=cmd_demo)

    p = sub.add_parser("frf", help="seat-to-body frequency responses (time-domain H1 or linearised model)")
    _model_options(p)
    _excitation_options(p, 60.0)
    p.add_argument("--axis", default="all", choices=("x", "y", "z", "all"), help="input axis (default all)")
    p.add_argument("--method", default="linear", choices=("time", "linear"), help="estimation route (default linear)")
    p.add_argument("--df", type=float, default=0.05, help="frequency step of the linear method [Hz] (default 0.05)")
    p.add_argument("--route", choices=("nonlinear", "linear"), default="nonlinear",
                   help="simulation route of the time method's runs (default nonlinear)")
    _motion_file_options(p, False, "time method: run the model with this measured seat motion instead of random "
                                   "vibration (H1 per excited seat axis)")
    p.add_argument("--out", required=True, metavar="FRF.csv|FRF.parquet")
    p.set_defaults(func=cmd_frf)

    p = sub.add_parser("compare", help="the paper's criterion (Eqs. 2-3) of measured gains against model gains")
    p.add_argument("--data", required=True, metavar="EXP.csv", help="measured gains (long format)")
    p.add_argument("--frf", required=True, metavar="MODEL.csv", help="model gains from 'ehm frf' (.csv or .parquet)")
    p.add_argument("--band", type=float, nargs=2, default=(0.1, 12.0), metavar=("LOW_HZ", "HIGH_HZ"))
    p.add_argument("--keep-small-curves", action="store_true", help=_KEEP_SMALL_HELP)
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_compare)

    p = sub.add_parser("fit", help="identify parameters from measured gains (writes a new parameter file)")
    _model_options(p)
    p.add_argument("--data", required=True, metavar="EXP.csv", help="measured gains (long format)")
    p.add_argument("--free", nargs="+", metavar="PATTERN",
                   help="parameters to fit, glob patterns of dotted names (default: neck and spine joints)")
    p.add_argument("--band", type=float, nargs=2, default=(0.1, 12.0), metavar=("LOW_HZ", "HIGH_HZ"))
    p.add_argument("--max-evals", type=int, default=400,
                   help="most linearised-model evaluations, finite differences included (default 400); exit "
                        "status 3 when the fit stops on it")
    p.add_argument("--workers", type=int, help="processes for the finite differences (default: 2 or the cores)")
    p.add_argument("--no-time-check", action="store_true", help="skip the time-domain check of the result")
    p.add_argument("--keep-small-curves", action="store_true", help=_KEEP_SMALL_HELP)
    p.add_argument("--out", required=True, metavar="FITTED.toml",
                   help="parameter file to write when the fit lowered the criterion; exit status 3 when it is not "
                        "identified (a value that ended on its search bound is written with grade 'at bound')")
    p.set_defaults(func=cmd_fit)

    p = sub.add_parser("plot-frf", help="plot gains: one grid per input axis, model lines and measured markers")
    p.add_argument("frf", nargs="+", metavar="FRF.csv")
    p.add_argument("--data", metavar="EXP.csv")
    p.add_argument("--out", required=True, metavar="FIG.png")
    p.set_defaults(func=cmd_plot_frf)

    p = sub.add_parser("study", help="studies: 'locking' (the paper's joint-locking study)")
    ssub = p.add_subparsers(dest="study", required=True)
    q = ssub.add_parser("locking", help="baseline, spine locked (SL), neck locked (NL) and named variants")
    q.add_argument("--params", metavar="FILE.toml")
    q.add_argument("--variant", action="append", metavar="NAME=J1,J2", help="another variant to run")
    q.add_argument("--method", default="linear", choices=("linear", "time"))
    q.add_argument("--band", type=float, nargs=2, default=(0.5, 4.0), metavar=("LOW_HZ", "HIGH_HZ"),
                   help="band of the mean-gain comparison (default 0.5 4)")
    q.add_argument("--duration", type=float, default=60.0, help="run length per axis of the time method [s]")
    q.add_argument("--out", required=True, metavar="DIR")
    q.set_defaults(func=cmd_study_locking)

    p = sub.add_parser("assess", help="comfort (ISO 2631-1) and motion sickness of a drive, at the seat and the body")
    _model_options(p)
    _motion_file_options(p, True, "drive file (.csv/.txt, .parquet, .mat, .mf4: time_s, ax_mps2, ay_mps2, az_mps2 "
                                  "[, wx_radps, wy_radps, wz_radps] unless --channel says) or 'city' / 'road' for the "
                                  "shipped SYNTHETIC drives")
    p.add_argument("--out", required=True, metavar="DIR")
    p.add_argument("--method", choices=("nonlinear", "linear"), default="nonlinear",
                   help="simulation route (default nonlinear; linear: translation only, small inputs)")
    p.set_defaults(func=cmd_assess)

    p = sub.add_parser("realtime", help="step the model paced to the wall clock; report per-step latency")
    _model_options(p)
    _motion_file_options(p, True, "seat motion file (.csv/.txt, .parquet, .mat, .mf4), or city / road")
    p.add_argument("--duration", type=float, help="run only this many seconds of the motion")
    p.add_argument("--no-pace", action="store_true", help="run as fast as possible (latency figures only)")
    p.add_argument("--no-comfort", action="store_true", help="skip the running comfort figures")
    p.add_argument("--ignore-rotation", action="store_true", help="drop the drive's angular velocity")
    p.set_defaults(func=cmd_realtime)

    p = sub.add_parser("batch", help="run a study file (people, seats, parameters) on Dask; one tidy table")
    p.add_argument("study", metavar="STUDY.toml")
    p.add_argument("--out", required=True, metavar="DIR")
    p.add_argument("--scheduler", metavar="tcp://HOST:PORT", help="an existing Dask scheduler (default: local)")
    p.add_argument("--workers", type=int, help="local worker processes (default: the number of cores)")
    p.add_argument("--csv", action="store_true", help="also write results.csv")
    p.add_argument("--retry-failed", action="store_true",
                   help="when resuming, run the recorded failures again too (lost workers are always retried)")
    p.set_defaults(func=cmd_batch)

    p = sub.add_parser("drive", help="write a SYNTHETIC drive file (city manoeuvres or a rough road)")
    p.add_argument("kind", choices=("city", "road"))
    p.add_argument("--duration", type=float, default=120.0, help="length [s] (default 120)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--speed", type=float, default=15.0, help="road: vehicle speed [m/s] (default 15)")
    p.add_argument("--road-class", default="C", choices=("A", "B", "C", "D", "E"), help="road: ISO 8608 class")
    p.add_argument("--out", required=True, metavar="DRIVE.csv")
    p.set_defaults(func=cmd_drive)

    p = sub.add_parser("export-fmu", help="write an FMI 2.0 co-simulation unit (FMU) of the person for vehicle tools")
    p.add_argument("--out", required=True, metavar="FILE.fmu", help="FMU file to write")
    _model_options(p)
    p.add_argument("--dt", type=float, help="model step [s] (default from the parameter file)")
    p.add_argument("--python", action="store_true",
                   help="build the older pythonfmu unit (its host must run ehm in Python) instead of the native one")
    p.add_argument("--rotating-seat", action="store_true",
                   help="a seat that turns with the unit's angular velocity inputs (native unit; steps cost ~1.5x)")
    p.set_defaults(func=cmd_export_fmu)

    p = sub.add_parser("animate", help="draw a run's person and seat into a .gif or .mp4 (offscreen, no display)")
    p.add_argument("run_dir", metavar="RUN_DIR", help="run folder with poses.npz (from 'ehm simulate --out RUN_DIR')")
    p.add_argument("--out", required=True, metavar="FILE.gif|FILE.mp4", help="animation file (.mp4 needs ehm[animate])")
    p.add_argument("--exaggerate", type=float, default=1.0, metavar="F",
                   help="scale the motion from the settled posture by F (default 1: true scale)")
    p.add_argument("--fps", type=float, default=25.0, help="frames per second (default 25; poses are stored at 25 Hz)")
    p.add_argument("--start", type=float, metavar="S", help="first time drawn [s] (default: the start)")
    p.add_argument("--end", type=float, metavar="S", help="last time drawn [s] (default: the end)")
    p.add_argument("--max-frames", type=int, metavar="N", help="stop after N frames")
    p.set_defaults(func=cmd_animate)

    p = sub.add_parser("check-step", help="transfer functions at a time step against the same model at finer steps")
    _model_options(p)
    p.add_argument("--dt", type=float, help="time step to check [s] (default from the parameter file: 0.001)")
    p.add_argument("--ratio", type=int, nargs="+", default=[8, 4], help="finer steps as divisors (default: 8 4)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=cmd_check_step)

    p = sub.add_parser("params", help="print or export the parameter file")
    p.add_argument("--params", metavar="FILE.toml", help="parameter file to read (default: the shipped defaults)")
    p.add_argument("--export", metavar="FILE.toml", help="write it to a file")
    p.set_defaults(func=cmd_params)
    return parser


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Warnings as one sentence on stderr, without the source line."""
    print(f"ehm: warning: {message}", file=sys.stderr if file is None else file)


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that every clean-up (temporary files, staging folders) runs."""


def _on_sigterm(signum, frame):
    raise Terminated()


def main(argv: list[str] | None = None) -> int:
    """Run the ``ehm`` command; returns the exit code."""
    import warnings

    parser = build_parser()
    args = parser.parse_args(argv)
    warnings.showwarning = _show_warning
    import signal
    import threading

    import shlex

    from .outdir import set_command

    previous = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _on_sigterm)
    set_command(shlex.join(["ehm", *(sys.argv[1:] if argv is None else argv)]))
    try:
        return args.func(args)
    except EhmError as exc:
        _end_progress_line()
        print(f"ehm: error: {exc}", file=sys.stderr)
        return EXIT_ERROR
    except MemoryError:
        _end_progress_line()
        print("ehm: error: out of memory; ehm simulate and ehm assess stream long drives in bounded memory, other "
              "commands hold their whole run: shorten --duration or use a machine with more memory.", file=sys.stderr)
        return EXIT_ERROR
    except OSError as exc:  # a failure of the system that no command foresaw (a full disk, a removed folder)
        _end_progress_line()
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"ehm: error: {where}{exc.strerror or exc} (check the disk and the folder, then "
              "run the command again).", file=sys.stderr)
        return EXIT_ERROR
    except Terminated:
        _end_progress_line()
        print("ehm: terminated", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        _end_progress_line()
        print("ehm: interrupted", file=sys.stderr)
        return 130
    finally:
        set_command(None)
        _end_progress_line()
        _report_mujoco_warnings()
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _report_mujoco_warnings() -> None:
    """MuJoCo's warnings that did not end a run (those that did are in the error sentence), one line each."""
    from .engine import take_warnings

    for text in dict.fromkeys(take_warnings()):
        print(f"ehm: note: MuJoCo warned: {text}", file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main())
