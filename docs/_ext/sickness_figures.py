"""Draw the figures of the motion-sickness page (``docs/user_guide/sickness.md``) at every build.

Called from ``conf.py``: the figures come from the model as it is, so the page cannot drift from it.  Writes
``_generated/sickness_frequency.png``, ``_generated/sickness_direction.png`` and ``_generated/sickness_support.png``
and ``_generated/sickness_figures.md`` (the numbers behind them, included by the page).  Every input is SYNTHETIC
(sinusoidal seat motion); the published values are facts read from the papers' abstracts, with their sources.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

RATE_HZ = 20.0  # the sickness model's rate in ehm.assess
#: Golding, Mueller and Gresty (2001), abstract: fore-aft, 1.0 m/s^2 peak; mean minutes to moderate nausea, and how
#: many of the 12 reached it.
GOLDING = {0.1: (18.0, 8), 0.2: (11.2, 12), 0.4: (20.2, 7)}


def _seat_run(axis: int, freq_hz: float, peak_mps2: float, minutes: float, params=None):
    from ehm.standards.sickness import subjective_vertical_conflict

    t = np.arange(0.0, 60.0 * minutes, 1.0 / RATE_HZ)
    gia = np.zeros((t.size, 3))
    gia[:, 2] = 9.81
    gia[:, axis] += peak_mps2 * np.sin(2 * np.pi * freq_hz * t)
    return subjective_vertical_conflict(t, gia, np.zeros_like(gia), params)


def _minutes_to(level: float, t: np.ndarray, y: np.ndarray) -> float:
    k = np.flatnonzero(y >= level)
    return float(t[k[0]] / 60.0) if k.size else float("inf")


def frequency(out: Path, lines: list) -> None:
    import matplotlib.pyplot as plt

    from ehm.standards.sickness import SvcParameters

    p = SvcParameters()
    isotropic = replace(p, horizontal_time_constant_s=p.vertical_time_constant_s,
                        k_vc_horizontal_per_s=p.k_vc_per_s)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    rows = []
    for label, params, style in (("ehm (UNIPG horizontal axes)", p, "o-"),
                                 ("ehm before (every axis the vertical's)", isotropic, "s--")):
        runs = {f: _seat_run(0, f, 1.0, 30.0, params) for f in GOLDING}
        level = float(np.interp(660.0, runs[0.2].time_s, runs[0.2].msi_percent))
        ratio = [_minutes_to(level, r.time_s, r.msi_percent) / 11.0 for r in runs.values()]
        shown = [min(x, 30.0 / 11.0) for x in ratio]
        ax1.plot(list(GOLDING), shown, style, label=label)
        rows.append((label, ratio))
    golding = [GOLDING[f][0] / GOLDING[0.2][0] for f in GOLDING]
    ax1.plot(list(GOLDING), golding, "k*", ms=12, label="Golding et al. 2001 (mean time to moderate nausea)")
    ax1.axhspan(1.3, 2.5, color="0.9", zorder=0, label="issue 37's check: 1.3-2.5")
    ax1.axhline(30.0 / 11.0, color="0.5", lw=0.8, ls=":")
    ax1.text(0.105, 30.0 / 11.0 + 0.05, "not within 30 min", fontsize=8, color="0.4")
    from matplotlib.ticker import NullFormatter

    ax1.set_xscale("log")
    ax1.set_xticks(list(GOLDING), [f"{f:g}" for f in GOLDING])
    ax1.xaxis.set_minor_formatter(NullFormatter())
    ax1.set_xlabel("frequency [Hz] (fore-aft, 1.0 m/s² peak)")
    ax1.set_ylabel("time to 0.2 Hz's level / 0.2 Hz's time")
    ax1.legend(fontsize=7)
    ax1.grid(alpha=0.3)
    freqs = np.array([0.05, 0.07, 0.1, 0.14, 0.2, 0.28, 0.4, 0.56, 0.8])
    for axis, name, style in ((2, "vertical", "k-"), (0, "fore-aft", "C0-"), (1, "lateral", "C1:")):
        msi = [_seat_run(axis, f, 1.0, 30.0).final_msi_percent for f in freqs]
        ax2.plot(freqs, msi, style, label=name)
    ax2.set_xscale("log")
    ax2.set_xticks([0.05, 0.1, 0.2, 0.4, 0.8], ["0.05", "0.1", "0.2", "0.4", "0.8"])
    ax2.xaxis.set_minor_formatter(NullFormatter())
    ax2.set_xlabel("frequency [Hz] (1.0 m/s² peak)")
    ax2.set_ylabel("MSI after 30 min [%]")
    ax2.legend(fontsize=8)
    ax2.grid(alpha=0.3)
    _finish(fig, "Horizontal frequency dependence against Golding, Mueller and Gresty (2001); the vertical unchanged",
            out / "sickness_frequency.png")
    lines += ["| fore-aft, 1.0 m/s² peak | 0.1 Hz | 0.2 Hz | 0.4 Hz |", "|---|---|---|---|",
              "| Golding et al. 2001: minutes to moderate nausea (reached by) | "
              + " | ".join(f"{m:g} ({n} of 12)" for m, n in GOLDING.values()) + " |",
              "| the same, relative to 0.2 Hz | " + " | ".join(f"{x:.2f}" for x in golding) + " |"]
    for label, ratio in rows:
        lines.append(f"| {label}: time to 0.2 Hz's 11-min MSI, relative | "
                     + " | ".join("not within 30 min" if not np.isfinite(x) else f"{x:.2f}" for x in ratio) + " |")
    lines.append("")


def direction(out: Path, lines: list) -> None:
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2), sharex=True)
    lines += ["| 0.315 Hz, 30 min | " + " | ".join(f"{r:g} m/s² rms" for r in (0.28, 0.56, 1.11)) + " |",
              "|---|---|---|---|"]
    for axis, name, style in ((0, "fore-aft", "-"), (1, "lateral", "--")):
        cells = []
        for k, rms in enumerate((0.28, 0.56, 1.11)):
            r = _seat_run(axis, 0.315, rms * np.sqrt(2.0), 30.0)
            ax1.plot(r.time_s / 60, r.msi_percent, style, color=f"C{k}", label=f"{name}, {rms:g} m/s² rms")
            ax2.plot(r.time_s / 60, r.misc, style, color=f"C{k}")
            cells.append(f"MSI {r.final_msi_percent:.1f} %, MISC {r.final_misc:.1f}")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    lines.append("")
    ax1.set_ylabel("MSI [%]")
    ax2.set_ylabel("predicted MISC (group)")
    ax2.set_ylim(0, 10)
    for ax in (ax1, ax2):
        ax.set_xlabel("time [min]")
        ax.grid(alpha=0.3)
    ax1.legend(fontsize=7)
    _finish(fig, "Fore-aft against lateral at 0.315 Hz (Griffin and Mills 2002: similar; growing with magnitude "
                 "and duration)", out / "sickness_direction.png")


def support(out: Path, lines: list, minutes: float = 30.0) -> None:
    import matplotlib.pyplot as plt

    import ehm

    drive = ehm.sine("x", 60.0 * minutes, 0.7 * np.sqrt(2.0), 0.25)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2), sharex=True)
    lines += [f"| fore-aft 0.25 Hz, 0.7 m/s² rms, {minutes:g} min, erect, linear route | MSI head | MSI seat | "
              "MISC head |", "|---|---|---|---|"]
    for k, back in enumerate(("low", "high")):
        a = ehm.assess(drive, ehm.Person(back_support=back), method="linear")
        h, s = a.sickness["head"], a.sickness["seat"]
        ax1.plot(h.time_s / 60, h.msi_percent, color=f"C{k}", label=f"head, {back} back support")
        ax2.plot(h.time_s / 60, h.misc, color=f"C{k}")
        if k == 0:
            ax1.plot(s.time_s / 60, s.msi_percent, "k:", label="seat (head fixed to it)")
            ax2.plot(s.time_s / 60, s.misc, "k:")
        lines.append(f"| {back} back support | {h.final_msi_percent:.2f} % | {s.final_msi_percent:.2f} % | "
                     f"{h.final_misc:.2f} |")
    lines.append("")
    ax1.set_ylabel("MSI [%]")
    ax2.set_ylabel("predicted MISC (group)")
    ax2.set_ylim(0, 10)
    for ax in (ax1, ax2):
        ax.set_xlabel("time [min]")
        ax.grid(alpha=0.3)
    ax1.legend(fontsize=8)
    _finish(fig, "Low against high back support (Mills and Griffin 2000: the low backrest the most nauseogenic)",
            out / "sickness_support.png")


def _finish(fig, title: str, path: Path) -> None:
    """Title a figure, lay it out, write it to ``path`` and close it."""
    import matplotlib.pyplot as plt

    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _key(src: Path) -> str:
    """What the figures depend on: this script, ehm's version, its sickness model and the body model's data."""
    import hashlib

    import ehm

    digest = hashlib.sha256(ehm.__version__.encode())
    paths = [Path(__file__), src / "standards" / "sickness.py", *sorted((src / "data").glob("*.csv")),
             src / "data" / "default_params.toml"]
    for path in paths:
        digest.update(path.read_bytes())
    return digest.hexdigest()


def write(out: Path, src: Path) -> None:
    """Every figure and the table of numbers behind them, into ``out``; drawn again only when what they depend on
    (:func:`_key`, over the package sources ``src``) changed since the last build (the back-support runs take a
    minute or two)."""
    import warnings

    import matplotlib

    matplotlib.use("Agg")
    out.mkdir(parents=True, exist_ok=True)
    key, stamp = _key(src), out / "sickness_figures.key"
    names = ("sickness_frequency.png", "sickness_direction.png", "sickness_support.png", "sickness_figures.md")
    if stamp.is_file() and stamp.read_text() == key and all((out / n).is_file() for n in names):
        return
    lines: list = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a sine drive does not cover every weighting's band: said on the page
        frequency(out, lines)
        direction(out, lines)
        support(out, lines)
    (out / "sickness_figures.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    stamp.write_text(key)


if __name__ == "__main__":
    here = Path(__file__).resolve().parents[1]
    write(here / "_generated", here.parent / "src" / "ehm")
