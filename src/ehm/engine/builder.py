"""Model building: :func:`build` compiles the seated human on its seat in named steps (solver options, seat
surfaces static or rotating, segments with their joints, mass and contact pads, contact pairs, actuators of the
posture and seat control, sensors) and returns the :class:`~ehm.engine.model.Model`."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from ..body.params import Parameters
from ..body.tables import Body
from ..errors import InputError
from . import control as _control
from .diagnostics import build_error, captured_warnings
from .inertia import PAD_INERTIA_KGM2, pad_masses, segment_mass_properties
from .laws import contact_solver_params, split_damping
from .model import G0, POINT_JOINTS, POINTS, Model
from .seat_geometry import (
    SEAT_BANDWIDTH_HZ,
    SEAT_DOFS,
    SEAT_INERTIA_KGM2,
    SeatGeometry,
    check_seat,
    quat_pitch,
    quat_z_to,
    seated_body,
)
from .sensors import REDUCE_NETFORCE, SENSOR_KINDS

#: Half sizes [m] of the static seat surfaces as drawn (planes: the contact is with the infinite plane).
_PLANE_SIZE = {"seat_pan": [0.25, 0.25, 0.05], "floor": [0.5, 0.4, 0.1],
               "backrest_lower": [0.08, 0.18, 0.05], "backrest_upper": [0.10, 0.20, 0.05],
               "bolster_r": [0.15, 0.04, 0.05], "bolster_l": [0.15, 0.04, 0.05],
               "back_bolster_r": [0.12, 0.04, 0.05], "back_bolster_l": [0.12, 0.04, 0.05]}


def build(body: Body, params: Parameters, locked: frozenset | set = frozenset(), rotating_seat: bool = False) -> Model:
    """Compile the seated human.

    Parameters
    ----------
    body : Body
        Segments, joints and contact ellipsoids in the tables' reference posture; the model is built in the
        parameters' posture and with their back support (:func:`~ehm.engine.seat_geometry.seated_body`), and its
        ``body`` is that one.
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
    locked = _checked_locked(body, locked)
    reference, body = body, seated_body(body, params)  # the parameters' posture and back support
    seat = SeatGeometry.from_params(params, body, reference)
    check_seat(seat, params, body)

    spec = _new_spec(params.section("simulation"))
    origin = _add_seat_surfaces(spec, seat, rotating_seat)
    tree = _SegmentTree(body, params, locked, seat)
    tree.add(spec.worldbody, "pelvis", np.zeros(3), np.zeros(3))
    _add_pairs(spec, body, params)
    _add_actuators(spec, rotating_seat, tree.actuated)
    _add_sensors(spec, seat)
    head_control = _control.HeadControl.from_params(params, float(params.value("simulation.dt_s")))
    _control.add_to_spec(spec, head_control)
    mj = _compile(spec)
    contact_solver_params(mj, body, params, mj.opt.timestep)
    model = _model(mj, body, params, locked, tree, seat, origin if rotating_seat else None)
    model.head_control = _head_control(model, head_control)
    return model


def _head_control(model: Model, control):
    """The head-in-space control with the compiled model's addresses (None when off)."""
    if control is None:
        return None
    mj = model.mj
    adr = {k: int(mj.sensor_adr[mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_SENSOR, f"head_{k}")])
           for k in ("framequat", "frameangvel")}
    return _control.compiled(mj, control, model.segment_bodies["head"][0], model.segment_bodies["upper_torso"][0],
                             adr["framequat"], adr["frameangvel"])


def _checked_locked(body: Body, locked) -> frozenset:
    """The joints to weld, each one the body has (InputError naming an unknown one)."""
    known = {j.name for j in body.joints}
    for name in locked:
        if name not in known:
            raise InputError(f"unknown joint {name!r}; joints are {', '.join(j.name for j in body.joints)}.")
    return frozenset(locked)


def _new_spec(sim: dict) -> mujoco.MjSpec:
    """An empty model with the integrator, friction cone and solver options of ``simulation``."""
    spec = mujoco.MjSpec()
    spec.modelname = "ehm_seated_human"
    spec.compiler.degree = False
    opt = spec.option
    opt.timestep = float(sim["dt_s"])
    opt.gravity = G0
    # Euler with implicit joint damping: with half the damping explicit (split_damping) the damping is
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
    return spec


