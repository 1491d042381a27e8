"""The MuJoCo engine: builds the seated human from the tables and parameters, settles it, runs it.

This is the only module that imports :mod:`mujoco`.

How the paper's model maps onto MuJoCo (measured in the project's feasibility study and re-checked by
the tests):

* Segments are bodies whose frames sit at their parent joint, axes parallel to the global axes in the
  reference posture, so every joint angle is zero in that posture.  The pelvis has a free joint.
* Spherical joints are three hinges (roll x, pitch y, yaw z), the universal lower neck two (roll, pitch),
  T12 a vertical slide plus three hinges, knees and ankles one hinge about y.  A locked joint is left out:
  its child is welded to its parent.
* Every degree of freedom has a linear spring and damper (MuJoCo joint stiffness and damping: the P and
  D of the paper's PID posture control).  The I part is MuJoCo's PID actuator with zero P and D gains
  (ki = k / Ti) on the open-chain joints named in ``posture.integral_joints``.
* The damping of trunk and neck joints is integrated by the trapezoidal rule, so that the step's error is
  of second order in it: half of it is MuJoCo joint damping, which the Euler integrator treats implicitly
  (the velocity at the step's end), and half an actuator whose bias force is -c/2 times the joint velocity,
  which it treats explicitly (the velocity at the step's start) (:func:`_split_damping`).  The other
  joints' damping is implicit.
* Contacts are explicit ellipsoid-plane pairs with a linear spring K and damper B on penetration,
  elliptic friction cones and the NoSlip solver; seat and backrest ellipsoids ride on soft-tissue pads
  (two tangential slide springs) so that friction neither creeps nor locks.  On the tissue pads the
  contact force is the trapezoidal one, f = -K r - B (v + v') / 2 with v' the velocity at the step's
  end, which MuJoCo's soft constraint gives exactly with regulariser R = 2 / (B h) and reference
  acceleration -(2 K / (B h)) r - (2 / h) v (:func:`contact_solver_params`); as h goes to 0 it is the
  spring and damper.  The feet keep the explicit f = -K r - B v.  The pads' slide joints carry an
  armature (``simulation.pad_armature_kg``): the NoSlip solver makes a pad stick for the mass matrix M,
  while the integrator advances with M + h D; the armature keeps h D small against the pad's inertia so
  that a stuck pad stays put.
* Point accelerations are taken from the integrated motion (velocity change over the step plus the seat
  acceleration, :func:`point_accelerations`), not from MuJoCo's acceleration sensors, which report the
  explicit acceleration of the step's start.
* Seat translation is applied as a d'Alembert load: the seat stays put and gravity becomes
  ``g0 - a_seat(t)``.
"""

from __future__ import annotations

import contextlib
import math
import re
from dataclasses import dataclass, field

import mujoco
import numpy as np

from .errors import DivergenceError, InputError
from .params import Parameters
from .tables import Body

_PAD_INERTIA = 1e-6  #: Moment of inertia of a soft-tissue pad about each axis [kg m^2] (nearly a point mass).
G0 = np.array([0.0, 0.0, -9.81])  #: Standard gravity in the seat frame [m/s^2].
POINTS = {"pelvis": "pelvis", "trunk": "upper_torso", "head": "head"}  #: Output point -> segment.
#: Support force groups: the seat pan with its cushion bolsters, the backrest with its pads and bolsters, the floor.
SUPPORT_GROUPS = {"seat_pan": ("seat_pan", "bolster_r", "bolster_l"),
                  "backrest": ("backrest_lower", "backrest_upper", "back_bolster_r", "back_bolster_l"),
                  "floor": ("floor",)}


def _quat_pitch(angle_rad: float) -> np.ndarray:
    """Quaternion (w, x, y, z) of a rotation about y."""
    return np.array([math.cos(angle_rad / 2), 0.0, math.sin(angle_rad / 2), 0.0])


def _rot_y(angle_rad: float) -> np.ndarray:
    """Rotation matrix about y."""
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _quat_z_to(normal: np.ndarray) -> np.ndarray:
    """Quaternion rotating +z onto ``normal`` (unit vector)."""
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(z, normal)
    s, c = np.linalg.norm(axis), float(np.dot(z, normal))
    if s < 1e-12:
        return np.array([1.0, 0.0, 0.0, 0.0]) if c > 0 else np.array([0.0, 1.0, 0.0, 0.0])
    angle = math.atan2(s, c)
    axis = axis / s
    return np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * axis])


@dataclass(frozen=True)
class SeatGeometry:
    """Seat surfaces as planes in body axes of the reference posture: name -> (point [m], unit normal)."""

    planes: dict

    @classmethod
    def from_params(cls, params: Parameters, body: Body) -> "SeatGeometry":
        s = params.section("seat")
        a = math.radians(s["pan_angle_deg"])
        b = math.radians(s["backrest_angle_deg"])
        pan_n = np.array([-math.sin(a), 0.0, math.cos(a)])
        back_n = np.array([math.cos(b), 0.0, math.sin(b)])
        planes = {
            "seat_pan": (np.array([0.0, 0.0, s["pan_height_m"]]), pan_n),
            "floor": (np.array([0.0, 0.0, s["floor_height_m"]]), np.array([0.0, 0.0, 1.0])),
        }
        for pad in ("lower", "upper"):
            h = s[f"{pad}_pad_height_m"]
            point = np.array([s["backrest_x_m"] - math.tan(b) * h, 0.0, h]) + s[f"{pad}_pad_thickness_m"] * back_n
            planes[f"backrest_{pad}"] = (point, back_n)
        # Bolsters: planes facing the body's side ellipsoids, a gap beyond the ellipsoid's extreme point.
        c_ang, b_ang = math.radians(s["bolster_angle_deg"]), math.radians(s["back_bolster_angle_deg"])
        for c in body.contacts:
            if not c.surface.startswith(("bolster", "back_bolster")) or c.surface in planes:
                continue
            inward = 1.0 if c.surface.endswith("_r") else -1.0  # the right bolster (at -y) faces +y
            if c.surface.startswith("bolster"):  # cushion bolster: face rising outward at bolster_angle
                n = np.array([0.0, inward * math.sin(c_ang), math.cos(c_ang)])
            else:  # backrest bolster: face turned forward by back_bolster_angle
                n = np.array([math.sin(b_ang), inward * math.cos(b_ang), 0.0])
            local = _rot_y(c.pitch_rad).T @ n
            support = c.center_m - _rot_y(c.pitch_rad) @ (c.semi_axes_m ** 2 * local / np.linalg.norm(c.semi_axes_m * local))
            planes[c.surface] = (support - s["bolster_gap_m"] * n, n)
        return cls(planes)

    def tangents(self, surface: str) -> tuple[np.ndarray, np.ndarray]:
        """Two unit tangents of a surface: the first in the x-z plane, the second along y."""
        n = self.planes[surface][1]
        t2 = np.array([0.0, 1.0, 0.0])
        t1 = np.cross(t2, n)
        return t1 / np.linalg.norm(t1), t2


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

    @property
    def dof(self) -> int:
        """Degrees of freedom of the human (pelvis 6 + unlocked joints; tissue pads not counted)."""
        return len(self.dof_names)

    @property
    def mass_kg(self) -> float:
        """Total mass of the human as compiled [kg] (segments plus their tissue pads)."""
        return float(self.mj.body_subtreemass[self.segment_bodies["pelvis"][0]])


