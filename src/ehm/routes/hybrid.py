"""The checked linear route and the hybrid route: the linear model where the contacts hold, the nonlinear
model where they approach their limits, with the state handed over between them.

The linear route (:mod:`ehm.routes.linear`) is exact for the model linearised at rest, and the nonlinear model stays
close to it as long as every touching contact keeps pressing and stays inside its friction cone.  Instead of
refusing a whole drive the first time a contact reaches its Coulomb limit, this module judges the linear
route by its effect:

1. The linear model runs a chunk ahead and marks every sample where a contact passes its Coulomb limit
   (:data:`NEAR_LIMIT`: tangential force over mu times normal force) or lifts off.
2. Each marked stretch becomes a *window*: it opens :data:`LEAD_S` before the first marked sample and
   closes once no sample has been marked for :data:`QUIET_S`.  The nonlinear model (MuJoCo) runs through the
   window, starting from the linear model's state at the window's start (positions, velocities and
   integral actions: :func:`ehm.routes.linear.state_of`, ``ehm.engine.data_at_deviation``), so it needs no
   settling lead-in.  Where a window leaves the body (where it sits and turns on the seat, the preload of a pad
   that stuck while its segment moved: directions the seat's acceleration does not drive, which the linear
   time run leaves out) is carried on as a constant offset of the linear model's state and outputs.  A person with
   the head-in-space control carries its delay across: the law's torques of the last N samples (from the linear
   model's sensed outputs, or the nonlinear model's sensors) fill the nonlinear model's delay line at a window's
   start (``ehm.engine.load_line``), and at its end the linear model's Padé states are those the window's torques
   leave them in (``ehm.engine.pade_steps``), started from the linear model's at the window's start.
3. Over every window the linear and the nonlinear answers are compared: the *discrepancy* of a point's
   acceleration is the rms of their difference over the windows, counted over the whole drive, as a share
   of that acceleration's rms over the drive (what the linear answer alone would be off by); a channel with no
   content of its own (rms below ``CONTENT_FLOOR`` of the largest point acceleration's rms, such as the
   sideways accelerations under vertical input) is measured against that largest rms instead.
4. ``method="auto"`` (the hybrid route) keeps the nonlinear answer in the windows and hands the nonlinear
   state back to the linear model at each window's end (``ehm.engine.deviation_of``,
   :func:`ehm.routes.linear.carry_of`), so both pieces join without a jump; once the windows cover more than
   :data:`FALLBACK_SHARE` of the drive so far (after :data:`FALLBACK_AFTER_S`, or a third of a shorter drive), it
   runs the rest of the drive on the nonlinear model (a long rest in segments on the machine's cores,
   :func:`ehm.routes.parallel.stream_rest`).  A drive whose manoeuvres hold the seat's horizontal acceleration
   above the back pads' friction limit for much of its length (:func:`sustained_share` above
   ``SUSTAINED_SHARE``) runs on the nonlinear model from its start: the linear model is then neither built nor run;
   so does a drive that turns the seat of a person with the head-in-space control (the linear model of a turning
   seat senses the head on the seat, not in space).
   ``method="linear"`` keeps the linear answer everywhere, the windows only checking it, and warns
   (:class:`LinearRouteWarning`, one sentence with the figure) when the discrepancy exceeds the tolerance.

Every result carries the check in ``RunResult.extra["route"]`` (:class:`RouteReport`): how much of the
drive each model carried, the windows, and the discrepancy per point.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, fields, replace

import numpy as np

from .. import engine
from ..errors import EhmWarning, InputError, warn
from ..inputs.kinematics import seat_kinematics, seat_rotation_matrices
from ..inputs.resampling import Resampler
from ..outputs.results import POINT_NAMES, merge_linear_checks
from .built import built_of
from .linear import (
    BLOCK,
    SeatRotation,
    advance,
    block_chunk,
    block_form,
    carry_of,
    contact_rows,
    head_sensed,
    in_time_order,
    initial_state,
    left_out,
    linear_model,
    modal_form,
    output_layout,
    run_result,
    seat_body_rates,
    settled_orientations,
    state_of,
)
from .nonlinear import chunk_result, stream_span
from .parallel import default_workers, stream_parallel, stream_rest
from .poses import PoseGrid

#: A contact whose tangential force in the linear model passes this share of its Coulomb limit (mu times its
#: normal force), or that lifts off, opens a nonlinear window.  Measured on a 219 s city-bus floor log (0.58 /
#: 0.46 / 0.34 m/s^2 rms x / y / z): at 1.0 the windows cover 23 % of the drive and the point accelerations stay
#: within 0.7 % of rms of one continuous nonlinear run (a_v within 0.02 %); at 1.5, 10 % and 5 % of rms.
NEAR_LIMIT = 1.0
#: The nonlinear model takes over this long [s] before the first marked sample of a window.
LEAD_S = 0.25
#: A window closes once no sample has been marked for this long [s].
QUIET_S = 0.5
#: The linear model looks this far ahead [s] from a window's start to find where it closes (at most).
LOOKAHEAD_S = 10.0
#: The hybrid route runs the rest of a drive on the nonlinear model once its windows cover more than this share of
#: the drive so far, after at least FALLBACK_AFTER_S.
FALLBACK_SHARE = 0.5
#: The rest of a drive goes to the nonlinear model no earlier than this far into it [s], or than FALLBACK_AFTER_SHARE of
#: a shorter drive: on a long drive a rough first stretch must not send an hour of smooth road to the nonlinear model
#: (20 times slower), while on a short one a late decision costs more than a wrong one (35 s of three-axis vibration
#: at 1 m/s^2, windows over 89 % of it, default person: deciding at 30 s left the hybrid route at 0.90 times the
#: nonlinear route's speed).
FALLBACK_AFTER_S = 30.0
FALLBACK_AFTER_SHARE = 1 / 3
#: The hybrid route runs a drive on the nonlinear model from its start when the seat's horizontal acceleration, in
#: means over SUSTAINED_WINDOW_S, is above SUSTAINED_MPS2 for more than SUSTAINED_SHARE of the drive
#: (:func:`sustained_share`).  Measured with the default person: a steady seat acceleration (a slow ramp) brings
#: the back pads to their friction limit at 1.13 m/s^2 sideways and 1.7 m/s^2 braking (never pressed into the
#: backrest).  Above 1.5 m/s^2: SYNTHETIC 120 s city drives (``ehm.city_drive``, seeds 0-7) 42-50 % of the drive,
#: where the windows cover about two thirds of the first 37 s and the rest goes to the nonlinear model; the measured
#: bus, tram and car logs of ``benchmarks/bench_routes.py`` 5 %, 0 % and 8 % (their linear shares 77 %, 95 % and 1 %:
#: the car's contacts slide under vibration, which the 30 s decision catches).  A drive judged wrongly costs time,
#: never accuracy (the nonlinear model is the reference).
SUSTAINED_MPS2 = 1.5
SUSTAINED_SHARE = 0.3
SUSTAINED_WINDOW_S = 1.0
#: Default tolerance of the linear answers: discrepancy as a share of each point acceleration's rms.
TOLERANCE = 0.01
#: A point acceleration whose rms is below this share of the largest one's has no content of its own: its
#: discrepancy is measured against the largest rms (the run's scale).  Under vertical input the sideways
#: accelerations are 1e-6 to 4e-6 of the vertical ones in both models (the settled posture's round-off asymmetry),
#: and their difference as a share of their own rms read 9 % on a 10 s, 0.8 m/s^2 vertical drive whose channels with
#: content all agreed within 1 % (measured with the default person).
CONTENT_FLOOR = 1e-4

class LinearRouteWarning(EhmWarning):
    """The linear route's answer is further from the nonlinear model's than its tolerance (``method="linear"``)."""


@dataclass
class RouteReport:
    """How a drive was run and checked (``RunResult.extra["route"]``, ``summary.json``, ``assessment.json``).

    Attributes
    ----------
    method : str
        ``auto``, ``linear`` or ``nonlinear`` (the method asked for).
    duration_s : float
        Length of the drive [s].
    nonlinear_s : float
        Time [s] the nonlinear model carried (in the answer: auto; checked only: linear).
    windows_s : list of [start, end]
        The nonlinear windows [s].
    discrepancy : dict
        Point -> [x, y, z]: rms of the linear answer's difference from the nonlinear one over the windows, as a
        share of the point acceleration's rms over the drive (0 where no window was needed); of the largest point
        acceleration's rms where the point's own is below ``CONTENT_FLOOR`` of it.
    tolerance : float
        The tolerance the discrepancy is held to (share of rms).
    fallback : str
        From when and why the rest of the drive went to the nonlinear model, or "".
    from_start : bool
        The nonlinear model ran the whole drive, decided from its level before it started (``fallback`` says why).
    left_out : dict
        For a drive that turns the seat: the estimate of the terms the linear model of the seat's rotation
        leaves out (:func:`ehm.routes.linear.left_out`, merged over the linear pieces); ``share`` its largest share of a
        point's rms.
    """

    method: str
    duration_s: float
    nonlinear_s: float = 0.0
    windows_s: list = field(default_factory=list)
    discrepancy: dict = field(default_factory=dict)
    tolerance: float = TOLERANCE
    fallback: str = ""
    from_start: bool = False
    #: drives that turn the seat: ehm.routes.linear.left_out over the linear pieces
    left_out: dict = field(default_factory=dict)

    @property
    def linear_share(self) -> float:
        """Share of the drive the linear model carried (auto) or answered (linear)."""
        if self.duration_s <= 0:
            return 0.0
        return max(0.0, 1.0 - self.nonlinear_s / self.duration_s) if self.method == "auto" else 1.0

    def largest(self) -> tuple[str, str, float]:
        """The largest discrepancy: point, axis, share of rms."""
        best = ("head", "x", 0.0)
        for p, v in self.discrepancy.items():
            for a, x in zip("xyz", v):
                if x > best[2]:
                    best = (p, a, float(x))
        return best

    def line(self) -> str:
        """One sentence for the console."""
        p, a, worst = self.largest()
        n = len(self.windows_s)
        if self.from_start:
            return f"route: nonlinear model for the whole drive {self.fallback}."
        if n == 0:
            return ("route: linear model for the whole drive; no contact reached its friction limit or lifted off "
                    "(checked at every step)." + self._left_out_sentence())
        share = min(1.0, self.nonlinear_s / self.duration_s) if self.duration_s > 0 else 0.0  # the grid's last
        # sample may lie up to a step past the drive's length
        checked = (f"{n} window{'s' if n != 1 else ''} where a contact reached its friction limit or lifted off "
                   f"({self.nonlinear_s:.1f} s, {share:.1%} of the drive)")
        if self.method == "auto":
            line = (f"route: linear model {self.linear_share:.1%} of the drive, nonlinear model in {checked}; "
                    f"there the figures are the nonlinear model's (the linear answer alone would differ by up to "
                    f"{worst:.2%} of rms, {p} {a}), so nothing is left to do.")
            if self.fallback:
                line += f" The nonlinear model ran the rest {self.fallback}."
        else:
            line = (f"route: linear model, checked against the nonlinear model in {checked}: largest discrepancy "
                    f"{worst:.2%} of rms ({p} {a}), tolerance {self.tolerance:.0%}.")
        return line + self._left_out_sentence()

    def _left_out_sentence(self) -> str:
        """What the linear model of a turning seat leaves out, where it may matter: at or above the tolerance
        (below it the figures are the nonlinear model's within that; ``left_out`` in the report has the figures)."""
        if not self.left_out or self.left_out["share"] < self.tolerance:
            return ""
        return (f" The seat's rotation: the loads the linear model leaves out (Coriolis and the like) reach "
                f"{self.left_out['share']:.1%} of a point's rms acceleration on the linear model's share of the drive "
                f"(rms against rms, above the {self.tolerance:.0%} tolerance), so its figures there may be off by "
                "about as much; --method nonlinear (method='nonlinear') includes them.")

    def as_dict(self) -> dict:
        """Plain data (what ``summary.json`` and ``assessment.json`` hold under ``route``)."""
        p, a, worst = self.largest()
        return {"summary_line": self.line(), "method": self.method, "duration_s": self.duration_s,
                "linear_share": self.linear_share,
                "nonlinear_s": self.nonlinear_s, "windows_s": [[float(t0), float(t1)] for t0, t1 in self.windows_s],
                "discrepancy_share_of_rms": {k: [float(x) for x in v] for k, v in self.discrepancy.items()},
                "largest_discrepancy": {"point": p, "axis": a, "share_of_rms": worst},
                "tolerance_share_of_rms": self.tolerance, "within_tolerance": worst <= self.tolerance,
                "fallback": self.fallback, "nonlinear_from_start": self.from_start,
                **({"left_out": self.left_out} if self.left_out else {})}


def sustained_share(motion) -> float:
    """Share of the drive's time where the seat's horizontal acceleration, in means over
    ``SUSTAINED_WINDOW_S`` around each moment, is above ``SUSTAINED_MPS2``: the manoeuvres (braking,
    pulling away, corners) that hold the back pads at their friction limit.  The means come from the running
    integral of each axis, read on a grid of a tenth of the window (irregular time steps are weighted by their
    length; the memory is one array of the drive's length per axis)."""
    t = motion.time_s
    half = SUSTAINED_WINDOW_S / 2
    grid = np.arange(t[0], t[-1], SUSTAINED_WINDOW_S / 10)
    lo, hi = np.maximum(grid - half, t[0]), np.minimum(grid + half, t[-1])
    means = []
    for a in motion.acc_mps2[:, :2].T:
        integral = np.concatenate([[0.0], np.cumsum(0.5 * (a[1:] + a[:-1]) * np.diff(t))])
        means.append((np.interp(hi, t, integral) - np.interp(lo, t, integral)) / (hi - lo))
    return float(np.mean(np.hypot(*means) > SUSTAINED_MPS2)) if grid.size else 0.0


def _nonlinear_from_start(human, motion, report: RouteReport):
    """The drive to run on the nonlinear model from its start (its angular velocities left out when they are all
    zero), with the reason in ``report``, when its level says the nonlinear model would carry most of it and the
    person can run it; else None."""
    turns = motion.angvel_radps is not None and bool(np.any(motion.angvel_radps != 0))
    if human.model.head_control is not None and turns:  # the control senses the head in space, not on the seat
        human.check_nonlinear_motion(motion)
        report.from_start = True
        report.fallback = ("from the start: the person's head-in-space control senses the head in space, which the "
                           "linear model of a turning seat does not carry (it senses the head on the seat)")
        return motion
    if turns and human.model.seat is None:  # the windows say what is needed, as they do today
        return None
    share = sustained_share(motion)
    if share <= SUSTAINED_SHARE:
        return None
    report.from_start = True
    report.fallback = (f"from the start: the seat's horizontal acceleration (in {SUSTAINED_WINDOW_S:g} s means) is "
                       f"above {SUSTAINED_MPS2:g} m/s^2 over {share:.0%} of the drive, more than "
                       f"{SUSTAINED_SHARE:.0%}, where the back pads reach their friction limit")
    return motion if turns or motion.angvel_radps is None else replace(motion, angvel_radps=None)


def _stream_nonlinear(human, motion, report: RouteReport, chunk_s: float, progress, pose_rate_hz, workers: int = 1,
                      lead_in_s: float | None = None):
    """The whole drive on the nonlinear route (in segments on ``workers`` processes when more than one,
    :mod:`ehm.routes.parallel`); the last chunk carries ``report``."""
    held = None
    if workers > 1:
        report.fallback += f"; in segments on {workers} processes"
        pieces = stream_parallel(human, motion, workers=workers, chunk_s=chunk_s, progress=progress,
                                 pose_rate_hz=pose_rate_hz, lead_in_s=lead_in_s)
    else:
        pieces = stream_span(human, motion, chunk_s=chunk_s, progress=progress, pose_rate_hz=pose_rate_hz)
    for piece in pieces:
        if held is not None:
            yield held
        held = piece
    dt = float(human.model.mj.opt.timestep)
    report.nonlinear_s = float(held.time_s[-1]) + dt
    report.windows_s = [[0.0, report.nonlinear_s]]
    report.discrepancy = {p: [0.0, 0.0, 0.0] for p in POINT_NAMES}
    yield replace(held, extra={**held.extra, "route": report.as_dict()})


def _near_limit(ss, y: np.ndarray, n: int) -> np.ndarray:
    """(n,) bool: samples where a touching contact comes within NEAR_LIMIT of its Coulomb limit or lifts off
    (``y`` as :func:`ehm.routes.linear.block_chunk` returns it)."""
    if not ss.contacts:
        return np.zeros(n, dtype=bool)
    fn, ft1, ft2 = (in_time_order(f)[:, :n] for f in contact_rows(ss, y))
    mu = np.array([ss.friction[c] for c in ss.contacts])[:, None]
    return ((fn <= 0) | (np.hypot(ft1, ft2) > NEAR_LIMIT * mu * fn)).any(axis=0)


def _window_end(flags: np.ndarray, k: int, quiet: int) -> int:
    """Index (into ``flags``) where the window opened by the marked sample ``k`` closes: ``quiet`` samples after
    the last marked sample of the stretch, the stretch ending at the first ``quiet`` unmarked samples in a row
    (or at the end of ``flags``)."""
    marked = np.flatnonzero(flags[k:]) + k
    gaps = np.flatnonzero(np.diff(marked) > quiet)
    last = marked[gaps[0]] if gaps.size else marked[-1]
    return int(min(flags.size, last + 1 + quiet))


class _Discrepancy:
    """Sums over a drive: each point acceleration's sum and sum of squares, and the squared difference of the
    linear answer from the nonlinear one in the windows."""

    def __init__(self):
        self.n = 0
        self.s1 = np.zeros((len(POINT_NAMES), 3))
        self.s2 = np.zeros((len(POINT_NAMES), 3))
        self.d2 = np.zeros((len(POINT_NAMES), 3))

    def add_answer(self, chunk) -> None:
        a = np.stack([chunk.point(p).acc_mps2 for p in POINT_NAMES])  # (points, n, 3)
        self.n += a.shape[1]
        self.s1 += a.sum(axis=1)
        self.s2 += (a * a).sum(axis=1)

    def add_window(self, linear, nonlinear) -> None:
        for i, p in enumerate(POINT_NAMES):
            diff = linear.point(p).acc_mps2 - nonlinear.point(p).acc_mps2
            self.d2[i] += (diff * diff).sum(axis=0)

    def shares(self) -> dict:
        if self.n == 0:
            return {p: [0.0, 0.0, 0.0] for p in POINT_NAMES}
        rms = np.sqrt(np.maximum(self.s2 / self.n - (self.s1 / self.n) ** 2, 0.0))
        rms_diff = np.sqrt(self.d2 / self.n)
        scale = np.maximum(rms, CONTENT_FLOOR * rms.max())  # a channel without content: the run's scale
        share = np.divide(rms_diff, scale, out=np.zeros_like(rms_diff), where=scale > 0)
        return {p: share[i].tolist() for i, p in enumerate(POINT_NAMES)}


def _contact_blocks(ss, blk):
    """The block form reduced to the contacts' forces (the last 3 x contacts outputs): a look ahead that only
    marks windows costs a third of a full linear run."""
    key = ("contact blocks", blk.dt_s)
    if key not in ss.cache:
        rows = 3 * len(ss.contacts) * BLOCK
        ss.cache[key] = replace(blk, M=np.ascontiguousarray(blk.M[blk.M.shape[0] - rows:]))
    return ss.cache[key]


class _Drive:
    """The drive on the model's time step, a stretch at a time: the seat's acceleration (n, 3, seat axes), the
    linear model's inputs and, when the seat rotates, its rotation (:class:`ehm.routes.linear.SeatRotation`), from the
    same resampling (:class:`ehm.inputs.resampling.Resampler`) and seat kinematics as the nonlinear route."""

    def __init__(self, motion, dt: float, rotates: bool):
        self.dt = dt
        self.grid = Resampler(motion.time_s, motion.acc_mps2, dt)
        self.n = self.grid.n_samples
        self.kin = seat_kinematics(motion.time_s, motion.angvel_radps) if rotates else None

    def at(self, a: int, b: int):
        """Samples a ... b - 1: (seat acceleration, linear inputs, SeatRotation or None)."""
        u = self.grid.block(a, b)
        if self.kin is None:
            return u, u, None
        seat = SeatRotation.at(self.kin, np.arange(a, b) * self.dt, u)
        return u, seat.inputs, seat


def stream_checked(human, motion, method: str = "auto", chunk_s: float = 10.0, progress=None,
                   tolerance: float = TOLERANCE, pose_rate_hz: float | None = None, workers: int | None = None,
                   lead_in_s: float | None = None):
    """Run ``motion`` on the hybrid route (``method="auto"``) or the checked linear route (``"linear"``), chunk
    by chunk, as :meth:`ehm.SeatedHuman.stream` does (see the module docstring).

    Yields :class:`ehm.outputs.results.RunResult` chunks on the model's time step; the last one carries the
    :class:`RouteReport` as plain data (:meth:`RouteReport.as_dict`) in ``extra["route"]``.  ``tolerance``:
    share of rms the linear route's discrepancy may reach (``method="linear"`` warns above it).  ``pose_rate_hz``:
    record the segments' poses at about this rate (:mod:`ehm.routes.poses`), as the nonlinear route does.
    ``workers``: processes for a drive the hybrid route runs on the nonlinear model from its start
    (:func:`ehm.routes.parallel.default_workers` when None: a long drive in segments on the machine's cores), and
    for the long rest of a drive it hands to the nonlinear model; ``lead_in_s``: those segments' lead-in (default
    :data:`ehm.routes.parallel.DEFAULT_LEAD_IN_S`).
    """
    if not (isinstance(tolerance, (int, float)) and 0 < tolerance < 1):
        raise InputError(f"tolerance must be a share of rms between 0 and 1, not {tolerance!r}.")
    human = built_of(human)
    dt = float(human.model.mj.opt.timestep)
    report = RouteReport(method=method, duration_s=motion.duration_s, tolerance=float(tolerance))
    # a motion that turns the seat: the linear model of the seat's rotation (a person on a rotating seat whose
    # motion does not turn it runs the translation's, the windows on the rotating seat held level)
    early = _nonlinear_from_start(human, motion, report) if method == "auto" else None
    if early is not None:
        yield from _stream_nonlinear(human, early, report, chunk_s, progress, pose_rate_hz,
                                     default_workers(early.duration_s, workers), lead_in_s)
        return
    rotates = motion.angvel_radps is not None and bool(np.any(motion.angvel_radps != 0))
    description = motion.description
    ss = linear_model(human, rotation=rotates)
    blk = block_form(ss, float(f"{dt:.12g}"))
    drive = _Drive(motion, dt, rotates)
    per_chunk = max(1, int(round(chunk_s / dt)))
    poses = PoseGrid(human, ss, blk, dt, pose_rate_hz, drive.kin) if pose_rate_hz else None
    pieces = _Hybrid(human, ss, blk, drive, per_chunk, method, report, description, poses,
                     rest=(motion, chunk_s, workers, lead_in_s)).pieces()
    held = None
    for piece in pieces:
        if held is not None:
            yield held
            if progress:
                progress(min(held.time_s[-1] + dt, motion.duration_s), motion.duration_s)
        held = piece
    p, a, worst = report.largest()
    if method == "linear" and worst > tolerance:
        warn(LinearRouteWarning(
            f"{description}: the linear route's answer is off by {worst:.2%} of rms ({p} {a} acceleration) in the "
            f"{len(report.windows_s)} windows where a contact reached its friction limit or lifted off "
            f"({report.nonlinear_s:.1f} s), more than the tolerance {tolerance:.0%}; the hybrid route (method='auto', "
            "--method auto) runs the nonlinear model there."), stacklevel=2)
    yield replace(held, extra={**held.extra, "route": report.as_dict()})
    if progress:
        progress(motion.duration_s, motion.duration_s)


class _Hybrid:
    """One drive through the checked linear route or the hybrid route: :meth:`pieces` yields its linear
    stretches and nonlinear windows in time order (see the module docstring)."""

    def __init__(self, human, ss, blk, drive: _Drive, per_chunk: int, method: str, report: RouteReport,
                 description: str, poses: PoseGrid | None = None, rest: tuple | None = None):
        self.human, self.ss, self.blk, self.drive, self.method, self.report = human, ss, blk, drive, method, report
        self.rest = rest  # (motion, chunk_s, workers, lead_in_s): for a long rest of the drive in segments
        self.poses = poses  # the segments' poses for pictures, when asked for
        self.dt = drive.dt
        self.per_chunk = per_chunk
        self.lead, self.quiet = int(round(LEAD_S / self.dt)), int(round(QUIET_S / self.dt))
        self.look = max(per_chunk, int(round(LOOKAHEAD_S / self.dt)))  # how far a window may run before it is cut
        self.R0 = settled_orientations(ss, human.model)
        self.models = _Models(human, drive.kin, poses)
        self.contact_blk = _contact_blocks(ss, blk)
        self.sums = _Discrepancy()
        self.checks = []  # the linear pieces' estimates of what the linear model of the seat's rotation leaves out
        self.description = f"{description}, at dt {self.dt:g} s, {'hybrid' if method == 'auto' else 'linear'} route"
        self.carry = None  # the linear time run's modal state at the next sample
        # The state's share in the modes the linear time run leaves out (not reached by the seat's acceleration:
        # where the body sits and turns on the seat pan, the integral actions' neutral directions) stays where a
        # nonlinear window left it: a constant offset of the linear model's state, and ``shift`` of its outputs.
        self.offset = np.zeros(ss.A.shape[0])
        self.shift = None
        self.x_end = None  # the linear state after the last nonlinear window
        self.end_at = -1  # ... at this sample
        # The head-in-space control's delay: the law's torques of the last N samples, whichever model gave them
        # (the linear model's sensed outputs, the nonlinear model's sensors), go into the delay line of the
        # nonlinear model at a window's start; the window's torques give the linear model's Padé states at its end.
        control = human.model.head_control
        self.control = control
        if control is not None:
            self.gains = engine.control_gains(control)
            self.pade = engine.pade_steps(human.model, self.dt)
            self.history = np.zeros((control.delay_steps, 3))

    def pieces(self):
        """The drive's pieces in time order; the report filled in as they come."""
        n, pos = self.drive.n, 0
        while pos < n:
            pos = yield from self._chunk(pos, min(n, pos + self.per_chunk))
            self.report.discrepancy = self.sums.shares()
            done_s = pos * self.dt
            after_s = min(FALLBACK_AFTER_S, FALLBACK_AFTER_SHARE * n * self.dt)
            if (self.method == "auto" and pos < n and done_s >= after_s
                    and self.report.nonlinear_s > FALLBACK_SHARE * done_s):
                yield from self._rest_nonlinear(pos)
                break
        self.report.discrepancy = self.sums.shares()
        if self.checks:
            self.report.left_out = merge_linear_checks(self.checks) if len(self.checks) > 1 else self.checks[0]

    def _chunk(self, pos: int, stop: int):
        """Samples from ``pos`` on: the linear look ahead to ``stop``, the answer up to the first window, and the
        window; returns the sample reached."""
        t_start = time.perf_counter()
        given = self.drive.at(pos, stop)
        if self.carry is None:
            self.carry = initial_state(self.blk, given[1][0])
        ahead = self.carry.copy()
        y = self._linear(given[1], ahead)
        flags = _near_limit(self.ss, y, stop - pos)
        if not flags.any():  # the look ahead is the answer
            yield self._answer(self._linear_piece(pos, stop, self.carry, given, y, time.perf_counter() - t_start))
            self.carry = ahead
            return stop
        k = int(np.argmax(flags))
        w0 = max(pos, pos + k - self.lead)
        if w0 > pos:  # the look ahead up to the window is the answer there
            yield self._answer(self._linear_piece(pos, w0, self.carry, given, y, time.perf_counter() - t_start))
            advance(self.blk, given[1][:w0 - pos], self.carry)
        w1 = self._window_end(flags, pos, k, w0, stop)
        yield from self._window(w0, w1)
        return w1

    def _window_end(self, flags: np.ndarray, pos: int, k: int, w0: int, stop: int) -> int:
        """Where the window opened by the marked sample pos + k closes: QUIET_S after the linear prediction's last
        mark of the stretch; within the chunk's look ahead if it shows that, else from a look ahead from w0 (the
        same trajectory, further)."""
        n = self.drive.n
        w1 = pos + _window_end(flags, k, self.quiet)
        if w1 == stop and stop < n:
            end = min(n, w0 + self.look)
            ahead = self.carry.copy()
            marks = _near_limit(self.ss, self._linear(self.drive.at(w0, end)[1], ahead, contacts_only=True), end - w0)
            w1 = w0 + _window_end(marks, pos + k - w0, self.quiet)
        return max(w1, w0 + 1)

    def _window(self, w0: int, w1: int):
        """The nonlinear model over samples w0 ... w1 - 1 from the linear state, compared with the linear answer;
        the answer kept (nonlinear for auto, linear for linear) and the state handed back."""
        given = self.drive.at(w0, w1)
        x0 = state_of(self.ss, self.blk, self.carry, given[1][0]) + self.offset
        line = None if self.control is None else self.history
        nonlinear, x1, torques = self.models.window(x0, given, w0, self.dt, self.description,
                                                    posed=self.method == "auto", line=line)
        self.x_end, self.end_at = self._with_pade(x0, x1, torques), w1
        lin_carry = self.carry.copy()
        # auto: the linear answer is only compared here, so what it leaves out of a turning seat does not count
        linear = self._linear_piece(w0, w1, lin_carry, given, posed=self.method != "auto",
                                    counted=self.method != "auto")
        self.sums.add_window(linear, nonlinear)
        self.report.windows_s.append([w0 * self.dt, w1 * self.dt])
        self.report.nonlinear_s += (w1 - w0) * self.dt
        if self.method != "auto":
            yield self._answer(linear)
            self.carry = lin_carry
            return
        yield self._answer(nonlinear)
        if torques is not None:
            self._remember(torques)
        if w1 < self.drive.n:
            self._hand_back(self.x_end, self.drive.at(w1, w1 + 1)[1][0])

    def _remember(self, torques: np.ndarray) -> None:
        """The head-in-space control's torques of the samples just run join the history (the last N kept)."""
        N = self.history.shape[0]
        self.history = np.concatenate([self.history, torques[-N:]])[-N:]

    def _with_pade(self, x0: np.ndarray, x1: np.ndarray, torques: np.ndarray | None) -> np.ndarray:
        """The linear state after a window: the nonlinear model's ``x1`` and, with the head-in-space control, the
        Padé states its torques leave the linear model's (from those of the window's start ``x0``, driven by the
        window's torques; the last sample's, whose state the window ends in, extrapolated linearly)."""
        if torques is None:
            return x1
        last = 2 * torques[-1] - torques[-2] if len(torques) > 1 else torques[-1]
        z = self.pade.after(x0[x1.size:], np.vstack([torques, last]))
        return np.concatenate([x1, z])

    def _hand_back(self, x: np.ndarray, u: np.ndarray) -> None:
        """The linear model continues from the nonlinear state ``x`` (input ``u`` at that sample); its share in
        the modes the time run leaves out becomes the offset."""
        self.carry = carry_of(self.ss, self.blk, x, u)
        self.offset = modal_form(self.ss).P_unreached @ x
        self.shift = self.ss.C[output_layout(self.ss)] @ self.offset

    def _rest_nonlinear(self, pos: int):
        """The rest of the drive on the nonlinear model, chunk by chunk, from the state the last window left; a long
        rest (:func:`ehm.routes.parallel.default_workers`, or the ``workers`` asked for) in segments on the machine's
        cores, this process going on from that state (:func:`ehm.routes.parallel.stream_rest`; not when poses are
        recorded)."""
        n, dt, done_s = self.drive.n, self.dt, pos * self.dt
        self.report.fallback = (f"from t = {done_s:.1f} s on: contacts reached their friction limit over "
                                f"{self.report.nonlinear_s / done_s:.0%} of the drive so far, more than "
                                f"{FALLBACK_SHARE:.0%}")
        x = self.x_end
        if self.end_at != pos:  # a linear stretch came after the last window: its state here
            x = state_of(self.ss, self.blk, self.carry, self.drive.at(pos, pos + 1)[1][0]) + self.offset

        def here(stop: int):
            nonlocal x
            for a in range(pos, stop, self.per_chunk):
                b = min(stop, a + self.per_chunk)
                line = None if self.control is None else self.history
                piece, x, torques = self.models.window(x, self.drive.at(a, b), a, dt, self.description, line=line)
                if torques is not None:
                    self._remember(torques)
                yield piece

        workers = 1
        if self.rest is not None and self.poses is None:
            motion, chunk_s, asked, lead_in_s = self.rest
            workers = default_workers((n - pos) * dt, asked)
        if workers > 1:
            pieces = stream_rest(self.human, motion, pos, workers, chunk_s, here, lead_in_s=lead_in_s)
            self.report.fallback += f"; in segments on {workers} processes"
        else:
            pieces = here(n)
        for piece in pieces:
            self.report.nonlinear_s += piece.time_s.size * dt
            yield self._answer(piece)
        self.report.windows_s.append([done_s, n * dt])

    def _answer(self, piece):
        self.sums.add_answer(piece)
        return piece

    def _linear(self, u: np.ndarray, carry: np.ndarray, contacts_only: bool = False) -> np.ndarray:
        """The linear model's outputs over the inputs ``u`` from ``carry`` (advanced past them), with the offset."""
        y = block_chunk(self.contact_blk if contacts_only else self.blk, u, carry)
        if self.shift is not None:
            y += self.shift[-y.shape[0]:, None, None]
        return y

    def _linear_piece(self, a: int, b: int, carry: np.ndarray, given=None, y=None, wall_s: float = 0.0,
                      posed: bool = True, counted: bool = True):
        """The linear answer over samples a ... b - 1 (``given``: the drive there, from :meth:`_Drive.at`; ``y``:
        outputs already computed from sample a, possibly further than b, ``carry`` then left as it is; ``counted``:
        its estimate of what the linear model of a turning seat leaves out joins the report's, as an answer kept)."""
        t0 = time.perf_counter()
        u, inputs, seat = self.drive.at(a, b) if given is None else given
        poses = self.poses.linear(a, b, carry, inputs[:b - a], self.offset) if self.poses and posed else None
        y = self._linear(inputs, carry) if y is None else y  # advances carry to b
        m, n_y = b - a, u.shape[0]
        if counted and self.control is not None:  # the linear model carries on from here: its torques
            self._remember(head_sensed(y, m, max(0, m - self.history.shape[0])) @ self.gains.T)
        check = None
        if seat is not None:
            check = left_out(y, m, seat if m == n_y else _first(seat, m))
            if counted:
                self.checks.append(check)
            seat.correct(y)
        res = run_result(self.human, self.ss, y, u, np.arange(a, a + n_y) * self.dt, self.dt, self.R0,
                      self.description, seat=seat, check=check)
        if m < n_y:
            res = res.take(slice(0, m))
        return replace(res, description=self.description, wall_s=wall_s + time.perf_counter() - t0, poses=poses)


def _first(seat: SeatRotation, m: int) -> SeatRotation:
    """The seat's rotation over its first ``m`` samples."""
    return SeatRotation(*(getattr(seat, f.name)[:m] for f in fields(SeatRotation)))


class _Models:
    """The nonlinear model for the windows, and the hand-over of the linear model's state to it and back.

    A static seat: the person's own model, whose state the linear model's is.  A rotating seat: the linear
    model is that of a static-seat build (in the seat's frame); the window runs on the rotating-seat build,
    its state carried into the world and back (``ehm.engine.rotating_data_at``,
    ``ehm.engine.static_deviation_of``)."""

    def __init__(self, human, kin, poses: PoseGrid | None = None):
        self.human = human
        self.kin = kin
        self.grid = poses
        self.rotating = human.model.seat is not None  # the windows on a rotating seat (level when kin is None)
        self.static = human.static_model
        self.poses = engine.settled_point_poses(human.model)
        self.pivot = human.model.seat["pivot"] if self.rotating else np.zeros(3)

    def _seat(self, t: np.ndarray):
        """The seat's angles, their rates and accelerations (the nonlinear route's drive), and its angular
        velocity in its own axes, at ``t``; level and still without a turning motion."""
        if self.kin is None:
            z = np.zeros((t.size, 3))
            return z, z, z, z
        angles, rates, accs = self.kin.at(t)
        return angles, rates, accs, seat_body_rates(angles, rates, accs)[0]

    def window(self, x0: np.ndarray, given, a: int, dt: float, description: str, posed: bool = True,
               line: np.ndarray | None = None):
        """The nonlinear model over the samples of ``given`` (from :meth:`_Drive.at`, starting at sample ``a``)
        from the linear state ``x0`` (the head-in-space control's delay line filled with ``line``, the law's torques
        of the N samples before); returns the piece (with poses if asked for and ``posed``), the linear state after
        its last sample (the body's: without the control's Padé states) and the law's torques of the window's
        samples (None without the control)."""
        grid = self.grid if posed else None
        u = given[0]
        b = a + u.shape[0]
        t = np.arange(a, b) * dt
        model = self.human.model
        if self.kin is not None and not self.rotating:
            raise InputError("this drive rotates the seat and a contact reaches its friction limit, which needs "
                             "the nonlinear model of a rotating seat: build the person with "
                             "SeatedHuman(rotating_seat=True) (the command line does so).")
        if self.rotating:
            angles, rates, accs, w = self._seat(t)
            R = seat_rotation_matrices(angles)
            d = engine.rotating_data_at(model, self.static, x0, R[0], angles[0], rates[0], w[0], time_s=a * dt)
            acc, rotation = np.einsum("nij,nj->ni", R, u), (angles, rates, accs)
        else:
            d = engine.data_at_deviation(model, x0, time_s=a * dt)
            R, angles, acc, rotation = None, None, u, None
        control = model.head_control
        if control is not None and line is not None:
            engine.load_line(control, d, line)
        t0 = time.perf_counter()
        with engine.captured_warnings():
            raw = engine.run(model, acc, d=d, seat_rotation=rotation, pose_every=grid.every if grid else None,
                             pose_first=grid.first(a) if grid else 0)
        wall = time.perf_counter() - t0
        piece = chunk_result(self.human, raw, t, u, R, angles, self.poses, self.pivot, wall, description)
        if grid:
            piece = replace(piece, poses=grid.of_raw(raw, a))
        if self.rotating:  # the state after the last sample, relative to the seat there
            angles1, _, _, w1 = self._seat(np.array([b * dt]))
            x1 = engine.static_deviation_of(model, self.static, d, seat_rotation_matrices(angles1)[0], w1[0])
        else:
            x1 = engine.deviation_of(model, d)
        torques = None if control is None else engine.control_torques(
            control, d, raw.sensors["head_framequat"], raw.sensors["head_frameangvel"])
        return piece, x1, torques

