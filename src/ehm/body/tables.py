"""Body data tables: segments (paper Table 2), joints (paper Table 1) and contact ellipsoids.

The tables are CSV files with the unit in every numeric column name (``mass_kg``, ``com_x_cm``,
``ixx_kgm2``).  :func:`load_body` reads all three, converts every value to SI units and checks
them; any problem raises :class:`~ehm.errors.InputError` naming the file, line, column and value.

Axes: x forward, y left, z up, origin at the pelvis centre of gravity in the reference posture.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from ..errors import InputError, checked, describe

#: Factors from a column's unit suffix to SI, grouped by quantity.
_UNITS: dict[str, dict[str, float]] = {
    "length": {"m": 1.0, "cm": 0.01, "mm": 0.001},
    "mass": {"kg": 1.0, "g": 0.001},
    "inertia": {"kgm2": 1.0},
    "angle": {"rad": 1.0, "deg": math.pi / 180.0},
}

#: Joint names in the order used everywhere (CLI, files, parameters).
JOINT_NAMES = (
    "upper_neck", "lower_neck", "t12", "l4_l5", "waist",
    "hip_r", "hip_l", "knee_r", "knee_l", "ankle_r", "ankle_l",
)

#: Degrees of freedom of each joint type, in the order they are built (slide first, then x, y, z hinges).
JOINT_TYPE_DOFS: dict[str, tuple[str, ...]] = {
    "spherical": ("roll", "pitch", "yaw"),
    "universal": ("roll", "pitch"),
    "spherical_vertical": ("z", "roll", "pitch", "yaw"),
    "revolute": ("pitch",),
}

def rot_y(angle_rad: float) -> np.ndarray:
    """Rotation matrix about y (positive: the front end of x down)."""
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


CONTACT_SURFACES = ("seat_pan", "backrest_lower", "backrest_upper", "floor",
                    "bolster_r", "bolster_l", "back_bolster_r", "back_bolster_l")


@dataclass(frozen=True)
class Segment:
    """One rigid body segment (paper Table 2).

    Attributes
    ----------
    name : str
    mass_kg : float
        Segment mass [kg].
    inertia_kgm2 : numpy.ndarray
        Principal moments of inertia (Ixx, Iyy, Izz) about the centre of gravity, axes parallel to the
        global axes in the reference posture [kg m^2].
    com_m : numpy.ndarray
        Centre of gravity in the reference posture [m].
    shape_m : numpy.ndarray
        Semi-axes of the drawn ellipsoid [m].
    shape_pitch_rad : float
        Rotation of the drawn ellipsoid about y [rad].
    inertia_pitch_rad : float
        Rotation of the principal axes of inertia about y [rad] (0 in the tables; a posture,
        :mod:`ehm.body.posture`, pitches a segment's axes with the segment).
    """

    name: str
    mass_kg: float
    inertia_kgm2: np.ndarray
    com_m: np.ndarray
    shape_m: np.ndarray
    shape_pitch_rad: float
    inertia_pitch_rad: float = 0.0


@dataclass(frozen=True)
class Joint:
    """One joint (paper Table 1).

    Attributes
    ----------
    name : str
    parent, child : str
        Segment names; the child moves relative to the parent.
    type : str
        One of ``spherical``, ``universal``, ``spherical_vertical``, ``revolute``.
    pos_m : numpy.ndarray
        Joint centre in the reference posture [m].
    locked : bool
        Welded by default (the paper's waist).
    axes_pitch_rad : float
        Rotation of the joint's axes about the lateral (y) axis [rad]; positive tips the front of the
        roll axis down (and the top of the yaw axis forward).  0: roll about x, pitch about y, yaw about z.
        A tilted roll axis couples lateral bending with axial rotation, as in the lower cervical spine.
        The pitch axis (y) is unchanged, so the tilt does nothing to a revolute joint; the vertical slide
        of a ``spherical_vertical`` joint stays vertical.
    """

    name: str
    parent: str
    child: str
    type: str
    pos_m: np.ndarray
    locked: bool
    axes_pitch_rad: float = 0.0
    where: str = field(default="", compare=False)  #: File and line it was read from.

    @property
    def dofs(self) -> tuple[str, ...]:
        """Names of this joint's degrees of freedom when unlocked."""
        return JOINT_TYPE_DOFS[self.type]


@dataclass(frozen=True)
class ContactEllipsoid:
    """A contact ellipsoid on the body, pressing on one seat surface.

    Attributes
    ----------
    name, segment, surface : str
    center_m : numpy.ndarray
        Centre in the reference posture [m].
    semi_axes_m : numpy.ndarray
        Semi-axes along the ellipsoid's own x, y, z [m].
    pitch_rad : float
        Rotation of the ellipsoid about y [rad].
    tissue_pad : bool
        Whether the ellipsoid rides on a soft-tissue shear pad.
    """

    name: str
    segment: str
    surface: str
    center_m: np.ndarray
    semi_axes_m: np.ndarray
    pitch_rad: float
    tissue_pad: bool
    where: str = field(default="", compare=False)  #: File and line it was read from.

    def reach_m(self, normal: np.ndarray) -> float:
        """How far the ellipsoid reaches from its centre along the unit vector ``normal`` [m]."""
        local = rot_y(self.pitch_rad).T @ normal
        return float(np.linalg.norm(self.semi_axes_m * local))


@dataclass(frozen=True)
class Body:
    """The three body tables together, checked for consistency."""

    segments: tuple[Segment, ...]
    joints: tuple[Joint, ...]
    contacts: tuple[ContactEllipsoid, ...]

    @property
    def mass_kg(self) -> float:
        """Total body mass [kg]."""
        return float(sum(s.mass_kg for s in self.segments))

    def segment(self, name: str) -> Segment:
        """The segment called ``name``."""
        for s in self.segments:
            if s.name == name:
                return s
        raise InputError(f"unknown segment {name!r}; known segments: {', '.join(s.name for s in self.segments)}.")

    def joint(self, name: str) -> Joint:
        """The joint called ``name``."""
        for j in self.joints:
            if j.name == name:
                return j
        raise InputError(f"unknown joint {name!r}; known joints: {', '.join(j.name for j in self.joints)}.")


class CsvTable:
    """Rows of a CSV table with unit-aware numeric access and precise error messages."""

    def __init__(self, path: Path | str, label: str | None = None):
        self.path = Path(path)
        self.label = label or self.path.name
        try:
            text = self.path.read_text(encoding="utf-8-sig")
        except OSError as exc:
            raise InputError(f"{self.label}: cannot read the file ({exc.strerror or exc}).") from None
        except UnicodeDecodeError:
            raise InputError(f"{self.label}: not a UTF-8 text file.") from None
        lines = [(i + 1, ln) for i, ln in enumerate(text.splitlines())
                 if ln.strip() and not ln.lstrip().startswith("#")]
        if not lines:
            raise InputError(f"{self.label}: the file has no header row.")
        rows = list(csv.reader([ln for _, ln in lines]))
        self.header = [h.strip() for h in rows[0]]
        self.rows = []
        for (lineno, _), fields in zip(lines[1:], rows[1:]):
            if len(fields) != len(self.header):
                raise InputError(
                    f"{self.label}, line {lineno}: {len(fields)} fields where the header has {len(self.header)}."
                )
            self.rows.append((lineno, dict(zip(self.header, (f.strip() for f in fields)))))
        if not self.rows:
            raise InputError(f"{self.label}: the table has a header but no rows.")

    def _column(self, base: str, quantity: str | None) -> tuple[str, float]:
        if quantity is None:
            if base not in self.header:
                raise InputError(f"{self.label}: missing column {base!r}.")
            return base, 1.0
        found = [(h, _UNITS[quantity][h[len(base) + 1:]]) for h in self.header
                 if h.startswith(base + "_") and h[len(base) + 1:] in _UNITS[quantity]]
        if not found:
            others = [h for h in self.header if h.startswith(base + "_")]
            if others:
                raise InputError(
                    f"{self.label}: column {others[0]!r} has an unknown unit; use one of "
                    f"{', '.join(base + '_' + u for u in _UNITS[quantity])}."
                )
            raise InputError(f"{self.label}: missing column {base}_<unit> "
                             f"(e.g. {base}_{next(iter(_UNITS[quantity]))}).")
        if len(found) > 1:
            raise InputError(f"{self.label}: columns {found[0][0]!r} and {found[1][0]!r} give the same quantity twice.")
        return found[0]

    def text(self, lineno: int, row: dict, base: str) -> str:
        col, _ = self._column(base, None)
        value = row[col]
        if not value:
            raise InputError(f"{self.label}, line {lineno}, column {col}: empty value.")
        return value

    def number(self, lineno: int, row: dict, base: str, quantity: str | None,
               positive: bool = False, nonnegative: bool = False) -> float:
        col, factor = self._column(base, quantity)
        raw = row[col]
        try:
            value = float(raw)
        except ValueError:
            raise InputError(f"{self.label}, line {lineno}, column {col}: {raw!r} is not a number.") from None
        if not math.isfinite(value):
            raise InputError(f"{self.label}, line {lineno}, column {col}: {raw!r} is not a finite number.")
        if positive and value <= 0:
            raise InputError(f"{self.label}, line {lineno}, column {col}: {raw} must be positive.")
        if nonnegative and value < 0:
            raise InputError(f"{self.label}, line {lineno}, column {col}: {raw} must not be negative.")
        return value * factor

    def vector(self, lineno: int, row: dict, bases: tuple[str, ...], quantity: str, **kw) -> np.ndarray:
        return np.array([self.number(lineno, row, b, quantity, **kw) for b in bases])

    def choice(self, lineno: int, row: dict, base: str, allowed, what: str) -> str:
        """A text value that must be one of ``allowed``."""
        value = self.text(lineno, row, base)
        if value not in allowed:
            raise InputError(f"{self.label}, line {lineno}, column {base}: unknown {what} {value!r}; "
                             f"use one of {', '.join(allowed)}.")
        return value

    def has(self, base: str) -> bool:
        """Whether the table has a column for this quantity (any unit), for optional columns."""
        return any(h == base or h.startswith(base + "_") for h in self.header)

    def flag(self, lineno: int, row: dict, base: str) -> bool:
        raw = self.text(lineno, row, base).lower()
        if raw in ("1", "true", "yes"):
            return True
        if raw in ("0", "false", "no"):
            return False
        raise InputError(f"{self.label}, line {lineno}, column {base}: {raw!r} is not 0 or 1.")


def _data_path(name: str) -> Path:
    return Path(str(resources.files("ehm") / "data" / name))


def load_segments(path: Path | str | None = None) -> tuple[Segment, ...]:
    """Read a segment table (default: the paper's Table 2).

    Columns: ``name``, ``mass_kg``, ``ixx_kgm2``, ``iyy_kgm2``, ``izz_kgm2``, ``com_{x,y,z}_<m|cm|mm>``,
    ``shape_{a,b,c}_<m|cm|mm>``, ``shape_pitch_<deg|rad>``.
    """
    t = CsvTable(path or _data_path("segments.csv"), label=str(path) if path else None)
    out = []
    for n, r in t.rows:
        inertia = t.vector(n, r, ("ixx", "iyy", "izz"), "inertia", positive=True)
        a, b, c = inertia
        if a + b < c * (1 - 1e-9) or a + c < b * (1 - 1e-9) or b + c < a * (1 - 1e-9):
            raise InputError(
                f"{t.label}, line {n}: moments of inertia {a:g}, {b:g}, {c:g} kg m^2 violate the triangle "
                "inequality (no rigid body has them)."
            )
        out.append(Segment(
            name=t.text(n, r, "name"),
            mass_kg=t.number(n, r, "mass", "mass", positive=True),
            inertia_kgm2=inertia,
            com_m=t.vector(n, r, ("com_x", "com_y", "com_z"), "length"),
            shape_m=t.vector(n, r, ("shape_a", "shape_b", "shape_c"), "length", positive=True),
            shape_pitch_rad=t.number(n, r, "shape_pitch", "angle"),
        ))
    _unique(t.label, [s.name for s in out], "segment")
    return tuple(out)


def load_joints(path: Path | str | None = None) -> tuple[Joint, ...]:
    """Read a joint table (default: the paper's Table 1).

    Columns: ``name``, ``parent``, ``child``, ``type``, ``{x,y,z}_<m|cm|mm>``, ``locked`` (0 or 1), and
    optionally ``axes_pitch_<deg|rad>`` (see :class:`Joint`; 0 when the column is absent).
    """
    t = CsvTable(path or _data_path("joints.csv"), label=str(path) if path else None)
    out = []
    for n, r in t.rows:
        jtype = t.choice(n, r, "type", JOINT_TYPE_DOFS, "joint type")
        tilt = t.number(n, r, "axes_pitch", "angle") if t.has("axes_pitch") else 0.0
        if abs(tilt) >= math.pi / 2:
            col = t._column("axes_pitch", "angle")[0]
            raise InputError(f"{t.label}, line {n}, column {col}: {r[col]} ({math.degrees(tilt):g} deg) must lie "
                             "strictly between -90 and 90 deg.")
        out.append(Joint(
            name=t.text(n, r, "name"), parent=t.text(n, r, "parent"), child=t.text(n, r, "child"), type=jtype,
            pos_m=t.vector(n, r, ("x", "y", "z"), "length"), locked=t.flag(n, r, "locked"),
            axes_pitch_rad=tilt, where=f"{t.label}, line {n}",
        ))
    _unique(t.label, [j.name for j in out], "joint")
    return tuple(out)


def load_contacts(path: Path | str | None = None) -> tuple[ContactEllipsoid, ...]:
    """Read a contact-ellipsoid table (default: the shipped ``contacts.csv``)."""
    t = CsvTable(path or _data_path("contacts.csv"), label=str(path) if path else None)
    out = []
    for n, r in t.rows:
        surface = t.choice(n, r, "surface", CONTACT_SURFACES, "surface")
        out.append(ContactEllipsoid(
            name=t.text(n, r, "name"), segment=t.text(n, r, "segment"), surface=surface,
            center_m=t.vector(n, r, ("x", "y", "z"), "length"),
            semi_axes_m=t.vector(n, r, ("a", "b", "c"), "length", positive=True),
            pitch_rad=t.number(n, r, "pitch", "angle"), tissue_pad=t.flag(n, r, "tissue_pad"),
            where=f"{t.label}, line {n}",
        ))
    _unique(t.label, [c.name for c in out], "contact")
    return tuple(out)


def _unique(label: str, names: list[str], what: str) -> None:
    seen = set()
    for name in names:
        if name in seen:
            raise InputError(f"{label}: {what} {name!r} appears twice.")
        seen.add(name)


@checked
def load_body(segments: Path | str | None = None, joints: Path | str | None = None,
              contacts: Path | str | None = None) -> Body:
    """Read and cross-check the three body tables (defaults: the shipped paper data).

    Checks that the joints form one tree rooted at the pelvis over all segments, and that every contact
    ellipsoid names a known segment.
    """
    segs = load_segments(segments)
    jnts = load_joints(joints)
    cons = load_contacts(contacts)
    names = {s.name for s in segs}
    if "pelvis" not in names:
        raise InputError("the segment table has no 'pelvis' (the root of the body).")
    children = set()
    for j in jnts:
        for column, end in (("parent", j.parent), ("child", j.child)):
            if end not in names:
                raise InputError(f"{j.where}, column {column}: segment {end!r} is not in the segment table.")
        if j.child in children:
            raise InputError(f"{j.where}, column child: segment {j.child!r} is the child of two joints; "
                             "the joints must form a tree.")
        children.add(j.child)
    missing = names - children - {"pelvis"}
    if missing or "pelvis" in children:
        raise InputError(
            "the joints must connect every segment to the pelvis exactly once; "
            f"unconnected: {', '.join(sorted(missing)) or 'pelvis is a child'}."
        )
    reached, frontier = {"pelvis"}, ["pelvis"]
    while frontier:
        parent = frontier.pop()
        for j in jnts:
            if j.parent == parent and j.child not in reached:
                reached.add(j.child)
                frontier.append(j.child)
    if reached != names:
        raise InputError(
            f"segments {', '.join(sorted(names - reached))} are not connected to the pelvis through the joints."
        )
    for c in cons:
        if c.segment not in names:
            raise InputError(f"{c.where}, column segment: segment {c.segment!r} is not in the segment table.")
    return Body(segs, jnts, cons)


def joint_names(value, what: str = "lock") -> tuple[str, ...]:
    """Joints given as one name (``"t12"``), a list of names or None, as a tuple of names (a single name is never
    split into letters); anything else is refused in one sentence naming the argument ``what``."""
    if value is None:
        return ()
    if isinstance(value, str):
        return (value,)
    try:
        names = tuple(value)
    except TypeError:
        names = None
    if names is None or not all(isinstance(n, str) for n in names):
        raise InputError(f"{what} must be a joint name or a list of joint names, e.g. ['t12', 'lower_neck'], "
                         f"not {describe(value)}.")
    return names


def resolve_locks(body: Body, lock=(), unlock=()) -> frozenset:
    """The complete set of locked joints: the table's defaults (the waist), plus ``lock``, minus ``unlock`` (each
    a joint name or a list of names: :func:`joint_names`)."""
    lock, unlock = joint_names(lock, "lock"), joint_names(unlock, "unlock")
    names = [j.name for j in body.joints]
    for name in list(lock) + list(unlock):
        if name not in names:
            raise InputError(f"unknown joint {name!r}; joints are {', '.join(names)}.")
    both = set(lock) & set(unlock)
    if both:
        raise InputError(f"joint {sorted(both)[0]!r} is asked to be both locked and unlocked.")
    return frozenset(({j.name for j in body.joints if j.locked} | set(lock)) - set(unlock))
