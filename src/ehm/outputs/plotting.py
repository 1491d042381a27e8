"""Figures of runs and transfer functions.  The only module that imports matplotlib.

Each function draws into new axes, saves the figure atomically when ``path`` is given, and returns the
figure.
"""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib

if "MPLBACKEND" not in os.environ:  # draw to files; no display is needed
    matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..errors import InputError, checked  # noqa: E402
from ..files import replace_atomically  # noqa: E402
from ..standards.transfer import band_select  # noqa: E402
from .results import RunResult  # noqa: E402

_AXIS_COLORS = {"x": "tab:blue", "y": "tab:orange", "z": "tab:green"}


def _save(fig, path: Path | str | None):
    """Save whole or not at all (temporary file, then rename); problems become one InputError sentence."""
    if path is None:
        return fig
    path = Path(path)
    fmt = path.suffix.lstrip(".").lower()
    try:
        if fmt not in fig.canvas.get_supported_filetypes():
            raise InputError(f"{path}: cannot draw a .{fmt} file; use .png, .pdf or .svg.")
        replace_atomically(path, lambda tmp: fig.savefig(tmp, dpi=110, format=fmt), "the figure")
    finally:
        plt.close(fig)
    return fig


#: A figure's title: at most this many lines; a longer one is cut with an ellipsis (the files keep the whole text).
TITLE_MAX_LINES = 3


def fit_title(text: str, width_in: float, fontsize: float = 12.0, max_lines: int = TITLE_MAX_LINES) -> str:
    """``text`` wrapped to lines that fit ``width_in`` inches at ``fontsize`` points (a character taken as 0.6 of
    the font size, a generous mean for the DejaVu Sans the figures use), each line of ``text`` on its own; at most
    ``max_lines`` lines, the last one ending in an ellipsis when the text is longer."""
    import textwrap

    chars = max(20, int(0.95 * width_in * 72 / (0.6 * fontsize)))
    lines = [w for part in str(text).splitlines() for w in (textwrap.wrap(part, chars) or [""])]
    if len(lines) > max_lines:
        lines = lines[:max_lines]
        lines[-1] = lines[-1][: chars - 1].rstrip() + "…"
    return "\n".join(lines)


def _suptitle(fig, text: str, fontsize: float = 12.0) -> None:
    """The figure's title, wrapped to its width (:func:`fit_title`): no title is cut at the figure's sides."""
    fig.suptitle(fit_title(text, fig.get_figwidth(), fontsize), fontsize=fontsize)


_AXIS_NAMES = {"x": "x, fore-aft", "y": "y, lateral", "z": "z, vertical"}
#: An axis counts as excited when its seat acceleration rms is at least this share of the largest axis's.
EXCITED_SHARE = 0.1


def excited_axes(seat_acc_mps2: np.ndarray) -> str:
    """The axes of a seat input worth a support-force panel, in xyz order: those whose rms is at least
    :data:`EXCITED_SHARE` of the largest; ``"z"`` (the weight) when the seat does not move."""
    acc = np.asarray(seat_acc_mps2, float)
    rms = np.sqrt(np.mean(acc ** 2, axis=0)) if len(acc) else np.zeros(3)
    if not np.isfinite(rms).all() or rms.max() <= 0:
        return "z"
    return "".join(a for a, r in zip("xyz", rms) if r >= EXCITED_SHARE * rms.max())


def plot_run_preview(preview: RunResult, folder: Path | str):
    """``time_histories.png`` in a run folder being written, from the run's preview (evenly spread rows): what
    ``ehm simulate --plot`` draws, passed as ``SeatedHuman.simulate_to(..., plot=plot_run_preview)``.  The title
    names the figure's row spacing when it is coarser than the run's time step."""
    dt = preview.dt_s
    step = float(preview.time_s[1] - preview.time_s[0]) if len(preview.time_s) > 1 else dt
    title = preview.description + (f" (figure: every {step:g} s)" if step > dt * 1.5 else "")
    return plot_time_histories(preview, Path(folder) / "time_histories.png", title=title)


