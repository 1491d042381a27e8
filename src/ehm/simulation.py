"""The seated human as a Python object: build it, ask about it, shake it, read the results by name.

>>> from ehm import SeatedHuman, random_vibration
>>> human = SeatedHuman()                       # the paper's default person and seat
>>> run = human.simulate(random_vibration("z", duration_s=10, rms_mps2=0.3, seed=0))
>>> run.point("head").acc_mps2[:, 2]            # absolute vertical head acceleration [m/s^2]
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from . import engine
from .errors import InputError
from .motion import Resampler, SeatMotion, seat_kinematics, seat_rotation_matrices
from .params import Parameters
from .tables import Body, load_body, resolve_locks

POINT_NAMES = tuple(engine.POINTS)  #: ``pelvis``, ``trunk`` (upper torso centre of gravity, T8 level), ``head``.


@dataclass(frozen=True)
class PointMotion:
    """Motion of one output point (a segment's centre of gravity).

    Attributes
    ----------
    name : str
        ``pelvis``, ``trunk`` or ``head``.
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
        """The motion of ``pelvis``, ``trunk`` or ``head``."""
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

    def take(self, rows) -> "RunResult":
        """The run at some rows only (a slice or index array; poses left out), e.g. for a figure."""
        pts = {p: PointMotion(p, *(getattr(m, f)[rows] for f in _POINT_FIELDS)) for p, m in self.points.items()}
        return replace(self, time_s=self.time_s[rows], seat_acc_mps2=self.seat_acc_mps2[rows], points=pts,
                       support_N={k: v[rows] for k, v in self.support_N.items()}, poses=None,
                       seat_angles_rad=None if self.seat_angles_rad is None else self.seat_angles_rad[rows])

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

    def write(self, out_dir: Path | str, output_rate_hz: float | None = None, formats=("csv",)) -> dict:
        """Write the run folder ``out_dir`` (``timeseries.csv`` and/or ``.parquet``, ``summary.json``, ``poses.npz``
        when the run has poses) as one unit (:mod:`ehm.outdir`: an earlier run's folder there is replaced whole);
        ``output_rate_hz`` thins the time series (default: every step).  Returns the file paths."""
        from .outdir import RunFolder
        from .runfiles import output_every, write_run

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
    """One :class:`RunResult` from consecutive chunks (as :meth:`SeatedHuman.stream` yields them)."""
    first = chunks[0]
    cat = lambda get: np.concatenate([get(c) for c in chunks])  # noqa: E731
    points = {p: PointMotion(p, *(cat(lambda c, f=f: getattr(c.points[p], f)) for f in _POINT_FIELDS))
              for p in first.points}
    return replace(first, time_s=cat(lambda c: c.time_s), seat_acc_mps2=cat(lambda c: c.seat_acc_mps2), points=points,
                   support_N={k: cat(lambda c, k=k: c.support_N[k]) for k in first.support_N},
                   wall_s=sum(c.wall_s for c in chunks),
                   seat_angles_rad=None if first.seat_angles_rad is None else cat(lambda c: c.seat_angles_rad),
                   poses=None if first.poses is None else {
                       **{k: v for k, v in first.poses.items() if k not in ("time_s", "pos", "quat")},
                       **{k: cat(lambda c, k=k: c.poses[k]) for k in ("time_s", "pos", "quat")}})


class SeatedHuman:
    """One person on one seat, ready to simulate.

    Parameters
    ----------
    params : Parameters, path or None
        Parameter set or TOML file (default: the shipped defaults).
    lock, unlock : iterable of str
        Joints to lock or unlock on top of the body table's defaults (the waist is locked by default).
    body : Body, optional
        Body tables (default: the paper's Tables 1 and 2 and the shipped contact ellipsoids).
    rotating_seat : bool
        Build the seat so that it can rotate (for motions with angular velocity; about 40 % slower).
    size : ehm.scaling.BodySize, optional
        Scale the person (and the seat's fit) to a stature, mass and sitting height.
    dt_s : float, optional
        Time step [s] (default: the parameter file's, 1 ms for the shipped defaults).  A step coarser
        than the one at which the model is converged gives a :class:`ehm.convergence.StepWarning` with the
        error to expect; ``ehm check-step`` measures it.
    """

    def __init__(self, params: Parameters | str | Path | None = None, lock=(), unlock=(),
                 body: Body | None = None, rotating_seat: bool = False, size=None, dt_s: float | None = None):
        from .convergence import warn_if_coarse

        self.body = body if body is not None else load_body()
        self.params = params if isinstance(params, Parameters) else Parameters.load(params)
        if dt_s is not None:
            if not (isinstance(dt_s, (int, float)) and np.isfinite(dt_s) and dt_s > 0):
                raise InputError(f"dt_s must be a positive time step in seconds, not {dt_s!r}.")
            self.params = self.params.with_values({"simulation.dt_s": float(dt_s)})
        warn_if_coarse(float(self.params.value("simulation.dt_s")))
        if size is not None:  # an individual body size (ehm.scaling.BodySize)
            from .scaling import check_buildable, scale_body, scale_params

            body0, params0 = self.body, self.params
            self.body, self.params = scale_body(self.body, size), scale_params(self.params, size, self.body)
            check_buildable(size, body0, params0, self.body, self.params)  # one sentence, with masses that work
        self.size = size
        self.locked = resolve_locks(self.body, lock, unlock)
        self.model = engine.build(self.body, self.params, self.locked, rotating_seat=rotating_seat)
        self._linear = None  # the linear route's model, built on first use (linear_model)

    @property
    def dof(self) -> int:
        """Degrees of freedom of the person (28 by default, 31 with the waist unlocked)."""
        return self.model.dof

    @property
    def mass_kg(self) -> float:
        """Total body mass as built [kg]."""
        return self.model.mass_kg

    def info(self) -> dict:
        """Segments, joints and totals as plain data (what ``ehm info --json`` prints)."""
        return {
            "mass_kg": self.mass_kg,
            "dof": self.dof,
            "locked": sorted(self.locked),
            "dt_s": float(self.params.value("simulation.dt_s")),
            "params": self.params.origin,
            "segments": [{"name": s.name, "mass_kg": s.mass_kg, "com_m": s.com_m.tolist(),
                          "inertia_kgm2": s.inertia_kgm2.tolist()} for s in self.body.segments],
            "joints": [{"name": j.name, "parent": j.parent, "child": j.child, "type": j.type,
                        "dof": 0 if j.name in self.locked else len(j.dofs), "dofs": list(j.dofs),
                        "locked": j.name in self.locked, "pos_m": j.pos_m.tolist(),
                        "axes_pitch_rad": j.axes_pitch_rad} for j in self.body.joints],
            "contacts": [{"name": c.name, "segment": c.segment, "surface": c.surface} for c in self.body.contacts],
            "points": {p: engine.POINTS[p] for p in POINT_NAMES},
        }

    def settle(self) -> None:
        """Let the person sink into the seat (done automatically before the first run)."""
        engine.settle(self.model)

    def linear_model(self):
        """The person linearised at the settled posture, continuous time (:func:`ehm.linear.continuous_model`;
        computed once, about 0.1 s after settling)."""
        if self._linear is None:
            from .linear import continuous_model

            if self.model.seat is not None:
                raise InputError("the linear route models a static seat; build the person without rotating_seat.")
            self._linear = continuous_model(self.model)
        return self._linear

    def simulate(self, motion: SeatMotion, progress=None, pose_rate_hz: float | None = None,
                 method: str = "nonlinear") -> RunResult:
        """Run the settled person with a seat motion.

        ``method="nonlinear"`` (default) steps the MuJoCo model (the motion resampled to the model's time
        step); a motion with angular velocity needs a person built with ``rotating_seat=True``; for long
        drives use :meth:`stream`, which holds one chunk at a time.  ``method="linear"`` runs the person
        linearised at rest (:mod:`ehm.linear`) on the same input as the nonlinear route (the motion resampled
        to the model's step, anti-aliased), exactly discretised: about a
        thousand times faster than real time (about thirty times faster than the nonlinear route), for
        translation inputs small enough that no contact lifts off or slides (checked while it runs:
        :class:`ehm.linear.LinearRouteError` otherwise).
        """
        if method == "linear":
            if not isinstance(motion, SeatMotion):
                raise InputError("simulate() needs a SeatMotion (see ehm.random_vibration, ehm.load_motion_csv).")
            from .linear import simulate_linear

            return simulate_linear(self, motion, dt_s=float(self.model.mj.opt.timestep))
        if method != "nonlinear":
            raise InputError(f"method must be 'nonlinear' or 'linear', not {method!r}.")
        return concatenate_runs(list(self.stream(motion, progress=progress, pose_rate_hz=pose_rate_hz)))

    def simulate_to(self, out_dir: Path | str, motion: SeatMotion, output_rate_hz: float | None = None,
                    formats=("csv",), pose_rate_hz: float | None = 25.0, progress=None, chunk_s: float = 10.0,
                    plot: bool = False, method: str = "nonlinear") -> dict:
        """Run a seat motion and write its run folder while it runs; returns the summary.

        Chunks of ``chunk_s`` go to disk as they are computed (:mod:`ehm.runfiles`), so memory does not grow
        with the motion's length; the folder ``out_dir`` is put in place as one unit when the run has ended
        (:mod:`ehm.outdir`), and a failure or an interrupt leaves an earlier folder there as it was.
        ``output_rate_hz`` thins the time series (it must divide the model's rate; default
        :data:`ehm.runfiles.DEFAULT_OUTPUT_RATE_HZ`, or the nearest whole fraction of the model's rate above it);
        ``formats``: ``"csv"`` and/or ``"parquet"``; ``plot`` also draws ``time_histories.png`` (from at most
        :data:`ehm.runfiles.PREVIEW_ROWS` evenly spread rows).  ``method`` as for :meth:`simulate` (the linear
        route records no poses).
        """
        from .outdir import RunFolder, check_output_folder
        from .runfiles import PREVIEW_ROWS, default_output_every, output_every, pyarrow_modules, write_run

        dt = float(self.model.mj.opt.timestep)
        if method == "linear":
            pose_rate_hz = None
        every = default_output_every(dt) if output_rate_hz is None else output_every(output_rate_hz, dt)
        if "parquet" in formats:
            pyarrow_modules()
        check_output_folder(out_dir)
        n_steps = int(np.floor(motion.duration_s / dt + 1e-9)) + 1 if isinstance(motion, SeatMotion) else None
        with RunFolder(out_dir) as tmp:
            chunks = self.stream(motion, chunk_s=chunk_s, progress=progress, pose_rate_hz=pose_rate_hz, method=method)
            summary, preview = write_run(tmp, chunks, output_every=every, formats=formats,
                                         preview_rows=PREVIEW_ROWS if plot else 0, n_steps=n_steps)
            if plot:
                from .plotting import plot_time_histories

                step = float(preview.time_s[1] - preview.time_s[0]) if len(preview.time_s) > 1 else dt
                title = preview.description + (f" (figure: every {step:g} s)" if step > dt * 1.5 else "")
                plot_time_histories(preview, tmp / "time_histories.png", title=title)
        return summary

    def stream(self, motion: SeatMotion, chunk_s: float = 10.0, progress=None, pose_rate_hz: float | None = None,
               method: str = "nonlinear"):
        """Run a seat motion chunk by chunk; yields one :class:`RunResult` per chunk (absolute times).

        Memory stays constant whatever the motion's length: the motion is resampled onto the model's time
        step (anti-aliased polyphase filter, :class:`ehm.motion.Resampler`) one chunk at a time.
        ``progress(done_s, total_s)`` is called after every chunk.  ``method`` as
        for :meth:`simulate` (both routes take the motion resampled to the model's step; the linear route records
        no poses).
        """
        if not isinstance(motion, SeatMotion):
            raise InputError("simulate() needs a SeatMotion (see ehm.random_vibration, ehm.load_motion_csv).")
        if method == "linear":
            from .linear import stream_linear

            # on the model's step, resampled as the nonlinear route resamples (the same input either way)
            yield from stream_linear(self, motion, chunk_s=chunk_s, progress=progress,
                                     dt_s=float(self.model.mj.opt.timestep))
            return
        if method != "nonlinear":
            raise InputError(f"method must be 'nonlinear' or 'linear', not {method!r}.")
        if motion.angvel_radps is not None and self.model.seat is None:
            raise InputError("this motion rotates the seat (it has angular velocities); build the person with "
                             "SeatedHuman(rotating_seat=True).")
        dt = float(self.model.mj.opt.timestep)
        if dt > motion.duration_s:
            raise InputError(f"the motion lasts {motion.duration_s:g} s, less than one time step ({dt:g} s).")
        rotating = self.model.seat is not None  # a rotating seat without angular velocities stays level
        if rotating:
            angvel = motion.angvel_radps if motion.angvel_radps is not None else np.zeros_like(motion.acc_mps2)
            kin = seat_kinematics(motion.time_s, angvel)
        grid = Resampler.of_motion(motion, dt)  # anti-aliased polyphase resampling, chunk by chunk
        n_total = grid.n_samples
        per_chunk = max(1, int(round(chunk_s / dt)))
        d = engine.settled_data(self.model)
        poses = engine.settled_point_poses(self.model)
        pivot = self.model.seat["pivot"] if rotating else np.zeros(3)
        description = f"{motion.description}, at dt {dt:g} s"
        pose_every = None
        if pose_rate_hz:
            pose_every = max(1, int(round(1.0 / (pose_rate_hz * dt))))
            per_chunk = max(pose_every, per_chunk // pose_every * pose_every)  # chunks hold whole pose periods
            geometry = {f"geometry_{k}": v for k, v in engine.drawing_geometry(self.model).items()}
        for start in range(0, n_total, per_chunk):
            t = np.arange(start, min(n_total, start + per_chunk)) * dt
            acc_seat = grid.block(start, start + t.size)[:, :3]  # from the samples around this chunk only
            if rotating:
                angles, rates, accs = kin.at(t)
                R = seat_rotation_matrices(angles)
                acc_world = np.einsum("nij,nj->ni", R, acc_seat)
                rotation = (angles, rates, accs)
            else:
                R, acc_world, rotation, angles = None, acc_seat, None, None
            t0 = time.perf_counter()
            with engine.captured_warnings():  # MuJoCo's warnings go into ehm's sentences, not raw to the terminal
                raw = engine.run(self.model, acc_world, d=d, seat_rotation=rotation, pose_every=pose_every)
            wall = time.perf_counter() - t0
            result = self._chunk_result(raw, t, acc_seat, R, angles, poses, pivot, wall, description)
            if pose_every:
                result = replace(result, poses={"time_s": t[raw.poses["step"]], "pos": raw.poses["pos"],
                                                "quat": raw.poses["quat"], **geometry})
            yield result
            del raw, result, acc_seat, acc_world, R  # the next chunk is made without this one held here
            if progress:
                progress(min(t[-1] + dt, motion.duration_s), motion.duration_s)

    def _chunk_result(self, raw, t, acc_seat, R, angles, poses, pivot, wall, description) -> RunResult:
        """Engine output -> results in seat axes, relative to the settled posture."""
        to_seat = (lambda v: v) if R is None else (lambda v: np.einsum("nji,nj->ni", R, v))  # R^T v
        seat_rot = None if R is None else Rotation.from_matrix(R)
        points = {}
        for p in POINT_NAMES:
            settled_pos, settled_quat = poses[p]
            world = Rotation.from_quat(raw.sensors[f"{p}_framequat"], scalar_first=True)
            rel = (world if seat_rot is None else seat_rot.inv() * world) * Rotation.from_quat(settled_quat, scalar_first=True).inv()
            acc_world = raw.sensors[f"{p}_acc"]
            points[p] = PointMotion(
                name=p,
                acc_mps2=to_seat(acc_world),
                disp_m=to_seat(raw.sensors[f"{p}_framepos"] - pivot) - (settled_pos - pivot),
                rot_rad=rel.as_euler("ZYX")[:, ::-1].copy(),
                angacc_radps2=to_seat(raw.sensors[f"{p}_angacc"]),
                angvel_radps=world.inv().apply(raw.sensors[f"{p}_frameangvel"]),
                gia_mps2=world.inv().apply(acc_world - engine.G0[None, :]),
            )
        support = {group: to_seat(sum(raw.support_N[s] for s in surfaces if s in raw.support_N))
                   for group, surfaces in engine.SUPPORT_GROUPS.items()}
        return RunResult(time_s=t, seat_acc_mps2=acc_seat, points=points, support_N=support, mass_kg=self.mass_kg,
                         dof=self.dof, dt_s=float(self.model.mj.opt.timestep), wall_s=wall, description=description,
                         locked=tuple(sorted(self.locked)), params_origin=self.params.origin, seat_angles_rad=angles)