def _add_seat_surfaces(spec: mujoco.MjSpec, seat: SeatGeometry, rotating_seat: bool) -> np.ndarray:
    """One body per seat surface, so that its contact force can be read by body: static planes, or thin boxes on
    a heavy seat frame with yaw, pitch and roll hinges about the seat pan's reference point.  Returns the pivot
    (zero for a static seat)."""
    parent, origin = spec.worldbody, np.zeros(3)
    if rotating_seat:
        origin = seat.planes["seat_pan"][0]
        parent = spec.worldbody.add_body(name="seat_frame", pos=origin)
        parent.explicitinertial = True
        parent.mass = SEAT_INERTIA_KGM2
        parent.inertia = [SEAT_INERTIA_KGM2] * 3
        for dof, axis in zip(SEAT_DOFS, ([0, 0, 1], [0, 1, 0], [1, 0, 0])):
            parent.add_joint(name=f"seat.{dof}", type=mujoco.mjtJoint.mjJNT_HINGE, axis=axis)
    for surface, (point, normal) in seat.planes.items():
        sb = parent.add_body(name=surface, pos=point - origin, quat=quat_z_to(normal))
        if rotating_seat:  # a box whose top face is the surface, large enough never to be run off
            half = [1.0, 1.0, 0.05]
            sb.add_geom(name=surface, type=mujoco.mjtGeom.mjGEOM_BOX, size=half, pos=[0, 0, -half[2]],
                        contype=0, conaffinity=0, group=3, rgba=[0.55, 0.55, 0.6, 0.3])
        else:
            sb.add_geom(name=surface, type=mujoco.mjtGeom.mjGEOM_PLANE, size=_PLANE_SIZE[surface],
                        contype=0, conaffinity=0, rgba=[0.55, 0.55, 0.6, 1.0])
    return origin


