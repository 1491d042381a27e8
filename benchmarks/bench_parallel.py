"""A long nonlinear run in segments on local processes (:mod:`ehm.routes.parallel`): speed-up and accuracy.

Usage::

    python benchmarks/bench_parallel.py                     # speed: the default and 2 workers against one process
    python benchmarks/bench_parallel.py --city              # the SYNTHETIC 10-minute city drive (rotating seat)
    python benchmarks/bench_parallel.py --duration 1200     # a longer SYNTHETIC drive
    python benchmarks/bench_parallel.py --motion LOG.csv --rate 500 --no-time   # your own log (x, y, z columns)
    python benchmarks/bench_parallel.py --lead-in           # the lead-in measurement (module docstring of segments)

Speed: every configuration runs in a fresh Python process from the person's construction (building, settling,
worker start-up, resampling and joining all counted), so that wall time and peak memory (this process's and its
children's largest resident set) are what a user sees.  The configurations: one continuous run
(``simulate(motion, workers=1)``), the default (``simulate(motion)``: a drive of three minutes or more on the
machine's cores, ``ehm.routes.parallel.default_workers``) and ``simulate_parallel`` with 2 workers.
Accuracy: the segmented run against the continuous one,
per point rms(difference) / rms(continuous) over the run and over the 10 s after each join, and the relative
difference of a_v, VDV_z, MSDV_z (pelvis, trunk, head) and the head-driven final MSI.

The default drive is SYNTHETIC: ``ehm.rough_road`` (class C road at 15 m/s, with the seat's pitch and roll: the
rotating seat) of ``--duration`` s.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

POINTS = ("pelvis", "trunk", "head")
JOIN_WINDOW_S = 10.0


def _motion(args):
    import ehm

    if args.motion:
        channels = {"time": None, "ax": "x", "ay": "y", "az": "z"} if args.no_time else None
        return ehm.read_motion(args.motion, channels=channels, rate_hz=args.rate)
    if args.city:
        return ehm.city_drive(args.duration)
    return ehm.rough_road(args.duration)


def _human(motion):
    import ehm

    return ehm.SeatedHuman(rotating_seat=motion.angvel_radps is not None)


# --- accuracy -------------------------------------------------------------------------------------------------------

def _replay(run):
    """A ``stream`` that replays a finished run in the chunks :func:`ehm.assess` asks for."""
    def stream(motion, chunk_s, progress=None, **kw):
        n = int(round(chunk_s / run.dt_s))
        for lo in range(0, run.time_s.size, n):
            yield run.take(slice(lo, lo + n))
    return stream


def _figures(motion, human, run) -> dict:
    import warnings

    from ehm.analysis.assessment import assess

    human.stream = _replay(run)  # this person's own stream, for the one call: the figures of the finished run
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            a = assess(motion, human)
    finally:
        del human.stream
    out = {}
    for p in POINTS:
        out[f"a_v {p}"] = a.total_value(p)
        out[f"VDV_z {p}"] = a.metrics[p]["z"].vdv
        out[f"MSDV_z {p}"] = a.metrics[p]["z"].msdv
    out["final MSI"] = a.sickness["head"].final_msi_percent
    return out


def compare(motion, human, cont, seg, joins_s) -> dict:
    """Differences of a segmented run ``seg`` from the continuous ``cont`` (shares, not percent)."""
    if not np.array_equal(cont.time_s, seg.time_s):
        raise AssertionError("the segmented run's time axis is not the continuous one's")
    out = {}
    for p in POINTS:
        a, b = cont.point(p).acc_mps2, seg.point(p).acc_mps2
        out[f"acc {p}"] = float(np.sqrt(np.mean((a - b) ** 2)) / np.sqrt(np.mean(a ** 2)))
        axis = np.sqrt(np.mean((a - b) ** 2, axis=0)) / np.sqrt(np.mean(a ** 2, axis=0))
        out[f"acc {p} worst axis"] = float(axis.max())
        out[f"acc {p} worst axis name"] = "xyz"[int(axis.argmax())]
        worst = worst_axis = 0.0
        for j in joins_s:
            w = (cont.time_s >= j) & (cont.time_s < j + JOIN_WINDOW_S)
            worst = max(worst, float(np.sqrt(np.mean((a[w] - b[w]) ** 2)) / np.sqrt(np.mean(a[w] ** 2))))
            worst_axis = max(worst_axis, float(np.max(np.sqrt(np.mean((a[w] - b[w]) ** 2, axis=0))
                                                      / np.sqrt(np.mean(a[w] ** 2, axis=0)))))
        out[f"acc {p} after join"] = worst
        out[f"acc {p} worst axis after join"] = worst_axis
    fc, fs = _figures(motion, human, cont), _figures(motion, human, seg)
    for k in fc:
        out[k] = abs(fs[k] - fc[k]) / abs(fc[k]) if fc[k] else abs(fs[k])
    return out


def measure_lead_in(args) -> None:
    """Segmented (4 segments on 2 workers) against continuous, for several lead-ins, with and without ramp-in."""
    from ehm.outputs.results import concatenate_runs
    from ehm.routes import parallel as segments
    from ehm.routes.parallel import stream_parallel

    segments.WORKER_START_S = 0.0  # segments of equal length, so that every join sits where the table says

    drives = []
    bus = Path("/work/shared/realdata/etakerim_esp32_L35_1915_Borska_Zaluhy.csv")
    if "bus" in args.drives and (args.motion or bus.exists()):
        import ehm

        log = ehm.read_motion(args.motion or bus, channels={"time": None, "ax": "x", "ay": "y", "az": "z"},
                              rate_hz=args.rate or 500)
        drives.append(("bus log (measured, 219 s)", log))
    import ehm

    if "city" in args.drives:
        drives.append((f"city drive (SYNTHETIC, {args.city_s:g} s, rotating seat)", ehm.city_drive(args.city_s)))
    rows = []
    for name, motion in drives:
        human = _human(motion)
        human.settle()
        cont = human.simulate(motion)
        for ramp in ((False, True) if args.ramp else (False,)):
            for lead in args.lead_ins:
                stats = {}
                t0 = time.perf_counter()
                seg = concatenate_runs(list(stream_parallel(human, motion, workers=2, lead_in_s=lead,
                                                            segment_s=motion.duration_s / 4 * 1.001, _ramp=ramp,
                                                            _stats=stats)))
                wall = time.perf_counter() - t0
                joins = [s.first * cont.dt_s for s in stats["segments"][1:]]
                diff = compare(motion, human, cont, seg, joins)
                rows.append({"drive": name, "ramp": ramp, "lead_in_s": lead, "wall_s": wall, **diff})
                nums = {k: v for k, v in diff.items() if not isinstance(v, str)}
                worst = max(v for k, v in nums.items() if "join" not in k and "acc" not in k)
                print(f"{name}: lead-in {lead:4g} s{' ramp' if ramp else '     '}: figures worst {100 * worst:6.3f} % "
                      + " ".join(f"{k}={100 * v:.3f}%" for k, v in nums.items()), flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))


# --- speed ----------------------------------------------------------------------------------------------------------

def one(args) -> dict:
    """One configuration in this (fresh) process: build, settle, run; wall time and peak memory."""
    from ehm.outputs.results import concatenate_runs
    from ehm.routes.parallel import stream_parallel

    motion = _motion(args)
    stats = {}
    t_epoch, t0, cpu0 = time.time(), time.perf_counter(), time.process_time()
    human = _human(motion)
    if args.workers == 0:  # one continuous run
        run = human.simulate(motion, workers=1)
    elif args.workers == -1:  # as a user calls it
        run = human.simulate(motion)
    else:
        run = concatenate_runs(list(stream_parallel(human, motion, workers=args.workers, lead_in_s=args.lead_in_s,
                                                    _stats=stats)))
    wall = time.perf_counter() - t0
    cpu = time.process_time() - cpu0 + sum(resource.getrusage(resource.RUSAGE_CHILDREN)[:2])
    tasks = stats.get("tasks", [])
    phases = {"segments": len(stats.get("segments", [])) or 1, "cpu_s": cpu,
              "first_segment_end_s": stats["first_end"] - t_epoch if "first_end" in stats else None,
              "worker_start_s": [t["start"] - t["submitted"] for t in tasks],
              "worker_build_s": [t["build_s"] for t in tasks],
              "worker_end_s": [t["end"] - t_epoch for t in tasks],
              "transfer_s": [t["received"] - t["end"] for t in tasks]}
    peak_self = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    peak_children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    np.save(args.save, np.hstack([run.point(p).acc_mps2 for p in POINTS]))
    return {"workers": args.workers, "wall_s": wall, "duration_s": run.duration_s, "peak_mb": peak_self,
            "peak_worker_mb": peak_children, "run_wall_s": run.wall_s, "figures": _figures(motion, human, run),
            **phases}


def measure_speed(args) -> None:
    import tempfile

    base = [sys.executable, __file__, "--one", "--duration", str(args.duration)]
    if args.motion:
        base += ["--motion", args.motion] + (["--rate", str(args.rate)] if args.rate else []) + \
                (["--no-time"] if args.no_time else [])
    if args.city:
        base.append("--city")
    if args.lead_in_s is not None:
        base += ["--lead-in-s", str(args.lead_in_s)]
    configs = (0, -1, 2)
    res, walls = {}, {w: [] for w in configs}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.repeat):  # rounds of all three, interleaved: on a shared machine the best of each
            for w in configs:
                out = subprocess.run(base + ["--workers", str(w), "--save", f"{tmp}/acc{w}.npy"],
                                     capture_output=True, text=True, check=True)
                r = json.loads(out.stdout.strip().splitlines()[-1])
                walls[w].append(r["wall_s"])
                if w not in res or r["wall_s"] < res[w]["wall_s"]:
                    res[w] = r
        acc = {w: np.load(f"{tmp}/acc{w}.npy") for w in res}
    c = res[0]
    print(f"drive: {c['duration_s']:.0f} s; wall time from building the person (settling, worker start-up, joining "
          f"included); best of {args.repeat} interleaved rounds (all rounds: "
          + "; ".join(f"{w}: " + "/".join(f"{x:.1f}" for x in v) for w, v in walls.items()) + " s)")
    for w, r in res.items():
        label = {0: "one process (workers=1)", -1: "default (simulate(motion))"}.get(
            w, f"simulate_parallel, {w} worker{'s' if w > 1 else ''}")
        d = np.abs(acc[w] - acc[0])
        share = max(np.sqrt(np.mean(d[:, 3 * i:3 * i + 3] ** 2)) / np.sqrt(np.mean(acc[0][:, 3 * i:3 * i + 3] ** 2))
                    for i in range(3))
        print(f"  {label:<30} {r['wall_s']:7.2f} s  {r['duration_s'] / r['wall_s']:5.1f}x real time  "
              f"speed-up {c['wall_s'] / r['wall_s']:4.2f}x  CPU {r['cpu_s']:6.2f} s  peak {r['peak_mb']:4.0f} MB "
              f"here, {r['peak_worker_mb']:4.0f} MB largest child  acc difference {100 * share:.3f} % of rms")
        if w != 0:
            worst = max(abs(r["figures"][k] - c["figures"][k]) / abs(c["figures"][k]) for k in c["figures"]
                        if c["figures"][k])
            name = max((k for k in c["figures"] if c["figures"][k]),
                       key=lambda k: abs(r["figures"][k] - c["figures"][k]) / abs(c["figures"][k]))
            print(f"      figures (a_v, VDV_z, MSDV_z of pelvis, trunk, head; final MSI): worst {100 * worst:.3f} % "
                  f"of the one-process run's ({name})")
        if r["worker_start_s"]:
            f = lambda xs: "/".join(f"{x:.2f}" for x in xs)  # noqa: E731
            print(f"      {r['segments']} segments; first (here) done at {r['first_segment_end_s']:.2f} s; worker "
                  f"start-up {f(r['worker_start_s'])} s (building the person {f(r['worker_build_s'])} s), done at "
                  f"{f(r['worker_end_s'])} s, result handed back in {f(r['transfer_s'])} s")
    print(f"load average while measuring: {', '.join(f'{x:.2f}' for x in __import__('os').getloadavg())} "
          "(1, 5, 15 min; 2 cores)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=600.0, help="SYNTHETIC drive length [s] (default 600)")
    ap.add_argument("--city", action="store_true", help="the SYNTHETIC city drive (rotating seat) instead")
    ap.add_argument("--motion", help="a log of your own instead")
    ap.add_argument("--rate", type=float, help="its sample rate [Hz] when it has no time column")
    ap.add_argument("--no-time", action="store_true", help="its columns are x, y, z without time")
    ap.add_argument("--lead-in", action="store_true", help="measure the lead-in instead of the speed")
    ap.add_argument("--lead-ins", type=float, nargs="+", default=[1, 2, 5, 10, 20])
    ap.add_argument("--lead-in-s", type=float, help="lead-in for the speed runs (default: ehm's)")
    ap.add_argument("--repeat", type=int, default=3, help="interleaved rounds of the speed runs (default 3)")
    ap.add_argument("--json", help="write the lead-in table here")
    ap.add_argument("--drives", nargs="+", default=["bus", "city"], help="--lead-in: bus (the log) and/or city")
    ap.add_argument("--city-s", type=float, default=60.0, help="--lead-in: the city drive's length [s] (default 60)")
    ap.add_argument("--ramp", action="store_true", help="--lead-in: also with the input faded in over the lead-in")
    ap.add_argument("--one", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--workers", type=int, default=0, help=argparse.SUPPRESS)  # 0: one process, -1: the default
    ap.add_argument("--save", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        print(json.dumps(one(args)))
    elif args.lead_in:
        measure_lead_in(args)
    else:
        measure_speed(args)


if __name__ == "__main__":
    main()
