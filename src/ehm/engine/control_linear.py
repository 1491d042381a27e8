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

from .model import Model

#: The control's torque on the head (world axes [N m], the reaction on the upper torso), inputs of the linearisation.
CONTROL_INPUTS = ("head_torque_x", "head_torque_y", "head_torque_z")
#: What the law senses among the linear route's outputs (:class:`ehm.linear.StateSpace`): the head's rotation in
#: roll and pitch (the rotation vector's horizontal components: its tilt) and its angular velocity.
SENSED = ("head.roll", "head.pitch", "head.wx", "head.wy", "head.wz")
#: Order of the Padé approximant of the delay: its phase is within 1 deg of the delay's up to
#: omega T = 3 (24 Hz at the default 20 ms).
PADE_ORDER = 3


@dataclass(frozen=True)
class Feedback:
    """A linear feedback law, dz/dt = A z + B s, drive = C z + D s, from the outputs ``sensed`` to the inputs ``drives``."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    sensed: tuple
    drives: tuple


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

    The engine senses the state a step starts from and applies the torque over the step N steps later
    (:func:`ehm.engine.control.after_step`): on average (N + 1/2) steps after the state, the delay taken here unless
    ``delay_s`` says otherwise (a study of the delay margin)."""
    c = model.head_control
    dt = float(model.mj.opt.timestep)
    T = c.delay_s + dt / 2 if delay_s is None else float(delay_s)
    kp, kd, ky = c.tilt_stiffness_Nm_per_rad, c.tilt_damping_Nms_per_rad, c.yaw_damping_Nms_per_rad
    K = -np.array([[kp, 0, kd, 0, 0], [0, kp, 0, kd, 0], [0, 0, 0, 0, ky]], dtype=float)
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
