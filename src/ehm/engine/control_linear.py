"""The head-in-space control's linearisation (:mod:`ehm.engine.control`), so that the linear route carries it without
knowing the law: :func:`ehm.engine.linearize` linearises the person without the control and with its torque as three
more inputs (:data:`CONTROL_INPUTS`, applied by :func:`control_loads`); :func:`feedback` is the law as a continuous
linear system from the linear model's outputs to those inputs, its delay as a Padé approximant (:data:`PADE_ORDER`
states per axis); :func:`close_loop` closes any state-space model with such a feedback."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import linalg, signal

from ..errors import InputError
from .control import MAX_DELAY_S
from .model import Model

#: The control's torque on the head (world axes [N m], the reaction on the upper torso), inputs of the linearisation.
CONTROL_INPUTS = ("head_torque_x", "head_torque_y", "head_torque_z")
#: What the law senses among the linear route's outputs (:class:`ehm.routes.linear.StateSpace`): the head's rotation in
#: roll and pitch (the rotation vector's horizontal components: its tilt) and its angular velocity.
SENSED = ("head.roll", "head.pitch", "head.wx", "head.wy", "head.wz")
#: Order of the Padé approximant of the delay: its phase is within 1 deg of the delay's up to
#: omega T = 3 (24 Hz at the default 20 ms).
PADE_ORDER = 3


@dataclass(frozen=True)
class Feedback:
    """A linear feedback law, dz/dt = A z + B s, drive = C z + D s (or z+ = A z + B s for one step), from the
    outputs ``sensed`` to the inputs ``drives``."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    sensed: tuple
    drives: tuple


def gains(control) -> np.ndarray:
    """The law's gains (3, 5): its torque (world axes, on the head) from what it senses (:data:`SENSED`), for small
    tilts."""
    kp, kd = control.tilt_stiffness_Nm_per_rad, control.tilt_damping_Nms_per_rad
    ky = control.yaw_damping_Nms_per_rad
    return -np.array([[kp, 0, kd, 0, 0], [0, kp, 0, kd, 0], [0, 0, 0, 0, ky]], dtype=float)


def control_loads(model: Model) -> np.ndarray:
    """The control's torque per unit input (3, n_body, 6), as ``MjData.xfrc_applied``: on the head, and its reaction
    on the upper torso."""
    c = model.head_control
    loads = np.zeros((3, model.mj.nbody, 6))
    for k in range(3):
        loads[k, c.head_body, 3 + k] = 1.0
        loads[k, c.torso_body, 3 + k] = -1.0
    return loads


def pade(delay_s: float, order: int = PADE_ORDER):
    """The Padé approximant of exp(-s T) as a state space (A, B, C, D), one input and one output."""
    n = order
    c = [math.factorial(2 * n - k) * math.factorial(n) / (math.factorial(2 * n) * math.factorial(k)
                                                          * math.factorial(n - k)) * delay_s ** k for k in range(n + 1)]
    num = [(-1) ** k * ck for k, ck in enumerate(c)][::-1]  # highest power first
    den = c[::-1]
    return signal.tf2ss(num, den)


def feedback(model: Model, delay_s: float | None = None, order: int = PADE_ORDER) -> Feedback:
    """The model's head-in-space control as a :class:`Feedback` from :data:`SENSED` to :data:`CONTROL_INPUTS`.

    The delay is the control's (the engine's is that on average, :func:`ehm.engine.control.after_step`) unless
    ``delay_s`` says otherwise (a study of the delay margin)."""
    c = model.head_control
    T = c.delay_s if delay_s is None else float(delay_s)
    K = gains(c)
    Ap, Bp, Cp, Dp = pade(T, order)
    blocks = [linalg.block_diag(*[m] * 3) for m in (Ap, Bp, Cp, Dp)]
    return Feedback(A=blocks[0], B=blocks[1] @ K, C=blocks[2], D=blocks[3] @ K, sensed=SENSED, drives=CONTROL_INPUTS)


