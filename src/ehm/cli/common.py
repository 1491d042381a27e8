"""What several commands make of their arguments: the person, the joints, the body size, the band, the motion file."""

from __future__ import annotations

import numpy as np

from ..drives import drive_path
from ..errors import InputError
from ..params import Parameters
from ..simulation import SeatedHuman
from ..tables import load_body


def joint_list(values: list[str] | None) -> list[str]:
    """The joint names of a repeatable, comma-separated option (--lock, --joints), blanks dropped."""
    out: list[str] = []
    for v in values or []:
        out += [x.strip() for x in v.split(",") if x.strip()]
    return out


def params_from_args(args) -> Parameters:
    """The parameter file of --params, in the posture of --posture and with the back support of --back-support, with
    the head-in-space control of --head-control and --head-control-gains."""
    return Parameters.load(args.params).seated(args.posture, args.back_support).with_head_control(_head_control(args))


def _head_control(args):
    """None (the parameter file's), True (--head-control) or the gains of --head-control-gains KEY=VALUE,..."""
    text = getattr(args, "head_control_gains", None)
    if text is None:
        return True if getattr(args, "head_control", False) else None
    gains = {}
    for item in (x.strip() for x in text.split(",") if x.strip()):
        key, eq, value = item.partition("=")
        try:
            gains[key.strip()] = float(value) if eq else None
        except ValueError:
            gains[key.strip()] = None
        if gains[key.strip()] is None:
            raise InputError(f"--head-control-gains: {item!r} is not KEY=NUMBER, e.g. tilt_stiffness_Nm_per_rad=30.")
    if not gains:
        raise InputError("--head-control-gains needs at least one KEY=NUMBER, e.g. tilt_stiffness_Nm_per_rad=30.")
    return gains


def human_from_args(args, rotating_seat: bool = False) -> SeatedHuman:
    """The SeatedHuman the shared options describe (parameters, body tables, locks, step, body size)."""
    params = params_from_args(args)
    if getattr(args, "dt", None) is not None:
        params = params.at_step(args.dt, "--dt")
    body = load_body(args.segments, args.joints, args.contacts)
    return SeatedHuman(params=params, lock=joint_list(args.lock), unlock=joint_list(args.unlock), body=body,
                       rotating_seat=rotating_seat, size=size_from_args(args))


def size_from_args(args):
    """A BodySize from --stature / --mass / --sitting-height, or None for the reference person."""
    if args.stature is None and args.mass is None and args.sitting_height is None:
        return None
    from ..scaling import REFERENCE_MASS_KG, REFERENCE_STATURE_M, BodySize

    return BodySize(args.stature if args.stature is not None else REFERENCE_STATURE_M,
                    args.mass if args.mass is not None else REFERENCE_MASS_KG, args.sitting_height)


def checked_band(values) -> tuple[float, float]:
    """The --band (low, high) in Hz, refused unless 0 < low < high and both finite."""
    lo, hi = values
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo < hi):
        raise InputError(f"--band {lo:g} {hi:g}: the band needs two finite frequencies with 0 < low < high [Hz].")
    return float(lo), float(hi)


def read_motion_file(args):
    """The --motion file (or a shipped SYNTHETIC drive) through ehm.readers.read_motion."""
    from ..readers import mounting_rotation, parse_assignments, read_motion

    return read_motion(drive_path(args.motion), channels=parse_assignments(args.channel, "--channel"),
                       units=parse_assignments(args.unit, "--unit"), rate_hz=args.rate, imu=args.imu,
                       fill_gaps=args.fill_gaps, columns=args.columns, gyro=args.gyro,
                       mounting=mounting_rotation(args.mounting) if args.mounting is not None else None,
                       start_s=args.start, end_s=args.end, gravity=getattr(args, "gravity", "auto"),
                       imu_options={"rest_s": args.rest, "max_tilt_deg": args.max_tilt},
                       frame=getattr(args, "frame", "seat"), drop_held=getattr(args, "drop_held", True),
                       encoding=getattr(args, "encoding", None))


def input_files(args) -> list[str]:
    """The files a command reads (--motion, --gyro, --params and the body tables), where given as files: an output
    folder that holds one would delete it (ehm.outdir.check_output_folder refuses that)."""
    from pathlib import Path

    given = [getattr(args, k, None) for k in ("motion", "gyro", "params", "segments", "joints", "contacts")]
    return [g for g in given if isinstance(g, str) and Path(g).is_file()]
