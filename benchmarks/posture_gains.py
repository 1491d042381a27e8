"""Seat-to-pelvis, trunk and head gains of erect and slouched posture on no, low and high back support.

Prints the Markdown tables of docs/model.md "Postures and back supports": for each input axis (fore-aft x, lateral
y, vertical z) and point, the in-axis translation (m/s^2 per m/s^2) and the main rotation (rad/s^2 per m/s^2:
pitch for x and z, roll for y); per condition the peak gain with its frequency, and the mean gain over 0.5-2 Hz,
where the measurements (Mirakhorlo et al. 2022) find posture and back support matter most.  The exact frequency
response of each person linearised at rest (ehm.analysis.frf.linear_frf: the response to small inputs such as the
measurements' 0.3 m/s^2), 0.1-12 Hz.  Takes about ten seconds.  ``--figures DIR`` also draws the gains, one
grid per input axis (ehm.outputs.plotting.plot_frf_grid), into DIR/posture_gains_{x,y,z}.png.

    python benchmarks/posture_gains.py > gains.md
    python benchmarks/posture_gains.py --figures figures > gains.md
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import ehm
from ehm.analysis.frf import linear_frf

POSTURES = ("erect", "slouched")
SUPPORTS = ("none", "low", "high")
PATHS = [(axis, point, dof) for axis, rot in (("x", "pitch"), ("y", "roll"), ("z", "pitch"))
         for point in ("pelvis", "trunk", "head") for dof in (axis, rot)]
BAND_HZ = (0.5, 2.0)


def tables(postures=POSTURES, supports=SUPPORTS) -> dict:
    """(posture, support) -> the person's linear FrfTable, 0.1-12 Hz in 0.05 Hz steps."""
    f = np.arange(0.1, 12.0 + 1e-9, 0.05)
    return {(p, s): linear_frf(ehm.SeatedHuman(posture=p, back_support=s), freq_hz=f)
            for p in postures for s in supports}


def gains(frfs: dict) -> dict:
    """(posture, support) -> path -> (peak gain, peak frequency [Hz], mean gain over BAND_HZ)."""
    out = {}
    for key, table in frfs.items():
        f = table.curve(*PATHS[0]).freq_hz
        band = (f >= BAND_HZ[0] - 1e-9) & (f <= BAND_HZ[1] + 1e-9)
        out[key] = {}
        for path in PATHS:
            g = table.curve(*path).gain
            k = int(np.argmax(g))
            out[key][path] = (float(g[k]), float(f[k]), float(g[band].mean()))
    return out


def markdown(result: dict) -> str:
    conditions = list(result)
    head = "| input | point | output | " + " | ".join(f"{p} {s}" for p, s in conditions) + " |"
    rule = "|---|---|---|" + "---|" * len(conditions)
    lines = ["Peak gain (frequency in Hz):", "", head, rule]
    for path in PATHS:
        cells = [f"{result[c][path][0]:.3g} ({result[c][path][1]:.2g})" for c in conditions]
        lines.append(f"| {path[0]} | {path[1]} | {path[2]} | " + " | ".join(cells) + " |")
    lines += ["", f"Mean gain over {BAND_HZ[0]:g}-{BAND_HZ[1]:g} Hz:", "", head, rule]
    for path in PATHS:
        cells = [f"{result[c][path][2]:.3g}" for c in conditions]
        lines.append(f"| {path[0]} | {path[1]} | {path[2]} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def figures(frfs: dict, folder: Path) -> None:
    from ehm.outputs.plotting import plot_frf_grid

    folder.mkdir(parents=True, exist_ok=True)
    labelled = [(f"{p}, {s}", t) for (p, s), t in frfs.items()]
    for axis in "xyz":
        plot_frf_grid(labelled, axis, folder / f"posture_gains_{axis}.png",
                      title=f"seat {axis}: erect and slouched on no, low and high back support (linear)")


if __name__ == "__main__":
    cli = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    cli.add_argument("--figures", metavar="DIR", type=Path, help="also draw the gains into DIR")
    args = cli.parse_args()
    frfs = tables()
    print(markdown(gains(frfs)), end="")
    if args.figures:
        figures(frfs, args.figures)
