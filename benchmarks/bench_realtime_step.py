"""Per-step latency of the stepping interface, paced to the wall clock (model steps, 0.5 ms by default; 10 s of the
SYNTHETIC rough road, translation only), with and without the running comfort figures.

Usage: python benchmarks/bench_realtime_step.py [--duration 10]
"""

from __future__ import annotations

import argparse
from importlib import resources
from pathlib import Path

from ehm.analysis.stepping import Simulator, run_realtime
from ehm.inputs.readers import load_motion_csv


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--duration", type=float, default=10.0)
    args = ap.parse_args()
    path = Path(str(resources.files("ehm") / "data" / "drives" / "synthetic_rough_road.csv"))
    for comfort in (False, True):
        sim = Simulator(comfort=comfort)
        acc = load_motion_csv(path).resample(sim.dt_s).acc_mps2[: int(round(args.duration / sim.dt_s))]
        r = run_realtime(sim, acc, pace=True)
        print(f"comfort figures {'on ' if comfort else 'off'}: median {r.median_s * 1e6:.0f} us, 99th percentile "
              f"{r.p99_s * 1e6:.0f} us, worst {r.worst_s * 1e6:.0f} us per {sim.dt_s * 1e3:g} ms step; "
              f"overruns {r.overruns} of "
              f"{r.n_steps}")


if __name__ == "__main__":
    main()
