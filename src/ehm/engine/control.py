"""Head-in-space control as the engine applies it: neck torques from the head's tilt relative to gravity and its
angular velocity in space, with a sensory delay, on top of the joint PID (docs/model.md, "Head-in-space control").

The law, with u the head's reference "up" (the world vertical in head axes in the settled posture) carried by the
head into world axes, the tilt e_z x u (its horizontal components are the head's roll and pitch in space for small
angles, whatever its yaw) and w the head's angular velocity in space (world axes)::

    tau(t + T) = -k_p (e_z x u(t)) - k_d (w_x, w_y, 0)(t) - k_yaw (0, 0, w_z)(t)

acts as a couple between head and upper torso (+tau on the head, -tau on the upper torso: a muscle from thorax to
skull, which loads the neck segment with no net torque).  T is the sensory delay, a whole number N >= 2 of time
steps.

It runs after every MuJoCo step (:func:`after_step`), when the sensors hold the state the step started from: the
torque computed from that state is applied N steps later (``MjData.xfrc_applied`` of the two bodies, set for the
next step from a first-in first-out line of N - 1 torques: the mean of the two oldest, so that held over the step
it is N steps late on average).  Everything it needs lives in the model and its data,
so that saving and restoring the integration state (:func:`ehm.engine.get_state`), chunked runs and the native FMU
carry it: the gains, the delay and the addresses in a MuJoCo numeric ``ehm_head_control`` (:data:`NUMERIC`), the
reference up and the delay line in ``MjData.userdata`` (:func:`start`).  The MuJoCo model stays that of the
uncontrolled person when the control is off (no numeric, no user data).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import mujoco
import numpy as np

from ..body.params import Parameters
from ..errors import InputError

#: Name of the MuJoCo numeric holding the law's constants, in the order of :data:`NUMERIC_FIELDS`.
NUMERIC = "ehm_head_control"
NUMERIC_FIELDS = ("delay_steps", "head_body", "torso_body", "quat_adr", "angvel_adr", "tilt_stiffness_Nm_per_rad",
                  "tilt_damping_Nms_per_rad", "yaw_damping_Nms_per_rad")
#: ``MjData.userdata``: the reference up in head axes (3), then the delay line, oldest torque first (3 per step).
REFERENCE = slice(0, 3)
LINE_START = 3
_EZ = np.array([0.0, 0.0, 1.0])
#: The longest sensory delay the control takes at all [s]: far beyond any stability margin (the default person's is
#: about 0.3 s, docs/model.md; :func:`ehm.engine.control_linear.check_stability` finds the person's own), and short
#: enough that the delay line stays small (a delay of 1e7 s overflowed MuJoCo's user data).
MAX_DELAY_S = 1.0


@dataclass(frozen=True)
class HeadControl:
    """The law's constants for one compiled model (see the module's description)."""

    tilt_stiffness_Nm_per_rad: float
    tilt_damping_Nms_per_rad: float
    yaw_damping_Nms_per_rad: float
    delay_s: float
    delay_steps: int
    head_body: int = -1
    torso_body: int = -1
    quat_adr: int = -1
    angvel_adr: int = -1

    @classmethod
    def from_params(cls, params: Parameters, dt_s: float) -> HeadControl | None:
        """The control the parameters ask for (None when ``head_control.enabled`` is false or the parameters have
        no [head_control]); a delay that is not a whole number of time steps, or shorter than one, is refused in
        one sentence."""
        if "head_control" not in params.data or not params.value("head_control.enabled"):
            return None
        delay = float(params.value("head_control.delay_s"))
        if delay > MAX_DELAY_S:
            raise InputError(f"head_control.delay_s = {delay:g} s is beyond any stability margin of the head's "
                             f"control (the default person's is about 0.3 s; the longest delay taken is "
                             f"{MAX_DELAY_S:g} s): use a delay of tens of milliseconds, as the reflex's (default "
                             "0.02 s).")
        steps = int(round(delay / dt_s))
        if steps < 2:
            raise InputError(f"head_control.delay_s = {delay:g} s is shorter than two time steps ({dt_s:g} s each); "
                             "the sensory delay must be at least two steps.")
        if abs(steps * dt_s - delay) > 1e-6 * dt_s + 1e-12:
            lo, hi = max(1, int(delay // dt_s)), int(delay // dt_s) + 1
            raise InputError(f"head_control.delay_s = {delay:g} s is not a whole number of time steps ({dt_s:g} s); "
                             f"use {lo * dt_s:g} or {hi * dt_s:g}.")
        return cls(*(float(params.value(f"head_control.{k}")) for k in NUMERIC_FIELDS[5:]), delay_s=steps * dt_s,
                   delay_steps=steps)

    @property
    def n_userdata(self) -> int:
        """Size of ``MjData.userdata`` the law needs: the reference up and N - 1 delayed torques."""
        return LINE_START + 3 * (self.delay_steps - 1)

    def numeric(self) -> list[float]:
        """The constants as the numeric :data:`NUMERIC` holds them."""
        return [float(getattr(self, k)) for k in NUMERIC_FIELDS]


def add_to_spec(spec: mujoco.MjSpec, control: HeadControl | None) -> None:
    """Room for the law in the model before compiling: the numeric (filled by :func:`compiled`) and the user data."""
    if control is None:
        return
    spec.add_numeric(name=NUMERIC, data=[0.0] * len(NUMERIC_FIELDS))
    spec.nuserdata = control.n_userdata


def compiled(mj: mujoco.MjModel, control: HeadControl | None, head_body: int, torso_body: int,
             quat_adr: int, angvel_adr: int) -> HeadControl | None:
    """The control with the compiled model's addresses, written into its numeric :data:`NUMERIC`."""
    if control is None:
        return None
    control = replace(control, head_body=head_body, torso_body=torso_body, quat_adr=quat_adr, angvel_adr=angvel_adr)
    i = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_NUMERIC, NUMERIC)
    adr = int(mj.numeric_adr[i])
    mj.numeric_data[adr:adr + len(NUMERIC_FIELDS)] = control.numeric()
    return control