class ImpossibleInertia(InputError):
    """A segment's moments of inertia are those of no rigid body (``segment``: its name; ``moments``: the
    principal moments [kg m^2]; ``rule``: which condition fails)."""

    def __init__(self, message: str, segment: str, moments: np.ndarray, rule: str):
        super().__init__(message)
        self.segment, self.moments, self.rule = segment, moments, rule


def inertia_problem(body: Body, params: Parameters) -> ImpossibleInertia | None:
    """The first segment whose own body (tissue pads taken out) would not be a rigid body, or None."""
    pad_mass = {c.name: float(params.value(f"contacts.{c.name}.pad_mass_kg")) for c in body.contacts if c.tissue_pad}
    for seg in body.segments:
        try:
            segment_mass_properties(seg, [c for c in body.contacts if c.segment == seg.name and c.tissue_pad], pad_mass)
        except ImpossibleInertia as exc:
            return exc
    return None


def segment_mass_properties(seg, pads: list, pad_mass: dict) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass [kg], centre of gravity [m] and inertia matrix about it [kg m^2] of a segment's own body: the table
    values minus the tissue pads riding on it (so that segment plus pads keep the table's mass properties).

    Raises InputError when the pads weigh more than the segment, :class:`ImpossibleInertia` when what is
    left is no rigid body (a principal moment not positive, or larger than the sum of the other two).
    """
    m_pads = sum(pad_mass[c.name] for c in pads)
    m_body = seg.mass_kg - m_pads
    if m_body <= 0:
        raise InputError(f"the tissue pads on segment {seg.name!r} weigh more than the segment ({seg.mass_kg} kg).")
    c_body = (seg.mass_kg * seg.com_m - sum(pad_mass[c.name] * c.center_m for c in pads)) / m_body
    inertia = np.diag(seg.inertia_kgm2).astype(float)

    def shift(mass, r):
        return mass * (np.dot(r, r) * np.eye(3) - np.outer(r, r))

    inertia -= shift(m_body, c_body - seg.com_m)
    for c in pads:
        inertia -= shift(pad_mass[c.name], c.center_m - seg.com_m) + _PAD_INERTIA * np.eye(3)
    _check_inertia(seg.name, inertia, seg.inertia_kgm2, len(pads))
    return m_body, c_body, inertia


def _check_inertia(name: str, inertia: np.ndarray, table: np.ndarray, n_pads: int) -> None:
    """One sentence when a segment's inertia matrix belongs to no rigid body (MuJoCo would refuse it)."""
    moments = np.sort(np.linalg.eigvalsh(0.5 * (inertia + inertia.T)))
    a, b, c = moments
    if a > 0 and c <= (a + b) * (1 + 1e-9):
        return
    pads = f" after its {n_pads} tissue pad{'s' * (n_pads > 1)} are taken out" if n_pads else ""
    rule = (f"the largest, {c:.4g}, exceeds the sum of the other two, {a + b:.4g}" if a > 0
            else "one is not positive")
    raise ImpossibleInertia(
        f"segment {name!r} would have principal moments of inertia {a:.4g}, {b:.4g}, {c:.4g} kg m^2{pads} (table "
        f"values Ixx, Iyy, Izz {', '.join(f'{v:.4g}' for v in table)}), which no rigid body has ({rule}); "
        "correct its inertia (or mass and shape) in the segment table.", name, moments, rule)


def _build_error(exc: Exception) -> InputError:
    """MuJoCo's compiler message as one sentence: what it refused, and where."""
    text = str(exc).strip()
    where = re.search(r"Element name '([^']*)'", text)
    first = text.splitlines()[0].removeprefix("Error:").strip().rstrip(".") if text else type(exc).__name__
    first = re.sub(r";?\s*use '\w+' to fix", "", first)
    at = f" at model element {where.group(1)!r} (a segment, joint, contact or seat surface of that name)" if where else ""
    return InputError(f"the model could not be built: MuJoCo refused it{at}: {first}; check that element's values "
                      "in the body tables and the parameter file.")


#: Seat-geometry parameters that place each seat surface (for messages).
_SURFACE_PARAMS = {"seat_pan": "seat.pan_height_m and seat.pan_angle_deg", "floor": "seat.floor_height_m",
                   "backrest_lower": "seat.backrest_x_m, seat.backrest_angle_deg, seat.lower_pad_height_m and "
                                     "seat.lower_pad_thickness_m",
                   "backrest_upper": "seat.backrest_x_m, seat.backrest_angle_deg, seat.upper_pad_height_m and "
                                     "seat.upper_pad_thickness_m"}


def check_seat(seat: SeatGeometry, params: Parameters, body: Body) -> None:
    """The seat's geometry fits together and fits the body (one InputError sentence otherwise): the pan above the
    floor, the backrest pads behind the pelvis, the lower pad above the pan and below the upper pad, and every
    contact ellipsoid's centre in front of (above) the surface it presses on."""
    s = params.section("seat")
    pan, floor = s["pan_height_m"], s["floor_height_m"]
    if not pan > floor:
        raise InputError(f"seat.pan_height_m = {pan:g} m puts the seat pan {floor - pan:.3g} m below the floor "
                         f"(seat.floor_height_m = {floor:g} m); the pan must be above the floor.")
    if not pan < s["lower_pad_height_m"] < s["upper_pad_height_m"]:
        raise InputError(f"the backrest pads must sit on the backrest above the seat pan, the lower one below the "
                         f"upper one: seat.pan_height_m = {pan:g} m, seat.lower_pad_height_m = "
                         f"{s['lower_pad_height_m']:g} m, seat.upper_pad_height_m = {s['upper_pad_height_m']:g} m.")
    pelvis = body.segment("pelvis").com_m
    for surface in ("backrest_lower", "backrest_upper"):
        point, normal = seat.planes[surface]
        gap = float(np.dot(pelvis - point, normal))
        if gap <= 0:
            raise InputError(f"the {surface.replace('_', ' ')} pad lies {-gap:.3g} m in front of the pelvis's centre "
                             f"of gravity; the backrest must be behind the pelvis (check {_SURFACE_PARAMS[surface]}).")
    for c in body.contacts:
        if c.surface not in _SURFACE_PARAMS:
            continue  # bolsters are placed from the contacts themselves
        point, normal = seat.planes[c.surface]
        gap = float(np.dot(c.center_m - point, normal))
        if gap <= 0:
            side = "below" if c.surface in ("seat_pan", "floor") else "behind"
            raise InputError(f"contact {c.name!r} (segment {c.segment}) starts with its centre {-gap:.3g} m {side} "
                             f"the {c.surface.replace('_', ' ')} surface it presses on; move the surface (check "
                             f"{_SURFACE_PARAMS[c.surface]}) or the contact (contacts table).")


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


def _warning_sentence(model: "Model", message: str) -> tuple[str, float | None]:
    """A captured MuJoCo warning in ehm's terms (degree of freedom named), and the time it gives, if any."""
    text = re.sub(r"\s*The simulation is unstable\.?", "", message).strip()
    number = r"([-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?)"
    when = re.search(r"Time = " + number, text)
    text = re.sub(r"\.?\s*Time = " + number + r"\.?", "", text).strip().rstrip(".")
    dof = re.search(r"at DOF (\d+)", text)
    if dof:
        text = text.replace(dof.group(0), f"at degree of freedom {dof_name(model, int(dof.group(1)))}")
    return text, float(when.group(1)) if when else None


def dof_name(model: "Model", index: int) -> str:
    """``<joint>.<dof>`` of a MuJoCo degree of freedom (pelvis: ``pelvis.x`` ... ``pelvis.yaw``)."""
    mj = model.mj
    if not 0 <= index < mj.nv:
        return f"#{index}"
    jnt = int(mj.dof_jntid[index])
    name = mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_JOINT, jnt) or f"joint {jnt}"
    if mj.jnt_type[jnt] == mujoco.mjtJoint.mjJNT_FREE:
        return f"{name}.{('x', 'y', 'z', 'roll', 'pitch', 'yaw')[index - int(mj.jnt_dofadr[jnt])]}"
    return name


