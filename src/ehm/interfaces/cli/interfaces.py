"""Commands that connect ehm to other tools: info, params, drive, realtime, batch and export-fmu."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from ... import __version__
from ...errors import InputError
from ...outputs.outdir import check_output_file, check_output_folder, folder_lock
from .common import human_from_args, params_from_args, person_from_args, read_motion_file
from .options import model_options, motion_file_options, progress_options, seating_options
from .progress import progress_count

# --- ehm info -------------------------------------------------------------------------------------------------------

def add_info(sub) -> None:
    p = sub.add_parser("info", help="describe the model (segments, joints, degrees of freedom)")
    model_options(p)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=cmd_info)


def cmd_info(args) -> int:
    human = human_from_args(args)
    info = human.info()
    if args.json:
        print(json.dumps(info, indent=2))
        return 0
    print(f"ehm {__version__}: seated human, {info['mass_kg']:.3f} kg, {info['dof']} degrees of freedom, "
          f"time step {info['dt_s'] * 1000:g} ms, parameters: {info['params']}")
    print(f"posture: {info['posture']}; back support: {info['back_support']} (backrest contacts: "
          f"{', '.join(c['name'] for c in info['contacts'] if c['surface'].startswith('backrest')) or 'none'})")
    print(f"{human.person.level_words()} (docs/model.md, 'Vibration magnitude')")
    print("segments (centre of gravity in m, x forward, y left, z up):")
    for s in info["segments"]:
        x, y, z = s["com_m"]
        print(f"  {s['name']:<13} {s['mass_kg']:7.3f} kg  ({x:+.4f}, {y:+.4f}, {z:+.4f})")
    print("joints:")
    for j in info["joints"]:
        state = "locked" if j["locked"] else f"{j['dof']} dof ({', '.join(j['dofs'])})"
        print(f"  {j['name']:<11} {j['type']:<19} {j['parent']} -> {j['child']}: {state}")
    return 0


# --- ehm params -----------------------------------------------------------------------------------------------------

def add_params(sub) -> None:
    p = sub.add_parser("params", help="print or export the parameter file")
    p.add_argument("--params", metavar="FILE.toml", help="parameter file to read (default: the shipped defaults)")
    p.add_argument("--export", metavar="FILE.toml", help="write it to a file")
    seating_options(p)
    p.set_defaults(func=cmd_params)


def cmd_params(args) -> int:
    if args.export:
        check_output_file(args.export, "parameter file")
    params = params_from_args(args)
    if args.export:
        params.export(args.export)
        print(f"wrote {args.export}")
    else:
        sys.stdout.write(params.to_toml())
    return 0


# --- ehm drive ------------------------------------------------------------------------------------------------------

def add_drive(sub) -> None:
    p = sub.add_parser("drive", help="write a SYNTHETIC drive file (city manoeuvres or a rough road)")
    p.add_argument("kind", choices=("city", "road"), help="city manoeuvres or a rough road")
    p.add_argument("--duration", type=float, default=120.0, help="length [s] (default 120)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--speed", type=float, default=15.0, help="road: vehicle speed [m/s] (default 15)")
    p.add_argument("--road-class", default="C", choices=("A", "B", "C", "D", "E"), help="road: ISO 8608 class")
    p.add_argument("--out", required=True, metavar="DRIVE.csv", help="the drive file to write")
    p.set_defaults(func=cmd_drive)


def cmd_drive(args) -> int:
    from ...inputs.drives import city_drive, rough_road, write_drive_csv

    check_output_file(args.out, "drive file")
    motion = (city_drive(args.duration, seed=args.seed) if args.kind == "city"
              else rough_road(args.duration, speed_mps=args.speed, road_class=args.road_class, seed=args.seed))
    write_drive_csv(motion, args.out)
    print(f"wrote {args.out}: {motion.description}")
    return 0


# --- ehm realtime ---------------------------------------------------------------------------------------------------

def add_realtime(sub) -> None:
    p = sub.add_parser("realtime", help="step the model paced to the wall clock; report per-step latency")
    model_options(p)
    motion_file_options(p, True, "seat motion file (.csv/.txt, .parquet, .mat, .mf4), or city / road")
    p.add_argument("--duration", type=float, help="run only this many seconds of the motion")
    p.add_argument("--no-pace", action="store_true", help="run as fast as possible (latency figures only)")
    p.add_argument("--no-comfort", action="store_true", help="skip the running comfort figures")
    p.add_argument("--ignore-rotation", action="store_true", help="drop the drive's angular velocity")
    p.set_defaults(func=cmd_realtime)


def _check_realtime_motion(args, motion) -> None:
    """Refuse a turning seat (unless --ignore-rotation) and a --duration that is not a positive time."""
    if motion.angvel_radps is not None and np.any(motion.angvel_radps != 0):
        if not args.ignore_rotation:
            raise InputError(f"{args.motion} rotates the seat; real-time stepping supports seat translation only "
                             "(use --ignore-rotation to drop the rotation, or 'ehm assess' for the whole drive).")
    if args.duration is not None and not (np.isfinite(args.duration) and args.duration > 0):
        raise InputError(f"--duration {args.duration}: give a positive number of seconds.")


def cmd_realtime(args) -> int:
    from ...analysis.stepping import Simulator, run_realtime

    motion = read_motion_file(args)
    _check_realtime_motion(args, motion)
    sim = Simulator(person_from_args(args), comfort=not args.no_comfort)
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
            f"{loc} z {c[loc]['z'][1]:.3f}" for loc in c))
    return 0


# --- ehm batch ------------------------------------------------------------------------------------------------------

def add_batch(sub) -> None:
    p = sub.add_parser("batch", help="run a study file (people, seats, parameters) on Dask; one tidy table")
    p.add_argument("study", metavar="STUDY.toml", help="the study file")
    p.add_argument("--out", required=True, metavar="DIR",
                   help="results folder (results.parquet; added to, so a study can resume)")
    p.add_argument("--scheduler", metavar="tcp://HOST:PORT", help="an existing Dask scheduler (default: local)")
    p.add_argument("--workers", type=int, help="local worker processes (default and at most: what the machine "
                                                    "holds, its cores and its memory at about 0.4 GB per worker)")
    p.add_argument("--csv", action="store_true", help="also write results.csv")
    p.add_argument("--retry-failed", action="store_true",
                   help="when resuming, run the recorded failures again too (lost workers are always retried)")
    progress_options(p)
    p.set_defaults(func=cmd_batch)


def cmd_batch(args) -> int:
    try:
        import dask.distributed  # noqa: F401
        import pyarrow  # noqa: F401

        from ..batch import check_scheduler, load_study, run_study
    except ImportError:
        raise InputError("batch studies need Dask and pyarrow: pip install 'ehm[batch]'.") from None
    if args.workers is not None and args.workers < 1:
        raise InputError(f"--workers {args.workers}: use 1 or more worker processes.")
    scheduler = check_scheduler(args.scheduler) if args.scheduler else None
    name, specs = load_study(args.study)
    with folder_lock(args.out, "study's results"):  # another study into this folder is refused before any check
        out = check_output_folder(args.out, "study's results", added_to=True, inputs=_study_inputs(args.study, specs))
        print(f"study '{name}': {len(specs)} runs" + (f" on {scheduler}" if scheduler else ""))
        res = run_study(specs, out, scheduler=scheduler, workers=args.workers, csv=args.csv,
                        progress=progress_count("runs", args.quiet),
                        retry_failed=args.retry_failed)
    if res["ran"] and res["failed"] == res["ran"]:
        raise InputError(f"all {res['ran']} runs failed; their errors are in {out}/results.parquet (output 'error').")
    _print_batch(res, out, args.csv)
    return 0


def _study_inputs(study: str, specs) -> list[str]:
    """The study file and the drive and gyro files its runs read."""
    inp = specs[0].input if specs else {}
    return [study, *(f for f in (inp.get("drive"), inp.get("gyro")) if isinstance(f, str) and Path(f).is_file())]


def _print_batch(res: dict, out: Path, csv: bool) -> None:
    tp = res["throughput_simulated_s_per_s"]
    changed = res["changed"]
    print(f"ran {res['ran']} runs ({res['skipped']} already done, "
          + (f"{changed['count']} rerun because an input changed ({', '.join(changed['inputs'])}), "
             if changed["count"] else "")
          + f"{res['failed']} failed) in {res['wall_s']:.1f} s"
          + (f"; {tp:.1f} simulated s per wall s" if tp else "") + f"; wrote {out}/results.parquet"
          + (" and results.csv" if csv else ""))


# --- ehm export-fmu -------------------------------------------------------------------------------------------------

def add_export_fmu(sub) -> None:
    p = sub.add_parser("export-fmu", help="write an FMI 2.0 co-simulation unit (FMU) of the person for vehicle tools")
    p.add_argument("--out", required=True, metavar="FILE.fmu", help="FMU file to write")
    model_options(p)
    p.add_argument("--dt", type=float,
                   help="model step [s] (default: the parameter file's, or the posture's own converged step)")
    p.add_argument("--python", action="store_true",
                   help="build the pythonfmu unit (its host must run ehm in Python) instead of the native one")
    p.add_argument("--rotating-seat", action="store_true",
                   help="a seat that turns with the unit's angular velocity inputs (native unit; steps cost ~1.5x)")
    p.set_defaults(func=cmd_export_fmu)


def cmd_export_fmu(args) -> int:
    import time

    t0 = time.perf_counter()
    if args.python:
        return _export_python_fmu(args, t0)
    from ..fmu_native import INPUTS, OUTPUTS, PLATFORM, export_native_fmu

    human = human_from_args(args, rotating_seat=args.rotating_seat)
    path = export_native_fmu(args.out, human)
    turning = "the seat turns with them" if args.rotating_seat else "seat angular velocity must stay 0"
    print(f"wrote {path} in {time.perf_counter() - t0:.1f} s: FMI 2.0 co-simulation unit (native C on MuJoCo, "
          f"{PLATFORM}), {human.mass_kg:.1f} kg, {human.dof} degrees of freedom, model step "
          f"{human.model.mj.opt.timestep * 1000:g} ms; {len(INPUTS)} inputs (seat acceleration and angular velocity; "
          f"{turning}), {len(OUTPUTS)} outputs (pelvis, trunk, head, lumbar, support forces); no Python needed to run "
          "it")
    return 0


def _export_python_fmu(args, t0: float) -> int:
    """export-fmu --python: the pythonfmu unit, which takes only --params, --lock and --unlock."""
    import time

    from ..fmu import INPUTS, OUTPUTS, export_fmu

    extra = [o for o, v in (("--segments", args.segments), ("--joints", args.joints), ("--contacts", args.contacts),
                            ("--stature", args.stature), ("--mass", args.mass),
                            ("--sitting-height", args.sitting_height), ("--dt", args.dt),
                            ("--rotating-seat", args.rotating_seat or None)) if v is not None]
    if extra:
        raise InputError(f"export-fmu --python takes only --params, --posture, --back-support, --lock and --unlock, "
                         f"not {', '.join(extra)}; "
                         "export the native unit (without --python) for these.")
    path = export_fmu(args.out, params=person_from_args(args), python=True)
    print(f"wrote {path} in {time.perf_counter() - t0:.1f} s: FMI 2.0 co-simulation unit (pythonfmu), "
          f"{len(INPUTS)} inputs ({', '.join(INPUTS[:3])}; seat angular velocity must stay 0), "
          f"{len(OUTPUTS)} outputs (pelvis, trunk, head, lumbar); the host's Python must be able to import ehm")
    return 0
