"""The nonlinear route: the MuJoCo model stepped through a drive chunk by chunk, each chunk's engine output turned
into a :class:`ehm.outputs.results.RunResult` in seat axes (:func:`stream`, :func:`stream_span`, :func:`chunk_result`).

The motion is resampled onto the model's time step (anti-aliased polyphase filter,
:class:`ehm.inputs.resampling.Resampler`) one chunk at a time, so memory stays constant whatever the drive's length.  A
divergence is told with its likely cause when the seat input before it is out of the ordinary
(:func:`with_input_cause`).
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
from scipy.spatial.transform import Rotation

from .. import engine
from ..errors import DivergenceError, InputError
from ..inputs.imu import STANDARD_GRAVITY_MPS2
from ..inputs.motion import Resampler, SeatMotion, seat_kinematics, seat_rotation_matrices
from ..outputs.results import POINT_NAMES, PointMotion, RunResult
from .built import BuiltPerson, built_of


def stream(person, motion: SeatMotion, chunk_s: float = 10.0, progress=None, pose_rate_hz: float | None = None):
    """The nonlinear route over the whole of ``motion``: one :class:`~ehm.RunResult` per chunk of ``chunk_s`` (absolute
    times), after the checks of :meth:`~ehm.routes.built.BuiltPerson.check_nonlinear_motion`.  ``person``: a
    :class:`~ehm.routes.built.BuiltPerson` (or a :class:`ehm.SeatedHuman`, whose is taken)."""
    person = built_of(person)
    person.check_nonlinear_motion(motion)
    yield from stream_span(person, motion, chunk_s=chunk_s, progress=progress, pose_rate_hz=pose_rate_hz)


def stream_span(person: BuiltPerson, motion: SeatMotion, first: int = 0, stop: int | None = None,
                lead_steps: int = 0, chunk_s: float = 10.0, progress=None, pose_rate_hz: float | None = None,
                ramp: bool = False):
    """The nonlinear route over grid steps ``first`` ... ``stop - 1`` of the motion resampled to the model's
    step (default: all of it), yielding one :class:`~ehm.RunResult` per chunk of ``chunk_s`` from ``first``.

    With ``first`` > 0 the person starts from the settled rest ``lead_steps`` steps before ``first`` (at most
    at the motion's start) and is run with the motion's own input over that lead-in, which is not yielded
    (:mod:`ehm.routes.parallel`).  A rotating seat starts level there: its yaw is offset by the yaw at the lead-in's
    start (a rotation about the vertical changes nothing in seat axes), and its pitch and roll at the
    lead-in's start are faded in over the lead-in (a quintic smoothstep); from ``first`` on the seat's
    attitude is the continuous run's.  ``ramp`` also fades the translational input in over the lead-in.
    ``progress(done_s, total_s)`` after every yielded chunk.  The checks are :func:`stream`'s (made by the
    caller).
    """
    dt = float(person.model.mj.opt.timestep)
    rotating = person.model.seat is not None  # a rotating seat without angular velocities stays level
    if rotating:
        angvel = motion.angvel_radps if motion.angvel_radps is not None else np.zeros_like(motion.acc_mps2)
        kin = seat_kinematics(motion.time_s, angvel)
    grid = Resampler.of_motion(motion, dt)  # anti-aliased polyphase resampling, chunk by chunk
    n_total = grid.n_samples if stop is None else min(stop, grid.n_samples)
    per_chunk = max(1, int(round(chunk_s / dt)))
    d = engine.settled_data(person.model)
    poses = engine.settled_point_poses(person.model)
    pivot = person.model.seat["pivot"] if rotating else np.zeros(3)
    description = f"{motion.description}, at dt {dt:g} s"
    pose_every = None
    if pose_rate_hz:
        pose_every = max(1, int(round(1.0 / (pose_rate_hz * dt))))
        per_chunk = max(pose_every, per_chunk // pose_every * pose_every)  # chunks hold whole pose periods
        geometry = {f"geometry_{k}": v for k, v in engine.drawing_geometry(person.model).items()}
    lead = _LeadIn(max(0, first - lead_steps), first, dt, kin if rotating else None, ramp)
    if lead.steps:
        d.time = lead.start * dt  # where the divergence check's sentences count from
        lead.start_seat(person.model, d)
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
                raw = engine.run(person.model, acc_world, d=d, seat_rotation=rotation,
                                 pose_every=pose_every if start >= first else None)
        except DivergenceError as exc:
            raise with_input_cause(exc, motion, t[-1] + dt) from None
        if start < first:  # the lead-in: only its end state goes on
            del raw
            continue
        wall = time.perf_counter() - t0
        result = chunk_result(person, raw, t, acc_seat, R, angles, poses, pivot, wall, description)
        if pose_every:
            result = replace(result, poses={"time_s": t[raw.poses["step"]], "pos": raw.poses["pos"],
                                            "quat": raw.poses["quat"], **geometry})
        yield result
        del raw, result, acc_seat, acc_world, R  # the next chunk is made without this one held here
        if progress:
            progress(min(t[-1] + dt, motion.duration_s), motion.duration_s)

def chunk_result(person: BuiltPerson, raw, t, acc_seat, R, angles, poses, pivot, wall, description) -> RunResult:
    """Engine output -> results in seat axes, relative to the settled posture."""
    to_seat = (lambda v: v) if R is None else (lambda v: np.einsum("nji,nj->ni", R, v))  # R^T v
    seat_rot = None if R is None else Rotation.from_matrix(R)
    points = {}
    for p in POINT_NAMES:
        settled_pos, settled_quat = poses[p]
        world = Rotation.from_quat(raw.sensors[f"{p}_framequat"], scalar_first=True)
        in_seat = world if seat_rot is None else seat_rot.inv() * world
        rel = in_seat * Rotation.from_quat(settled_quat, scalar_first=True).inv()
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
    return RunResult(time_s=t, seat_acc_mps2=acc_seat, points=points, support_N=support, mass_kg=person.mass_kg,
                     dof=person.dof, dt_s=float(person.model.mj.opt.timestep), wall_s=wall, description=description,
                     locked=tuple(sorted(person.locked)), params_origin=person.params.origin, seat_angles_rad=angles)


class _LeadIn:
    """A segment's lead-in, grid steps ``start`` ... ``first - 1`` (none when they are equal): what the run does
    differently there from the continuous run (:func:`stream_span`)."""

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


def with_input_cause(exc: DivergenceError, motion: SeatMotion, ran_s: float) -> DivergenceError:
    """``_input_cause``, once: an error it has already seen passes as it is (a route that runs another inside
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

