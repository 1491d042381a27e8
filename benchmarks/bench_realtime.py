"""Real-time factor of a 35 s run of the default model (the paper's EHM: 30 s wall for 35 s).

Prints wall time, real-time factor and peak memory for each time step given (default: the model's
1 ms).  Usage: python benchmarks/bench_realtime.py [--dt 0.001 0.002] [--repeat 3]
"""

from __future__ import annotations

import argparse
import resource
import time

import ehm
from ehm.params import Parameters


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--dt", type=float, nargs="+", default=[0.001])
    ap.add_argument("--duration", type=float, default=35.0)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    print(f"ehm {ehm.__version__}: {args.duration:g} s of 0.3 m/s^2 rms random vertical vibration, "
          f"best of {args.repeat}")
    for dt in args.dt:
        params = Parameters.load().with_values({"simulation.dt_s": dt})
        t0 = time.perf_counter()
        human = ehm.SeatedHuman(params=params)
        human.settle()
        setup = time.perf_counter() - t0
        motion = ehm.random_vibration("z", args.duration, 0.3, seed=0, dt_s=dt)
        walls = []
        for _ in range(args.repeat):
            run = human.simulate(motion)
            walls.append(run.wall_s)
        best = min(walls)
        peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        print(f"dt {dt * 1000:g} ms: run wall {best:.2f} s, real-time factor {args.duration / best:.0f}x "
              f"(build + settle {setup:.2f} s; us per step {best / (args.duration / dt) * 1e6:.1f}; "
              f"peak memory {peak_mb:.0f} MB)")


if __name__ == "__main__":
    main()
