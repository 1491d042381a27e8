"""The stepping loop: one step (:func:`step`) and a whole run with a seat acceleration history (:func:`run`, giving
a :class:`RawRun`), with the divergence checks between blocks of steps, the rotating seat's drive, the poses
recorded for pictures, and the point accelerations taken from the integrated motion."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from ..errors import InputError
from . import native
from .control import after_step
from .diagnostics import CHECK_EVERY, divergence_error, instability
from .model import G0, POINTS, Model
from .seat_geometry import SEAT_INERTIA_KGM2
from .sensors import sensor_slices, support_slices
from .state import new_data, qpos_at_deviation, rotating_qpos, settled_data


def evaluate_velocities(model: Model, d: mujoco.MjData) -> np.ndarray:
    """Velocity-stage kinematics and sensors of the current state of ``d``; returns ``d.sensordata``.

    After :func:`mujoco.mj_step` the sensors hold the step's start state; this brings the velocity sensors
    (``framelinvel``, ``frameangvel``) to the new state without changing the state (the next step recomputes
    everything), so that the acceleration of the step can be taken from them (:func:`point_accelerations`).
    """
    mj = model.mj
    mujoco.mj_kinematics(mj, d)
    mujoco.mj_comPos(mj, d)
    mujoco.mj_comVel(mj, d)
    mujoco.mj_sensorVel(mj, d)
    return d.sensordata


def point_accelerations(v_lin: np.ndarray, v_ang: np.ndarray, seat_acc_mps2: np.ndarray, dt_s: float):
    """Absolute translational and angular acceleration of a point over each step, from its velocities.

    ``v_lin`` and ``v_ang`` (n + 1, 3) are the point's linear [m/s] and angular [rad/s] velocity in world
    axes at the start of steps 0 ... n (the last one: after the last step); ``seat_acc_mps2`` (n, 3) is the
    seat's acceleration held over each step, world axes.  Returns (n, 3) arrays [m/s^2], [rad/s^2].

    These are the accelerations of the motion the integrator produces.  MuJoCo's acceleration sensors report
    the explicit acceleration M^-1 f at the start of the step, whereas the implicit integrator advances the
    velocity with (M + h D)^-1 f; where the damping h D is not small against the inertia M (neck, spine,
    tissue pads) the two differ by far more than the motion's own step error.
    """
    return np.diff(v_lin, axis=0) / dt_s + seat_acc_mps2, np.diff(v_ang, axis=0) / dt_s


_BADQACC = int(mujoco.mjtWarning.mjWARN_BADQACC)


def step(model: Model, d: mujoco.MjData, seat_acc_mps2: np.ndarray, check: bool = False,
         start_s: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Advance one time step with a seat acceleration (static seat).

    Returns the sensor data of the step's start state and the sensor data after :func:`evaluate_velocities`
    of its end state (velocity sensors valid), from which :func:`point_accelerations` gives the step's
    accelerations.  The same operations as one iteration of :func:`run`, so stepping reproduces whole runs
    exactly.  ``check`` tests for divergence after the step; a step after which MuJoCo found a bad acceleration
    (and reset the state) is refused whatever ``check`` says, since its outputs are those of the reset state
    (a read of one counter, about 1 % of a step).  ``start_s``: the caller's time at the step's start, for the
    divergence sentence (MuJoCo's own clock restarts when it resets the state).
    """
    g = model.mj.opt.gravity
    with model.busy:  # the seat's load goes into the model's gravity: one thread at a time
        g[:] = G0 - seat_acc_mps2
        try:
            mujoco.mj_step(model.mj, d)
        finally:
            g[:] = G0
    if model.head_control is not None:
        after_step(model.head_control, d)
    start = d.sensordata.copy()
    if check or d.warning[_BADQACC].number:
        why = instability(model, d)
        if why:
            raise divergence_error(model, d.time if start_s is None else start_s, why)
    return start, evaluate_velocities(model, d)


@dataclass(frozen=True)
class RawRun:
    """Engine output of one run, sampled at every step (before integration).

    Attributes
    ----------
    time_s : (n,) array
    sensors : dict
        ``<point>_acc`` (absolute translational acceleration over each step, world axes [m/s^2]),
        ``<point>_angacc`` (angular acceleration, world axes [rad/s^2]), both from
        :func:`point_accelerations`; and the raw sensors of each step's start state:
        ``<point>_framepos`` [m], ``<point>_framequat`` (w, x, y, z), ``<point>_framelinvel`` [m/s],
        ``<point>_frameangvel`` [rad/s], each (n, 3) or (n, 4).
    support_N : dict
        Force of each seat surface on the body, (n, 3) [N].
    """

    time_s: np.ndarray
    sensors: dict
    support_N: dict
    poses: dict | None = None  #: ``step`` (m,), ``pos`` (m, k, 3), ``quat`` (m, k, 4) of the bodies drawn


