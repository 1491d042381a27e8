"""The linear route: the settled person as a continuous-time state-space model, for small vibration.

Most of what ehm runs is small-amplitude vibration, where the model behaves linearly: contacts stay
closed and stuck.  :func:`continuous_model` linearises the settled model by finite differences of one
MuJoCo step at a fine step (the model's step / 8 by default, where the integrator's own error is a few
per mille) and converts that step to continuous time exactly (matrix logarithm of the zero-order-hold
step, ``[[A_d, B_d], [0, I]] = expm([[A, B], [0, 0]] h)``).  Accelerations are then the derivative of the
velocity outputs, ``V (A x + B u)`` plus the seat acceleration, so the model has no step error of its own.

A time run (:func:`simulate_linear`, :func:`stream_linear`) evaluates the model in modal form, with two
reductions: modes that the input does not reach (time constant over 1000 s, input gain at the finite
differences' round-off: the integral actuators' neutral directions) are left out, and modes above
:data:`STATIC_ABOVE_HZ` (which follow the seat within half a millisecond) are taken as static, their
quasi-static response added to the direct term; against the full model the outputs stay within 0.1 % of
their rms (tested).  It discretises the rest exactly at the sample step of its input (first-order hold: the
seat acceleration linear between samples); :class:`ehm.SeatedHuman` gives it the motion resampled to the
model's step by the same anti-aliased :class:`ehm.inputs.resampling.Resampler` as the nonlinear route, so that both
routes see the same input (a first-order hold at a low log rate, 20 Hz, would cut the head's rms by a
fifth).  It arranges the discretised model in blocks of :data:`BLOCK` samples, so that a whole run is one
matrix product (block inputs and block start state to
all the block's outputs) after a recursion over the block starts only (``block_form``).  While it runs
it checks that the model still holds: every touching contact must keep pressing (normal force > 0) and
stay inside its friction cone; otherwise it raises :class:`LinearRouteError` saying when, where and by how
much the input was too large.

:func:`ehm.linear_frf` evaluates the same model's frequency response exactly; there is one
linearisation and one state-space model.

A motion that rotates the seat runs in the seat's own frame on a second model of the same static-seat
person, with twelve inputs (:func:`continuous_model` with ``pivot_m``): the uniform field with the tilt taken
exactly, and the seat's angular acceleration and centripetal matrix as fictitious loads at the bodies' rest
positions; what that leaves out (Coriolis and the loads' change with the body's displacement) is estimated
per point in the result (:func:`ehm.routes.linear.left_out`).  See :func:`stream_linear`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import linalg
from scipy.spatial.transform import Rotation

from .. import engine
from ..errors import InputError
from ..inputs.kinematics import seat_kinematics
from ..outputs.results import POINT_NAMES, PointMotion, RunResult
from .built import built_of

#: Finer step used for the linearisation: the model's step divided by this.
REFINE = 8
_POINT_OUTPUTS = ("ax", "ay", "az", "x", "y", "z", "roll", "pitch", "yaw", "roll_acc", "pitch_acc", "yaw_acc",
                  "wx", "wy", "wz")


class LinearRouteError(InputError):
    """The input is too large for the linear route: a contact lifts off or slides."""


@dataclass(frozen=True)
class StateSpace:
    """Continuous-time model around the settled posture: dx/dt = A x + B u, y = y0 + C x + D u.

    u is the seat acceleration (x, y, z) [m/s^2].  Outputs ``<point>.<name>`` for name in
    ``ax, ay, az`` (absolute acceleration [m/s^2]), ``x, y, z`` (displacement [m]), ``roll, pitch, yaw``
    (rotation vector of R R0^T [rad]), ``roll_acc, pitch_acc, yaw_acc`` [rad/s^2] and ``wx, wy, wz``
    (angular velocity [rad/s]), all in seat axes; ``support.<group>.f{x,y,z}`` [N]; and
    ``contact.<name>.fn, ft1, ft2`` [N] of every contact touching at rest (with ``friction`` its
    coefficient).  ``y0`` holds the outputs at rest.

    A model of the seat's rotation (``pivot_m`` set, see :func:`continuous_model`) has the twelve inputs
    ``input_names``: the uniform field's change (the seat's acceleration plus G0 - R^T G0), the seat's angular
    acceleration and the centripetal matrix of its angular velocity (:data:`ehm.engine.ROTATION_INPUTS`).  Its
    outputs are relative to the seat's frame (seat axes), except the point accelerations (absolute, once the time
    run has taken the tilt's share G0 - R^T G0 back out) and angular accelerations (absolute); the time run
    adds the seat's angular velocity (:func:`stream_linear`).
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    y0: np.ndarray
    output_names: tuple
    contacts: tuple
    friction: dict
    linearised_at_step_s: float
    input_names: tuple = engine.FIELD_INPUTS
    pivot_m: np.ndarray | None = None  #: the seat's pivot [m] of a model with its rotation's inputs (else None)
    cache: dict = field(default_factory=dict, repr=False, compare=False)  #: discretisations by sample step

    def index(self, name: str) -> int:
        return self.output_names.index(name)

    def rows(self, names) -> np.ndarray:
        return np.array([self.index(n) for n in names])


