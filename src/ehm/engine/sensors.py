"""Reading a state: where each sensor sits in ``sensordata`` (:func:`sensor_slices`, :func:`support_slices`),
the support force of each seat surface, and the forces and names of the contacts (touching, sliding)."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from .model import POINTS, Model
from .state import settled_data

#: Per output point.  ``framelinvel`` and ``frameangvel`` give the accelerations (see :func:`point_accelerations`).
#: There are no acceleration sensors: they would make MuJoCo run its post-constraint pass (``cacc``,
#: ``cfrc_ext``) in every step, about 7 % of a step; the support forces come from contact sensors instead.
SENSOR_KINDS = ("framepos", "framequat", "framelinvel", "frameangvel")
REDUCE_NETFORCE = 3  #: A contact sensor's ``reduce="netforce"``: the net force of all matching contacts, world axes.


def sensor_slices(model: Model) -> dict:
    """``"<point>_<kind>" -> slice`` of each output sensor in ``sensordata``."""
    mj = model.mj
    out = {}
    for point in POINTS:
        for kind in SENSOR_KINDS:
            sid = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_SENSOR, f"{point}_{kind}")
            out[f"{point}_{kind}"] = slice(int(mj.sensor_adr[sid]), int(mj.sensor_adr[sid] + mj.sensor_dim[sid]))
    return out


def support_slices(model: Model) -> dict:
    """``surface -> slice`` of its support force sensor (3 values, world axes) in ``sensordata``."""
    mj = model.mj
    out = {}
    for s in model.surface_bodies:
        sid = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_SENSOR, f"support_{s}")
        out[s] = slice(int(mj.sensor_adr[sid]), int(mj.sensor_adr[sid]) + 3)
    return out


def support_forces(model: Model, d: mujoco.MjData) -> dict:
    """Force [N] that each seat surface exerts on the body now, world axes, by surface (its contact sensor:
    valid once MuJoCo's acceleration stage has run, as after :func:`mujoco.mj_step` for the step's start)."""
    sl = support_slices(model)
    return {s: d.sensordata[sl[s]].copy() for s in model.surface_bodies}


def contact_name(model: Model, c) -> str:
    """The body-side contact name (contacts.csv) of a MuJoCo contact: the pair's name."""
    return mujoco.mj_id2name(model.mj, mujoco.mjtObj.mjOBJ_GEOM, int(c.geom[1]))


def contact_forces(model: Model, d: mujoco.MjData, names) -> np.ndarray:
    """Normal and the two tangential force components [N] (contact frame) of the named contacts now, in that
    order per contact; zeros for a contact that does not touch."""
    out = np.zeros(3 * len(names))
    index = {n: i for i, n in enumerate(names)}
    f6 = np.zeros(6)
    for i in range(d.ncon):
        k = index.get(contact_name(model, d.contact[i]))
        if k is not None:
            mujoco.mj_contactForce(model.mj, d, i, f6)
            out[3 * k:3 * k + 3] += f6[:3]
    return out


def touching_contacts(model: Model) -> list[str]:
    """Names (contacts.csv) of the contacts that touch in the settled state, with friction (the linear model
    holds them stuck)."""
    d = settled_data(model)
    return sorted({contact_name(model, d.contact[i]) for i in range(d.ncon) if d.contact[i].dim >= 3})


def sliding_contacts(model: Model, d: mujoco.MjData, ratio: float = 0.98) -> list[str]:
    """Names (contacts.csv) of the contacts whose friction force is at the Coulomb limit (sliding or about to).

    A contact counts when it presses (positive normal force) and its tangential force, measured against
    the friction cone (``hypot(f1 / mu1, f2 / mu2)``), is at least ``ratio`` times the normal force.  The
    linearised model assumes none do.
    """
    out = []
    f6 = np.zeros(6)
    for i in range(d.ncon):
        c = d.contact[i]
        if c.dim < 3:
            continue
        mujoco.mj_contactForce(model.mj, d, i, f6)  # contact frame: normal, then the two tangents
        if f6[0] > 0 and math.hypot(f6[1] / c.friction[0], f6[2] / c.friction[1]) >= ratio * f6[0]:
            out.append(contact_name(model, c))
    return out