def _run_of(array: np.ndarray, idx) -> np.ndarray:
    """The view ``array[idx]`` for indices that are one contiguous run (written once per step, a slice is
    several times cheaper than fancy indexing); the seat's dofs and controls are built first, so they are."""
    idx = np.asarray(idx, dtype=int)
    if not np.array_equal(idx, np.arange(idx[0], idx[0] + idx.size)):
        raise RuntimeError(f"indices {idx.tolist()} are not one contiguous run")
    return array[idx[0]:idx[0] + idx.size]


def run(model: Model, seat_acc_mps2: np.ndarray, d: mujoco.MjData | None = None,
        seat_rotation: tuple | None = None, pose_every: int | None = None, pose_first: int = 0) -> RawRun:
    """Run the settled model with a seat acceleration history, one row per time step.

    Parameters
    ----------
    seat_acc_mps2 : (n, 3) array
        Translational acceleration of the seat pivot [m/s^2] at t = 0, dt, 2 dt, ... in world axes (equal
        to seat axes when the seat does not rotate).
    d : MjData, optional
        Start state (default: the settled state); advanced in place, so consecutive calls continue a run.
    seat_rotation : (angles, rates, accelerations), each (n, 3) yaw-pitch-roll, optional
        Prescribed seat orientation for a model built with ``rotating_seat=True``.
    pose_every : int, optional
        Record the world pose of every segment body (and of the seat frame, if any) every this many steps,
        for pictures, from step ``pose_first`` on (a run that continues another on the same pose grid).
    """
    mj = model.mj
    if (seat_rotation is not None) != (model.seat is not None):
        raise InputError("a rotating seat needs a seat rotation, and a seat rotation needs a model built with "
                         "rotating_seat=True.")
    if d is None:
        d = settled_data(model)
    acc = np.asarray(seat_acc_mps2, dtype=float)
    n = acc.shape[0]
    sens = np.empty((n, mj.nsensordata))
    drive = _seat_drive(model, d, seat_rotation, n) if seat_rotation is not None else None
    poses = _pose_buffers(model, n, int(pose_every), int(pose_first)) if pose_every else None
    gravity = np.ascontiguousarray(G0[None, :] - acc)
    control = model.head_control
    advance = native.advancer(mj, d, gravity, sens, drive,
                              None if control is None else np.array(control.numeric(), dtype=float))
    if advance is None:
        advance = _advancer(mj, d, gravity, sens, drive, control)
    with model.busy:  # the seat's load goes into the model's gravity at every step: one thread at a time
        try:
            _run_blocks(model, d, n, advance, poses)
        finally:
            mj.opt.gravity[:] = G0
    return _raw_run(model, d, sens, acc, poses)


def _seat_drive(model: Model, d: mujoco.MjData, seat_rotation: tuple, n: int) -> dict:
    """The rotating seat's per-step controls (position and velocity set-points, interleaved per hinge) and
    feed-forward torques, with the views of ``d.ctrl`` and ``d.qfrc_applied`` they are written into."""
    q_des, qd_des, qdd_des = (np.asarray(a, dtype=float) for a in seat_rotation)
    ctrl_adr = np.array(model.seat["ctrl"])
    ctrl = np.empty((n, 6))
    ctrl[:, 0::2], ctrl[:, 1::2] = q_des, qd_des
    ctrl_idx = np.column_stack([ctrl_adr, ctrl_adr + 1]).ravel()
    ff = np.ascontiguousarray(SEAT_INERTIA_KGM2 * qdd_des)  # feed-forward torque of the heavy seat
    c_view, f_view = _run_of(d.ctrl, ctrl_idx), _run_of(d.qfrc_applied, model.seat["dofs"])
    return {"ctrl": ctrl, "ff": ff, "c_view": c_view, "f_view": f_view, "ctrl_adr": int(ctrl_idx[0]),
            "ff_adr": int(model.seat["dofs"][0])}


def _drawn_bodies(model: Model) -> np.ndarray:
    """Body ids whose poses pictures draw: every segment body (and the seat frame, if any)."""
    return np.array([model.segment_bodies[s.name][0] for s in model.body.segments]
                    + ([model.seat["body"]] if model.seat else []))


def _pose_buffers(model: Model, n: int, every: int, first: int = 0) -> dict:
    """Empty pose records of the bodies drawn, one every ``every`` steps from step ``first``."""
    ids = _drawn_bodies(model)
    steps = np.arange(first, n, every)
    return {"every": every, "first": first, "ids": ids, "step": steps, "pos": np.empty((steps.size, ids.size, 3)),
            "quat": np.empty((steps.size, ids.size, 4))}


