"""Back supports of the seat, and where their pads sit on a person in a given posture.

``none``: no backrest (the person sits unsupported, held by the posture control alone); ``low``: one pad, at the
posterior superior iliac spine (the lower back contact); ``high``: the paper's experimental seat, that pad and
one at the lower tip of the scapula (the upper back contact): the default; ``full``: a car backrest, one plane
along the whole back that both back contacts press on.

The parameter file's ``[seat]`` places the pads for the tables' reference posture (erect): backrest frame
(``backrest_x_m``, recline ``backrest_angle_deg``), pad heights and thicknesses.  In another posture each pad
follows its landmark on the body, as the experiment's configurable supports were set to each sitter: it sits
at the landmark's height, and stands out of the backrest so that the contact presses into it as deep as in the
reference posture (or just touches it, where the reference posture's pad leaves a gap).  A full backrest is
the plane that both back contacts press into that deep; its recline follows the back.  A posture whose back
would have to be inside the backrest, or that a pad cannot reach, is refused in one sentence.  No MuJoCo
here: the engine's builder reads the planes.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from scipy.optimize import brentq

from ..errors import InputError
from .tables import Body, ContactEllipsoid

BACK_SUPPORTS = ("none", "low", "high", "full")  #: Back supports, from none to a full car backrest.
DEFAULT_BACK_SUPPORT = "high"  #: The paper's validation seat.
#: Seat surfaces each back support has (the others' contacts are left out of the person).
_SURFACES = {"none": (), "low": ("backrest_lower",),
             "high": ("backrest_lower", "backrest_upper", "back_bolster_r", "back_bolster_l"),
             "full": ("backrest_lower", "backrest_upper", "back_bolster_r", "back_bolster_l")}
_BACK = ("backrest_lower", "backrest_upper", "back_bolster_r", "back_bolster_l")
PAD_REACH_M = 0.15  #: A back pad stands at most this far out of the backrest (grade assumed).
FULL_RECLINE_DEG = (-15.0, 40.0)  #: Recline a full backrest may take to meet the back [deg from vertical].
_PAD = {"backrest_lower": "lower back pad", "backrest_upper": "upper back pad"}
_LANDMARK = {"backrest_lower": "lower back (posterior superior iliac spine)",
             "backrest_upper": "upper back (lower tip of the scapula)"}


def check_back_support(name: str, where: str = "back support") -> str:
    """``name`` if it is one of :data:`BACK_SUPPORTS`, else one sentence naming them."""
    if name not in BACK_SUPPORTS:
        raise InputError(f"{where}: unknown back support {name!r}; use one of {', '.join(BACK_SUPPORTS)}.")
    return name


def supported(body: Body, back_support: str) -> Body:
    """The body without the contacts of backrest surfaces the back support does not have."""
    keep = _SURFACES[check_back_support(back_support)]
    contacts = tuple(c for c in body.contacts if c.surface not in _BACK or c.surface in keep)
    return body if len(contacts) == len(body.contacts) else replace(body, contacts=contacts)


def _pad_plane(seat: dict, pad: str) -> tuple[np.ndarray, np.ndarray]:
    """A back pad's plane (point, normal) as ``[seat]`` places it for the reference posture."""
    b = math.radians(seat["backrest_angle_deg"])
    normal = np.array([math.cos(b), 0.0, math.sin(b)])
    h = seat[f"{pad}_pad_height_m"]
    point = np.array([seat["backrest_x_m"] - math.tan(b) * h, 0.0, h]) + seat[f"{pad}_pad_thickness_m"] * normal
    return point, normal


def _depth(c: ContactEllipsoid, point: np.ndarray, normal: np.ndarray) -> float:
    """How far contact ``c`` reaches through the plane (point, normal) [m] (negative: a gap)."""
    return c.reach_m(normal) - float(np.dot(c.center_m - point, normal))


