"""Settling and state: a fresh state, the person settled into the seat under gravity (:func:`settle`, kept on
the model), that settled state as data and point poses, and the whole integration state to save and restore."""

from __future__ import annotations

import mujoco
import numpy as np

from . import control as _control
from .diagnostics import CHECK_EVERY, captured_warnings, divergence_error, instability
from .model import G0, Model


def new_data(model: Model) -> mujoco.MjData:
    """A fresh MjData at the reference posture."""
    return mujoco.MjData(model.mj)


def settle(model: Model, duration_s: float | None = None) -> dict:
    """Let the person sink into the seat under gravity until the posture controller has converged.

    Starts from the reference posture; the integral action of the posture control pulls the open-chain
    joints back to it.  For the first ``simulation.back_slide_s`` the backrest contacts are frictionless.  The
    settled state (``qpos``, ``qvel``, ``act``) is stored on the model and returned.
    Raises :class:`DivergenceError` if the model does not stay seated.
    """
    slide_s = float(model.params.value("simulation.back_slide_s"))
    if duration_s is None:
        duration_s = float(model.params.value("simulation.settle_s"))
    else:  # a settling time other than the file's: slide for at most half of it
        slide_s = min(slide_s, duration_s / 2)
    mj = model.mj
    d = new_data(model)
    mj.opt.gravity[:] = G0
    n = int(round(duration_s / mj.opt.timestep))
    # The back first slides onto the backrest pads without friction, so that it comes to rest there without
    # a shear preload (sinking into the cushion would otherwise leave the back pads at their friction limit).
    n_slide = int(round(slide_s / mj.opt.timestep))
    back = [mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_PAIR, c.name) for c in model.body.contacts
            if c.surface.startswith("backrest")]
    friction = mj.pair_friction[back].copy()
    mj.pair_friction[back, :2] = 0.0
    try:
        with captured_warnings():
            for i in range(n):
                if i == n_slide:
                    mj.pair_friction[back] = friction
                mujoco.mj_step(mj, d)
                if i % CHECK_EVERY == 0:
                    why = instability(model, d)
                    if why:
                        raise divergence_error(model, d.time, why, " while settling into the seat, before the run")
    finally:
        mj.pair_friction[back] = friction
    why = instability(model, d)
    if why:
        raise divergence_error(model, d.time, why, " while settling into the seat, before the run")
    model.settled = {"qpos": d.qpos.copy(), "qvel": d.qvel.copy(), "act": d.act.copy(), "settle_s": duration_s}
    if model.head_control is not None:
        _check_head_control(model)
    return model.settled


def _check_head_control(model: Model) -> None:
    """The settled person's head-in-space control refused, in one sentence naming its stability margin, when its
    gains and delay leave the linearised loop unstable (:func:`ehm.engine.control_linear.check_stability`: one
    linearisation and a few eigenvalue problems, about 0.03 s when stable); the person then stays unsettled, so that
    every later run is refused too.  Here, where every route, the stepping and the FMUs settle the person."""
    from .control_linear import check_stability
    from .linearisation import linearize

    try:
        check_stability(model, linearize(model))
    except BaseException:
        model.settled = None
        raise


def settled_data(model: Model) -> mujoco.MjData:
    """A fresh MjData in the settled state (settling first if needed), time reset to 0."""
    if model.settled is None:
        settle(model)
    d = new_data(model)
    d.qpos[:] = model.settled["qpos"]
    d.qvel[:] = model.settled["qvel"]
    d.act[:] = model.settled["act"]
    mujoco.mj_forward(model.mj, d)
    _control.start(model.head_control, d)
    return d


def settled_point_poses(model: Model) -> dict:
    """Per output point: position [m] and orientation quaternion (w, x, y, z) in the settled state."""
    d = settled_data(model)
    out = {}
    for point, sid in model.point_sites.items():
        quat = np.empty(4)
        mujoco.mju_mat2Quat(quat, d.site_xmat[sid])
        out[point] = (d.site_xpos[sid].copy(), quat)
    return out


