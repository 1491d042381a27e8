"""The linear route: the settled person as a continuous-time state-space model, for small vibration.

Most of what ehm runs is small-amplitude vibration, where the model behaves linearly: contacts stay
closed and stuck.  :func:`continuous_model` linearises the settled model by finite differences of one
MuJoCo step at a fine step (the model's step / 8 by default, where the integrator's own error is a few
per mille) and converts that step to continuous time exactly (matrix logarithm of the zero-order-hold
step, ``[[A_d, B_d], [0, I]] = expm([[A, B], [0, 0]] h)``).  Accelerations are then the derivative of the
velocity outputs, ``V (A x + B u)`` plus the seat acceleration, so the model has no step error of its own.

:func:`simulate_linear` discretises it exactly at the motion's own sample step (first-order hold: the seat
acceleration linear between samples, as the nonlinear route interpolates it) and runs it in modal form, one
first-order recursion per mode (``scipy.signal.lfilter``).  While it runs it checks that it still holds:
every touching contact must keep pressing (normal force > 0) and stay inside its friction cone; otherwise
it raises :class:`LinearRouteError` saying when, where and by how much the input was too large.

:func:`ehm.frf.linear_frf` evaluates the same model's frequency response exactly; there is one
linearisation and one state-space model.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import linalg, signal
from scipy.spatial.transform import Rotation

from . import engine
from .errors import InputError

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
    cache: dict = field(default_factory=dict, repr=False, compare=False)  #: discretisations by sample step

    def index(self, name: str) -> int:
        return self.output_names.index(name)

    def rows(self, names) -> np.ndarray:
        return np.array([self.index(n) for n in names])


def continuous_model(model: engine.Model, refine: int = REFINE) -> StateSpace:
    """Linearise the settled ``model`` at its step / ``refine`` and convert to continuous time."""
    h = float(model.mj.opt.timestep) / refine
    lm = engine.linearize(model, step_s=h)
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
    for i, p in enumerate(engine.POINTS):
        V, Vd = lm.velocity_C[6 * i:6 * i + 6], lm.velocity_D[6 * i:6 * i + 6]  # linear then angular velocity
        acc_C, acc_D = V @ A, V @ B
        acc_D[:3] += np.eye(3)  # absolute = relative to the seat frame + the seat's own acceleration
        keep = [names.index(f"{p}.{k}") for k in ("x", "y", "z", "roll", "pitch", "yaw")]
        C_rows += [acc_C[:3], lm.C[keep], acc_C[3:], V[3:]]
        D_rows += [acc_D[:3], lm.D[keep], acc_D[3:], Vd[3:]]
        y0 += [np.zeros(3), lm.y0[keep], np.zeros(6)]
        out_names += [f"{p}.{k}" for k in _POINT_OUTPUTS]
    rest = [k for k, n in enumerate(names) if n.startswith(("support.", "contact."))]
    C_rows.append(lm.C[rest])
    D_rows.append(lm.D[rest])
    y0.append(lm.y0[rest])
    out_names += [names[k] for k in rest]
    contacts = tuple(n.split(".")[1] for n in out_names if n.startswith("contact.") and n.endswith(".fn"))
    friction = {c: float(model.params.value(f"contacts.{c}.friction")) for c in contacts}
    return StateSpace(A=A, B=B, C=np.vstack(C_rows), D=np.vstack(D_rows), y0=np.concatenate(y0),
                      output_names=tuple(out_names), contacts=contacts, friction=friction, linearised_at_step_s=h)


def frequency_response(ss: StateSpace, freq_hz: np.ndarray, rows=None) -> np.ndarray:
    """H(f) = C (j 2 pi f I - A)^-1 B + D, complex (n_freq, n_outputs, 3); ``rows`` selects outputs."""
    C, D = (ss.C, ss.D) if rows is None else (ss.C[rows], ss.D[rows])
    lam, V = np.linalg.eig(ss.A)
    CV, VinvB = C @ V, np.linalg.solve(V, ss.B)
    s = 2j * np.pi * np.asarray(freq_hz, dtype=float)
    inv = 1.0 / (s[:, None] - lam[None, :])
    return np.einsum("os,fs,si->foi", CV, inv, VinvB) + D[None, :, :]


@dataclass(frozen=True)
class _Modal:
    """The model discretised at one sample step (first-order hold) in modal form: real modes and one of each
    complex pair; outputs = Z @ C.T + u @ D.T, with Z the real modal states side by side with the real and
    imaginary parts of the complex ones."""

    lam_real: np.ndarray
    lam_pair: np.ndarray
    B_real: np.ndarray
    B_pair: np.ndarray
    C: np.ndarray
    D: np.ndarray


def _modal(ss: StateSpace, dt_s: float) -> _Modal:
    cached = ss.cache.get(dt_s)
    if cached is None:
        Ad, Bd, Cd, Dd, _ = signal.cont2discrete((ss.A, ss.B, ss.C, ss.D), dt_s, method="foh")
        lam, V = np.linalg.eig(Ad)
        Bm, Cm = np.linalg.solve(V, Bd), Cd @ V
        real = np.abs(lam.imag) <= 1e-12 * np.maximum(1.0, np.abs(lam))
        pair = (lam.imag > 0) & ~real
        # a conjugate pair contributes 2 Re(c z) = 2 (Re c Re z - Im c Im z)
        C = np.hstack([Cm[:, real].real, 2 * Cm[:, pair].real, -2 * Cm[:, pair].imag])
        cached = _Modal(lam_real=lam[real].real, lam_pair=lam[pair], B_real=Bm[real].real, B_pair=Bm[pair],
                        C=np.ascontiguousarray(C.T), D=np.ascontiguousarray(Dd.T))
        ss.cache[dt_s] = cached
    return cached


def _modal_chunk(m: _Modal, u: np.ndarray, carry: list) -> np.ndarray:
    """Outputs (deviations from y0) for input samples ``u`` (n, 3); ``carry`` holds the real and complex modal
    states at the chunk's first sample (zeros at the start of a run) and is advanced past its last sample."""
    n, nr, npair = u.shape[0], m.lam_real.size, m.lam_pair.size
    Z = np.empty((nr + 2 * npair, n))  # one contiguous row per modal state: real modes, Re and Im of pairs
    for i, (lam, B) in enumerate(((m.lam_real, m.B_real), (m.lam_pair, m.B_pair))):
        drive = B @ u.T  # (modes, n), rows contiguous
        for k in range(lam.size):  # z[n + 1] = lam z[n] + drive[n]
            w, _ = signal.lfilter([1.0], [1.0, -lam[k]], drive[k], zi=[lam[k] * carry[i][k]])
            if i == 0:
                Z[k, 0], Z[k, 1:] = carry[0][k], w[:-1]
            else:
                z0 = carry[1][k]
                Z[nr + k, 0], Z[nr + k, 1:] = z0.real, w[:-1].real
                Z[nr + npair + k, 0], Z[nr + npair + k, 1:] = z0.imag, w[:-1].imag
            carry[i][k] = w[-1]
    return Z.T @ m.C + u @ m.D


