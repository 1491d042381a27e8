"""Batch studies: many people, seats and parameter sets, run on Dask (locally or on a cluster).

A study file (TOML) names what varies and what to compute::

    [study]
    name = "spine stiffness and body size"
    compute = ["transmissibility", "comfort"]   # one or both

    [people]                    # body sizes; rows are paired (zip), not crossed
    stature_m = [1.52, 1.76, 1.87]
    mass_kg = [50.0, 70.882, 98.0]
    # sitting_height_m = [0.79, 0.92, 0.97]   (optional)

    [grid]                      # crossed with each other and with the people
    "joints.t12.z.stiffness_N_per_m" = [10000.0, 15000.0, 20000.0]
    lock = [[], ["t12"]]
    # posture = ["erect", "slouched"]          postures (the parameter file's [postures.NAME])
    # back_support = ["none", "low", "high"]   back supports (none, low, high, full)
    # head_control = [false, true]             head-in-space control off and on (gains: "head_control.<gain>" axes)

    [input]
    axes = ["x", "y", "z"]      # transmissibility: seat axes (linear model; method = "time" for runs)
    drive = "city"              # comfort: "city", "road", a drive file, or "random" (vibration of `axes`);
                                # a relative file path starts from the study file's folder
    # channels = { ax = "AccX", ay = "AccY", az = "AccZ" }   a log's own names (any format ehm.read_motion reads)
    # units = { ax = "g", ay = "g", az = "g" }                units the file does not carry; imu = true for an IMU
    # fill_gaps = true          bridge the drive file's gaps in its time stamps with a straight line (warned)
    # columns = ["x", "y", "z", "delay_ms"]   names of a headerless text file's columns (channels then name them;
    #                           channels: dt = "delay_ms" for a column of the time since the previous row, ax = "-x"
    #                           for a sign flip)
    # gyro = "gyro.csv"         a gyro in a file of its own (its wx, wy, wz and time named in channels); relative
    #                           paths start from the study file's folder
    # mounting = [0.0, 0.0, 90.0]   the sensor's roll, pitch, yaw [deg]: its axes turned into seat axes
    # start_s = 6.0             read the drive file from 6 s after its first sample (end_s: up to)
    # gravity = "auto"          gravity in the drive file's accelerations: auto, included (level it) or removed
    # frame = "seat"            the drive file's axes: seat, or earth (x east, y north, z up: read with a note)
    # drop_held = false         keep held samples (default true: a slow sensor's repeated rows are dropped)
    # encoding = "cp1252"       the drive file's text encoding (default: from its byte-order mark, else UTF-8)
    # handling = "keep"         keep a handled start and end of the drive file (default "cut": left out, with a note)
    # sickness_params = "person.toml"   comfort: a person's MISC parameters ('ehm fit-sickness'; default the
    #                           group's); a relative path starts from the study file's folder
    duration_s = 30.0
    route = "auto"              # simulation route of a drive's runs: "auto" (ehm.routes.hybrid, the default),
    #                           "nonlinear" (MuJoCo) or "linear"; transmissibility by method = "time": "nonlinear"

Every run is recorded (its inputs, and its outputs or its error) in ``OUT/runs/<point>.json`` as soon as it
ends, so an interrupted study resumes without redoing finished runs; at the end all runs are gathered
into one tidy table ``OUT/results.parquet`` (and ``results.csv`` when asked) with one row per run and
output.  A run that fails (diverges, bad parameters) is recorded with its error and does not stop the
study.

Records cannot go stale: a run's id (``run_id``) covers everything its answer depends on, the study point
(person, grid values, locks, what to compute, the ``[input]`` settings) and a fingerprint of its inputs:
the parameter values actually used, the content of the drive file and of the shipped body tables, and the
ehm and MuJoCo versions.  A recorded run whose fingerprint differs from today's (a drive file edited, ehm
upgraded) is run again, and :func:`run_study` counts those reruns and names what changed.

A drive longer than ``duration_s`` is cut by time: the samples up to ``duration_s`` after its first, and
one interpolated at exactly ``duration_s`` when no sample falls there (sample intervals may vary).
"""

from __future__ import annotations