def get_state(model: Model, d: mujoco.MjData) -> np.ndarray:
    """The full integration state of ``d`` (positions, velocities, activations, time, ...)."""
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    buf = np.empty(mujoco.mj_stateSize(model.mj, spec))
    mujoco.mj_getState(model.mj, d, buf, spec)
    return buf


def set_state(model: Model, d: mujoco.MjData, state: np.ndarray) -> None:
    """Put a state from :func:`get_state` back into ``d``."""
    mujoco.mj_setState(model.mj, d, state, mujoco.mjtState.mjSTATE_INTEGRATION)


def data_at_deviation(model: Model, x: np.ndarray, time_s: float = 0.0) -> mujoco.MjData:
    """A fresh MjData at the state ``x`` of the linear model (:func:`ehm.engine.linearize`: MuJoCo's tangent-space
    state, positions, velocities and activations, relative to the settled state), at ``time_s``."""
    s = model.settled if model.settled is not None else settle(model)
    d = settled_data(model)
    nv = model.mj.nv
    d.qpos[:] = qpos_at_deviation(model, x)
    d.qvel[:] = s["qvel"] + x[nv:2 * nv]
    d.act[:] = s["act"] + x[2 * nv:2 * nv + model.mj.na]  # a closed loop's control states follow: not MuJoCo's
    d.time = time_s
    mujoco.mj_forward(model.mj, d)
    return d


def qpos_at_deviation(model: Model, x: np.ndarray) -> np.ndarray:
    """The positions (qpos) of the linear model's state ``x``: its first nv entries integrated from the settled
    qpos (MuJoCo's tangent space)."""
    s = model.settled if model.settled is not None else settle(model)
    qpos = s["qpos"].copy()
    mujoco.mj_integratePos(model.mj, qpos, np.ascontiguousarray(x[:model.mj.nv]), 1.0)
    return qpos


def deviation_of(model: Model, d: mujoco.MjData) -> np.ndarray:
    """The state of ``d`` as the linear model's state ``x``: the inverse of :func:`data_at_deviation`."""
    s = model.settled if model.settled is not None else settle(model)
    nv = model.mj.nv
    x = np.empty(2 * nv + model.mj.na)
    mujoco.mj_differentiatePos(model.mj, x[:nv], 1.0, s["qpos"], d.qpos)
    x[nv:2 * nv] = d.qvel - s["qvel"]
    x[2 * nv:] = d.act - s["act"]
    return x


def _free_joint(model: Model) -> tuple[int, int]:
    """qpos and dof address of the (one) free joint, the pelvis's."""
    j = int(np.flatnonzero(model.mj.jnt_type == mujoco.mjtJoint.mjJNT_FREE)[0])
    return int(model.mj.jnt_qposadr[j]), int(model.mj.jnt_dofadr[j])


def _quat(R: np.ndarray) -> np.ndarray:
    q = np.empty(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(R).ravel())
    return q


def _quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    q = np.empty(4)
    mujoco.mju_mulQuat(q, a, b)
    return q


def _quat_mat(q: np.ndarray) -> np.ndarray:
    R = np.empty(9)
    mujoco.mju_quat2Mat(R, q)
    return R.reshape(3, 3)


