"""What the linear route leaves out: the nonlinear model's second-order response, by the nonlinear route's step.

Runs SYNTHETIC three-axis random vibration (seed 0) through the nonlinear route with the input u and with -u, and
through the linear route with u, on one person built at one vibration level at each step. Prints, per point and
axis, the rms of three differences as a share of the nonlinear route's acceleration rms:

- nonlinear - linear: what a comparison of the two routes reads;
- odd part - linear: the nonlinear route's first-order part (nl(u) - nl(-u)) / 2 against the linear route, which
  falls with the step (the linear model is linearised at the default step / 8);
- even part: (nl(u) + nl(-u)) / 2, the nonlinear model's second-order response, which a linear model cannot hold;
  it does not depend on the step and scales with the input (try --rms 0.03).

    python benchmarks/linear_second_order.py [--rms 0.3] [--duration 35] [--steps 0.001 0.0005 0.00025 0.000125]
        [--head-control]
"""

from __future__ import annotations

import argparse

import numpy as np

import ehm
from ehm import engine


def _rms(x: np.ndarray) -> np.ndarray:
    return np.sqrt(np.mean(x ** 2, axis=0))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rms", type=float, default=0.3, help="rms of each axis of the input [m/s^2]")
    ap.add_argument("--duration", type=float, default=35.0, help="length of the drive [s]")
    ap.add_argument("--level", type=float, default=0.3,
                    help="vibration level the person is built at [m/s^2 rms], the same for every --rms")
    ap.add_argument("--steps", nargs="+", type=float, default=[0.001, 0.0005, 0.00025, 0.000125],
                    help="the nonlinear route's time steps [s]")
    ap.add_argument("--head-control", action="store_true", help="the person with head-in-space control")
    a = ap.parse_args()
    if a.rms <= 0 or a.duration < 1.0 or a.level <= 0 or min(a.steps) <= 0:
        ap.error("--rms and --level must be positive, --duration at least 1 s, --steps positive.")
    motion = ehm.random_vibration("xyz", a.duration, a.rms, seed=0, dt_s=0.001)
    reverse = ehm.SeatMotion(motion.time_s, -motion.acc_mps2, f"{motion.description}, reversed")
    print(f"SYNTHETIC {motion.description}; person at {a.level:g} m/s^2 rms"
          f"{', with head control' if a.head_control else ''}; rms of each difference as a share of "
          "the nonlinear route's acceleration rms, x / y / z")
    n = motion.time_s.size
    for dt in a.steps:
        human = ehm.SeatedHuman(ehm.Person(dt_s=dt, vibration_rms_mps2=a.level,
                                             head_control=a.head_control or None))
        up, down = human.simulate(motion, method="nonlinear"), human.simulate(reverse, method="nonlinear")
        lin = human.simulate(motion, method="linear")
        every = int(round(0.001 / dt))  # the common 1 ms grid
        print(f"\nnonlinear step {dt * 1e3:g} ms")
        print(f"{'point':8} {'nonlinear - linear':>22} {'odd part - linear':>22} {'even part':>22}")
        for p in engine.POINTS:
            nl, nr, li = (r.point(p).acc_mps2[::every][:n] for r in (up, down, lin))
            share = 100 / _rms(nl)
            cols = [share * _rms(nl - li), share * _rms((nl - nr) / 2 - li), share * _rms((nl + nr) / 2)]
            print(f"{p:8} " + " ".join(f"{' / '.join(f'{v:.2f}' for v in c) + ' %':>22}" for c in cols))


if __name__ == "__main__":
    main()