SEAT_DOFS = ("yaw", "pitch", "roll")  #: Hinges of a rotating seat, outermost first (intrinsic z-y-x).
_SEAT_INERTIA = 1e5  #: Moment of inertia of a rotating seat about its pivot [kg m^2]: the person barely moves it.
_SEAT_BANDWIDTH_HZ = 20.0  #: Bandwidth of the seat's tracking controller (on top of feed-forward).


def build(body: Body, params: Parameters, locked: frozenset | set = frozenset(), rotating_seat: bool = False) -> Model:
    """Compile the seated human.

    Parameters
    ----------
    body : Body
        Segments, joints and contact ellipsoids.
    params : Parameters
        Joint, contact, posture, seat and solver parameters.
    locked : set of str
        Names of joints to weld (the complete set: include ``waist`` to keep the paper's default).
    rotating_seat : bool
        Put seat pan, backrest and floor on a heavy seat body that rotates about a pivot at the seat pan
        reference point (yaw, pitch and roll hinges driven by feed-forward plus stiff PD control), for
        vehicle motion with rotation.  The surfaces are then thin boxes (MuJoCo allows planes only on
        static bodies), which makes each step about 40 % slower.
    """
    params.check_against(body)
    known = {j.name for j in body.joints}
    for name in locked:
        if name not in known:
            raise InputError(f"unknown joint {name!r}; joints are {', '.join(j.name for j in body.joints)}.")
    locked = frozenset(locked)
    sim = params.section("simulation")
    posture = params.section("posture")
    seat = SeatGeometry.from_params(params, body)
    check_seat(seat, params, body)

    spec = mujoco.MjSpec()
    spec.modelname = "ehm_seated_human"
    spec.compiler.degree = False
    opt = spec.option
    opt.timestep = float(sim["dt_s"])
    opt.gravity = G0
    # Euler with implicit joint damping: with half the damping explicit (_split_damping) the damping is
    # trapezoidal.  (implicitfast would also take the explicit half's actuators implicitly.)
    opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    opt.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    # Projected Gauss-Seidel: the NoSlip pass needs the constraint-space matrix that PGS works on anyway, so
    # PGS + NoSlip costs about 30 % less per step than Newton + NoSlip, with the same transfer functions
    # (0.00 % apart at step / 8; README "Speed").
    opt.solver = mujoco.mjtSolver.mjSOL_PGS
    opt.iterations = int(sim["solver_iterations"])
    opt.noslip_iterations = int(sim["noslip_iterations"])
    # No island discovery: the body and its contacts form one island, and PGS solves all rows at once anyway.
    # The same numbers to the bit, 3 us a step less (36 -> 33 us at 1 ms).
    opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_ISLAND)

    # Seat surfaces: static bodies, one per surface, so their contact forces can be read by body.
    plane_size = {"seat_pan": [0.25, 0.25, 0.05], "floor": [0.5, 0.4, 0.1],
                  "backrest_lower": [0.08, 0.18, 0.05], "backrest_upper": [0.10, 0.20, 0.05],
                  "bolster_r": [0.15, 0.04, 0.05], "bolster_l": [0.15, 0.04, 0.05],
                  "back_bolster_r": [0.12, 0.04, 0.05], "back_bolster_l": [0.12, 0.04, 0.05]}
    parent, origin = spec.worldbody, np.zeros(3)
    if rotating_seat:
        origin = seat.planes["seat_pan"][0]
        parent = spec.worldbody.add_body(name="seat_frame", pos=origin)
        parent.explicitinertial = True
        parent.mass = _SEAT_INERTIA
        parent.inertia = [_SEAT_INERTIA] * 3
        for dof, axis in zip(SEAT_DOFS, ([0, 0, 1], [0, 1, 0], [1, 0, 0])):
            parent.add_joint(name=f"seat.{dof}", type=mujoco.mjtJoint.mjJNT_HINGE, axis=axis)
    for surface, (point, normal) in seat.planes.items():
        sb = parent.add_body(name=surface, pos=point - origin, quat=_quat_z_to(normal))
        if rotating_seat:  # a box whose top face is the surface, large enough never to be run off
            half = [1.0, 1.0, 0.05]
            sb.add_geom(name=surface, type=mujoco.mjtGeom.mjGEOM_BOX, size=half, pos=[0, 0, -half[2]],
                        contype=0, conaffinity=0, group=3, rgba=[0.55, 0.55, 0.6, 0.3])
        else:
            sb.add_geom(name=surface, type=mujoco.mjtGeom.mjGEOM_PLANE, size=plane_size[surface],
                        contype=0, conaffinity=0, rgba=[0.55, 0.55, 0.6, 1.0])

    # Pads take their mass from their segment: keep each segment's total mass, centre of gravity and
    # inertia exactly as in the table.
    pads = {s.name: [c for c in body.contacts if c.segment == s.name and c.tissue_pad] for s in body.segments}
    pad_mass = {c.name: float(params.value(f"contacts.{c.name}.pad_mass_kg")) for c in body.contacts if c.tissue_pad}
    pad_armature = float(sim["pad_armature_kg"])

    children: dict[str, list] = {}
    for j in body.joints:
        children.setdefault(j.parent, []).append(j)

    dof_names: list[str] = ["pelvis.x", "pelvis.y", "pelvis.z", "pelvis.roll", "pelvis.pitch", "pelvis.yaw"]
    segment_bodies: dict[str, list[int]] = {}
    integral_joints = set(posture["integral_joints"])
    ti = float(posture["integral_time_s"])
    actuated: list[tuple[str, float]] = []

    def add_segment(parent_body, seg_name: str, frame_pos: np.ndarray, parent_frame: np.ndarray, joint=None):
        seg = body.segment(seg_name)
        b = parent_body.add_body(name=seg_name, pos=frame_pos - parent_frame)
        if joint is None:
            b.add_freejoint(name="pelvis")
        elif joint.name not in locked:
            # Joint axes pitched about y by the joint's axes_pitch_rad (x -> front down, z -> top forward).
            cp, sp = math.cos(joint.axes_pitch_rad), math.sin(joint.axes_pitch_rad)
            joint_axes = {"roll": [cp, 0.0, -sp], "pitch": [0.0, 1.0, 0.0], "yaw": [sp, 0.0, cp]}
            for dof in joint.dofs:
                k, c = params.joint_dof(joint.name, dof)
                jn = f"{joint.name}.{dof}"
                if dof == "z":
                    b.add_joint(name=jn, type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0, 0, 1], stiffness=k, damping=c)
                else:
                    b.add_joint(name=jn, type=mujoco.mjtJoint.mjJNT_HINGE, axis=joint_axes[dof], stiffness=k, damping=c)
                dof_names.append(jn)
                if joint.name in integral_joints and k > 0:
                    actuated.append((jn, k / ti))
        m_body, c_body, inertia = segment_mass_properties(seg, pads[seg_name], pad_mass)
        b.explicitinertial = True
        b.mass = m_body
        b.ipos = c_body - frame_pos
        b.fullinertia = [inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2], inertia[1, 2]]
        b.add_geom(name=f"{seg_name}_shape", type=mujoco.mjtGeom.mjGEOM_ELLIPSOID, size=seg.shape_m,
                   pos=seg.com_m - frame_pos, quat=_quat_pitch(seg.shape_pitch_rad), contype=0, conaffinity=0,
                   group=1, rgba=[0.85, 0.65, 0.5, 0.5])
        segment_bodies.setdefault(seg_name, []).append(seg_name)
        if seg_name in POINTS.values():
            point = [p for p, s in POINTS.items() if s == seg_name][0]
            b.add_site(name=point, pos=seg.com_m - frame_pos, size=[0.01, 0, 0])
        for c in body.contacts:
            if c.segment != seg_name:
                continue
            holder = b
            if c.tissue_pad:
                holder = b.add_body(name=f"pad_{c.name}", pos=c.center_m - frame_pos)
                holder.explicitinertial = True
                holder.mass = pad_mass[c.name]
                holder.ipos = [0.0, 0.0, 0.0]
                holder.iquat = [1.0, 0.0, 0.0, 0.0]
                holder.inertia = [_PAD_INERTIA, _PAD_INERTIA, _PAD_INERTIA]
                ks = float(params.value(f"contacts.{c.name}.shear_stiffness_N_per_m"))
                cs = float(params.value(f"contacts.{c.name}.shear_damping_Ns_per_m"))
                for i, t in enumerate(seat.tangents(c.surface)):
                    holder.add_joint(name=f"pad_{c.name}.t{i + 1}", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=t,
                                     stiffness=ks, damping=cs, armature=pad_armature)
                segment_bodies[seg_name].append(f"pad_{c.name}")
                gpos = np.zeros(3)
            else:
                gpos = c.center_m - frame_pos
            holder.add_geom(name=c.name, type=mujoco.mjtGeom.mjGEOM_ELLIPSOID, size=c.semi_axes_m, pos=gpos,
                            quat=_quat_pitch(c.pitch_rad), contype=0, conaffinity=0, group=2,
                            rgba=[0.3, 0.5, 0.8, 0.4])
        for j in children.get(seg_name, []):
            add_segment(b, j.child, j.pos_m, frame_pos, j)

    add_segment(spec.worldbody, "pelvis", np.zeros(3), np.zeros(3))

    # Contact pairs, with placeholder solref: the linear spring needs the compiled inverse weights.
    d_imp = float(sim["contact_impedance"])
    for c in body.contacts:
        mu = float(params.value(f"contacts.{c.name}.friction"))
        spec.add_pair(name=c.name, geomname1=c.surface, geomname2=c.name, condim=3 if mu > 0 else 1,
                      friction=[mu, mu, 0.005, 1e-4, 1e-4], solimp=[d_imp, d_imp, 0.001, 0.5, 2.0])
    if rotating_seat:  # tracking PD with position and velocity set-points (two controls each)
        wn = 2 * math.pi * _SEAT_BANDWIDTH_HZ
        for dof in SEAT_DOFS:
            a = spec.add_actuator(name=f"seat_{dof}", target=f"seat.{dof}", trntype=mujoco.mjtTrn.mjTRN_JOINT)
            a.set_to_pid(kp=_SEAT_INERTIA * wn ** 2, kv=2 * _SEAT_INERTIA * wn)
    for jn, ki in actuated:
        a = spec.add_actuator(name=f"integral_{jn}", target=jn, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        a.set_to_pid(kp=0.0, kv=0.0, ki=ki)
    _split_damping(spec)
    for point in POINTS:
        for kind in SENSOR_KINDS:
            spec.add_sensor(name=f"{point}_{kind}", type=getattr(mujoco.mjtSensor, f"mjSENS_{kind.upper()}"),
                            objtype=mujoco.mjtObj.mjOBJ_SITE, objname=point)
    for surface in seat.planes:  # net contact force of each surface on the body, world axes
        spec.add_sensor(name=f"support_{surface}", type=mujoco.mjtSensor.mjSENS_CONTACT,
                        objtype=mujoco.mjtObj.mjOBJ_BODY, objname=surface,
                        intprm=[1 << int(mujoco.mjtConDataField.mjCONDATA_FORCE), _REDUCE_NETFORCE, 1])
    try:
        with captured_warnings():
            mj = spec.compile()
    except ValueError as exc:
        raise _build_error(exc) from None

    contact_solver_params(mj, body, params, mj.opt.timestep)

    if rotating_seat:
        spec_body = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_BODY, "seat_frame")
        seat_dofs = [int(mj.jnt_dofadr[mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_JOINT, f"seat.{d}")]) for d in SEAT_DOFS]
        seat_qpos = [int(mj.jnt_qposadr[mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_JOINT, f"seat.{d}")]) for d in SEAT_DOFS]
        seat_ctrl = [int(mj.actuator_ctrladr[mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_ACTUATOR, f"seat_{d}")]) for d in SEAT_DOFS]
        seat_info = {"body": spec_body, "dofs": seat_dofs, "qpos": seat_qpos, "ctrl": seat_ctrl, "pivot": origin.copy()}
    else:
        seat_info = None
    point_sites = {p: mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_SITE, p) for p in POINTS}
    surface_bodies = {s: mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_BODY, s) for s in seat.planes}
    seg_ids = {s: [mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_BODY, n) for n in names]
               for s, names in segment_bodies.items()}
    return Model(mj=mj, body=body, params=params, locked=locked, dof_names=dof_names,
                 point_sites=point_sites, surface_bodies=surface_bodies, segment_bodies=seg_ids, seat=seat_info,
                 pelvis_qpos=int(mj.jnt_qposadr[mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_JOINT, "pelvis")]))