def rotating_data_at(rotating: Model, static: Model, x: np.ndarray, seat_R: np.ndarray, seat_angles_rad: np.ndarray,
                     seat_rates_radps: np.ndarray, seat_w_radps: np.ndarray, time_s: float = 0.0) -> mujoco.MjData:
    """MjData of the rotating-seat model ``rotating`` in the state that ``x`` (the state of the static-seat model
    ``static``'s linear model: positions and velocities relative to the seat) has in the world, the seat at
    ``seat_angles_rad`` (yaw, pitch, roll; rotation ``seat_R``, seat axes -> world axes) turning at
    ``seat_rates_radps`` (the hinges' rates), ``seat_w_radps`` in its own axes.

    The two models differ by the seat's three hinges, built first: every other joint is the same and relative to
    its parent, but the pelvis's free joint is in the world: its position p + R (r - p) about the pivot p, its
    orientation R q, its linear velocity R (v + w x (r - p)) (world axes, as MuJoCo's free joint) and its
    angular velocity (its own axes) that relative to the seat plus the seat's w.
    """
    ds = data_at_deviation(static, x)
    d = new_data(rotating)
    kv = rotating.mj.nv - static.mj.nv
    d.qpos[:] = rotating_qpos(rotating, static, ds.qpos, seat_R, seat_angles_rad)
    d.qvel[rotating.seat["dofs"]] = seat_rates_radps
    d.qvel[kv:], d.act[:] = ds.qvel, ds.act
    a, b = _free_joint(static)
    p = rotating.seat["pivot"]
    r, q = ds.qpos[a:a + 3], ds.qpos[a + 3:a + 7]
    d.qvel[kv + b:kv + b + 3] = seat_R @ (ds.qvel[b:b + 3] + np.cross(seat_w_radps, r - p))
    d.qvel[kv + b + 3:kv + b + 6] = ds.qvel[b + 3:b + 6] + _quat_mat(q).T @ seat_w_radps
    if rotating.head_control is not None:  # the law's reference up, the rotating model's own, its line empty
        d.userdata[:] = settled_data(rotating).userdata
    d.time = time_s
    mujoco.mj_forward(rotating.mj, d)
    return d


def rotating_qpos(rotating: Model, static: Model, qpos: np.ndarray, seat_R: np.ndarray,
                  seat_angles_rad: np.ndarray) -> np.ndarray:
    """The rotating-seat model's positions for the static-seat model's ``qpos`` (relative to the seat), the seat at
    ``seat_angles_rad`` (rotation ``seat_R``): the seat's hinges first, the pelvis's free joint carried about the
    pivot p into the world (position p + R (r - p), orientation R q), every other joint as it is."""
    k = rotating.mj.nq - static.mj.nq
    out = np.zeros(rotating.mj.nq)
    out[k:] = qpos
    out[rotating.seat["qpos"]] = seat_angles_rad
    a, _ = _free_joint(static)
    p = rotating.seat["pivot"]
    r, q = qpos[a:a + 3], qpos[a + 3:a + 7]
    out[k + a:k + a + 3] = p + seat_R @ (r - p)
    out[k + a + 3:k + a + 7] = _quat_mul(_quat(seat_R), q)
    return out


def static_deviation_of(rotating: Model, static: Model, d: mujoco.MjData, seat_R: np.ndarray,
                        seat_w_radps: np.ndarray) -> np.ndarray:
    """The state ``x`` of the static-seat model's linear model that the rotating-seat model's data ``d`` holds,
    relative to the seat at rotation ``seat_R`` turning at ``seat_w_radps`` (own axes): the inverse of
    :func:`rotating_data_at`."""
    ds = new_data(static)
    k, kv = rotating.mj.nq - static.mj.nq, rotating.mj.nv - static.mj.nv
    ds.qpos[:], ds.qvel[:], ds.act[:] = d.qpos[k:], d.qvel[kv:], d.act
    a, b = _free_joint(static)
    p = rotating.seat["pivot"]
    r = p + seat_R.T @ (d.qpos[k + a:k + a + 3] - p)
    q = _quat_mul(_quat(seat_R.T), d.qpos[k + a + 3:k + a + 7])
    ds.qpos[a:a + 3], ds.qpos[a + 3:a + 7] = r, q
    ds.qvel[b:b + 3] = seat_R.T @ d.qvel[kv + b:kv + b + 3] - np.cross(seat_w_radps, r - p)
    ds.qvel[b + 3:b + 6] = d.qvel[kv + b + 3:kv + b + 6] - _quat_mat(q).T @ seat_w_radps
    return deviation_of(static, ds)


def set_seat(model: Model, d: mujoco.MjData, angles_rad: np.ndarray, rates_radps: np.ndarray) -> None:
    """Put a rotating seat's hinges of ``d`` at yaw, pitch, roll ``angles_rad`` turning at ``rates_radps`` (Euler
    angle rates), the rest of the state as it is (a segment's start, :mod:`ehm.routes.parallel`)."""
    d.qpos[model.seat["qpos"]] = angles_rad
    d.qvel[model.seat["dofs"]] = rates_radps
    mujoco.mj_forward(model.mj, d)