def deviation_poses(model: Model, x: np.ndarray, static: Model | None = None, seat_R: np.ndarray | None = None,
                    seat_angles_rad: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """World poses of the bodies drawn (as :func:`run` records them: ``pos`` (m, k, 3), ``quat`` (m, k, 4)) in the
    linear model's states ``x`` (m, n_state), by forward kinematics of their positions.

    For a rotating-seat ``model`` the states are those of the static-seat build ``static`` (relative to the seat),
    the seat at ``seat_angles_rad`` (m, 3), rotations ``seat_R`` (m, 3, 3) (:func:`rotating_qpos`)."""
    ids = _drawn_bodies(model)
    d = new_data(model)
    m = x.shape[0]
    pos, quat = np.empty((m, ids.size, 3)), np.empty((m, ids.size, 4))
    for i in range(m):
        if model.seat is None:
            d.qpos[:] = qpos_at_deviation(model, x[i])
        else:
            d.qpos[:] = rotating_qpos(model, static, qpos_at_deviation(static, x[i]), seat_R[i], seat_angles_rad[i])
        mujoco.mj_kinematics(model.mj, d)
        pos[i], quat[i] = d.xpos[ids], d.xquat[ids]
    return pos, quat


def _advancer(mj: mujoco.MjModel, d: mujoco.MjData, gravity: np.ndarray, sens: np.ndarray, drive: dict | None,
              control=None):
    """The hot loop, ``advance(lo, hi)``: steps lo ... hi - 1 with their gravity (and seat drive), each step's
    start sensors into ``sens``.  Views bound once, no allocation per step.  With a head-in-space ``control``
    (:mod:`ehm.engine.control`) each MuJoCo step is followed by the law's update."""
    g_view, s_view = mj.opt.gravity, d.sensordata
    step = mujoco.mj_step if control is None else _controlled_step(control)
    if drive is not None:
        ctrl, ff, c_view, f_view = drive["ctrl"], drive["ff"], drive["c_view"], drive["f_view"]

        def advance(lo: int, hi: int) -> None:
            for i in range(lo, hi):
                g_view[:] = gravity[i]
                c_view[:] = ctrl[i]
                f_view[:] = ff[i]
                step(mj, d)
                sens[i] = s_view
    else:
        def advance(lo: int, hi: int) -> None:
            for i in range(lo, hi):
                g_view[:] = gravity[i]
                step(mj, d)
                sens[i] = s_view
    return advance


def _controlled_step(control):
    """One MuJoCo step followed by the head-in-space control's update (:func:`ehm.engine.control.after_step`)."""
    mj_step = mujoco.mj_step

    def step(m: mujoco.MjModel, d: mujoco.MjData) -> None:
        mj_step(m, d)
        after_step(control, d)
    return step


def _run_blocks(model: Model, d: mujoco.MjData, n: int, advance, poses: dict | None) -> None:
    """All ``n`` steps in blocks (of the pose interval, or :data:`CHECK_EVERY`): a pose at each block's start if
    asked for, the divergence check at least every :data:`CHECK_EVERY` steps and after the last."""
    block = poses["every"] if poses else CHECK_EVERY
    first = poses["first"] if poses else 0
    checked = 0
    starts = ([0] if first else []) + list(range(first, n, block))
    for start, stop in zip(starts, starts[1:] + [n]):
        if poses and start >= first:  # the kinematics of the block's first step's start state, as the sensors
            advance(start, start + 1)
            ids, k = poses["ids"], (start - first) // block
            poses["pos"][k], poses["quat"][k] = d.xpos[ids], d.xquat[ids]
            start += 1
        advance(start, stop)
        if stop - checked >= CHECK_EVERY or stop == n:
            checked = stop
            why = instability(model, d)
            if why:
                raise divergence_error(model, d.time, why)  # d.time: 0 in the settled state, across chunks


def _raw_run(model: Model, d: mujoco.MjData, sens: np.ndarray, acc: np.ndarray, poses: dict | None) -> RawRun:
    """The run's record: sensors by name with the point accelerations over each step (the end state's velocities
    close the last step), support forces by surface, and the poses."""
    mj = model.mj
    n = sens.shape[0]
    slices = sensor_slices(model)
    end = evaluate_velocities(model, d)
    sensors = {name: sens[:, sl] for name, sl in slices.items()}
    for p in POINTS:
        lin, ang = slices[f"{p}_framelinvel"], slices[f"{p}_frameangvel"]
        sensors[f"{p}_acc"], sensors[f"{p}_angacc"] = point_accelerations(
            np.vstack([sens[:, lin], end[lin]]), np.vstack([sens[:, ang], end[ang]]), acc, mj.opt.timestep)
    support = {s: sens[:, sl] for s, sl in support_slices(model).items()}
    recorded = {"step": poses["step"], "pos": poses["pos"], "quat": poses["quat"]} if poses else None
    return RawRun(time_s=np.arange(n) * mj.opt.timestep, sensors=sensors, support_N=support, poses=recorded)
