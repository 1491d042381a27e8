"""What a compiled model is: the :class:`Model` record, and the names every engine module shares (gravity, the
output points, the support groups)."""

from __future__ import annotations

import threading
from dataclasses import dataclass, field

import mujoco
import numpy as np

from ..body.params import Parameters
from ..body.tables import Body

G0 = np.array([0.0, 0.0, -9.81])  #: Standard gravity in the seat frame [m/s^2].
#: Output point -> the segment that carries it.  New points go last: the order is that of every output list
#: (files, FMU value references).
POINTS = {"pelvis": "pelvis", "trunk": "upper_torso", "head": "head", "lumbar": "lower_torso"}
#: Points at a joint's centre (point -> joint, a joint of its segment); the others sit at their segment's centre
#: of gravity.  ``lumbar`` is the L4-L5 joint centre on the lower torso: ISO 2631-5's lumbar response is that
#: of the lower lumbar spine, and the joint centre is an anatomical landmark (docs/model.md, "Outputs").
POINT_JOINTS = {"lumbar": "l4_l5"}
#: Support force groups: the seat pan with its cushion bolsters, the backrest with its pads and bolsters, the floor.
SUPPORT_GROUPS = {"seat_pan": ("seat_pan", "bolster_r", "bolster_l"),
                  "backrest": ("backrest_lower", "backrest_upper", "back_bolster_r", "back_bolster_l"),
                  "floor": ("floor",)}


@dataclass
class Model:
    """A compiled seated human on its seat, with names for everything a user addresses.

    Attributes
    ----------
    mj : mujoco.MjModel
    body : Body
    params : Parameters
    locked : frozenset of str
        Joints left out (welded).
    dof_names : list of str
        ``<joint>.<dof>`` for every human degree of freedom (pelvis: ``pelvis.x`` ... ``pelvis.yaw``).
    """

    mj: mujoco.MjModel
    body: Body
    params: Parameters
    locked: frozenset
    dof_names: list
    point_sites: dict
    surface_bodies: dict
    segment_bodies: dict
    seat: dict | None = None  #: Rotating seat: body id, dof, qpos and ctrl addresses (None: static seat).
    pelvis_qpos: int = 0  #: Address of the pelvis free joint in qpos.
    settled: dict | None = field(default=None, repr=False)
    #: Head-in-space control (:class:`ehm.engine.control.HeadControl`), None when off.
    head_control: object | None = None
    #: Held while a run steps the model (:func:`ehm.engine.run`, :func:`ehm.engine.step`): a run writes the seat's
    #: load into the model's gravity at every step, so two threads stepping one person take turns.
    busy: object = field(default_factory=threading.RLock, repr=False, compare=False)

    @property
    def dof(self) -> int:
        """Degrees of freedom of the human (pelvis 6 + unlocked joints; tissue pads not counted)."""
        return len(self.dof_names)

    @property
    def mass_kg(self) -> float:
        """Total mass of the human as compiled [kg] (segments plus their tissue pads)."""
        return float(self.mj.body_subtreemass[self.segment_bodies["pelvis"][0]])