def close_loop(A, B, C, D, input_names, output_names, fb: Feedback):
    """The model dx/dt = A x + B u, y = C x + D u closed with the feedback ``fb`` (its drives among the inputs, what
    it senses among the outputs).  Returns (A, B, C, D, input_names) of the closed loop: states x then the
    feedback's, the drives no longer inputs."""
    inputs, outputs = list(input_names), list(output_names)
    drive = [inputs.index(n) for n in fb.drives]
    keep = [k for k in range(len(inputs)) if k not in drive]
    sense = [outputs.index(n) for n in fb.sensed]
    Bu, Bd, Du, Dd = B[:, keep], B[:, drive], D[:, keep], D[:, drive]
    Cs, Dsu, Dsd = C[sense], Du[sense], Dd[sense]
    # drive = M (fb.C z + fb.D (Cs x + Dsu u)), M = (I - fb.D Dsd)^-1 (the loop through the direct terms)
    M = np.linalg.inv(np.eye(len(drive)) - fb.D @ Dsd)
    Gx, Gz, Gu = M @ fb.D @ Cs, M @ fb.C, M @ fb.D @ Dsu
    A_cl = np.block([[A + Bd @ Gx, Bd @ Gz], [fb.B @ (Cs + Dsd @ Gx), fb.A + fb.B @ Dsd @ Gz]])
    B_cl = np.vstack([Bu + Bd @ Gu, fb.B @ (Dsu + Dsd @ Gu)])
    C_cl = np.hstack([C + Dd @ Gx, Dd @ Gz])
    D_cl = Du + Dd @ Gu
    return A_cl, B_cl, C_cl, D_cl, tuple(inputs[k] for k in keep)


def delay_line(model: Model, step_s: float | None = None) -> Feedback:
    """The model's head-in-space control as a discrete :class:`Feedback` of one time step ``step_s`` (default the
    model's), its delay as the engine applies it: the line of the torques of the last N states
    (:func:`ehm.engine.control.after_step`), the mean of the two oldest applied over the step.  The delay must be a
    whole number N >= 2 of such steps."""
    c = model.head_control
    h = float(model.mj.opt.timestep) if step_s is None else float(step_s)
    N = int(round(c.delay_s / h))
    if N < 2 or abs(N * h - c.delay_s) > 1e-6 * h:
        raise ValueError(f"the control's delay {c.delay_s:g} s is not a whole number of steps of {h:g} s")
    K = gains(c)
    A = np.eye(3 * N, k=-3)  # newest first: the line shifts by one torque per step
    B = np.zeros((3 * N, 5))
    B[:3] = K
    C = np.zeros((3, 3 * N))
    C[:, -3:] = C[:, -6:-3] = 0.5 * np.eye(3)  # the mean of the two oldest
    return Feedback(A=A, B=B, C=C, D=np.zeros((3, 5)), sensed=SENSED, drives=CONTROL_INPUTS)


def closed_linear_model(model: Model, lm, fb: Feedback | None = None):
    """The discrete linear model ``lm`` of :func:`ehm.engine.linearize` (with :data:`CONTROL_INPUTS`) closed with the
    model's control, its delay exact (:func:`delay_line`; or the discrete feedback ``fb``): the states then the
    feedback's; the point velocity rows closed alike.  A model without control, or ``lm`` without its inputs, is
    returned as it is."""
    if model.head_control is None or CONTROL_INPUTS[0] not in lm.input_names:
        return lm
    from dataclasses import replace

    from .model import POINTS

    names = list(lm.output_names)
    head = 6 * list(POINTS).index("head") + 3  # the head's angular velocity among the velocity rows
    vel_names = [f"velocity.{k}" for k in range(lm.velocity_C.shape[0])]
    C = np.vstack([lm.C, lm.velocity_C])
    D = np.vstack([lm.D, lm.velocity_D])
    outputs = names + vel_names
    for k, axis in enumerate(("wx", "wy", "wz")):  # the sensed angular velocity: its velocity rows
        outputs[len(names) + head + k] = f"head.{axis}"
    A, B, C, D, inputs = close_loop(lm.A, lm.B, C, D, lm.input_names, outputs,
                                    delay_line(model, lm.dt_s) if fb is None else fb)
    n = len(names)
    return replace(lm, A=A, B=B, C=C[:n], D=D[:n], velocity_C=C[n:], velocity_D=D[n:], input_names=inputs)


