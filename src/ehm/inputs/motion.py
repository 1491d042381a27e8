"""Seat motion: translational seat acceleration time histories.

A :class:`SeatMotion` holds the acceleration of the seat in the seat's own
axes (x forward, y left, z up) as a function of time.  Motions are either
generated here (band-limited random vibration, a sine, a logarithmic sweep) or
read from a file or a DataFrame with :func:`ehm.read_motion`.

Motions are brought onto another sample interval (the model's time step) by
anti-aliased polyphase resampling (:class:`~ehm.inputs.resampling.Resampler`, :meth:`~ehm.SeatMotion.resample`),
never by plain interpolation: a file sampled faster than the model would alias,
and a slower log would lose its upper content (linear interpolation of a 100 Hz
log costs about 5 % of its weighted rms).

Generated motions start at ``t = 0`` and fade in and out with a raised-cosine
(Tukey) taper, so the seat acceleration is exactly zero at the first and last
sample.  The taper on each end lasts 1 s or 10 % of the duration, whichever is
smaller.

All quantities are SI: time in s, acceleration in m/s^2, frequency in Hz.
Every problem with an argument or an input file raises
:class:`ehm.errors.InputError` with one sentence naming what is wrong and
where.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from numbers import Integral

import numpy as np
from scipy import signal

from ehm.errors import InputError, checked, checked_class, describe, finite_number, positive_number

from .kinematics import (  # noqa: F401 - re-exported: ehm.inputs.motion.seat_kinematics etc.
    SeatKinematics,
    integrate_attitude,
    seat_kinematics,
    seat_rotation_matrices,
)
from .resampling import PASS_FRACTION, UNIFORM_TOLERANCE, Resampler  # noqa: F401 - re-exported: ehm.inputs.motion.Resampler

__all__ = [
    "AXIS_NAMES",
    "CSV_COLUMNS",
    "MAX_SAMPLES",
    "Resampler",
    "SeatMotion",
    "parse_axes",
    "random_vibration",
    "sine",
    "sweep",
]

#: Axis names in column order of ``SeatMotion.acc_mps2``.
AXIS_NAMES: tuple[str, str, str] = ("x", "y", "z")

#: Columns required in a motion CSV file, in the order time, x, y, z.
CSV_COLUMNS: tuple[str, str, str, str] = ("time_s", "ax_mps2", "ay_mps2", "az_mps2")
#: Optional angular-velocity columns (all three or none): roll, pitch and yaw rates [rad/s].
CSV_ROTATION_COLUMNS: tuple[str, str, str] = ("wx_radps", "wy_radps", "wz_radps")

#: Largest number of samples a generated or resampled motion may have; it
#: catches a mistyped time step before it exhausts memory.
MAX_SAMPLES: int = 20_000_000

#: Longest fade-in / fade-out of generated motions [s].
_FADE_MAX_S = 1.0
#: Fade-in / fade-out length as a fraction of the duration, if shorter.
_FADE_FRACTION = 0.1
#: Butterworth order of each band edge of the random-vibration filter.
_FILTER_ORDER = 4


#: The high-pass [Hz] before a motion's vibration level is taken (:attr:`SeatMotion.vibration_rms_mps2`): the
#: vibration a person's tissues feel, without the vehicle's manoeuvres (braking, cornering: 0.1 Hz and below).
LEVEL_HIGHPASS_HZ = 0.5


# --------------------------------------------------------------------------
# The motion container
# --------------------------------------------------------------------------


@checked_class(skip=("__init__",))  # the constructor checks every field itself, naming more
@dataclass(frozen=True, eq=False)
class SeatMotion:
    """Seat translational acceleration time history in the seat's axes.

    Parameters
    ----------
    time_s : numpy.ndarray, shape (n,)
        Sample times [s], strictly increasing, finite, first value >= 0,
        ``n >= 2``.  The sample interval may vary.
    acc_mps2 : numpy.ndarray, shape (n, 3)
        Seat acceleration [m/s^2]; columns are the x (forward), y (left) and
        z (up) axes of the seat.
    description : str
        Human-readable summary, e.g.
        ``"band-limited random, z, 0.3 m/s^2 rms, 0.1-12 Hz, seed 0"``.
    angvel_radps : numpy.ndarray, shape (n, 3), optional
        Seat (vehicle) angular velocity about its own x, y, z axes (roll, pitch,
        yaw rates) [rad/s]; None for a seat that only translates.
    content_limit_hz : float, optional
        The highest frequency [Hz] the record holds, when that is below half its
        own rate: a record resampled from a slower one holds nothing above 0.4
        times the slower rate (:meth:`resample` sets it).  None: half its own rate.
    handling : tuple of dict, optional
        The stretches at the start and end of a measured log that :func:`ehm.read_motion` left out because the
        logger was handled rather than carried by the vehicle (``ehm.inputs.handling``): each a dict with
        ``where`` (``"start"`` or ``"end"``), ``start_s`` and ``end_s`` (seconds from the log's first sample),
        ``turn_deg``, ``turned_s``, ``peak_mps2`` and ``drive_peak_mps2``.  Empty: nothing was left out.

    Notes
    -----
    The arrays are copied to float64 on construction and made read-only, so a
    ``SeatMotion`` cannot change after it is made (an array that is already
    float64, read-only and owns its data is taken as it is: nothing can
    change it, and a long log is not held twice).  Invalid arrays raise
    :class:`~ehm.errors.InputError`.
    """

    #: where to get one, in the sentence refusing another value as a motion (``ehm.errors.checked``)
    ARGUMENT_HINT = "read a file with ehm.read_motion, take ehm.city_drive() or generate one with ehm.sine"

    time_s: np.ndarray
    acc_mps2: np.ndarray
    description: str
    angvel_radps: np.ndarray | None = None
    content_limit_hz: float | None = None
    handling: tuple = ()

    def __post_init__(self) -> None:
        if not isinstance(self.handling, tuple) or not all(isinstance(h, dict) for h in self.handling):
            raise InputError(f"SeatMotion: handling must be a tuple of dicts (the stretches read_motion left out); "
                             f"got {type(self.handling).__name__}.")
        if self.content_limit_hz is not None:
            object.__setattr__(self, "content_limit_hz", _positive("SeatMotion", "content_limit_hz",
                                                                   self.content_limit_hz))
        try:
            time_s = _owned_copy(self.time_s)
            acc = _owned_copy(self.acc_mps2)
        except (TypeError, ValueError):
            raise InputError(
                f"SeatMotion: time_s and acc_mps2 must be numeric arrays of one length per axis, not "
                f"{describe(self.time_s)} and {describe(self.acc_mps2)}."
            ) from None
        if time_s.ndim != 1:
            raise InputError(
                f"SeatMotion: time_s must be one-dimensional, got shape {time_s.shape}."
            )
        n = time_s.shape[0]
        if n < 2:
            raise InputError(f"SeatMotion: at least 2 samples are needed, got {n}.")
        if acc.shape != (n, 3):
            raise InputError(
                f"SeatMotion: acc_mps2 must have shape ({n}, 3) to match time_s, "
                f"got {acc.shape}."
            )
        bad = np.flatnonzero(~np.isfinite(time_s))
        if bad.size:
            i = int(bad[0])
            raise InputError(
                f"SeatMotion: time_s[{i}] is {float(time_s[i])!r}, not a finite number."
            )
        bad_rows, bad_cols = np.nonzero(~np.isfinite(acc))
        if bad_rows.size:
            i, j = int(bad_rows[0]), int(bad_cols[0])
            raise InputError(
                f"SeatMotion: acc_mps2[{i}, {j}] ({AXIS_NAMES[j]}) is {float(acc[i, j])!r}, "
                "not a finite number."
            )
        if time_s[0] < 0.0:
            raise InputError(
                f"SeatMotion: time_s must start at or after 0 s, got {float(time_s[0])!r} s."
            )
        steps = np.diff(time_s)
        bad = np.flatnonzero(steps <= 0.0)
        if bad.size:
            i = int(bad[0]) + 1
            raise InputError(
                f"SeatMotion: time_s must be strictly increasing, but time_s[{i}] = "
                f"{float(time_s[i])!r} s is not after time_s[{i - 1}] = {float(time_s[i - 1])!r} s."
            )
        if not isinstance(self.description, str):
            raise InputError(
                f"SeatMotion: description must be a str, got {type(self.description).__name__}."
            )
        if self.angvel_radps is not None:
            try:
                w = _owned_copy(self.angvel_radps)
            except (TypeError, ValueError):
                raise InputError(f"SeatMotion: angvel_radps must be a numeric array of shape (n, 3), not "
                                 f"{describe(self.angvel_radps)}.") from None
            if w.shape != (n, 3):
                raise InputError(
                    f"SeatMotion: angvel_radps must have shape ({n}, 3) to match time_s, got {w.shape}."
                )
            bad_rows, bad_cols = np.nonzero(~np.isfinite(w))
            if bad_rows.size:
                i, j = int(bad_rows[0]), int(bad_cols[0])
                raise InputError(
                    f"SeatMotion: angvel_radps[{i}, {j}] is {float(w[i, j])!r}, not a finite number."
                )
            w.flags.writeable = False
            object.__setattr__(self, "angvel_radps", w)
        time_s.flags.writeable = False
        acc.flags.writeable = False
        object.__setattr__(self, "time_s", time_s)
        object.__setattr__(self, "acc_mps2", acc)

    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(self.time_s.shape[0])

    @property
    def duration_s(self) -> float:
        """Duration of the record, ``time_s[-1] - time_s[0]`` [s]."""
        return float(self.time_s[-1] - self.time_s[0])

    @property
    def rate_hz(self) -> float:
        """The log's own sample rate [Hz], from its median time step."""
        return 1.0 / float(np.median(np.diff(self.time_s)))

    @functools.cached_property
    def vibration_rms_mps2(self) -> float:
        """The seat's vibration level [m/s^2 rms], what a person whose level is not given runs at
        (:class:`ehm.Person`'s ``vibration_rms_mps2``; docs/model.md, "Vibration magnitude").

        The rms over the whole motion of the translational acceleration vector, sqrt(mean(ax^2 + ay^2 + az^2)),
        after a zero-phase 4th-order Butterworth high-pass at ``LEVEL_HIGHPASS_HZ`` (forward and backward, at
        the log's own rate, :attr:`rate_hz`): the vibration, not the manoeuvres (braking and cornering, below it, do
        not count).  A 5 Hz sine of amplitude A on one axis gives A / sqrt(2):

        >>> import numpy as np
        >>> t = np.arange(0.0, 10.0, 0.001)
        >>> acc = np.zeros((t.size, 3))
        >>> acc[:, 2] = 1.0 * np.sin(2 * np.pi * 5.0 * t)
        >>> print(f"{SeatMotion(t, acc, 'a 5 Hz sine').vibration_rms_mps2:.3f}")
        0.707
        """
        fs = self.rate_hz
        sos = signal.butter(4, LEVEL_HIGHPASS_HZ, btype="highpass", fs=fs, output="sos") \
            if LEVEL_HIGHPASS_HZ < 0.5 * fs else None
        # padded by the log mirrored about its ends over three of the high-pass's periods (or what the log holds):
        # scipy's default, 27 samples, left a start and end transient of up to 1 % on a sine
        pad = min(int(3 * fs / LEVEL_HIGHPASS_HZ), self.n_samples - 1)
        power = 0.0
        for k in range(3):  # one axis at a time: a long log is not copied whole
            a = self.acc_mps2[:, k]
            # (a log too slow for the high-pass: its mean left out)
            a = signal.sosfiltfilt(sos, a, padlen=pad) if sos is not None else a - a.mean()
            power += float(np.mean(a ** 2))
        return float(np.sqrt(power))

    def covered_band_hz(self, run_rate_hz: float | None = None) -> tuple[float, float]:
        """The band [Hz] the seat input actually covers.

        Low: 1 / duration (the longest period the log holds once).  High: the log's Nyquist frequency (half its own
        rate, :attr:`rate_hz`), or the content limit of a log that was resampled from a slower rate
        (``content_limit_hz``: a phone's 51 Hz sensor read onto a 50 Hz grid, or a 100 Hz log read with
        ``--rate 500``, holds nothing above 20 and 40 Hz); and when it is run at another rate ``run_rate_hz`` (the
        model's step), at most 0.4 times the lower of the two rates, where the resampler's anti-alias filter starts
        to cut.
        """
        fs_log = self.rate_hz
        high = fs_log / 2.0 if self.content_limit_hz is None else min(fs_log / 2.0, self.content_limit_hz)
        if run_rate_hz is not None and abs(fs_log - run_rate_hz) > 1e-6 * run_rate_hz:
            high = min(high, PASS_FRACTION * min(fs_log, run_rate_hz))
        return 1.0 / self.duration_s, high

    def axis(self, name: str) -> np.ndarray:
        """Acceleration of one axis.

        Parameters
        ----------
        name : {"x", "y", "z"}
            Axis name (case-insensitive).

        Returns
        -------
        numpy.ndarray, shape (n,)
            Read-only view of that column of ``acc_mps2`` [m/s^2].

        Raises
        ------
        InputError
            If `name` is not one of ``"x"``, ``"y"``, ``"z"``.
        """
        key = name.strip().lower() if isinstance(name, str) else None
        if key not in AXIS_NAMES:
            raise InputError(f"Unknown axis {name!r}: expected 'x', 'y' or 'z'.")
        return self.acc_mps2[:, AXIS_NAMES.index(key)]

    def resample(self, dt_s: float) -> SeatMotion:
        """Resample onto a uniform grid starting at 0 s, with an anti-alias (polyphase) filter.

        The record is shifted in time so that it starts at 0, then sampled at
        ``t = 0, dt_s, 2 dt_s, ...`` up to and including the duration (the
        last point lies at most ``dt_s`` before the end of the record), by
        :class:`~ehm.inputs.resampling.Resampler` (``scipy.signal.resample_poly``): content below
        0.4 times the lower of the two sampling rates passes within 0.001 dB,
        content above 0.6 times it is suppressed by more than 80 dB.

        Parameters
        ----------
        dt_s : float
            New sample interval [s], finite, > 0 and not longer than the
            duration.

        Returns
        -------
        SeatMotion
            The resampled motion; its description notes the new interval.

        Raises
        ------
        InputError
            If `dt_s` is not a finite positive number, is longer than the
            duration, or would give more than :data:`~ehm.inputs.motion.MAX_SAMPLES` samples.
        """
        dt = _positive("resample", "dt_s", dt_s)
        duration = self.duration_s
        if dt > duration:
            raise InputError(
                f"resample: dt_s = {dt!r} s is longer than the motion duration "
                f"{duration!r} s."
            )
        n = _sample_count("resample", duration, dt)
        data = Resampler.of_motion(self, dt).block(0, n)
        w = None if self.angvel_radps is None else data[:, 3:]
        own_hz = 1.0 / float(np.median(np.diff(self.time_s)))
        held = self.content_limit_hz if self.content_limit_hz is not None else own_hz / 2.0
        limit = min(held, PASS_FRACTION * min(own_hz, 1.0 / dt))  # what the resampler passes
        return SeatMotion(np.arange(n) * dt, data[:, :3], f"{self.description}, resampled to dt {dt:g} s", w,
                          content_limit_hz=limit, handling=self.handling)


def _owned_copy(values) -> np.ndarray:
    """float64 array for a SeatMotion: a copy, unless ``values`` already is a read-only float64 array that owns
    its data (then no one can change it, and it is used as it is)."""
    if (isinstance(values, np.ndarray) and values.dtype == np.float64 and not values.flags.writeable
            and values.base is None and values.flags.c_contiguous):
        return values
    return np.array(values, dtype=float)


# --------------------------------------------------------------------------
# Argument checks
# --------------------------------------------------------------------------


#: a finite number, and one above 0, or one sentence naming the function and the argument
_number, _positive = finite_number, positive_number


def require_motion(func: str, motion: object) -> SeatMotion:
    """``motion`` if it is a :class:`SeatMotion`, else one sentence saying what ``func`` needs and where to get it."""
    if not isinstance(motion, SeatMotion):
        raise InputError(f"{func} needs a SeatMotion, not {describe(motion)}: read a file with ehm.read_motion, take a "
                         "shipped drive with ehm.city_drive or ehm.rough_road, or generate one with "
                         "ehm.random_vibration.")
    return motion


def _non_negative(func: str, name: str, value: object) -> float:
    result = _number(func, name, value)
    if result < 0.0:
        raise InputError(f"{func}: {name} must be >= 0, got {result!r}.")
    return result


def _frequency(func: str, name: str, value: object, nyquist_hz: float) -> float:
    """A frequency strictly between 0 and the Nyquist frequency [Hz]."""
    result = _positive(func, name, value)
    if result >= nyquist_hz:
        raise InputError(
            f"{func}: {name} = {result!r} Hz must be below the Nyquist frequency "
            f"{nyquist_hz:g} Hz (1 / (2 dt_s))."
        )
    return result


def _sample_count(func: str, duration_s: float, dt_s: float) -> int:
    """Number of samples of ``t = 0, dt, 2 dt, ... <= duration``.

    A duration that is a whole multiple of `dt_s` up to rounding error keeps
    its last sample.
    """
    steps = duration_s / dt_s
    whole = round(steps)
    k = whole if abs(steps - whole) <= 1e-9 * max(1.0, steps) else math.floor(steps)
    n = int(k) + 1
    if n > MAX_SAMPLES:
        raise InputError(
            f"{func}: a duration of {duration_s:g} s at dt_s = {dt_s:g} s gives {n} "
            f"samples, more than the limit of {MAX_SAMPLES}."
        )
    return n


def _time_grid(func: str, duration_s: object, dt_s: object) -> tuple[float, float, np.ndarray]:
    """Validate duration and step; return them with ``t = 0, dt, ...`` [s]."""
    duration = _positive(func, "duration_s", duration_s)
    dt = _positive(func, "dt_s", dt_s)
    if dt > duration:
        raise InputError(
            f"{func}: duration_s = {duration!r} s is shorter than one time step "
            f"dt_s = {dt!r} s."
        )
    n = _sample_count(func, duration, dt)
    return duration, dt, np.arange(n) * dt


def parse_axes(axis: str) -> tuple[int, ...]:
    """Column indices of the axes named in `axis`.

    Parameters
    ----------
    axis : str
        One or more distinct letters out of ``x``, ``y``, ``z`` in any order
        (``"z"``, ``"xz"``, ``"xyz"``; case-insensitive), or ``"all"`` for
        ``"xyz"``.

    Returns
    -------
    tuple of int
        Sorted column indices into ``SeatMotion.acc_mps2``
        (0 = x, 1 = y, 2 = z).

    Raises
    ------
    InputError
        If `axis` is not a string of that form.
    """
    if not isinstance(axis, str):
        raise InputError(f"Axis must be a string such as 'z' or 'xyz', got {axis!r}.")
    axis = str(axis)
    key = axis.strip().lower()
    if key == "all":
        key = "xyz"
    if not key or any(c not in AXIS_NAMES for c in key):
        raise InputError(
            f"Unknown axis {axis!r}: use one or more of the letters x, y, z "
            "(e.g. 'z', 'xz', 'xyz') or 'all'."
        )
    if len(set(key)) != len(key):
        raise InputError(f"Axis {axis!r} names the same axis more than once.")
    return tuple(sorted(AXIS_NAMES.index(c) for c in key))


def _axes_label(axes: tuple[int, ...]) -> str:
    return "".join(AXIS_NAMES[i] for i in axes)


# --------------------------------------------------------------------------
# Generated motions
# --------------------------------------------------------------------------


def _fade_window(t_s: np.ndarray) -> np.ndarray:
    """Raised-cosine fade-in and fade-out over a uniform time grid.

    Each taper lasts ``min(1 s, 0.1 * duration)``; the window is exactly 0 at
    the first and last sample and 1 in between the tapers.
    """
    duration = float(t_s[-1] - t_s[0])
    fade = min(_FADE_MAX_S, _FADE_FRACTION * duration)
    from_start = t_s - t_s[0]
    to_end = t_s[-1] - t_s
    edge = np.minimum(from_start, to_end)
    window = np.ones_like(t_s)
    inside = edge < fade
    window[inside] = 0.5 * (1.0 - np.cos(np.pi * edge[inside] / fade))
    return window


def _motion(t_s: np.ndarray, axes: tuple[int, ...], columns: dict[int, np.ndarray],
            description: str) -> SeatMotion:
    acc = np.zeros((t_s.shape[0], 3))
    for i in axes:
        acc[:, i] = columns[i]
    return SeatMotion(t_s, acc, description)


def check_seed(seed: object, func: str = "random_vibration") -> int | None:
    """A random seed as an int (or None), refused with InputError naming ``func`` when not an integer >= 0."""
    if seed is None:
        return None
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, Integral):
        raise InputError(f"{func}: seed must be a whole number or None, got {seed!r}.")
    if seed < 0:
        raise InputError(f"{func}: seed must be >= 0, got {int(seed)}.")
    return int(seed)


