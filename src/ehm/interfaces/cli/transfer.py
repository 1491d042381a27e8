"""Transfer-function commands: frf, compare, fit, plot-frf, check-step, the locking study and validate."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from ...body.params import refuse_defaults
from ...body.tables import load_body
from ...body.timestep import check_time_step
from ...errors import InputError
from ...files import write_json_atomic
from ...outputs.outdir import RunFolder, check_output_file, check_output_folder
from .common import (
    checked_band,
    human_from_args,
    input_files,
    joint_list,
    params_from_args,
    person_from_args,
    read_motion_file,
    size_from_args,
)
from .options import (
    KEEP_SMALL_HELP,
    excitation_options,
    model_options,
    motion_file_options,
    progress_options,
    seating_options,
    size_options,
)
from .progress import end_progress_line, progress_count

#: ehm validate: the person was evaluated, and some check does not pass.
EXIT_CHECKS_FAILED = 1
#: ehm fit: stopped on its budget, did not lower the criterion, its check disagreed, or a value ended on its
#: search bound (then the file is still written, that value graded "at bound").
EXIT_NOT_IDENTIFIED = 3


# --- ehm frf --------------------------------------------------------------------------------------------------------

def add_frf(sub) -> None:
    p = sub.add_parser("frf", help="seat-to-body frequency responses (time-domain H1 or linearised model)")
    model_options(p)
    excitation_options(p, 60.0)
    p.add_argument("--axis", default="all", choices=("x", "y", "z", "all"), help="input axis (default all)")
    p.add_argument("--method", default="linear", choices=("time", "linear"), help="estimation route (default linear)")
    p.add_argument("--df", type=float, default=0.05, help="frequency step of the linear method [Hz] (default 0.05)")
    p.add_argument("--route", choices=("nonlinear", "linear"), default="nonlinear",
                   help="simulation route of the time method's runs (default nonlinear)")
    motion_file_options(p, False, "time method: run the model with this measured seat motion instead of random "
                                   "vibration (H1 per excited seat axis)")
    p.add_argument("--out", required=True, metavar="FRF.csv|FRF.parquet")
    p.set_defaults(func=cmd_frf)


def _linear_frequencies(df: float, band: tuple[float, float]) -> np.ndarray:
    """The linear method's frequencies: the band in steps of --df."""
    if not (np.isfinite(df) and df > 0) or (band[1] - band[0]) / df > 1e5:
        raise InputError(f"--df {df:g}: the frequency step must be positive and give at most 100000 "
                         "frequencies in the band.")
    return np.arange(band[0], band[1] + 1e-9, df)


def cmd_frf(args) -> int:
    from ...analysis.frf import linear_frf, time_domain_frf

    band = checked_band(args.band)
    check_output_file(args.out, "FRF table")
    human = human_from_args(args)
    if args.motion and args.method == "linear":
        raise InputError("--motion: a measured seat motion needs the time method (--method time).")
    if args.method == "linear":
        table = linear_frf(human, args.axis, freq_hz=_linear_frequencies(args.df, band))
    else:
        table = time_domain_frf(human, args.axis, duration_s=args.duration, rms_mps2=args.rms, seed=args.seed,
                                band_hz=band, route=args.route, motion=read_motion_file(args) if args.motion else None)
    table.write(args.out)  # CSV, or Parquet for a .parquet name
    _print_frf_peaks(table)
    print(f"wrote {args.out}: {len(table.curves)} curves ({args.method} method; the person recorded in the file)")
    return 0


def _print_frf_peaks(table) -> None:
    """The peak of every path along its input axis: what a table is usually read for."""
    peaks = table.peaks()
    if not peaks:
        return
    print(f"peaks along each input axis ({table.meta.get('person_description', 'the person')}):")
    for (axis, point, _), f, g, unit in peaks:
        what = f"apparent mass ({'all supports' if point == 'support' else 'seat pan'})" if unit == "kg" else point
        print(f"  seat {axis} -> {what:<28} {g:8.3g} {unit} at {f:5.2f} Hz")


# --- ehm compare ----------------------------------------------------------------------------------------------------

