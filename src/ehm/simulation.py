"""The seated human as a Python object: build it, ask about it, shake it, read the results by name.

>>> from ehm import SeatedHuman, random_vibration
>>> human = SeatedHuman()                       # the paper's default person and seat
>>> run = human.simulate(random_vibration("z", duration_s=10, rms_mps2=0.3, seed=0))
>>> head_z = run.point("head").acc_mps2[:, 2]   # absolute vertical head acceleration [m/s^2]
>>> head_z.shape                                # 10 s at the default 1 ms step
(10001,)
>>> print(f"{(head_z ** 2).mean() ** 0.5:.2f} m/s^2 rms")
0.39 m/s^2 rms
"""

from __future__ import annotations

import math
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from . import engine
from .errors import DivergenceError, InputError
from .imu import STANDARD_GRAVITY_MPS2
from .motion import Resampler, SeatMotion, require_motion, seat_kinematics, seat_rotation_matrices
from .params import Parameters
from .results import (  # noqa: F401 - POINT_NAMES, PointMotion, concatenate_runs: also importable from here
    POINT_NAMES,
    PointMotion,
    RunResult,
    concatenate_runs,
)
from .tables import Body, load_body, resolve_locks
from .timestep import warn_if_coarse


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
        Time step [s].  Default: the parameter file's ``simulation.dt_s`` when the file sets its own, else the
        posture's own converged step when it has one (the shipped ``slouched``: 0.5 ms), else the shipped 1 ms
        (:meth:`ehm.Parameters.time_step`); the person's ``params`` record the step it runs at.  A step coarser
        than the one at which the person in its posture is converged gives a :class:`ehm.timestep.StepWarning`
        with the error to expect; ``ehm check-step`` measures it.
    posture, back_support : str, optional
        The reference posture (``"erect"``, the default, ``"slouched"``, or one the parameter file defines;
        :mod:`ehm.posture`) and the seat's back support (``"none"``, ``"low"``, ``"high"``, the default, or
        ``"full"``; :mod:`ehm.seat`).  None: the parameter file's (``posture.name``, ``seat.back_support``); the
        person's ``params`` record them.
    head_control : bool or dict, optional
        Head-in-space control on top of the joint PID (``ehm.engine.control``, docs/model.md "Head-in-space
        control"): True with the parameter file's gains ([head_control]), a dict of gains (e.g.
        ``{"tilt_stiffness_Nm_per_rad": 30.0, "delay_s": 0.03}``) to switch it on with those, False off; None (the
        default) keeps the file's ``head_control.enabled`` (off in the shipped file).
    """

    def __init__(self, params: Parameters | str | Path | None = None, lock=(), unlock=(),
                 body: Body | None = None, rotating_seat: bool = False, size=None, dt_s: float | None = None,
                 posture: str | None = None, back_support: str | None = None, head_control=None):
        self.body = body if body is not None else load_body()
        self.params = params if isinstance(params, Parameters) else Parameters.load(params)
        self.params = self.params.seated(posture, back_support).with_head_control(head_control)
        self.params = self.params.at_step(dt_s)
        warn_if_coarse(float(self.params.value("simulation.dt_s")), converged_s=self.params.converged_step(),
                       posture=self.params.posture)
        if size is not None:  # an individual body size (ehm.scaling.BodySize)
            from .scaling import check_buildable, scale_body, scale_params

            body0, params0 = self.body, self.params
            self.body, self.params = scale_body(self.body, size), scale_params(self.params, size, self.body)
            check_buildable(size, body0, params0, self.body, self.params)  # one sentence, with masses that work
        self.size = size
        self.locked = resolve_locks(self.body, lock, unlock)
        self.model = engine.build(self.body, self.params, self.locked, rotating_seat=rotating_seat)
        self._linear = {}  # the linear route's models (translation, rotation), built on first use (linear_model)
        self._static_model = None  # a rotating seat's person on a static seat, for the linearisation

    def recipe(self) -> dict:
        """What rebuilds this person in another process (:meth:`from_recipe`), as plain picklable data: the body
        tables and parameters as built (scaled, with the time step), the locked joints, the seat kind, the body
        size, and the settled state when the person has settled (so that a rebuilt person need not settle again:
        settling is deterministic, so this is the state it would reach)."""
        settled = self.model.settled
        return {"body": self.body, "params": self.params, "locked": frozenset(self.locked),
                "rotating_seat": self.model.seat is not None, "size": self.size,
                "settled": None if settled is None else {k: (v.copy() if isinstance(v, np.ndarray) else v)
                                                         for k, v in settled.items()}}

    @classmethod
    def from_recipe(cls, recipe: dict) -> SeatedHuman:
        """The person of :meth:`recipe`, built anew (the same MuJoCo model, and settled if it was)."""
        human = cls.__new__(cls)
        human.body, human.params, human.size = recipe["body"], recipe["params"], recipe["size"]
        human.locked = frozenset(recipe["locked"])
        human.model = engine.build(human.body, human.params, human.locked, rotating_seat=recipe["rotating_seat"])
        human._linear, human._static_model = {}, None
        if recipe.get("settled") is not None:
            human.model.settled = {k: (v.copy() if isinstance(v, np.ndarray) else v)
                                   for k, v in recipe["settled"].items()}
        return human

    @property
    def head_control(self) -> bool:
        """Whether the person's head-in-space control is on (``ehm.engine.control``)."""
        return self.model.head_control is not None

    @property
    def dof(self) -> int:
        """Degrees of freedom of the person (28 by default, 31 with the waist unlocked)."""
        return self.model.dof

    @property
    def mass_kg(self) -> float:
        """Total body mass as built [kg]."""
        return self.model.mass_kg

    def info(self) -> dict:
        """Segments, joints and totals as plain data (what ``ehm info --json`` prints), in the person's posture."""
        body = self.model.body  # the tables in the posture, with the back support's contacts
        return {
            "mass_kg": self.mass_kg,
            "dof": self.dof,
            "locked": sorted(self.locked),
            "dt_s": float(self.params.value("simulation.dt_s")),
            "params": self.params.origin,
            "posture": self.params.posture,
            "back_support": self.params.back_support,
            "segments": [{"name": s.name, "mass_kg": s.mass_kg, "com_m": s.com_m.tolist(),
                          "inertia_kgm2": s.inertia_kgm2.tolist()} for s in body.segments],
            "joints": [{"name": j.name, "parent": j.parent, "child": j.child, "type": j.type,
                        "dof": 0 if j.name in self.locked else len(j.dofs), "dofs": list(j.dofs),
                        "locked": j.name in self.locked, "pos_m": j.pos_m.tolist(),
                        "axes_pitch_rad": j.axes_pitch_rad} for j in body.joints],
            "contacts": [{"name": c.name, "segment": c.segment, "surface": c.surface} for c in body.contacts],
            "points": {p: engine.POINTS[p] for p in POINT_NAMES},  # point -> its segment
            "point_joints": dict(engine.POINT_JOINTS),  # a point at a joint's centre (else the segment's COG)
        }

    def settle(self) -> None:
        """Let the person sink into the seat (done automatically before the first run)."""
        engine.settle(self.model)

    def linear_model(self, rotation: bool = False):
        """The person linearised at the settled posture, continuous time (:func:`ehm.linear.continuous_model`;
        computed once, about 0.1 s after settling).

        Parameters
        ----------
        rotation : bool
            False: the model of seat translation (three inputs, the seat's acceleration).  True: with the
            seat's rotation about its pivot (``ehm.engine.seat_pivot``) in the seat's own frame, twelve
            inputs (see :func:`ehm.linear.stream_linear`), what a motion with angular velocities runs on.

        Both are linearised on the person on a static seat: for a person built with ``rotating_seat=True`` a
        static-seat build of the same person is made (and settled) once for it.
        """
        key = "rotation" if rotation else "translation"
        if key not in self._linear:
            from .linear import continuous_model

            model = self.model
            if model.seat is not None:  # the linearisation is in the seat's frame: the static seat's model
                if self._static_model is None:
                    self._static_model = engine.build(self.body, self.params, self.locked, rotating_seat=False)
                model = self._static_model
            self._linear[key] = continuous_model(model, pivot_m=engine.seat_pivot(model) if rotation else None)
        return self._linear[key]

    def simulate(self, motion: SeatMotion, progress=None, pose_rate_hz: float | None = None,
                 method: str = "auto", tolerance: float | None = None) -> RunResult:
        """Run the settled person with a seat motion.

        ``method="auto"`` (the default, as for :func:`ehm.assess`, ``ehm simulate`` and ``ehm assess``) is the
        hybrid route, described below: the linear model where the contacts stick, the nonlinear one where they
        slide or lift off, checked at every step.  ``method="nonlinear"`` steps the MuJoCo model throughout (the
        motion resampled to the model's time step); a motion with angular velocity needs a person built with
        ``rotating_seat=True``.  For long drives use :meth:`stream`, which holds one chunk at a time.

        ``method="linear"`` runs the person linearised at rest (:mod:`ehm.linear`) on the same input (the
        motion resampled to the model's step, anti-aliased), exactly discretised, about a thousand times
        faster than real time, and checks it by its effect (:mod:`ehm.hybrid`): wherever a contact reaches its
        friction limit or lifts off, the nonlinear model runs too and the two answers are compared; above
        ``tolerance`` (share of each point acceleration's rms, default 1 %) it warns
        (:class:`ehm.hybrid.LinearRouteWarning`) with the figure.  ``method="auto"`` (the hybrid route) keeps the
        nonlinear answer in those windows and the linear one elsewhere.  Both record what they checked in
        ``result.extra["route"]`` (:class:`ehm.hybrid.RouteReport`).  Every route records the segments' poses at
        ``pose_rate_hz`` when asked (for ``ehm.animation``; the linear pieces through the model's kinematics,
        :mod:`ehm.linear_poses`).  A motion that rotates
        the seat runs on the linear model of the seat's rotation in the seat's own frame (whether or not the
        person was built with ``rotating_seat=True``): see :func:`ehm.linear.stream_linear` for what it assumes;
        its estimate of the terms it leaves out is in ``result.extra["linear_check"]``.
        """
        return concatenate_runs(list(self.stream(motion, progress=progress, method=method, tolerance=tolerance,
                                                 pose_rate_hz=pose_rate_hz)))

    def simulate_to(self, out_dir: Path | str, motion: SeatMotion, output_rate_hz: float | None = None,
                    formats=("csv",), pose_rate_hz: float | None = 25.0, progress=None, chunk_s: float = 10.0,
                    plot=None, method: str = "auto", tolerance: float | None = None, chunks=None) -> dict:
        """Run a seat motion and write its run folder while it runs; returns the summary.

        Chunks of ``chunk_s`` go to disk as they are computed (:mod:`ehm.runfiles`), so memory does not grow
        with the motion's length; the folder ``out_dir`` is put in place as one unit when the run has ended
        (:mod:`ehm.outdir`), and a failure or an interrupt leaves an earlier folder there as it was.
        ``output_rate_hz`` thins the time series (it must divide the model's rate; default
        :data:`ehm.runfiles.DEFAULT_OUTPUT_RATE_HZ`, or the nearest whole fraction of the model's rate above it);
        ``formats``: ``"csv"`` and/or ``"parquet"``.  ``method`` and ``tolerance`` as for :meth:`simulate` (every
        route records poses at ``pose_rate_hz``).

        ``plot`` draws figures into the folder before it is put in place: a callable ``plot(preview, folder)``
        that gets a :class:`RunResult` of at most :data:`ehm.runfiles.PREVIEW_ROWS` evenly spread rows and the
        folder being written, e.g. ``ehm.plotting.plot_run_preview`` (``time_histories.png``).  Computing
        and drawing stay apart: this module does not import matplotlib.

        ``chunks``: the run's chunks made elsewhere, in order (e.g. :func:`ehm.segments.stream_parallel` with the
        same ``chunk_s`` and ``pose_rate_hz``), written instead of this person's own :meth:`stream`.
        """
        from .outdir import RunFolder, check_output_folder
        from .runfiles import PREVIEW_ROWS, default_output_every, output_every, pyarrow_modules, write_run

        if plot is not None and plot is not False and not callable(plot):
            raise InputError("plot must be a function plot(preview, folder), e.g. ehm.plotting.plot_run_preview; "
                             "simulate_to does not draw by itself.")
        dt = float(self.model.mj.opt.timestep)
        every = default_output_every(dt) if output_rate_hz is None else output_every(output_rate_hz, dt)
        if "parquet" in formats:
            pyarrow_modules()
        check_output_folder(out_dir)
        n_steps = int(np.floor(motion.duration_s / dt + 1e-9)) + 1 if isinstance(motion, SeatMotion) else None
        with RunFolder(out_dir) as tmp:
            if chunks is None:
                chunks = self.stream(motion, chunk_s=chunk_s, progress=progress, pose_rate_hz=pose_rate_hz,
                                     method=method, tolerance=tolerance)
            summary, pieces = write_run(tmp, chunks, output_every=every, formats=formats,
                                        preview_rows=PREVIEW_ROWS if plot else 0, n_steps=n_steps)
            if plot and pieces:
                plot(concatenate_runs(pieces), tmp)
        return summary

    def stream(self, motion: SeatMotion, chunk_s: float = 10.0, progress=None, pose_rate_hz: float | None = None,
               method: str = "auto", tolerance: float | None = None):
        """Run a seat motion chunk by chunk; yields one :class:`RunResult` per chunk (absolute times).

        Memory stays constant whatever the motion's length: the motion is resampled onto the model's time
        step (anti-aliased polyphase filter, :class:`ehm.resampling.Resampler`) one chunk at a time.
        ``progress(done_s, total_s)`` is called after every chunk.  ``method`` as
        for :meth:`simulate` (default ``"auto"``, the hybrid route; every route takes the motion resampled to the
        model's step).
        """
        require_motion("simulate()", motion)
        if method in ("linear", "auto"):
            from .hybrid import TOLERANCE, stream_checked

            # on the model's step, resampled as the nonlinear route resamples (the same input either way)
            try:
                yield from stream_checked(self, motion, method=method, chunk_s=chunk_s, progress=progress,
                                          tolerance=TOLERANCE if tolerance is None else tolerance,
                                          pose_rate_hz=pose_rate_hz)
            except DivergenceError as exc:
                raise _with_input_cause(exc, motion, motion.duration_s) from None
            return
        if method != "nonlinear":
            raise InputError(f"method must be 'nonlinear', 'linear' or 'auto', not {method!r}.")
        self.check_nonlinear_motion(motion)
        yield from self._stream_span(motion, chunk_s=chunk_s, progress=progress, pose_rate_hz=pose_rate_hz)

    def check_nonlinear_motion(self, motion: SeatMotion) -> float:
        """Refuse, in one sentence, a motion the nonlinear model cannot run on this person: one that turns the seat
        of a person built without ``rotating_seat=True``, or one shorter than a time step; returns the step [s]."""
        if motion.angvel_radps is not None and self.model.seat is None:
            raise InputError("this motion rotates the seat (it has angular velocities); build the person with "
                             "SeatedHuman(rotating_seat=True).")
        dt = float(self.model.mj.opt.timestep)
        if dt > motion.duration_s:
            raise InputError(f"the motion lasts {motion.duration_s:g} s, less than one time step ({dt:g} s).")
        return dt

    def _stream_span(self, motion: SeatMotion, first: int = 0, stop: int | None = None, lead_steps: int = 0,
                     chunk_s: float = 10.0, progress=None, pose_rate_hz: float | None = None, ramp: bool = False):
        """The nonlinear route over grid steps ``first`` ... ``stop - 1`` of the motion resampled to the model's
        step (default: all of it), yielding one :class:`RunResult` per chunk of ``chunk_s`` from ``first``.

        With ``first`` > 0 the person starts from the settled rest ``lead_steps`` steps before ``first`` (at most
        at the motion's start) and is run with the motion's own input over that lead-in, which is not yielded
        (:mod:`ehm.segments`).  A rotating seat starts level there: its yaw is offset by the yaw at the lead-in's
        start (a rotation about the vertical changes nothing in seat axes), and its pitch and roll at the
        lead-in's start are faded in over the lead-in (a quintic smoothstep); from ``first`` on the seat's
        attitude is the continuous run's.  ``ramp`` also fades the translational input in over the lead-in.
        ``progress(done_s, total_s)`` after every yielded chunk.  The checks are :meth:`stream`'s.
        """
        dt = float(self.model.mj.opt.timestep)
        rotating = self.model.seat is not None  # a rotating seat without angular velocities stays level
        if rotating:
            angvel = motion.angvel_radps if motion.angvel_radps is not None else np.zeros_like(motion.acc_mps2)
            kin = seat_kinematics(motion.time_s, angvel)
        grid = Resampler.of_motion(motion, dt)  # anti-aliased polyphase resampling, chunk by chunk
        n_total = grid.n_samples if stop is None else min(stop, grid.n_samples)
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
        lead = _LeadIn(max(0, first - lead_steps), first, dt, kin if rotating else None, ramp)
        if lead.steps:
            d.time = lead.start * dt  # where the divergence check's sentences count from
            lead.start_seat(self.model, d)
        for start in list(range(lead.start, first, per_chunk)) + list(range(first, n_total, per_chunk)):
            t = np.arange(start, min(first if start < first else n_total, start + per_chunk)) * dt
            acc_seat = grid.block(start, start + t.size)[:, :3]  # from the samples around this chunk only
            if rotating:
                angles, rates, accs = kin.at(t)
                run_angles, rates, accs = lead.seat(t, angles, rates, accs)
                R = seat_rotation_matrices(run_angles)
                acc_world = np.einsum("nij,nj->ni", R, lead.fade(t, acc_seat))
                rotation = (run_angles, rates, accs)
            else:
                R, acc_world, rotation, angles = None, lead.fade(t, acc_seat), None, None
            t0 = time.perf_counter()
            try:
                with engine.captured_warnings():  # MuJoCo's warnings go into ehm's sentences, not raw to the terminal
                    raw = engine.run(self.model, acc_world, d=d, seat_rotation=rotation,
                                     pose_every=pose_every if start >= first else None)
            except DivergenceError as exc:
                raise _with_input_cause(exc, motion, t[-1] + dt) from None
            if start < first:  # the lead-in: only its end state goes on
                del raw
                continue
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
                   if any(s in raw.support_N for s in surfaces) else np.zeros((t.size, 3))  # no backrest
                   for group, surfaces in engine.SUPPORT_GROUPS.items()}
        return RunResult(time_s=t, seat_acc_mps2=acc_seat, points=points, support_N=support, mass_kg=self.mass_kg,
                         dof=self.dof, dt_s=float(self.model.mj.opt.timestep), wall_s=wall, description=description,
                         locked=tuple(sorted(self.locked)), params_origin=self.params.origin, seat_angles_rad=angles)


