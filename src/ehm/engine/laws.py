"""The force laws MuJoCo is set to integrate: trapezoidal damping of the trunk and neck joints
(:func:`split_damping`, at build time) and the contacts' spring and damper with their friction
(:func:`contact_solver_params`, after compiling and whenever the step changes)."""

from __future__ import annotations

import mujoco

from ..body.params import Parameters
from ..body.tables import Body

#: Joints whose damping is trapezoidal (:func:`split_damping`): the open chain of trunk and neck, where implicit
#: damping on light segments (the 1.6 kg neck) was the largest step error left (seat z -> head pitch 2.7 % at
#: 1 ms).  The legs and the tissue pads keep implicit damping: splitting them as well measured 1.8 % instead of
#: 1.5 % at 1 ms, at 22 more actuators.
TRAPEZOIDAL_JOINTS = ("l4_l5", "waist", "t12", "lower_neck", "upper_neck")


def split_damping(spec: mujoco.MjSpec) -> None:
    """Make the damping of :data:`TRAPEZOIDAL_JOINTS` trapezoidal: half stays joint damping (implicit under the
    Euler integrator), half becomes an actuator ``damper_<dof>`` with bias force -c/2 times the joint velocity
    (explicit)."""
    for j in list(spec.joints):
        c = float(j.damping[0])
        if c <= 0 or j.name.split(".")[0] not in TRAPEZOIDAL_JOINTS:
            continue
        j.damping[0] = c / 2
        a = spec.add_actuator(name=f"damper_{j.name}", target=j.name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        a.gainprm[0] = 0.0
        a.biastype = mujoco.mjtBias.mjBIAS_AFFINE
        a.biasprm[0], a.biasprm[1], a.biasprm[2] = 0.0, 0.0, -c / 2


#: Sets the friction rows' regulariser, 2 / (B * FRICTION_SOFTNESS) [1/kg], independent of the step [s]
#: (:func:`contact_solver_params`): 2.7e-6 s gives 1000 for the buttocks' 750 N s/m.
FRICTION_SOFTNESS = 2.7e-6


def contact_solver_params(mj: mujoco.MjModel, body: Body, params: Parameters, h: float) -> None:
    """Set each contact pair's solver parameters for its spring K [N/m] and damper B [N s/m]
    (``contacts.<name>.stiffness_N_per_m``, ``damping_Ns_per_m``) at step ``h`` [s].

    The contacts on tissue pads (seat and backrest) are
    trapezoidal; the others (the feet) keep the explicit spring and damper, f = -K r - B v: their friction is
    not backed by a shear pad, and with the trapezoid's small regulariser R the NoSlip solver's correction
    of their friction reached their normal force (1 N of 43 N at rest at 1 ms, a step-dependent posture).

    MuJoCo's soft constraint gives the normal force f = (a_ref - a_0) / (A + R), with A the contact's
    inverse inertia, a_0 its acceleration without the contact, R = (1 - d) / d * A_0 (A_0: the pair's
    inverse weight, ``body_invweight0``; d the impedance) and a_ref = -b v - k d r (b = -solref[1] / d,
    k = -solref[0] / d^2).  The trapezoidal contact f = -K r - B (v + v') / 2, v' = v + h (a_0 + A f),
    is f = (-K r - B v - (B h / 2) a_0) / (1 + B h A / 2): that is R = 2 / (B h) and
    a_ref = -(2 K / (B h)) r - (2 / h) v, so d = A_0 B h / (A_0 B h + 2), solref = (-2 K d / (B h), -2 d / h).
    An explicit pair (or one without damping) has a tiny impedance d = ``simulation.contact_impedance`` and
    solref = (-K (1-d) A_0,
    -B (1-d) A_0), so that f = -(1-d)(K r + B v) - d a_0 / A_0 at the step's start.
    Friction rows keep the damping rate 1 / h (solreffriction (0, -d / h)), which stops the soft friction
    from chattering at the Nyquist frequency, and a regulariser that does not depend on the step: MuJoCo
    takes a friction row's R as the normal row's over ``impratio``, so ``impratio`` = :data:`FRICTION_SOFTNESS`
    / h makes it 2 / (B * FRICTION_SOFTNESS), about a thousand times the pair's inverse weight (as weak as
    before this formulation).  The NoSlip solver then enforces sticking.
    """
    d_imp = float(params.value("simulation.contact_impedance"))
    mj.opt.impratio = FRICTION_SOFTNESS / h
    for c in body.contacts:
        k = float(params.value(f"contacts.{c.name}.stiffness_N_per_m"))
        b = float(params.value(f"contacts.{c.name}.damping_Ns_per_m"))
        i = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_PAIR, c.name)
        g1, g2 = mj.pair_geom1[i], mj.pair_geom2[i]
        a0 = mj.body_invweight0[mj.geom_bodyid[g1], 0] + mj.body_invweight0[mj.geom_bodyid[g2], 0]
        if c.tissue_pad and b > 0:
            d = a0 * b * h / (a0 * b * h + 2.0)
            mj.pair_solref[i] = [-2.0 * k * d / (b * h), -2.0 * d / h]
        else:
            d = d_imp
            mj.pair_solref[i] = [-k * (1 - d) * a0, -b * (1 - d) * a0]
        mj.pair_solimp[i][:2] = d
        mj.pair_solreffriction[i] = [0.0, -d / h]
