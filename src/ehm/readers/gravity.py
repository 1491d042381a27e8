"""Gravity in a seat or floor accelerometer log: level it, take it as removed, or find out which.

A DC-coupled accelerometer (every MEMS sensor) at rest reads its specific force: +9.81 m/s^2 on the axis
that points up.  The seat acceleration ehm wants holds no gravity, so such a log is levelled:

1. the quietest window (:data:`QUIET_WINDOW_S` long, the least summed variance of the three axes, searched
   in steps of a tenth of the window) is taken as the vehicle at rest or cruising, where the mean specific
   force is gravity alone: its direction in sensor axes gives the sensor's static tilt;
2. the log is rotated (the smallest rotation, about a horizontal axis) so that this mean points along +z:
   the axes become level, the heading is kept;
3. the mean's norm (the sensor's own measure of g, so that its scale error goes too) is subtracted from z.

Modes (``read_motion(gravity=...)``, ``--gravity``):

``"auto"`` (default)
    Level the log when the norm of its mean is within :data:`G_TOLERANCE` (10 %) of standard gravity, with
    a one-line warning naming the tilt, the g removed and the window; otherwise take it as gravity-free.
    A vehicle cannot keep a mean acceleration near 1 g over a log; a sensor with gravity cannot avoid it.
``"included"``
    Level the log whatever its mean.
``"removed"``
    Take the log as it is, but refuse a mean that cannot be a vehicle's: a mean norm within 10 % of g, or a
    mean vertical (z) acceleration above :data:`MAX_MEAN_VERTICAL_MPS2` (a vehicle on the road cannot keep
    rising or falling; its mean horizontal acceleration may be large over a short manoeuvre).

IMU logs (``imu=True``) are not touched here: :func:`ehm.from_imu` handles their gravity.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from ..errors import EhmWarning, InputError
from ..imu import STANDARD_GRAVITY_MPS2

GRAVITY_MODES = ("auto", "included", "removed")
STANDARD_GRAVITY = STANDARD_GRAVITY_MPS2  #: [m/s^2] (ehm.imu's)
G_TOLERANCE = 0.10  #: a mean norm within this share of g is taken as gravity
MAX_MEAN_VERTICAL_MPS2 = 2.0  #: a gravity-free log's mean z above this is refused
QUIET_WINDOW_S = 5.0  #: length of the quiet window the tilt is taken from [s]


def check_mode(gravity) -> str:
    if gravity not in GRAVITY_MODES:
        raise InputError(f"gravity must be one of {', '.join(GRAVITY_MODES)}; got {gravity!r}.")
    return gravity


def quiet_window(time_s: np.ndarray, acc: np.ndarray, window_s: float = QUIET_WINDOW_S) -> tuple[int, int]:
    """Index range [i, j) of the window of ``window_s`` (the whole log if shorter) with the least summed
    variance of the three axes; the search steps by a tenth of the window."""
    n = acc.shape[0]
    dt = float(np.median(np.diff(time_s))) if n > 1 else 1.0
    m = int(min(n, max(2, round(window_s / dt))))
    if m >= n:
        return 0, n
    c1 = np.concatenate((np.zeros((1, 3)), np.cumsum(acc, axis=0)))
    c2 = np.concatenate((np.zeros((1, 3)), np.cumsum(acc * acc, axis=0)))
    starts = np.arange(0, n - m + 1, max(1, m // 10))
    s1 = c1[starts + m] - c1[starts]
    s2 = c2[starts + m] - c2[starts]
    var = np.sum(s2 / m - (s1 / m) ** 2, axis=1)
    i = int(starts[int(np.argmin(var))])
    return i, i + m


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
    mean = acc.mean(axis=0)
    norm = float(np.linalg.norm(mean))
    near_g = abs(norm - STANDARD_GRAVITY) <= G_TOLERANCE * STANDARD_GRAVITY
    if gravity == "removed":
        if near_g or abs(mean[2]) > MAX_MEAN_VERTICAL_MPS2:
            raise InputError(
                f"{label}: taken as gravity removed (--gravity removed), but its mean acceleration "
                f"({mean[0]:.3g}, {mean[1]:.3g}, {mean[2]:.3g}) m/s^2 cannot be a vehicle's (a mean norm within "
                f"{G_TOLERANCE:.0%} of g, or a mean z above {MAX_MEAN_VERTICAL_MPS2:g} m/s^2, is gravity or an "
                "offset); give --gravity included to level it.")
        return acc, rates, ""
    if gravity == "auto" and not near_g:
        return acc, rates, ""
    if earth:
        levelled, note = _level_earth(acc, mean)
    else:
        levelled, rates, note = _level_by_tilt(time_s, acc, rates, label)
    if gravity == "auto":
        warnings.warn(f"{label}: the mean acceleration's norm is {norm:.4g} m/s^2, within {G_TOLERANCE:.0%} of g, so "
                      f"the log is taken to include gravity and is {note} (--gravity included does the same "
                      "without this note).",
                      EhmWarning, stacklevel=4)
    return levelled, rates, note


def _level_earth(acc: np.ndarray, mean: np.ndarray):
    """An earth-axis log levelled: gravity lies along z by construction, so the log's mean z is taken off z."""
    levelled = acc.copy()
    levelled[:, 2] -= mean[2]
    levelled.flags.writeable = False
    return levelled, f"levelled: its mean z ({mean[2]:.4g} m/s^2) taken as g and removed (earth axes: no tilt)"


def _level_by_tilt(time_s: np.ndarray, acc: np.ndarray, rates: np.ndarray | None, label: str):
    """A sensor's log levelled with the static tilt of its quietest window (the module docstring's steps 1-3)."""
    i, j = quiet_window(time_s, acc)
    g_vec = acc[i:j].mean(axis=0)
    g_norm = float(np.linalg.norm(g_vec))
    if g_norm == 0.0:
        raise InputError(f"{label}: its quietest window has a mean acceleration of zero; gravity's direction cannot "
                         "be found (give --gravity removed if the log holds no gravity).")
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
