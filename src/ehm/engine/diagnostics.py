"""What goes wrong, in ehm's words: MuJoCo's warnings captured (:func:`captured_warnings`, :func:`take_warnings`),
its compiler's refusal as one sentence, and the divergence check of a running state with its sentence."""

from __future__ import annotations

import contextlib
import re

import mujoco
import numpy as np

from ..errors import DivergenceError, InputError
from .model import Model

DIVERGED_M = 0.5  #: A point further than this from its settled position means the run has diverged [m].
#: A pelvis that left its seat slower than this [m/s], with every value finite and no warning from MuJoCo, fell off
#: the seat (a physical fall, which no smaller step changes); faster, the integration blew up.
FALL_SPEED_MPS = 5.0
#: ... and with no degree of freedom faster than this [m/s or rad/s] (a blow-up shakes some joint or pad far faster).
FALL_DOF_SPEED = 20.0
#: A pelvis tilted further than this [deg] from its seated orientation (relative to the seat) has fallen over, even
#: where it has not moved :data:`DIVERGED_M` yet: the erect person without back support tipped over sideways in the
#: SYNTHETIC city drive's first corner (2.9 m/s^2) at 11-12 s and lay on the seat, rolled 170 deg, until its pelvis
#: passed 0.5 m at 48 s.  Seated people's pelvis turns by a few degrees in hard manoeuvres.
FALL_TILT_DEG = 45.0
CHECK_EVERY = 100  #: Steps between divergence checks (0.1 s at the default step).


_MAX_WARNINGS = 20
_warnings: list[str] = []  #: MuJoCo's own warnings captured since :func:`take_warnings` last ran.


def _keep_warning(message: str) -> None:
    if len(_warnings) < _MAX_WARNINGS:
        _warnings.append(str(message).strip())


@contextlib.contextmanager
def captured_warnings():
    """While inside, MuJoCo's warnings are kept (for :func:`take_warnings` and divergence messages) instead of
    being printed raw; the previous handler comes back on leaving."""
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(_keep_warning)
    try:
        yield
    finally:
        mujoco.set_mju_user_warning(previous)


def take_warnings() -> list[str]:
    """MuJoCo's warnings captured since the last call (and not yet folded into an error), oldest first."""
    out = list(_warnings)
    _warnings.clear()
    return out


def _warning_sentence(model: Model, message: str) -> tuple[str, float | None]:
    """A captured MuJoCo warning in ehm's terms (degree of freedom named), and the time it gives, if any."""
    text = re.sub(r"\s*The simulation is unstable\.?", "", message).strip()
    number = r"([-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?)"
    when = re.search(r"Time = " + number, text)
    text = re.sub(r"\.?\s*Time = " + number + r"\.?", "", text).strip().rstrip(".")
    dof = re.search(r"at DOF (\d+)", text)
    if dof:
        text = text.replace(dof.group(0), f"at degree of freedom {dof_name(model, int(dof.group(1)))}")
    return text, float(when.group(1)) if when else None


def dof_name(model: Model, index: int) -> str:
    """``<joint>.<dof>`` of a MuJoCo degree of freedom (pelvis: ``pelvis.x`` ... ``pelvis.yaw``)."""
    mj = model.mj
    if not 0 <= index < mj.nv:
        return f"#{index}"
    jnt = int(mj.dof_jntid[index])
    name = mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_JOINT, jnt) or f"joint {jnt}"
    if mj.jnt_type[jnt] == mujoco.mjtJoint.mjJNT_FREE:
        return f"{name}.{('x', 'y', 'z', 'roll', 'pitch', 'yaw')[index - int(mj.jnt_dofadr[jnt])]}"
    return name


def build_error(exc: Exception) -> InputError:
    """MuJoCo's compiler message as one sentence: what it refused, and where."""
    text = str(exc).strip()
    where = re.search(r"Element name '([^']*)'", text)
    first = text.splitlines()[0].removeprefix("Error:").strip().rstrip(".") if text else type(exc).__name__
    first = re.sub(r";?\s*use '\w+' to fix", "", first)
    at = (f" at model element {where.group(1)!r} (a segment, joint, contact or seat surface of that name)"
          if where else "")
    return InputError(f"the model could not be built: MuJoCo refused it{at}: {first}; check that element's values "
                      "in the body tables and the parameter file.")