#: Joints whose damping is trapezoidal (:func:`_split_damping`): the open chain of trunk and neck, where implicit
#: damping on light segments (the 1.6 kg neck) was the largest step error left (seat z -> head pitch 2.7 % at
#: 1 ms).  The legs and the tissue pads keep implicit damping: splitting them as well measured 1.8 % instead of
#: 1.5 % at 1 ms, at 22 more actuators.
TRAPEZOIDAL_JOINTS = ("l4_l5", "waist", "t12", "lower_neck", "upper_neck")


def _split_damping(spec: mujoco.MjSpec) -> None:
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


_DIVERGED_M = 0.5  #: A point further than this from its settled position means the run has diverged [m].
CHECK_EVERY = 100  #: Steps between divergence checks (0.1 s at the default step).


def _instability(model: Model, d: mujoco.MjData) -> str | None:
    """A reason why the state is no longer a seated person, or None."""
    if d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0:
        return "the accelerations became infinite or NaN"
    if not np.isfinite(d.qpos).all() or not np.isfinite(d.qvel).all():
        return "the state became infinite or NaN"
    pelvis = d.qpos[model.pelvis_qpos:model.pelvis_qpos + 3]
    if np.abs(pelvis).max() > _DIVERGED_M:
        return f"the pelvis moved {np.linalg.norm(pelvis):.3g} m from its seated position"
    return None


