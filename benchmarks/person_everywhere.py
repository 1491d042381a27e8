"""The person on every posture and back support: the figures of "a person that holds wherever a user puts it".

Prints Markdown tables, one per part (``--parts`` picks them; default all):

``linear``
    The linearised person at rest (exact frequency response, 0.1-20 Hz): how many of the bands of
    ``ehm.validate`` that apply there pass in each condition and which fail, the vertical apparent mass (every
    support) over its 0.5 Hz value at 10 Hz and its largest value over 15-20 Hz, the apparent-mass and seat-to-head
    vertical peaks, and the seat-to-head fore-aft and lateral peaks (gain, frequency).
``horizontal``
    Seat-to-head fore-aft and lateral H1 peaks from 60 s random runs at 0.3 m/s^2 rms (0.1-12 Hz), nonlinear
    route against the linear route with the same input.
``level``
    The vertical apparent-mass resonance (H1, every support, 0.5-12 Hz input) on the nonlinear route at 0.25, 1
    and 2 m/s^2 rms, and its fall from 0.25 to 2 m/s^2; the linear route at the same levels beside it.
``foreaft``
    The head's motion under fore-aft random vibration, 0.5-10 Hz, 0.5 m/s^2 rms, 60 s, nonlinear route:
    rms of the head's fore-aft acceleration, its fore-aft displacement relative to the seat and its pitch.
``city``
    The shipped city drive (``ehm.city_drive``) assessed on each seat: whether it runs to its end, and the head's
    peak displacement on the seat.

Every input is SYNTHETIC (ehm's random vibration and city drive).  The nonlinear parts take minutes.

    python benchmarks/person_everywhere.py                      # every part
    python benchmarks/person_everywhere.py --parts linear,level
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import ehm
from ehm.analysis.frf import linear_frf
from ehm.analysis.validation import FREQ_HZ, band_checks, bands_applying

POSTURES = ("erect", "slouched")
SUPPORTS = ("none", "low", "high", "full")
LEVELS_MPS2 = (0.25, 1.0, 2.0)


def _peak(curve, lo: float, hi: float) -> tuple[float, float]:
    f, g = np.asarray(curve.freq_hz), np.asarray(curve.gain)
    sel = (f >= lo - 1e-9) & (f <= hi + 1e-9)
    k = int(np.argmax(g[sel]))
    return float(g[sel][k]), float(f[sel][k])


def _person(posture: str, support: str, level: float | None = None) -> ehm.SeatedHuman:
    if level is None:
        return ehm.SeatedHuman(posture=posture, back_support=support)
    return ehm.SeatedHuman(ehm.Person(posture=posture, back_support=support, vibration_rms_mps2=level))


def _level_supported() -> bool:
    return "vibration_rms_mps2" in getattr(ehm.Person, "__dataclass_fields__", {})


def part_linear(conditions) -> str:
    lines = ["| posture | back | bands passed | failed | AM 10 Hz | AM 15-20 Hz | AM peak (Hz) | head z peak (Hz) | "
             "head x peak (Hz) | head y peak (Hz) |", "|---|---|---|---|---|---|---|---|---|---|"]
    for post, back in conditions:
        t = linear_frf(_person(post, back), "all", freq_hz=FREQ_HZ)
        checks = band_checks(t, f"{post}, {back}", bands_applying(post, back))
        failed = [c.name for c in checks if not c.passed]
        am = t.curve("z", "support", "z")
        f, g = np.asarray(am.freq_hz), np.asarray(am.gain)
        g = g / np.interp(0.5, f, g)
        at10 = float(np.interp(10.0, f, g))
        hi = float(g[(f >= 15 - 1e-9) & (f <= 20 + 1e-9)].max())
        sel = (f >= 0.5) & (f <= 20)
        k = int(np.argmax(g[sel]))
        hz = _peak(t.curve("z", "head", "z"), 0.5, 20)
        hx = _peak(t.curve("x", "head", "x"), 0.5, 12)
        hy = _peak(t.curve("y", "head", "y"), 0.5, 12)
        lines.append(f"| {post} | {back} | {len(checks) - len(failed)} of {len(checks)} | {', '.join(failed) or '-'} | "
                     f"{at10:.2f} | {hi:.2f} | {g[sel][k]:.2f} ({f[sel][k]:.2f}) | {hz[0]:.2f} ({hz[1]:.2f}) | "
                     f"{hx[0]:.2f} ({hx[1]:.2f}) | {hy[0]:.2f} ({hy[1]:.2f}) |")
    return "\n".join(lines)


def part_horizontal(conditions) -> str:
    lines = ["| posture | back | head x nonlinear (Hz) | head x linear (Hz) | head y nonlinear (Hz) | "
             "head y linear (Hz) | worst linear vs nonlinear, 0.5-3 Hz |", "|---|---|---|---|---|---|---|"]
    for post, back in conditions:
        h = _person(post, back)
        cells, worst = [], 0.0
        for axis in ("x", "y"):
            nl = ehm.time_domain_frf(h, axis, duration_s=60.0, rms_mps2=0.3, route="nonlinear")
            li = ehm.time_domain_frf(h, axis, duration_s=60.0, rms_mps2=0.3, route="linear")
            a, b = nl.curve(axis, "head", axis), li.curve(axis, "head", axis)
            cells += [_peak(a, 0.5, 12), _peak(b, 0.5, 12)]
            f = np.asarray(a.freq_hz)
            sel = (f >= 0.5) & (f <= 3.0)
            worst = max(worst, float(np.max(np.abs(np.asarray(b.gain)[sel] / np.asarray(a.gain)[sel] - 1))))
        lines.append(f"| {post} | {back} | " + " | ".join(f"{g:.2f} ({fr:.2f})" for g, fr in cells)
                     + f" | {100 * worst:.1f} % |")
    return "\n".join(lines)


def _am_resonance(table) -> float:
    return _peak(table.curve("z", "support", "z"), 2.0, 12.0)[1]


def part_level(conditions) -> str:
    levels = LEVELS_MPS2
    head = " | ".join(f"{lv:g} m/s^2" for lv in levels)
    lines = [f"| posture | back | route | {head} | fall 0.25 -> 2 |", "|---|---|---|" + "---|" * len(levels) + "---|"]
    for post, back in conditions:
        for route in ("nonlinear", "linear"):
            hz = []
            for lv in levels:
                h = _person(post, back, lv if _level_supported() else None)
                t = ehm.time_domain_frf(h, "z", duration_s=60.0, rms_mps2=lv, route=route, band_hz=(0.5, 12.0))
                hz.append(_am_resonance(t))
            lines.append(f"| {post} | {back} | {route} | " + " | ".join(f"{x:.2f} Hz" for x in hz)
                         + f" | {100 * (1 - hz[-1] / hz[0]):.0f} % |")
    return "\n".join(lines)


def part_foreaft(conditions) -> str:
    lines = ["| posture | back | head x acc rms [m/s^2] | head x disp rms [mm] | head pitch rms [deg] |",
             "|---|---|---|---|---|"]
    for post, back in conditions:
        h = _person(post, back)
        motion = ehm.random_vibration("x", 60.0, 0.5, seed=1, dt_s=float(h.params.value("simulation.dt_s")),
                                      band_hz=(0.5, 10.0))
        run = h.simulate(motion, method="nonlinear")
        p = run.point("head")
        n0 = int(5.0 / run.dt_s)
        acc = np.sqrt(np.mean(p.acc_mps2[n0:, 0] ** 2))
        disp = np.sqrt(np.mean((p.disp_m[n0:, 0] - p.disp_m[n0:, 0].mean()) ** 2))
        pitch = np.sqrt(np.mean((p.rot_rad[n0:, 1] - p.rot_rad[n0:, 1].mean()) ** 2))
        lines.append(f"| {post} | {back} | {acc:.3f} | {1000 * disp:.2f} | {np.degrees(pitch):.3f} |")
    return "\n".join(lines)


def part_city(conditions) -> str:
    lines = ["| posture | back | runs to the end | note |", "|---|---|---|---|"]
    motion = ehm.city_drive()
    for post, back in conditions:
        try:
            ehm.assess(motion, ehm.Person(posture=post, back_support=back))
            lines.append(f"| {post} | {back} | yes | |")
        except ehm.EhmError as e:
            lines.append(f"| {post} | {back} | no | {str(e)[:160]} |")
    return "\n".join(lines)


PARTS = {"linear": part_linear, "horizontal": part_horizontal, "level": part_level, "foreaft": part_foreaft,
         "city": part_city}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--parts", default=",".join(PARTS), help="comma-separated: " + ", ".join(PARTS))
    ap.add_argument("--postures", default=",".join(POSTURES))
    ap.add_argument("--supports", default=",".join(SUPPORTS))
    args = ap.parse_args(argv)
    conditions = [(p, s) for p in args.postures.split(",") for s in args.supports.split(",")]
    for name in args.parts.split(","):
        t0 = time.perf_counter()
        print(f"## {name}\n\n{PARTS[name](conditions)}\n\n({time.perf_counter() - t0:.0f} s)\n", flush=True)


if __name__ == "__main__":
    main()