class _LeadIn:
    """A segment's lead-in, grid steps ``start`` ... ``first - 1`` (none when they are equal): what the run does
    differently there from the continuous run (:meth:`SeatedHuman._stream_span`)."""

    def __init__(self, start: int, first: int, dt: float, kin, ramp: bool):
        self.start, self.steps, self.dt, self.ramp = start, first - start, dt, ramp
        self.t0, self.length_s, self.kin = start * dt, (first - start) * dt, kin
        if kin is not None and self.steps:
            a0 = kin.at(np.array([self.t0]))[0][0]
            self.yaw0, self.tilt0 = float(a0[0]), np.array([0.0, a0[1], a0[2]])
        else:
            self.yaw0, self.tilt0 = 0.0, np.zeros(3)

    def _smooth(self, t: np.ndarray):
        """Quintic smoothstep r(t) from 0 at the lead-in's start to 1 at its end, and r', r''."""
        if not self.steps:
            one = np.ones_like(t)
            return one, 0 * one, 0 * one
        L = self.length_s
        x = np.clip((t - self.t0) / L, 0.0, 1.0)
        inside = (x > 0) & (x < 1)
        r = x ** 3 * (10 - 15 * x + 6 * x ** 2)
        r1 = np.where(inside, 30 * x ** 2 * (1 - x) ** 2 / L, 0.0)
        r2 = np.where(inside, 60 * x * (1 - x) * (1 - 2 * x) / L ** 2, 0.0)
        return r, r1, r2

    def fade(self, t: np.ndarray, acc: np.ndarray) -> np.ndarray:
        """The translational input, faded in over the lead-in when asked to."""
        if not (self.ramp and self.steps) or t[0] >= self.t0 + self.length_s:
            return acc
        return acc * self._smooth(t)[0][:, None]

    def seat(self, t: np.ndarray, angles: np.ndarray, rates: np.ndarray, accs: np.ndarray):
        """The seat's driven angles, rates and accelerations: level at the lead-in's start (yaw offset, pitch and
        roll faded in), the continuous run's but for a constant yaw offset from the lead-in's end on."""
        if not self.steps:
            return angles, rates, accs
        r, r1, r2 = self._smooth(t)
        offset = np.array([self.yaw0, 0.0, 0.0])[None, :] + (1 - r)[:, None] * self.tilt0[None, :]
        return angles - offset, rates + r1[:, None] * self.tilt0, accs + r2[:, None] * self.tilt0

    def start_seat(self, model, d) -> None:
        """Put the seat's hinges at the lead-in's first angles and rates (level, moving with the drive)."""
        if model.seat is None or self.kin is None:
            return
        # the level seat turning at the drive's rates; the person, at rest on it, is carried along by the contacts
        t = np.array([self.t0])
        angles, rates, _ = self.seat(t, *self.kin.at(t))
        engine.set_seat(model, d, angles[0], rates[0])