def _diverged(model: Model, t: float, why: str, phase: str = "") -> DivergenceError:
    """The divergence sentence, with MuJoCo's own warning folded in (its time replaces ``t``: MuJoCo resets the
    state, and with it the time, when it finds a bad acceleration)."""
    dt = model.mj.opt.timestep
    for message in take_warnings()[:1]:
        said, when = _warning_sentence(model, message)
        why = f"{why}; MuJoCo: {said}"
        t = when if when is not None else t
    return DivergenceError(
        f"the simulation diverged at t = {t:.3f} s{phase} ({why}); try a smaller time step than dt = {dt:g} s "
        "or check the stiffness and damping parameters."
    )


def new_data(model: Model) -> mujoco.MjData:
    """A fresh MjData at the reference posture."""
    return mujoco.MjData(model.mj)


def settle(model: Model, duration_s: float | None = None) -> dict:
    """Let the person sink into the seat under gravity until the posture controller has converged.

    Starts from the reference posture; the integral action of the posture control pulls the open-chain
    joints back to it.  For the first ``simulation.back_slide_s`` the backrest contacts are frictionless.  The settled state (``qpos``, ``qvel``, ``act``) is stored on the model and returned.
    Raises :class:`DivergenceError` if the model does not stay seated.
    """
    slide_s = float(model.params.value("simulation.back_slide_s"))
    if duration_s is None:
        duration_s = float(model.params.value("simulation.settle_s"))
    else:  # a settling time other than the file's: slide for at most half of it
        slide_s = min(slide_s, duration_s / 2)
    mj = model.mj
    d = new_data(model)
    mj.opt.gravity[:] = G0
    n = int(round(duration_s / mj.opt.timestep))
    # The back first slides onto the backrest pads without friction, so that it comes to rest there without
    # a shear preload (sinking into the cushion would otherwise leave the back pads at their friction limit).
    n_slide = int(round(slide_s / mj.opt.timestep))
    back = [mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_PAIR, c.name) for c in model.body.contacts
            if c.surface.startswith("backrest")]
    friction = mj.pair_friction[back].copy()
    mj.pair_friction[back, :2] = 0.0
    try:
        with captured_warnings():
            for i in range(n):
                if i == n_slide:
                    mj.pair_friction[back] = friction
                mujoco.mj_step(mj, d)
                if i % CHECK_EVERY == 0:
                    why = _instability(model, d)
                    if why:
                        raise _diverged(model, d.time, why, " while settling into the seat, before the run")
    finally:
        mj.pair_friction[back] = friction
    why = _instability(model, d)
    if why:
        raise _diverged(model, d.time, why, " while settling into the seat, before the run")
    model.settled = {"qpos": d.qpos.copy(), "qvel": d.qvel.copy(), "act": d.act.copy(), "settle_s": duration_s}
    return model.settled


def settled_data(model: Model) -> mujoco.MjData:
    """A fresh MjData in the settled state (settling first if needed), time reset to 0."""
    if model.settled is None:
        settle(model)
    d = new_data(model)
    d.qpos[:] = model.settled["qpos"]
    d.qvel[:] = model.settled["qvel"]
    d.act[:] = model.settled["act"]
    mujoco.mj_forward(model.mj, d)
    return d


def settled_point_poses(model: Model) -> dict:
    """Per output point: position [m] and orientation quaternion (w, x, y, z) in the settled state."""
    d = settled_data(model)
    out = {}
    for point, sid in model.point_sites.items():
        quat = np.empty(4)
        mujoco.mju_mat2Quat(quat, d.site_xmat[sid])
        out[point] = (d.site_xpos[sid].copy(), quat)
    return out


