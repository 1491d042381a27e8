"""Individual body sizes: scale the reference person (paper Tables 1 and 2) to a stature, mass and
sitting height.

Rules (each documented with its source; the reference person is its own fixed point):

* Reference size: the paper's model matches the MADYMO active human model's 50th percentile male,
  standing height 1.76 m and sitting height 0.92 m (paper section 1), with the EHM's own mass
  70.882 kg (Table 2).
* Lengths: heights (z) of the trunk, neck and head (everything above the hips) scale with the
  sitting-height ratio; thighs, lower legs and feet, which extend forward and down when seated, scale
  with the leg-length ratio (stature minus sitting height) in x and z; without a sitting height both
  follow the stature ratio (geometric similarity).  Widths (y) and the upper body's depth (x) scale with
  sqrt(mass ratio / stature ratio), which keeps the body's density: volume ~ width * depth * height ~ mass.
* Masses scale with the body-mass ratio (constant segment mass fractions, as in anthropometric tables
  such as Dempster's); moments of inertia as those of the segment's mass stretched by its length factors:
  the second moments of mass along each principal axis, C_x = (I_yy + I_zz - I_xx) / 2 and so on, scale
  with the mass ratio times the square of that axis's length factor, and I_xx = C_y + C_z again.  (A
  stretched rigid body stays a rigid body; the table's foot, whose I_yy equals I_xx + I_zz, keeps a
  millionth of its trace as C_y so that it stays just inside that bound instead of crossing it.)
* Stiffness and damping: the dimensionless scaling of Hof (1996, "Scaling gait data to body size",
  Gait & Posture 4: 222-223), with body mass m, length L and gravity g as base units: rotational
  stiffness ~ m g L, rotational damping ~ m L sqrt(g L), translational (and contact) stiffness ~ m g / L,
  translational damping ~ m sqrt(g / L); L is the stature (or sitting-height) ratio of the segment's
  region.  This keeps every natural frequency proportional to sqrt(g / L), so a scaled person has the
  same dimensionless dynamics (grade: literature for the rule, assumed for its use in seated vibration).
* The seat is adjusted to the person: its geometry, given in body coordinates, scales like the body,
  so the seat pan, backrest pads and floor meet the scaled body as they meet the reference person.

Range: stature 1.2 to 2.2 m, mass 30 to 200 kg, sitting height 0.4 to 0.6 of stature, and a body mass index
(mass / stature^2) of 13 to 50 kg/m^2, with a warning outside 16 to 40.  The rules carry one person's build (the
reference's body mass index is 22.9, his segment mass fractions and density) to other sizes.  The World Health
Organization's classes of body mass index (WHO Technical Report Series 854, 1995, and 894, 2000) mark where that
becomes doubtful: below 16 is severe thinness and from 40 obesity class III, where the mass is distributed over
the segments differently from constant mass fractions and one width factor; such a person is built, with a
warning that says so.  Beyond 13 and 50 (grade: assumed, the ehm authors' limit) the build stands for no person
(a 2.2 m, 30 kg person, index 6.2, would be 58 % of the reference's width) and is refused.  Tested: a
5th-percentile woman (1.52 m, 50 kg, index 21.6) and a 95th-percentile man (1.87 m, 98 kg, index 28.0) carry
their weight within 1 % and move their vertical trunk mode as the rules predict.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np

from ..body.params import Parameters
from ..body.tables import Body
from ..errors import EhmWarning, InputError, checked_class, describe, warn

REFERENCE_STATURE_M = 1.76  #: Paper section 1: the AHM's standing height, matched by the EHM.
REFERENCE_SITTING_HEIGHT_M = 0.92  #: Paper section 1: the AHM's sitting height.
REFERENCE_MASS_KG = 70.882  #: Paper Table 2: the EHM's total mass.
LEG_SEGMENTS = ("thigh", "leg", "foot")  #: Segment name prefixes scaled with leg length.
LEG_JOINTS = ("hip", "knee", "ankle")
STATURE_RANGE_M = (1.2, 2.2)  #: Standing heights the person can be scaled to [m].
MASS_RANGE_KG = (30.0, 200.0)  #: Body masses the person can be scaled to [kg].
#: Body mass indices (mass / stature^2) a person can be scaled to [kg/m^2] (grade: assumed; the module docstring).
BMI_RANGE_KG_M2 = (13.0, 50.0)
#: Body mass indices the scaling stands for without a warning [kg/m^2]: WHO, from the limit of severe thinness (16)
#: to that of obesity class III (40); see the module docstring.
BMI_WHO_RANGE_KG_M2 = (16.0, 40.0)


def mass_range_kg(stature_m: float) -> tuple[float, float]:
    """The body masses [kg] a person of ``stature_m`` can be scaled to (mass range and body mass index range)."""
    lo = max(MASS_RANGE_KG[0], BMI_RANGE_KG_M2[0] * stature_m ** 2)
    hi = min(MASS_RANGE_KG[1], BMI_RANGE_KG_M2[1] * stature_m ** 2)
    return lo, hi


def _check(name: str, value, low: float, high: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, not {value!r}.") from None
    if not (math.isfinite(v) and low <= v <= high):
        raise InputError(f"{name} = {value!r} lies outside the range this model can be scaled to ({low:g}-{high:g}).")
    return v


def _check_build(stature_m: float, mass_kg: float) -> None:
    """One sentence when mass and stature make a body mass index outside :data:`BMI_RANGE_KG_M2`, a warning when
    it lies outside :data:`BMI_WHO_RANGE_KG_M2`."""
    bmi = mass_kg / stature_m ** 2
    lo, hi = BMI_RANGE_KG_M2
    if not lo <= bmi <= hi:
        m_lo, m_hi = mass_range_kg(stature_m)  # never empty within the stature range
        raise InputError(f"a person of {stature_m:g} m and {mass_kg:g} kg has a body mass index of {bmi:.1f} kg/m^2, "
                         f"outside the {lo:g}-{hi:g} kg/m^2 the scaling can build (it keeps the reference person's "
                         f"segment mass fractions and density): at {stature_m:g} m choose a mass from {m_lo:.1f} to "
                         f"{m_hi:.1f} kg.")
    lo, hi = BMI_WHO_RANGE_KG_M2
    if not lo <= bmi <= hi:
        warn(f"a person of {stature_m:g} m and {mass_kg:g} kg has a body mass index of {bmi:.1f} kg/m^2, "
             f"{'below' if bmi < lo else 'above'} the {lo:g}-{hi:g} kg/m^2 the scaling stands for (WHO: "
             f"{'severe thinness' if bmi < lo else 'obesity class III'}): the person is built with the "
             "reference's segment mass fractions and density, which such a body does not have.",
             EhmWarning, stacklevel=3)


@checked_class
class BodySize:
    """Scale factors from the reference person to a person of the given size.

    Parameters
    ----------
    stature_m : float
        Standing height [m] (1.2 to 2.2).
    mass_kg : float
        Body mass [kg] (30 to 200, and a body mass index mass / stature^2 of 13 to 50 kg/m^2, with a warning
        outside 16 to 40: see the module docstring).
    sitting_height_m : float, optional
        Sitting height [m]; default: the reference proportion (0.92 / 1.76 of stature).
    """

    def __init__(self, stature_m: float, mass_kg: float, sitting_height_m: float | None = None):
        self.stature_m = _check("stature_m", stature_m, *STATURE_RANGE_M)
        self.mass_kg = _check("mass_kg", mass_kg, *MASS_RANGE_KG)
        _check_build(self.stature_m, self.mass_kg)
        if sitting_height_m is None:
            sitting_height_m = self.stature_m * REFERENCE_SITTING_HEIGHT_M / REFERENCE_STATURE_M
        self.sitting_height_m = _check("sitting_height_m", sitting_height_m, 0.4 * self.stature_m, 0.6 * self.stature_m)
        self.mass = self.mass_kg / REFERENCE_MASS_KG
        self.stature = self.stature_m / REFERENCE_STATURE_M
        self.trunk = self.sitting_height_m / REFERENCE_SITTING_HEIGHT_M
        self.legs = (self.stature_m - self.sitting_height_m) / (REFERENCE_STATURE_M - REFERENCE_SITTING_HEIGHT_M)
        self.width = math.sqrt(self.mass / self.stature)

    def is_reference(self) -> bool:
        return all(abs(f - 1.0) < 1e-12 for f in (self.mass, self.trunk, self.legs, self.width))

    def factors(self, leg: bool) -> np.ndarray:
        """Position factors (x, y, z) of the leg or the upper-body region.  Seated, the legs extend forward
        and down, so their x and z both follow leg length; the upper body's z follows sitting height and
        its x (depth) the width factor."""
        return np.array([self.legs, self.width, self.legs]) if leg else np.array([self.width, self.width, self.trunk])

    def shape_factors(self, leg: bool) -> np.ndarray:
        """Factors of an ellipsoid's own semi-axes: a leg segment's first axis lies along its length."""
        return np.array([self.legs, self.width, self.width]) if leg else np.array([self.width, self.width, self.trunk])

    def length(self, leg: bool) -> float:
        """The characteristic length ratio L of a region (for stiffness and damping)."""
        return self.legs if leg else self.trunk


def _is_leg(name: str, prefixes: tuple[str, ...]) -> bool:
    return name.startswith(prefixes)


def stretched_inertia(moments_kgm2: np.ndarray, mass_ratio: float, factors: np.ndarray) -> np.ndarray:
    """Principal moments of inertia [kg m^2] of a body whose mass is multiplied by ``mass_ratio`` and whose
    extent along its principal axes is stretched by ``factors`` (3,): second moments C_i = sum m x_i^2 =
    (tr I) / 2 - I_ii scale with mass_ratio * factor_i^2, and I_ii = tr C - C_i."""
    moments = np.asarray(moments_kgm2, dtype=float)
    second = moments.sum() / 2 - moments
    # a table on the bound (the foot: C_y = 0) keeps a millionth of the trace, so that round-off in the
    # stretched moments cannot cross the bound MuJoCo checks (A + B >= C)
    second = np.maximum(second, 1e-6 * moments.sum())
    second = second * mass_ratio * np.asarray(factors, dtype=float) ** 2
    return second.sum() - second


def scale_body(body: Body, size: BodySize) -> Body:
    """The body tables of a person of ``size`` (the reference size returns the tables unchanged)."""
    if not isinstance(size, BodySize):
        raise InputError(f"size must be an ehm.person.scaling.BodySize, e.g. BodySize(stature_m=1.7, mass_kg=70), not "
                         f"{describe(size)}.")
    if size.is_reference():
        return body
    segments = []
    for s in body.segments:
        leg = _is_leg(s.name, LEG_SEGMENTS)
        f, fs = size.factors(leg), size.shape_factors(leg)
        segments.append(replace(s, mass_kg=s.mass_kg * size.mass, inertia_kgm2=stretched_inertia(s.inertia_kgm2,
                                                                                                 size.mass, fs),
                                com_m=s.com_m * f, shape_m=s.shape_m * fs))
    joints = [replace(j, pos_m=j.pos_m * size.factors(_is_leg(j.name, LEG_JOINTS))) for j in body.joints]
    contacts = [replace(c, center_m=c.center_m * size.factors(_is_leg(c.segment, LEG_SEGMENTS)),
                        semi_axes_m=c.semi_axes_m * size.shape_factors(_is_leg(c.segment, LEG_SEGMENTS)))
                for c in body.contacts]
    return Body(tuple(segments), tuple(joints), tuple(contacts))


def scale_params(params: Parameters, size: BodySize, body: Body | None = None) -> Parameters:
    """Joint, contact and seat parameters for a person of ``size`` (Hof 1996 dimensionless scaling).

    A contact scales with the legs when its segment does (as in :func:`scale_body`); ``body`` gives the
    contacts' segments (default: the shipped tables).
    """
    if size.is_reference():
        return params
    if body is None:
        from ..body.tables import load_body

        body = load_body()
    leg_contacts = {c.name for c in body.contacts if _is_leg(c.segment, LEG_SEGMENTS)}
    g_m, updates = size.mass, {}
    for path in params.numeric_paths():
        parts = path.split(".")
        v = float(params.value(path))
        if parts[0] == "joints":
            L = size.length(parts[1].startswith(LEG_JOINTS))
            key = parts[-1]
            rot = key.endswith("per_rad")
            if key.startswith("stiffness"):
                updates[path] = v * g_m * (L if rot else 1.0 / L)
            elif key.startswith("damping"):
                updates[path] = v * g_m * (L * math.sqrt(L) if rot else 1.0 / math.sqrt(L))
        elif parts[0] == "contacts":
            L = size.length(parts[1] in leg_contacts)
            key = parts[-1]
            if "stiffness" in key:
                updates[path] = v * g_m / L
            elif "damping" in key:
                updates[path] = v * g_m / math.sqrt(L)
            elif key == "pad_mass_kg":
                updates[path] = v * g_m
        elif path == "simulation.pad_armature_kg":  # an inertia of the pads' shear motion: scales as their mass
            updates[path] = v * g_m
        elif parts[0] == "seat" and path.endswith("_m"):
            name = parts[1]
            if name == "floor_height_m":  # the floor sits under the feet: pelvis-to-floor height is legs
                updates[path] = v * size.legs
            elif name.endswith(("height_m",)):
                updates[path] = v * size.trunk
            else:  # fore-aft positions and pad thicknesses
                updates[path] = v * size.width
    about = (f"scaled to stature {size.stature_m:g} m, mass {size.mass_kg:g} kg, "
             f"sitting height {size.sitting_height_m:g} m")
    return params.with_values(updates).with_about({"scaled": about})


def check_buildable(size: BodySize, body: Body, params: Parameters, scaled_body: Body,
                    scaled_params: Parameters) -> None:
    """One sentence when a person of ``size`` (``body`` and ``params`` scaled to ``scaled_body`` and
    ``scaled_params``) would have a segment that is no rigid body, naming the segment and the masses that can
    be built at this stature instead."""
    from ..engine import inertia_problem

    problem = inertia_problem(scaled_body, scaled_params)
    if problem is None:
        return
    ok = []
    m_lo, m_hi = mass_range_kg(size.stature_m)
    for m in np.arange(math.ceil(m_lo), m_hi + 1e-9, 1.0):
        with warnings.catch_warnings():  # a probe size's body mass index is no news for the user
            warnings.simplefilter("ignore", EhmWarning)
            s = BodySize(size.stature_m, m, size.sitting_height_m)
        if inertia_problem(scale_body(body, s), scale_params(params, s, body)) is None:
            ok.append(m)
    spans, start = [], None
    for i, m in enumerate(ok):
        start = m if start is None else start
        if i + 1 == len(ok) or ok[i + 1] - m > 1.5:
            spans.append(f"{start:g}-{m:g} kg" if m > start else f"{m:g} kg")
            start = None
    where = f"at stature {size.stature_m:g} m and sitting height {size.sitting_height_m:.3g} m"
    hint = (f"{where} it can be built with a mass of {', '.join(spans)}: choose one there or another stature"
            if spans else f"no mass from {m_lo:.0f} to {m_hi:.0f} kg can be built {where}: choose another stature or "
            "sitting height")
    a, b, c = problem.moments
    raise InputError(f"a person of {size.stature_m:g} m and {size.mass_kg:g} kg cannot be built: scaled to that size, "
                     f"segment {problem.segment!r} would have principal moments of inertia {a:.4g}, {b:.4g}, "
                     f"{c:.4g} kg m^2, which no rigid body has ({problem.rule}); {hint}.")
