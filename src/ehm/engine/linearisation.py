"""Linearisation: the settled model's one-step map differentiated by central differences (:func:`linearize`),
as a discrete-time :class:`LinearModel` whose outputs are the point motions, support forces and contact forces."""

from __future__ import annotations

from dataclasses import dataclass, replace

import mujoco
import numpy as np

from .control_linear import CONTROL_INPUTS, control_loads
from .laws import contact_solver_params
from .model import G0, POINTS, SUPPORT_GROUPS, Model
from .seat_geometry import SeatGeometry
from .sensors import SENSOR_KINDS, contact_forces, sensor_slices, support_forces, touching_contacts
from .state import new_data, settle, settled_data, settled_point_poses

#: Per point, in output order: absolute acceleration, displacement, rotation, angular acceleration.
OUTPUT_DOFS = ("ax", "ay", "az", "x", "y", "z", "roll", "pitch", "yaw", "roll_acc", "pitch_acc", "yaw_acc")
#: The uniform field's inputs (seat acceleration less the change of gravity, seat axes [m/s^2]).
FIELD_INPUTS = ("x", "y", "z")
#: The seat rotation's inputs of :func:`linearize` with ``pivot_m`` (after :data:`FIELD_INPUTS`): the seat's
#: angular acceleration alpha (seat axes [rad/s^2]), then the six entries of the symmetric matrix
#: S = w w^T - |w|^2 I of its angular velocity w [rad^2/s^2] (xx, yy, zz, xy, xz, yz): the centripetal
#: acceleration of a point at r from the pivot is S r.
ROTATION_INPUTS = ("alpha_x", "alpha_y", "alpha_z", "s_xx", "s_yy", "s_zz", "s_xy", "s_xz", "s_yz")
#: (row, column) of S for each of the six S inputs.
S_ENTRIES = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))