def plot_time_histories(run: RunResult, path: Path | str | None = None, title: str | None = None):
    """Seat input, support forces, and the points' acceleration and rotation over time (pelvis, lumbar, trunk,
    head: bottom to top).

    The support forces are drawn in the axes the seat moves in (:func:`excited_axes`): for a fore-aft run the
    x forces, for a lateral run the y forces, one panel per excited axis for a run in several axes."""
    t = run.time_s
    names = _bottom_up(run.points)
    force_axes = excited_axes(run.seat_acc_mps2)
    extra = len(force_axes) // 2  # force panels beyond the first fill extra rows, two per row
    rows = 1 + extra + len(names)
    fig, axes = plt.subplots(rows, 2, figsize=(12, 2.3 * rows), sharex=True, squeeze=False)
    for k, a in enumerate("xyz"):
        axes[0, 0].plot(t, run.seat_acc_mps2[:, k], lw=0.6, color=_AXIS_COLORS[a], label=a)
    axes[0, 0].set_ylabel("seat acc [m/s²]")
    axes[0, 0].legend(loc="upper right", ncol=3, fontsize=8)
    force_panels = [axes[0, 1]] + [axes[1 + i // 2, i % 2] for i in range(len(force_axes) - 1)]
    for ax, a in zip(force_panels, force_axes):
        k = "xyz".index(a)
        for s, f in run.support_N.items():
            ax.plot(t, f[:, k], lw=0.6, label=f"{s} F{a}")
        ax.set_ylabel(f"support force {a} [N]")
        ax.set_title(f"support forces on the body, {_AXIS_NAMES[a]}", fontsize=9)
        ax.legend(loc="center right", ncol=3, fontsize=8)
    if len(force_axes) == 2:  # one panel of the extra row is left over
        axes[1, 1].set_visible(False)
    for i, p in enumerate(names, start=1 + extra):
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
    _suptitle(fig, title or run.description)
    fig.tight_layout()
    return _save(fig, path)


def plot_transmissibility(table, path: Path | str | None = None, band_hz=(0.2, 12.0),
                          title: str = "Seat-to-body transmissibility (H1 estimate)"):
    """Grid of same-axis gains with coherence: one row per input axis, one column per point.

    ``table`` is an :class:`ehm.analysis.frf.FrfTable` (e.g. the demo's time-domain estimates).
    """
    axes_in = sorted({k[0] for k in table.curves}, key="xyz".index)
    points = _bottom_up(dict.fromkeys(k[1] for k in table.keys() if k[1] not in _MASS_ORDER))  # gains, not masses
    fig, axes = plt.subplots(len(axes_in), len(points), figsize=(4 * len(points), 3 * len(axes_in)),
                             squeeze=False, sharex=True)
    for i, a in enumerate(axes_in):
        for j, p in enumerate(points):
            ax = axes[i, j]
            c = table.curves.get((a, p, a))
            if c is not None:
                sel = band_select(c.freq_hz, band_hz)
                ax.plot(c.freq_hz[sel], c.gain[sel], color=_AXIS_COLORS[a], label="gain")
                ax2 = ax.twinx()
                ax2.plot(c.freq_hz[sel], c.coherence[sel], color="0.6", lw=0.8, ls="--", label="coherence")
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
    _suptitle(fig, title)
    fig.tight_layout()
    return _save(fig, path)


_DOF_UNITS = {"x": "(m/s²)/(m/s²)", "y": "(m/s²)/(m/s²)", "z": "(m/s²)/(m/s²)",
              "roll": "(rad/s²)/(m/s²)", "pitch": "(rad/s²)/(m/s²)", "yaw": "(rad/s²)/(m/s²)"}
_DOF_ORDER = ("x", "y", "z", "roll", "pitch", "yaw")
_POINT_ORDER = ("head", "trunk", "lumbar", "pelvis")  #: top to bottom
_MASS_ORDER = ("support", "seat_pan")
_MASS_LABEL = {"support": "all supports", "seat_pan": "seat pan"}


def _bottom_up(points) -> list:
    """Point names from the pelvis up (:data:`_POINT_ORDER` reversed), any others after them."""
    order = _POINT_ORDER[::-1]
    return sorted(points, key=lambda p: order.index(p) if p in order else len(order))


#: A model path whose peak gain is below this share of the largest gain of its kind (translations, rotations,
#: apparent masses) under the same input axis has no response: its gains are round-off (e.g. 1e-6 of seat z ->
#: head y in a symmetric person), drawn as an empty panel, not at full scale.
NO_RESPONSE_SHARE = 1e-4


def _gain_kind(point: str, dof: str) -> str:
    return "kg" if point in _MASS_ORDER else ("rotation" if dof in ("roll", "pitch", "yaw") else "translation")


def empty_paths(tables: list, input_axis: str, band_hz=(0.1, 12.0)) -> dict:
    """The model paths of one input axis without a response: ``{(point, dof): peak gain}`` of the paths whose
    largest gain in ``band_hz``, over every model (not measured) table, is below :data:`NO_RESPONSE_SHARE` of the
    largest gain of their kind (translation, rotation, apparent mass) under that input axis."""
    peaks: dict = {}
    for _, t in tables:
        if t.method == "measured":
            continue
        for (a, p, d), c in t.curves.items():
            sel = band_select(c.freq_hz, band_hz)
            if a == input_axis and sel.any():
                g = float(np.nanmax(c.gain[sel]))
                peaks[(p, d)] = max(peaks.get((p, d), 0.0), g)
    largest: dict = {}
    for (p, d), g in peaks.items():
        largest[_gain_kind(p, d)] = max(largest.get(_gain_kind(p, d), 0.0), g)
    return {(p, d): g for (p, d), g in peaks.items() if g < NO_RESPONSE_SHARE * largest[_gain_kind(p, d)]}


def plot_frf_grid(tables: list, input_axis: str, path: Path | str | None = None, title: str | None = None,
                  band_hz=(0.1, 12.0)):
    """Gains of one input axis: rows head, trunk, lumbar, pelvis (those the tables hold); one column per output
    dof (as the paper's Figs. 3-5); and, when the tables hold them, a last row with the apparent masses (all
    supports, seat pan) [kg].

    ``tables`` is a list of ``(label, FrfTable)``; a table whose method is ``measured`` is drawn as
    markers (with gain_sd error bars when given), the others as lines.  A path without a response in the model
    tables (:func:`empty_paths`: round-off gains) is drawn as an empty grey panel that says so, not at full scale.
    """
    empty = empty_paths(tables, input_axis, band_hz)
    held = lambda p, d: any((input_axis, p, d) in t.curves for _, t in tables)  # noqa: E731
    points = [p for p in _POINT_ORDER if any(held(p, d) for d in _DOF_ORDER)]
    dofs = [d for d in _DOF_ORDER if any(held(p, d) for p in points)]
    masses = [p for p in _MASS_ORDER if held(p, input_axis)]
    if not dofs and not masses:
        raise ValueError(f"no curves for input axis {input_axis}")
    n_rows, n_cols = len(points) * bool(dofs) + bool(masses), max(len(dofs), len(masses))
    fig, axes = plt.subplots(n_rows, n_cols, figsize=(3.3 * n_cols, 2.5 * n_rows), squeeze=False, sharex=True)
    cells = {(i, j): (p, d) for i, p in enumerate(points) for j, d in enumerate(dofs)} if dofs else {}
    cells.update({(n_rows - 1, j): (p, input_axis) for j, p in enumerate(masses)})
    for (i, j), (p, d) in cells.items():
        ax = axes[i, j]
        for k, (label, t) in enumerate(tables):
            c = t.curves.get((input_axis, p, d))
            if c is None:
                continue
            sel = band_select(c.freq_hz, band_hz)
            if t.method == "measured":
                sd = c.gain_sd[sel] if np.isfinite(c.gain_sd[sel]).any() else None
                ax.errorbar(c.freq_hz[sel], c.gain[sel], yerr=sd, fmt="o", ms=3, color="k", lw=0.8, label=label)
            elif (p, d) not in empty:
                ax.plot(c.freq_hz[sel], c.gain[sel], lw=1.3, label=label, color=f"C{k}")
            else:  # keep the label for the legend, draw nothing
                ax.plot([], [], lw=1.3, label=label, color=f"C{k}")
        if (p, d) in empty:
            ax.set_facecolor("0.95")
            ax.text(0.5, 0.5, f"no response\n(peak gain {empty[(p, d)]:.1g}:\nround-off, not drawn)",
                    transform=ax.transAxes, ha="center", va="center", fontsize=8, color="0.35")
            ax.set_yticks([])
        ax.set_xscale("log")
        ax.grid(alpha=0.3, which="both")
        mass = p in _MASS_ORDER
        ax.set_title(f"apparent mass, {_MASS_LABEL[p]} {d} [kg]" if mass else f"{p} {d}", fontsize=9)
        if j == 0:
            ax.set_ylabel("kg" if mass else "gain")
        if i == n_rows - 1 or (i == n_rows - 2 and j >= len(masses) and masses):
            ax.set_xlabel("frequency [Hz]")
        if (i, j) == min(cells):
            ax.legend(fontsize=7)
    for i in range(n_rows):
        for j in range(n_cols):
            if (i, j) not in cells:
                axes[i, j].set_visible(False)
    _suptitle(fig, title or f"seat {input_axis} input: gains; translations {_DOF_UNITS['x']}, "
                          f"rotations {_DOF_UNITS['roll']}"
                 + ("; apparent mass: support force per seat acceleration [kg]" if masses else "")
                 + (f"\ngrey panels: no response (peak below {NO_RESPONSE_SHARE:.0e} of the largest gain of its kind)"
                    if empty else ""))
    fig.tight_layout()
    return _save(fig, path)


def plot_locking_study(study, path: Path | str | None = None):
    """The paper's locking findings: key paths for every variant."""
    keys = [("z", "trunk", "z"), ("z", "head", "z"), ("z", "pelvis", "z"),
            ("x", "head", "pitch"), ("z", "head", "pitch"), ("y", "head", "y"),
            ("y", "head", "roll"), ("y", "head", "yaw"), ("y", "trunk", "roll")]
    fig, axes = plt.subplots(3, 3, figsize=(12, 9))
    for ax, key in zip(axes.flat, keys):
        for k, (name, table) in enumerate(study.tables.items()):
            c = table.curve(*key)
            sel = band_select(c.freq_hz, (0.3, 15.0))
            ax.plot(c.freq_hz[sel], c.gain[sel], lw=1.3, color=f"C{k}", label=name)
        ax.set_xscale("log")
        ax.grid(alpha=0.3, which="both")
        ax.set_title(f"seat {key[0]} → {key[1]} {key[2]} [{_DOF_UNITS[key[2]]}]", fontsize=9)
        ax.set_xlabel("frequency [Hz]")
    axes[0, 0].legend(fontsize=8)
    how = "linearised model" if study.method == "linear" else "random-vibration runs, H1"
    _suptitle(fig, f"Joint-locking study ({how}): SL = T12 locked, NL = lower neck locked")
    fig.tight_layout()
    return _save(fig, path)


_LOC_COLORS = {"seat": "0.3", "pelvis": "tab:blue", "trunk": "tab:orange", "head": "tab:red", "lumbar": "tab:green"}


def plot_weighted_spectra(assessment, path: Path | str | None = None):
    """PSD of the frequency-weighted acceleration (Wd x/y, Wk z) at seat, pelvis, trunk, head and lumbar spine."""
    fig, axes = plt.subplots(1, 3, figsize=(14, 4), sharey=True)
    for ax, a in zip(axes, "xyz"):
        for loc, spec in assessment.spectra.items():
            f, p = spec[a]
            sel = band_select(f, (0.2, 80.0))
            if sel.any():
                ax.loglog(f[sel], p[sel], color=_LOC_COLORS[loc], lw=1.1, label=loc)
        ax.set_title(f"{a}: {'Wd' if a != 'z' else 'Wk'}-weighted acceleration")
        ax.set_xlabel("frequency [Hz]")
        ax.grid(alpha=0.3, which="both")
    axes[0].set_ylabel("PSD [(m/s²)²/Hz]")
    axes[0].legend(fontsize=8)
    _suptitle(fig, f"Weighted spectra: {assessment.description}")
    fig.tight_layout()
    return _save(fig, path)


def plot_running_rms(assessment, path: Path | str | None = None):
    """Running rms (1 s) of the weighted acceleration per axis, seat and body."""
    fig, axes = plt.subplots(3, 1, figsize=(12, 7.5), sharex=True)
    t = assessment.trace_time_s
    for ax, a in zip(axes, "xyz"):
        for loc, per_axis in assessment.metrics.items():
            rr = per_axis[a].running_rms
            ax.plot(t[: rr.size], rr, color=_LOC_COLORS[loc], lw=0.9, label=f"{loc} (MTVV {per_axis[a].mtvv:.2f})")
        ax.set_ylabel(f"{a} running rms [m/s²]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncol=4, loc="upper right")
    axes[-1].set_xlabel("time [s]")
    _suptitle(fig, "Running rms of the weighted acceleration (1 s, ISO 2631-1 6.3.1)")
    fig.tight_layout()
    return _save(fig, path)


def plot_sickness(assessment, path: Path | str | None = None):
    """Predicted motion sickness incidence and MISC rating over time: head motion against a head fixed to the
    seat."""
    with_misc = any(getattr(r, "misc", None) is not None for r in assessment.sickness.values())
    fig, axes = plt.subplots(3 if with_misc else 2, 1, figsize=(12, 8.5 if with_misc else 6), sharex=True)
    styles = {"head": ("tab:red", "head (through the body)"), "seat": ("0.3", "seat (head fixed to the seat)")}
    for key, r in assessment.sickness.items():
        color, label = styles[key]
        axes[0].plot(r.time_s, r.msi_percent, color=color, label=f"{label}: {r.final_msi_percent:.2f} % at the end")
        axes[1].plot(r.time_s, r.conflict_magnitude_mps2, color=color, lw=0.8, label=label)
        if with_misc and r.misc is not None:
            axes[2].plot(r.time_s, r.misc, color=color, label=f"{label}: {r.final_misc:.2f} at the end")
    axes[0].set_ylabel("MSI [%]")
    axes[1].set_ylabel("vertical conflict [m/s²]")
    if with_misc:
        axes[2].set_ylabel("predicted MISC (0-10)")
        axes[2].set_ylim(0, 10)
    axes[-1].set_xlabel("time [s]")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    _suptitle(fig, "Motion sickness incidence (subjective vertical conflict model)")
    fig.tight_layout()
    return _save(fig, path)


def plot_sickness_fit(fit, path: Path | str | None = None):
    """A person's MISC ratings against the accumulation model fitted to them (:func:`ehm.fit_sickness`)."""
    fig, ax = plt.subplots(figsize=(10, 4.5))
    f = fit.fit
    ax.plot(fit.trace_time_s / 60.0, fit.trace_misc, color="tab:red",
            label=f"model: K1 {f.params.fast_gain:.3g} ± {f.std['fast_gain']:.2g} (m/s²)⁻¹, "
                  f"T1 {f.params.fast_time_constant_s:.3g} ± {f.std['fast_time_constant_s']:.2g} s")
    ax.plot(f.time_s / 60.0, f.misc_rated, "ko", ms=4, label=f"ratings ({f.n_ratings}); rms misfit {f.rms_misc:.2f}")
    ax.set_xlabel("time [min]")
    ax.set_ylabel("MISC (0-10)")
    ax.set_ylim(0, 10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    _suptitle(fig, f"MISC ratings and the fitted accumulation model ({fit.location}'s conflict)")
    fig.tight_layout()
    return _save(fig, path)


# --- the person against the references (ehm validate) ---------------------------------------------------------------

_CONDITION_STYLES = ("-", "--", ":", "-.")  #: the first condition evaluated (the references') solid, then dashed
_VALIDATION_BAND_HZ = (0.5, 20.0)
_VALIDATION_XLIM_HZ = (0.45, 22.0)  #: a margin round the band, so that marks at its ends show whole
_REF_COLOR, _BAND_COLOR = "k", "0.55"
_SOURCES = {"z": "Sources: ISO 2631-5:2018 cl. 5.2 Formula 1 (seat to lumbar spine); Fairley & Griffin 1989, one-mass "
                 "fit to 60 seated people (apparent mass);\nseat-to-head ranges reported for seated people "
                 "(docs/model); band widths: ehm's choice (docs/validation).",
            "x": "Sources: fore-aft head peak below 3 Hz, ranges reported for seated people (docs/model); its gain at "
                 "most 3: a measured median of 2 (16 seated men), the limit ehm's choice (docs/validation).",
            "y": "Sources: lateral head peak below 3 Hz, ranges reported for seated people (docs/model); its gain at "
                 "most 3: the fore-aft limit carried over, ehm's choice (docs/validation)."}


def plot_validation(validation, axis: str, path: Path | str | None = None):
    """The person against the references for one seat input axis (:func:`ehm.validate`): the model's curves in
    each condition evaluated (the references' condition solid, the person's own seat dashed) over the bands.

    ``z``: (a) seat-to-lumbar gain against ISO 2631-5's transfer function and its ±0.20 band; (b) the apparent
    mass over its 0.5 Hz value against Fairley & Griffin's one-mass fit (frame share 0 to 0.5, the region
    between shaded) with the band limits; (c) seat-to-pelvis and seat-to-head gains with the head's band and the
    pelvis peak's limit.  ``x``, ``y``: seat-to-head, trunk and pelvis gains on that axis with the head peak's
    limit.  Where a check takes its figure (a peak, the worst deviation, the largest gain against a limit) is
    marked on the model's curve: a dot where it passes, a cross where it fails.  The titles count the checks that
    pass.
    """
    if axis not in _SOURCES:
        raise InputError(f"axis {axis!r}: use x, y or z.")
    if len(validation.tables) > len(_CONDITION_STYLES):
        raise InputError(f"the validation holds {len(validation.tables)} conditions, more than one figure per axis "
                         f"tells apart ({len(_CONDITION_STYLES)}): draw it with plot_validation_grid (what ehm "
                         "validate --all draws).")
    panels = _Z_PANELS if axis == "z" else ((_horizontal_panel(axis),))
    one = len(panels) == 1  # a single panel keeps its legend at its right, several theirs below them
    fig, axes = plt.subplots(1, len(panels), figsize=(10.5, 5.2) if one else (5.4 * len(panels) + 1.0, 6.4),
                             squeeze=False)
    for ax, (title, draw) in zip(axes[0], panels):
        names = draw(ax, validation)
        ax.set_title(f"{title}: {_pass_count(validation, names)}", fontsize=9)
        _frequency_axis(ax)
        ax.legend(fontsize=7, frameon=False, **(dict(loc="center left", bbox_to_anchor=(1.02, 0.5)) if one else
                                                dict(loc="upper center", bbox_to_anchor=(0.5, -0.16))))
    bands = [c for c in validation.on_axis(axis) if not c.name.startswith("locking_")]
    locking = [c for c in validation.on_axis(axis) if c.name.startswith("locking_")]
    title = f"The person against the references, seat {_AXIS_NAMES[axis]} input: {_count(bands)} band checks pass"
    if locking:
        title += f"\nthe paper's joint-locking findings under it: {_count(locking)} pass (ehm study locking draws them)"
    _suptitle(fig, title, fontsize=10)
    fig.text(0.01, 0.01, _SOURCES[axis] + "\nMarked: where each check takes its figure (dot: passes, cross: fails).",
             fontsize=7, color="0.3")
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    return _save(fig, path)


def _count(checks) -> str:
    return f"{sum(c.passed for c in checks)} of {len(checks)}"


def _pass_count(validation, names) -> str:
    checks = [c for c in validation.checks if c.name in names]
    return f"{_count(checks)} checks pass" if checks else "no checks"


def _frequency_axis(ax) -> None:
    ax.set_xscale("log")
    ax.set_xlim(*_VALIDATION_XLIM_HZ)
    ticks = [0.5, 1, 2, 3, 5, 10, 20]
    ax.set_xticks(ticks, [f"{t:g}" for t in ticks])
    ax.set_xlabel("frequency [Hz]")
    ax.grid(alpha=0.3, which="both")


def _band(name: str):
    from ..standards.references import BANDS

    return next(b for b in BANDS if b.name == name)


def _model_lines(ax, validation, path, color, label, names=(), normalise_at_hz=None):
    """The model's gain of ``path`` in each condition, one line style each; the peaks of the checks ``names`` taken
    on it marked (a dot: passes, a cross: fails)."""
    for style, (condition, table) in zip(_CONDITION_STYLES, validation.tables.items()):
        c = table.curve(*path)
        g = np.asarray(c.gain, float)
        if normalise_at_hz is not None:
            g = g / np.interp(normalise_at_hz, c.freq_hz, g)
        sel = band_select(c.freq_hz, _VALIDATION_BAND_HZ)
        ax.plot(c.freq_hz[sel], g[sel], ls=style, color=color, lw=1.4,
                label=f"{label} ({condition})" if len(validation.tables) > 1 else label)
        for check in validation.checks:
            if check.name in names and check.condition == condition and np.isfinite(check.at_hz):
                y = float(np.interp(check.at_hz, c.freq_hz, g))
                ax.plot(check.at_hz, y, "o" if check.passed else "x", color=color, ms=6,
                        mfc=color if check.passed else "none", mew=1.8)


def _box(ax, f_band, g_band, label, color=_BAND_COLOR):
    """A band of peak frequency and gain as a box."""
    (f0, f1), (g0, g1) = f_band, g_band
    ax.add_patch(plt.Rectangle((f0, g0), f1 - f0, g1 - g0, fill=True, alpha=0.15, color=color, lw=0, label=label))
    ax.add_patch(plt.Rectangle((f0, g0), f1 - f0, g1 - g0, fill=False, ec=color, lw=1.0))


def _peak_limit(ax, high_hz, label, color=_BAND_COLOR):
    """An upper limit of a peak's frequency: a line, and the frequencies allowed (up to it) shaded, as the bands'
    boxes shade what is allowed."""
    ax.axvline(high_hz, color=color, lw=1.0, ls="-.")
    ax.axvspan(_VALIDATION_XLIM_HZ[0], high_hz, color=color, alpha=0.08, lw=0, label=label)


def _graded(validation, name: str) -> bool:
    """Whether the band ``name`` is graded in ``validation`` (a check of it there): only then is it drawn."""
    return any(c.name == name for c in validation.checks)


def _not_graded(ax, names, validation, where: str) -> None:
    """Say in the panel that its bands are not graded here (their sources do not speak of this seat)."""
    if not any(_graded(validation, n) for n in names):
        ax.text(0.03, 0.97, "not graded here; graded on\n" + where.replace("; ", ",\n"), transform=ax.transAxes,
                fontsize=6, va="top", color="0.35")


def _lumbar_panel(ax, validation):
    from ..standards.references import iso2631_5_lumbar_tf

    dev, peak = _band("lumbar_gain_vs_iso2631_5"), _band("lumbar_peak_frequency")
    if _graded(validation, dev.name):
        f = np.geomspace(*_VALIDATION_BAND_HZ, 400)
        ax.plot(f, np.abs(iso2631_5_lumbar_tf(f)), color=_REF_COLOR, lw=1.2, label="ISO 2631-5:2018 Formula 1")
        fb = np.geomspace(*dev.freq_range_hz, 200)
        ref = np.abs(iso2631_5_lumbar_tf(fb))
        ax.fill_between(fb, ref + dev.low, ref + dev.high, color=_BAND_COLOR, alpha=0.25, lw=0,
                        label=f"±{dev.high:.2f} over {dev.freq_range_hz[0]:g}-{dev.freq_range_hz[1]:g} Hz")
    if _graded(validation, peak.name):
        ax.axvspan(peak.low, peak.high, color="tab:green", alpha=0.08, lw=0,
                   label=f"its peak at {peak.low:g}-{peak.high:g} Hz")
    names = ("lumbar_gain_vs_iso2631_5", "lumbar_peak_frequency", "spine_first_resonance")
    _not_graded(ax, names, validation, dev.where())
    _model_lines(ax, validation, dev.path, _LOC_COLORS["lumbar"], "model lumbar z", names)
    ax.set_ylabel("gain [(m/s²)/(m/s²)]")
    return names


def _apparent_mass_panel(ax, validation):
    from ..standards.references import apparent_mass_one_mass

    pf, pg = _band("apparent_mass_peak_frequency"), _band("apparent_mass_peak")
    if _graded(validation, pf.name) or _graded(validation, pg.name):
        f = np.geomspace(*_VALIDATION_BAND_HZ, 400)
        lo, hi = (np.abs(apparent_mass_one_mass(f, share)) for share in (0.0, 0.5))
        ax.plot(f, lo, color=_REF_COLOR, lw=1.2, label="Fairley & Griffin 1989, one-mass fit")
        ax.plot(f, hi, color=_REF_COLOR, lw=0.8, ls=":", label="the same, half the mass on the frame")
        ax.fill_between(f, np.minimum(lo, hi), np.maximum(lo, hi), color=_REF_COLOR, alpha=0.08, lw=0)
        _box(ax, (pf.low, pf.high), (pg.low, pg.high), f"peak {pg.low:g}-{pg.high:g} at {pf.low:g}-{pf.high:g} Hz")
    for name in ("apparent_mass_10hz", "apparent_mass_15_20hz"):
        if not _graded(validation, name):
            continue
        b = _band(name)
        f0, f1 = b.freq_range_hz
        ax.plot([f0, f1] if f1 > f0 else [f0 * 0.96, f0 * 1.04], [b.high, b.high], color="tab:red", lw=2.0)
        ax.plot([f0, f1] if f1 > f0 else [f0], [b.high] * (2 if f1 > f0 else 1), "v", color="tab:red", ms=6,
                label="upper limits: ≤ 0.75 at 10 Hz, ≤ 0.6 at 15-20 Hz" if name == "apparent_mass_10hz" else None)
    names = ("apparent_mass_peak_frequency", "apparent_mass_peak", "apparent_mass_10hz", "apparent_mass_15_20hz")
    _model_lines(ax, validation, pf.path, "tab:purple", "model, all supports", names,
                 normalise_at_hz=pf.normalise_at_hz)
    ax.set_ylabel(f"apparent mass over its {pf.normalise_at_hz:g} Hz value")
    return names


def _pelvis_head_panel(ax, validation):
    pelvis, hf, hg = (_band(n) for n in ("pelvis_peak_frequency", "head_vertical_peak_frequency",
                                         "head_vertical_peak_gain"))
    if _graded(validation, hf.name) or _graded(validation, hg.name):
        _box(ax, (hf.low, hf.high), (hg.low, hg.high),
             f"head peak {hg.low:g}-{hg.high:g} at {hf.low:g}-{hf.high:g} Hz", color="tab:red")
    if _graded(validation, pelvis.name):
        _peak_limit(ax, pelvis.high, f"allowed: pelvis peak at most {pelvis.high:g} Hz (shaded)", color="tab:blue")
    _model_lines(ax, validation, pelvis.path, _LOC_COLORS["pelvis"], "model pelvis z", (pelvis.name,))
    _model_lines(ax, validation, hf.path, _LOC_COLORS["head"], "model head z", (hf.name,))
    ax.set_ylabel("gain [(m/s²)/(m/s²)]")
    return pelvis.name, hf.name, hg.name


_Z_PANELS = (("(a) seat z → lumbar z", _lumbar_panel), ("(b) apparent mass z", _apparent_mass_panel),
             ("(c) seat z → pelvis z, head z", _pelvis_head_panel))


def _horizontal_panel(axis: str):
    name = {"x": "head_fore_aft_peak_frequency", "y": "head_lateral_peak_frequency"}[axis]
    gain = {"x": "head_fore_aft_peak_gain", "y": "head_lateral_peak_gain"}[axis]

    def draw(ax, validation):
        b, g = _band(name), _band(gain)
        if _graded(validation, name):
            _peak_limit(ax, b.high, f"allowed: head peak at most {b.high:g} Hz (shaded)", color="tab:red")
        if _graded(validation, gain):
            ax.axhline(g.high, color="tab:red", lw=1.0, ls="--", label=f"head peak gain at most {g.high:g}")
        for point in ("pelvis", "trunk", "head"):
            _model_lines(ax, validation, (axis, point, axis), _LOC_COLORS[point], f"model {point} {axis}",
                         (name, gain) if point == "head" else ())
        ax.set_ylabel("gain [(m/s²)/(m/s²)]")
        return name, gain

    return f"seat {axis} → head, trunk, pelvis {axis}", draw


_GRID_COLUMNS = (("seat z → lumbar z", _lumbar_panel), ("apparent mass z", _apparent_mass_panel),
                 ("seat z → pelvis z, head z", _pelvis_head_panel), ("seat x → head x", _horizontal_panel("x")[1]),
                 ("seat y → head y", _horizontal_panel("y")[1]))


@checked
def plot_validation_grid(validation, path: Path | str | None = None):
    """Every condition of a validation (:func:`ehm.validate` with ``every_condition=True``, ``ehm validate --all``)
    in one grid: a row per condition (posture and back support), a column per curve the bands grade: (a) seat-to-lumbar
    gain against ISO 2631-5 and its band, (b) the apparent mass over its 0.5 Hz value against the one-mass fit with
    its bands, (c) seat-to-pelvis and seat-to-head vertical gains with their bands, (d) and (e) seat-to-head, trunk
    and pelvis fore-aft and lateral gains with the head's limits.  Each panel draws only the bands graded in its
    condition (a band applies where its source speaks of that seat) and says so where none is; a dot marks where a
    check passes, a cross where it fails, and a panel's title, red when a check in it fails, counts them.  The
    findings across two conditions and the locking findings (on the paper's seat) are counted in the title and
    listed under the grid.
    """
    from types import SimpleNamespace

    conditions = list(validation.tables)
    if not conditions:
        raise InputError("the validation holds no condition's frequency responses to draw.")
    rows, cols = len(conditions), len(_GRID_COLUMNS)
    height = 2.25 * rows + 3.4
    fig, axes = plt.subplots(rows, cols, figsize=(3.4 * cols + 1.0, height), squeeze=False)
    legends = {}
    for r, condition in enumerate(conditions):
        one = SimpleNamespace(checks=tuple(c for c in validation.checks if c.condition == condition),
                              tables={condition: validation.tables[condition]})
        for k, (ax, (title, draw)) in enumerate(zip(axes[r], _GRID_COLUMNS)):
            names = draw(ax, one)
            checks = [c for c in one.checks if c.name in names]
            failing = any(not c.passed for c in checks)
            ax.set_title(f"({'abcde'[k]}) {title}: {_pass_count(one, names)}", fontsize=7,
                         color="tab:red" if failing else "black")
            _frequency_axis(ax)
            ax.tick_params(labelsize=6)
            ax.set_ylabel(ax.get_ylabel(), fontsize=6)
            if r < rows - 1:
                ax.set_xlabel("")
            if r == 0 or len(ax.get_legend_handles_labels()[0]) > len(legends.get(k, ((), ()))[0]):
                legends[k] = ax.get_legend_handles_labels()  # the row drawing the most bands
        axes[r][0].annotate(condition.replace(", ", "\n"), xy=(-0.5, 0.5), xycoords="axes fraction", rotation=90,
                            ha="center", va="center", fontsize=8, weight="bold")
    for k, (handles, labels) in legends.items():
        axes[-1][k].legend(handles, labels, fontsize=6, frameon=False, loc="upper center",
                           bbox_to_anchor=(0.5, -0.32))
    bands = [c for c in validation.checks if c.condition in conditions]
    across = [c for c in validation.checks if c.condition not in conditions and not c.name.startswith("locking_")]
    locking = [c for c in validation.checks if c.name.startswith("locking_")]
    title = f"The person on {rows} postures and back supports: {_count(bands)} band checks pass"
    if across:
        title += f"; across two conditions {_count(across)}"
    if locking:
        title += f"; the paper's locking findings on its seat {_count(locking)}"
    _suptitle(fig, title, fontsize=11)
    notes = [f"{c.name} ({c.condition}): {c.what}: {'pass' if c.passed else 'FAIL'}" for c in across]
    fig.text(0.01, 0.005, "\n".join(notes + [
        "Sources: ISO 2631-5:2018 Formula 1; Fairley & Griffin 1989 one-mass fit; seat-to-head ranges reported for "
        "seated people (docs/model); band widths and the horizontal gain limits: ehm's choice (docs/validation).",
        "Marked: where each check takes its figure (dot: passes, cross: fails); a red title: a check in the panel "
        "fails."]), fontsize=7, color="0.3", va="bottom")
    fig.subplots_adjust(left=0.075, right=0.99, top=1.0 - 1.0 / height, bottom=(2.5 + 0.12 * len(notes)) / height,
                        wspace=0.42, hspace=0.5)
    return _save(fig, path)
