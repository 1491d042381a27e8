"""Whole-drive assessment: speed and memory for SYNTHETIC city drives of growing length.

Prints wall time, real-time factor and the peak of Python/numpy allocations (tracemalloc) during the
assessment: memory must not grow with the drive's length (chunked simulation, streaming metrics).
Usage: python benchmarks/bench_assess.py [--durations 60 300]
"""

from __future__ import annotations

import argparse
import time
import tracemalloc

import ehm
from ehm.analysis.assessment import assess
from ehm.inputs.drives import city_drive


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--durations", type=float, nargs="+", default=[60.0, 300.0])
    args = ap.parse_args()
    human = ehm.SeatedHuman(rotating_seat=True)
    human.settle()
    for duration in args.durations:
        drive = city_drive(duration, seed=0)
        tracemalloc.start()
        t0 = time.perf_counter()
        res = assess(drive, human)
        wall = time.perf_counter() - t0
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        print(f"city drive {duration:g} s (with rotation): {wall:.1f} s wall, {duration / wall:.0f}x real time, "
              f"peak allocations {peak / 2**20:.0f} MB, head MSI {res.sickness['head'].final_msi_percent:.2f} %")


if __name__ == "__main__":
    main()
