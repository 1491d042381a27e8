"""IMU logs: the seat's motion from an inertial measurement unit fixed to the seat.

An IMU's accelerometers measure specific force, ``f = R^T (a - g)`` in its own axes (at rest, level:
``(0, 0, +9.81)``), next to gyro rates about those axes.  :func:`~ehm.from_imu` turns both into what
:class:`ehm.inputs.motion.SeatMotion` holds, the seat's translational acceleration without gravity and its angular
velocity, in seat axes:

1. the mounting rotation (sensor axes -> seat axes) is applied to both;
2. the units are checked: the accelerometers must read about 9.81 m/s^2 for gravity, and gyro rates that a
   seat cannot have in rad/s (over 10 rad/s for a second, or a tilt that disagrees with gravity's direction
   as if they were deg/s) are refused with the ``--unit`` fix;
3. **rests** are looked for anywhere in the log: ``rest_s`` seconds (default 2) or more whose mean specific
   force is steady (its two halves within 0.1 m/s^2), whose gyro is quiet (mean rate and each axis' standard
   deviation at most 1 deg/s) and whose mean specific force lies within 1 % of its value at rest (the median
   over the steady, quiet windows).
   Their mean rates give the **gyro bias**, interpolated in time between them (a drifting bias is
   followed), which is removed.  Without a rest the bias is not measured (a warning says so); for a log of a
   minute or more its part about the axes across gravity is estimated from the whole log (a seat's roll and
   pitch rates average to about 0).  A log need not start at rest: a drive may start moving, even in a corner;
4. the **attitude** R(t) comes from a gravity-aided filter, x-io's Fusion AHRS (``imufusion``, in the
   ``logs`` extra): the gyro is integrated and the accelerometer's direction pulls the attitude towards
   gravity with gain 0.05 (time constant 20 s), except while the specific force points more than 5 deg
   away from the filter's gravity (a horizontal acceleration over 0.86 m/s^2: braking, corners), whose
   samples are not used; see ``ehm.inputs.attitude`` for these settings and why.  The filter starts at the longest
   rest (or else the quietest 5 s of the log), with the tilt of its mean specific force, and runs forwards and
   backwards in time from there, so long drives do not drift.  A **weak gyro**, whose rates integrated from one
   rest to the next miss the next rest's tilt by more than 0.4 deg per square root of a second (a gyro logged
   more slowly than its mount vibrates, or a noisy one: ``ehm.inputs.imu.gyro_drift``), makes the filter lean on
   gravity instead: gain 0.1, rejection 10 deg, with a warning;
5. the seat's **roll and pitch** must stay within ``max_tilt_deg`` (default 45 deg): an attitude beyond is
   refused with its time (an IMU not fixed to the seat, its mounting not given, or gyro rates off);
6. the seat acceleration is ``a = f + R^T g``, with g the mean ``|f|`` at the rests (else the mean vertical
   specific force over the log): the accelerometers' own reading of gravity;
7. the seat's **angular velocity** is the gyro's, bias removed, with the filter's gravity-aided corrections
   added (``ehm.inputs.attitude.rates_of``), so that the rotating seat of a simulation, which integrates it, tilts as
   the attitude does (the gyro alone would drift: on a synthetic 20 min drive with a drifting bias, 4.7 deg
   against 1.0 deg), while the gyro's own vibration passes unchanged.

A log **without gyro** (``angular_rate_radps=None``) is levelled with the static tilt of its quietest 5 s and
the seat is taken as not rotating (the returned motion has no angular velocity): the body's roll and pitch
in manoeuvres then stay in the horizontal acceleration (about 9 % of it for a car).

The IMU is taken to be at the seat's reference point (no lever-arm terms); yaw is unobservable and
irrelevant (gravity is vertical) and starts at 0.  A simulation of the result starts with the seat level: a
log recorded on a slope keeps that tilt in the acceleration it describes, not in the seat's pose.

Logs already turned into earth axes by a phone (x east, y north, z up) are not seat axes: their
accelerometers hold gravity on z whatever the car does, and their gyro rates are earth-axis rates.  Give
such a log without its gyro (it is already levelled), and mind that its x and y are east and north, not
forward and left.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import EhmWarning, InputError, checked, warn
from . import attitude as _att
from .motion import SeatMotion, integrate_attitude
from .vocabulary import GYRO_UNIT, fix

__all__ = ["STANDARD_GRAVITY_MPS2", "from_imu"]

STANDARD_GRAVITY_MPS2 = 9.80665  #: Standard gravity [m/s^2]; the local value is measured from the log.
_GRAVITY_TOLERANCE = 0.1         #: The accelerometers' gravity reading must lie within 10 % of standard gravity.
_TILT_BIAS_MIN_S = 60.0          #: Shortest log whose tilt-axis gyro bias is estimated from the whole log [s].
_ANCHOR_S = 5.0                  #: Length of the quietest window that starts the filter without a rest [s].


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


def mounting_matrix(mounting, label: str = "from_imu") -> np.ndarray:
    """A mounting (sensor axes -> seat axes) as a 3x3 rotation matrix: None (the identity), one scipy Rotation, a
    proper 3x3 rotation matrix, or the sensor's (roll, pitch, yaw) in degrees as three numbers or ``"ROLL,PITCH,YAW"``
    (as ``--mounting`` takes them, :func:`ehm.inputs.readers.mounting_rotation`); anything else is refused in one
    sentence
    naming ``label``."""
    if mounting is None:
        return np.eye(3)
    from scipy.spatial.transform import Rotation

    try:
        ndim = np.ndim(mounting)
    except ValueError:  # a ragged list
        ndim = None
    if isinstance(mounting, str) or (not isinstance(mounting, Rotation) and ndim == 1):
        mounting = mounting_rotation(mounting)  # roll, pitch, yaw [deg]
    if isinstance(mounting, Rotation):
        if not mounting.single:
            raise InputError(f"{label}: mounting must be one rotation, not {len(mounting)}.")
        return mounting.as_matrix()
    try:
        m = np.array(mounting, dtype=float)
    except (TypeError, ValueError):
        m = None
    if m is None or m.shape != (3, 3):
        raise InputError(f"{label}: mounting must be (roll, pitch, yaw) in degrees, a scipy Rotation or a 3x3 rotation "
                         "matrix (sensor axes -> seat axes).")
    if not (np.all(np.isfinite(m)) and np.allclose(m @ m.T, np.eye(3), atol=1e-6) and np.linalg.det(m) > 0):
        raise InputError(f"{label}: mounting must be a proper 3x3 rotation matrix (orthonormal, determinant +1), "
                         "sensor axes -> seat axes.")
    return m


def mounting_rotation(roll, pitch=None, yaw=None, degrees: bool = True):
    """A sensor's mounting (sensor axes -> seat axes) from its roll, pitch and yaw.

    The sensor's axes are the seat's axes (x forward, y left, z up) turned by ``yaw`` about z, then ``pitch``
    about the turned y, then ``roll`` about the twice-turned x (intrinsic z-y'-x'', as a vehicle's attitude).
    A phone lying flat with its x axis pointing left (seat y) has yaw +90°; one standing upright in a windscreen
    mount facing the driver, its y axis up and its screen facing back, has roll 90° and yaw -90°.

    Parameters
    ----------
    roll : float, or a sequence of three floats, or str
        Roll angle; or (roll, pitch, yaw); or ``"ROLL,PITCH,YAW"`` (as ``--mounting`` takes it).
    pitch, yaw : float, optional
        The other two angles, when ``roll`` is one number.
    degrees : bool
        Angles in degrees (default) or radians.

    Returns
    -------
    scipy.spatial.transform.Rotation
        For ``mounting=`` of :func:`ehm.read_motion` and :func:`ehm.from_imu`.
    """
    from scipy.spatial.transform import Rotation

    given = roll
    if isinstance(roll, str):
        parts = [p.strip() for p in roll.split(",")]
    elif pitch is None and yaw is None and np.ndim(roll) == 1:
        parts = list(roll)
    else:
        parts = [roll, pitch, yaw]
    try:
        angles = [float(p) for p in parts]
    except (TypeError, ValueError):
        angles = []
    if len(angles) != 3 or any(isinstance(p, bool) for p in parts) or not all(map(math.isfinite, angles)):
        raise InputError(f"mounting {given!r} (--mounting): give three angles ROLL,PITCH,YAW "
                         f"({'degrees' if degrees else 'radians'}), e.g. 0,0,90.")
    r, p, y = angles
    return Rotation.from_euler("ZYX", [y, p, r], degrees=degrees)


def _positive(value, arg: str) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        out = math.nan
    if not (math.isfinite(out) and out > 0):
        raise InputError(f"from_imu: {arg} must be a positive number, got {value!r}.")
    return out


def _check_tilt(t: np.ndarray, roll: np.ndarray, pitch: np.ndarray, limit: float, label: str, gyro: bool) -> None:
    """Refuse a seat roll or pitch beyond ``limit`` in one sentence: when, how far, the likely causes, and the
    option that allows it (``--max-tilt`` on the command line, ``max_tilt_deg`` in Python)."""
    over = np.flatnonzero((np.abs(roll) > limit) | (np.abs(pitch) > limit))
    if not over.size:
        return
    k = int(over[0])
    what, value = ("rolled", roll[k]) if abs(roll[k]) > limit else ("pitched", pitch[k])
    unit = GYRO_UNIT.get()  # how the reader found the gyro's unit ("in deg/s, as their names say"), if it did
    if gyro and (unit is None or "as no unit is given" in unit):
        units = fix("--unit wx=deg/s --unit wy=deg/s --unit wz=deg/s",
                    "units={'wx': 'deg/s', 'wy': 'deg/s', 'wz': 'deg/s'}")
        why = ("the IMU is not fixed to the seat (moved by hand), its mounting (sensor axes -> seat axes) is not "
               f"given, or its gyro rates are not in rad/s ({'read ' + unit if unit else 'taken as rad/s'}: in "
               f"deg/s give {units})")
    else:
        why = ("the IMU is not fixed to the seat (moved by hand, not by a vehicle) or its mounting (sensor axes -> "
               "seat axes) is not given" + (f" (its gyro rates were read {unit}, so their unit is not the cause)"
                                            if gyro and unit else ""))
    if abs(value) > 135.0:  # gravity reads downwards in seat axes
        why = ("the mounting (sensor axes -> seat axes; --mounting, mounting=) is upside down, or the accelerometers "
               "hold the negative of the specific force, as Apple's Core Motion does, which a '-' before each "
               "channel's name (--channel ax=-NAME) or negated values fix")
    largest = float(max(np.max(np.abs(roll)), np.max(np.abs(pitch))))
    allow = 5.0 * math.ceil((largest + 1e-9) / 5.0)
    option = fix(f"--max-tilt {allow:g}", f"max_tilt_deg={allow:g} (read_motion: imu_options={{'max_tilt_deg': "
                                          f"{allow:g}}})")
    slides = (" (beyond about 30 deg the body model's unbelted person slides off the seat and the run stops)"
              if largest > 30.0 else "")
    raise InputError(f"{label}: at t = {t[k]:.1f} s the seat is {what} {value:.0f} deg, more than the "
                     f"{limit:g} deg a seat plausibly tilts: perhaps {why}; if the seat does tilt so (up to "
                     f"{largest:.0f} deg in this log), allow it with {option}{slides}.")


#: The shortest rest accepted [s]: shorter windows average too little vibration to tell a bias (and would make
#: the search over windows long).
MIN_REST_S = 0.5


def gyro_drift(t: np.ndarray, f: np.ndarray, w: np.ndarray, rest) -> float | None:
    """How well the gyro carries the attitude [deg/sqrt(s)]: its rates ``w`` (bias removed) integrated as the
    rotating seat integrates them (:func:`ehm.inputs.kinematics.integrate_attitude`) from the end of each rest to the
    start of the next, from the tilt of the first rest's last ``ehm.inputs.attitude.DRIFT_EDGE_S``, against the tilt
    of the second's first, over the square root of the time between them; the median over rests
    ``ehm.inputs.attitude.DRIFT_GAP_S`` or more apart (None with fewer than two such rests; ``rest`` as
    ``ehm.inputs.attitude.find_rests`` returns it)."""
    from scipy.spatial.transform import Rotation

    if rest is None:
        return None
    stretches = sorted(rest.stretches, key=lambda s: s.t0)
    out = []
    for a, b in zip(stretches[:-1], stretches[1:]):
        gap = float(t[b.start] - t[a.stop - 1])
        if gap < _att.DRIFT_GAP_S:
            continue
        tail = f[max(a.start, int(np.searchsorted(t, t[a.stop - 1] - _att.DRIFT_EDGE_S))):a.stop]
        k = slice(a.stop - 1, b.start + 1)
        end = integrate_attitude(t[k], w[k], _att.tilt_quaternion(tail.mean(axis=0)))[-1]
        up = Rotation.from_quat(end).inv().apply([0.0, 0.0, 1.0])
        head = f[b.start:max(b.start + 1, min(b.stop, int(np.searchsorted(t, t[b.start] + _att.DRIFT_EDGE_S))))]
        seen = head.mean(axis=0) / np.linalg.norm(head.mean(axis=0))
        out.append(math.degrees(math.acos(max(-1.0, min(1.0, float(up @ seen))))) / math.sqrt(gap))
    return float(np.median(out)) if out else None


def _filter_settings(t: np.ndarray, f: np.ndarray, w: np.ndarray, rest, label: str) -> tuple[float, float, str]:
    """The attitude filter's gain and acceleration rejection [deg] for this gyro, and a note for the description:
    the vehicle settings, or, for a gyro that misses the tilt from rest to rest by more than
    ``ehm.inputs.attitude.GYRO_DRIFT_LIMIT``, settings that lean on gravity (with a warning)."""
    drift = gyro_drift(t, f, w, rest)
    if drift is None or drift <= _att.GYRO_DRIFT_LIMIT:
        return _att.FILTER_GAIN, _att.ACCELERATION_REJECTION_DEG, ""
    rate = 1.0 / float(np.median(np.diff(t)))
    why = (f"its rates, integrated from one rest to the next, miss the next rest's tilt by {drift:.2f} deg per "
           f"square root of a second, more than {_att.GYRO_DRIFT_LIMIT:g}")
    cause = (f"logged at {rate:.3g} Hz it is probably slower than its mount vibrates, so log it at 50 Hz or more"
             if rate < 50.0 else "it is noisy or not fixed to the seat")
    warn(f"{label}: the gyro cannot carry the seat's attitude through manoeuvres, so the attitude leans on "
         f"gravity (filter gain {_att.WEAK_GYRO_GAIN:g}, acceleration rejection "
         f"{_att.WEAK_GYRO_REJECTION_DEG:g} deg), because {why}; {cause}.", EhmWarning, stacklevel=3)
    return _att.WEAK_GYRO_GAIN, _att.WEAK_GYRO_REJECTION_DEG, f"; a weak gyro: {why}"


@checked
def from_imu(time_s, specific_force_mps2, angular_rate_radps=None, mounting=None, rest_s: float = 2.0,
             description: str = "IMU log", label: str = "from_imu", max_tilt_deg: float = _att.MAX_TILT_DEG
             ) -> SeatMotion:
    """The seat's motion from an IMU at the seat (see the module docstring for the method).

    Parameters
    ----------
    time_s : (n,) array
        Sample times [s], strictly increasing, starting at or after 0.
    specific_force_mps2 : (n, 3) array
        Accelerometer reading [m/s^2]: specific force, gravity included (+9.81 up at rest), sensor axes.
    angular_rate_radps : (n, 3) array or None
        Gyro rates about the sensor axes [rad/s]; None for an accelerometer-only log (levelled with its
        static tilt, the seat taken as not rotating).
    mounting : (roll, pitch, yaw) in degrees, 3x3 array or scipy.spatial.transform.Rotation, optional
        Rotation from sensor axes to seat axes (x forward, y left, z up), the angles as ``--mounting`` takes them
        (:func:`ehm.inputs.readers.mounting_rotation`); default: aligned.
    rest_s : float
        Shortest rest [s] whose mean gyro rate is taken as the gyro bias (default 2 s); a rest may lie
        anywhere in the log, and a log without one is used without bias removal.
    description : str
        The returned motion's description starts with this.
    label : str
        How messages name the log.
    max_tilt_deg : float
        Largest roll or pitch of the seat accepted [deg] (default 45).

    Returns
    -------
    SeatMotion
        Seat acceleration without gravity and angular velocity (of the filtered attitude; None without gyro), seat
        axes.  Its description names the filter, the rest used (or that there was none) and the roll and
        pitch range.
    """
    from scipy.spatial.transform import Rotation

    t = _array(time_s, "(n,)", "time_s")
    n = t.size
    f = _array(specific_force_mps2, "(n, 3)", "specific_force_mps2", n)
    gyro = angular_rate_radps is not None
    w = _array(angular_rate_radps, "(n, 3)", "angular_rate_radps", n) if gyro else None
    if n < 2 or np.any(np.diff(t) <= 0):
        raise InputError(f"{label}: time_s must hold at least 2 strictly increasing times.")
    rest_s = _positive(rest_s, "rest_s")
    if rest_s < MIN_REST_S:
        raise InputError(f"{label}: rest_s (--rest) = {rest_s:g} s; a rest that tells the gyro's bias from vibration "
                         f"lasts {MIN_REST_S:g} s or more.")
    limit = _positive(max_tilt_deg, "max_tilt_deg")
    m = mounting_matrix(mounting, label)
    f = f @ m.T
    g_ref = _att.gravity_reading(f)
    if abs(g_ref / STANDARD_GRAVITY_MPS2 - 1.0) > _GRAVITY_TOLERANCE:
        raise InputError(f"{label}: the accelerometers read {g_ref:.3g} m/s^2 for gravity (the median of |f|), not "
                         f"about {STANDARD_GRAVITY_MPS2:g}: an IMU log's accelerometers must be in m/s^2 with "
                         "gravity included (for a log in g give the unit, e.g. "
                         + fix("--unit ax=g --unit ay=g --unit az=g", "units={'ax': 'g', 'ay': 'g', 'az': 'g'}") + ").")
    rest = None
    if not gyro:
        anchor = _att.quietest_window(t, f, None, _ANCHOR_S, g_ref)
        q = np.tile(_att.tilt_quaternion(f[anchor.start:anchor.stop].mean(axis=0)), (n, 1))
        roll, pitch = _att.roll_pitch_deg(q[:1])
        _check_tilt(t, roll, pitch, limit, label, gyro=False)
        how = (f"no gyro: levelled with the static tilt of the quietest {anchor.text()} (roll {roll[0]:.1f} deg, "
               f"pitch {pitch[0]:.1f} deg), the seat taken as not rotating")
        warn(f"{label}: without gyro rates the seat is taken as not rotating, levelled with the tilt of "
             f"its quietest stretch ({anchor.text()}).", EhmWarning, stacklevel=2)
        bias_text = ""
    else:
        w = w @ m.T
        _att.check_gyro_units(t, f, w, label)
        rest = _att.find_rests(t, f, w, rest_s)
        if rest is not None:
            w = w - rest.bias_at(t)
            bias_text = rest.text()
        else:
            bias_text = (f"no rest of {rest_s:g} s found (mean |f| within 1 % of its value at rest, gyro within "
                         "1 deg/s)")
            warn(f"{label}: no rest of {rest_s:g} s or more found (mean specific force within 1 % of its "
                 "value at rest and a gyro quiet within 1 deg/s), so the gyro bias is not measured "
                 "(for a log of a minute or more its part across gravity is estimated from the whole log).",
                 EhmWarning, stacklevel=2)
        if rest is not None:
            anchor = max(rest.stretches, key=lambda s: s.t1 - s.t0)
        else:
            anchor = _att.quietest_window(t, f, w, _ANCHOR_S, g_ref)
        gain, rejection, weak = _filter_settings(t, f, w, rest, label)
        q = _att.filter_attitude(t, f, w, anchor, gain, rejection)
        if rest is None and t[-1] - t[0] >= _TILT_BIAS_MIN_S:
            # no rest: the bias about the axes across gravity from the whole log, then the filter again
            bias = _att.tilt_bias(t, w, q)
            w = w - bias
            q = _att.filter_attitude(t, f, w, anchor, gain, rejection)
            bias_text += (f"; a gyro bias of {math.degrees(np.linalg.norm(bias)):.2f} deg/s about the axes across "
                          "gravity estimated from the whole log's attitude and removed")
        roll, pitch = _att.roll_pitch_deg(q)
        _check_tilt(t, roll, pitch, limit, label, gyro=True)
        w = _att.rates_of(t, q, w)  # the seat turns as the filtered attitude does
        how = (f"attitude by a gravity-aided filter (Fusion AHRS, gain {gain:g}, acceleration rejection "
               f"{rejection:g} deg, forwards and backwards{weak}), roll {roll.min():.1f} to "
               f"{roll.max():.1f} deg, pitch {pitch.min():.1f} to {pitch.max():.1f} deg")
    attitude = Rotation.from_quat(q)  # seat axes -> world (z up)
    # the accelerometers' reading of gravity: at the rests, else the mean vertical specific force over the log
    g = rest.gravity_mps2 if rest is not None else float(np.mean(attitude.apply(f)[:, 2]))
    acc = f + attitude.inv().apply(np.array([0.0, 0.0, -g]))
    del attitude
    text = f"{description}; seat motion from the IMU ({how}; gravity {g:.3f} m/s^2" + \
        (f"; {bias_text})" if bias_text else ")")
    return SeatMotion(t, acc, text, w)