def save_binary(model: Model, path) -> None:
    """Write the compiled model as a MuJoCo binary model file (MJB) at ``path``, for the native FMU.

    The MJB holds the model exactly as compiled here (solver, contact pairs and their solref set after
    compilation, sensors), with gravity G0: the C unit loads it with ``mj_loadModel`` and steps it as
    :func:`step` does.
    """
    mujoco.mj_saveModel(model.mj, str(path), None)


def c_library() -> dict:
    """Where the installed MuJoCo keeps its C library and headers, for building the native FMU.

    Returns ``version`` (e.g. ``"4.0.0"``), ``include_dir`` (holding ``mujoco/mujoco.h``), ``library``
    (the shared library ``libmujoco.so.<version>`` on Linux) and ``licenses`` (the wheel's licence files, to
    ship with the library), or raises :class:`InputError` naming what is missing.
    """
    from importlib import metadata
    from pathlib import Path

    root = Path(mujoco.__file__).resolve().parent
    version = mujoco.mj_versionString()
    include = root / "include"
    libs = sorted(root.glob("libmujoco.so*"))
    if not (include / "mujoco" / "mujoco.h").is_file():
        raise InputError(f"the installed mujoco package ({root}) ships no C headers (include/mujoco/mujoco.h).")
    if not libs:
        raise InputError(f"the installed mujoco package ({root}) ships no shared library libmujoco.so for this "
                         "platform.")
    try:
        licenses = [Path(f.locate()) for f in metadata.distribution("mujoco").files or ()
                    if "LICENSE" in f.name.upper()]
    except metadata.PackageNotFoundError:
        licenses = []
    return {"version": version, "include_dir": include, "library": libs[-1],
            "licenses": [p for p in licenses if p.is_file()]}


def support_forces(model: Model, d: mujoco.MjData) -> dict:
    """Force [N] that each seat surface exerts on the body now, world axes, by surface (its contact sensor:
    valid once MuJoCo's acceleration stage has run, as after :func:`mujoco.mj_step` for the step's start)."""
    sl = support_slices(model)
    return {s: d.sensordata[sl[s]].copy() for s in model.surface_bodies}


def support_slices(model: Model) -> dict:
    """``surface -> slice`` of its support force sensor (3 values, world axes) in ``sensordata``."""
    mj = model.mj
    out = {}
    for s in model.surface_bodies:
        sid = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_SENSOR, f"support_{s}")
        out[s] = slice(int(mj.sensor_adr[sid]), int(mj.sensor_adr[sid]) + 3)
    return out


#: Per output point.  ``framelinvel`` and ``frameangvel`` give the accelerations (see :func:`point_accelerations`).
#: There are no acceleration sensors: they would make MuJoCo run its post-constraint pass (``cacc``,
#: ``cfrc_ext``) in every step, about 7 % of a step; the support forces come from contact sensors instead.
SENSOR_KINDS = ("framepos", "framequat", "framelinvel", "frameangvel")
_REDUCE_NETFORCE = 3  #: A contact sensor's ``reduce="netforce"``: the net force of all matching contacts, world axes.


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
            out.append(_contact_name(model, c))
    return out


def _contact_name(model: Model, c) -> str:
    """The body-side contact name (contacts.csv) of a MuJoCo contact: the pair's name."""
    return mujoco.mj_id2name(model.mj, mujoco.mjtObj.mjOBJ_GEOM, int(c.geom[1]))


def sensor_slices(model: Model) -> dict:
    """``"<point>_<kind>" -> slice`` of each output sensor in ``sensordata``."""
    mj = model.mj
    out = {}
    for point in POINTS:
        for kind in SENSOR_KINDS:
            sid = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_SENSOR, f"{point}_{kind}")
            out[f"{point}_{kind}"] = slice(int(mj.sensor_adr[sid]), int(mj.sensor_adr[sid] + mj.sensor_dim[sid]))
    return out


def get_state(model: Model, d: mujoco.MjData) -> np.ndarray:
    """The full integration state of ``d`` (positions, velocities, activations, time, ...)."""
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    buf = np.empty(mujoco.mj_stateSize(model.mj, spec))
    mujoco.mj_getState(model.mj, d, buf, spec)
    return buf


def set_state(model: Model, d: mujoco.MjData, state: np.ndarray) -> None:
    """Put a state from :func:`get_state` back into ``d``."""
    mujoco.mj_setState(model.mj, d, state, mujoco.mjtState.mjSTATE_INTEGRATION)


def evaluate_velocities(model: Model, d: mujoco.MjData) -> np.ndarray:
    """Velocity-stage kinematics and sensors of the current state of ``d``; returns ``d.sensordata``.

    After :func:`mujoco.mj_step` the sensors hold the step's start state; this brings the velocity sensors
    (``framelinvel``, ``frameangvel``) to the new state without changing the state (the next step recomputes
    everything), so that the acceleration of the step can be taken from them (:func:`point_accelerations`).
    """
    mj = model.mj
    mujoco.mj_kinematics(mj, d)
    mujoco.mj_comPos(mj, d)
    mujoco.mj_comVel(mj, d)
    mujoco.mj_sensorVel(mj, d)
    return d.sensordata


def point_accelerations(v_lin: np.ndarray, v_ang: np.ndarray, seat_acc_mps2: np.ndarray, dt_s: float):
    """Absolute translational and angular acceleration of a point over each step, from its velocities.

    ``v_lin`` and ``v_ang`` (n + 1, 3) are the point's linear [m/s] and angular [rad/s] velocity in world
    axes at the start of steps 0 ... n (the last one: after the last step); ``seat_acc_mps2`` (n, 3) is the
    seat's acceleration held over each step, world axes.  Returns (n, 3) arrays [m/s^2], [rad/s^2].

    These are the accelerations of the motion the integrator produces.  MuJoCo's acceleration sensors report
    the explicit acceleration M^-1 f at the start of the step, whereas the implicit integrator advances the
    velocity with (M + h D)^-1 f; where the damping h D is not small against the inertia M (neck, spine,
    tissue pads) the two differ by far more than the motion's own step error.
    """
    return np.diff(v_lin, axis=0) / dt_s + seat_acc_mps2, np.diff(v_ang, axis=0) / dt_s


