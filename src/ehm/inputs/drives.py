"""SYNTHETIC vehicle drives for examples and tests (no measured drive ships with ehm).

* :func:`~ehm.city_drive`: repeated accelerating, braking and cornering (0.1-0.5 Hz manoeuvres of a few
  m/s^2) with the body roll, pitch and yaw of a car, plus light road vibration.
* :func:`~ehm.rough_road`: straight driving on a random road: an ISO 8608 road profile (class and speed
  given) through a quarter-car model gives the vertical seat acceleration; pitch and roll follow from
  the height differences along and across the car.

Both return a :class:`~ehm.inputs.motion.SeatMotion` with angular velocity, in the seat's axes (x forward, y
left, z up), whose description starts with "SYNTHETIC".
"""

from __future__ import annotations

import numpy as np
from scipy import signal

from ..errors import InputError, checked, finite_number
from .motion import SeatMotion, check_seed

#: ISO 8608 road classes: displacement PSD Gd(n0) at n0 = 0.1 cycles/m [m^3] (geometric class mean).
ROAD_CLASS_GD0_M3 = {"A": 16e-6, "B": 64e-6, "C": 256e-6, "D": 1024e-6, "E": 4096e-6}


def _check(name: str, value: float, low: float, high: float = np.inf) -> float:
    v = finite_number("drive", name, value)
    if v <= low or v > high:
        raise InputError(f"{name} must be a number above {low:g}"
                         + (f" and at most {high:g}" if np.isfinite(high) else "") + f", not {value!r}.")
    return v


def _seed(seed) -> int:
    if seed is None:
        raise InputError("drive: seed must be a whole number >= 0 (a drive file names its seed), got None.")
    return check_seed(seed, "drive")


def _smooth_steps(t: np.ndarray, events: list[tuple[float, float, float, float]]) -> np.ndarray:
    """Sum of plateaus (start [s], length [s], level, rise [s]) with raised-cosine edges; each plateau's
    integral is level * length."""
    out = np.zeros_like(t)
    for start, length, level, rise in events:
        up = np.clip((t - start) / rise, 0, 1)
        down = np.clip((t - start - length) / rise, 0, 1)
        out += level * (0.5 - 0.5 * np.cos(np.pi * up) - (0.5 - 0.5 * np.cos(np.pi * down)))
    return out