def continuous_model(model: engine.Model, refine: int = REFINE, pivot_m: np.ndarray | None = None,
                     control_delay_s: float | None = None) -> StateSpace:
    """Linearise the settled ``model`` at its step / ``refine`` and convert to continuous time.

    Parameters
    ----------
    model : ehm.engine.Model
        A static-seat model.
    refine : int
        The linearisation's step is the model's step divided by this.
    pivot_m : (3,) array, optional
        The seat's pivot [m] (``ehm.engine.seat_pivot``): linearise for the seat's rotation about it as well
        (twelve inputs, ``ehm.engine.linearize``); the point accelerations then include the seat's own
        alpha x r and S r (r the point's rest position from the pivot) and the angular accelerations the seat's
        alpha, so that they are absolute like the nonlinear route's.  None: seat translation only (three inputs).
    control_delay_s : float, optional
        A model with head-in-space control: its loop is closed with this delay [s] instead of the one the engine
        applies (``ehm.engine.feedback``; a study of the delay margin).
    """
    if model.head_control is not None and pivot_m is not None:
        raise InputError("the linear route of a seat that turns does not carry the head-in-space control (it would "
                         "sense the head relative to the seat, not in space); run the nonlinear route "
                         "(method='nonlinear' or 'auto').")
    h = float(model.mj.opt.timestep) / refine
    lm = engine.linearize(model, step_s=h, pivot_m=pivot_m)
    nx, nu = lm.B.shape
    block = np.zeros((nx + nu, nx + nu))
    block[:nx, :nx], block[:nx, nx:], block[nx:, nx:] = lm.A, lm.B, np.eye(nu)
    L = linalg.logm(block)
    if np.iscomplexobj(L):
        if np.abs(L.imag).max() > 1e-8 * max(1.0, np.abs(L.real).max()):
            raise InputError("the linear route cannot be built for this person: its linearised step has no real "
                             "logarithm (a mode faster than the step / 8 it is linearised at); use the nonlinear "
                             "route.")
        L = L.real
    A, B = L[:nx, :nx] / h, L[:nx, nx:] / h

    names = list(lm.output_names)
    C_rows, D_rows, y0, out_names = [], [], [], []
    settled = engine.settled_point_poses(model)
    for i, p in enumerate(engine.POINTS):
        V, Vd = lm.velocity_C[6 * i:6 * i + 6], lm.velocity_D[6 * i:6 * i + 6]  # linear then angular velocity
        acc_C, acc_D = V @ A, V @ B
        acc_D[:3, :3] += np.eye(3)  # absolute = relative to the seat frame + the seat's own acceleration
        if pivot_m is not None:  # + the seat's alpha x r + S r at the point's rest position r; + alpha
            r = settled[p][0] - np.asarray(pivot_m, dtype=float)
            acc_D[:3, 3:6] += [[0.0, r[2], -r[1]], [-r[2], 0.0, r[0]], [r[1], -r[0], 0.0]]  # alpha x r
            for k, (a, b) in enumerate(engine.S_ENTRIES):
                acc_D[a, 6 + k] += r[b]
                if a != b:
                    acc_D[b, 6 + k] += r[a]
            acc_D[3:, 3:6] += np.eye(3)
        keep = [names.index(f"{p}.{k}") for k in ("x", "y", "z", "roll", "pitch", "yaw")]
        C_rows += [acc_C[:3], lm.C[keep], acc_C[3:], V[3:]]
        D_rows += [acc_D[:3], lm.D[keep], acc_D[3:], Vd[3:]]
        y0 += [np.zeros(3), lm.y0[keep], np.zeros(6)]
        out_names += [f"{p}.{k}" for k in _POINT_OUTPUTS]
        if pivot_m is not None:  # the velocity relative to the seat, for the Coriolis acceleration
            C_rows.append(V[:3])
            D_rows.append(Vd[:3])
            y0.append(np.zeros(3))
            out_names += [f"{p}.{k}" for k in _VELOCITY]
    rest = [k for k, n in enumerate(names) if n.startswith(("support.", "contact."))]
    C_rows.append(lm.C[rest])
    D_rows.append(lm.D[rest])
    y0.append(lm.y0[rest])
    out_names += [names[k] for k in rest]
    contacts = tuple(n.split(".")[1] for n in out_names if n.startswith("contact.") and n.endswith(".fn"))
    friction = {c: float(model.params.value(f"contacts.{c}.friction")) for c in contacts}
    C, D, inputs = np.vstack(C_rows), np.vstack(D_rows), lm.input_names
    if model.head_control is not None:  # the control's linear model closes the loop (its delay as Padé states)
        A, B, C, D, inputs = engine.close_loop(A, B, C, D, inputs, out_names,
                                                     engine.feedback(model, control_delay_s))
    ss = StateSpace(A=A, B=B, C=C, D=D, y0=np.concatenate(y0),
                    output_names=tuple(out_names), contacts=contacts, friction=friction, linearised_at_step_s=h,
                    input_names=inputs, pivot_m=None if pivot_m is None else np.array(pivot_m, dtype=float))
    settled_orientations(ss, model)  # kept with the model: a time run need not know which engine model it was
    return ss


def linear_model(person, rotation: bool = False) -> StateSpace:
    """The person linearised at the settled posture, continuous time (:func:`continuous_model`; computed once per
    person and kept in its :attr:`~ehm.routes.built.BuiltPerson.linear`, about 0.1 s after settling).

    ``rotation`` False: the model of seat translation (three inputs, the seat's acceleration); True: with the
    seat's rotation about its pivot (``ehm.engine.seat_pivot``) in the seat's own frame, twelve inputs
    (:func:`stream_linear`).  Both are linearised on the person on a static seat
    (:attr:`~ehm.routes.built.BuiltPerson.static_model`).  ``person``: a :class:`~ehm.routes.built.BuiltPerson`
    (or a :class:`ehm.SeatedHuman`, whose is taken).
    """
    person = built_of(person)
    key = "rotation" if rotation else "translation"
    if key not in person.linear:
        model = person.static_model  # the linearisation is in the seat's frame: the static seat's model
        person.linear[key] = continuous_model(model, pivot_m=engine.seat_pivot(model) if rotation else None)
    return person.linear[key]


def frequency_response(ss: StateSpace, freq_hz: np.ndarray, rows=None) -> np.ndarray:
    """H(f) = C (j 2 pi f I - A)^-1 B + D, complex (n_freq, n_outputs, n_inputs); ``rows`` selects outputs."""
    C, D = (ss.C, ss.D) if rows is None else (ss.C[rows], ss.D[rows])
    lam, V = np.linalg.eig(ss.A)
    CV, VinvB = C @ V, np.linalg.solve(V, ss.B)
    s = 2j * np.pi * np.asarray(freq_hz, dtype=float)
    inv = 1.0 / (s[:, None] - lam[None, :])
    return np.einsum("os,fs,si->foi", CV, inv, VinvB) + D[None, :, :]


#: Modes faster than this follow the seat within a fraction of a millisecond: time runs take them as static
#: (their quasi-static response is added to D, "residualisation") [Hz].
STATIC_ABOVE_HZ = 250.0
#: Samples per block of the block form that time runs evaluate (see ``block_form``).
BLOCK = 8
#: A mode with a time constant beyond 1000 s whose input gain (unit eigenvector) is below this share of the
#: largest is not reached by the input and left out of time runs.
UNREACHED_GAIN = 1e-6


@dataclass(frozen=True)
class _Modes:
    """The continuous model in modal form as time runs use it.

    ``lam`` holds the kept modes, real ones first, then one of each complex pair; ``B`` (m, nu) and ``C``
    (p, m) their input rows and output columns (complex; real for the real modes); a real mode contributes
    ``C z`` to the outputs, a pair ``2 Re(C z)`` (``weight`` 1 or 2).  ``D`` includes the static share of the
    modes above :data:`STATIC_ABOVE_HZ`; modes that the input does not reach (``unreached``) are left out.
    """

    lam: np.ndarray
    B: np.ndarray
    C: np.ndarray
    weight: np.ndarray
    n_real: int
    D: np.ndarray
    y0: np.ndarray
    static_hz: np.ndarray  #: natural frequencies of the modes taken as static
    unreached: int  #: number of modes left out: time constant over 1000 s, input gain at round-off level
    V: np.ndarray  #: (n_state, m) the kept modes' eigenvectors: the state x = sum of w Re(V z) + X_static u
    W: np.ndarray  #: (m, n_state) the kept modes' rows of V^-1: z = W x
    X_static: np.ndarray  #: (n_state, nu) the static modes' share of the state per unit input
    P_unreached: np.ndarray  #: (n_state, n_state) projection of a state onto the modes left out (not reached)


