"""Seat-to-pelvis, trunk and head gains of erect and slouched posture on no, low and high back support.

Prints the Markdown tables of docs/model.md "Postures and back supports": for each input axis (fore-aft x, lateral
y, vertical z) and point, the in-axis translation (m/s^2 per m/s^2) and the main rotation (rad/s^2 per m/s^2:
pitch for x and z, roll for y); per condition the peak gain with its frequency, and the mean gain over 0.5-2 Hz,
where the measurements (Mirakhorlo et al. 2022) find posture and back support matter most.  The exact frequency
response of each person linearised at rest (ehm.frf.linear_frf: the response to small inputs such as the
measurements' 0.3 m/s^2), 0.1-12 Hz.  Takes about half a minute.

    python benchmarks/posture_gains.py > gains.md
"""

from __future__ import annotations

import argparse

import numpy as np

import ehm
from ehm.frf import linear_frf

POSTURES = ("erect", "slouched")
SUPPORTS = ("none", "low", "high")
PATHS = [(axis, point, dof) for axis, rot in (("x", "pitch"), ("y", "roll"), ("z", "pitch"))
         for point in ("pelvis", "trunk", "head") for dof in (axis, rot)]
BAND_HZ = (0.5, 2.0)


def gains(postures=POSTURES, supports=SUPPORTS) -> dict:
    """(posture, support) -> path -> (peak gain, peak frequency [Hz], mean gain over BAND_HZ)."""
    f = np.arange(0.1, 12.0 + 1e-9, 0.05)
    band = (f >= BAND_HZ[0] - 1e-9) & (f <= BAND_HZ[1] + 1e-9)
    out = {}
    for posture in postures:
        for support in supports:
            table = linear_frf(ehm.SeatedHuman(posture=posture, back_support=support), freq_hz=f)
            out[(posture, support)] = {}
            for path in PATHS:
                g = table.curve(*path).gain
                k = int(np.argmax(g))
                out[(posture, support)][path] = (float(g[k]), float(f[k]), float(g[band].mean()))
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


if __name__ == "__main__":
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args()
    print(markdown(gains()), end="")
