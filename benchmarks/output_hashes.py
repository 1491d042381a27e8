"""SHA-256 of ehm's outputs, to show that a change of structure leaves behaviour unchanged.

Run it before and after a refactoring and compare the lines: each names one output and the hash of its numbers
(arrays as little-endian float64 bytes; summaries without wall-clock fields).  The inputs are SYNTHETIC.

    python benchmarks/output_hashes.py > before.txt   # ... change ...
    python benchmarks/output_hashes.py > after.txt && diff before.txt after.txt

It takes a few seconds; with ``--fmu`` also the native FMU's outputs through fmpy (needs a C compiler and the
``fmu`` extra; about 15 s more).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import tempfile
from pathlib import Path

import numpy as np

import ehm

WALL_KEYS = {"wall_s", "realtime_factor", "throughput_simulated_s_per_s", "written_utc"}


def _digest(*arrays) -> str:
    h = hashlib.sha256()
    for a in arrays:
        h.update(np.ascontiguousarray(np.asarray(a, dtype="<f8")).tobytes())
    return h.hexdigest()[:16]


def _without_wall(obj):
    if isinstance(obj, dict):
        return {k: _without_wall(v) for k, v in sorted(obj.items()) if k not in WALL_KEYS}
    if isinstance(obj, list):
        return [_without_wall(v) for v in obj]
    return obj


def _json_digest(obj) -> str:
    return hashlib.sha256(json.dumps(_without_wall(obj), sort_keys=True).encode()).hexdigest()[:16]


def _run_digest(run) -> str:
    arrays = [run.time_s, run.seat_acc_mps2]
    for p in sorted(run.points):
        m = run.points[p]
        arrays += [m.acc_mps2, m.disp_m, m.rot_rad, m.angacc_radps2]
    arrays += [run.support_N[k] for k in sorted(run.support_N)]
    if run.seat_angles_rad is not None:
        arrays.append(run.seat_angles_rad)
    return _digest(*arrays)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu", action="store_true", help="also the native FMU's outputs (fmpy, a C compiler)")
    args = parser.parse_args()
    human = ehm.SeatedHuman()
    human.settle()
    motion = ehm.random_vibration("xyz", duration_s=6.0, rms_mps2=0.3, seed=3)
    static = human.simulate(motion, pose_rate_hz=25.0)
    print("static run          ", _run_digest(static))
    print("static summary      ", _json_digest(static.summary()))
    print("poses               ", _digest(static.poses["time_s"], static.poses["pos"], static.poses["quat"]))
    linear = human.simulate(motion, method="linear")
    print("linear-route run    ", _run_digest(linear))
    rotating = ehm.SeatedHuman(rotating_seat=True)
    drive = ehm.city_drive(12.0, seed=1)
    print("rotating run        ", _run_digest(rotating.simulate(drive)))
    assessed = ehm.assess(drive, rotating)
    print("assess summary      ", _json_digest(assessed.summary()))
    with tempfile.TemporaryDirectory() as tmp:
        human.simulate_to(Path(tmp) / "run", motion)
        print("simulate_to summary ", _json_digest(json.loads((Path(tmp) / "run" / "summary.json").read_text())))
        print("simulate_to csv     ", hashlib.sha256((Path(tmp) / "run" / "timeseries.csv").read_bytes())
              .hexdigest()[:16])
        if args.fmu:
            from fmpy import simulate_fmu

            from ehm.interfaces.fmu import export_fmu

            unit = export_fmu(Path(tmp) / "person.fmu")
            t = np.arange(0.0, 2.0, 0.001)
            names = ["seat_ax_mps2", "seat_ay_mps2", "seat_az_mps2", "seat_wx_radps", "seat_wy_radps", "seat_wz_radps"]
            signal = np.zeros(len(t), dtype=[("time", "<f8")] + [(n, "<f8") for n in names])
            signal["time"], signal["seat_az_mps2"] = t, 0.5 * np.sin(2 * np.pi * 4.0 * t)
            signal["seat_ax_mps2"] = 0.3 * np.sin(2 * np.pi * 1.5 * t)
            res = simulate_fmu(str(unit), stop_time=1.99, step_size=0.001, input=signal, output_interval=0.001)
            print("native FMU outputs  ", _digest(*(res[n] for n in res.dtype.names)))


if __name__ == "__main__":
    main()