#: A seat input beyond this [m/s^2] (2 g) is out of the ordinary for a vehicle: a sensor handled or knocked.
UNUSUAL_ACC_MPS2 = 2 * STANDARD_GRAVITY_MPS2
#: A change between two samples beyond this [m/s^2] (1 g) is a jump, not a vehicle's motion.
UNUSUAL_JUMP_MPS2 = STANDARD_GRAVITY_MPS2
#: A seat rolled or pitched beyond this [deg] is out of the ordinary: the unbelted person is held by friction
#: (0.5 by default: it holds on a flat pan up to 27 deg) and the seat's bolsters, and slides off beyond.
UNUSUAL_TILT_DEG = 30.0


def _with_input_cause(exc: DivergenceError, motion: SeatMotion, ran_s: float) -> DivergenceError:
    """:func:`_input_cause`, once: an error it has already seen passes as it is (a route that runs another inside
    it, as the hybrid route runs the nonlinear one from a drive's start, would otherwise name the input twice)."""
    if getattr(exc, "input_checked", False):
        return exc
    out = _input_cause(exc, motion, ran_s)
    out.input_checked = True
    return out


def _input_cause(exc: DivergenceError, motion: SeatMotion, ran_s: float) -> DivergenceError:
    """The divergence sentence naming the input as its cause when the seat input before the divergence is out of
    the ordinary (above 2 g, a jump of 1 g between two samples, or a seat tilted beyond 30 deg); the sentence as
    it was otherwise (then the time step or the parameters are the suspects).  ``ran_s``: how far the run got
    [s from the motion's first sample]; the divergence's own time (``exc.time_s``), where it has one, is nearer
    (only the input before it is the suspect, not what follows)."""
    until_s = float(motion.time_s[0]) + (ran_s if exc.time_s is None else min(ran_s, exc.time_s))
    n = int(np.searchsorted(motion.time_s, until_s, side="right"))
    acc = motion.acc_mps2[:n]
    if acc.shape[0] < 2:
        return exc
    size = np.linalg.norm(acc, axis=1)
    jump = np.r_[0.0, np.linalg.norm(np.diff(acc, axis=0), axis=1)]
    bad = np.flatnonzero((size > UNUSUAL_ACC_MPS2) | (jump > UNUSUAL_JUMP_MPS2))
    tilted = _tilted(motion, n)
    where = str(exc).split(" (", 1)[0]
    if tilted is not None and (bad.size == 0 or tilted[0] <= bad[0]):
        k, what, angle = tilted
        return DivergenceError(
            f"{where}: the seat input is out of the ordinary before it (the seat is {what} beyond "
            f"{UNUSUAL_TILT_DEG:g} deg from t = {motion.time_s[k]:.3f} s, up to {angle:.0f} deg, further than "
            "friction and bolsters hold an unbelted person): check that the sensor was fixed to the seat and its "
            "mounting (--mounting), or cut the log (--start, --end).")
    if bad.size == 0:
        return exc
    i = int(bad[0])
    what = (f"{size[i]:.3g} m/s^2, above 2 g" if size[i] > UNUSUAL_ACC_MPS2
            else f"a jump of {jump[i]:.3g} m/s^2 from one sample to the next")
    last = float(motion.time_s[int(bad[-1])])
    cut = math.ceil(last - float(motion.time_s[0]) + 1.0)  # a cut counts from the first sample
    fix = (f"cut it away with --start {cut:g} (start_s= in read_motion; counted from the log's first sample, so add "
           f"any --start given already), or check the log's units" if cut < motion.duration_s
           else "check the log's units and what the sensor was fixed to")
    return DivergenceError(f"{where}: the seat input is out of the ordinary before it ({what} at t = "
                           f"{motion.time_s[i]:.3f} s; the last such sample at {last:.3f} s), e.g. a sensor being put "
                           f"in place or knocked; {fix}.")


def _tilted(motion: SeatMotion, n: int):
    """(sample, "rolled" or "pitched", largest angle [deg]): where the seat's first n samples first tilt beyond
    :data:`UNUSUAL_TILT_DEG`, and how far they tilt about that axis; None if they do not (also for a motion that
    does not turn the seat)."""
    if motion.angvel_radps is None or n < 2:
        return None
    try:
        angles = np.degrees(seat_kinematics(motion.time_s[:n], motion.angvel_radps[:n]).angles_rad)
    except InputError:  # pitch beyond 80 deg: the seat tilts out of the ordinary, and further than told here
        return None
    over = np.flatnonzero((np.abs(angles[:, 1]) > UNUSUAL_TILT_DEG) | (np.abs(angles[:, 2]) > UNUSUAL_TILT_DEG))
    if over.size == 0:
        return None
    k = int(over[0])
    j, what = (2, "rolled") if abs(angles[k, 2]) > UNUSUAL_TILT_DEG else (1, "pitched")
    return k, what, float(angles[np.argmax(np.abs(angles[:, j])), j])

