"""Gravity in a seat or floor accelerometer log: level it, take it as removed, or find out which.

A DC-coupled accelerometer (every MEMS sensor) at rest reads its specific force: +9.81 m/s^2 on the axis
that points up.  The seat acceleration ehm wants holds no gravity, so such a log is levelled:

1. the quietest window (:data:`QUIET_WINDOW_S` long, the least summed variance of the three axes, searched
   in steps of a tenth of the window) is taken as the vehicle at rest or cruising, where the mean specific
   force is gravity alone: its direction in sensor axes gives the sensor's static tilt;
2. the log is rotated (the smallest rotation, about a horizontal axis) so that this mean points along +z:
   the axes become level, the heading is kept;
3. the mean's norm (the sensor's own measure of g, so that its scale error goes too) is subtracted from z.

The window the tilt is taken from is the quietest whose mean's norm is within :data:`G_TOLERANCE` of g
(a stop, or cruising), when the log has one: a long braking or cornering, quiet too, holds a horizontal
acceleration that would be taken for a tilt.  Else it is the quietest window.

Modes (``read_motion(gravity=...)``, ``--gravity``):

``"auto"`` (default)
    Level the log when gravity is found in that window's mean: its norm, or its vertical (z) component, is
    within :data:`G_TOLERANCE` (10 %) of standard gravity (a log that brakes or corners most of the time has a
    mean far from 1 g, but its vertical mean is still g), with a one-line warning naming the tilt, the g
    removed and the window.  Otherwise the log is taken as gravity-free, but refused in one sentence naming
    ``--gravity included`` and ``--gravity removed`` when its mean cannot be a vehicle's (the rule of ``removed``
    below, at any length), or when that window's mean norm is half a g (``UNSURE_BAND``) or more in a log of
    :data:`QUIET_WINDOW_S` or longer: neither gravity nor a vehicle's.  (A shorter table written by hand, a step or a
    ramp, may hold a large horizontal mean.)
``"included"``
    Level the log whatever its mean; refused when the window's mean is under ``INCLUDED_MIN_SHARE`` of g
    (there is no gravity to take out: levelling would remove a few hundredths of a m/s^2 as "g" and turn the
    axes by the direction of the vehicle's own mean).
``"removed"``
    Take the log as it is, but refuse a mean that cannot be a vehicle's: a mean norm within 10 % of g, or a
    mean vertical (z) acceleration above :data:`MAX_MEAN_VERTICAL_MPS2` (a vehicle on the road cannot keep
    rising or falling; its mean horizontal acceleration may be large over a short manoeuvre).

IMU logs (``imu=True``) are not touched here: :func:`ehm.from_imu` handles their gravity.
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import EhmWarning, InputError, describe, warn
from ..imu import STANDARD_GRAVITY_MPS2

GRAVITY_MODES = ("auto", "included", "removed")
STANDARD_GRAVITY = STANDARD_GRAVITY_MPS2  #: [m/s^2] (ehm.inputs.imu's)
G_TOLERANCE = 0.10  #: a mean norm within this share of g is taken as gravity
MAX_MEAN_VERTICAL_MPS2 = 2.0  #: a gravity-free log's mean z above this is refused
QUIET_WINDOW_S = 5.0  #: length of the quiet window the tilt is taken from [s]
#: ``auto``: a quiet window whose mean is not gravity (neither its norm nor its z within :data:`G_TOLERANCE` of g)
#: but whose norm is this multiple of g or more, in a log of :data:`QUIET_WINDOW_S` or longer, is refused: a vehicle
#: keeps half a g for 5 s seldom, and a sensor with gravity in it reads more than half a g always (1.12 g braking at
#: half a g, a sensor tilted far).  Below, the log is gravity-free (unless its mean z is an offset).
UNSURE_BAND = 0.5
#: ``included``: a window's mean under this share of g holds no gravity to take out.
INCLUDED_MIN_SHARE = 0.5


def check_mode(gravity) -> str:
    if gravity not in GRAVITY_MODES:
        raise InputError(f"gravity must be one of {', '.join(GRAVITY_MODES)}; got {describe(gravity)}.")
    return gravity


def _windows(time_s: np.ndarray, acc: np.ndarray, window_s: float) -> tuple[np.ndarray, int, np.ndarray, np.ndarray]:
    """(first rows, rows per window, summed variance of the three axes, mean (k, 3)) of the windows of
    ``window_s`` (one window of the whole log if shorter), in steps of a tenth of the window."""
    n = acc.shape[0]
    dt = float(np.median(np.diff(time_s))) if n > 1 else 1.0
    m = int(min(n, max(2, round(window_s / dt))))
    starts = np.arange(0, n - m + 1, max(1, m // 10))
    c1 = np.concatenate((np.zeros((1, 3)), np.cumsum(acc, axis=0)))
    c2 = np.concatenate((np.zeros((1, 3)), np.cumsum(acc * acc, axis=0)))
    s1 = c1[starts + m] - c1[starts]
    s2 = c2[starts + m] - c2[starts]
    return starts, m, np.sum(s2 / m - (s1 / m) ** 2, axis=1), s1 / m


def gravity_window(time_s: np.ndarray, acc: np.ndarray, window_s: float = QUIET_WINDOW_S):
    """(i, j, mean) of the window gravity is looked for in: the quietest whose mean's norm is within
    :data:`G_TOLERANCE` of g (a stop, or cruising), else the quietest (see the module docstring)."""
    starts, m, var, means = _windows(time_s, acc, window_s)
    near = np.abs(np.linalg.norm(means, axis=1) - STANDARD_GRAVITY) <= G_TOLERANCE * STANDARD_GRAVITY
    k = int(np.flatnonzero(near)[np.argmin(var[near])]) if near.any() else int(np.argmin(var))
    return int(starts[k]), int(starts[k]) + m, means[k]


def rotation_to_up(v: np.ndarray) -> np.ndarray:
    """The smallest rotation R (3, 3) with R @ v/|v| = (0, 0, 1)."""
    u = v / np.linalg.norm(v)
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(u, z)
    s, c = np.linalg.norm(axis), float(np.dot(u, z))
    if s < 1e-12:
        if c > 0:
            return np.eye(3)
        return np.diag([1.0, -1.0, -1.0])  # upside down: half a turn about x
    k = axis / s
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + s * kx + (1 - c) * (kx @ kx)


def handle_gravity(time_s: np.ndarray, acc: np.ndarray, rates: np.ndarray | None, gravity: str, label: str,
                   earth: bool = False):
    """Apply the gravity mode to a (non-IMU) log: returns ``(acc, rates, note)``, ``note`` an empty string
    when nothing was done, else what was done (for the motion's description).  ``earth``: the log is in earth
    axes, so gravity lies along z by construction; levelling then takes the log's mean z off z, without a
    tilt."""
    if gravity == "removed":
        _check_removed(acc.mean(axis=0), label)
        return acc, rates, ""
    i, j, quiet = gravity_window(time_s, acc)
    where = f"its quietest window ({float(time_s[i]):g}-{float(time_s[j - 1]):g} s)"
    norm, vertical = float(np.linalg.norm(quiet)), float(quiet[2])
    found = min(abs(norm - STANDARD_GRAVITY), abs(vertical - STANDARD_GRAVITY)) <= G_TOLERANCE * STANDARD_GRAVITY
    mean_words = (f"{where} has a mean acceleration of ({quiet[0]:.3g}, {quiet[1]:.3g}, {quiet[2]:.3g}) m/s^2 "
                  f"(norm {norm:.3g} m/s^2)")
    if gravity == "auto" and not found:
        _check_not_found(time_s, acc, norm, mean_words, label)
        return acc, rates, ""
    if gravity == "included" and norm < INCLUDED_MIN_SHARE * STANDARD_GRAVITY:
        raise InputError(f"{label}: taken as gravity included (--gravity included), but {mean_words}, far from g "
                         f"({STANDARD_GRAVITY:.4g} m/s^2): there is no gravity to take out; read it with --gravity "
                         "removed (gravity='removed') or auto.")
    if earth:
        levelled, note = _level_earth(acc, acc.mean(axis=0))
    else:
        levelled, rates, note = _level_by_tilt(time_s, acc, rates, i, j)
    if gravity == "auto":
        which = "norm" if abs(norm - STANDARD_GRAVITY) <= G_TOLERANCE * STANDARD_GRAVITY else "vertical part"
        warn(f"{label}: the mean acceleration of its quietest window has a {which} within {G_TOLERANCE:.0%} "
             f"of g (norm {norm:.4g}, z {vertical:.4g} m/s^2), so the log is taken to include gravity and is "
             f"{note} (--gravity included does the same without this note).", EhmWarning, stacklevel=4)
    return levelled, rates, note


def _offset(mean: np.ndarray) -> bool:
    """A mean no vehicle's can be: its norm within :data:`G_TOLERANCE` of g, or its z above
    :data:`MAX_MEAN_VERTICAL_MPS2` (gravity, or an offset)."""
    norm = float(np.linalg.norm(mean))
    return abs(norm - STANDARD_GRAVITY) <= G_TOLERANCE * STANDARD_GRAVITY or abs(mean[2]) > MAX_MEAN_VERTICAL_MPS2


_OFFSET_RULE = (f"a mean norm within {G_TOLERANCE:.0%} of g, or a mean z above {MAX_MEAN_VERTICAL_MPS2:g} m/s^2, is "
                "gravity or an offset")


def _check_removed(mean: np.ndarray, label: str) -> None:
    """``removed``: refuse a mean that cannot be a vehicle's (:func:`_offset`)."""
    if _offset(mean):
        raise InputError(
            f"{label}: taken as gravity removed (--gravity removed), but its mean acceleration "
            f"({mean[0]:.3g}, {mean[1]:.3g}, {mean[2]:.3g}) m/s^2 cannot be a vehicle's ({_OFFSET_RULE}); give "
            "--gravity included to level it.")


def _check_not_found(time_s: np.ndarray, acc: np.ndarray, norm: float, mean_words: str, label: str) -> None:
    """``auto`` without gravity in the quiet window: refuse a log whose mean is an offset (:func:`_offset`, at any
    length), and a log of :data:`QUIET_WINDOW_S` or longer whose quiet window's norm is half a g or more (neither
    gravity nor a vehicle's); a shorter one (a table written by hand: a step, a ramp) with a small z mean is taken
    as it is."""
    mean = acc.mean(axis=0)
    offset = _offset(mean)
    if not offset and (float(time_s[-1] - time_s[0]) < QUIET_WINDOW_S or norm < UNSURE_BAND * STANDARD_GRAVITY):
        return
    included = "give --gravity included (gravity='included') to level it"
    if offset:
        found = (f"a mean z of {mean[2]:.3g} m/s^2 over the whole log, above {MAX_MEAN_VERTICAL_MPS2:g} m/s^2"
                 if abs(mean[2]) > MAX_MEAN_VERTICAL_MPS2 else f"a mean norm of {np.linalg.norm(mean):.3g} m/s^2 over "
                 f"the whole log, within {G_TOLERANCE:.0%} of g")
        why = f"{found}, is gravity or an offset, which --gravity removed refuses too"
        level = f"{included} with that mean taken as g, or " if norm >= INCLUDED_MIN_SHARE * STANDARD_GRAVITY else ""
        advice = f"{level}take the offset out of the log (or check the acceleration's unit, --unit)"
    else:
        why = "a vehicle keeps half a g for 5 s seldom"
        advice = f"{included}, or --gravity removed (gravity='removed') to take it as it is"
    raise InputError(f"{label}: {mean_words}, neither gravity (within {G_TOLERANCE:.0%} of g) nor a vehicle's "
                     f"({why}), so ehm cannot tell whether the log holds gravity: {advice}.")


def _level_earth(acc: np.ndarray, mean: np.ndarray):
    """An earth-axis log levelled: gravity lies along z by construction, so the log's mean z is taken off z."""
    levelled = acc.copy()
    levelled[:, 2] -= mean[2]
    levelled.flags.writeable = False
    return levelled, f"levelled: its mean z ({mean[2]:.4g} m/s^2) taken as g and removed (earth axes: no tilt)"


def _level_by_tilt(time_s: np.ndarray, acc: np.ndarray, rates: np.ndarray | None, i: int, j: int):
    """A sensor's log levelled with the static tilt of its window [i, j) (the module docstring's steps 1-3)."""
    g_vec = acc[i:j].mean(axis=0)
    g_norm = float(np.linalg.norm(g_vec))
    rot = rotation_to_up(g_vec)
    levelled = acc @ rot.T
    levelled[:, 2] -= g_norm
    levelled.flags.writeable = False
    if rates is not None:
        rates = rates @ rot.T
        rates.flags.writeable = False
    tilt = math.degrees(math.acos(max(-1.0, min(1.0, g_vec[2] / g_norm))))
    t0, t1 = float(time_s[i]), float(time_s[j - 1])
    return levelled, rates, (f"levelled: tilt {tilt:.2f} deg, g {g_norm:.4g} m/s^2 removed, from the quietest window "
                             f"{t0:g}-{t1:g} s")
