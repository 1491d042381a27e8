"""What several commands make of their arguments: the person, the joints, the body size, the band, the motion file."""

from __future__ import annotations

import numpy as np

from ...body.level import at_level
from ...body.params import Parameters
from ...body.tables import load_body
from ...body.timestep import check_time_step
from ...errors import InputError
from ...inputs.drives import drive_path
from ...person import Person
from ...simulation import SeatedHuman


def joint_list(values: list[str] | None) -> list[str]:
    """The joint names of a repeatable, comma-separated option (--lock, --joints), blanks dropped."""
    out: list[str] = []
    for v in values or []:
        out += [x.strip() for x in v.split(",") if x.strip()]
    return out


#: Options that name a file or folder, with what to do instead of giving them empty.
_PATH_OPTIONS = {
    "motion": "give a motion file (or a shipped drive: city, road), or leave --motion out for the generated vibration",
    "gyro": "give the gyro file, or leave --gyro out",
    "params": "give a parameter file, or leave --params out for the shipped defaults",
    "segments": "give a segment table, or leave --segments out for the paper's",
    "joints": "give a joint table, or leave --joints out for the paper's",
    "contacts": "give a contact table, or leave --contacts out for the shipped one",
    "out": "give where to write, e.g. --out runs/first",
    "ratings": "give the person's ratings file (time_s,misc)",
    "sickness_params": "give the file 'ehm fit-sickness' wrote, or leave --sickness-params out for the group's values",
}


def check_empty_paths(args) -> None:
    """Refuse, in one sentence, a file or folder option given as an empty or blank string (an unset shell variable,
    ``--motion "$DRIVE"``): it would otherwise run on the default (``--motion ''`` simulated the generated
    vibration) or on the current folder."""
    for name, advice in _PATH_OPTIONS.items():
        value = getattr(args, name, None)
        if isinstance(value, str) and not value.strip():
            raise InputError(f"--{name.replace('_', '-')} is empty ({value!r}: an unset shell variable?); {advice}.")


def person_from_args(args) -> Person:
    """The one :class:`ehm.Person` of the shared person options, for every command: --params, --posture,
    --back-support, --head-control, --head-control-gains, --lock, --unlock, --segments/--joints/--contacts,
    --stature/--mass/--sitting-height, --dt and --vibration-rms (an option a command does not declare keeps the
    person's default)."""
    dt = getattr(args, "dt", None)
    if dt is not None:
        check_time_step(dt, "--dt")
    tables = [getattr(args, k, None) for k in ("segments", "joints", "contacts")]
    return Person(params=getattr(args, "params", None), body=load_body(*tables) if any(tables) else None,
                  size=size_from_args(args), posture=getattr(args, "posture", None),
                  back_support=getattr(args, "back_support", None), head_control=_head_control(args),
                  lock=joint_list(getattr(args, "lock", None)), unlock=joint_list(getattr(args, "unlock", None)),
                  dt_s=dt, vibration_rms_mps2=getattr(args, "vibration_rms", None))


def params_from_args(args) -> Parameters:
    """The parameter file of --params, in the posture of --posture and with the back support of --back-support, with
    the head-in-space control of --head-control and --head-control-gains (the person's, before its step and size), at
    the level of --vibration-rms when given (its values at that level, ehm.body.level.at_level)."""
    person = Person(params=getattr(args, "params", None), posture=getattr(args, "posture", None),
                    back_support=getattr(args, "back_support", None), head_control=_head_control(args),
                    vibration_rms_mps2=getattr(args, "vibration_rms", None))
    params = person.seated_params()
    return params if person.vibration_rms_mps2 is None else at_level(params, person.vibration_rms_mps2)


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
    """The SeatedHuman of :func:`person_from_args`."""
    return SeatedHuman(person_from_args(args), rotating_seat=rotating_seat)


def size_from_args(args):
    """A BodySize from --stature / --mass / --sitting-height, or None for the reference person."""
    stature, mass, sitting = (getattr(args, k, None) for k in ("stature", "mass", "sitting_height"))
    if stature is None and mass is None and sitting is None:
        return None
    from ...person.scaling import REFERENCE_MASS_KG, REFERENCE_STATURE_M, BodySize

    return BodySize(stature if stature is not None else REFERENCE_STATURE_M,
                    mass if mass is not None else REFERENCE_MASS_KG, sitting)


def checked_band(values) -> tuple[float, float]:
    """The --band (low, high) in Hz, refused unless 0 < low < high and both finite."""
    lo, hi = values
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo < hi):
        raise InputError(f"--band {lo:g} {hi:g}: the band needs two finite frequencies with 0 < low < high [Hz].")
    return float(lo), float(hi)


def read_motion_file(args):
    """The --motion file (or a shipped SYNTHETIC drive) through ehm.inputs.readers.read_motion."""
    from ...inputs.readers import mounting_rotation, parse_assignments, read_motion
    from ...inputs.vocabulary import command_line

    with command_line():  # messages name the options (--rate), not the Python arguments (rate_hz=)
        return _read_motion_file(args, read_motion, parse_assignments, mounting_rotation)


def _read_motion_file(args, read_motion, parse_assignments, mounting_rotation):
    return read_motion(drive_path(args.motion), channels=parse_assignments(args.channel, "--channel"),
                       units=parse_assignments(args.unit, "--unit"), rate_hz=args.rate, imu=args.imu,
                       fill_gaps=args.fill_gaps, columns=args.columns, gyro=args.gyro,
                       mounting=mounting_rotation(args.mounting) if args.mounting is not None else None,
                       start_s=args.start, end_s=args.end, gravity=getattr(args, "gravity", "auto"),
                       imu_options={"rest_s": args.rest, "max_tilt_deg": args.max_tilt},
                       frame=getattr(args, "frame", "seat"), drop_held=getattr(args, "drop_held", True),
                       encoding=getattr(args, "encoding", None),
                       handling="keep" if getattr(args, "keep_handling", False) else "cut")


def input_files(args) -> list[str]:
    """The files a command reads (--motion, --gyro, --params and the body tables), where given as files: an output
    folder that holds one would delete it (ehm.outputs.outdir.check_output_folder refuses that)."""
    from pathlib import Path

    given = [getattr(args, k, None) for k in ("motion", "gyro", "params", "segments", "joints", "contacts")]
    return [g for g in given if isinstance(g, str) and Path(g).is_file()]
