"""The body's part in motion sickness: fore-aft oscillation at 0.25 Hz, 0.7 m/s^2 rms, on every back support and in
both postures (Mills and Griffin 2000: with a low backrest this was the most nauseogenic condition; support of the
upper body reduced sickness).

SYNTHETIC input: a fore-aft sine at the seat, 0.25 Hz, 0.99 m/s^2 peak (0.7 m/s^2 rms), ``--minutes`` long (default
30, as Mills and Griffin's exposures).  For each posture and back support it prints, through ``ehm.assess`` (route
``--method``, default ``auto``): the MSI and the predicted MISC (group parameters) after the exposure from the head's
motion and from the seat's (the head fixed to it); and, from a 60 s run of the same motion (the last 40 s, periodic by
then), the head motion behind the difference: the rms of the head's fore-aft gravito-inertial acceleration in head
axes (what the sickness model is fed, tilt included), of its fore-aft acceleration in seat axes, and of its pitch.

The body model's values change the head's motion, so these figures are measured, not fixed; the low-against-high
comparison is the point.

    python benchmarks/sickness_back_support.py [--minutes 30] [--method auto]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import ehm

POSTURES = ("erect", "slouched")
SUPPORTS = ("none", "low", "high", "full")
FREQ_HZ, RMS_MPS2 = 0.25, 0.7


def rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(x**2)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=30.0)
    parser.add_argument("--method", default="auto", choices=("auto", "linear", "nonlinear"))
    args = parser.parse_args()
    peak = RMS_MPS2 * np.sqrt(2.0)
    drive = ehm.sine("x", 60.0 * args.minutes, peak, FREQ_HZ)
    short = ehm.sine("x", 60.0, peak, FREQ_HZ)
    print(f"fore-aft {FREQ_HZ:g} Hz, {RMS_MPS2:g} m/s^2 rms, {args.minutes:g} min, route {args.method} (SYNTHETIC)")
    print()
    print("| posture | back support | MSI head (%) | MSI seat (%) | MISC head | MISC seat | head GIA_x rms (m/s^2) "
          "| head a_x rms (m/s^2) | head pitch rms (deg) | wall (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for posture in POSTURES:
        for support in SUPPORTS:
            t0 = time.perf_counter()
            person = ehm.Person(posture=posture, back_support=support)
            a = ehm.assess(drive, person, method=args.method)
            run = ehm.SeatedHuman(person).simulate(short, method=args.method)
            head = run.point("head")
            late = run.time_s >= 20.0
            gia_x = head.gia_mps2[late, 0] - head.gia_mps2[late, 0].mean()
            h, s = a.sickness["head"], a.sickness["seat"]
            print(f"| {posture} | {support} | {h.final_msi_percent:.2f} | {s.final_msi_percent:.2f} | "
                  f"{h.final_misc:.2f} | {s.final_misc:.2f} | {rms(gia_x):.3f} | {rms(head.acc_mps2[late, 0]):.3f} | "
                  f"{np.degrees(rms(head.rot_rad[late, 1] - head.rot_rad[late, 1].mean())):.2f} | "
                  f"{time.perf_counter() - t0:.0f} |", flush=True)


if __name__ == "__main__":
    main()
