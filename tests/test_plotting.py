"""What the run figures show (ehm.outputs.plotting): the support forces in the axes the seat moves in."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest

import ehm
from ehm.outputs.plotting import plot_time_histories


def _force_panels(fig):
    """{axis letter: axes} of the support-force panels, found by their y label."""
    return {ax.get_ylabel().split()[2]: ax for ax in fig.axes
            if ax.get_visible() and ax.get_ylabel().startswith("support force ")}


@pytest.mark.parametrize("axis", ["x", "y"])
def test_time_histories_show_the_forces_of_the_excited_axis(human, axis):
    # A fore-aft (lateral) run: the support-force panel holds each surface's x (y) force [N], not the vertical
    # forces (which carry the weight and hardly move with fore-aft or lateral input).
    run = human.simulate(ehm.random_vibration(axis, 1.0, 0.3, seed=1), method="nonlinear")
    fig = plot_time_histories(run)
    try:
        panels = _force_panels(fig)
        assert list(panels) == [axis]
        ax = panels[axis]
        assert ax.get_ylabel() == f"support force {axis} [N]"
        k = "xyz".index(axis)
        lines = {ln.get_label(): ln.get_ydata() for ln in ax.get_lines()}
        assert set(lines) == {f"{s} F{axis}" for s in run.support_N}
        for s, f in run.support_N.items():
            np.testing.assert_array_equal(lines[f"{s} F{axis}"], f[:, k])
        assert max(np.ptp(f[:, k]) for f in run.support_N.values()) > 1.0  # the panel shows forces that move
    finally:
        plt.close(fig)


def test_time_histories_of_a_run_in_three_axes_show_three_force_panels(human, tmp_path):
    run = human.simulate(ehm.random_vibration("xyz", 0.5, 0.3, seed=2), method="nonlinear")
    fig = plot_time_histories(run)
    try:
        panels = _force_panels(fig)
        assert sorted(panels) == ["x", "y", "z"]
        for a, ax in panels.items():
            seat_pan = {ln.get_label(): ln.get_ydata() for ln in ax.get_lines()}[f"seat_pan F{a}"]
            np.testing.assert_array_equal(seat_pan, run.support_N["seat_pan"][:, "xyz".index(a)])
    finally:
        plt.close(fig)
    plot_time_histories(run, tmp_path / "th.png")  # and it draws to a file
    assert (tmp_path / "th.png").stat().st_size > 0
    assert plt.get_fignums() == []  # saving closes the figure: no figures pile up across tests


def test_excited_axes():
    from ehm.outputs.plotting import excited_axes

    t = np.arange(1000) * 0.001
    s = np.sin(2 * np.pi * 3 * t)
    assert excited_axes(np.column_stack([s, 0 * s, 0 * s])) == "x"
    assert excited_axes(np.column_stack([0.05 * s, s, 0.2 * s])) == "yz"  # 5 % of the largest: not excited
    assert excited_axes(np.column_stack([s, s, s])) == "xyz"
    assert excited_axes(np.zeros((10, 3))) == "z"  # a seat at rest: the forces that carry the weight


def o_is_title(artist, fig) -> bool:
    """Whether ``artist`` is the figure's title (its text, a direct child of the figure)."""
    return artist.get_text() == fig.get_suptitle() and artist in fig.get_children()


def test_long_titles_fit_the_figure(human):
    """A measured log's description runs to 300 characters (the weighted spectra's title was cut at both sides on
    every real log): drawn, the title lies inside the figure, on at most three lines; a short one stays one line."""
    from dataclasses import replace

    from ehm.outputs.plotting import TITLE_MAX_LINES, fit_title, plot_weighted_spectra

    with pytest.warns(ehm.EhmWarning):  # 3 s cannot cover the Wf band
        a = ehm.assess(ehm.random_vibration("z", 3.0, 0.3, seed=1), human, method="linear")
    long = ("from SYNTHETIC_phone_log.csv (cut from 10 s to 285 s), 14030 samples, 274.994 s, levelled: tilt 1.02 "
            "deg, g 9.544 m/s^2 removed, from the quietest window 203.199-208.255 s, resampled to dt 0.02 s, "
            "resampled to dt 0.001 s")
    for description, lines in ((long, (2, TITLE_MAX_LINES)), ("short", (1, 1))):
        fig = plot_weighted_spectra(replace(a, description=description))
        try:
            fig.canvas.draw()
            title = next(t for t in fig.findobj(lambda o: hasattr(o, "get_text")) if o_is_title(t, fig))
            box, page = title.get_window_extent(), fig.bbox
            assert box.x0 >= page.x0 and box.x1 <= page.x1 and box.y1 <= page.y1, description
            assert lines[0] <= title.get_text().count("\n") + 1 <= lines[1]
        finally:
            plt.close(fig)
    cut = fit_title("word " * 400, 5.0)
    assert cut.count("\n") == TITLE_MAX_LINES - 1 and cut.endswith("…")
