"""The linear route against the nonlinear one: speed and accuracy of a 35 s three-axis run.

Prints, for 35 s of 0.3 m/s^2 rms random vibration on x, y and z at once (sampled at 1 ms and at the
model's 0.5 ms step): the one-time cost of the linear model (linearisation and conversion to continuous
time) and of its discretisation at the sample step, the wall time of the run itself (the whole ``simulate``
call: the process's first one, which also first touches its memory, then best and median of --repeat) and
its real-time factor, and the accuracy: rms difference of the pelvis, trunk and head accelerations from
the nonlinear (MuJoCo) route on the same motion, as a share of their rms.

BLAS threads as installed: the routes keep their own small matrix products on one BLAS thread (threadpoolctl), so the
environment need not say anything.  With --busy a second process keeps one core busy meanwhile (what a user's
other work, or a Dask worker beside this one, does), where a threaded BLAS loses most.

Usage: python benchmarks/bench_linear.py [--duration 35] [--repeat 20] [--busy]
"""

from __future__ import annotations

import argparse
import multiprocessing
import resource
import time

import numpy as np
from threadpoolctl import threadpool_info

import ehm
from ehm.routes import linear


def _spin() -> None:
    """Keep one core busy (--busy)."""
    while True:
        pass


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--duration", type=float, default=35.0)
    ap.add_argument("--repeat", type=int, default=20)
    ap.add_argument("--busy", action="store_true", help="keep one other core busy while timing")
    args = ap.parse_args()
    busy = None
    if args.busy:
        busy = multiprocessing.Process(target=_spin, daemon=True)
        busy.start()
    human = ehm.SeatedHuman()
    human.settle()
    t0 = time.perf_counter()
    ss = human.linear_model()
    built = time.perf_counter() - t0
    modes = linear.modal_form(ss)
    n_states = modes.n_real + 2 * (modes.lam.size - modes.n_real)
    blas = ", ".join(f"{i['internal_api']} {i['num_threads']} threads" for i in threadpool_info()
                     if i["user_api"] == "blas") or "none found"
    print(f"ehm {ehm.__version__}, BLAS as installed ({blas}; the routes use one), "
          f"{'one other core busy' if busy else 'machine otherwise idle'}: linear model {ss.A.shape[0]} "
          f"states, {len(ss.output_names)} outputs, built in {built:.2f} s after settling (linearised at "
          f"{ss.linearised_at_step_s * 1e6:.1f} us); time runs use {n_states} states ({modes.unreached} not "
          f"reached by the input left out, {len(modes.static_hz)} above {linear.STATIC_ABOVE_HZ:g} Hz static)")
    for dt in sorted({0.001, float(human.params.value("simulation.dt_s"))}):  # 1 ms samples and the model's step
        motion = ehm.random_vibration("xyz", args.duration, 0.3, seed=0, dt_s=dt)
        t0 = time.perf_counter()
        linear.block_form(ss, dt)  # what the first run at this step computes once
        disc = time.perf_counter() - t0
        t0 = time.perf_counter()
        lin = human.simulate(motion, method="linear")
        first = time.perf_counter() - t0
        walls = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            lin = human.simulate(motion, method="linear")
            walls.append(time.perf_counter() - t0)
        best, median = min(walls), float(np.median(walls))
        t0 = time.perf_counter()
        nl = human.simulate(motion, method="nonlinear")
        wall_nl = time.perf_counter() - t0
        errs = []
        every = int(round(dt / nl.dt_s))  # the nonlinear run is sampled at the model's step
        for p in ("pelvis", "trunk", "head"):
            a, b = nl.point(p).acc_mps2[::every], lin.point(p).acc_mps2
            errs.append(np.sqrt(np.mean((a - b) ** 2, axis=0)) / np.sqrt(np.mean(a ** 2, axis=0)))
        errs = 100 * np.array(errs)
        print(f"samples every {dt * 1e3:g} ms: linear run {best * 1e3:.1f} ms best of {args.repeat} (median "
              f"{median * 1e3:.1f} ms; {args.duration / best:.0f}x real time; the process's first run "
              f"{first * 1e3:.0f} ms; discretisation once {disc * 1e3:.0f} ms), nonlinear {wall_nl:.2f} s "
              f"({args.duration / wall_nl:.0f}x); acceleration rms difference pelvis/trunk/head x,y,z: "
              + ", ".join("/".join(f"{e:.1f}" for e in row) for row in errs) + " %")
    print(f"peak memory {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB")
    if busy is not None:
        busy.terminate()


if __name__ == "__main__":
    main()