def step(model: Model, d: mujoco.MjData, seat_acc_mps2: np.ndarray, check: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Advance one time step with a seat acceleration (static seat).

    Returns the sensor data of the step's start state and the sensor data after :func:`evaluate_velocities`
    of its end state (velocity sensors valid), from which :func:`point_accelerations` gives the step's
    accelerations.  The same operations as one iteration of :func:`run`, so stepping reproduces whole runs
    exactly.  ``check`` tests for divergence after the step.
    """
    g = model.mj.opt.gravity
    g[:] = G0 - seat_acc_mps2
    try:
        mujoco.mj_step(model.mj, d)
    finally:
        g[:] = G0
    start = d.sensordata.copy()
    if check:
        why = _instability(model, d)
        if why:
            raise _diverged(model, d.time, why)
    return start, evaluate_velocities(model, d)


@dataclass(frozen=True)
class RawRun:
    """Engine output of one run, sampled at every step (before integration).

    Attributes
    ----------
    time_s : (n,) array
    sensors : dict
        ``<point>_acc`` (absolute translational acceleration over each step, world axes [m/s^2]),
        ``<point>_angacc`` (angular acceleration, world axes [rad/s^2]), both from
        :func:`point_accelerations`; and the raw sensors of each step's start state:
        ``<point>_framepos`` [m], ``<point>_framequat`` (w, x, y, z), ``<point>_framelinvel`` [m/s],
        ``<point>_frameangvel`` [rad/s], each (n, 3) or (n, 4).
    support_N : dict
        Force of each seat surface on the body, (n, 3) [N].
    """

    time_s: np.ndarray
    sensors: dict
    support_N: dict
    poses: dict | None = None  #: ``step`` (m,), ``pos`` (m, k, 3), ``quat`` (m, k, 4) of the bodies drawn


def drawing_geometry(model: Model) -> dict:
    """What a picture of the model needs, from the compiled model: per segment its drawn ellipsoid (semi-axes,
    position and orientation in the segment body's frame) and per seat surface its shape and pose at rest.

    Returns a dict of arrays: ``segments`` (names), ``segment_body`` (body ids), ``shape_size_m`` (k, 3),
    ``shape_pos_m`` (k, 3), ``shape_quat`` (k, 4); ``surfaces`` (names), ``surface_type`` ("plane"/"box"),
    ``surface_size_m`` (s, 3), ``surface_pos_m`` (s, 3), ``surface_quat`` (s, 4) in world axes at rest.
    """
    mj = model.mj
    segs = [s.name for s in model.body.segments]
    gids = [mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_GEOM, f"{s}_shape") for s in segs]
    d = mujoco.MjData(mj)
    mujoco.mj_forward(mj, d)
    surf = list(model.surface_bodies)
    sg = [mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_GEOM, s) for s in surf]
    quats = np.empty((len(sg), 4))
    for i, g in enumerate(sg):
        mujoco.mju_mat2Quat(quats[i], d.geom_xmat[g])
    return {
        "segments": np.array(segs), "segment_body": np.array([mj.geom_bodyid[g] for g in gids]),
        "shape_size_m": mj.geom_size[gids].copy(), "shape_pos_m": mj.geom_pos[gids].copy(),
        "shape_quat": mj.geom_quat[gids].copy(),
        "surfaces": np.array(surf),
        "surface_type": np.array(["plane" if mj.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE else "box" for g in sg]),
        "surface_size_m": mj.geom_size[sg].copy(), "surface_pos_m": d.geom_xpos[sg].copy(), "surface_quat": quats,
    }


def _run_of(array: np.ndarray, idx) -> np.ndarray:
    """The view ``array[idx]`` for indices that are one contiguous run (written once per step, a slice is
    several times cheaper than fancy indexing); the seat's dofs and controls are built first, so they are."""
    idx = np.asarray(idx, dtype=int)
    if not np.array_equal(idx, np.arange(idx[0], idx[0] + idx.size)):
        raise RuntimeError(f"indices {idx.tolist()} are not one contiguous run")
    return array[idx[0]:idx[0] + idx.size]


def run(model: Model, seat_acc_mps2: np.ndarray, d: mujoco.MjData | None = None,
        seat_rotation: tuple | None = None, pose_every: int | None = None) -> RawRun:
    """Run the settled model with a seat acceleration history, one row per time step.

    Parameters
    ----------
    seat_acc_mps2 : (n, 3) array
        Translational acceleration of the seat pivot [m/s^2] at t = 0, dt, 2 dt, ... in world axes (equal
        to seat axes when the seat does not rotate).
    d : MjData, optional
        Start state (default: the settled state); advanced in place, so consecutive calls continue a run.
    seat_rotation : (angles, rates, accelerations), each (n, 3) yaw-pitch-roll, optional
        Prescribed seat orientation for a model built with ``rotating_seat=True``.
    pose_every : int, optional
        Record the world pose of every segment body (and of the seat frame, if any) every this many steps,
        for pictures.
    """
    mj = model.mj
    if (seat_rotation is not None) != (model.seat is not None):
        raise InputError("a rotating seat needs a seat rotation, and a seat rotation needs a model built with "
                         "rotating_seat=True.")
    if d is None:
        d = settled_data(model)
    acc = np.asarray(seat_acc_mps2, dtype=float)
    n = acc.shape[0]
    sens = np.empty((n, mj.nsensordata))
    gravity = G0[None, :] - acc
    if seat_rotation is not None:
        q_des, qd_des, qdd_des = (np.asarray(a, dtype=float) for a in seat_rotation)
        ctrl_adr = np.array(model.seat["ctrl"])
        ctrl = np.empty((n, 6))
        ctrl[:, 0::2], ctrl[:, 1::2] = q_des, qd_des
        ctrl_idx = np.column_stack([ctrl_adr, ctrl_adr + 1]).ravel()
        ff = _SEAT_INERTIA * qdd_des  # feed-forward torque of the heavy seat
        c_view, f_view = _run_of(d.ctrl, ctrl_idx), _run_of(d.qfrc_applied, model.seat["dofs"])
    if pose_every:
        pose_ids = np.array([model.segment_bodies[s.name][0] for s in model.body.segments]
                            + ([model.seat["body"]] if model.seat else []))
        pose_steps = np.arange(0, n, int(pose_every))
        pose_pos = np.empty((pose_steps.size, pose_ids.size, 3))
        pose_quat = np.empty((pose_steps.size, pose_ids.size, 4))
    # Hot loop: views bound once, no allocation per step; poses and the divergence check between blocks.
    g_view, s_view, step = mj.opt.gravity, d.sensordata, mujoco.mj_step

    def advance(lo: int, hi: int) -> None:
        if seat_rotation is not None:
            for i in range(lo, hi):
                g_view[:] = gravity[i]
                c_view[:] = ctrl[i]
                f_view[:] = ff[i]
                step(mj, d)
                sens[i] = s_view
        else:
            for i in range(lo, hi):
                g_view[:] = gravity[i]
                step(mj, d)
                sens[i] = s_view

    block = int(pose_every) if pose_every else CHECK_EVERY
    checked = 0
    try:
        for start in range(0, n, block):
            stop = min(n, start + block)
            if pose_every:  # the kinematics of the block's first step's start state, as the sensors
                advance(start, start + 1)
                pose_pos[start // block], pose_quat[start // block] = d.xpos[pose_ids], d.xquat[pose_ids]
                start += 1
            advance(start, stop)
            if stop - checked >= CHECK_EVERY or stop == n:
                checked = stop
                why = _instability(model, d)
                if why:
                    raise _diverged(model, d.time, why)  # d.time: 0 in the settled state, across chunks
    finally:
        mj.opt.gravity[:] = G0
    slices = sensor_slices(model)
    end = evaluate_velocities(model, d)
    sensors = {name: sens[:, sl] for name, sl in slices.items()}
    for p in POINTS:
        lin, ang = slices[f"{p}_framelinvel"], slices[f"{p}_frameangvel"]
        sensors[f"{p}_acc"], sensors[f"{p}_angacc"] = point_accelerations(
            np.vstack([sens[:, lin], end[lin]]), np.vstack([sens[:, ang], end[ang]]), acc, mj.opt.timestep)
    support = {s: sens[:, sl] for s, sl in support_slices(model).items()}
    poses = {"step": pose_steps, "pos": pose_pos, "quat": pose_quat} if pose_every else None
    return RawRun(time_s=np.arange(n) * mj.opt.timestep, sensors=sensors, support_N=support, poses=poses)


# ----------------------------------------------------------------------------------------- linearisation
#: Per point, in output order: absolute acceleration, displacement, rotation, angular acceleration.
OUTPUT_DOFS = ("ax", "ay", "az", "x", "y", "z", "roll", "pitch", "yaw", "roll_acc", "pitch_acc", "yaw_acc")


@dataclass(frozen=True)
class LinearModel:
    """Discrete-time linear model around the settled posture: x+ = A x + B u, y = y0 + C x + D u.

    The state x is MuJoCo's tangent-space state (qpos tangent, qvel, act) relative to the settled state;
    the input u is the seat acceleration (x, y, z) [m/s^2].  The outputs are, per point, ``<point>.<dof>``
    with dof in :data:`OUTPUT_DOFS`: absolute acceleration [m/s^2], displacement [m], rotation (roll, pitch,
    yaw) [rad] and angular acceleration [rad/s^2], the accelerations over the step as in
    :func:`point_accelerations`; then ``support.<group>.f{x,y,z}``, the force of each support group
    (:data:`SUPPORT_GROUPS`) on the body [N]; then ``contact.<name>.fn``, ``.ft1``, ``.ft2``, the normal and
    tangential forces [N] of each contact that touches at rest (contact frame, see :func:`contact_forces`).  ``y0`` holds the outputs in the settled state (the support
    forces carry the body's weight there).  Contacts are linearised as they are at rest: all stuck.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    dt_s: float
    output_names: tuple
    input_names: tuple = ("x", "y", "z")
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
    out += [sum(forces[s] for s in surfaces if s in forces) for surfaces in SUPPORT_GROUPS.values()]
    out.append(contact_forces(model, d, contacts))
    return np.concatenate(out)


def contact_forces(model: Model, d: mujoco.MjData, names) -> np.ndarray:
    """Normal and the two tangential force components [N] (contact frame) of the named contacts now, in that
    order per contact; zeros for a contact that does not touch."""
    out = np.zeros(3 * len(names))
    index = {n: i for i, n in enumerate(names)}
    f6 = np.zeros(6)
    for i in range(d.ncon):
        k = index.get(_contact_name(model, d.contact[i]))
        if k is not None:
            mujoco.mj_contactForce(model.mj, d, i, f6)
            out[3 * k:3 * k + 3] += f6[:3]
    return out


def touching_contacts(model: Model) -> list[str]:
    """Names (contacts.csv) of the contacts that touch in the settled state, with friction (the linear model
    holds them stuck)."""
    d = settled_data(model)
    return sorted({_contact_name(model, d.contact[i]) for i in range(d.ncon) if d.contact[i].dim >= 3})


def linearize(model: Model, eps: float = 1e-6, step_s: float | None = None) -> LinearModel:
    """Linearise the settled model by central finite differences of one time step.

    The state outputs (positions, rotations, velocities, support forces and the forces of the touching
    contacts at a step's start state) are differentiated directly; the accelerations are the velocity change
    over the step plus the seat acceleration, exactly as :func:`run` computes them: with V the velocity rows,
    C_acc = (V A - V) / h and D_acc = V B / h (+ the identity for the seat acceleration).  ``step_s``
    linearises one step of another length h around the same settled state (default: the model's step).
    Costs 2 (n_state + 3) time steps.
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

    def evaluate(dx: np.ndarray, du: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        mujoco.mj_resetData(mj, d)
        qpos = s["qpos"].copy()
        mujoco.mj_integratePos(mj, qpos, dx[:nv], 1.0)
        d.qpos[:] = qpos
        d.qvel[:] = s["qvel"] + dx[nv:2 * nv]
        d.act[:] = s["act"] + dx[2 * nv:]
        d.qacc_warmstart[:] = warm
        mj.opt.gravity[:] = G0 - du
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
        A, B, Cs, Ds, y0 = _differentiate(evaluate, nx, eps)
    finally:
        if h != own_step:
            contact_solver_params(mj, model.body, model.params, own_step)
    return _with_accelerations(A, B, Cs, Ds, y0, h, contacts)


def _differentiate(evaluate, nx: int, eps: float):
    """Central differences of one step: state and output matrices (A, B, C, D) and the outputs y0."""
    _, y0 = evaluate(np.zeros(nx), np.zeros(3))
    ny = y0.size
    A, Cs = np.empty((nx, nx)), np.empty((ny, nx))
    B, Ds = np.empty((nx, 3)), np.empty((ny, 3))
    for i in range(nx):
        e = np.zeros(nx)
        e[i] = eps
        xp, yp = evaluate(e, np.zeros(3))
        xm, ym = evaluate(-e, np.zeros(3))
        A[:, i] = (xp - xm) / (2 * eps)
        Cs[:, i] = (yp - ym) / (2 * eps)
    for k in range(3):
        e = np.zeros(3)
        e[k] = eps * 1e3  # seat acceleration perturbation [m/s^2]
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
        rows_D += [acc_D(lin) + np.eye(3), Ds[disp], Ds[rot], acc_D(ang)]
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
