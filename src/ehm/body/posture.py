"""Named postures of the seated person: the reference posture that the joints' zero (the PID references) is.

A posture is a set of sagittal angles relative to the body tables' reference posture (the paper's erect
sitting, ``data/segments.csv``, ``joints.csv``, ``contacts.csv``): the pelvis's tilt (positive forward, i.e.
anterior; a slouched person's pelvis tilts backwards), the flexion of the waist and the L4/L5 joint (lumbar),
of T12 (thoracic), of the lower and upper neck (positive: forward flexion), and how far the pelvis slides
forward along the seat pan.  The legs follow: the thighs keep their orientation on the pan (the hips take the
pelvis's tilt), knees and ankles keep their angles.

:func:`pose_body` turns the tables into that posture by forward kinematics about the joints (positions of
segments, joints and contact ellipsoids; inertia, drawn shapes, contact ellipsoids and joint axes pitched with
their segment), with the pelvis rolling on its ischial tuberosities (the buttock contacts) and then put back
onto the seat pan as deep as before.  No MuJoCo here: the engine's builder reads the posed tables.

The postures themselves are entries of the parameter file (``[postures.NAME]``, :data:`POSTURE_KEYS`), the one
in use is ``posture.name``.  A posture may also carry its own converged time step (``STEP_KEY``; the shipped
``slouched`` one does), which the person then runs at unless a step is given (:meth:`ehm.Parameters.time_step`).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..errors import InputError
from .tables import Body, rot_y

#: Keys of a posture in the parameter file ([postures.NAME]), with what each one turns.
POSTURE_KEYS = {
    "pelvis_tilt_deg": "pelvis",  # about the ischial tuberosities; positive anterior (forward)
    "waist_deg": "waist",  # flexion of the waist joint (pelvis - lower torso)
    "l4_l5_deg": "l4_l5",  # flexion of L4/L5 (lower - middle torso)
    "t12_deg": "t12",  # flexion of T12 (middle - upper torso)
    "lower_neck_deg": "lower_neck",  # flexion of the lower neck
    "upper_neck_deg": "upper_neck",  # flexion of the upper neck (head on neck)
    "seat_slide_m": "seat",  # how far the pelvis sits further forward along the seat pan [m]
}
#: The optional key of a posture's own converged time step [s] (the largest step at which ``ehm check-step`` holds
#: its 2 % for that posture), when it is finer than ``simulation.dt_s``.
STEP_KEY = "dt_s"
#: The optional key of a posture's trunk muscle tone: the factor on the stiffness and damping of the joints of
#: ``posture.tone_joints`` in that posture (1 when it is not given; see :meth:`ehm.Parameters.tone`).
TONE_KEY = "tone"
#: Keys of a posture that are not angles.
OPTIONAL_KEYS = (STEP_KEY, TONE_KEY)
#: The range a muscle tone factor may take.
TONE_RANGE = (0.1, 10.0)
DEFAULT_POSTURE = "erect"  #: The tables' own posture (the paper's).
#: Largest angle [deg] a posture may turn one joint (or the pelvis) from the tables' reference posture.
MAX_ANGLE_DEG = 45.0
#: Largest slide along the pan [m].
MAX_SLIDE_M = 0.15


def check_posture(name: str, values: dict, where: str) -> None:
    """One sentence if a posture's entries are not :data:`POSTURE_KEYS` with plausible values (``where``: the file);
    the optional ``STEP_KEY`` is checked as a time step by the parameter file's checks."""
    for key in POSTURE_KEYS:
        if key not in values:
            raise InputError(f"{where}: posture {name!r} needs {key!r} in [postures.{name}].")
    for key, value in values.items():
        if key == STEP_KEY:
            continue
        if key == TONE_KEY:
            if not TONE_RANGE[0] <= value <= TONE_RANGE[1]:
                raise InputError(f"{where}: postures.{name}.{key} = {value:g} is not a plausible muscle tone factor: "
                                 f"give one from {TONE_RANGE[0]:g} to {TONE_RANGE[1]:g} (1: as the joints' values).")
            continue
        if key not in POSTURE_KEYS:
            raise InputError(f"{where}: unknown key {key!r} in [postures.{name}]; a posture has "
                             f"{', '.join(POSTURE_KEYS)} and optionally {STEP_KEY!r} (its converged time step) and "
                             f"{TONE_KEY!r} (its trunk muscle tone).")
        limit = MAX_SLIDE_M if key.endswith("_m") else MAX_ANGLE_DEG
        if not abs(value) <= limit:
            unit = "m" if key.endswith("_m") else "deg"
            raise InputError(f"{where}: postures.{name}.{key} = {value:g} {unit} is beyond the {limit:g} {unit} a "
                             "posture may turn or move the body from the tables' reference posture.")


