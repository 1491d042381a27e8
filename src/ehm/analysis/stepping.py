"""Sample-by-sample simulation for vehicle simulators, driving simulators and control loops.

>>> sim = Simulator()                       # settles the default person on the default seat
>>> state = sim.step([0.0, 0.0, 0.3])       # seat acceleration [m/s^2] for one time step (1 ms)
>>> state.head.acc_mps2.shape               # absolute head acceleration, seat axes
(3,)
>>> print(f"{state.head.acc_mps2[2]:.3f} m/s^2")
0.010 m/s^2

Each step gives the same numbers as a whole run of the same input (``SeatedHuman.simulate``); memory
stays constant.  With ``comfort=True`` the running ISO 2631-1 figures (1 s running rms, a_w so far) of
seat, pelvis, trunk, head and lumbar spine are kept: the weighting filters run every step, and the figures
reported in the returned state are refreshed every ``comfort_every`` steps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import engine
from ..body.params import Parameters
from ..errors import InputError, checked_class, describe
from ..outputs.results import POINT_NAMES
from ..person import Person
from ..simulation import SeatedHuman


@dataclass(frozen=True)
class PointState:
    """One output point after a step: absolute acceleration, displacement and rotation (seat axes) and
    angular velocity (the segment's own axes), as in :class:`ehm.outputs.results.PointMotion`."""

    acc_mps2: np.ndarray
    disp_m: np.ndarray
    rot_rad: np.ndarray
    angvel_radps: np.ndarray


@checked_class
@dataclass(frozen=True)
class StepState:
    """Result of one :meth:`Simulator.step`: the time of the sample and the output points.

    ``comfort`` maps ``location -> axis -> (running_rms, a_w_so_far)`` [m/s^2] when comfort figures are
    on (updated every ``comfort_every`` steps), else it is empty.
    """

    time_s: float
    pelvis: PointState
    trunk: PointState
    head: PointState
    lumbar: PointState  #: the L4-L5 joint centre (on the lower torso)
    comfort: dict


def _conjugate(q) -> tuple:
    """Inverse of a unit quaternion (w, x, y, z), as a tuple of floats."""
    return (float(q[0]), -float(q[1]), -float(q[2]), -float(q[3]))


def _quat_mul(a, b) -> tuple:
    """Hamilton product a * b of quaternions (w, x, y, z): rotation b, then a (plain floats: this is
    on the stepping hot path)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw)


def _rotate(q, v) -> np.ndarray:
    """Vector v rotated by the unit quaternion q."""
    w, x, y, z = q
    return np.array(_quat_mul(_quat_mul(q, (0.0, v[0], v[1], v[2])), (w, -x, -y, -z))[1:])


def _euler_zyx(q: np.ndarray) -> np.ndarray:
    """(roll, pitch, yaw) of the intrinsic z-y-x decomposition of a unit quaternion (w, x, y, z)."""
    w, x, y, z = q
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return np.array([roll, pitch, yaw])


@checked_class(skip=("step",))
class Simulator:
    """One settled person on one seat, advanced one fixed time step at a time.

    Parameters
    ----------
    params : Person, Parameters, path or None
        The person (:class:`ehm.Person`: its posture, back support, head control and time step apply step by
        step too), or its parameters, as for :class:`ehm.SeatedHuman`.
    lock, unlock, body, size
        Shortcuts that build (or change) the :class:`ehm.Person`, as for :class:`ehm.SeatedHuman`.
    comfort : bool
        Keep running ISO 2631-1 figures (Wd x, y; Wk z) of seat, pelvis, trunk, head and lumbar spine.
    comfort_every : int
        Steps between refreshes of the reported comfort figures (the filters run every step).

    Notes
    -----
    Only translational seat motion is supported step by step; a seat that rotates needs the whole drive
    in advance (:func:`ehm.assess`), since its orientation is integrated over the record.
    """

    def __init__(self, params: Person | Parameters | str | None = None, lock=(), unlock=(), comfort: bool = True,
                 comfort_every: int = 10, body=None, size=None):
        self.human = SeatedHuman(params, lock=lock, unlock=unlock, body=body, size=size)
        self.person = self.human.person
        self.model = self.human.model
        self.dt_s = float(self.model.mj.opt.timestep)
        engine.settle(self.model)
        self._poses = engine.settled_point_poses(self.model)
        self._inv0 = {p: _conjugate(q0) for p, (_, q0) in self._poses.items()}
        slices = engine.sensor_slices(self.model)
        self._point_slices = {p: tuple(slices[f"{p}_{k}"] for k in ("framelinvel", "framepos", "framequat",
                                                                     "frameangvel")) for p in POINT_NAMES}
        self.comfort = comfort
        self.comfort_every = max(1, int(comfort_every))
        self.reset()

    # ------------------------------------------------------------------ state
    def reset(self) -> None:
        """Back to the settled posture at t = 0 (comfort figures cleared)."""
        self._d = engine.settled_data(self.model)
        self._step = 0
        self._comfort_state: dict = {}
        if self.comfort:
            self._running = _RunningComfort(1.0 / self.dt_s)
            self._comfort_state = self._running.state()

    @property
    def time_s(self) -> float:
        """Simulated time of the next sample [s]."""
        return self._step * self.dt_s

    def save_state(self) -> dict:
        """A snapshot of the full simulation state (restore it with :meth:`restore_state`)."""
        import copy

        return {"mujoco": engine.get_state(self.model, self._d), "step": self._step,
                "comfort": copy.deepcopy(self._running) if self.comfort else None,
                "comfort_state": copy.deepcopy(self._comfort_state)}

    def restore_state(self, state: dict) -> None:
        """Return to a snapshot taken by :meth:`save_state`."""
        import copy

        if not isinstance(state, dict) or "mujoco" not in state:
            raise InputError("restore_state needs a snapshot from save_state().")
        engine.set_state(self.model, self._d, state["mujoco"])
        self._step = int(state["step"])
        if self.comfort:
            self._running = copy.deepcopy(state["comfort"])
        self._comfort_state = copy.deepcopy(state["comfort_state"])

    # ------------------------------------------------------------------ stepping
    def step(self, seat_acc_mps2, seat_angvel_radps=None) -> StepState:
        """Advance one time step with this seat acceleration [m/s^2] (seat axes: x forward, y left, z up).

        Returns the outputs at the start of the step (the sample at :attr:`time_s` before the call), as a
        whole run reports its row for that time.
        """
        if seat_angvel_radps is not None and np.any(_three_finite(seat_angvel_radps, "seat_angvel_radps", "rad/s")):
            raise InputError("step-by-step runs support seat translation only; for seat rotation run the whole "
                             "drive with 'ehm assess' or SeatedHuman(rotating_seat=True).simulate().")
        a = _three_finite(seat_acc_mps2, "seat_acc_mps2", "m/s^2")
        t = self._step * self.dt_s
        data, end = engine.step(self.model, self._d, a, check=self._step % engine.CHECK_EVERY == 0, start_s=t)
        self._step += 1
        points = {}
        for p in POINT_NAMES:
            s_vel, s_pos, s_quat, s_angvel = self._point_slices[p]
            q = data[s_quat].tolist()
            w_body = _rotate(_conjugate(q), data[s_angvel].tolist())
            acc = (end[s_vel] - data[s_vel]) / self.dt_s + a  # engine.point_accelerations of one step
            points[p] = PointState(acc_mps2=acc, disp_m=data[s_pos] - self._poses[p][0],
                                   rot_rad=_euler_zyx(_quat_mul(q, self._inv0[p])), angvel_radps=w_body)
        if self.comfort:
            row = np.concatenate([a] + [points[p].acc_mps2 for p in POINT_NAMES])
            self._running.add(row)
            if self._step % self.comfort_every == 0:
                self._comfort_state = self._running.state()
        return StepState(time_s=t, **points, comfort=self._comfort_state)



def _three_finite(value, name: str, unit: str) -> np.ndarray:
    """``value`` as 3 finite floats (x, y, z), or one sentence saying what it was instead."""
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        v = None
    if v is None or v.shape != (3,) or not np.all(np.isfinite(v)):
        raise InputError(f"Simulator.step: {name} must be 3 finite numbers (x, y, z) [{unit}], not {describe(value)}.")
    return v


LOCATIONS = ("seat",) + POINT_NAMES


def _cascade_state_space(sos: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """(A, B, C, D) of a cascade of second-order sections in transposed direct form II: the same
    arithmetic as ``scipy.signal.sosfilt``, written as one state-space model to step many channels."""
    A = np.zeros((0, 0))
    B = np.zeros(0)
    C = np.zeros(0)
    D = 1.0
    for b0, b1, b2, _, a1, a2 in sos:
        As = np.array([[-a1, 1.0], [-a2, 0.0]])
        Bs = np.array([b1 - a1 * b0, b2 - a2 * b0])
        Cs = np.array([1.0, 0.0])
        n = A.shape[0]
        A = np.block([[A, np.zeros((n, 2))], [np.outer(Bs, C), As]])
        B = np.concatenate([B, Bs * D])
        C = np.concatenate([b0 * C, Cs])
        D = b0 * D
    return A, B, C, D


class _RunningComfort:
    """Running ISO 2631-1 figures of 15 channels (seat, pelvis, trunk, head, lumbar; x, y, z), one row per step:
    causal Wd (x, y) and Wk (z) weighting, 1 s rectangular running rms and the weighted rms so far.  Each
    step costs the same few microseconds (no block spikes); the filters start in the steady state for the first
    row; equal to :class:`ehm.standards.comfort.ComfortAccumulator` fed a first block of one row, channel by channel, to
    round-off."""

    def __init__(self, fs_hz: float, tau_s: float = 1.0):
        from ..standards.comfort import weighting_sos

        self.cols = {"Wd": np.array([3 * i + j for i in range(len(LOCATIONS)) for j in (0, 1)]),
                     "Wk": np.array([3 * i + 2 for i in range(len(LOCATIONS))])}
        self.ss = {k: _cascade_state_space(weighting_sos(k, fs_hz)) for k in self.cols}
        self.state_ = {k: np.zeros((self.ss[k][0].shape[0], len(c))) for k, c in self.cols.items()}
        self.n_tau = int(round(tau_s * fs_hz))
        self.ring = np.zeros((self.n_tau, 3 * len(LOCATIONS)))  # squared weighted samples of the last tau
        self.pos = 0
        self.window = np.zeros(3 * len(LOCATIONS))
        self.sum2 = np.zeros(3 * len(LOCATIONS))
        self.n = 0

    def add(self, row: np.ndarray) -> None:
        aw = np.empty_like(row)
        for k, cols in self.cols.items():
            A, B, C, D = self.ss[k]
            x = row[cols]
            if self.n == 0:  # the steady state for the first row (a real-time stepper cannot wait for more)
                self.state_[k] = np.linalg.solve(np.eye(A.shape[0]) - A, np.outer(B, x))
            s = self.state_[k]
            aw[cols] = C @ s + D * x
            self.state_[k] = A @ s + B[:, None] * x
        sq = aw * aw
        self.window += sq - self.ring[self.pos]
        self.ring[self.pos] = sq
        self.pos = (self.pos + 1) % self.n_tau
        self.sum2 += sq
        self.n += 1

    def state(self) -> dict:
        rr = np.sqrt(np.maximum(self.window, 0.0) / self.n_tau)
        aw = np.sqrt(self.sum2 / self.n) if self.n else np.zeros_like(self.sum2)
        return {loc: {a: (float(rr[3 * i + j]), float(aw[3 * i + j])) for j, a in enumerate("xyz")}
                for i, loc in enumerate(LOCATIONS)}


@dataclass(frozen=True)
class RealtimeReport:
    """Per-step compute latency of a paced run [s] and the deadlines missed."""

    n_steps: int
    median_s: float
    p99_s: float
    worst_s: float
    overruns: int
    wall_s: float


def run_realtime(sim: Simulator, acc_mps2: np.ndarray, pace: bool = True, on_step=None) -> RealtimeReport:
    """Feed a seat acceleration history (n, 3) step by step, paced to the wall clock when ``pace``.

    Each step must finish before the next sample is due (its deadline, t0 + (i + 1) dt); a step that ends
    later is an overrun.  Latency is the compute time of :meth:`Simulator.step` alone.
    """
    import time

    acc = np.asarray(acc_mps2, dtype=float)
    lat = np.empty(acc.shape[0])
    overruns = 0
    dt = sim.dt_s
    t0 = time.perf_counter()
    with engine.captured_warnings():  # MuJoCo's warnings go into ehm's divergence sentence, not to the terminal
        for i, a in enumerate(acc):
            start = time.perf_counter()
            state = sim.step(a)
            end = time.perf_counter()
            lat[i] = end - start
            deadline = t0 + (i + 1) * dt
            if pace:
                if end > deadline:
                    overruns += 1
                else:  # spin (sleeping lets the core cool down and doubles the next step's latency)
                    while time.perf_counter() < deadline:
                        pass
            if on_step is not None:
                on_step(state)
    wall = time.perf_counter() - t0
    return RealtimeReport(n_steps=acc.shape[0], median_s=float(np.median(lat)), p99_s=float(np.percentile(lat, 99)),
                          worst_s=float(lat.max()), overruns=overruns, wall_s=wall)