import builtins
import functools
import hashlib
import itertools
import json
import math
import re
import time
import tomllib
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import EhmError, EhmWarning, InputError, checked, warn
from ..files import replace_atomically
from ..outputs.outdir import added_folder, write_owned, write_owned_json
from .cluster import check_scheduler, dask_client  # noqa: F401  (check_scheduler: the CLI's)

COMPUTE = ("transmissibility", "comfort")
#: [grid] axes of how the person sits: the short name -> the parameter it sets (a name, not a number).
SEATING = {"posture": "posture.name", "back_support": "seat.back_support"}
#: [grid] axes that switch something on or off: the short name -> the parameter it sets (true or false).
SWITCHES = {"head_control": "head_control.enabled"}


@dataclass(frozen=True)
class RunSpec:
    """One run of a study: who, with which parameters and locks, and what to compute."""

    run_id: str
    person: dict          # stature_m, mass_kg, sitting_height_m (or empty for the reference person)
    params: dict          # dotted parameter path -> value
    lock: tuple
    compute: tuple
    input: dict
    point_id: str = ""    # the study point alone (its record's file name); run_id adds the input fingerprint
    fingerprint: dict = field(default_factory=dict)  # input -> digest (parameters, drive, tables, versions)

    def build_person(self):
        """The run's :class:`ehm.Person`: the shipped parameters with the grid's values, the body size and locks."""
        from ..body.params import Parameters
        from ..person import Person
        from ..person.scaling import BodySize

        params = Parameters.load().with_values(self.params) if self.params else Parameters.load()
        return Person(params=params, size=BodySize(**self.person) if self.person else None, lock=self.lock)

    def inputs(self) -> dict:
        """The run's inputs as flat columns."""
        out = {"run_id": self.run_id, "lock": "+".join(self.lock) or "none"}
        out.update({k: v for k, v in self.person.items()})
        out.update(self.params)
        return out


def load_study(path: Path | str) -> tuple[str, list[RunSpec]]:
    """Read a study file and expand it into runs; clear errors for bad files."""
    label = str(path)
    try:
        doc = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as exc:
        raise InputError(f"{label}: cannot read the study file ({exc.strerror or exc}).") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{label}: not a valid TOML file ({exc}).") from None
    unknown = set(doc) - {"study", "people", "grid", "input"}
    if unknown:
        raise InputError(f"{label}: unknown section [{sorted(unknown)[0]}]; use study, people, grid, input.")
    for section in ("study", "people", "grid", "input"):
        if section in doc and not isinstance(doc[section], dict):
            raise InputError(f"{label}: {section} must be a [{section}] table, not {doc[section]!r}.")
    study = doc.get("study", {})
    compute = study.get("compute", ["transmissibility"])
    if not isinstance(compute, list) or not compute:
        raise InputError(f"{label}: [study] compute must be a list, e.g. [\"transmissibility\", \"comfort\"].")
    compute = tuple(compute)
    for c in compute:
        if c not in COMPUTE:
            raise InputError(f"{label}: [study] compute names {c!r}; use {', '.join(COMPUTE)}.")
    people = doc.get("people", {})
    keys = [k for k in ("stature_m", "mass_kg", "sitting_height_m") if k in people]
    if set(people) - set(keys):
        raise InputError(f"{label}: unknown key {sorted(set(people) - set(keys))[0]!r} in [people].")
    if keys:
        lengths = {len(people[k]) for k in keys if isinstance(people[k], list)}
        if len(lengths) != 1 or not all(isinstance(people[k], list) for k in keys):
            raise InputError(f"{label}: [people] needs lists of equal length ({', '.join(keys)}).")
        rows = [dict(zip(keys, vals)) for vals in zip(*(people[k] for k in keys))]
    else:
        rows = [{}]
    grid = dict(doc.get("grid", {}))
    locks = grid.pop("lock", [[]])
    if not isinstance(locks, list) or not all(isinstance(x, list) for x in locks):
        raise InputError(f"{label}: [grid] lock must be a list of joint lists, e.g. [[], [\"t12\"]].")
    for k, v in grid.items():
        if not isinstance(v, list) or not v:
            raise InputError(f"{label}: [grid] {k!r} must be a non-empty list of values.")
    grid = {SEATING.get(k, SWITCHES.get(k, k)): v for k, v in grid.items()}  # short names: their parameters
    inp = dict(doc.get("input", {}))
    allowed_input = {"axes", "method", "route", "drive", "duration_s", "rms_mps2", "seed", "channels", "units", "imu",
                     "rate_hz", "fill_gaps", "columns", "gyro", "mounting", "start_s", "end_s", "gravity", "frame",
                     "drop_held", "encoding", "handling", "sickness_params"}
    if set(inp) - allowed_input:
        raise InputError(f"{label}: unknown key {sorted(set(inp) - allowed_input)[0]!r} in [input]; "
                         f"use {', '.join(sorted(allowed_input))}.")
    written = dict(inp)  # the study point's key: the drive as written, so that a moved study folder resumes
    if "drive" in inp:
        inp["drive"] = drive_beside(inp["drive"], Path(path))
    if isinstance(inp.get("gyro"), str) and not Path(inp["gyro"]).is_absolute():
        inp["gyro"] = str(Path(path).absolute().parent / inp["gyro"])
    if "sickness_params" in inp:
        from ..standards.sickness import read_sickness_params

        if not isinstance(inp["sickness_params"], str):
            raise InputError(f"{label}: [input] sickness_params must be the path of the file 'ehm fit-sickness' "
                             f"wrote, not {inp['sickness_params']!r}.")
        if not Path(inp["sickness_params"]).is_absolute():
            inp["sickness_params"] = str(Path(path).absolute().parent / inp["sickness_params"])
        read_sickness_params(inp["sickness_params"])  # refused before any run
    _check_input(label, inp, written.get("drive"), written.get("gyro"))
    _check_before_running(label, rows, grid, locks)
    name = str(study.get("name", Path(path).stem))
    common = _common_fingerprint(inp, compute)
    specs = []
    for person in rows:
        for lock in locks:
            for combo in itertools.product(*grid.values()) if grid else [()]:
                params = dict(zip(grid.keys(), combo))
                key = json.dumps([person, params, sorted(lock), compute, written], sort_keys=True)
                point_id = hashlib.sha256(key.encode()).hexdigest()[:12]
                fingerprint = {"parameter values": _parameters_digest(json.dumps(params, sort_keys=True)),
                               **common}
                run_id = _digest(key, json.dumps(fingerprint, sort_keys=True))[:12]
                specs.append(RunSpec(run_id, person, params, tuple(lock), compute, inp, point_id, fingerprint))
    return name, specs