def add_compare(sub) -> None:
    p = sub.add_parser("compare", help="the paper's criterion (Eqs. 2-3) of measured gains against model gains")
    p.add_argument("--data", required=True, metavar="EXP.csv", help="measured gains (long format)")
    p.add_argument("--frf", required=True, metavar="MODEL.csv", help="model gains from 'ehm frf' (.csv or .parquet)")
    p.add_argument("--band", type=float, nargs=2, default=(0.1, 12.0), metavar=("LOW_HZ", "HIGH_HZ"),
                   help="frequency band of the criterion (default 0.1 12)")
    p.add_argument("--keep-small-curves", action="store_true", help=KEEP_SMALL_HELP)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=cmd_compare)


def cmd_compare(args) -> int:
    from ...analysis.criterion import compare
    from ...analysis.frf import read_frf

    result = compare(read_frf(args.data), read_frf(args.frf), checked_band(args.band),
                     keep_small=args.keep_small_curves)
    if args.json:
        print(json.dumps(result.as_dict(), indent=2))
    else:
        for c in result.curves:
            print(f"seat {c.input_axis} -> {c.point:<6} {c.dof:<5} crit {c.crit:.5g} ({c.n_freq} frequencies)")
        print(f"total criterion {result.total:.5g}")
    return 0


# --- ehm fit --------------------------------------------------------------------------------------------------------

def add_fit(sub) -> None:
    p = sub.add_parser("fit", help="identify parameters from measured gains (writes a new parameter file)")
    model_options(p)
    p.add_argument("--data", required=True, metavar="EXP.csv", help="measured gains (long format)")
    p.add_argument("--free", nargs="+", metavar="PATTERN",
                   help="parameters to fit, glob patterns of dotted names (default: neck and spine joints)")
    p.add_argument("--band", type=float, nargs=2, default=(0.1, 12.0), metavar=("LOW_HZ", "HIGH_HZ"),
                   help="frequency band of the criterion (default 0.1 12)")
    p.add_argument("--max-evals", type=int, default=400,
                   help="most linearised-model evaluations, finite differences included (default 400); exit "
                        "status 3 when the fit stops on it")
    p.add_argument("--workers", type=int, help="processes for the finite differences (default: 2 or the cores)")
    p.add_argument("--no-time-check", action="store_true", help="skip the time-domain check of the result")
    p.add_argument("--keep-small-curves", action="store_true", help=KEEP_SMALL_HELP)
    p.add_argument("--out", required=True, metavar="FITTED.toml",
                   help="parameter file to write when the fit lowered the criterion; exit status 3 when it is not "
                        "identified (a value that ended on its search bound is written with grade 'at bound')")
    progress_options(p)
    p.set_defaults(func=cmd_fit)


def _fit_inputs(args):
    """The checked inputs of a fit, in the order their problems are reported: band, measured gains, parameters, body."""
    from ...analysis.frf import read_frf

    if size_from_args(args) is not None:
        raise InputError("--stature/--mass/--sitting-height: ehm fit identifies the reference person's parameters; "
                         "fit without them (body sizes scale a parameter file when it is used).")
    if getattr(args, "vibration_rms", None) is not None:
        raise InputError("--vibration-rms: ehm fit identifies the parameters at the parameter file's reference level "
                         "([level] reference_rms_mps2); fit without it, with measurements taken near that level.")
    check_output_file(args.out, "parameter file")
    refuse_defaults(args.out)
    band = checked_band(args.band)
    data = read_frf(args.data)
    params = params_from_args(args)
    body = load_body(args.segments, args.joints, args.contacts)
    if args.workers is not None and args.workers < 1:
        raise InputError(f"--workers {args.workers}: use 1 or more processes.")
    return band, data, params, body


def cmd_fit(args) -> int:
    from ...analysis.fit import fit, print_progress, write_identified

    band, data, params, body = _fit_inputs(args)
    result = fit(data, params=params, free=args.free, lock=joint_list(args.lock), unlock=joint_list(args.unlock),
                 body=body, band_hz=band, max_evals=args.max_evals, workers=args.workers,
                 time_check=not args.no_time_check, progress=None if args.quiet else print_progress,
                 keep_small_curves=args.keep_small_curves)
    written = result.moved and result.crit_after < result.crit_before
    if written:
        write_identified(result, args.data, args.out)
    _print_fit(result)
    print(f"wrote {args.out}" if written else f"no parameter file written ({args.out} left as it was)")
    if not result.identified:
        end_progress_line()
        print(f"ehm: fit: {result.verdict}", file=sys.stderr)
        return EXIT_NOT_IDENTIFIED
    return 0