def instability(model: Model, d: mujoco.MjData) -> str | None:
    """A reason why the state is no longer a seated person, or None."""
    if d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0:
        return "the accelerations became infinite or NaN"
    if not np.isfinite(d.qpos).all() or not np.isfinite(d.qvel).all():
        return "the state became infinite or NaN"
    pelvis = d.qpos[model.pelvis_qpos:model.pelvis_qpos + 3]
    moved, tilt = bool(np.abs(pelvis).max() > DIVERGED_M), _tilt_deg(model, d)
    if moved or tilt > FALL_TILT_DEG:
        why = (f"the pelvis moved {np.linalg.norm(pelvis):.3g} m from its seated position" if moved
               else f"the pelvis tilted {tilt:.0f} deg from its seated orientation, beyond {FALL_TILT_DEG:g} deg")
        speed = float(np.linalg.norm(d.qvel[model.pelvis_qpos:model.pelvis_qpos + 3]))
        if speed < FALL_SPEED_MPS and np.abs(d.qvel).max() < FALL_DOF_SPEED and not _warnings:
            way = _direction(pelvis)
            return Fall(", ".join([why] + ([way] if way != "away" else []) + [_tilt(model, d), f"at {speed:.2g} m/s"]))
        return why
    return None


def _pelvis_on_seat(model: Model, d: mujoco.MjData) -> tuple[np.ndarray, np.ndarray] | None:
    """The pelvis's orientation now and settled, as rotation matrices in seat axes (a rotating seat's own turning
    taken out), or None before the person has settled."""
    q0 = (model.settled or {}).get("qpos")
    if q0 is None:
        return None
    a = model.pelvis_qpos + 3
    R0 = np.empty(9)
    mujoco.mju_quat2Mat(R0, q0[a:a + 4])  # settled on the level seat: world axes are seat axes
    R = np.empty(9)
    mujoco.mju_quat2Mat(R, d.qpos[a:a + 4])
    R = R.reshape(3, 3)
    if model.seat is not None:
        R = d.xmat[model.seat["body"]].reshape(3, 3).T @ R
    return R, R0.reshape(3, 3)


def _tilt_deg(model: Model, d: mujoco.MjData) -> float:
    """Angle [deg] between the pelvis's up axis now and settled, in seat axes (0 before the person has settled)."""
    both = _pelvis_on_seat(model, d)
    if both is None:
        return 0.0
    R, R0 = both
    return float(np.degrees(np.arccos(np.clip(R[:, 2] @ R0[:, 2], -1.0, 1.0))))


class Fall(str):
    """The reason of :func:`instability` when the person left the seat at a physical speed (a fall, not a blow-up
    of the integration)."""


def _direction(offset: np.ndarray) -> str:
    """Where the pelvis went, in words (seat axes: x forward, y left, z up)."""
    names = (("forward", "backward"), ("to the left", "to the right"), ("up", "down"))
    parts = [names[i][0 if offset[i] > 0 else 1] for i in np.argsort(-np.abs(offset)) if abs(offset[i]) > 0.05]
    return " and ".join(parts[:2]) or "away"


def _tilt(model: Model, d: mujoco.MjData) -> str:
    """How far the pelvis turned from its settled orientation, in words (degrees, for people)."""
    both = _pelvis_on_seat(model, d)
    if both is None:
        return "turning"
    R, R0 = both
    quat, dq = np.empty(4), np.empty(3)
    mujoco.mju_mat2Quat(quat, (R @ R0.T).ravel())  # the turn from the settled orientation, seat axes
    mujoco.mju_quat2Vel(dq, quat, 1.0)
    k = int(np.argmax(np.abs(dq)))
    how = (("rolling", "rolling"), ("pitching back", "pitching forward"), ("turning", "turning"))[k][int(dq[k] > 0)]
    return f"{how} {np.degrees(abs(dq[k])):.0f} deg"


def divergence_error(model: Model, t: float, why: str, phase: str = "") -> DivergenceError:
    """The divergence sentence, with MuJoCo's own warning folded in (its time replaces ``t``: MuJoCo resets the
    state, and with it the time, when it finds a bad acceleration)."""
    dt = model.mj.opt.timestep
    for message in take_warnings()[:1]:
        said, when = _warning_sentence(model, message)
        why = f"{why}; MuJoCo: {said}"
        t = when if when is not None else t
    if isinstance(why, Fall) and not phase:  # (while settling nothing moves the seat: a fall there is the model's)
        back = model.params.back_support
        err = DivergenceError(
            f"the person fell off the seat at t = {t:.3f} s{phase} ({why}: a body leaving its seat at a physical "
            f"speed, not a numerical divergence, so a smaller time step does not change it); ehm's person on a seat "
            f"with back support {back} does not stay seated through this motion: give a back support (--back-support "
            "high; back_support='high'), or check the drive's sustained accelerations.")
        err.fell = True
    else:
        err = DivergenceError(
            f"the simulation diverged at t = {t:.3f} s{phase} ({why}); try a smaller time step than dt = {dt:g} s "
            "or check the stiffness and damping parameters."
        )
    err.time_s = None if phase else float(t)  # (settling has a clock of its own)
    return err
