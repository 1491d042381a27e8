"""Peak memory of `ehm simulate` on long drives: it streams its chunks to disk, so memory must not grow with
the drive's length (goal: a 60 min drive under 500 MB and within 1.2x of a 10 min drive).

Writes SYNTHETIC city drives (`ehm drive city`, 100 Hz, with vehicle rotation) of each length, runs
`ehm simulate --motion DRIVE --out RUN` for each in its own process and prints the process's peak resident
memory (ru_maxrss from wait4), wall time, real-time factor and the sizes of the files written.  For
comparison it also prints the peak of a process that only reads the drive file and integrates its rotation
(the input side, which holds the whole drive), after importing ehm and building the person as simulate does.

Usage: python benchmarks/bench_simulate_memory.py [--durations 600 3600] [--output-rate 200] [--format csv]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

_INPUT_ONLY = """
import sys
import ehm
from ehm.inputs.motion import seat_kinematics
from ehm.inputs.readers import load_motion_csv
human = ehm.SeatedHuman(rotating_seat=True)
human.settle()
motion = load_motion_csv(sys.argv[1])
kin = seat_kinematics(motion.time_s - motion.time_s[0], motion.angvel_radps)
"""


def _run(args: list[str], env: dict, log: Path) -> tuple[int, float, float]:
    """Run a command; returns (exit status, wall time [s], peak RSS [MB]) of that process alone."""
    t0 = time.perf_counter()
    with open(log, "w") as err:
        proc = subprocess.Popen(args, env=env, stdout=subprocess.DEVNULL, stderr=err)
        _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    return proc.returncode, time.perf_counter() - t0, usage.ru_maxrss / 1024  # Linux: kilobytes


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--durations", type=float, nargs="+", default=[600.0, 3600.0], help="drive lengths [s]")
    ap.add_argument("--output-rate", type=float, default=None, help="rows per second (default: ehm's default)")
    ap.add_argument("--format", default="csv", choices=("csv", "parquet", "both"))
    ap.add_argument("--keep", action="store_true", help="keep the run folders (printed)")
    args = ap.parse_args()
    src = Path(__file__).resolve().parents[1] / "src"
    env = {**os.environ, "PYTHONPATH": f"{src}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    ehm = [sys.executable, "-m", "ehm.interfaces.cli"]
    work = Path(tempfile.mkdtemp(prefix="ehm-bench-memory-"))
    peaks = {}
    for duration in args.durations:
        drive = work / f"city_{duration:g}.csv"
        subprocess.run(ehm + ["drive", "city", "--duration", f"{duration:g}", "--seed", "0", "--out", str(drive)],
                       env=env, check=True, stdout=subprocess.DEVNULL)
        _, _, input_peak = _run([sys.executable, "-c", _INPUT_ONLY, str(drive)], env, work / f"input_{duration:g}.log")
        out = work / f"run_{duration:g}"
        cmd = ehm + ["simulate", "--motion", str(drive), "--out", str(out), "--format", args.format]
        if args.output_rate:
            cmd += ["--output-rate", f"{args.output_rate:g}"]
        code, wall, peak = _run(cmd, env, work / f"run_{duration:g}.log")
        if code != 0:
            log = (work / f"run_{duration:g}.log").read_text()[-500:]
            print(f"{duration:g} s: ehm simulate failed (exit {code}): {log}")
            continue
        summary = json.loads((out / "summary.json").read_text())
        sizes = ", ".join(f"{p.name} {p.stat().st_size / 2**20:.0f} MB" for p in sorted(out.iterdir()))
        peaks[duration] = peak
        print(f"city drive {duration / 60:g} min (SYNTHETIC, with rotation): peak RSS {peak:.0f} MB "
              f"(reading the drive "
              f"and integrating its rotation alone: {input_peak:.0f} MB), wall {wall:.0f} s "
              f"({summary['realtime_factor']:.1f}x real time in the run), "
              f"{summary['output_rate_hz']:g} rows/s; {sizes}")
        if not args.keep:
            for p in out.iterdir():
                p.unlink()
            out.rmdir()
    if len(peaks) >= 2:
        lo, hi = min(peaks), max(peaks)
        met = peaks[hi] / peaks[lo] <= 1.2 and peaks[hi] < 500
        print(f"peak RSS ratio {hi / 60:g} min / {lo / 60:g} min: {peaks[hi] / peaks[lo]:.2f} "
              f"(goal: at most 1.2, and under 500 MB: {'met' if met else 'NOT met'})")
    print(f"files in {work}" if args.keep else "")


if __name__ == "__main__":
    main()