def _validity(ss: StateSpace, y: np.ndarray, t: np.ndarray) -> None:
    """Raise :class:`LinearRouteError` if a contact lifts off or slides anywhere in the run."""
    worst = None  # (scale at which the input still holds, time, contact, what)
    for c in ss.contacts:
        i = ss.rows([f"contact.{c}.fn", f"contact.{c}.ft1", f"contact.{c}.ft2"])
        n0, t10, t20 = ss.y0[i]
        dn, dt1, dt2 = y[:, i[0]], y[:, i[1]], y[:, i[2]]
        mu = ss.friction[c]
        # largest scale s of the dynamic part for which N0 + s dN > 0 and |T0 + s dT| <= mu (N0 + s dN)
        # at every sample: bisection on s (the constraints are convex in s).
        def holds(s: float):
            n = n0 + s * dn
            bad = (n <= 0) | (np.hypot(t10 + s * dt1, t20 + s * dt2) > mu * n)
            return not bad.any(), bad

        ok, bad = holds(1.0)
        if ok:
            continue
        lo, hi = 0.0, 1.0
        for _ in range(30):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if holds(mid)[0] else (lo, mid)
        k = int(np.argmax(bad))
        what = "lifts off the seat" if n0 + dn[k] <= 0 else "slides (friction at its Coulomb limit)"
        if worst is None or lo < worst[0]:
            worst = (lo, t[k], c, what)
    if worst is not None:
        s, tk, c, what = worst
        raise LinearRouteError(
            f"the input is too large for the linear route: at t = {tk:.3f} s the {c} contact {what}; the linear "
            f"route holds for this motion scaled by {s:.2f} or less (about {1 / max(s, 1e-9):.1f} times too large); "
            "use the nonlinear route (method='nonlinear', --method nonlinear).")


