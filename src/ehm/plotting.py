"""Figures of runs and transfer functions.  The only module that imports matplotlib.

Each function draws into new axes, saves the figure atomically when ``path`` is given, and returns the
figure.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import matplotlib

if "MPLBACKEND" not in os.environ:  # draw to files; no display is needed
    matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .simulation import RunResult  # noqa: E402

_AXIS_COLORS = {"x": "tab:blue", "y": "tab:orange", "z": "tab:green"}


def _save(fig, path: Path | str | None):
    if path is None:
        return fig
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=110)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
        plt.close(fig)
    return fig


def plot_time_histories(run: RunResult, path: Path | str | None = None, title: str | None = None):
    """Seat input, support forces, and pelvis, trunk and head acceleration and rotation over time."""
    t = run.time_s
    names = list(run.points)
    fig, axes = plt.subplots(1 + len(names), 2, figsize=(12, 2.3 * (1 + len(names))), sharex=True)
    for k, a in enumerate("xyz"):
        axes[0, 0].plot(t, run.seat_acc_mps2[:, k], lw=0.6, color=_AXIS_COLORS[a], label=a)
    axes[0, 0].set_ylabel("seat acc [m/s²]")
    axes[0, 0].legend(loc="upper right", ncol=3, fontsize=8)
    for s, f in run.support_N.items():
        axes[0, 1].plot(t, f[:, 2], lw=0.6, label=f"{s} z")
    axes[0, 1].set_ylabel("support force [N]")
    axes[0, 1].legend(loc="upper right", ncol=3, fontsize=8)
    for i, p in enumerate(names, start=1):
        m = run.points[p]
        for k, a in enumerate("xyz"):
            axes[i, 0].plot(t, m.acc_mps2[:, k], lw=0.6, color=_AXIS_COLORS[a], label=a)
        for k, r in enumerate(("roll", "pitch", "yaw")):
            axes[i, 1].plot(t, np.degrees(m.rot_rad[:, k]), lw=0.6, color=list(_AXIS_COLORS.values())[k], label=r)
        axes[i, 0].set_ylabel(f"{p} acc [m/s²]")
        axes[i, 1].set_ylabel(f"{p} rotation [deg]")
        axes[i, 0].legend(loc="upper right", ncol=3, fontsize=8)
        axes[i, 1].legend(loc="upper right", ncol=3, fontsize=8)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    fig.suptitle(title or run.description)
    fig.tight_layout()
    return _save(fig, path)


def plot_transmissibility(rows: list[dict], path: Path | str | None = None, band_hz=(0.2, 12.0),
                          title: str = "Seat-to-body transmissibility (H1 estimate)"):
    """Grid of gains: one row per input axis, one column per point, the input-axis translation.

    ``rows`` are dicts with ``input_axis``, ``point``, ``dof``, ``freq_hz``, ``gain``, ``coherence``
    (arrays), e.g. from :func:`ehm.cli` demo's estimates.
    """
    axes_in = sorted({r["input_axis"] for r in rows}, key="xyz".index)
    points = list(dict.fromkeys(r["point"] for r in rows))
    fig, axes = plt.subplots(len(axes_in), len(points), figsize=(4 * len(points), 3 * len(axes_in)),
                             squeeze=False, sharex=True)
    for i, a in enumerate(axes_in):
        for j, p in enumerate(points):
            ax = axes[i, j]
            for r in rows:
                if r["input_axis"] == a and r["point"] == p and r["dof"] == a:
                    f = r["freq_hz"]
                    sel = (f >= band_hz[0]) & (f <= band_hz[1])
                    ax.plot(f[sel], r["gain"][sel], color=_AXIS_COLORS[a], label="gain")
                    ax2 = ax.twinx()
                    ax2.plot(f[sel], r["coherence"][sel], color="0.6", lw=0.8, ls="--", label="coherence")
                    ax2.set_ylim(0, 1.05)
                    if j == len(points) - 1:
                        ax2.set_ylabel("coherence", color="0.4")
            ax.set_title(f"seat {a} → {p} {a}", fontsize=10)
            ax.set_xscale("log")
            ax.grid(alpha=0.3, which="both")
            if j == 0:
                ax.set_ylabel("gain [(m/s²)/(m/s²)]")
            if i == len(axes_in) - 1:
                ax.set_xlabel("frequency [Hz]")
    fig.suptitle(title)
    fig.tight_layout()
    return _save(fig, path)
