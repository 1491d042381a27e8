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
