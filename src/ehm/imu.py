"""IMU logs: the seat's motion from an inertial measurement unit fixed to the seat.

An IMU's accelerometers measure specific force, ``f = R^T (a - g)`` in its own axes (at rest, level:
``(0, 0, +9.81)``), next to gyro rates about those axes.  :func:`from_imu` turns both into what
:class:`ehm.motion.SeatMotion` holds, the seat's translational acceleration without gravity and its angular
velocity, in seat axes:

1. the mounting rotation (sensor axes -> seat axes) is applied to both;
2. the first ``rest_s`` seconds must be at rest (vibration is fine, no manoeuvre): their mean specific
   force gives the initial roll and pitch (gravity's direction) and the local gravity magnitude, their mean
   gyro rate the gyro bias, which is removed;
3. the attitude R(t) is integrated from the gyro rates alone (:func:`ehm.motion.integrate_attitude`, the
   same integrator the simulation uses for a rotating seat), from that initial tilt; there is no
   accelerometer correction, which would pull the attitude towards the specific force and so tilt it in
   every sustained manoeuvre (a 3 m/s^2 corner would read as a 17 degree roll);
4. the seat acceleration is ``a = f + R^T g``.

The IMU is taken to be at the seat's reference point (no lever-arm terms); yaw is unobservable and
irrelevant (gravity is vertical) and set to 0.  A simulation of the result starts with the seat level: a
log that starts on a slope keeps its start tilt in the acceleration it describes, not in the seat's pose.
"""

from __future__ import annotations

import math

import numpy as np

from .errors import InputError
from .motion import SeatMotion, integrate_attitude

__all__ = ["STANDARD_GRAVITY_MPS2", "from_imu"]

STANDARD_GRAVITY_MPS2 = 9.80665  #: Standard gravity [m/s^2]; the local value is measured at rest.
_REST_GRAVITY_TOLERANCE = 0.1    #: The specific force at rest must lie within 10 % of standard gravity.
_REST_RATE_LIMIT_RADPS = math.radians(5.0)  #: Largest mean gyro rate at rest (bias) accepted [rad/s].


def _array(value, shape_text: str, arg: str, n: int | None = None) -> np.ndarray:
    try:
        out = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"from_imu: {arg} must be a numeric array {shape_text}.") from None
    want_2d = n is not None
    if (want_2d and out.shape != (n, 3)) or (not want_2d and out.ndim != 1):
        raise InputError(f"from_imu: {arg} must have shape {shape_text}; got {out.shape}.")
    bad = np.argwhere(~np.isfinite(out))
    if bad.size:
        raise InputError(f"from_imu: {arg}{list(bad[0])} is {out[tuple(bad[0])]!r}, not a finite number.")
    return out


def _mounting_matrix(mounting) -> np.ndarray:
    if mounting is None:
        return np.eye(3)
    from scipy.spatial.transform import Rotation

    if isinstance(mounting, Rotation):
        return mounting.as_matrix()
    try:
        m = np.array(mounting, dtype=float)
    except (TypeError, ValueError):
        raise InputError("from_imu: mounting must be a 3x3 rotation matrix (sensor axes -> seat axes) or a "
                         "scipy Rotation.") from None
    if m.shape != (3, 3) or not np.allclose(m @ m.T, np.eye(3), atol=1e-6) or np.linalg.det(m) < 0:
        raise InputError("from_imu: mounting must be a proper 3x3 rotation matrix (orthonormal, determinant +1), "
                         "sensor axes -> seat axes.")
    return m


def from_imu(time_s, specific_force_mps2, angular_rate_radps, mounting=None, rest_s: float = 1.0,
             description: str = "IMU log", label: str = "from_imu") -> SeatMotion:
    """The seat's motion from an IMU at the seat (see the module docstring for the method).

    Parameters
    ----------
    time_s : (n,) array
        Sample times [s], strictly increasing, starting at or after 0.
    specific_force_mps2 : (n, 3) array
        Accelerometer reading [m/s^2]: specific force, gravity included (+9.81 up at rest), sensor axes.
    angular_rate_radps : (n, 3) array
        Gyro rates about the sensor axes [rad/s].
    mounting : 3x3 array or scipy.spatial.transform.Rotation, optional
        Rotation from sensor axes to seat axes (x forward, y left, z up); default: aligned.
    rest_s : float
        Length of the rest at the start of the log [s] (default 1 s): initial tilt, gravity and gyro bias.
    description : str
        The returned motion's description starts with this.
    label : str
        How messages name the log.

    Returns
    -------
    SeatMotion
        Seat acceleration without gravity and angular velocity (gyro bias removed), seat axes.
    """
    from scipy.spatial.transform import Rotation

    t = _array(time_s, "(n,)", "time_s")
    n = t.size
    f = _array(specific_force_mps2, "(n, 3)", "specific_force_mps2", n)
    w = _array(angular_rate_radps, "(n, 3)", "angular_rate_radps", n)
    if n < 2 or np.any(np.diff(t) <= 0):
        raise InputError(f"{label}: time_s must hold at least 2 strictly increasing times.")
    m = _mounting_matrix(mounting)
    f, w = f @ m.T, w @ m.T
    rest_s = float(rest_s)
    rest = (t - t[0]) <= rest_s
    if not (rest_s > 0 and rest.sum() >= 2 and t[-1] - t[0] > rest_s):
        raise InputError(f"{label}: the log ({t[-1] - t[0]:g} s) must be longer than its rest at the start "
                         f"(rest_s = {rest_s:g} s) and the rest must hold 2 samples or more.")
    f_rest = f[rest].mean(axis=0)
    g = float(np.linalg.norm(f_rest))
    if abs(g / STANDARD_GRAVITY_MPS2 - 1.0) > _REST_GRAVITY_TOLERANCE:
        raise InputError(f"{label}: the specific force over the first {rest_s:g} s is {g:.3g} m/s^2, not about "
                         f"{STANDARD_GRAVITY_MPS2:g}: an IMU log must start at rest with its accelerometers in "
                         "m/s^2 (for a log in g give the unit, e.g. --unit ax=g --unit ay=g --unit az=g).")
    bias = w[rest].mean(axis=0)
    if np.linalg.norm(bias) > _REST_RATE_LIMIT_RADPS:
        raise InputError(f"{label}: the gyro turns at {math.degrees(np.linalg.norm(bias)):.1f} deg/s over the first "
                         f"{rest_s:g} s: an IMU log must start at rest (or its rates are not in rad/s: give the "
                         "unit, e.g. --unit wx=deg/s).")
    w = w - bias
    up = f_rest / g
    roll = math.atan2(up[1], up[2])
    pitch = math.atan2(-up[0], math.hypot(up[1], up[2]))
    q0 = Rotation.from_euler("ZYX", [0.0, pitch, roll]).as_quat()
    attitude = Rotation.from_quat(integrate_attitude(t, w, q0))  # seat axes -> world (z up)
    acc = f + attitude.inv().apply(np.array([0.0, 0.0, -g]))
    del attitude
    text = (f"{description}; seat motion from the IMU (initial roll {math.degrees(roll):.1f} deg, pitch "
            f"{math.degrees(pitch):.1f} deg and gravity {g:.3f} m/s^2 from the first {rest_s:g} s at rest, gyro "
            f"bias {math.degrees(np.linalg.norm(bias)):.2f} deg/s removed)")
    return SeatMotion(t, acc, text, w)
