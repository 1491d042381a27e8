"""What the head-in-space control (issue 30, ehm.engine.control) changes, measured: the figures of docs/model.md,
"Head-in-space control".  Inputs are SYNTHETIC (random vibration, the shipped SYNTHETIC city drive).

    python benchmarks/head_control.py            # about a minute on one core

1. Head rotation in space per m/s^2 of seat acceleration (H1, 20 s Welch segments) in the bands 0.1-0.5, 0.5-1 and
   1-2 Hz, lateral input -> head roll and fore-aft input -> head pitch, nonlinear route, 60 s of 0.1-2 Hz random
   vibration at 0.5 m/s^2 rms, with and without the control.
2. The delay margin: the linearised closed loop (one step, the delay exactly as the engine applies it) at growing
   delays: the least damped mode below 20 Hz and the first delay with an unstable mode.
3. The SYNTHETIC city drive with and without: the head's roll in space in corners (|a_y| > 1.5 m/s^2; outward is
   positive: the head tilts away from the curve's centre), its pitch in space in braking (a_x < -2 m/s^2; forward
   positive) and the motion sickness incidence at the end.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy import signal
from scipy.spatial.transform import Rotation

import ehm
from ehm import engine
from ehm.inputs.drives import drive_path
from ehm.inputs.readers import read_motion

BANDS = ((0.1, 0.5), (0.5, 1.0), (1.0, 2.0))


def band_gains(run, axis: str, k: int) -> list[float]:
    fs = 1.0 / run.dt_s
    a, r = run.seat_acc_mps2[:, "xyz".index(axis)], run.point("head").rot_rad[:, k]
    f, pxy = signal.csd(a, r, fs=fs, nperseg=int(20 * fs))
    _, pxx = signal.welch(a, fs=fs, nperseg=int(20 * fs))
    h = np.abs(pxy / pxx)
    return [float(np.degrees(h[(f >= lo) & (f < hi)].mean())) for lo, hi in BANDS]


def closed_rates(human, delay_s: float | None) -> np.ndarray:
    """Continuous-time rates of the linearised one-step loop (closed with the control at ``delay_s``; None: the
    person without the control), the integral actions' neutral directions left out."""
    if delay_s is None:
        lm = engine.linearize(human.model)
    else:
        model = replace(human.model, head_control=replace(human.model.head_control, delay_s=delay_s))
        lm = engine.closed_linear_model(model, engine.linearize(human.model))
    mu = np.linalg.eigvals(lm.A)
    s = np.log(mu[np.abs(mu) > 1e-12].astype(complex)) / lm.dt_s
    return s[np.abs(s) > 1e-3]


def head_in_space(run) -> np.ndarray:
    """(n, 3) roll, pitch, yaw [deg] of the head in space (seat attitude times the head's rotation on the seat)."""
    rel = Rotation.from_euler("ZYX", run.point("head").rot_rad[:, ::-1])
    if run.seat_angles_rad is None:
        return np.degrees(rel.as_euler("ZYX")[:, ::-1])
    seat = Rotation.from_euler("ZYX", run.seat_angles_rad)
    return np.degrees((seat * rel).as_euler("ZYX")[:, ::-1])


def city(head_control):
    motion = read_motion(drive_path("city"))
    human = ehm.SeatedHuman(rotating_seat=True, head_control=head_control)
    result = ehm.assess(motion, human=human, method="nonlinear")
    run = human.simulate(motion, method="nonlinear")
    ang = head_in_space(run)
    ay, ax = run.seat_acc_mps2[:, 1], run.seat_acc_mps2[:, 0]
    corner, brake = np.abs(ay) > 1.5, ax < -2.0
    outward = ang[corner, 0] * np.sign(ay[corner])
    return {"corner roll mean deg (outward +)": float(outward.mean()),
            "corner roll largest outward deg": float(outward.max()),
            "corner roll least outward deg": float(outward.min()),
            "braking pitch mean deg (forward +)": float(ang[brake, 1].mean()),
            "braking pitch largest deg": float(ang[brake, 1].max()),
            "MSI head %": float(result.sickness["head"].msi_percent[-1]),
            "corner samples": int(corner.sum()), "braking samples": int(brake.sum())}


def main() -> None:
    off, on = ehm.SeatedHuman(), ehm.SeatedHuman(head_control=True)
    print("1. head rotation in space [deg per m/s^2], bands", BANDS)
    for axis, k, what in (("y", 0, "lateral -> roll"), ("x", 1, "fore-aft -> pitch")):
        motion = ehm.random_vibration(axis, 60.0, 0.5, seed=1, band_hz=(0.1, 2.0))
        for name, h in (("off", off), ("on", on)):
            gains = band_gains(h.simulate(motion, method="nonlinear"), axis, k)
            print(f"   {what:18s} {name:3s}", " ".join(f"{g:.2f}" for g in gains))
    print("2. delay margin (least damped mode below 20 Hz)")
    on.settle()
    off.settle()
    for _name, h, T in [("off", off, None)] + [("on", on, T) for T in (0.02, 0.05, 0.1, 0.15, 0.2, 0.25, 0.28, 0.29,
                                                                      0.3, 0.31, 0.32, 0.33)]:
        s = closed_rates(h, T)
        slow = s[np.abs(s) < 2 * np.pi * 20]
        z = -slow.real / np.abs(slow)
        k = int(np.argmin(z))
        flag = "  UNSTABLE" if s.real.max() > 0 else ""
        what = "control off" if T is None else f"delay {T:.3f} s"
        print(f"   {what}: {abs(slow[k]) / 2 / np.pi:5.2f} Hz, zeta {z[k]:+.4f}{flag}")
    print("3. SYNTHETIC city drive")
    for name, hc in (("off", False), ("on", True)):
        print(f"   {name}:", {k: round(v, 3) if isinstance(v, float) else v for k, v in city(hc).items()})


if __name__ == "__main__":
    main()
