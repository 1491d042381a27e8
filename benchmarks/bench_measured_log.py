"""A long measured-style log through ehm: write a SYNTHETIC 1-hour 200 Hz MDF4 log, read it, assess it.

    python benchmarks/bench_measured_log.py [--hours 1] [--rate 200] [--method nonlinear|linear] [--scale 1]
                                            [--keep DIR]

The log is SYNTHETIC (labelled so in the file's comment and channel comments): three seat-pad
accelerometer channels in g with logger-style names, vertical vibration of the shipped rough-road kind
(ISO 8608 class C at 15 m/s) and city-drive fore-aft and lateral manoeuvres, stored as float32 like a
logger's (``--scale`` multiplies them: the linear route refuses the full log, whose upper back would slide).
Printed: wall time of writing, reading and assessing, and the peak of Python/numpy allocations
(tracemalloc; MuJoCo's own buffers are not counted; imports and filter designs made before, on a 12 s log)
while reading and while assessing, against the size of the log's own arrays in ehm (time and three channels as
float64).  Goal: within 2x.  Timings on a shared
machine under load are noisy.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

G = 9.80665  # the logger's g [m/s^2]
NAMES = {"ax": "SeatPad_AccX", "ay": "SeatPad_AccY", "az": "SeatPad_AccZ"}


def write_log(path: Path, hours: float, rate_hz: float, scale: float = 1.0) -> int:
    """The SYNTHETIC log, written 10 minutes at a time (the writer's memory is not what is measured)."""
    from asammdf import MDF, Signal

    from ehm.inputs.drives import city_drive, rough_road

    duration = hours * 3600.0
    piece = 600.0
    n_total = 0
    with MDF(version="4.10") as mdf:
        start = 0.0
        seed = 0
        while start < duration - 1e-9:
            length = min(piece, duration - start)
            road = rough_road(length, dt_s=1.0 / rate_hz, seed=seed)
            city = city_drive(max(length, 10.5), seed=seed, dt_s=1.0 / rate_hz)
            n = road.n_samples - (1 if start + length < duration - 1e-9 else 0)  # pieces join without a repeat
            t = start + road.time_s[:n]
            acc = scale * np.column_stack([city.acc_mps2[:n, 0], city.acc_mps2[:n, 1], road.acc_mps2[:n, 2]])
            sigs = [Signal((acc[:, j] / G).astype(np.float32), t, name=NAMES[k], unit="g",
                           comment="SYNTHETIC: ehm benchmark, not measured")
                    for j, k in enumerate(("ax", "ay", "az"))]
            if n_total == 0:
                mdf.append(sigs, comment="SYNTHETIC seat-pad log (ehm benchmark)")
            else:
                mdf.extend(0, [(t, None)] + [(s.samples, None) for s in sigs])
            n_total += n
            start += length
            seed += 1
        mdf.save(path, overwrite=True)
    return n_total


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=1.0)
    ap.add_argument("--rate", type=float, default=200.0)
    ap.add_argument("--method", choices=("nonlinear", "linear"), default="nonlinear", help="route of the assessment")
    ap.add_argument("--scale", type=float, default=1.0, help="multiply the log's accelerations by this")
    ap.add_argument("--keep", metavar="DIR", help="keep the log and the assessment in DIR")
    args = ap.parse_args()

    import ehm
    from ehm.analysis.assessment import assess

    with tempfile.TemporaryDirectory() as tmp:
        where = Path(args.keep) if args.keep else Path(tmp)
        where.mkdir(parents=True, exist_ok=True)
        path = where / "synthetic_seat_log.mf4"
        t0 = time.perf_counter()
        n = write_log(path, args.hours, args.rate, args.scale)
        print(f"wrote {path.name}: SYNTHETIC, {n} samples x 3 channels at {args.rate:g} Hz ({args.hours:g} h), "
              f"{path.stat().st_size / 1e6:.1f} MB, accelerations x {args.scale:g}, "
              f"in {time.perf_counter() - t0:.1f} s")
        own_mb = n * 4 * 8 / 1e6  # time and three channels as float64
        human = ehm.SeatedHuman()
        human.settle()
        # warm-up on a 12 s log: imports (asammdf, pandas, pint's registry) and the weighting filters' designs are
        # made once per process and are not what grows with a log
        warm = where / "warm_up.mf4"
        write_log(warm, 12.0 / 3600.0, args.rate, args.scale)
        assess(ehm.read_motion(warm, channels=NAMES), human, method=args.method)
        tracemalloc.start()
        t0 = time.perf_counter()
        motion = ehm.read_motion(path, channels=NAMES)  # units from the file (g)
        read_s = time.perf_counter() - t0
        read_peak = tracemalloc.get_traced_memory()[1] / 1e6
        tracemalloc.reset_peak()
        t0 = time.perf_counter()
        result = assess(motion, human, method=args.method)
        assess_s = time.perf_counter() - t0
        assess_peak = tracemalloc.get_traced_memory()[1] / 1e6
        tracemalloc.stop()
        seat = result.summary()["locations"]["seat"]
        print(f"read: {read_s:.1f} s, peak allocations {read_peak:.0f} MB")
        print(f"assess ({args.method}): {assess_s:.0f} s for {motion.duration_s:.0f} s "
              f"({motion.duration_s / assess_s:.1f}x "
              f"real time, model step {human.model.mj.opt.timestep * 1e3:g} ms), peak allocations {assess_peak:.0f} MB "
              f"(the motion included; {assess_peak - own_mb:.0f} MB above it)")
        print(f"the log's own arrays in ehm: {own_mb:.0f} MB; peak / own: read {read_peak / own_mb:.2f}x, assess "
              f"{assess_peak / own_mb:.2f}x (goal: within 2x)")
        print(f"seat: a_v {seat['total_value_mps2']:.3f} m/s^2 ({seat['comfort_reaction']}), "
              f"a_w z {seat['axes']['z']['a_w_mps2']:.3f} m/s^2, VDV z {seat['axes']['z']['vdv_mps175']:.2f} m/s^1.75")


if __name__ == "__main__":
    main()