def start(control: HeadControl | None, d: mujoco.MjData) -> None:
    """Start the law in the state ``d`` holds (its sensors computed): that head orientation is the reference, the
    delay line empty (no torque: the person at rest)."""
    if control is None:
        return
    q = d.sensordata[control.quat_adr:control.quat_adr + 4]
    up = np.empty(3)
    mujoco.mju_rotVecQuat(up, _EZ, np.array([q[0], -q[1], -q[2], -q[3]]))  # R^T e_z
    d.userdata[:] = 0.0
    d.userdata[REFERENCE] = up
    d.xfrc_applied[control.head_body, 3:] = 0.0
    d.xfrc_applied[control.torso_body, 3:] = 0.0


def torque(control: HeadControl, d: mujoco.MjData) -> np.ndarray:
    """The law's torque [N m] (world axes, on the head) from the sensors ``d`` holds."""
    s = d.sensordata
    u = np.empty(3)
    mujoco.mju_rotVecQuat(u, d.userdata[REFERENCE], s[control.quat_adr:control.quat_adr + 4])
    w = s[control.angvel_adr:control.angvel_adr + 3]
    kp, kd = control.tilt_stiffness_Nm_per_rad, control.tilt_damping_Nms_per_rad
    # -k_tilt (e_z x u) - c_tilt (w_x, w_y, 0) - c_yaw (0, 0, w_z)
    return np.array([kp * u[1] - kd * w[0], -kp * u[0] - kd * w[1], -control.yaw_damping_Nms_per_rad * w[2]])