def is_reference(angles: dict) -> bool:
    """Whether a posture is the tables' own (every angle and the slide zero)."""
    return all(float(v) == 0.0 for v in angles.values())


def joint_angles(angles: dict, body: Body, thigh_rad: float = 0.0) -> dict:
    """Each joint's sagittal angle [rad] in the posture, and the pelvis's tilt under key ``"pelvis"``: the
    posture's own joints, the hips taking the pelvis's tilt back (the thighs keep their orientation but for
    ``thigh_rad``, which the knees take back: the lower legs keep theirs), the rest zero."""
    tilt = math.radians(angles["pelvis_tilt_deg"])
    out = {"pelvis": tilt}
    for j in body.joints:
        key = f"{j.name}_deg"
        if key in angles:
            out[j.name] = math.radians(angles[key])
        elif j.parent == "pelvis" and j.child.startswith("thigh"):
            out[j.name] = thigh_rad - tilt
        elif j.parent.startswith("thigh"):
            out[j.name] = -thigh_rad
        else:
            out[j.name] = 0.0
    return out


def pose_body(body: Body, angles: dict, pan_height_m: float, pan_angle_deg: float) -> Body:
    """The body tables turned into the posture ``angles`` (a ``[postures.NAME]`` table's values), sitting on the
    seat pan (height and angle in body axes of the reference posture, ``[seat]``): the pelvis's seat-pan contacts
    as deep in the pan as in the tables, and the thighs pitched so that theirs are too (the pelvis's roll lifts
    or lowers the hips).  The tables unchanged for the reference posture (``is_reference``)."""
    if is_reference(angles):
        return body
    pan = (pan_height_m, pan_angle_deg)
    thigh, step = 0.0, 1.0
    for _ in range(40):  # the thighs' pitch that keeps their contacts' depth (each pass shrinks the step ~5 times)
        posed = _posed_at(body, angles, thigh, pan)
        if abs(step) < 1e-9:
            break
        step = _thigh_correction(body, posed, pan)
        thigh += step
    return posed


def _posed_at(body: Body, angles: dict, thigh_rad: float, pan: tuple) -> Body:
    """The posture with the thighs pitched by ``thigh_rad``, put onto the pan."""
    q = joint_angles(angles, body, thigh_rad)
    pitch = {"pelvis": q["pelvis"]}
    move = {}  # segment -> (rotation, point in reference, point posed): x -> R (x - p) + p'
    pivot = _ischia(body)
    move["pelvis"] = (rot_y(q["pelvis"]), pivot, pivot)
    order = ["pelvis"]
    for seg in order:  # breadth first from the pelvis: every parent posed before its children
        for j in body.joints:
            if j.parent == seg:
                pitch[j.child] = pitch[seg] + q[j.name]
                move[j.child] = (rot_y(pitch[j.child]), j.pos_m, _apply(move[seg], j.pos_m))
                order.append(j.child)
    posed = _posed_tables(body, move, pitch)
    return _shifted(posed, _onto_pan(body, posed, angles["seat_slide_m"], *pan))