@checked
def city_drive(duration_s: float = 120.0, seed: int = 0, dt_s: float = 0.01) -> SeatMotion:
    """A SYNTHETIC city drive: start, corners left and right, braking, stops, with road vibration.

    Longitudinal and lateral accelerations come as smooth plateaus (1-2.5 s rise, 0.1-0.5 Hz content) of
    1-3.5 m/s^2; each braking brings the speed back to 4-8 m/s, so the speed stays in a city range; the
    yaw rate is lateral acceleration / speed; the body rolls 0.5 deg and pitches 0.6 deg per m/s^2
    (typical passenger car gradients) with a 0.15 s lag; light vertical road vibration (0.15 m/s^2 rms,
    0.5-15 Hz) is added.  The event sequence is drawn from ``seed``.
    """
    duration = _check("duration_s", duration_s, 10.0, 4 * 3600.0)
    dt = _check("dt_s", dt_s, 1e-4, 0.1)
    rng = np.random.default_rng(_seed(seed))
    t = np.arange(0.0, duration + dt / 2, dt)
    lon, lat = [], []
    clock, speed = 2.0, 8.0
    while clock < duration - 12.0:
        length, level = rng.uniform(3.0, 5.0), rng.uniform(1.5, 2.5)
        lon.append((clock, length, level, rng.uniform(1.0, 2.5)))                          # pull away
        speed += level * length
        clock += rng.uniform(5.0, 8.0)
        lat.append((clock, rng.uniform(3.0, 6.0), rng.choice([-1, 1]) * rng.uniform(2.0, 3.5),
                    rng.uniform(1.0, 2.5)))                                                 # corner
        clock += rng.uniform(7.0, 10.0)
        length = rng.uniform(2.5, 4.0)
        level = -float(np.clip((speed - rng.uniform(4.0, 8.0)) / length, 1.0, 3.5))        # brake
        lon.append((clock, length, level, rng.uniform(1.0, 2.5)))
        speed = max(speed + level * length, 3.0)
        clock += rng.uniform(5.0, 8.0)
    ax = _smooth_steps(t, lon)
    ay = _smooth_steps(t, lat)
    speed = np.maximum(np.cumsum(ax) * dt + 8.0, 3.0)  # never below 3 m/s
    yaw_rate = ay / speed
    lag = signal.butter(1, 1 / (2 * np.pi * 0.15), fs=1 / dt, output="sos")
    roll = signal.sosfilt(lag, np.radians(0.5) * ay)     # rolls outward: right in a left turn
    pitch = signal.sosfilt(lag, -np.radians(0.6) * ax)   # dives when braking (pitch > 0 is nose down)
    # body-axis rates of these z-y-x angles (yaw, pitch, roll): w = E(roll, pitch) (roll', pitch', yaw')
    droll, dpitch = np.gradient(roll, dt), np.gradient(pitch, dt)
    wx = droll - yaw_rate * np.sin(pitch)
    wy = dpitch * np.cos(roll) + yaw_rate * np.cos(pitch) * np.sin(roll)
    wz = -dpitch * np.sin(roll) + yaw_rate * np.cos(pitch) * np.cos(roll)
    band = signal.butter(4, (0.5, 15.0), btype="band", fs=1 / dt, output="sos")
    az = signal.sosfiltfilt(band, rng.standard_normal(t.size))
    az *= 0.15 / np.sqrt(np.mean(az ** 2))
    # Specific-force-free kinematics: the lateral and longitudinal accelerations are those of the seat.
    return SeatMotion(t, np.column_stack([ax, ay, az]),
                      f"SYNTHETIC city drive, {duration:g} s, seed {seed}", np.column_stack([wx, wy, wz]))