@checked
def random_vibration(
    axis: str,
    duration_s: float,
    rms_mps2: float,
    seed: int | None = 0,
    dt_s: float = 0.001,
    band_hz: tuple[float, float] = (0.1, 12.0),
) -> SeatMotion:
    """Band-limited Gaussian random seat acceleration.

    White Gaussian noise is band-pass filtered with a zero-phase Butterworth
    filter (order 4 at each band edge, second-order sections), faded in and
    out with a raised-cosine taper, and scaled so that the rms over the whole
    record of each excited axis is exactly `rms_mps2`.  The noise is drawn
    with extra lead-in and lead-out that is discarded, so the filter start-up
    transient does not appear in the record.

    Parameters
    ----------
    axis : str
        Excited axes, e.g. ``"z"``, ``"xz"``, ``"xyz"`` or ``"all"`` (see
        :func:`~ehm.inputs.motion.parse_axes`).  Each axis gets an independent signal; a given
        axis gets the same signal for a given seed whichever other axes are
        excited.  The other axes are zero.
    duration_s : float
        Record length [s], > 0.
    rms_mps2 : float
        Rms acceleration of each excited axis over the whole record [m/s^2],
        >= 0.  Zero gives an all-zero acceleration.
    seed : int or None, optional
        Seed for :func:`numpy.random.default_rng`; equal seeds give identical
        records.  ``None`` draws fresh entropy.  Default 0.
    dt_s : float, optional
        Sample interval [s], > 0.  Default 0.001.
    band_hz : (float, float), optional
        Pass band ``(low, high)`` [Hz] with ``0 < low < high < 1 / (2 dt_s)``.
        Default (0.1, 12.0).

    Returns
    -------
    SeatMotion
        Uniformly sampled motion starting at 0 s.

    Raises
    ------
    InputError
        If any argument is out of range or not finite, or the record is too
        short to hold any samples between the fade-in and fade-out.
    """
    func = "random_vibration"
    axes = parse_axes(axis)
    duration, dt, t = _time_grid(func, duration_s, dt_s)
    rms = _non_negative(func, "rms_mps2", rms_mps2)
    seed_value = check_seed(seed)
    low, high = _pass_band(func, band_hz, dt)
    label = _axes_label(axes)
    seed_text = "unseeded" if seed_value is None else f"seed {seed_value}"
    description = (
        f"band-limited random, {label}, {rms:g} m/s^2 rms, {low:g}-{high:g} Hz, {seed_text}"
    )
    n = t.shape[0]
    if rms == 0.0:
        return _motion(t, axes, {i: np.zeros(n) for i in axes}, description)
    columns = _filtered_noise(func, t, axes, rms, seed_value, low, high, duration, dt)
    return _motion(t, axes, columns, description)


