"""Mass properties of the segments: each segment's own body once its soft-tissue pads are taken out
(:func:`segment_mass_properties`), and the check that what is left is a rigid body (:func:`inertia_problem`)."""

from __future__ import annotations

import numpy as np

from ..body.params import Parameters
from ..body.tables import Body, rot_y
from ..errors import InputError

PAD_INERTIA_KGM2 = 1e-6  #: Moment of inertia of a soft-tissue pad about each axis [kg m^2] (nearly a point mass).


class ImpossibleInertia(InputError):
    """A segment's moments of inertia are those of no rigid body (``segment``: its name; ``moments``: the
    principal moments [kg m^2]; ``rule``: which condition fails)."""

    def __init__(self, message: str, segment: str, moments: np.ndarray, rule: str):
        super().__init__(message)
        self.segment, self.moments, self.rule = segment, moments, rule


def inertia_problem(body: Body, params: Parameters) -> ImpossibleInertia | None:
    """The first segment whose own body (tissue pads taken out) would not be a rigid body, or None."""
    pad_mass = pad_masses(body, params)
    for seg in body.segments:
        try:
            segment_mass_properties(seg, [c for c in body.contacts if c.segment == seg.name and c.tissue_pad], pad_mass)
        except ImpossibleInertia as exc:
            return exc
    return None


def pad_masses(body: Body, params: Parameters) -> dict:
    """Mass [kg] of each soft-tissue pad, by contact name (``contacts.<name>.pad_mass_kg``)."""
    return {c.name: float(params.value(f"contacts.{c.name}.pad_mass_kg")) for c in body.contacts if c.tissue_pad}


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
    if seg.inertia_pitch_rad:  # principal axes pitched with the segment (a posture, ehm.body.posture)
        rot = rot_y(seg.inertia_pitch_rad)
        inertia = rot @ inertia @ rot.T

    def shift(mass, r):
        return mass * (np.dot(r, r) * np.eye(3) - np.outer(r, r))

    inertia -= shift(m_body, c_body - seg.com_m)
    for c in pads:
        inertia -= shift(pad_mass[c.name], c.center_m - seg.com_m) + PAD_INERTIA_KGM2 * np.eye(3)
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