def after_step(control: HeadControl, d: mujoco.MjData) -> None:
    """After a MuJoCo step k: the torque of the state it started from into the delay line, and onto head and upper
    torso for step k + 1 the mean of the torques of the states N and N - 1 steps before it.  Held over the step, that
    is the torque of N steps before on average, whatever the step: the delay converges with the step as the rest
    of the model does (the oldest torque alone would be half a step late, 2.4 % of the peak of seat z -> head pitch
    at 1 ms against 0.125 ms)."""
    # torque(control, d) written out on Python floats (the same operations, half the time: 4 us a step of 20)
    s, userdata = d.sensordata, d.userdata
    u = np.empty(3)
    mujoco.mju_rotVecQuat(u, userdata[REFERENCE], s[control.quat_adr:control.quat_adr + 4])
    w0, w1, w2 = s[control.angvel_adr:control.angvel_adr + 3].tolist()
    u0, u1, _ = u.tolist()
    kp, kd = control.tilt_stiffness_Nm_per_rad, control.tilt_damping_Nms_per_rad
    tau = (kp * u1 - kd * w0, -kp * u0 - kd * w1, -control.yaw_damping_Nms_per_rad * w2)
    line = userdata[LINE_START:]  # the torques of the last N - 1 states, oldest first
    applied = 0.5 * (line[:3] + (line[3:6] if line.size > 3 else tau))
    line[:-3] = line[3:]
    line[-3:] = tau
    xfrc = d.xfrc_applied
    xfrc[control.head_body, 3:] = applied
    xfrc[control.torso_body, 3:] = -applied


# --- the delay line handed between the models -----------------------------------------------------------------------


def torques_of(control: HeadControl, d: mujoco.MjData, quat: np.ndarray, angvel: np.ndarray) -> np.ndarray:
    """The law's torques [N m] (n, 3) of recorded states: the head's orientation ``quat`` (n, 4, w x y z) and its
    angular velocity ``angvel`` (n, 3, world axes) as the sensors read them (a :class:`ehm.engine.RawRun`'s
    ``head_framequat`` and ``head_frameangvel``), with the reference up of ``d`` (the run's data): what
    :func:`torque` gave in each of them."""
    ref = d.userdata[REFERENCE]
    w, v = quat[:, :1], quat[:, 1:]
    t = 2.0 * np.cross(v, ref)  # u = R(q) ref = ref + w t + v x t
    u = ref + w * t + np.cross(v, t)
    kp, kd = control.tilt_stiffness_Nm_per_rad, control.tilt_damping_Nms_per_rad
    return np.column_stack([kp * u[:, 1] - kd * angvel[:, 0], -kp * u[:, 0] - kd * angvel[:, 1],
                            -control.yaw_damping_Nms_per_rad * angvel[:, 2]])


def line_torques(control: HeadControl, d: mujoco.MjData) -> np.ndarray:
    """The torques (N, 3) of the N states before the one ``d`` holds, oldest first, as the law keeps them between
    steps: the oldest from the torque applied over the next step (the mean of the two oldest), the others from the
    delay line.  The inverse of :func:`load_line`."""
    line = d.userdata[LINE_START:].reshape(-1, 3)
    oldest = 2.0 * d.xfrc_applied[control.head_body, 3:] - line[0]
    return np.vstack([oldest, line])


def load_line(control: HeadControl, d: mujoco.MjData, torques: np.ndarray) -> None:
    """Put the torques (N, 3) of the N states before the one ``d`` holds (oldest first) into the law's delay line and
    onto head and upper torso for the next step, as :func:`after_step` would have left them had the law run through
    those states: a run continues another's delay (the hybrid route's hand-over from the linear model,
    :mod:`ehm.routes.hybrid`)."""
    torques = np.asarray(torques, dtype=float)
    if torques.shape != (control.delay_steps, 3):
        raise ValueError(f"the delay line takes {control.delay_steps} torques, not an array of shape {torques.shape}")
    d.userdata[LINE_START:] = torques[1:].ravel()
    applied = 0.5 * (torques[0] + torques[1])
    d.xfrc_applied[control.head_body, 3:] = applied
    d.xfrc_applied[control.torso_body, 3:] = -applied