def _pass_band(func: str, band_hz: object, dt: float) -> tuple[float, float]:
    """The checked pass band ``(low, high)`` [Hz] of :func:`random_vibration`."""
    try:
        low_raw, high_raw = band_hz
    except (TypeError, ValueError):
        raise InputError(
            f"{func}: band_hz must be a pair (low, high) in Hz, got {band_hz!r}."
        ) from None
    nyquist = 0.5 / dt
    low = _frequency(func, "band_hz low", low_raw, nyquist)
    high = _frequency(func, "band_hz high", high_raw, nyquist)
    if low >= high:
        raise InputError(
            f"{func}: band_hz low ({low!r} Hz) must be below band_hz high ({high!r} Hz)."
        )
    return low, high


def _filtered_noise(func: str, t: np.ndarray, axes: tuple[int, ...], rms: float, seed_value: int | None,
                    low: float, high: float, duration: float, dt: float) -> dict[int, np.ndarray]:
    """Band-passed, faded Gaussian noise of each excited axis, scaled to ``rms`` (one random stream per axis)."""
    n = t.shape[0]
    sos = signal.butter(_FILTER_ORDER, [low, high], btype="bandpass", fs=1.0 / dt, output="sos")
    # Lead-in/out of about two periods of the low band edge lets the filter settle.
    pad = min(max(int(math.ceil(2.0 / (low * dt))), 64), MAX_SAMPLES // 10)
    window = _fade_window(t)
    streams = np.random.default_rng(seed_value).spawn(len(AXIS_NAMES))
    columns = {}
    for i in axes:
        noise = streams[i].standard_normal(n + 2 * pad)
        filtered = signal.sosfiltfilt(sos, noise)[pad:pad + n] * window
        current = math.sqrt(float(np.mean(filtered**2)))
        if current == 0.0:
            raise InputError(
                f"{func}: duration_s = {duration!r} s is too short at dt_s = {dt!r} s: "
                "the fade-in and fade-out leave no non-zero samples."
            )
        columns[i] = filtered * (rms / current)
    return columns


@checked
def sine(
    axis: str,
    duration_s: float,
    amplitude_mps2: float,
    freq_hz: float,
    dt_s: float = 0.001,
) -> SeatMotion:
    """Sinusoidal seat acceleration with a raised-cosine fade-in and fade-out.

    ``a(t) = w(t) * amplitude_mps2 * sin(2 pi freq_hz t)`` on every named
    axis, where ``w`` is the fade window (see the module notes).

    Parameters
    ----------
    axis : str
        Excited axes (see :func:`~ehm.inputs.motion.parse_axes`); all get the same signal.
    duration_s : float
        Record length [s], > 0.
    amplitude_mps2 : float
        Peak acceleration [m/s^2], >= 0.
    freq_hz : float
        Frequency [Hz], ``0 < freq_hz < 1 / (2 dt_s)``.
    dt_s : float, optional
        Sample interval [s], > 0.  Default 0.001.

    Returns
    -------
    SeatMotion
        Uniformly sampled motion starting at 0 s.

    Raises
    ------
    InputError
        If any argument is out of range or not finite.
    """
    func = "sine"
    axes = parse_axes(axis)
    _, dt, t = _time_grid(func, duration_s, dt_s)
    amplitude = _non_negative(func, "amplitude_mps2", amplitude_mps2)
    freq = _frequency(func, "freq_hz", freq_hz, 0.5 / dt)
    wave = amplitude * np.sin(2.0 * np.pi * freq * t) * _fade_window(t)
    description = f"sine, {_axes_label(axes)}, {amplitude:g} m/s^2 peak, {freq:g} Hz"
    return _motion(t, axes, {i: wave for i in axes}, description)


@checked
def sweep(
    axis: str,
    duration_s: float,
    amplitude_mps2: float,
    f0_hz: float,
    f1_hz: float,
    dt_s: float = 0.001,
) -> SeatMotion:
    """Logarithmic sine sweep of seat acceleration, faded in and out.

    The instantaneous frequency goes exponentially from `f0_hz` at 0 s to
    `f1_hz` at the last sample (:func:`scipy.signal.chirp` with
    ``method="logarithmic"``), starting in sine phase; the amplitude follows
    the same fade window as :func:`sine`.

    Parameters
    ----------
    axis : str
        Excited axes (see :func:`~ehm.inputs.motion.parse_axes`); all get the same signal.
    duration_s : float
        Record length [s], > 0.
    amplitude_mps2 : float
        Peak acceleration [m/s^2], >= 0.
    f0_hz, f1_hz : float
        Start and end frequency [Hz], each ``> 0`` and below ``1 / (2 dt_s)``;
        a downward sweep (``f1_hz < f0_hz``) is allowed.
    dt_s : float, optional
        Sample interval [s], > 0.  Default 0.001.

    Returns
    -------
    SeatMotion
        Uniformly sampled motion starting at 0 s.

    Raises
    ------
    InputError
        If any argument is out of range or not finite.
    """
    func = "sweep"
    axes = parse_axes(axis)
    duration, dt, t = _time_grid(func, duration_s, dt_s)
    amplitude = _non_negative(func, "amplitude_mps2", amplitude_mps2)
    nyquist = 0.5 / dt
    f0 = _frequency(func, "f0_hz", f0_hz, nyquist)
    f1 = _frequency(func, "f1_hz", f1_hz, nyquist)
    wave = signal.chirp(t, f0=f0, t1=float(t[-1]), f1=f1, method="logarithmic", phi=-90.0)
    wave = amplitude * wave * _fade_window(t)
    description = (
        f"log sweep, {_axes_label(axes)}, {amplitude:g} m/s^2 peak, "
        f"{f0:g}-{f1:g} Hz, {duration:g} s"
    )
    return _motion(t, axes, {i: wave for i in axes}, description)