# --- the stability margin -------------------------------------------------------------------------------------------

#: Rates |s| below this [1/s] are the integral actions' neutral directions, not modes (left out of the check).
_NEUTRAL = 1e-3


def closed_loop_rates(model: Model, lm, delay_s: float | None) -> np.ndarray:
    """The continuous-time rates s = ln(mu) / h of the one-step linear model ``lm`` (:func:`ehm.engine.linearize`)
    closed with the model's control at the delay ``delay_s`` (its Pade approximant, held over the step; None: the
    loop open, the person without the control), the integral actions' neutral directions left out."""
    if delay_s is None:
        A = lm.A
    else:
        fb = feedback(model, delay_s)
        Ad, Bd, Cd, Dd, _ = signal.cont2discrete((fb.A, fb.B, fb.C, fb.D), lm.dt_s, method="zoh")
        A = closed_linear_model(model, lm, Feedback(A=Ad, B=Bd, C=Cd, D=Dd, sensed=fb.sensed, drives=fb.drives)).A
    mu = np.linalg.eigvals(A)
    rates = np.log(mu[np.abs(mu) > 1e-12].astype(complex)) / lm.dt_s
    return rates[np.abs(rates) > _NEUTRAL]


def _growing(rates: np.ndarray, open_rates: np.ndarray) -> np.ndarray:
    """The rates that grow (real part > 0) in the closed loop and not in the open one (a seat that can turn has an
    unstable mode of its own in the linearisation, controlled or not): each open growing rate takes away the
    closed loop's nearest."""
    grow = list(rates[rates.real > 0])
    for r in open_rates[open_rates.real > 0]:
        if grow:
            grow.pop(int(np.argmin(np.abs(np.array(grow) - r))))
    return np.array(grow, dtype=complex)


def delay_margin(model: Model, lm, upper_s: float = MAX_DELAY_S, tolerance_s: float = 0.005):
    """The longest delay [s] up to which the model's control (its gains) keeps the linearised loop stable (no mode
    grows that does not grow without the control), found by a scan from two time steps up to ``upper_s`` and a
    bisection to ``tolerance_s``; with the growing rates of the first unstable loop.  Returns (margin_s, rates):
    margin_s is 0 when the loop is unstable at two steps already, ``upper_s`` (and no rates) when it stays stable up
    to there."""
    open_rates = closed_loop_rates(model, lm, None)

    def growing(T):
        return _growing(closed_loop_rates(model, lm, T), open_rates)

    lo = 2 * lm.dt_s
    bad = growing(lo)
    if bad.size:
        return 0.0, bad
    hi = None
    for T in np.geomspace(lo, upper_s, 12)[1:]:
        r = growing(T)
        if r.size:
            hi, bad = T, r
            break
        lo = T
    if hi is None:
        return float(upper_s), None
    while hi - lo > tolerance_s:
        mid = 0.5 * (lo + hi)
        r = growing(mid)
        if r.size:
            hi, bad = mid, r
        else:
            lo = mid
    return float(lo), bad