class _SegmentTree:
    """Adds the segments from the pelvis outward: per segment its body, the degrees of freedom of the joint to its
    parent (springs and dampers; the integral actuators to add are collected), its own mass properties, its drawn
    shape and output site, and its contact ellipsoids, on soft-tissue pads where the contact has one."""

    def __init__(self, body: Body, params: Parameters, locked: frozenset, seat: SeatGeometry):
        self.body, self.params, self.locked, self.seat = body, params, locked, seat
        # Pads take their mass from their segment: keep each segment's total mass, centre of gravity and
        # inertia exactly as in the table.
        self.pads = {s.name: [c for c in body.contacts if c.segment == s.name and c.tissue_pad] for s in body.segments}
        self.pad_mass = pad_masses(body, params)
        self.pad_armature = float(params.section("simulation")["pad_armature_kg"])
        self.children: dict[str, list] = {}
        for j in body.joints:
            self.children.setdefault(j.parent, []).append(j)
        posture = params.section("posture")
        self.integral_joints = params.integral_joints()
        self.ti = float(posture["integral_time_s"])
        self.dof_names: list[str] = ["pelvis.x", "pelvis.y", "pelvis.z", "pelvis.roll", "pelvis.pitch", "pelvis.yaw"]
        self.segment_bodies: dict[str, list] = {}  #: segment -> names of its body and its pad bodies
        self.actuated: list[tuple[str, float]] = []  #: (joint dof, integral gain ki) of the posture control

    def add(self, parent_body, seg_name: str, frame_pos: np.ndarray, parent_frame: np.ndarray, joint=None) -> None:
        """Add segment ``seg_name`` with its frame at ``frame_pos`` (reference posture) under ``parent_body``, then
        its children."""
        seg = self.body.segment(seg_name)
        b = parent_body.add_body(name=seg_name, pos=frame_pos - parent_frame)
        if joint is None:
            b.add_freejoint(name="pelvis")
        elif joint.name not in self.locked:
            self._add_joint(b, joint)
        m_body, c_body, inertia = segment_mass_properties(seg, self.pads[seg_name], self.pad_mass)
        b.explicitinertial = True
        b.mass = m_body
        b.ipos = c_body - frame_pos
        b.fullinertia = [inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2], inertia[1, 2]]
        b.add_geom(name=f"{seg_name}_shape", type=mujoco.mjtGeom.mjGEOM_ELLIPSOID, size=seg.shape_m,
                   pos=seg.com_m - frame_pos, quat=quat_pitch(seg.shape_pitch_rad), contype=0, conaffinity=0,
                   group=1, rgba=[0.85, 0.65, 0.5, 0.5])
        self.segment_bodies.setdefault(seg_name, []).append(seg_name)
        for point in (p for p, s in POINTS.items() if s == seg_name):
            b.add_site(name=point, pos=self._point_position(point, seg) - frame_pos, size=[0.01, 0, 0])
        for c in self.body.contacts:
            if c.segment == seg_name:
                self._add_contact(b, c, frame_pos)
        for j in self.children.get(seg_name, []):
            self.add(b, j.child, j.pos_m, frame_pos, j)

    def _point_position(self, point: str, seg) -> np.ndarray:
        """Where output ``point`` sits (reference frame of the built posture): the centre of its joint
        (:data:`~ehm.engine.model.POINT_JOINTS`), else its segment's centre of gravity."""
        if point in POINT_JOINTS:
            return np.asarray(self.body.joint(POINT_JOINTS[point]).pos_m, dtype=float)
        return seg.com_m

    def _add_joint(self, b, joint) -> None:
        """The joint's degrees of freedom on body ``b``, each with its spring and damper."""
        # Joint axes pitched about y by the joint's axes_pitch_rad (x -> front down, z -> top forward).
        cp, sp = math.cos(joint.axes_pitch_rad), math.sin(joint.axes_pitch_rad)
        joint_axes = {"roll": [cp, 0.0, -sp], "pitch": [0.0, 1.0, 0.0], "yaw": [sp, 0.0, cp]}
        for dof in joint.dofs:
            k, c = self.params.joint_dof(joint.name, dof)
            jn = f"{joint.name}.{dof}"
            if dof == "z":
                b.add_joint(name=jn, type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0, 0, 1], stiffness=k, damping=c)
            else:
                b.add_joint(name=jn, type=mujoco.mjtJoint.mjJNT_HINGE, axis=joint_axes[dof], stiffness=k, damping=c)
            self.dof_names.append(jn)
            if joint.name in self.integral_joints and k > 0:
                self.actuated.append((jn, k / self.ti))

    def _add_contact(self, b, c, frame_pos: np.ndarray) -> None:
        """Contact ellipsoid ``c`` on segment body ``b``, on its own soft-tissue pad if it has one."""
        holder = b
        if c.tissue_pad:
            holder = self._add_pad(b, c, frame_pos)
            gpos = np.zeros(3)
        else:
            gpos = c.center_m - frame_pos
        holder.add_geom(name=c.name, type=mujoco.mjtGeom.mjGEOM_ELLIPSOID, size=c.semi_axes_m, pos=gpos,
                        quat=quat_pitch(c.pitch_rad), contype=0, conaffinity=0, group=2,
                        rgba=[0.3, 0.5, 0.8, 0.4])

    def _add_pad(self, b, c, frame_pos: np.ndarray):
        """A soft-tissue pad body for contact ``c``: a near point mass on two tangential slide springs."""
        pad = b.add_body(name=f"pad_{c.name}", pos=c.center_m - frame_pos)
        pad.explicitinertial = True
        pad.mass = self.pad_mass[c.name]
        pad.ipos = [0.0, 0.0, 0.0]
        pad.iquat = [1.0, 0.0, 0.0, 0.0]
        pad.inertia = [PAD_INERTIA_KGM2, PAD_INERTIA_KGM2, PAD_INERTIA_KGM2]
        ks = float(self.params.value(f"contacts.{c.name}.shear_stiffness_N_per_m"))
        cs = float(self.params.value(f"contacts.{c.name}.shear_damping_Ns_per_m"))
        for i, t in enumerate(self.seat.tangents(c.surface)):
            pad.add_joint(name=f"pad_{c.name}.t{i + 1}", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=t,
                          stiffness=ks, damping=cs, armature=self.pad_armature)
        self.segment_bodies[c.segment].append(f"pad_{c.name}")
        return pad


def _add_pairs(spec: mujoco.MjSpec, body: Body, params: Parameters) -> None:
    """One contact pair per contact, with placeholder solref: the linear spring needs the compiled inverse
    weights (:func:`~ehm.engine.laws.contact_solver_params` sets them after compiling)."""
    d_imp = float(params.section("simulation")["contact_impedance"])
    for c in body.contacts:
        mu = float(params.value(f"contacts.{c.name}.friction"))
        spec.add_pair(name=c.name, geomname1=c.surface, geomname2=c.name, condim=3 if mu > 0 else 1,
                      friction=[mu, mu, 0.005, 1e-4, 1e-4], solimp=[d_imp, d_imp, 0.001, 0.5, 2.0])