def modal_form(ss: StateSpace) -> _Modes:
    cached = ss.cache.get("modes")
    if cached is None:
        lam, V = np.linalg.eig(ss.A)
        Bm, Cm = np.linalg.solve(V, ss.B), ss.C @ V
        # Modes with a time constant beyond 1000 s whose input gain is at the finite differences' round-off
        # (the default person has 16, all below 2e-8 of the largest gain, the next smallest at 3e-6): the
        # integral actuators' neutral directions, which the seat's acceleration does not drive.
        gain = np.linalg.norm(Bm, axis=1)
        unreached = (np.abs(lam) < 1e-3) & (gain < UNREACHED_GAIN * gain.max())
        static = (np.abs(lam) > 2 * np.pi * STATIC_ABOVE_HZ) & ~unreached
        # a fast mode dz/dt = lam z + B u stays at its quasi-static value z = -B u / lam
        D = ss.D - (Cm[:, static] @ (Bm[static] / lam[static, None])).real
        real = np.abs(lam.imag) <= 1e-12 * np.maximum(1.0, np.abs(lam))
        kept_real = real & ~static & ~unreached
        kept_pair = (lam.imag > 0) & ~real & ~static & ~unreached
        lam_k = np.concatenate([lam[kept_real].real + 0j, lam[kept_pair]])
        B = np.vstack([Bm[kept_real].real + 0j, Bm[kept_pair]])
        C = np.hstack([Cm[:, kept_real].real + 0j, Cm[:, kept_pair]])
        weight = np.concatenate([np.ones(kept_real.sum()), 2 * np.ones(kept_pair.sum())])
        Winv = np.linalg.inv(V)
        kept = np.concatenate([np.flatnonzero(kept_real), np.flatnonzero(kept_pair)])
        X_static = -(V[:, static] @ (Bm[static] / lam[static, None])).real
        cached = _Modes(lam=lam_k, B=B, C=C, weight=weight, n_real=int(kept_real.sum()), D=D, y0=ss.y0,
                        static_hz=np.sort(np.abs(lam[static])) / (2 * np.pi), unreached=int(unreached.sum()),
                        V=V[:, kept], W=Winv[kept], X_static=X_static,
                        P_unreached=(V[:, unreached] @ Winv[unreached]).real)
        ss.cache["modes"] = cached
    return cached


def reduced_model(ss: StateSpace):
    """The model time runs evaluate, as real continuous-time matrices (A, B, C, D): the kept modes (2 x 2
    blocks for complex pairs), the fast modes' static share in D; outputs are deviations from ``ss.y0``."""
    m = modal_form(ss)
    nr, lam = m.n_real, m.lam
    npair = lam.size - nr
    n = nr + 2 * npair
    A = np.zeros((n, n))
    A[np.arange(nr), np.arange(nr)] = lam[:nr].real
    re, im = nr + np.arange(npair), nr + npair + np.arange(npair)  # z = Re z + i Im z
    A[re, re], A[re, im] = lam[nr:].real, -lam[nr:].imag
    A[im, re], A[im, im] = lam[nr:].imag, lam[nr:].real
    B = np.vstack([m.B[:nr].real, m.B[nr:].real, m.B[nr:].imag])
    C = np.hstack([m.C[:, :nr].real, 2 * m.C[:, nr:].real, -2 * m.C[:, nr:].imag])
    return A, B, C, m.D


def _foh(lam: np.ndarray, h: float):
    """First-order-hold discretisation of the scalar modes dz/dt = lam z + b u over a step h, the input linear
    between samples: z[k+1] = phi z[k] + (g0 u[k] + g1 u[k+1]) b.  Returns phi, g0 + phi g1 (the input gain of
    the state z~ = z - g1 b u, which makes the recursion z~[k+1] = phi z~[k] + (g0 + phi g1) b u[k]) and g1."""
    x = lam * h
    small = np.abs(x) < 0.1
    xs = np.where(small, 1.0, x)
    # e1 = (e^x - 1) / x and e2 = (e^x - 1 - x) / x^2, by their series where x is small
    k = np.arange(9)
    fact = np.cumprod(np.concatenate([[1.0], np.arange(1, 11)]))  # 0! .. 10!
    powers = np.where(small, x, 0.0)[:, None] ** k
    e1 = np.where(small, powers @ (1 / fact[1:10]), np.expm1(xs) / xs)
    e2 = np.where(small, powers @ (1 / fact[2:11]), (np.expm1(xs) - xs) / xs ** 2)
    phi = np.exp(x)
    g1 = h * e2
    return phi, h * (e1 - e2) + phi * g1, g1


#: Output kinds per point in a time run's output array, in this order (each: every point of
#: ``engine.POINTS`` in turn; x, y, z).
_KINDS = (("ax", "ay", "az"), ("x", "y", "z"), ("roll", "pitch", "yaw"), ("roll_acc", "pitch_acc", "yaw_acc"),
          ("wx", "wy", "wz"))
_ACC, _DISP, _ROTVEC, _ANGACC, _ANGVEL = range(5)
#: A model of the seat's rotation also gives each point's velocity relative to the seat (seat axes) [m/s]; a time
#: run has them after the support forces, before the contacts (see :func:`output_layout`).
_VELOCITY = ("vx", "vy", "vz")
_NP = len(POINT_NAMES)  #: output points
_PER_KIND = 3 * _NP  #: rows of one kind of :data:`_KINDS` in a time run's output array (points x axes)
_SUPPORT_ROWS = slice(len(_KINDS) * _PER_KIND, len(_KINDS) * _PER_KIND + 3 * len(engine.SUPPORT_GROUPS))
_VELOCITY_ROWS = slice(_SUPPORT_ROWS.stop, _SUPPORT_ROWS.stop + _PER_KIND)


def _kind(y: np.ndarray, k: int) -> np.ndarray:
    """The rows of output kind ``k`` (an index into :data:`_KINDS`) of a time run's output array: the points'
    x, y, z in turn."""
    return y[_PER_KIND * k:_PER_KIND * (k + 1)]


def head_sensed(y: np.ndarray, n: int, first: int = 0) -> np.ndarray:
    """What the head-in-space control senses (``ehm.engine.control_linear.SENSED``: the head's roll and pitch, its
    rotation vector's horizontal components, and its angular velocity, seat axes) at the samples ``first`` ... n - 1
    of a time run's outputs ``y`` (as ``block_chunk`` returns them), (n - first, 5) in time order."""
    i = list(engine.POINTS).index("head")
    b0 = first // BLOCK  # only the blocks that hold those samples
    rot, w = _kind(y, _ROTVEC)[3 * i:3 * i + 2, :, b0:], _kind(y, _ANGVEL)[3 * i:3 * i + 3, :, b0:]
    return in_time_order(np.concatenate([rot, w]))[:, first - b0 * BLOCK:n - b0 * BLOCK].T


def output_layout(ss: StateSpace) -> np.ndarray:
    """Output indices in the order a time run computes them: per kind of :data:`_KINDS` the points'
    three axes, then the support groups' x, y, z, (for a model of the seat's rotation the points' velocities,
    :data:`_VELOCITY`,) then all contacts' fn, all ft1, all ft2."""
    cached = ss.cache.get("layout")
    if cached is None:
        names = [f"{p}.{k}" for kind in _KINDS for p in engine.POINTS for k in kind]
        names += [f"support.{g}.f{a}" for g in engine.SUPPORT_GROUPS for a in "xyz"]
        if ss.pivot_m is not None:
            names += [f"{p}.{k}" for p in engine.POINTS for k in _VELOCITY]
        names += [f"contact.{c}.{k}" for k in ("fn", "ft1", "ft2") for c in ss.contacts]
        cached = ss.rows(names)
        ss.cache["layout"] = cached
    return cached