def drive_beside(drive, study_path: Path):
    """The ``[input] drive`` of a study file with a relative file path resolved against the study file's folder.

    Parameters
    ----------
    drive : str
        As written: ``"random"``, a shipped drive's name, or a motion file's path.
    study_path : Path
        The study file.

    Returns
    -------
    str
        ``drive`` unchanged when it is a name or an absolute path (or not a string: refused later), else the
        absolute path of the file beside the study file.
    """
    from ..inputs.drives import SHIPPED_DRIVES

    if not isinstance(drive, str) or drive == "random" or drive in SHIPPED_DRIVES or Path(drive).is_absolute():
        return drive
    return str(Path(study_path).absolute().parent / drive)


def _digest(*texts: str) -> str:
    h = hashlib.sha256()
    for t in texts:
        h.update(t.encode())
        h.update(b"\0")
    return h.hexdigest()


def _file_digest(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


@functools.lru_cache(maxsize=4096)
def _parameters_digest(grid_values_json: str) -> str:
    """Digest of every parameter value a run uses (the defaults with its grid values), before body scaling."""
    from ..body.params import Parameters

    params = Parameters.load()
    try:
        params = params.with_values(json.loads(grid_values_json))
    except InputError:  # the run will fail on these values (and be recorded so): the defaults and the values
        return _digest(json.dumps(params.data, sort_keys=True, default=str), grid_values_json)
    return _digest(json.dumps(params.data, sort_keys=True, default=str))


def _common_fingerprint(inp: dict, compute: tuple) -> dict:
    """Digests of the inputs all runs of a study share: versions, body tables, the drive file's content."""
    from importlib import metadata, resources

    from .. import __version__

    data = Path(str(resources.files("ehm") / "data"))
    out = {"ehm version": __version__,
           "MuJoCo version": metadata.version("mujoco"),
           "body tables": _digest(*(_file_digest(data / f) for f in ("segments.csv", "joints.csv", "contacts.csv")))}
    drive = inp.get("drive", "random")
    if "comfort" in compute and drive != "random":
        from ..inputs.drives import drive_path

        out["drive file content"] = _file_digest(drive_path(drive))
        if isinstance(inp.get("gyro"), str) and Path(inp["gyro"]).is_file():
            out["gyro file content"] = _file_digest(Path(inp["gyro"]))
    if "comfort" in compute and isinstance(inp.get("sickness_params"), str) and Path(inp["sickness_params"]).is_file():
        out["sickness parameter file content"] = _file_digest(Path(inp["sickness_params"]))
    return out


def _check_input(label: str, inp: dict, written_drive=None, written_gyro=None) -> None:
    """The [input] values, checked before any cluster starts (every run would trip over them); ``written_drive``
    and ``written_gyro``: the drive and the gyro file as the file gives them, when ``inp`` holds them resolved."""
    if inp.get("method", "linear") not in ("linear", "time"):
        raise InputError(f"{label}: [input] method {inp['method']!r}: use \"linear\" or \"time\".")
    if inp.get("route", "auto") not in ("nonlinear", "linear", "auto"):
        raise InputError(f"{label}: [input] route {inp['route']!r}: use \"nonlinear\", \"auto\" or \"linear\".")
    axes = inp.get("axes", ["x"])
    if (not isinstance(axes, list) or not axes or any(a not in ("x", "y", "z") for a in axes)
            or len(set(axes)) < len(axes)):
        raise InputError(f"{label}: [input] axes {axes!r}: use a list of distinct axes from \"x\", \"y\", \"z\".")
    for key in ("duration_s", "rms_mps2"):
        v = inp.get(key, 1.0)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not v > 0:
            raise InputError(f"{label}: [input] {key} {v!r}: use a positive number.")
    for key, default in (("imu", False), ("fill_gaps", False), ("drop_held", True)):
        if not isinstance(inp.get(key, default), bool):  # (read_motion's sentence names the Python values)
            raise InputError(f"{label}: [input] {key} must be true or false (a TOML boolean, no quotes); got "
                             f"{inp[key]!r}.")
    seed = inp.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError(f"{label}: [input] seed {seed!r}: use a whole number >= 0.")
    drive = inp.get("drive", "random")
    if drive != "random":
        from ..inputs.drives import drive_path

        if not isinstance(drive, str) or not drive_path(drive).is_file():
            looked = f" (no file {drive})" if isinstance(drive, str) and drive != written_drive else ""
            raise InputError(f"{label}: [input] drive {written_drive if written_drive is not None else drive!r}"
                             f"{looked}: use \"random\", \"city\", \"road\" or a motion file's path (relative "
                             "paths start from the study file's folder).")
        gyro = inp.get("gyro")
        if isinstance(gyro, str) and not Path(gyro).is_file():
            looked = f" (no file {gyro})" if gyro != written_gyro else ""
            raise InputError(f"{label}: [input] gyro {written_gyro if written_gyro is not None else gyro!r}{looked}: "
                             "give the gyro file's path (relative paths start from the study file's folder).")
        try:  # channels, units, imu: read the drive once here, so that a bad mapping stops the study at once
            _read_drive(inp)
        except InputError as exc:
            raise InputError(f"{label}: [input] drive: {exc}") from None


def _check_before_running(label: str, people: list, grid: dict, locks: list) -> None:
    """Names and ranges that every run would trip over are refused before any cluster starts."""
    from ..body.params import Parameters
    from ..body.tables import load_body, resolve_locks
    from ..person.scaling import BodySize

    params = Parameters.load()
    for key, values in grid.items():
        try:
            params.value(key)
        except InputError:
            raise InputError(f"{label}: [grid] names {key!r}, which is not a parameter (see 'ehm params').") from None
        seating = [name for name, path in SEATING.items() if path == key]
        if seating:  # names: a posture of the parameter file, a back support
            for v in values:
                try:
                    params.seated(**{seating[0]: v})
                except InputError as exc:
                    raise InputError(f"{label}: [grid] {seating[0]}: {exc}") from None
            continue
        if key in SWITCHES.values():
            for v in values:
                if not isinstance(v, bool):
                    name = [n for n, p in SWITCHES.items() if p == key][0]
                    raise InputError(f"{label}: [grid] {name} holds {v!r}; use true or false.")
            continue
        for v in values:
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise InputError(f"{label}: [grid] {key!r} holds {v!r}, not a number.")
    body = load_body()
    for lock in locks:
        try:
            resolve_locks(body, lock)
        except InputError as exc:
            raise InputError(f"{label}: [grid] lock: {exc}") from None
    for person in people:
        if person:
            try:
                BodySize(**person)
            except InputError as exc:
                raise InputError(f"{label}: [people]: {exc}") from None


def _drive(inp: dict, dt_s: float):
    from ..inputs.motion import random_vibration

    drive = inp.get("drive", "random")
    duration = float(inp.get("duration_s", 30.0))
    if drive == "random":
        return random_vibration("".join(inp.get("axes", ["z"])), duration, float(inp.get("rms_mps2", 0.3)),
                                seed=int(inp.get("seed", 0)), dt_s=dt_s)
    return cut_by_time(_read_drive(inp), duration)


def _read_drive(inp: dict):
    """The [input] drive file through ehm.inputs.readers.read_motion, with its channels, units, imu, rate_hz, fill_gaps,
    columns, gyro, mounting (roll, pitch, yaw in degrees), start_s, end_s, gravity, frame, drop_held, encoding and
    handling keys."""
    from ..inputs.drives import drive_path
    from ..inputs.readers import mounting_rotation, read_motion

    gyro = inp.get("gyro")
    if gyro is not None and not isinstance(gyro, str):
        raise InputError(f"gyro {gyro!r}: use the gyro file's path.")
    mounting = inp.get("mounting")
    return read_motion(drive_path(inp["drive"]), channels=inp.get("channels"), units=inp.get("units"),
                       rate_hz=inp.get("rate_hz"), imu=inp.get("imu", False), fill_gaps=inp.get("fill_gaps", False),
                       columns=inp.get("columns"), gyro=gyro,
                       mounting=None if mounting is None else mounting_rotation(mounting),
                       start_s=inp.get("start_s"), end_s=inp.get("end_s"), gravity=inp.get("gravity", "auto"),
                       frame=inp.get("frame", "seat"), drop_held=inp.get("drop_held", True),
                       encoding=inp.get("encoding"), handling=inp.get("handling", "cut"))


def cut_by_time(motion, duration_s: float):
    """The first ``duration_s`` of a motion: its samples up to ``duration_s`` after the first, plus one
    interpolated at exactly ``duration_s`` when none falls there (sample intervals may vary)."""
    from ..inputs.motion import SeatMotion

    t = motion.time_s - motion.time_s[0]
    tol = 1e-9 * max(1.0, duration_s)
    if t[-1] <= duration_s + tol:
        return motion
    n = int(np.searchsorted(t, duration_s + tol, side="right"))
    rows = [np.asarray(a)[:n] for a in (motion.time_s, motion.acc_mps2, motion.angvel_radps) if a is not None]
    if t[n - 1] < duration_s - tol:  # the cut falls between samples n - 1 and n
        end = motion.time_s[0] + duration_s
        extra = [np.array([end])] + [np.array([[np.interp(end, motion.time_s, a[:, j]) for j in range(3)]])
                                     for a in (motion.acc_mps2, motion.angvel_radps) if a is not None]
        rows = [np.concatenate([r, e]) for r, e in zip(rows, extra)]
    angvel = rows[2] if motion.angvel_radps is not None else None
    return SeatMotion(rows[0], rows[1], motion.description, angvel, motion.content_limit_hz, handling=motion.handling)


def run_one(spec: RunSpec) -> dict:
    """Run one study point; returns its record (inputs, outputs as {name: value}, error, timings, warnings).

    Its warnings are caught and returned in the record (``"warnings"``: [category name, sentence] pairs, each
    once), so that they come back from a worker process to the command running the study, rather than being
    printed by the worker as raw Python onto the command's progress line."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        record = _run_point(spec)
    caught = dict.fromkeys((_category_name(c.category), str(c.message)) for c in caught)
    record["warnings"] = [list(w) for w in caught]
    return record


def _run_point(spec: RunSpec) -> dict:
    from ..simulation import SeatedHuman

    record = {"inputs": spec.inputs(), "outputs": {}, "error": None, "simulated_s": 0.0}
    t0 = time.perf_counter()
    try:
        person = spec.build_person()
        params = person.params
        inp = spec.input
        if "transmissibility" in spec.compute:
            from ..analysis.frf import POINTS, linear_frf, time_domain_frf

            human = SeatedHuman(person)
            axes = inp.get("axes", ["x", "y", "z"])
            for axis in axes:
                if inp.get("method", "linear") == "time":
                    table = time_domain_frf(human, axis, duration_s=float(inp.get("duration_s", 30.0)),
                                            route=inp.get("route", "nonlinear"))
                    record["simulated_s"] += float(inp.get("duration_s", 30.0))
                else:
                    table = linear_frf(human, axis)
                for p in POINTS:
                    c = table.curve(axis, p, axis)
                    f_pk, g_pk = c.peak((0.3, 12.0))
                    record["outputs"][f"seat_{axis}->{p}_{axis}.peak_hz"] = f_pk
                    record["outputs"][f"seat_{axis}->{p}_{axis}.peak_gain"] = g_pk
        if "comfort" in spec.compute:
            from ..analysis.assessment import assess, needs_rotating_seat

            motion = _drive(inp, params.time_step())
            route = inp.get("route", "auto")  # the hybrid route, as ehm.assess and ehm assess by default
            human = SeatedHuman(person, rotating_seat=needs_rotating_seat(motion, route))
            misc = None
            if inp.get("sickness_params"):
                from ..standards.sickness import read_sickness_params

                misc = read_sickness_params(inp["sickness_params"])
            # one process per drive: the study shares the cores out by drive
            result = assess(motion, human, method=route, sickness_params=misc, workers=1)
            record["simulated_s"] += motion.duration_s
            summary = result.summary()
            for loc, v in summary["locations"].items():
                record["outputs"][f"{loc}.a_v_mps2"] = v["total_value_mps2"]
                for a in "xyz":
                    record["outputs"][f"{loc}.a_w_{a}_mps2"] = v["axes"][a]["a_w_mps2"]
            record["outputs"]["head.msi_percent"] = summary["sickness"]["head"]["final_msi_percent"]
            record["outputs"]["head.misc"] = summary["sickness"]["head"]["final_misc"]
            if "route" in summary:  # the hybrid and linear routes: how much of the drive the linear model carried
                record["outputs"]["route.linear_share"] = summary["route"]["linear_share"]
    except EhmError as exc:
        record["error"] = str(exc)
    except Exception as exc:  # noqa: BLE001 - a failed run is recorded, the study goes on
        record["error"] = f"{type(exc).__name__}: {exc}"
    record["wall_s"] = time.perf_counter() - t0
    return record


#: An output's name -> its location, axis, metric and unit (as :meth:`ehm.Assessment.to_dataframe` names them).
_OUTPUT_NAMES = (
    (re.compile(r"seat_(?P<axis>[xyz])->(?P<location>\w+)_(?P=axis)\.peak_hz"), "peak_frequency", "Hz"),
    (re.compile(r"seat_(?P<axis>[xyz])->(?P<location>\w+)_(?P=axis)\.peak_gain"), "peak_gain", "(m/s^2)/(m/s^2)"),
    (re.compile(r"(?P<location>\w+)\.a_w_(?P<axis>[xyz])_mps2"), "a_w", "m/s^2"),
    (re.compile(r"(?P<location>\w+)\.a_v_mps2"), "total_value", "m/s^2"),
    (re.compile(r"(?P<location>\w+)\.msi_percent"), "msi_final", "%"),
    (re.compile(r"(?P<location>\w+)\.misc"), "misc_final", "MISC"),
    (re.compile(r"route\.linear_share"), "linear_share", "1"),
)


def output_fields(name: str) -> dict:
    """The ``location``, ``axis``, ``metric`` and ``unit`` of an output of the results table (``axis`` ``xyz``
    for the total value and the sickness model; the transmissibility's axis is the seat's and the point's);
    an output of another name is its own metric, without a unit."""
    for pattern, metric, unit in _OUTPUT_NAMES:
        m = pattern.fullmatch(name)
        if m:
            found = m.groupdict()
            return {"location": found.get("location", ""),
                    "axis": found.get("axis", "xyz" if "location" in found else ""), "metric": metric, "unit": unit}
    return {"location": "", "axis": "", "metric": name, "unit": ""}


def _table_rows(records: list[dict]) -> list[dict]:
    rows = []
    for rec in records:
        base = dict(rec["inputs"])
        if rec["error"]:
            rows.append({**base, "output": "error", **output_fields("error"), "value": math.nan, "error": rec["error"]})
        for name, value in rec["outputs"].items():
            rows.append({**base, "output": name, **output_fields(name), "value": float(value), "error": ""})
    return rows


@checked
def read_results(out: Path | str):
    """A study's results table (``OUT/results.parquet``) as a pandas DataFrame, in the shape of
    :meth:`ehm.Assessment.to_dataframe`: one row per run and output, the columns ``run_id``, ``output``,
    ``location``, ``axis``, ``metric``, ``value``, ``unit``, ``error`` (empty, or the failed run's sentence on
    an ``error`` row) and the run's inputs (person, grid values, ``lock``); the folder in ``DataFrame.attrs``.
    A table written by an earlier ehm without ``location`` ... ``unit`` gets them from the output names."""
    from ..outputs.dataframes import frame
    from ..outputs.runfiles import pyarrow_modules

    path = Path(out) / "results.parquet"
    if not path.is_file():
        raise InputError(f"{out}: no results.parquet there; run the study first (ehm batch STUDY --out {out}).")
    _, pq = pyarrow_modules()
    cols = pq.read_table(path).to_pydict()
    if "unit" not in cols:
        fields_ = [output_fields(name) for name in cols["output"]]
        cols.update({k: [f[k] for f in fields_] for k in ("location", "axis", "metric", "unit")})
    first = [c for c in _FIRST_COLUMNS if c in cols]
    ordered = {c: cols[c] for c in first + [c for c in cols if c not in first]}
    return frame(ordered, {"description": f"batch study results in {out}", "source": str(path)})


_FIRST_COLUMNS = ("run_id", "output", "location", "axis", "metric", "value", "unit", "error")


def write_table(records: list[dict], out: Path, csv: bool = False) -> Path:
    """Gather run records into ``results.parquet`` (and ``results.csv``), written whole or not at all."""
    import pyarrow as pa
    import pyarrow.csv as pacsv
    import pyarrow.parquet as pq

    rows = _table_rows(records)
    columns = list(_FIRST_COLUMNS) + sorted({k for r in rows for k in r} - set(_FIRST_COLUMNS))
    table = pa.table({c: [r.get(c) if not isinstance(r.get(c), (list, tuple)) else str(r.get(c)) for r in rows]
                      for c in columns})
    path = out / "results.parquet"
    targets = [(path, lambda tmp: pq.write_table(table, tmp))]
    if csv:
        targets.append((out / "results.csv", lambda tmp: pacsv.write_csv(table, tmp)))
    for target, write in targets:
        write_owned(target, functools.partial(replace_atomically, target, write, "the results table"), out)
    return path


def _needs_run(record_path: Path, spec: RunSpec, retry_failed: bool) -> tuple[bool, list[str]]:
    """Whether a run must (re)run, and which of its inputs changed since its record was made.

    It runs when there is no record yet, the record belongs to other inputs (another fingerprint: those
    inputs are named), its worker was lost, or it failed and retries are asked for.
    """
    if not record_path.exists():
        return True, []
    try:
        rec = json.loads(record_path.read_text(encoding="utf-8"))
        error, run_id = rec.get("error"), rec["inputs"]["run_id"]
    except (OSError, ValueError, AttributeError, KeyError, TypeError):
        return True, []  # an unreadable record is redone
    if run_id != spec.run_id:
        old = rec.get("fingerprint")
        if not isinstance(old, dict):
            return True, ["inputs not recorded by an earlier ehm"]
        return True, [k for k in spec.fingerprint if old.get(k) != spec.fingerprint[k]] or ["run id"]
    return bool(error) and (retry_failed or error.startswith(_LOST_WORKER)), []


_LOST_WORKER = "worker failed: "


def run_study(specs: list[RunSpec], out: Path, scheduler: str | None = None, workers: int | None = None,
              csv: bool = False, progress=None, retry_failed: bool = False) -> dict:
    """Run the specs on Dask (a local cluster of processes, or the cluster at ``scheduler``); returns counts and
    the throughput.

    Runs already recorded in ``out/runs`` are skipped, except those whose worker was lost (always redone)
    and, with ``retry_failed``, those that failed (e.g. after the parameter or study file was fixed).
    ``out`` is a folder of ehm's that is added to (``ehm.outputs.outdir.added_folder``: refused when it holds files
    ehm did not write); every record and table written there is listed in its manifest.  The runs' warnings come
    back with their records and are warned here, each sentence once.  The manifest is written at most about once a
    second while runs end (and when the study ends); a record written after its last writing says which folder it
    belongs to, so a study killed meanwhile resumes with it (``ehm.outputs.outdir.write_owned_json``).
    """
    with added_folder(out, "study's results"):
        runs_dir = out / "runs"
        runs_dir.mkdir(parents=True, exist_ok=True)
        todo, changed, n_changed = [], set(), 0
        for s in specs:
            needed, what = _needs_run(runs_dir / f"{s.point_id}.json", s, retry_failed)
            if needed:
                todo.append(s)
            changed.update(what)
            n_changed += bool(what)
        ran = _run_on_dask(todo, out, scheduler, workers, progress) if todo else {"simulated_s": 0.0, "failed": 0,
                                                                                  "wall_s": 0.0}
        records = [json.loads((runs_dir / f"{s.point_id}.json").read_text()) for s in specs]  # this study's only
        write_table(records, out, csv=csv)
    wall, simulated = ran["wall_s"], ran["simulated_s"]
    return {"runs": len(specs), "ran": len(todo), "skipped": len(specs) - len(todo), "failed": ran["failed"],
            "changed": {"count": n_changed, "inputs": sorted(changed)},
            "wall_s": wall, "simulated_s": simulated,
            "throughput_simulated_s_per_s": simulated / wall if wall > 0 and simulated > 0 else None}


def _run_on_dask(todo: list[RunSpec], out: Path, scheduler, workers, progress) -> dict:
    """Run ``todo`` on Dask, recording each run in ``out/runs`` as it ends; its time, simulated time, failures."""
    from dask.distributed import as_completed

    simulated, failed, shown = 0.0, 0, set()
    with dask_client(scheduler, workers) as client:
        t0 = time.perf_counter()  # throughput excludes starting the cluster
        futures = client.map(run_one, todo, pure=False)
        by_future = dict(zip(futures, todo))
        for done, fut in enumerate(as_completed(futures), start=1):
            spec = by_future[fut]
            try:
                rec = fut.result()
            except Exception as exc:  # noqa: BLE001 - a lost worker is recorded like a failed run
                rec = {"inputs": spec.inputs(), "outputs": {}, "error": f"{_LOST_WORKER}{exc}",
                       "simulated_s": 0.0, "wall_s": 0.0}
            rec["fingerprint"] = spec.fingerprint
            write_owned_json(out / "runs" / f"{spec.point_id}.json", rec, out)  # listed within about a second
            _warn_once(rec.get("warnings", []), shown)
            simulated += rec["simulated_s"]
            failed += rec["error"] is not None
            if progress:
                progress(done, len(todo))
        wall = time.perf_counter() - t0
    return {"simulated_s": simulated, "failed": failed, "wall_s": wall}


def _category_name(category: type) -> str:
    """A warning's category as a record keeps it: ``EhmWarning`` for ehm's own (and its kinds), else the name of
    Python's built-in category (``RuntimeWarning``, ...)."""
    return EhmWarning.__name__ if issubclass(category, EhmWarning) else category.__name__


def _warn_once(caught: list, shown: set) -> None:
    """Warn here the warnings a run caught in its worker (``[category name, sentence]``), each sentence once."""
    for name, text in caught:
        if text not in shown:
            shown.add(text)
            category = EhmWarning if name == EhmWarning.__name__ else getattr(builtins, name, UserWarning)
            warn(text, category if isinstance(category, type) and issubclass(category, Warning)
                 else UserWarning, stacklevel=2)