def check_stability(model: Model, lm) -> None:
    """Refuse, in one sentence naming the margin, a head-in-space control (gains and delay) that leaves the settled
    person's linearised loop (``lm``, :func:`ehm.engine.linearize`) unstable (a mode grows that does not grow without
    the control): run on, it would shake the head in a limit cycle or a growing oscillation.  Nothing for a model
    without the control."""
    c = model.head_control
    if c is None:
        return
    if not _growing(closed_loop_rates(model, lm, c.delay_s), closed_loop_rates(model, lm, None)).size:
        return
    margin, bad = delay_margin(model, lm, upper_s=min(MAX_DELAY_S, c.delay_s))
    grows = bad[np.argmax(bad.real)]
    hz = abs(grows.imag) / (2 * np.pi)
    mode = f"a {hz:.2f} Hz mode grows" if abs(grows.imag) > _NEUTRAL else "a mode drifts away"
    gains = (f"tilt_stiffness_Nm_per_rad={c.tilt_stiffness_Nm_per_rad:g}, "
             f"tilt_damping_Nms_per_rad={c.tilt_damping_Nms_per_rad:g}, yaw_damping_Nms_per_rad="
             f"{c.yaw_damping_Nms_per_rad:g}")
    how = ("--head-control-gains on the command line, head_control={...} or the parameter file's [head_control] "
           "in Python")
    if margin <= 0:
        raise InputError(f"head-in-space control with {gains}: its loop is unstable on this person even at the "
                         f"shortest delay ({2 * lm.dt_s:g} s; {mode}), so it has no stability margin; lower the "
                         f"gains ({how}).")
    raise InputError(f"head_control.delay_s = {c.delay_s:g} s leaves no stability margin: with {gains} this "
                     f"person's head control stays stable only up to a delay of about {margin:.2f} s (beyond it "
                     f"{mode}); use a delay below {margin:.2f} s or lower the gains ({how}).")


# --- the Padé states handed over from the engine's delay line ---------------------------------------------------------

#: The Padé states of :func:`feedback` forget a torque history after this many delays: their slowest pole decays by
#: exp(-3.6) per delay at order 3 (below 1e-15 after 10), so only the last HISTORY_DELAYS delays of torques count.
HISTORY_DELAYS = 10


@dataclass(frozen=True)
class PadeSteps:
    """The Padé states of the model's control (:func:`feedback`: 3 x order states, axis by axis, the last states of
    a closed linear model) over steps of ``step_s``, driven by the law's undelayed torque linear between samples
    (first-order hold): z[k+1] = phi z[k] + g0 tau[k] + g1 tau[k+1]."""

    step_s: float
    phi: np.ndarray
    g0: np.ndarray
    g1: np.ndarray
    powers: np.ndarray  #: (H + 1, n, n) phi^j, j = 0 ... H, H = HISTORY_DELAYS delays in steps

    def after(self, z0: np.ndarray, torques: np.ndarray) -> np.ndarray:
        """The Padé states after the torques (n + 1, 3) of n + 1 samples (the first the state ``z0``'s, the last the
        state sought's): exact for the filter on that history, the torques more than ``H`` steps back dropped
        (their share is below round-off)."""
        n, H = torques.shape[0] - 1, self.powers.shape[0]
        z = self.powers[n] @ z0 if n < H else np.zeros_like(z0)
        m = min(n, H)
        if m:
            e = torques[n - m:n] @ self.g0.T + torques[n - m + 1:] @ self.g1.T  # (m, states)
            z += np.einsum("kij,kj->i", self.powers[m - 1::-1], e)
        return z


def pade_steps(model: Model, step_s: float, order: int = PADE_ORDER) -> PadeSteps:
    """The model's :class:`PadeSteps` at ``step_s`` (the control's own delay)."""
    Ap, Bp, _, _ = pade(model.head_control.delay_s, order)
    A, B = linalg.block_diag(*[Ap] * 3), linalg.block_diag(*[Bp] * 3)
    n, h = A.shape[0], float(step_s)
    aug = np.zeros((n + 6, n + 6))  # [z, tau, tau' h]: z' = A z + B tau, tau' = (tau[k+1] - tau[k]) / h
    aug[:n, :n], aug[:n, n:n + 3], aug[n:n + 3, n + 3:] = A * h, B * h, np.eye(3)
    E = linalg.expm(aug)
    phi, ga, gb = E[:n, :n], E[:n, n:n + 3], E[:n, n + 3:]
    H = max(2, int(math.ceil(HISTORY_DELAYS * model.head_control.delay_s / h)))
    powers = np.empty((H + 1, n, n))
    powers[0] = np.eye(n)
    for j in range(1, H + 1):
        powers[j] = phi @ powers[j - 1]
    return PadeSteps(step_s=h, phi=phi, g0=ga - gb, g1=gb, powers=powers)