def stream_linear(human, motion, chunk_s: float = 10.0, progress=None, dt_s: float | None = None):
    """Run ``motion`` (a translational :class:`ehm.motion.SeatMotion`) through the linear route, chunk by chunk.

    Yields one :class:`ehm.simulation.RunResult` per chunk (absolute times, the motion's own time step), like
    :meth:`ehm.SeatedHuman.stream`; raises :class:`LinearRouteError` as soon as a contact would lift off or
    slide.  ``progress(done_s, total_s)`` is called after every chunk.  ``dt_s`` [s]: run on this step
    instead, the motion resampled onto it one chunk at a time (:class:`ehm.motion.Resampler`, as the
    nonlinear route does), so that no resampled copy of the whole motion is made.
    """
    if motion.angvel_radps is not None and np.any(motion.angvel_radps != 0):
        raise InputError("the linear route takes seat translation only; for a motion with seat rotation use the "
                         "nonlinear route (method='nonlinear') with SeatedHuman(rotating_seat=True).")
    grid = None
    if dt_s is None:
        steps = np.diff(motion.time_s)
        dt = float(np.median(steps))
        if np.abs(steps - dt).max() > 1e-6 * dt:
            motion = motion.resample(dt)
        del steps
    else:
        from .motion import Resampler

        dt = float(dt_s)
        grid = Resampler(motion.time_s, motion.acc_mps2, dt)
    ss = human.linear_model()
    m = _modal(ss, dt)
    carry = [np.zeros(m.lam_real.size), np.zeros(m.lam_pair.size, dtype=complex)]
    settled = engine.settled_point_poses(human.model)
    R0 = {p: Rotation.from_quat(settled[p][1], scalar_first=True).as_matrix() for p in engine.POINTS}
    n_total = motion.time_s.size if grid is None else grid.n_samples
    description = motion.description if grid is None else f"{motion.description}, resampled to dt {dt:g} s"
    per_chunk = n_total if not np.isfinite(chunk_s) else max(1, int(round(chunk_s / dt)))
    for start in range(0, n_total, per_chunk):
        t0 = time.perf_counter()
        stop = min(n_total, start + per_chunk)
        if grid is None:
            t, u = motion.time_s[start:stop] - motion.time_s[0], motion.acc_mps2[start:stop]
        else:
            t, u = np.arange(start, stop) * dt, grid.block(start, stop)
        y = _modal_chunk(m, u, carry)
        _validity(ss, y, t)
        y += ss.y0
        result = _result(human, ss, y, u, t, dt, R0, description)
        yield replace(result, wall_s=time.perf_counter() - t0)
        del result, y, u  # the next chunk is made without this one held here
        if progress:
            progress(min(t[-1] + dt, motion.duration_s), motion.duration_s)


def _result(human, ss: StateSpace, y: np.ndarray, u: np.ndarray, t: np.ndarray, dt: float, R0: dict,
            description: str):
    """Outputs of the linear model -> a RunResult in the nonlinear route's terms."""
    from .simulation import POINT_NAMES, PointMotion, RunResult

    points = {}
    for p in POINT_NAMES:
        col = lambda names, p=p: y[:, ss.rows([f"{p}.{n}" for n in names])]  # noqa: E731
        acc, rotvec, w_world = col(("ax", "ay", "az")), col(("roll", "pitch", "yaw")), col(("wx", "wy", "wz"))
        rel = Rotation.from_rotvec(rotvec)
        R = np.einsum("nij,jk->nik", rel.as_matrix(), R0[p])  # world orientation R = R_rel R0
        to_body = lambda v, R=R: np.einsum("nji,nj->ni", R, v)  # noqa: E731  R^T v: into the segment's axes
        points[p] = PointMotion(name=p, acc_mps2=acc, disp_m=col(("x", "y", "z")),
                                rot_rad=rel.as_euler("ZYX")[:, ::-1].copy(),
                                angacc_radps2=col(("roll_acc", "pitch_acc", "yaw_acc")),
                                angvel_radps=to_body(w_world), gia_mps2=to_body(acc - engine.G0[None, :]))
    support = {g: y[:, ss.rows([f"support.{g}.f{a}" for a in "xyz"])] for g in engine.SUPPORT_GROUPS}
    return RunResult(time_s=t, seat_acc_mps2=u, points=points, support_N=support, mass_kg=human.mass_kg,
                     dof=human.dof, dt_s=dt, wall_s=0.0, description=f"{description}, linear route",
                     locked=tuple(sorted(human.locked)), params_origin=human.params.origin)


def simulate_linear(human, motion):
    """Run ``motion`` through the linear route in one piece: a :class:`ehm.simulation.RunResult` sampled at
    the motion's own time step, like the nonlinear route's (see :func:`stream_linear`)."""
    (result,) = stream_linear(human, motion, chunk_s=np.inf)
    return result