def backrest_planes(seat: dict, reference: Body, posed: Body, back_support: str, posture: str) -> dict:
    """The backrest surfaces of ``back_support`` as planes, surface -> (point [m], unit normal), for the person
    ``posed`` (``reference``: the same tables in the reference posture, which ``seat`` is set for).  Raises
    InputError, naming what to change, when a pad cannot meet the posture's back."""
    check_back_support(back_support)
    contact = {c.surface: c for c in posed.contacts if c.surface in ("backrest_lower", "backrest_upper")}
    ref = {c.name: c for c in reference.contacts}
    if back_support == "full":
        return _full_backrest(seat, contact, ref, posture)
    planes = {}
    for surface in ("backrest_lower", "backrest_upper"):
        if surface not in _SURFACES[back_support]:
            continue
        pad = surface.split("_")[1]
        point, normal = _pad_plane(seat, pad)
        c = contact.get(surface)
        if c is None or c is ref[c.name]:  # the reference posture: the pads as [seat] places them
            planes[surface] = (point, normal)
            continue
        depth = max(_depth(ref[c.name], point, normal), 0.0)  # the pad set to the sitter: at least touching
        new_point = c.center_m - (c.reach_m(normal) - depth) * normal
        thickness = seat[f"{pad}_pad_thickness_m"] + float(np.dot(new_point - point, normal))
        _check_reach(thickness, surface, posture, back_support)
        planes[surface] = (new_point, normal)
    return planes


def _check_reach(thickness: float, surface: str, posture: str, back_support: str) -> None:
    if thickness < 0:
        raise InputError(f"the {posture} posture puts the {_LANDMARK[surface]} {-thickness:.3g} m inside the backrest "
                         f"of the '{back_support}' back support; move the backrest back (a smaller seat.backrest_x_m "
                         "or seat.backrest_angle_deg) or choose another posture.")
    if thickness > PAD_REACH_M:
        raise InputError(f"the {_PAD[surface]} of the '{back_support}' back support would have to "
                         f"stand {thickness:.3g} m out of the backrest to touch the {posture} posture's "
                         f"{_LANDMARK[surface]} (at most {PAD_REACH_M:g} m), so it touches nothing; move the backrest "
                         "forward (a larger seat.backrest_x_m) or choose back support 'none'.")


def _full_backrest(seat: dict, contact: dict, ref: dict, posture: str) -> dict:
    """One plane that both back contacts press into as deep as into the reference posture's pads; its recline is
    where the two meet (between :data:`FULL_RECLINE_DEG`)."""
    lower, upper = contact.get("backrest_lower"), contact.get("backrest_upper")
    if lower is None or upper is None:
        raise InputError("a full backrest needs both back contacts (lower_back on backrest_lower and upper_back on "
                         "backrest_upper in the contacts table); choose back support 'low' or 'none'.")
    depth = {s: _depth(ref[c.name], *_pad_plane(seat, s.split("_")[1])) for s, c in contact.items()}

    def offset(c: ContactEllipsoid, surface: str, normal: np.ndarray) -> float:  # the plane n.x = offset
        return float(np.dot(c.center_m, normal)) - c.reach_m(normal) + depth[surface]

    def normal(deg: float) -> np.ndarray:
        b = math.radians(deg)
        return np.array([math.cos(b), 0.0, math.sin(b)])

    def mismatch(deg: float) -> float:
        n = normal(deg)
        return offset(lower, "backrest_lower", n) - offset(upper, "backrest_upper", n)

    lo, hi = FULL_RECLINE_DEG
    if mismatch(lo) * mismatch(hi) > 0:
        raise InputError(f"no full backrest reclined between {lo:g} and {hi:g} deg touches both the lower and the "
                         f"upper back of the {posture} posture; choose back support 'high' (two pads) or another "
                         "posture.")
    n = normal(brentq(mismatch, lo, hi, xtol=1e-10))
    plane = offset(lower, "backrest_lower", n)
    # each surface drawn where its contact meets it (the same plane)
    return {s: (c.center_m - (float(np.dot(c.center_m, n)) - plane) * n, n) for s, c in contact.items()}


def recline_deg(planes: dict) -> float | None:
    """The backrest's recline [deg from vertical] of a set of planes, None without a backrest."""
    for surface in ("backrest_upper", "backrest_lower"):
        if surface in planes:
            n = planes[surface][1]
            return math.degrees(math.atan2(n[2], n[0]))
    return None