def _add_actuators(spec: mujoco.MjSpec, rotating_seat: bool, actuated: list) -> None:
    """The rotating seat's tracking PD (position and velocity set-points, two controls each), the integral part
    of the posture control, and the explicit half of the trapezoidal damping, in that order."""
    if rotating_seat:
        wn = 2 * math.pi * SEAT_BANDWIDTH_HZ
        for dof in SEAT_DOFS:
            a = spec.add_actuator(name=f"seat_{dof}", target=f"seat.{dof}", trntype=mujoco.mjtTrn.mjTRN_JOINT)
            a.set_to_pid(kp=SEAT_INERTIA_KGM2 * wn ** 2, kv=2 * SEAT_INERTIA_KGM2 * wn)
    for jn, ki in actuated:
        a = spec.add_actuator(name=f"integral_{jn}", target=jn, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        a.set_to_pid(kp=0.0, kv=0.0, ki=ki)
    split_damping(spec)


def _add_sensors(spec: mujoco.MjSpec, seat: SeatGeometry) -> None:
    """Per output point its frame sensors (:data:`~ehm.engine.sensors.SENSOR_KINDS`), then per seat surface the
    net contact force on the body, world axes."""
    for point in POINTS:
        for kind in SENSOR_KINDS:
            spec.add_sensor(name=f"{point}_{kind}", type=getattr(mujoco.mjtSensor, f"mjSENS_{kind.upper()}"),
                            objtype=mujoco.mjtObj.mjOBJ_SITE, objname=point)
    for surface in seat.planes:
        spec.add_sensor(name=f"support_{surface}", type=mujoco.mjtSensor.mjSENS_CONTACT,
                        objtype=mujoco.mjtObj.mjOBJ_BODY, objname=surface,
                        intprm=[1 << int(mujoco.mjtConDataField.mjCONDATA_FORCE), REDUCE_NETFORCE, 1])


def _compile(spec: mujoco.MjSpec) -> mujoco.MjModel:
    """The compiled model, or MuJoCo's refusal as one InputError sentence."""
    try:
        with captured_warnings():
            return spec.compile()
    except ValueError as exc:
        raise build_error(exc) from None


def _model(mj: mujoco.MjModel, body: Body, params: Parameters, locked: frozenset, tree: _SegmentTree,
           seat: SeatGeometry, pivot: np.ndarray | None) -> Model:
    """The :class:`Model` record: the compiled model with the ids and addresses of what users address."""
    def obj(kind, name):
        return mujoco.mj_name2id(mj, kind, name)

    seat_info = None
    if pivot is not None:  # rotating seat
        joints = [obj(mujoco.mjtObj.mjOBJ_JOINT, f"seat.{d}") for d in SEAT_DOFS]
        seat_info = {"body": obj(mujoco.mjtObj.mjOBJ_BODY, "seat_frame"),
                     "dofs": [int(mj.jnt_dofadr[j]) for j in joints], "qpos": [int(mj.jnt_qposadr[j]) for j in joints],
                     "ctrl": [int(mj.actuator_ctrladr[obj(mujoco.mjtObj.mjOBJ_ACTUATOR, f"seat_{d}")])
                              for d in SEAT_DOFS],
                     "pivot": pivot.copy()}
    point_sites = {p: obj(mujoco.mjtObj.mjOBJ_SITE, p) for p in POINTS}
    surface_bodies = {s: obj(mujoco.mjtObj.mjOBJ_BODY, s) for s in seat.planes}
    seg_ids = {s: [obj(mujoco.mjtObj.mjOBJ_BODY, n) for n in names] for s, names in tree.segment_bodies.items()}
    return Model(mj=mj, body=body, params=params, locked=locked, dof_names=tree.dof_names,
                 point_sites=point_sites, surface_bodies=surface_bodies, segment_bodies=seg_ids, seat=seat_info,
                 pelvis_qpos=int(mj.jnt_qposadr[obj(mujoco.mjtObj.mjOBJ_JOINT, "pelvis")]))