@dataclass(frozen=True)
class LinearModel:
    """Discrete-time linear model around the settled posture: x+ = A x + B u, y = y0 + C x + D u.

    The state x is MuJoCo's tangent-space state (qpos tangent, qvel, act) relative to the settled state;
    the input u is the seat acceleration (x, y, z) [m/s^2].  The outputs are, per point, ``<point>.<dof>``
    with dof in :data:`OUTPUT_DOFS`: absolute acceleration [m/s^2], displacement [m], rotation (roll, pitch,
    yaw) [rad] and angular acceleration [rad/s^2], the accelerations over the step as in
    :func:`point_accelerations`; then ``support.<group>.f{x,y,z}``, the force of each support group
    (:data:`SUPPORT_GROUPS`) on the body [N]; then ``contact.<name>.fn``, ``.ft1``, ``.ft2``, the normal and
    tangential forces [N] of each contact that touches at rest (contact frame, see :func:`contact_forces`).
    ``y0`` holds the outputs in the settled state (the support forces carry the body's weight there).  Contacts
    are linearised as they are at rest: all stuck.
    With the seat rotation's inputs (:data:`ROTATION_INPUTS`, ``input_names``) the outputs are relative to the
    seat's frame: the accelerations leave out the seat's own alpha x r and S r (added by :mod:`ehm.routes.linear`).
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    dt_s: float
    output_names: tuple
    input_names: tuple = FIELD_INPUTS
    y0: np.ndarray | None = None
    #: Per point, linear then angular velocity (world axes) as outputs of the state: rows of C and D.
    velocity_C: np.ndarray | None = None
    velocity_D: np.ndarray | None = None


def _state_outputs(model: Model, d: mujoco.MjData, ref: dict, slices: dict, contacts: list) -> np.ndarray:
    """Outputs of the state whose sensors ``d`` holds (a step's start): per point displacement, rotation
    vector, linear and angular velocity (world axes); then the support forces by group."""
    out = []
    for p in POINTS:
        vals = {kind: d.sensordata[slices[f"{p}_{kind}"]] for kind in SENSOR_KINDS}
        q0inv = np.empty(4)
        mujoco.mju_negQuat(q0inv, ref[p][1])
        qrel = np.empty(4)
        mujoco.mju_mulQuat(qrel, vals["framequat"], q0inv)
        rotvec = np.empty(3)
        mujoco.mju_quat2Vel(rotvec, qrel, 1.0)
        out += [vals["framepos"] - ref[p][0], rotvec, vals["framelinvel"], vals["frameangvel"]]
    forces = support_forces(model, d)
    for surfaces in SUPPORT_GROUPS.values():  # a group without surfaces (no backrest): zero
        present = [forces[s] for s in surfaces if s in forces]
        out.append(sum(present) if present else np.zeros(3))
    out.append(contact_forces(model, d, contacts))
    return np.concatenate(out)


def seat_pivot(model: Model) -> np.ndarray:
    """The point the rotating seat turns about [m] (world axes of the model at rest): the seat pan's reference
    point, where :func:`ehm.engine.build` puts the hinges of a ``rotating_seat`` build; the same point for a
    static build (whose seat does not turn), so that a static model can be linearised about it."""
    if model.seat is not None:
        return np.array(model.seat["pivot"], dtype=float)
    return np.array(SeatGeometry.from_params(model.params, model.body).planes["seat_pan"][0], dtype=float)


def _cross_matrix(v: np.ndarray) -> np.ndarray:
    """[v]x, the matrix of v x ."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def rotation_loads(model: Model, pivot_m: np.ndarray) -> np.ndarray:
    """Fictitious loads of the seat's rotation on every body at rest, per unit input of :data:`ROTATION_INPUTS`:
    (9, n_body, 6), as ``MjData.xfrc_applied`` (force [N], torque [N m] at the body's centre of mass, world axes).

    In the seat's frame (origin at the pivot, turning with the seat) a body of mass m, centre of mass at c and
    inertia I (world axes, at rest) feels the Euler force -m alpha x (c - pivot) and torque -I alpha, the
    centrifugal force -m S (c - pivot) and the gyroscopic torque -w x (I w), which is linear in S as well
    (-e_ijk (I S)_kj).  The loads are taken at the rest positions: their change with the body's own motion
    (alpha x dr, S dr) and the Coriolis force -2 m w x v are left out (second order: products of the seat's
    rates with the body's deviation).
    """
    mj = model.mj
    d = settled_data(model)
    pivot = np.asarray(pivot_m, dtype=float)
    loads = np.zeros((len(ROTATION_INPUTS), mj.nbody, 6))
    for b in range(1, mj.nbody):
        m = float(mj.body_mass[b])
        if m == 0.0:
            continue
        c = d.xipos[b] - pivot
        Rb = d.ximat[b].reshape(3, 3)
        inertia = Rb @ np.diag(mj.body_inertia[b]) @ Rb.T
        for k in range(3):  # angular acceleration about axis k
            e = np.zeros(3)
            e[k] = 1.0
            loads[k, b, :3] = -m * np.cross(e, c)
            loads[k, b, 3:] = -inertia[:, k]
        for k, (i, j) in enumerate(S_ENTRIES):
            E = np.zeros((3, 3))
            E[i, j] = E[j, i] = 1.0
            IE = inertia @ E
            loads[3 + k, b, :3] = -m * E @ c
            loads[3 + k, b, 3:] = -np.array([IE[2, 1] - IE[1, 2], IE[0, 2] - IE[2, 0], IE[1, 0] - IE[0, 1]])
    return loads


def linearize(model: Model, eps: float = 1e-6, step_s: float | None = None,
              pivot_m: np.ndarray | None = None) -> LinearModel:
    """Linearise the settled model by central finite differences of one time step.

    The state outputs (positions, rotations, velocities, support forces and the forces of the touching
    contacts at a step's start state) are differentiated directly; the accelerations are the velocity change
    over the step plus the seat acceleration, exactly as :func:`run` computes them: with V the velocity rows,
    C_acc = (V A - V) / h and D_acc = V B / h (+ the identity for the seat acceleration).  ``step_s``
    linearises one step of another length h around the same settled state (default: the model's step).
    Costs 2 (n_state + n_input) time steps.

    ``pivot_m`` (a point [m], :func:`seat_pivot`): also linearise for the seat's rotation about it, in the
    seat's own frame: nine more inputs (:data:`ROTATION_INPUTS`), the seat's angular acceleration and the
    centripetal matrix S of its angular velocity, applied as the fictitious loads of :func:`rotation_loads`
    (``MjData.xfrc_applied``).  The model itself is the static seat's; the first three inputs are then the
    uniform field's change (seat acceleration plus the change of gravity in seat axes), the acceleration rows'
    identity is for them as before.

    A model with head-in-space control (:mod:`ehm.engine.control`) is linearised without it, with three more inputs
    last (:data:`CONTROL_INPUTS`: the control's torque on the head, world axes, held over the step), which
    :func:`ehm.engine.close_loop` closes with the control's own linear model (its delay as Padé states).
    """
    mj = model.mj
    if model.settled is None:
        settle(model)
    s = model.settled
    ref = settled_point_poses(model)
    slices = sensor_slices(model)
    contacts = touching_contacts(model)
    own_step = float(mj.opt.timestep)
    h = own_step if step_s is None else float(step_s)
    d = new_data(model)
    nv, na = mj.nv, mj.na
    nx = 2 * nv + na
    warm = settled_data(model).qacc_warmstart.copy()
    loads = _loads(model, pivot_m)
    nu = len(FIELD_INPUTS) + (0 if loads is None else loads.shape[0])

    def evaluate(dx: np.ndarray, du: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        mujoco.mj_resetData(mj, d)
        qpos = s["qpos"].copy()
        mujoco.mj_integratePos(mj, qpos, dx[:nv], 1.0)
        d.qpos[:] = qpos
        d.qvel[:] = s["qvel"] + dx[nv:2 * nv]
        d.act[:] = s["act"] + dx[2 * nv:]
        d.qacc_warmstart[:] = warm
        mj.opt.gravity[:] = G0 - du[:3]
        if loads is not None:
            d.xfrc_applied[:] = np.tensordot(du[3:], loads, axes=1)
        mj.opt.timestep = h
        try:
            mujoco.mj_step(mj, d)
        finally:
            mj.opt.gravity[:] = G0
            mj.opt.timestep = own_step
        y = _state_outputs(model, d, ref, slices, contacts)
        x_next = np.empty(nx)
        mujoco.mj_differentiatePos(mj, x_next[:nv], 1.0, s["qpos"], d.qpos)
        x_next[nv:2 * nv] = d.qvel - s["qvel"]
        x_next[2 * nv:] = d.act - s["act"]
        return x_next, y

    if h != own_step:  # the contacts' trapezoidal law is written for the step taken
        contact_solver_params(mj, model.body, model.params, h)
    try:
        A, B, Cs, Ds, y0 = _differentiate(evaluate, nx, eps, nu)
    finally:
        if h != own_step:
            contact_solver_params(mj, model.body, model.params, own_step)
    lm = _with_accelerations(A, B, Cs, Ds, y0, h, contacts)
    return replace(lm, input_names=FIELD_INPUTS + (() if pivot_m is None else ROTATION_INPUTS)
                   + (() if model.head_control is None else CONTROL_INPUTS))


def _loads(model: Model, pivot_m: np.ndarray | None) -> np.ndarray | None:
    """Loads on the bodies per unit input beyond the uniform field (as ``MjData.xfrc_applied``): the seat rotation's
    (:func:`rotation_loads`, with ``pivot_m``), then the head-in-space control's torque (:data:`CONTROL_INPUTS`, when
    the model has the control, which the step linearised does not apply itself)."""
    parts = ([] if pivot_m is None else [rotation_loads(model, pivot_m)]) + \
        ([] if model.head_control is None else [control_loads(model)])
    return np.concatenate(parts) if parts else None


def _differentiate(evaluate, nx: int, eps: float, nu: int = 3):
    """Central differences of one step: state and output matrices (A, B, C, D) and the outputs y0."""
    _, y0 = evaluate(np.zeros(nx), np.zeros(nu))
    ny = y0.size
    A, Cs = np.empty((nx, nx)), np.empty((ny, nx))
    B, Ds = np.empty((nx, nu)), np.empty((ny, nu))
    for i in range(nx):
        e = np.zeros(nx)
        e[i] = eps
        xp, yp = evaluate(e, np.zeros(nu))
        xm, ym = evaluate(-e, np.zeros(nu))
        A[:, i] = (xp - xm) / (2 * eps)
        Cs[:, i] = (yp - ym) / (2 * eps)
    for k in range(nu):
        e = np.zeros(nu)
        e[k] = eps * 1e3  # input perturbation [m/s^2, rad/s^2 or rad^2/s^2]
        xp, yp = evaluate(np.zeros(nx), e)
        xm, ym = evaluate(np.zeros(nx), -e)
        B[:, k] = (xp - xm) / (2 * e[k])
        Ds[:, k] = (yp - ym) / (2 * e[k])
    return A, B, Cs, Ds, y0


def _with_accelerations(A, B, Cs, Ds, y0, dt, contacts):
    """Rearrange the state outputs of :func:`linearize` into :data:`OUTPUT_DOFS` per point plus the support
    forces, adding the acceleration rows (velocity change over the step, plus the seat acceleration)."""
    rows_C, rows_D, rows_y0, names = [], [], [], []
    for i, p in enumerate(POINTS):
        base = 12 * i  # displacement 3, rotation 3, linear velocity 3, angular velocity 3
        disp, rot, lin, ang = (slice(base + 3 * j, base + 3 * j + 3) for j in range(4))
        acc_C = lambda v: (Cs[v] @ A - Cs[v]) / dt  # noqa: E731
        acc_D = lambda v: Cs[v] @ B / dt  # noqa: E731
        rows_C += [acc_C(lin), Cs[disp], Cs[rot], acc_C(ang)]
        rows_D += [acc_D(lin) + np.eye(3, B.shape[1]), Ds[disp], Ds[rot], acc_D(ang)]
        rows_y0 += [np.zeros(3), y0[disp], y0[rot], np.zeros(3)]
        names += [f"{p}.{dof}" for dof in OUTPUT_DOFS]
    forces = slice(12 * len(POINTS), None)
    rows_C.append(Cs[forces])
    rows_D.append(Ds[forces])
    rows_y0.append(y0[forces])
    names += [f"support.{g}.f{a}" for g in SUPPORT_GROUPS for a in "xyz"]
    names += [f"contact.{c}.{k}" for c in contacts for k in ("fn", "ft1", "ft2")]
    return LinearModel(A=A, B=B, C=np.vstack(rows_C), D=np.vstack(rows_D), dt_s=dt, output_names=tuple(names),
                       y0=np.concatenate(rows_y0), velocity_C=Cs[_velocity_rows()], velocity_D=Ds[_velocity_rows()])


def _velocity_rows() -> np.ndarray:
    """Rows of the per-point linear and angular velocities among the state outputs of :func:`linearize`."""
    return np.concatenate([np.arange(12 * i + 6, 12 * i + 12) for i in range(len(POINTS))])
