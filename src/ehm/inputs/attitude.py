"""The seat's attitude (roll and pitch) from an IMU log: rests, a gravity-aided filter and unit checks.

Used by :func:`ehm.from_imu`; everything works in seat axes (x forward, y left, z up) on arrays that are
already checked.  The attitude R(t) maps seat axes to world axes (z up); yaw is unobservable and irrelevant
here (gravity is vertical) and is whatever the gyro integrates to from 0.

The filter is x-io Technologies' Fusion AHRS (Python package ``imufusion``, MIT licence; S. Madgwick,
*AHRS algorithms and calibration solutions to facilitate new applications using low-cost MEMS*, PhD thesis,
University of Bristol 2014, chapter 7): the gyro rates are integrated and the accelerometer's direction pulls
the attitude towards gravity with a gain, a complementary filter whose accelerometer path is a first-order
low-pass of time constant 1 / gain.  Its settings here (:data:`FILTER_GAIN`, :data:`ACCELERATION_REJECTION_DEG`,
:data:`REJECTION_TIMEOUT_S`) are chosen for a vehicle, not Fusion's hand-held defaults (gain 0.5, rejection
10 deg, timeout 5 s), because a vehicle's horizontal accelerations last for seconds: with a 2 s time constant
a 5 s braking at 1.5 m/s^2 would be taken as a 8.7 deg pitch of the seat.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError

#: Gain of the accelerometer feedback [1/s]: the attitude follows gravity's direction with a 20 s time constant.
#: Slow enough that a manoeuvre of a few seconds that passes the rejection moves it little (a 5 s braking
#: at 0.8 m/s^2, a 4.7 deg tilt of the specific force, moves it 1.1 deg), fast enough that a gyro bias left
#: after the rest (0.02 deg/s) stands for a 0.4 deg error.
FILTER_GAIN = 0.05
#: Acceleration rejection [deg]: a sample whose (1 Hz low-passed) specific force points more than this away
#: from the filter's gravity is not used: a horizontal acceleration above g tan(5 deg) = 0.86 m/s^2.
ACCELERATION_REJECTION_DEG = 5.0
#: Acceleration recovery [s]: when more than 90 % of samples are rejected for this long the accelerometer is
#: used again whatever it says (Fusion's guard against an attitude that has drifted away); longer than a
#: vehicle's manoeuvres, corners and roundabouts included.
REJECTION_TIMEOUT_S = 30.0
#: The accelerometer is low-passed (2nd-order Butterworth, forward and backward: no lag) at this frequency
#: before it reaches the filter, so that road vibration does not decide the rejection.
ACCELERATION_LOWPASS_HZ = 1.0

#: A rest: the mean specific force within this fraction of the log's gravity reading ...
REST_GRAVITY_TOLERANCE = 0.01
#: ... steady: the mean specific force of the window's second half within this of its first half [m/s^2]
#: (0.6 deg of tilt; a braking that eases out, whose slow pitch the gyro would read as bias, is no rest) ...
REST_STEADY_MPS2 = 0.1
#: ... and a quiet gyro: mean rate and each axis' standard deviation at most this [rad/s] (1 deg/s).
REST_RATE_LIMIT_RADPS = math.radians(1.0)
#: The bias at a rest is the median of the rests' mean rates within this time either side [s].
BIAS_SPAN_S = 120.0
#: Sustained gyro rates above this [rad/s] (over 1 s) are not a seat's: the unit is probably deg/s.
SUSTAINED_RATE_LIMIT_RADPS = 10.0
#: Default limit of the seat's roll and pitch [deg].
MAX_TILT_DEG = 45.0
#: A gyro whose rates, integrated from one rest to the next, miss the next rest's tilt by more than this
#: [deg/sqrt(s)] (the median over rests :data:`DRIFT_GAP_S` or more apart) cannot carry the attitude through
#: a vehicle's manoeuvres (``ehm.inputs.imu.gyro_drift``): a gyro logged slower than its mount vibrates, or a noisy one.
#: Measured: 0.02-0.25 on synthetic 50 Hz drives with bias and noise; 1.1 on a real iPhone drive logged
#: at 10 Hz on a dash mount.
GYRO_DRIFT_LIMIT = 0.4
#: The shortest time between two rests that ``ehm.inputs.imu.gyro_drift`` counts [s].
DRIFT_GAP_S = 10.0
#: ``ehm.inputs.imu.gyro_drift`` compares the tilt of a rest's last and the next rest's first seconds, this long [s].
DRIFT_EDGE_S = 2.0
#: For such a gyro the filter leans on gravity: a gain of 0.1 (time constant 10 s) and an acceleration rejection
#: of 10 deg (1.7 m/s^2).  On the iPhone drive: horizontal acceleration 0.73 m/s^2 rms from the car's own
#: CAN-bus accelerometer, against 1.10 with the settings above; on the synthetic drives these settings would
#: leave 8-17 % instead of 1 % (a good gyro is better trusted).
WEAK_GYRO_GAIN = 0.1
WEAK_GYRO_REJECTION_DEG = 10.0

_DEG_PER_RAD = math.degrees(1.0)


def imufusion_module():
    """The imufusion package, or one sentence on how to install it."""
    try:
        import imufusion
    except ImportError:
        raise InputError("IMU logs with gyro rates need the imufusion package for their attitude filter: "
                         "pip install 'ehm[logs]' (or pip install imufusion).") from None
    return imufusion


@dataclass(frozen=True)
class Window:
    """Samples ``start:stop`` of a log, from ``t0`` to ``t1`` [s]."""

    start: int
    stop: int
    t0: float
    t1: float

    def text(self) -> str:
        return f"{self.t0:.1f}-{self.t1:.1f} s"


def _window_stats(t: np.ndarray, x: np.ndarray, length_s: float):
    """Start and stop indices of windows of ``length_s`` (a step of a quarter of that), with the mean and the
    standard deviation of each column of x over each window (running sums: any length of log)."""
    step = max(length_s / 4.0, 1e-9)
    starts = np.searchsorted(t, np.arange(t[0], t[-1] - length_s + 1e-9, step))
    starts = np.unique(starts)
    stops = np.searchsorted(t, t[starts] + length_s, side="right")
    keep = stops - starts >= 2
    starts, stops = starts[keep], stops[keep]
    c1 = np.vstack([np.zeros((1, x.shape[1])), np.cumsum(x, axis=0)])
    c2 = np.vstack([np.zeros((1, x.shape[1])), np.cumsum(x * x, axis=0)])
    count = (stops - starts)[:, None]
    mean = (c1[stops] - c1[starts]) / count
    var = np.maximum((c2[stops] - c2[starts]) / count - mean ** 2, 0.0)
    return starts, stops, mean, np.sqrt(var)


def gravity_reading(f: np.ndarray) -> float:
    """What the accelerometers read for gravity: the median of |f| over the log [m/s^2] (vibration and a
    vehicle's horizontal accelerations move it by well under 1 %)."""
    return float(np.median(np.linalg.norm(f, axis=1)))


@dataclass(frozen=True)
class Rest:
    """The rests found in a log: the gyro bias at each [rad/s] and the stretches they cover (in time order)."""

    stretches: tuple[Window, ...]
    centre_s: np.ndarray     #: (k,) the middle of each stretch [s]
    rate_radps: np.ndarray   #: (k, 3) the mean gyro rate over each stretch: the bias there
    gravity_mps2: float      #: the mean |f| over the rest windows: the accelerometers' reading of gravity

    def bias_at(self, t: np.ndarray) -> np.ndarray:
        """The gyro bias (n, 3) [rad/s]: interpolated in time between the rests (a bias that drifts as the
        sensor warms up is followed), held before the first and after the last."""
        return np.column_stack([np.interp(t, self.centre_s, self.rate_radps[:, j]) for j in range(3)])

    def text(self) -> str:
        total = sum(s.t1 - s.t0 for s in self.stretches)
        longest = sorted(self.stretches, key=lambda s: s.t0 - s.t1)
        shown = ", ".join(s.text() for s in longest[:3])
        more = f" and {len(longest) - 3} more" if len(longest) > 3 else ""
        size = np.degrees(np.linalg.norm(self.rate_radps, axis=1))
        amount = f"{size[0]:.2f} deg/s" if size.size == 1 or np.ptp(size) < 0.005 else \
            f"{size.min():.2f}-{size.max():.2f} deg/s (interpolated between the rests)"
        return f"gyro bias {amount} removed, from {total:.0f} s of rest at {shown}{more}"


def find_rests(t: np.ndarray, f: np.ndarray, w: np.ndarray, min_s: float) -> Rest | None:
    """The rests of at least ``min_s`` seconds in a log and the gyro bias they show, or None.

    Every window of ``min_s`` (a step of a quarter of that) is a rest when the mean specific forces of its two
    halves lie within :data:`REST_STEADY_MPS2` of each other, its gyro is quiet (the mean rate and the
    standard deviation of each axis at most :data:`REST_RATE_LIMIT_RADPS`) and the norm of its mean specific
    force lies within :data:`REST_GRAVITY_TOLERANCE` of the log's gravity reading at rest: the median of that
    norm over the steady, quiet windows (on a rocking mount the norm of the mean of a swinging vector is
    short, so a low percentile over all windows would miss the true rests).  Overlapping rest windows join
    into stretches; each stretch's bias is the median of its windows' mean rates (axis by axis), then the
    median of the stretches within :data:`BIAS_SPAN_S` either side.  A stretch
    that only looks like rest (a steady pull-away, a straight at constant speed) does not turn the seat
    either, so its mean rate is the bias too; a gentle curve can pass as rest only below 1 deg/s.
    """
    if t[-1] - t[0] < min_s:
        return None
    starts, stops, fm, _ = _window_stats(t, f, min_s)
    if starts.size == 0:  # no window of min_s holds two samples: no rest can be told
        return None
    _, _, wm, ws = _window_stats(t, w, min_s)
    level = np.linalg.norm(fm, axis=1)
    c1 = np.vstack([np.zeros((1, 3)), np.cumsum(f, axis=0)])
    mid = (starts + stops) // 2
    halves = ((c1[stops] - c1[mid]) / (stops - mid)[:, None] - (c1[mid] - c1[starts]) / (mid - starts)[:, None])
    quiet = ((np.linalg.norm(halves, axis=1) <= REST_STEADY_MPS2)
             & (np.linalg.norm(wm, axis=1) <= REST_RATE_LIMIT_RADPS) & (ws.max(axis=1) <= REST_RATE_LIMIT_RADPS))
    if not quiet.any():
        return None
    g_rest = float(np.median(level[quiet]))
    ok = quiet & (np.abs(level / g_rest - 1.0) <= REST_GRAVITY_TOLERANCE)
    runs = []  # [first window, last window] index pairs; rest windows that overlap join, across a window that is not
    for k in np.flatnonzero(ok).tolist():  # one (the stretches do not overlap: their lengths add up)
        if runs and starts[k] <= stops[runs[-1][1]]:
            runs[-1][1] = k
        else:
            runs.append([k, k])
    stretches = tuple(Window(int(starts[a]), int(stops[b]), float(t[starts[a]]), float(t[stops[b] - 1]))
                      for a, b in runs)
    rates = np.array([np.median(wm[a:b + 1][ok[a:b + 1]], axis=0) for a, b in runs])
    centres = np.array([0.5 * (s.t0 + s.t1) for s in stretches])
    # robust against a stretch that turned a little: the median of the stretches within BIAS_SPAN_S
    near = np.abs(centres[:, None] - centres[None, :]) <= BIAS_SPAN_S
    smooth = np.array([np.median(rates[row], axis=0) for row in near])
    return Rest(stretches, centres, smooth, float(np.mean(level[ok])))


def quietest_window(t: np.ndarray, f: np.ndarray, w: np.ndarray | None, length_s: float, g_ref: float) -> Window:
    """The window of ``length_s`` (the whole log if shorter) where the seat is most likely level and still:
    the mean specific force closest to the gravity reading, the gyro's mean rate and fluctuation and the
    accelerometers' fluctuation smallest (1 deg/s of rate counts like 1 % of gravity)."""
    if t[-1] - t[0] <= length_s:
        return Window(0, t.size, float(t[0]), float(t[-1]))
    starts, stops, fm, fs = _window_stats(t, f, length_s)
    if starts.size == 0:  # too sparse for a window of length_s: the whole log
        return Window(0, t.size, float(t[0]), float(t[-1]))
    score = np.abs(np.linalg.norm(fm, axis=1) / g_ref - 1.0) + np.linalg.norm(fs, axis=1) / g_ref
    if w is not None:
        _, _, wm, ws = _window_stats(t, w, length_s)
        score = score + 0.01 * (np.linalg.norm(wm, axis=1) + np.linalg.norm(ws, axis=1)) / math.radians(1.0)
    k = int(np.argmin(score))
    return Window(int(starts[k]), int(stops[k]), float(t[starts[k]]), float(t[stops[k] - 1]))


def tilt_quaternion(up: np.ndarray) -> np.ndarray:
    """Seat -> world quaternion (scipy order x, y, z, w) of zero yaw whose gravity direction in seat axes is
    ``up`` (the direction of the specific force at rest)."""
    from scipy.spatial.transform import Rotation

    up = up / np.linalg.norm(up)
    roll = math.atan2(up[1], up[2])
    pitch = math.atan2(-up[0], math.hypot(up[1], up[2]))
    return Rotation.from_euler("ZYX", [0.0, pitch, roll]).as_quat()


def roll_pitch_deg(quat_xyzw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Roll and pitch [deg] (z-y-x angles) of seat -> world quaternions."""
    x, y, z, w = (quat_xyzw[:, k] for k in range(4))
    # third row of the rotation matrix: gravity's direction (up) in seat axes
    ux = 2.0 * (x * z - w * y)
    uy = 2.0 * (y * z + w * x)
    uz = 1.0 - 2.0 * (x * x + y * y)
    return np.degrees(np.arctan2(uy, uz)), np.degrees(np.arctan2(-ux, np.hypot(uy, uz)))


def up_in_seat_axes(quat_xyzw: np.ndarray) -> np.ndarray:
    """Gravity's (upward) direction in seat axes, (n, 3), for seat -> world quaternions."""
    x, y, z, w = (quat_xyzw[:, k] for k in range(4))
    return np.column_stack([2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)])


def tilt_bias(t: np.ndarray, w: np.ndarray, quat_xyzw: np.ndarray) -> np.ndarray:
    """The gyro bias about the axes across gravity [rad/s], from a whole log and its attitude.

    A seat's roll and pitch stay bounded, so over a long log its rates about horizontal axes average to
    (change of tilt) / (duration), about 0; what the gyro shows there on average is its bias.  The rate about
    the vertical (a vehicle's turning) is left out, so a drive's net heading change does not count.  Used
    when a log has no rest; its error is about the tilt change over the log divided by its length.
    """
    up = up_in_seat_axes(quat_xyzw)
    across = w - np.sum(w * up, axis=1)[:, None] * up
    weights = np.gradient(t)
    return np.sum(across * weights[:, None], axis=0) / np.sum(weights)


def _lowpass(t: np.ndarray, x: np.ndarray, cutoff_hz: float) -> np.ndarray:
    from scipy import signal

    fs = 1.0 / float(np.median(np.diff(t)))
    if fs <= 4.0 * cutoff_hz or t.size < 16:
        return x
    sos = signal.butter(2, cutoff_hz, fs=fs, output="sos")
    return signal.sosfiltfilt(sos, x, axis=0, padlen=min(3 * 7, t.size - 1))


def _fusion_pass(imufusion, settings, t: np.ndarray, acc: np.ndarray, rate_dps: np.ndarray, q0: np.ndarray,
                 forward: bool, out: np.ndarray) -> np.ndarray:
    """One pass of the Fusion AHRS over the whole log, forwards or backwards in time (rates negated), from the
    seat -> world quaternion ``q0`` (scipy order) at its first sample; fills ``out`` (n, 4) and returns it."""
    n = t.size
    ahrs = imufusion.Ahrs()
    ahrs.set_settings(settings)
    ahrs.set_quaternion(np.array([q0[3], q0[0], q0[1], q0[2]]))
    ahrs.skip_startup()
    first = 0 if forward else n - 1
    out[first] = q0
    sign = 1.0 if forward else -1.0
    dts = np.abs(np.diff(t)).tolist()
    rates = (0.5 * sign * (rate_dps[1:] + rate_dps[:-1]))  # the mean of the two samples' rates over each step
    steps = range(1, n) if forward else range(n - 2, -1, -1)
    for k in steps:
        step = k - 1 if forward else k  # the step between samples k and k -/+ 1
        ahrs.set_sample_period(dts[step])
        ahrs.update_no_magnetometer(rates[step], acc[k])
        qw, qx, qy, qz = ahrs.get_quaternion()
        out[k] = (qx, qy, qz, qw)
    return out


def filter_attitude(t: np.ndarray, f: np.ndarray, w: np.ndarray, anchor: Window, gain: float | None = None,
                    rejection_deg: float = ACCELERATION_REJECTION_DEG, timeout_s: float = REJECTION_TIMEOUT_S,
                    ) -> np.ndarray:
    """Seat -> world quaternions (n, 4), scipy order: the Fusion AHRS run forwards and backwards, averaged.

    Three passes: forwards from the ``anchor`` window (a rest, or the quietest stretch of the log) to the end,
    starting with the tilt of the anchor's mean specific force; backwards from where that pass ends to the
    start; forwards again from where the backward pass ends.  The attitude is the mean of the last two: a
    smoother without lag, in which the steady error a gyro bias leaves (bias / gain, of opposite sign in the
    two directions) cancels.  So a log may start in a manoeuvre, and no start-up phase is needed.
    """
    imufusion = imufusion_module()
    gain = FILTER_GAIN if gain is None else gain
    n = t.size
    fs = 1.0 / float(np.median(np.diff(t)))
    settings = imufusion.AhrsSettings(sample_rate=fs, convention=imufusion.CONVENTION_NWU, gain=gain,
                                      gyroscope_range=0.0, acceleration_rejection=rejection_deg,
                                      magnetic_rejection=0.0, rejection_timeout=timeout_s)
    acc = _lowpass(t, f, ACCELERATION_LOWPASS_HZ)
    acc = acc / np.linalg.norm(acc, axis=1).clip(1e-9)[:, None]  # direction only (Fusion normalises it)
    rate_dps = np.degrees(w)
    q0 = tilt_quaternion(f[anchor.start:anchor.stop].mean(axis=0))
    k0 = (anchor.start + anchor.stop - 1) // 2
    one = np.empty((n - k0, 4))
    _fusion_pass(imufusion, settings, t[k0:], acc[k0:], rate_dps[k0:], q0, True, one)
    back = _fusion_pass(imufusion, settings, t, acc, rate_dps, one[-1].copy(), False, np.empty((n, 4)))
    del one
    fwd = _fusion_pass(imufusion, settings, t, acc, rate_dps, back[0].copy(), True, np.empty((n, 4)))
    # the mean of the two attitudes (quaternions of one sign: q and -q are the same rotation)
    fwd *= np.where(np.sum(fwd * back, axis=1) < 0, -1.0, 1.0)[:, None]
    fwd += back
    fwd /= np.linalg.norm(fwd, axis=1)[:, None]
    return fwd


def rates_of(t: np.ndarray, quat_xyzw: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Body-axis angular velocity (n, 3) [rad/s], n >= 2: the gyro rates ``w`` (bias removed) with the filter's
    corrections added, so that their integration (:func:`ehm.inputs.kinematics.integrate_attitude`, the rotating
    seat's) follows the attitude ``quat_xyzw`` (seat -> world, scipy order) while the gyro's own content passes
    unchanged.  Each step's correction is the rotation the attitude makes beyond the gyro's, exp(w dt)^-1 q(k)^-1
    q(k+1) with w the mean of the step's two samples, over the step's duration; at the samples it is the mean
    of the two steps either side, weighted by their durations (the first and last sample: their one step).
    So the simulated seat tilts as the filter's attitude does, gravity-aided, instead of as the gyro alone
    integrates."""
    from scipy.spatial.transform import Rotation

    rot = Rotation.from_quat(quat_xyzw)
    dt = np.diff(t)[:, None]
    gyro = Rotation.from_rotvec(0.5 * (w[1:] + w[:-1]) * dt)
    turn = (gyro.inv() * rot[:-1].inv() * rot[1:]).as_rotvec()  # each step's correction [rad]
    out = np.array(w, dtype=float, copy=True)
    out[0] += turn[0] / dt[0]
    out[-1] += turn[-1] / dt[-1]
    out[1:-1] += (turn[:-1] + turn[1:]) / (dt[:-1] + dt[1:])
    return out


def check_gyro_units(t: np.ndarray, f: np.ndarray, w: np.ndarray, label: str) -> None:
    """Refuse gyro rates that are plausible only as deg/s, in one sentence naming the unit assumed and the fix.

    1. Sustained rates: the mean of |w| over any 1 s above :data:`SUSTAINED_RATE_LIMIT_RADPS` (573 deg/s).
    2. Gyro against gravity: over 1 s windows, the seat's tilt change integrated from the gyro (about axes
       across gravity) is compared with the change in direction of the (1 Hz low-passed) specific force.  If
       the rates, read as rad/s, disagree with gravity's turning more than 3 times as much as they would if
       they were deg/s, and by more than 5 deg rms, they are refused.
    """
    from .vocabulary import GYRO_UNIT
    from .vocabulary import fix as words

    fix = ("give the gyro's unit (e.g. " + words("--unit wx=deg/s --unit wy=deg/s --unit wz=deg/s",
                                                 "units={'wx': 'deg/s', 'wy': 'deg/s', 'wz': 'deg/s'}")
           + ") or convert the rates to rad/s")
    taken = GYRO_UNIT.get() or "in rad/s, as no unit is given"  # how the reader found the unit (from_imu: rad/s)
    speed = np.linalg.norm(w, axis=1)
    if t[-1] - t[0] >= 1.0:
        starts, stops, m, _ = _window_stats(t, speed[:, None], 1.0)
        k = int(np.argmax(m[:, 0])) if starts.size else 0
        if starts.size and m[k, 0] > SUSTAINED_RATE_LIMIT_RADPS:
            raise InputError(f"{label}: the gyro reads {m[k, 0]:.3g} rad/s ({math.degrees(m[k, 0]):.0f} deg/s) for a "
                             f"second from t = {t[starts[k]]:.1f} s, more than a seat turns, so its rates are "
                             f"probably in deg/s, not read {taken}: {fix}.")
    if t[-1] - t[0] < 4.0:
        return
    up = _lowpass(t, f, ACCELERATION_LOWPASS_HZ)
    up = up / np.linalg.norm(up, axis=1).clip(1e-9)[:, None]
    angle = np.vstack([np.zeros((1, 3)), np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(t)[:, None], axis=0)])
    edges = np.searchsorted(t, np.arange(t[0], t[-1], 1.0))
    a, b = edges[:-1], edges[1:]
    keep = b > a
    a, b = a[keep], b[keep]
    mid = (a + b) // 2
    u = up[mid]
    d_gyro = angle[b] - angle[a]
    d_gyro = d_gyro - np.sum(d_gyro * u, axis=1)[:, None] * u   # the tilt part: about axes across gravity
    d_grav = np.cross(up[b] - up[a], u)                          # the tilt gravity's direction shows
    as_rad = math.sqrt(np.mean(np.sum((d_gyro - d_grav) ** 2, axis=1)))
    as_deg = math.sqrt(np.mean(np.sum((d_gyro / _DEG_PER_RAD - d_grav) ** 2, axis=1)))
    if as_rad > 3.0 * as_deg and as_rad > math.radians(5.0):
        raise InputError(f"{label}: read {taken}, the gyro tilts the seat by {math.degrees(as_rad):.0f} deg rms per "
                         f"second more than gravity's direction shows, and as deg/s it would agree within "
                         f"{math.degrees(as_deg):.1f} deg: {fix}.")
