"""Real-time factor and accuracy, side by side: a 35 s three-axis run of the default person at each step.

For each time step (default: the model's own, 0.5 ms) prints the wall time of 35 s of 0.3 m/s^2 rms random
vibration on x, y and z at once (best of --repeat), the real-time factor, the cost per step and peak
memory, and the accuracy of that step: the worst seat-to-body transfer function against the same model at
step / 8 (``ehm check-step``).  With --rotating, also a SYNTHETIC city drive with seat rotation.
The paper's EHM took 30 s for 35 s (1.2x); its detailed active human model 3 h.

The stepping loop is compiled (``ehm.engine.native``); ``EHM_NATIVE_STEPS=0`` in the environment times the Python
loop instead (the same numbers).  ``--posture slouched`` times another posture at its own default step.

Usage: python benchmarks/bench_realtime.py [--dt 0.0005 0.001] [--repeat 3] [--rotating] [--posture slouched]
"""

from __future__ import annotations

import argparse
import resource
import time
import warnings

import ehm
from ehm.analysis.convergence import StepWarning, check_step
from ehm.engine import native_steps_available
from ehm.inputs.drives import city_drive


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--dt", type=float, nargs="+", default=[None])
    ap.add_argument("--duration", type=float, default=35.0)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--rotating", action="store_true", help="also a 35 s synthetic city drive with seat rotation")
    ap.add_argument("--posture", help="a posture of the parameter file (default: the file's own, erect)")
    ap.add_argument("--back-support", help="a back support of the parameter file (default: the file's own)")
    ap.add_argument("--method", default="nonlinear", choices=("nonlinear", "auto", "linear"),
                    help="the route timed (default nonlinear: MuJoCo every step; auto: the default hybrid route)")
    args = ap.parse_args()
    warnings.simplefilter("ignore", StepWarning)  # coarse steps are measured on purpose; their error is printed
    native = "compiled" if native_steps_available() else "Python"
    print(f"ehm {ehm.__version__}: {args.duration:g} s of 0.3 m/s^2 rms random vibration on x, y and z, "
          f"{args.method} route, best of {args.repeat}; {native} stepping loop"
          + (f"; posture {args.posture}" if args.posture else "")
          + (f", back support {args.back_support}" if args.back_support else ""))
    seat = {"posture": args.posture, "back_support": args.back_support}
    for dt in args.dt:
        t0 = time.perf_counter()
        human = ehm.SeatedHuman(dt_s=dt, **seat)
        human.settle()
        setup = time.perf_counter() - t0
        dt = float(human.params.value("simulation.dt_s"))
        motion = ehm.random_vibration("xyz", args.duration, 0.3, seed=0, dt_s=dt)
        best = min(human.simulate(motion, method=args.method).wall_s for _ in range(args.repeat))
        peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        path, err = check_step(ehm.Person(**{k: v for k, v in seat.items() if v}), dt_s=dt, ratios=(8,)).worst(8)
        print(f"dt {dt * 1000:g} ms: run wall {best:.2f} s, real-time factor {args.duration / best:.1f}x, "
              f"{best / (args.duration / dt) * 1e6:.1f} us per step (build + settle {setup:.2f} s, peak memory "
              f"{peak_mb:.0f} MB); accuracy: worst transfer function {100 * err:.1f} % of its peak from dt/8 "
              f"(seat {path[0]} -> {path[1]} {path[2]})")
        if args.rotating:
            rot = ehm.SeatedHuman(dt_s=dt, rotating_seat=True, **seat)
            rot.settle()
            drive = city_drive(args.duration, seed=0)
            best = min(rot.simulate(drive, method=args.method).wall_s for _ in range(args.repeat))
            print(f"   rotating seat, SYNTHETIC city drive: run wall {best:.2f} s, real-time factor "
                  f"{args.duration / best:.1f}x")


if __name__ == "__main__":
    main()