@dataclass(frozen=True)
class _Blocks:
    """The modal model discretised at one sample step (first-order hold) and arranged for blocks of
    :data:`BLOCK` samples (see ``block_form``)."""

    dt_s: float
    phi: np.ndarray  #: (m,) modal transition over one step
    Bd: np.ndarray  #: (m, nu) modal input gain of the hold-transformed state z~
    g1: np.ndarray  #: (m,) z = z~ + g1 B u
    B: np.ndarray  #: (m, nu) continuous modal input rows
    n_real: int
    drive: np.ndarray  #: (nu L, 2 m) a block's inputs -> the state one block later (Re, Im of each mode in turn)
    phi_block: np.ndarray  #: (m,) transition over one block
    M: np.ndarray  #: (p L, nu L + n + 1): output o at the block's sample j (row o L + j) from [block inputs,
    #: block start state (real modes, then Re and Im of each pair in turn), 1], outputs in :func:`output_layout` order


def block_form(ss: StateSpace, dt_s: float) -> _Blocks:
    """Discretise the kept modes at ``dt_s`` and build the block matrix.

    Within a block of L samples starting at state z_b, sample j's outputs are y0 + Dd u[j] + sum_{i<j}
    H_(j-1-i) u[i] + O_j z_b (H_k = Re C diag(w phi^k) Bd, O_j = C diag(w phi^j) in real form), so a whole run is
    one matrix product of M with the rows [u of the block's L samples, z_b (real, Re and Im of pairs), 1].
    Only the block start states need a recursion (over n / L samples).
    """
    cached = ss.cache.get(("blocks", dt_s))
    if cached is None:
        m = modal_form(ss)
        L = BLOCK
        phi, gain, g1 = _foh(m.lam, dt_s)
        Bd = gain[:, None] * m.B
        P = phi[None, :] ** np.arange(L + 1)[:, None]  # (L + 1, m): phi^j
        M = _block_matrix(m, Bd, (m.C * (m.weight * g1)) @ m.B, P)[:, :, output_layout(ss)]  # (K, L, p)
        nu = m.B.shape[1]
        G = (P[L - 1::-1, :, None] * Bd[None, :, :]).transpose(0, 2, 1).reshape(nu * L, -1)  # phi^(L-1-i) Bd
        cached = _Blocks(dt_s=dt_s, phi=phi, Bd=Bd, g1=g1, B=m.B, n_real=m.n_real,
                         drive=np.ascontiguousarray(np.stack([G.real, G.imag], axis=2).reshape(nu * L, -1)),
                         phi_block=P[L],
                         M=np.ascontiguousarray(M.transpose(2, 1, 0).reshape(-1, M.shape[0])))
        ss.cache[("blocks", dt_s)] = cached
    return cached


def _block_matrix(m: _Modes, Bd: np.ndarray, hold_D: np.ndarray, P: np.ndarray) -> np.ndarray:
    """M[k, j, o]: row k of [block inputs (sample i, axis), block start state (real modes, then Re and Im of
    each pair in turn), 1] -> output o at the block's sample j."""
    L, p, nr, nu = BLOCK, m.C.shape[0], m.n_real, m.B.shape[1]
    Dd = (m.D + hold_D).real  # y = C z + D u = C z~ + (D + C g1 B) u
    Cw = m.C * m.weight
    H = np.einsum("pm,km,mi->kpi", Cw, P[:L - 1], Bd).real  # H_k, k = 0 .. L - 2
    Mu = np.zeros((L, nu, L, p))  # [input sample i, input] -> [output sample j, output]
    for j in range(L):
        Mu[j, :, j, :] = Dd.T
        for i in range(j):
            Mu[i, :, j, :] = H[j - 1 - i].T
    Q = Cw[None, :, :] * P[:L, None, :]  # (L, p, m); a pair gives 2 Re(C z) = 2 Re C Re z - 2 Im C Im z
    pairs = np.stack([Q[:, :, nr:].real, -Q[:, :, nr:].imag], axis=3).reshape(L, p, -1)
    Out = np.concatenate([Q[:, :, :nr].real, pairs], axis=2)  # (L, p, n)
    return np.concatenate([Mu.reshape(nu * L, L, p), Out.transpose(2, 0, 1), np.tile(m.y0, (1, L, 1))])


def initial_state(blk: _Blocks, u0: np.ndarray) -> np.ndarray:
    """Modal state z~ of the person at rest (z = 0) when the seat acceleration starts at ``u0``."""
    return -blk.g1 * (blk.B @ u0)


