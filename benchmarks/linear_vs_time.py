"""Where the linearised model holds: linear against time-domain transfer functions, by input level.

For each seat axis and rms level, runs 60 s of random vibration (0.1-12 Hz, seed 0), estimates H1
gains and compares them with the exact response of the model linearised around its settled posture
(contacts stuck). Prints, per level, the largest and median gain deviation over 1-10 Hz on the paths
of the locking study, each as a share of the path's peak linear gain in that band (so that small
cross-axis gains do not dominate), and the share of time steps in which a contact's friction is at
its Coulomb limit (sliding), with the contacts that slide most.

    python benchmarks/linear_vs_time.py [--axis x y z] [--rms 0.3 1 2 4]
"""

from __future__ import annotations

import argparse
import time
from collections import Counter

import numpy as np

from ehm import engine
from ehm.analysis.frf import linear_frf, run_curves
from ehm.analysis.study import STUDY_PATHS
from ehm.errors import DivergenceError
from ehm.inputs.motion import random_vibration
from ehm.simulation import SeatedHuman


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--axis", nargs="+", default=["x", "y", "z"], choices=["x", "y", "z"])
    ap.add_argument("--rms", nargs="+", type=float, default=[0.3, 1.0, 2.0, 4.0])
    ap.add_argument("--duration", type=float, default=60.0)
    a = ap.parse_args()
    if a.duration < 20.0:
        ap.error("--duration must be at least 20 s (two 10 s Welch segments).")
    human = SeatedHuman()
    model = human.model
    for axis in a.axis:
        lin = linear_frf(human, axis)
        for rms in a.rms:
            t0 = time.perf_counter()
            motion = random_vibration(axis, a.duration, rms, seed=0, dt_s=float(model.mj.opt.timestep))
            try:
                run = human.simulate(motion)
            except DivergenceError as exc:
                print(f"seat {axis}, {rms:g} m/s^2 rms: {exc}")
                continue
            d = engine.settled_data(model)  # the same run again, step by step, to watch the contacts
            sliding, any_sliding = Counter(), 0
            for acc in motion.acc_mps2:
                engine.step(model, d, acc)
                names = set(engine.sliding_contacts(model, d))
                sliding.update(names)
                any_sliding += bool(names)
            curves = run_curves(run, axis)
            dev = []
            for (ax, point, dof), c in curves.items():
                if (ax, point, dof) not in STUDY_PATHS:
                    continue
                sel = (c.freq_hz >= 1.0) & (c.freq_hz <= 10.0)
                ref = lin.curve(ax, point, dof)
                g_lin = np.interp(c.freq_hz[sel], ref.freq_hz, ref.gain)
                r = np.abs(c.gain[sel] - g_lin) / g_lin.max()
                dev.append((r.max(), np.median(r), f"{point} {dof}", c.freq_hz[sel][r.argmax()]))
            dev.sort(reverse=True)
            n = motion.time_s.size
            top = ", ".join(f"{name} {100 * v / n:.0f} %" for name, v in sliding.most_common(3)) or "none"
            print(f"seat {axis}, {rms:g} m/s^2 rms: largest deviation (of the path's peak gain) "
                  f"{100 * dev[0][0]:.0f} % ({dev[0][2]} at "
                  f"{dev[0][3]:.1f} Hz), median over paths {100 * np.median([x[1] for x in dev]):.0f} %; "
                  f"friction at its limit in {100 * any_sliding / n:.0f} % of steps ({top}) "
                  f"[{time.perf_counter() - t0:.0f} s]", flush=True)


if __name__ == "__main__":
    main()
