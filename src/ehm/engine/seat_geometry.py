"""The seat: its surfaces as planes placed from the parameters and the body (:class:`SeatGeometry`), the checks
that they fit together and fit the body (:func:`check_seat`), the rotating seat's constants, and the small
rotations that place surfaces and ellipsoids."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..body.params import Parameters
from ..body.posture import pose_body
from ..body.supports import backrest_planes, supported
from ..body.tables import Body, rot_y
from ..errors import InputError

SEAT_DOFS = ("yaw", "pitch", "roll")  #: Hinges of a rotating seat, outermost first (intrinsic z-y-x).
SEAT_INERTIA_KGM2 = 1e5  #: Moment of inertia of a rotating seat about its pivot [kg m^2]: the person barely moves it.
SEAT_BANDWIDTH_HZ = 20.0  #: Bandwidth of the seat's tracking controller (on top of feed-forward).


def quat_pitch(angle_rad: float) -> np.ndarray:
    """Quaternion (w, x, y, z) of a rotation about y."""
    return np.array([math.cos(angle_rad / 2), 0.0, math.sin(angle_rad / 2), 0.0])


def quat_z_to(normal: np.ndarray) -> np.ndarray:
    """Quaternion rotating +z onto ``normal`` (unit vector)."""
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(z, normal)
    s, c = np.linalg.norm(axis), float(np.dot(z, normal))
    if s < 1e-12:
        return np.array([1.0, 0.0, 0.0, 0.0]) if c > 0 else np.array([0.0, 1.0, 0.0, 0.0])
    angle = math.atan2(s, c)
    axis = axis / s
    return np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * axis])


def seated_body(body: Body, params: Parameters) -> Body:
    """The body tables (reference posture) in the parameters' posture (:func:`ehm.body.posture.pose_body`), with the
    contacts of the back support (:func:`ehm.body.supports.supported`)."""
    s = params.section("seat")
    posed = pose_body(body, params.posture_angles(), s["pan_height_m"], s["pan_angle_deg"])
    return supported(posed, params.back_support)


@dataclass(frozen=True)
class SeatGeometry:
    """Seat surfaces as planes in body axes of the reference posture: name -> (point [m], unit normal)."""

    planes: dict

    @classmethod
    def from_params(cls, params: Parameters, body: Body, reference: Body | None = None) -> SeatGeometry:
        """The seat of ``params`` for the person ``body`` (:func:`seated_body`; ``reference``: the same tables in the
        reference posture, default ``body``): pan and floor as the parameters place them, the back support's
        surfaces from :func:`ehm.body.supports.backrest_planes`, the bolsters a gap beside the body's side contacts."""
        s = params.section("seat")
        a = math.radians(s["pan_angle_deg"])
        pan_n = np.array([-math.sin(a), 0.0, math.cos(a)])
        planes = {
            "seat_pan": (np.array([0.0, 0.0, s["pan_height_m"]]), pan_n),
            "floor": (np.array([0.0, 0.0, s["floor_height_m"]]), np.array([0.0, 0.0, 1.0])),
        }
        planes.update(backrest_planes(s, body if reference is None else reference, body, params.back_support,
                                      params.posture))
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
            local = rot_y(c.pitch_rad).T @ n
            support = c.center_m - rot_y(c.pitch_rad) @ (c.semi_axes_m ** 2 * local
                                                          / np.linalg.norm(c.semi_axes_m * local))
            planes[c.surface] = (support - s["bolster_gap_m"] * n, n)
        return cls(planes)

    def tangents(self, surface: str) -> tuple[np.ndarray, np.ndarray]:
        """Two unit tangents of a surface: the first in the x-z plane, the second along y."""
        n = self.planes[surface][1]
        t2 = np.array([0.0, 1.0, 0.0])
        t1 = np.cross(t2, n)
        return t1 / np.linalg.norm(t1), t2


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
        if surface not in seat.planes:  # a back support without it
            continue
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