def _pan(pan_height_m: float, pan_angle_deg: float):
    """The seat pan's point, unit normal and forward tangent."""
    a = math.radians(pan_angle_deg)
    return (np.array([0.0, 0.0, pan_height_m]), np.array([-math.sin(a), 0.0, math.cos(a)]),
            np.array([math.cos(a), 0.0, math.sin(a)]))


def _depth(contacts, point: np.ndarray, normal: np.ndarray) -> float:
    """Mean depth [m] of ``contacts`` in the plane (point, normal)."""
    if not contacts:
        return 0.0
    return float(np.mean([c.reach_m(normal) - np.dot(c.center_m - point, normal) for c in contacts]))


def _thigh_correction(body: Body, posed: Body, pan: tuple) -> float:
    """The further thigh pitch [rad] (front down positive) that brings the posed thighs' seat-pan contacts as deep
    into the pan as the tables' ones: their lost depth over their lever from the hips along the pan."""
    point, normal, forward = _pan(*pan)

    def thighs(b: Body):
        return [c for c in b.contacts if c.segment.startswith("thigh") and c.surface == "seat_pan"]

    if not thighs(body):
        return 0.0
    hips = [j.pos_m for j in posed.joints if j.parent == "pelvis" and j.child.startswith("thigh")]
    lever = float(np.dot(np.mean([c.center_m for c in thighs(posed)], axis=0) - np.mean(hips, axis=0), forward))
    return math.atan2(_depth(thighs(body), point, normal) - _depth(thighs(posed), point, normal), lever)


def _apply(move, x: np.ndarray) -> np.ndarray:
    rot, p, p_new = move
    return rot @ (np.asarray(x) - p) + p_new


def _ischia(body: Body) -> np.ndarray:
    """Where the pelvis rolls: the mean of its seat-pan contacts' centres (the ischial tuberosities), or its
    centre of gravity if it has none."""
    centres = [c.center_m for c in body.contacts if c.segment == "pelvis" and c.surface == "seat_pan"]
    return np.mean(centres, axis=0) if centres else body.segment("pelvis").com_m.copy()


def _posed_tables(body: Body, move: dict, pitch: dict) -> Body:
    """Segments, joints and contacts moved by their segment's motion and pitched with it."""
    segments = tuple(replace(s, com_m=_apply(move[s.name], s.com_m),
                             inertia_pitch_rad=s.inertia_pitch_rad + pitch[s.name],
                             shape_pitch_rad=s.shape_pitch_rad + pitch[s.name]) for s in body.segments)
    joints = tuple(replace(j, pos_m=_apply(move[j.parent], j.pos_m), axes_pitch_rad=j.axes_pitch_rad + pitch[j.child])
                   for j in body.joints)
    contacts = tuple(replace(c, center_m=_apply(move[c.segment], c.center_m), pitch_rad=c.pitch_rad + pitch[c.segment])
                     for c in body.contacts)
    return Body(segments, joints, contacts)


def _onto_pan(body: Body, posed: Body, slide_m: float, pan_height_m: float, pan_angle_deg: float) -> np.ndarray:
    """The shift that puts the posed pelvis's seat-pan contacts as deep into the pan as the reference ones (on
    average along the pan's normal), plus the slide forward along the pan."""
    point, normal, forward = _pan(pan_height_m, pan_angle_deg)

    def depth(b: Body) -> float:
        return _depth([c for c in b.contacts if c.segment == "pelvis" and c.surface == "seat_pan"], point, normal)

    return (depth(posed) - depth(body)) * normal + slide_m * forward


def _shifted(body: Body, shift: np.ndarray) -> Body:
    return Body(tuple(replace(s, com_m=s.com_m + shift) for s in body.segments),
                tuple(replace(j, pos_m=j.pos_m + shift) for j in body.joints),
                tuple(replace(c, center_m=c.center_m + shift) for c in body.contacts))