def state_of(ss: StateSpace, blk: _Blocks, carry: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The full state x of the continuous model (``ehm.engine.linearize``'s, relative to the settled state)
    from a time run's modal state ``carry`` (z~, as ``block_chunk`` advances it) at a sample whose input
    is ``u`` (nu,); the modes left out of time runs (not reached by the input) are taken as zero.  Rows of
    ``carry`` (k, m) and ``u`` (k, nu) give the states' rows (k, n_state)."""
    m = modal_form(ss)
    wz = m.weight * (carry + blk.g1 * (u @ blk.B.T))
    real = np.ascontiguousarray  # Re(V w z) as real products of contiguous arrays: BLAS's, 10x faster for many rows
    return real(wz.real) @ real(m.V.real.T) - real(wz.imag) @ real(m.V.imag.T) + u @ m.X_static.T


def carry_of(ss: StateSpace, blk: _Blocks, x: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The modal state z~ of a time run at a sample whose state is ``x`` and input ``u`` (nu,): the inverse of
    :func:`state_of` on the kept modes (a state's share in the modes left out is dropped)."""
    m = modal_form(ss)
    return m.W @ x - blk.g1 * (blk.B @ u)


def block_chunk(blk: _Blocks, u: np.ndarray, carry: np.ndarray) -> np.ndarray:
    """Outputs (absolute, y0 included) at the input samples ``u`` (n, nu), (p, L, blocks) in :func:`output_layout`
    order: output o at sample b L + j is [o, j, b]; the last block is padded past n.  ``carry`` holds the
    modal state z~ at the chunk's first sample and is advanced past its last sample (in place)."""
    (n, nu), L = u.shape, BLOCK
    nb = -(-n // L)
    X = np.empty((nb, blk.M.shape[1]))
    _block_inputs(X[:, :nu * L], u, L)
    S = _block_starts(blk, X[:, :nu * L], carry)
    nr = blk.n_real
    X[:, nu * L:nu * L + nr] = S[:, :nr].real
    X[:, nu * L + nr:-1].view(complex)[:] = S[:, nr:]
    X[:, -1] = 1.0
    y = (blk.M @ X.T).reshape(-1, L, nb)
    _carry_past(blk, S[-1], u, carry)
    return y


def _carry_past(blk: _Blocks, last_start: np.ndarray, u: np.ndarray, carry: np.ndarray) -> None:
    """``carry`` (in place) past the input samples ``u``, from the modal state at their last block's start."""
    n, L = u.shape[0], BLOCK
    last = (-(-n // L) - 1) * L
    r = n - last  # r <= L steps from the last block's start
    pw = blk.phi[None, :] ** np.arange(r - 1, -1, -1)[:, None]  # (r, m): phi^(r-1-i)
    carry[:] = blk.phi ** r * last_start + np.einsum("im,mk,ik->m", pw, blk.Bd, u[last:])


def advance(blk: _Blocks, u: np.ndarray, carry: np.ndarray) -> None:
    """Advance the modal state ``carry`` (in place) past the input samples ``u`` (n, nu), as ``block_chunk``
    does, without computing the outputs."""
    (n, nu), L = u.shape, BLOCK
    U = np.empty((-(-n // L), nu * L))
    _block_inputs(U, u, L)
    _carry_past(blk, _block_starts(blk, U, carry)[-1], u, carry)


def _block_inputs(Xu: np.ndarray, u: np.ndarray, L: int) -> None:
    """Write the input samples into the block rows (the last block padded with zeros)."""
    n, nu = u.shape
    full = n // L
    Xu[:full] = u[:full * L].reshape(full, nu * L)
    if full < Xu.shape[0]:
        Xu[full] = 0.0
        Xu[full, :nu * (n - full * L)] = u[full * L:].ravel()


def _block_starts(blk: _Blocks, U: np.ndarray, carry: np.ndarray) -> np.ndarray:
    """The modal states at the blocks' first samples (blocks, m), complex: z_(b+1) = phi^L z_b + (block b's
    inputs U[b]) @ drive, from z_0 = ``carry``."""
    e = (U[:-1] @ blk.drive).view(complex)  # (nb - 1, m)
    return scan(blk.phi_block, e, carry)


def scan(a: np.ndarray, e: np.ndarray, z0: np.ndarray) -> np.ndarray:
    """s[0] = z0, s[k + 1] = a s[k] + e[k] for all modes at once: (len(e) + 1, m).

    Two levels of about sqrt(n) steps each, vectorised over the modes and the other level: the recursion
    within segments of q steps from zero, then the segments' first values, then both added."""
    n, m = e.shape[0] + 1, a.size
    q = max(1, int(np.sqrt(n)))
    c = (n - 1) // q  # whole segments
    out = np.empty((n, m), dtype=np.result_type(a, e, z0))
    out[0] = z0
    if c:
        E = e[:c * q].reshape(c, q, m)
        local = np.empty((c, q, m), dtype=out.dtype)  # local[:, j]: after j + 1 steps from zero
        local[:, 0] = E[:, 0]
        for j in range(1, q):
            np.multiply(a, local[:, j - 1], out=local[:, j])
            local[:, j] += E[:, j]
        first = np.empty((c, m), dtype=out.dtype)  # the segments' first values s[i q]
        first[0] = z0
        aq = a ** q
        for i in range(c - 1):
            first[i + 1] = aq * first[i] + local[i, q - 1]
        seg = out[1:c * q + 1].reshape(c, q, m)  # s[i q + j + 1] = a^(j + 1) s[i q] + local[i, j]
        np.multiply((a[None, :] ** np.arange(1, q + 1)[:, None])[None], first[:, None, :], out=seg)
        seg += local
    for k in range(c * q, n - 1):  # the rest, fewer than q steps
        out[k + 1] = a * out[k] + e[k]
    return out


def contact_rows(ss: StateSpace, y: np.ndarray):
    """The touching contacts' normal and tangential forces fn, ft1, ft2 [N] among a time run's outputs ``y`` (as
    ``block_chunk`` returns them; the contacts' rows come last): three (contacts, L, blocks) views."""
    nc = len(ss.contacts)
    first = y.shape[0] - 3 * nc
    return tuple(y[first + k * nc:first + (k + 1) * nc] for k in range(3))


def _validity(ss: StateSpace, y: np.ndarray, n: int, t: np.ndarray, whole: bool = True) -> None:
    """Raise :class:`LinearRouteError` if a contact lifts off or slides anywhere in the run's ``n`` samples
    (``y`` as ``block_chunk`` returns it); ``whole``: these samples end the motion (else the advised scale
    covers the motion up to them only)."""
    if not ss.contacts:
        return
    fn, ft1, ft2 = contact_rows(ss, y)
    # A quick test over all samples, the last block's padding included: if every one is clearly inside (the
    # squares, with a margin of 1e-12), the run holds; otherwise the exact test below decides, on the run's
    # own samples.
    limit = (1 - 1e-12) * np.array([ss.friction[c] for c in ss.contacts]) ** 2
    if fn.min() > 0:
        shear = ft1 * ft1
        shear += ft2 * ft2
        press = fn * fn
        press *= limit[:, None, None]
        if (shear <= press).all():
            return
    checks = [_ContactCheck(ss, c, *(in_time_order(f[j])[:n] for f in (fn, ft1, ft2)))
              for j, c in enumerate(ss.contacts)]
    failed = [ck for ck in checks if not ck.holds(1.0)]
    if not failed:
        return
    worst = min(failed, key=lambda ck: ck.largest_scale())
    s = worst.largest_scale()
    advised = advised_scale(s, lambda f: all(ck.holds(f) for ck in failed))
    k = int(np.argmax(worst.violations(1.0)))
    what = "lifts off the seat" if worst.n0 + worst.dn[k] <= 0 else "slides (friction at its Coulomb limit)"
    scope = "this motion" if whole else f"this motion up to t = {t[-1]:.3g} s (the rest not yet checked)"
    advice = (f"holds for {scope} scaled by {advised:.2g} or less" if advised > 0
              else f"holds only for {scope} scaled by less than 1e-9")
    raise LinearRouteError(
        f"the input is too large for the linear route: at t = {t[k]:.3f} s the {worst.contact} contact {what}; "
        f"the linear route {advice} (about {1 / max(s, 1e-9):.1f} times too large); use the nonlinear route "
        "(method='nonlinear', --method nonlinear).")


class _ContactCheck:
    """One contact's forces over a run, as equilibrium plus a dynamic part that scales with the input."""

    def __init__(self, ss: StateSpace, contact: str, fn: np.ndarray, ft1: np.ndarray, ft2: np.ndarray):
        self.contact, self.mu = contact, ss.friction[contact]
        self.n0, self.t10, self.t20 = ss.y0[ss.rows([f"contact.{contact}.{k}" for k in ("fn", "ft1", "ft2")])]
        self.dn, self.dt1, self.dt2 = fn - self.n0, ft1 - self.t10, ft2 - self.t20
        self._largest = None

    def violations(self, scale: float) -> np.ndarray:
        """Samples where, with the dynamic part scaled by ``scale``, the contact lifts off or leaves its cone."""
        n = self.n0 + scale * self.dn
        return (n <= 0) | (np.hypot(self.t10 + scale * self.dt1, self.t20 + scale * self.dt2) > self.mu * n)

    def holds(self, scale: float) -> bool:
        return not self.violations(scale).any()

    def largest_scale(self) -> float:
        """Largest scale (to 2**-30) at which every sample holds: bisection, the constraints being convex in
        the scale (so every smaller scale holds too)."""
        if self._largest is None:
            lo, hi = 0.0, 1.0
            for _ in range(30):
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if self.holds(mid) else (lo, mid)
            self._largest = lo
        return self._largest


def advised_scale(limit: float, holds, digits: int = 2) -> float:
    """A scale factor to advise: ``limit`` less a millionth, rounded down to ``digits`` significant digits,
    and lowered by one unit of its last digit until ``holds(factor)`` is true (0 when none is found).

    Parameters
    ----------
    limit : float
        The largest scale at which the check holds, from bisection.
    holds : callable(float) -> bool
        The check itself, at a scale.
    digits : int
        Significant digits of the advice.
    """
    if not limit > 0:
        return 0.0
    x = limit * (1 - 1e-6)
    unit = 10.0 ** (math.floor(math.log10(x)) - digits + 1)
    for m in range(math.floor(x / unit), 0, -1):
        factor = float(f"{m * unit:.{digits}g}")
        if holds(factor):
            return factor
    return 0.0


def in_time_order(x: np.ndarray) -> np.ndarray:
    """(..., L, blocks) -> (..., blocks L): samples in time order (a copy)."""
    return np.ascontiguousarray(np.swapaxes(x, -1, -2)).reshape(*x.shape[:-2], -1)


def stream_linear(human, motion, chunk_s: float = 10.0, progress=None, dt_s: float | None = None):
    """Run ``motion`` (a :class:`ehm.inputs.motion.SeatMotion`) through the linear route, chunk by chunk.

    Yields one :class:`ehm.outputs.results.RunResult` per chunk (absolute times, the motion's own time step), like
    :meth:`ehm.SeatedHuman.stream`; raises :class:`LinearRouteError` as soon as a contact would lift off or
    slide.  ``progress(done_s, total_s)`` is called after every chunk.  The person starts at rest in the
    settled posture.  ``dt_s`` [s]: run on this step instead, the motion resampled onto it one chunk at a time
    (:class:`ehm.inputs.resampling.Resampler`, as the nonlinear route does), so that no resampled copy of the whole
    motion
    is made.

    A motion that rotates the seat (angular velocities not all zero) runs on the model of the seat's rotation
    (``human.linear_model(rotation=True)``, :func:`continuous_model` with the pivot), in the seat's own frame:
    the seat's orientation R, angular velocity w and angular acceleration alpha come from
    ``ehm.inputs.kinematics.seat_kinematics`` as in the nonlinear route; the inputs are the uniform field's change
    a_seat + G0 - R^T G0 (the tilt exactly, no small-angle approximation), alpha and the centripetal matrix
    ``w w^T - |w|^2 I`` (the fictitious loads at the bodies' rest positions).  The results are in the nonlinear
    route's terms: absolute point accelerations and angular accelerations in seat axes, angular velocities
    (absolute) and gravito-inertial accelerations in the points' own axes, displacements and rotations
    relative to the seat, and ``seat_angles_rad``; the kinematic terms of the body's own motion in the
    turning frame (Coriolis 2 w x v and the like) are added to the outputs exactly.  What the linear model
    leaves out of the body's dynamics (the fictitious loads that are products of the seat's rates with the
    body's own motion) is estimated per point in ``result.extra["linear_check"]`` (:func:`left_out`); a
    motion without rotation runs exactly as before.
    """
    w_seat = motion.angvel_radps
    rotating = w_seat is not None and bool(np.any(w_seat != 0))
    kin = seat_kinematics(motion.time_s, w_seat) if rotating else None  # on the motion's own samples, as nonlinear
    grid = None
    if dt_s is None:
        steps = np.diff(motion.time_s)
        dt = float(np.median(steps))
        if np.abs(steps - dt).max() > 1e-6 * dt:
            motion = motion.resample(dt)
        del steps
    else:
        from ..inputs.resampling import Resampler

        dt = float(dt_s)
        grid = Resampler(motion.time_s, motion.acc_mps2, dt)
    human = built_of(human)
    ss = linear_model(human, rotation=rotating)
    blk = block_form(ss, float(f"{dt:.12g}"))  # one discretisation per step, not per rounding of it
    R0 = settled_orientations(ss, human.model)
    n_total = motion.time_s.size if grid is None else grid.n_samples
    description = motion.description if grid is None else f"{motion.description}, resampled to dt {dt:g} s"
    per_chunk = n_total if not np.isfinite(chunk_s) else max(1, int(round(chunk_s / dt)))
    carry = None
    for start in range(0, n_total, per_chunk):
        t0 = time.perf_counter()
        stop = min(n_total, start + per_chunk)
        if grid is None:
            t, u = motion.time_s[start:stop] - motion.time_s[0], motion.acc_mps2[start:stop]
        else:
            t, u = np.arange(start, stop) * dt, grid.block(start, stop)
        seat = None if kin is None else SeatRotation.at(kin, t, u)
        inputs = u if seat is None else seat.inputs
        if carry is None:
            carry = initial_state(blk, inputs[0])
        y = block_chunk(blk, inputs, carry)
        check = None
        if seat is not None:
            check = left_out(y, len(t), seat)
            seat.correct(y)
        _validity(ss, y, len(t), t, whole=stop == n_total)
        result = run_result(human, ss, y, u, t, dt, R0, description, seat=seat, check=check)
        yield replace(result, wall_s=time.perf_counter() - t0)
        del result, y, u, inputs, seat  # the next chunk is made without this one held here
        if progress:
            progress(min(t[-1] + dt, motion.duration_s), motion.duration_s)


@dataclass(frozen=True)
class SeatRotation:
    """The seat's rotation over a chunk's samples, as the linear route takes it.

    ``angles_rad`` (n, 3) yaw, pitch, roll, as the nonlinear route drives the seat
    (``ehm.inputs.kinematics.seat_kinematics``, linearly interpolated); ``w_radps`` and ``alpha_radps2`` (n, 3) the
    seat's angular velocity and acceleration in seat axes (from the Euler angles, their rates and accelerations:
    what the seat's hinges do); ``g_seat_mps2`` (n, 3) gravity in seat axes, R^T G0 with R the rotation of the
    angles (seat axes -> world axes, ``ehm.inputs.kinematics.seat_rotation_matrices``); ``inputs`` (n, 12) the
    linear model's inputs (:func:`continuous_model` with a pivot).
    """

    angles_rad: np.ndarray
    w_radps: np.ndarray
    alpha_radps2: np.ndarray
    g_seat_mps2: np.ndarray
    inputs: np.ndarray

    @classmethod
    def at(cls, kin, t_s: np.ndarray, acc_mps2: np.ndarray) -> SeatRotation:
        """The rotation at times ``t_s`` [s] (from the motion's start) with the seat's acceleration ``acc_mps2``
        (n, 3, seat axes)."""
        angles, rates, accs = kin.at(t_s)
        w, alpha = seat_body_rates(angles, rates, accs)
        # R^T G0 = G0_z (R_20, R_21, R_22) for R = Rz(yaw) Ry(pitch) Rx(roll) and G0 along z
        pitch, roll = angles[:, 1], angles[:, 2]
        cp = np.cos(pitch)
        g = engine.G0[2] * np.column_stack([-np.sin(pitch), cp * np.sin(roll), cp * np.cos(roll)])
        inputs = np.empty((t_s.size, 12))
        np.add(acc_mps2, engine.G0 - g, out=inputs[:, :3])
        inputs[:, 3:6] = alpha
        w2 = np.einsum("ni,ni->n", w, w)
        for k, (i, j) in enumerate(engine.S_ENTRIES):  # S = w w^T - |w|^2 I
            np.multiply(w[:, i], w[:, j], out=inputs[:, 6 + k])
            if i == j:
                inputs[:, 6 + k] -= w2
        return cls(angles_rad=angles, w_radps=w, alpha_radps2=alpha, g_seat_mps2=g, inputs=inputs)

    def correct(self, y: np.ndarray) -> None:
        """Outputs of ``block_chunk`` (in place) to the nonlinear route's terms.

        The acceleration rows less G0 - R^T G0 (the input's tilt share, which the D matrix's identity put in),
        plus the kinematic terms of the body's own motion in the turning frame, exact given the linear outputs:
        the Coriolis acceleration 2 w x v, and S dr + alpha x dr (the seat's centripetal and Euler acceleration
        at the displacement dr from rest; at rest they are in D); the angular acceleration rows plus
        w x w_rel; the angular velocity rows plus the seat's own w (absolute, seat axes).  (v, dr and w_rel:
        the point's velocity, displacement and angular velocity relative to the seat, seat axes.)"""
        L, nb = y.shape[1:]
        acc, disp, angacc, angvel = (_kind(y, k).reshape(_NP, 3, L, nb) for k in (_ACC, _DISP, _ANGACC, _ANGVEL))
        vel = y[_VELOCITY_ROWS].reshape(_NP, 3, L, nb)
        w, alpha = _to_blocks(self.w_radps, L, nb), _to_blocks(self.alpha_radps2, L, nb)
        acc -= _to_blocks(engine.G0 - self.g_seat_mps2, L, nb)[None]
        for i in range(_NP):  # 2 w x v + w x (w x dr) = w x (2 v + w x dr), then alpha x dr
            _add_cross(acc[i], w, _add_cross(2 * vel[i], w, disp[i]))
            _add_cross(acc[i], alpha, disp[i])
            _add_cross(angacc[i], w, angvel[i])
        angvel += w[None]


def _add_cross(out: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """out += a x b for vectors along the first axis (3, ...); returns ``out`` (numpy's cross along another axis
    than the last copies: four times slower)."""
    out[0] += a[1] * b[2] - a[2] * b[1]
    out[1] += a[2] * b[0] - a[0] * b[2]
    out[2] += a[0] * b[1] - a[1] * b[0]
    return out


def _to_blocks(v: np.ndarray, L: int, nb: int) -> np.ndarray:
    """(n, 3) samples -> (3, L, blocks) as ``block_chunk`` lays outputs out (padding zero)."""
    out = np.zeros((nb * L, 3))
    out[:v.shape[0]] = v
    return out.reshape(nb, L, 3).transpose(2, 1, 0)


def seat_body_rates(angles_rad: np.ndarray, rates_radps: np.ndarray, accs_radps2: np.ndarray):
    """The seat's angular velocity [rad/s] and acceleration [rad/s^2] in its own axes (n, 3 each) from z-y-x
    angles (yaw psi, pitch theta, roll phi) with their rates and accelerations (columns yaw, pitch, roll):
    wx = phi' - psi' sin theta, wy = theta' cos phi + psi' cos theta sin phi,
    wz = -theta' sin phi + psi' cos theta cos phi, and their time derivatives."""
    th, ph = angles_rad[:, 1], angles_rad[:, 2]
    dps, dth, dph = rates_radps.T
    aps, ath, aph = accs_radps2.T
    sth, cth, sph, cph = np.sin(th), np.cos(th), np.sin(ph), np.cos(ph)
    w = np.column_stack([dph - dps * sth, dth * cph + dps * cth * sph, -dth * sph + dps * cth * cph])
    alpha = np.column_stack([
        aph - aps * sth - dps * dth * cth,
        ath * cph - dth * dph * sph + aps * cth * sph - dps * dth * sth * sph + dps * dph * cth * cph,
        -ath * sph - dth * dph * cph + aps * cth * cph - dps * dth * sth * cph - dps * dph * cth * sph,
    ])
    return w, alpha


def left_out(y: np.ndarray, n: int, seat: SeatRotation) -> dict:
    """What the linear model of the seat's rotation leaves out, per point, from a chunk's outputs ``y`` (as
    ``block_chunk`` returns them, before :meth:`SeatRotation.correct`) over its ``n`` samples.

    The outputs carry the turning frame's kinematic terms exactly (:meth:`SeatRotation.correct`); the body's
    dynamics leave out the fictitious loads that are products of the seat's rates with the body's own motion:
    the Coriolis force -2 m w x v, the change of the Euler and centripetal loads with the displacement, and
    the gyroscopic torques of the rotation relative to the seat.  Their size per unit mass at each output
    point, against the point's own acceleration, estimates their effect (the response to a load is of the
    order of the load per unit mass).

    Per point (``pelvis``, ``trunk``, ``head``, ``lumbar``) a dict: ``coriolis_mps2``, the largest ``2 |w| |v|`` (v
    the point's velocity relative to the seat); ``offset_mps2``, the largest ``(|w|^2 + |alpha|) |dr|`` (dr its
    displacement from rest); ``left_out_rms_mps2``, the rms over time of their sum; ``acc_rms_mps2``, the rms of its
    absolute acceleration (vector length); ``share``, the one rms over the other; ``gyro_radps2`` and
    ``gyro_rms_radps2``, the largest and the rms ``|w| |w_rel|`` (w_rel its angular velocity relative to the seat);
    ``angacc_rms_radps2`` and ``angular_share`` (rms over rms) likewise; and ``n`` the samples.  At the top level
    ``share``: the largest share of all points, to compare with a tolerance (e.g. 0.01).  Rms against rms: the
    loads' own size per unit mass against the response's, an estimate of the order of their effect, not a bound.
    Measured: on a SYNTHETIC yaw spin-up to 0.6 rad/s the linear route's error against the nonlinear model was
    6.2, 0.39, 1.5 and 0.39 % of the rms at pelvis, trunk, head and lumbar point, estimated 12, 0.83, 2.6 and 0.12 %
    (the largest, 12 %, covers the largest error); on the x-io IMU log moved by hand (its first 15 s) 0.6 %
    estimated where the nonlinear model's figures differ by 0.002 % (the largest load against the rms, as this
    estimate was before, gave 8.8 %, and 292 % with the stretches the nonlinear model ran counted in).
    """
    kind = lambda k: in_time_order(_kind(y, k))[:, :n].reshape(_NP, 3, n)  # noqa: E731
    acc = kind(_ACC) - (engine.G0 - seat.g_seat_mps2).T[None]
    disp, w_rel, angacc = kind(_DISP), kind(_ANGVEL), kind(_ANGACC)
    vel = in_time_order(y[_VELOCITY_ROWS])[:, :n].reshape(_NP, 3, n)
    w = np.linalg.norm(seat.w_radps, axis=1)
    a = np.linalg.norm(seat.alpha_radps2, axis=1)
    out, worst = {}, 0.0
    rms = lambda x: float(np.sqrt(np.mean(x * x)))  # noqa: E731
    for i, p in enumerate(POINT_NAMES):
        coriolis_t = 2 * w * np.linalg.norm(vel[i], axis=0)
        offset_t = (w * w + a) * np.linalg.norm(disp[i], axis=0)
        gyro_t = w * np.linalg.norm(w_rel[i], axis=0)
        acc_rms = float(np.sqrt(np.mean(np.sum(acc[i] ** 2, axis=0))))
        angacc_rms = float(np.sqrt(np.mean(np.sum(angacc[i] ** 2, axis=0))))
        left_rms, gyro_rms = rms(coriolis_t + offset_t), rms(gyro_t)
        share = left_rms / acc_rms if acc_rms > 0 else 0.0
        angular = gyro_rms / angacc_rms if angacc_rms > 0 else 0.0
        out[p] = {"coriolis_mps2": float(np.max(coriolis_t)), "offset_mps2": float(np.max(offset_t)),
                  "left_out_rms_mps2": left_rms, "acc_rms_mps2": acc_rms, "share": share,
                  "gyro_radps2": float(np.max(gyro_t)), "gyro_rms_radps2": gyro_rms, "angacc_rms_radps2": angacc_rms,
                  "angular_share": angular, "n": n}
        worst = max(worst, share, angular)
    out["share"] = worst
    return out


def settled_orientations(ss: StateSpace, model: engine.Model) -> dict:
    """The points' orientation matrices R0 in the settled state (point, 3, 3), kept with the linear model."""
    if "R0" not in ss.cache:
        settled = engine.settled_point_poses(model)
        ss.cache["R0"] = np.stack([Rotation.from_quat(settled[p][1], scalar_first=True).as_matrix()
                                   for p in engine.POINTS])
    return ss.cache["R0"]


#: Power series in x^2 (coefficients of x^0, x^2, ...) of sin x / x and (1 - cos x) / x^2, for the small
#: rotations of a linear run (15 times quicker than np.sinc there; numpy's arctan2 and arcsin need no series).
_SINC = (1.0, -1 / 6, 1 / 120, -1 / 5040, 1 / 362880, -1 / 39916800, 1 / 6227020800)
_VERSC = (1 / 2, -1 / 24, 1 / 720, -1 / 40320, 1 / 3628800, -1 / 479001600, 1 / 87178291200)
_SERIES_UP_TO = 0.06  #: |x| up to which the series are used (their terms reach round-off there)


def _series(x2: np.ndarray, coeffs: tuple, x2_max: float) -> np.ndarray:
    """sum_k coeffs[k] x^(2k) by Horner's scheme, with only the terms above 1e-17 of the first at x2_max."""
    k = len(coeffs)
    while k > 1 and abs(coeffs[k - 1]) * x2_max ** (k - 1) < 1e-17 * abs(coeffs[0]):
        k -= 1
    acc = np.multiply(x2, coeffs[k - 1])
    for c in coeffs[k - 2:0:-1]:
        acc += c
        acc *= x2
    acc += coeffs[0]
    return acc


def _rodrigues_factors(t2: np.ndarray):
    """a = sin t / t and b = (1 - cos t) / t^2 of the rotation angle t (t2 = t^2)."""
    t2_max = float(t2.max())
    if t2_max <= _SERIES_UP_TO ** 2:
        return _series(t2, _SINC, t2_max), _series(t2, _VERSC, t2_max)
    t = np.sqrt(t2)
    return np.sinc(t / np.pi), 0.5 * np.sinc(t / (2 * np.pi)) ** 2


def _orientations(y: np.ndarray, R0: np.ndarray, gravity: np.ndarray | None = None):
    """The points' rotation (roll, pitch, yaw), angular velocity and gravito-inertial acceleration in their own
    axes from the rotation vector r (R = R_rel R0, R_rel = exp([r]x)), all points and axes at once: three
    arrays (point, axis, L, blocks) like ``y[...]`` of ``block_chunk``'s layout.  ``gravity``: gravity in
    seat axes per sample, (3, L, blocks) (a rotating seat's R^T G0), default G0."""
    kind = lambda k: _kind(y, k).reshape(_NP, 3, *y.shape[1:])  # noqa: E731  (point, axis, L, blocks)
    r, w, acc = kind(_ROTVEC), kind(_ANGVEL), kind(_ACC)
    rot, angvel, gia = (np.empty_like(r) for _ in range(3))
    r0, r1, r2 = r[:, 0], r[:, 1], r[:, 2]
    s0, s1, s2 = r0 * r0, r1 * r1, r2 * r2
    a, b = _rodrigues_factors(s0 + s1 + s2)  # R_rel = I + a [r]x + b [r]x^2,  [r]x^2 = r r^T - |r|^2 I
    br0, br1 = b * r0, b * r1
    p01, p02, p12 = br0 * r1, br0 * r2, br1 * r2
    ar0, ar1, ar2 = a * r0, a * r1, a * r2

    def diagonal(u, v):  # 1 - b (u + v)
        d = u + v
        d *= b
        return np.subtract(1.0, d, out=d)

    R = [[diagonal(s1, s2), p01 - ar2, p02 + ar1],
         [p01 + ar2, diagonal(s0, s2), p12 - ar0],
         [p02 - ar1, p12 + ar0, diagonal(s0, s1)]]
    # intrinsic z-y-x angles: R_rel = Rz(yaw) Ry(pitch) Rx(roll)
    np.arctan2(R[2][1], R[2][2], out=rot[:, 0])
    np.arcsin(np.clip(R[2][0], -1.0, 1.0), out=rot[:, 1])
    np.negative(rot[:, 1], out=rot[:, 1])
    np.arctan2(R[1][0], R[0][0], out=rot[:, 2])

    def body(v, into):  # R^T v = R0^T R_rel^T v, per point
        rel = np.empty_like(v)
        for i in range(3):
            np.multiply(R[0][i], v[:, 0], out=rel[:, i])
            rel[:, i] += R[1][i] * v[:, 1]
            rel[:, i] += R[2][i] * v[:, 2]
        np.einsum("pki,pk...->pi...", R0, rel, out=into)

    body(w, angvel)
    body(acc - (engine.G0[None, :, None, None] if gravity is None else gravity[None]), gia)
    return rot, angvel, gia


def run_result(human, ss: StateSpace, y: np.ndarray, u: np.ndarray, t: np.ndarray, dt: float, R0: np.ndarray,
            description: str, seat: SeatRotation | None = None, check: dict | None = None):
    """Outputs of the linear model (as ``block_chunk`` returns them, corrected by
    :meth:`SeatRotation.correct` if the seat rotates) -> a RunResult in the nonlinear route's terms; ``u`` the
    seat's acceleration (n, 3), ``check`` :func:`ehm.routes.linear.left_out`'s estimate."""
    n = len(t)
    gravity = None if seat is None else _to_blocks(seat.g_seat_mps2, *y.shape[1:])
    rot, angvel, gia = (in_time_order(x)[..., :n] for x in _orientations(y, R0, gravity))  # (point, axis, sample)
    kind = lambda k: in_time_order(_kind(y, k))[:, :n].reshape(_NP, 3, n)  # noqa: E731
    acc, disp, angacc = kind(_ACC), kind(_DISP), kind(_ANGACC)
    points = {p: PointMotion(name=p, acc_mps2=acc[i].T, disp_m=disp[i].T, rot_rad=rot[i].T,
                             angacc_radps2=angacc[i].T, angvel_radps=angvel[i].T, gia_mps2=gia[i].T)
              for i, p in enumerate(POINT_NAMES)}
    forces = in_time_order(y[_SUPPORT_ROWS])[:, :n].reshape(-1, 3, n)
    support = {g: forces[i].T for i, g in enumerate(engine.SUPPORT_GROUPS)}
    return RunResult(time_s=t, seat_acc_mps2=u, points=points, support_N=support, mass_kg=human.mass_kg,
                     dof=human.dof, dt_s=dt, wall_s=0.0, description=f"{description}, linear route",
                     locked=tuple(sorted(human.locked)), params_origin=human.params.origin,
                     seat_angles_rad=None if seat is None else seat.angles_rad,
                     extra={} if check is None else {"linear_check": check})


def simulate_linear(human, motion, dt_s: float | None = None):
    """Run ``motion`` through the linear route in one piece: a :class:`ehm.outputs.results.RunResult` sampled at
    ``dt_s`` [s] (the motion resampled onto it, anti-aliased), or at the motion's own time step when None
    (see :func:`stream_linear`)."""
    (result,) = stream_linear(human, motion, chunk_s=np.inf, dt_s=dt_s)
    return result
