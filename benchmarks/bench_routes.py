"""Real drives by each route: ``assess`` on the hybrid route (the default), the nonlinear route and, where it
runs, the linear route, against one continuous nonlinear run.

    python benchmarks/bench_routes.py [--realdata ../shared/realdata] [--hours 1] [--only bus,tram,car,city,vib]
                                      [--repeat 3] [--cold]

Drives:

* ``bus``, ``tram``: the ESP32 floor logs of a city bus (219 s) and a tram (240 s) from ``--realdata`` (500 Hz,
  gravity included; read with options only, as ``ehm assess`` reads them);
* ``car``: a phone on a car's windshield mount (406 s, about 51 Hz, gravity removed, earth-frame axes: the
  horizontal axes turn with the car's heading, which the seat-level a_v does not see but the body's response
  does);
* ``city``: a SYNTHETIC city drive of ``--hours`` (the shipped ``ehm.inputs.drives.city_drive``: rotating seat);
* ``vib``: SYNTHETIC three-axis random vibration, 1 m/s^2 rms, 60 s (``ehm.random_vibration``, 1 ms): the contacts
  slide under vibration rather than manoeuvres.

The recordings are read from their folder where they are; nothing of them is copied.  Printed per drive and
route: wall time of ``assess`` (the best of ``--repeat`` runs; the model built and linearised before, or with
``--cold`` built only, so that the time includes settling and linearising as a first call's does; reading
excluded), real-time factor,
the peak of Python allocations with ``--memory`` (a second run under tracemalloc; 0 without),
the share of the drive each model carried, and the largest relative difference of the seat, pelvis, trunk and
head a_v, VDV_z and MSDV_z and of the final MSI (head and seat) from the continuous nonlinear run, with
the figure it is.  Timings on a shared machine are noisy; run it alone.
"""

from __future__ import annotations

import argparse
import sys
import time
import tracemalloc
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

LOCATIONS = ("seat", "pelvis", "trunk", "head")


def drives(realdata: Path, hours: float, only: set):
    import ehm
    from ehm.inputs.drives import city_drive

    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the readers' notes (gravity levelled, irregular steps) are known here
        for name, file in (("bus", "etakerim_esp32_L35_1915_Borska_Zaluhy.csv"),
                           ("tram", "etakerim_esp32_L3_StnVinohrady_Riazanska.csv")):
            if name in only and (realdata / file).exists():
                out[name] = ehm.read_motion(realdata / file, channels={"time": None, "ax": "x", "ay": "y", "az": "z"},
                                            rate_hz=500)
        car = realdata / "driverbehavior_trip17_aceleracaoLinear_terra.csv"
        if "car" in only and car.exists():
            out["car"] = ehm.read_motion(car, channels={"time": "uptimeNanos", "ax": "x", "ay": "y", "az": "z"})
    if "city" in only:
        out["city"] = city_drive(hours * 3600.0, seed=0, dt_s=0.01)
    if "vib" in only:
        out["vib"] = ehm.random_vibration("xyz", 60.0, 1.0, seed=0, dt_s=0.001)
    return out


def figures(summary: dict) -> dict:
    """The figures compared: a_v, VDV_z, MSDV_z per location, final MSI (head, seat)."""
    out = {}
    for loc in LOCATIONS:
        v = summary["locations"][loc]
        out[f"{loc} a_v"] = v["total_value_mps2"]
        out[f"{loc} VDV_z"] = v["axes"]["z"]["vdv_mps175"]
        out[f"{loc} MSDV_z"] = v["msdv_z_mps15"]
    for k in ("head", "seat"):
        out[f"{k} MSI"] = summary["sickness"][k]["final_msi_percent"]
    return out


def person(motion, method: str, cold: bool):
    """The person for ``method``: built, and unless ``cold`` settled and linearised for it."""
    from ehm import SeatedHuman
    from ehm.analysis.assessment import needs_rotating_seat

    human = SeatedHuman(rotating_seat=needs_rotating_seat(motion, method))
    if not cold:
        if method != "nonlinear":
            turns = motion.angvel_radps is not None and bool((motion.angvel_radps != 0).any())
            human.linear_model(rotation=turns)
        human.settle()
    return human


def run(motion, method: str, memory: bool = False, repeat: int = 1, cold: bool = False):
    from ehm.analysis.assessment import assess

    human = person(motion, method, cold)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        wall = float("inf")
        for _ in range(repeat):
            if cold:
                human = person(motion, method, cold)
            t0 = time.perf_counter()
            result = assess(motion, human, method=method)
            wall = min(wall, time.perf_counter() - t0)
        peak = 0
        if memory:  # a second run under tracemalloc (which slows Python down several times)
            tracemalloc.start()
            assess(motion, human, method=method)
            peak = tracemalloc.get_traced_memory()[1]
            tracemalloc.stop()
    return result.summary(), wall, peak


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--realdata", default=str(Path(__file__).resolve().parents[2] / "shared" / "realdata"))
    ap.add_argument("--hours", type=float, default=1.0, help="length of the SYNTHETIC city drive [h]")
    ap.add_argument("--only", default="bus,tram,car,city,vib")
    ap.add_argument("--methods", default="auto,linear")
    ap.add_argument("--memory", action="store_true", help="also the peak of Python allocations (a second run each)")
    ap.add_argument("--repeat", type=int, default=1, help="the best of this many runs of each route")
    ap.add_argument("--cold", action="store_true",
                    help="time settling and linearising too (a fresh person for each run, as a first call)")
    args = ap.parse_args(argv)
    only = set(args.only.split(","))
    print(f"best of {args.repeat}, {'settling and linearising included' if args.cold else 'the person ready'}")
    print(f"{'drive':<6} {'length':>8} {'route':<9} {'wall':>8} {'x real':>7} {'linear':>7} "
          f"{'peak MB':>8}  largest difference from the continuous nonlinear run")
    for name, motion in drives(Path(args.realdata), args.hours, only).items():
        ref, wall, peak = run(motion, "nonlinear", args.memory, args.repeat, args.cold)
        base = figures(ref)
        print(f"{name:<6} {motion.duration_s:>7.0f}s {'nonlinear':<9} {wall:>7.1f}s {motion.duration_s / wall:>7.0f} "
              f"{0:>6.0%} {peak / 1e6:>8.0f}  (reference)", flush=True)
        for method in args.methods.split(","):
            try:
                got, wall, peak = run(motion, method, args.memory, args.repeat, args.cold)
            except Exception as exc:  # noqa: BLE001 - a route that refuses the drive is a result here
                print(f"{name:<6} {motion.duration_s:>7.0f}s {method:<9} refused: {exc}", flush=True)
                continue
            figs = figures(got)
            diffs = {k: (figs[k] - base[k]) / base[k] if base[k] else 0.0 for k in base}
            worst = max(diffs, key=lambda k: abs(diffs[k]))
            route = got.get("route", {})
            print(f"{name:<6} {motion.duration_s:>7.0f}s {method:<9} {wall:>7.1f}s {motion.duration_s / wall:>7.0f} "
                  f"{route.get('linear_share', 0):>6.0%} {peak / 1e6:>8.0f}  {diffs[worst]:+.2%} ({worst}); "
                  f"a_v head {diffs['head a_v']:+.2%}, MSI head {diffs['head MSI']:+.2%}", flush=True)
            if route:
                print(f"{'':<6} {route['summary_line']}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