def _print_fit(result) -> None:
    """The criterion before and after, and how each free value ended."""
    print(f"criterion {result.crit_before:.5g} -> {result.crit_after:.5g} (linear model)"
          + (f", {result.crit_before_time:.5g} -> {result.crit_after_time:.5g} (time-domain check)"
             if result.crit_after_time is not None else "")
          + f"; {result.n_eval} of {result.max_evals} evaluations in {result.wall_s:.0f} s; {result.message}")
    for p in result.free:
        print(f"  {p}: {result.start[p]:.5g} -> {result.final[p]:.5g} ({_fit_state(result, p)})")


def _fit_state(result, path: str) -> str:
    """How one free value of a fit ended, in a few words."""
    side = next((f"at its {s} bound" for p, s, _ in result.at_bound if p == path), None)
    if side is not None:
        return side
    return ("identified" if path in result.identified else "moved, not identified" if path in result.moved
            else "not moved")


# --- ehm plot-frf ---------------------------------------------------------------------------------------------------

def add_plot_frf(sub) -> None:
    p = sub.add_parser("plot-frf", help="plot gains: one grid per input axis, model lines and measured markers")
    p.add_argument("frf", nargs="+", metavar="FRF.csv", help="model gains from 'ehm frf' (.csv or .parquet)")
    p.add_argument("--data", metavar="EXP.csv", help="measured gains to draw as markers (long format)")
    p.add_argument("--out", required=True, metavar="FIG.png",
                   help="figure file (FIG_x.png, FIG_y.png, ... when the tables hold several input axes)")
    progress_options(p)
    p.set_defaults(func=cmd_plot_frf)


def cmd_plot_frf(args) -> int:
    from ...analysis.frf import AXES, read_frf
    from ...outputs.plotting import NO_RESPONSE_SHARE, empty_paths, plot_frf_grid

    check_output_file(args.out, "figure")
    tables = []
    for path in args.frf:
        t = read_frf(path)
        tables.append((Path(path).stem, t.__class__(t.curves, method="model")))
    if args.data:
        tables.append(("measured", read_frf(args.data)))
    axes = [a for a in AXES if any(k[0] == a for _, t in tables for k in t.curves)]
    out = Path(args.out)
    written, empty = [], {}
    show = progress_count("figures", args.quiet)
    if show is not None:
        show(0, len(axes))
    for i, a in enumerate(axes):
        path = out if len(axes) == 1 else out.with_name(f"{out.stem}_{a}{out.suffix}")
        empty[a] = empty_paths(tables, a)
        plot_frf_grid(tables, a, path)
        written.append(str(path))
        if show is not None:
            show(i + 1, len(axes))
    end_progress_line()
    counts = {a: len(e) for a, e in empty.items() if e}
    if counts:
        print(f"{sum(counts.values())} paths without a response (peak gain below {NO_RESPONSE_SHARE:g} of the largest "
              "of their kind: round-off, e.g. a symmetric person's sideways response to vertical input) drawn as "
              "empty grey panels: " + ", ".join(f"{n} under seat {a}" for a, n in counts.items()))
    print("wrote " + ", ".join(written))
    return 0


# --- ehm study locking ----------------------------------------------------------------------------------------------