@checked
def rough_road(duration_s: float = 60.0, speed_mps: float = 15.0, road_class: str = "C", seed: int = 0,
               dt_s: float = 0.005, wheelbase_m: float = 2.7, track_m: float = 1.5) -> SeatMotion:
    """A SYNTHETIC straight drive on a random road (ISO 8608 class ``road_class`` at ``speed_mps``).

    Each wheel path is a random profile with displacement PSD Gd(n) = Gd(n0) (n / n0)^-2, n0 = 0.1
    cycles/m (the two tracks independent, the rear following the front after wheelbase / speed).  A
    quarter-car (sprung mass 1.2 Hz, 0.3 damping ratio; wheel hop 11 Hz) filters each wheel input; the
    seat's vertical acceleration is the mean of the four corners, its pitch and roll rates follow from the
    corner differences over wheelbase and track.
    """
    duration = _check("duration_s", duration_s, 1.0, 4 * 3600.0)
    speed = _check("speed_mps", speed_mps, 1.0, 70.0)
    dt = _check("dt_s", dt_s, 1e-4, 0.1)
    seed = _seed(seed)
    if road_class not in ROAD_CLASS_GD0_M3:
        raise InputError(f"road class {road_class!r} is not one of {', '.join(ROAD_CLASS_GD0_M3)} (ISO 8608).")
    wheelbase, track = _check("wheelbase_m", wheelbase_m, 0.5, 10.0), _check("track_m", track_m, 0.5, 5.0)
    rng = np.random.default_rng(seed)
    delay = int(round(wheelbase / speed / dt))
    n = int(round(duration / dt)) + 1 + delay
    fs = 1 / dt
    # Road height as a function of time at speed v: temporal PSD G(f) = Gd(n0) n0^2 v / f^2 (one-sided).
    f = np.fft.rfftfreq(n, dt)
    gd0, n0 = ROAD_CLASS_GD0_M3[road_class], 0.1
    psd = np.zeros_like(f)
    psd[1:] = gd0 * n0 ** 2 * speed / f[1:] ** 2
    psd[f < 0.2] = 0.0  # below 0.2 Hz the road is slope, not vibration

    def profile():
        spec = np.sqrt(psd * fs * n / 2) * np.exp(2j * np.pi * rng.random(f.size))
        return np.fft.irfft(spec, n)

    left, right = profile(), profile()
    # Quarter car (Mitschke-style parameters): sprung 300 kg, unsprung 40 kg, spring 17 kN/m, tyre 200 kN/m.
    ms, mu, ks, cs, kt = 300.0, 40.0, 17e3, 1.35e3, 200e3
    A = np.array([[0, 1, 0, 0], [-ks / ms, -cs / ms, ks / ms, cs / ms], [0, 0, 0, 1],
                  [ks / mu, cs / mu, -(ks + kt) / mu, -cs / mu]])
    B = np.array([[0], [0], [0], [kt / mu]])
    C = A[1:2, :]
    sys = signal.cont2discrete((A, B, C, np.zeros((1, 1))), dt, method="bilinear")

    def corner(u):
        return signal.dlsim(sys, u)[1][:, 0]

    fl, fr = corner(left), corner(right)
    rl, rr = corner(np.roll(left, delay)), corner(np.roll(right, delay))
    sl = slice(delay, delay + int(round(duration / dt)) + 1)
    fl, fr, rl, rr = fl[sl], fr[sl], rl[sl], rr[sl]
    az = (fl + fr + rl + rr) / 4
    # angular accelerations from corner differences, integrated once (drift removed) to rates
    pitch_acc = ((rl + rr) - (fl + fr)) / 2 / wheelbase  # nose down positive about y
    roll_acc = ((fl + rl) - (fr + rr)) / 2 / track        # left side up is positive roll about x
    hp = signal.butter(2, 0.1, btype="high", fs=fs, output="sos")
    wy = signal.sosfiltfilt(hp, np.cumsum(pitch_acc) * dt)
    wx = signal.sosfiltfilt(hp, np.cumsum(roll_acc) * dt)
    t = np.arange(az.size) * dt
    zeros = np.zeros_like(t)
    return SeatMotion(t, np.column_stack([zeros, zeros, az]),
                      f"SYNTHETIC rough road, ISO 8608 class {road_class}, {speed:g} m/s, {duration:g} s, seed {seed}",
                      np.column_stack([wx, wy, zeros]))


def write_drive_csv(motion: SeatMotion, path) -> None:
    """Write a drive in the motion CSV format (with angular velocity columns), labelled by its description."""
    from ..files import write_text_atomic

    w = motion.angvel_radps if motion.angvel_radps is not None else np.zeros_like(motion.acc_mps2)
    lines = [f"# {motion.description}", "# seat acceleration in seat axes (x forward, y left, z up) and angular "
             "velocity about those axes",
             "time_s,ax_mps2,ay_mps2,az_mps2,wx_radps,wy_radps,wz_radps"]
    for t, row in zip(motion.time_s, np.column_stack([motion.acc_mps2, w])):
        lines.append(f"{t:.6f}," + ",".join(f"{v:.6g}" for v in row))  # time to the microsecond
    write_text_atomic(path, "\n".join(lines) + "\n")


SHIPPED_DRIVES = {"city": "synthetic_city_drive.csv", "road": "synthetic_rough_road.csv"}


def drive_path(name: str):
    """A motion file's path, or the path of a shipped SYNTHETIC drive named ``city`` or ``road``."""
    from importlib import resources
    from pathlib import Path

    if name in SHIPPED_DRIVES:
        return Path(str(resources.files("ehm") / "data" / "drives" / SHIPPED_DRIVES[name]))
    return Path(name)