def add_study(sub) -> None:
    p = sub.add_parser("study", help="studies: 'locking' (the paper's joint-locking study)")
    ssub = p.add_subparsers(dest="study", required=True)
    q = ssub.add_parser("locking", help="baseline, spine locked (SL), neck locked (NL) and named variants")
    q.add_argument("--params", metavar="FILE.toml", help="parameter file (default: the shipped defaults)")
    seating_options(q)
    q.add_argument("--variant", action="append", metavar="NAME=J1,J2", help="another variant to run")
    q.add_argument("--method", default="linear", choices=("linear", "time"),
                   help="transfer functions of the linearised person (default) or of random-vibration runs")
    q.add_argument("--band", type=float, nargs=2, default=(0.5, 4.0), metavar=("LOW_HZ", "HIGH_HZ"),
                   help="band of the mean-gain comparison (default 0.5 4)")
    q.add_argument("--duration", type=float, default=60.0, help="run length per axis of the time method [s]")
    q.add_argument("--out", required=True, metavar="DIR",
                   help="output folder: locking.csv, locking.json, locking.png, frf_<variant>.csv")
    q.set_defaults(func=cmd_study_locking)


def cmd_study_locking(args) -> int:
    from ...analysis.study import PAPER_VARIANTS, locking_study, parse_variant

    variants = dict(PAPER_VARIANTS)
    for v in args.variant or []:
        name, joints = parse_variant(v)
        variants[name] = joints
    band = checked_band(args.band)
    person = person_from_args(args)
    final = check_output_folder(args.out, inputs=input_files(args))
    study = locking_study(params=person, variants=variants, method=args.method, band_hz=band,
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
    from ...files import write_text_atomic
    from ...outputs.plotting import plot_locking_study

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


# --- ehm validate ---------------------------------------------------------------------------------------------------

#: The files ``ehm validate --out`` writes.
VALIDATION_FILES = ("validation.csv", "validation.json", "validation_z.png", "validation_x.png", "validation_y.png")
#: The files ``ehm validate --all --out`` writes: the table and one figure grid, a row per condition.
VALIDATION_ALL_FILES = ("validation.csv", "validation.json", "validation_grid.png")


def add_validate(sub) -> None:
    p = sub.add_parser(
        "validate", help="the person against the standards' reference curves and the paper's findings (exit "
                         "status 1 when a check fails)",
        description="Evaluate a person (parameter file, size, posture, seat) against every reference of "
                    "ehm.standards.references: ISO 2631-5's seat-to-lumbar transfer function, the measured apparent "
                    "mass (Fairley & Griffin's one-mass fit), the whole-body mode, the seat-to-head ranges, and the "
                    "paper's joint-locking findings.  Prints one line per check (the model's figure and its unit, "
                    "the band, pass or FAIL, its sources by number) and the sources a reader can look up.  Without "
                    "--posture and --back-support the person is evaluated in the "
                    "references' condition (erect, back support none) and on its own seat; with either, in that one "
                    "condition; with --all, every posture "
                    "on every back support, and the findings across two conditions.  Each band is graded only where "
                    "its source applies; the locking findings on the paper's seat (erect, high back support).  Exit "
                    "status: 0 when every check passes, 1 when some check fails, 2 on bad input.")
    p.add_argument("--params", metavar="FILE.toml", help="parameter file (default: the shipped defaults)")
    seating_options(p)
    size_options(p)
    p.add_argument("--dt", type=float, help="time step the person is linearised at [s] (default: its own)")
    p.add_argument("--all", action="store_true", dest="every_condition",
                   help="every posture the parameter file defines (shipped: erect, slouched) on every back support "
                        "(none, low, high, full), each band where its source applies, and the findings across two "
                        "conditions; --out writes " + ", ".join(VALIDATION_ALL_FILES) + " (not with --posture or "
                        "--back-support)")
    p.add_argument("--no-locking", action="store_true",
                   help="leave out the paper's joint-locking findings (three fewer linearisations)")
    p.add_argument("--out", metavar="DIR",
                   help="output folder: " + ", ".join(VALIDATION_FILES) + " (with --all: "
                        + ", ".join(VALIDATION_ALL_FILES) + "; default: print the table only)")
    progress_options(p)
    p.set_defaults(func=cmd_validate)


def cmd_validate(args) -> int:
    from ...analysis.validation import validate

    if args.dt is not None:
        check_time_step(args.dt, "--dt")
    every = args.every_condition
    if every and (args.posture is not None or args.back_support is not None):
        raise InputError("--all evaluates every posture on every back support: leave out --posture and "
                         "--back-support (posture, back_support in Python), or evaluate that one condition without "
                         "--all (every_condition).")
    final = None if args.out is None else check_output_folder(args.out, inputs=input_files(args))
    validation = validate(person_from_args(args), locking=not args.no_locking, every_condition=every,
                          progress=progress_count("linearisations", args.quiet))
    end_progress_line()
    print(validation.format_table())
    if every:
        print("per condition:\n" + validation.format_counts())
    if final is not None:
        with RunFolder(final) as out:
            _write_validation(validation, out, every)
        print(f"wrote {final}/" + ", ".join(VALIDATION_ALL_FILES if every else VALIDATION_FILES))
    if not validation.passed:
        print(f"ehm: validate: {len(validation.failed)} of {len(validation.checks)} checks fail: "
              f"{', '.join(dict.fromkeys(c.name for c in validation.failed))}.", file=sys.stderr)
        return EXIT_CHECKS_FAILED
    return 0


def _write_validation(validation, out: Path, every_condition: bool = False) -> None:
    """The checks' table (CSV, JSON) and a figure per seat input axis, or (``every_condition``) one figure grid with
    a row per condition, written into ``out``."""
    from ...outputs.plotting import plot_validation, plot_validation_grid

    validation.to_csv(out / "validation.csv")
    write_json_atomic(out / "validation.json", validation.as_dict())
    if every_condition:
        plot_validation_grid(validation, out / "validation_grid.png")
        return
    for axis in "zxy":
        plot_validation(validation, axis, out / f"validation_{axis}.png")


# --- ehm check-step -------------------------------------------------------------------------------------------------

def add_check_step(sub) -> None:
    p = sub.add_parser("check-step", help="transfer functions at a time step against the same model at finer steps")
    model_options(p)
    p.add_argument("--dt", type=float, help="time step to check [s] (default: the person's: the parameter file's "
                                            "0.001, or the posture's own converged step: slouched 0.0005)")
    p.add_argument("--ratio", type=int, nargs="+", default=[8, 4], help="finer steps as divisors (default: 8 4)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=cmd_check_step)


def cmd_check_step(args) -> int:
    from ...analysis.convergence import check_step

    if args.dt is not None:
        check_time_step(args.dt, "--dt")
    body_args = (args.segments, args.joints, args.contacts)
    if any(body_args):
        raise InputError("check-step uses the shipped body tables; --segments, --joints and --contacts are not "
                         "supported here.")
    check = check_step(person_from_args(args), ratios=args.ratio)
    if args.json:
        _print_step_check_json(check)
    else:
        _print_step_check(check)
    return 0


def _print_step_check_json(check) -> None:
    from ...analysis.convergence import TOLERANCE

    ratios = sorted(check.errors, reverse=True)
    print(json.dumps({"dt_s": check.dt_s, "tolerance_pct": 100 * TOLERANCE, "paths": check.rows(),
                      "worst": {f"step_over_{r}": {"path": list(check.worst(r)[0]),
                                                   "error_pct": 100 * check.worst(r)[1]} for r in ratios}},
                     indent=1))


def _print_step_check(check) -> None:
    """One line per path with its error against each finer step, and the worst against the finest."""
    from ...analysis.convergence import TOLERANCE

    ratios = sorted(check.errors, reverse=True)
    head = "".join(f"  vs dt/{r:<3d}" for r in ratios)
    print(f"time step {check.dt_s * 1e3:g} ms; error = largest |gain difference| / peak gain, 0.2-12 Hz")
    print(f"{'path':<24s}{'peak':>14s}{head}")
    for row in check.rows():
        path = f"seat {row['input_axis']} -> {row['point']} {row['dof']}"
        errs = "".join(f"  {row[f'error_vs_step_over_{r}_pct']:6.2f} %  " for r in ratios)
        print(f"{path:<24s}{row['peak_gain']:7.3g} @{row['peak_hz']:5.2f}{errs}")
    (k, e) = check.worst(ratios[0])
    verdict = "converged" if e <= TOLERANCE else "NOT converged"
    print(f"worst: seat {k[0]} -> {k[1]} {k[2]}, {100 * e:.2f} % against dt/{ratios[0]}: {verdict} "
          f"(tolerance {100 * TOLERANCE:g} %)")
