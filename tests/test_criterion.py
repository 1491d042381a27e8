"""The paper's criterion (Eqs. 2-3) and the long-format FRF files."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ehm.analysis.criterion import compare, curve_criterion, relative_gain
from ehm.analysis.frf import Curve, FrfTable, read_frf_csv
from ehm.errors import InputError

HEADER = "input_axis,point,dof,freq_hz,gain,phase_deg,coherence\n"


def test_criterion_by_hand():
    # Eq. 2: Rel = G_exp + 0.05 mean(G_exp); mean of (1, 2) = 1.5, so Rel = (1.075, 2.075).
    f = np.array([1.0, 2.0])
    g_exp = np.array([1.0, 2.0])
    g_mod = np.array([1.5, 1.0])
    np.testing.assert_allclose(relative_gain(g_exp), [1.075, 2.075])
    # Eq. 3: terms (1 - 1.5) / (1.075 * 1) = -0.465116..., (2 - 1) / (2.075 * 4) = 0.120482...
    t1, t2 = -0.5 / 1.075, 1.0 / (2.075 * 4)
    assert curve_criterion(f, g_exp, g_mod) == pytest.approx(math.sqrt((t1 ** 2 + t2 ** 2) / 2), rel=1e-12)
    assert curve_criterion(f, g_exp, g_exp) == 0.0


def _table(curves: dict, method="model") -> FrfTable:
    nan = lambda n: np.full(n, np.nan)  # noqa: E731
    return FrfTable({k: Curve(np.asarray(f, float), np.asarray(g, float), nan(len(f)), nan(len(f)), nan(len(f)), w)
                     for k, (f, g, w) in curves.items()}, method)


def test_compare_interpolates_and_weights():
    # The model curve is linear in f, so linear interpolation onto 1.5 Hz is exact: 1.5.
    model = _table({("z", "head", "z"): ([1.0, 2.0], [1.0, 2.0], 1.0),
                    ("x", "head", "x"): ([1.0, 2.0], [1.0, 1.0], 1.0)})
    data = _table({("z", "head", "z"): ([1.5], [1.5], 3.0), ("x", "head", "x"): ([1.0], [2.0], 1.0)}, "measured")
    res = compare(data, model, (0.1, 12))
    crit = {(c.input_axis, c.point, c.dof): c.crit for c in res.curves}
    assert crit[("z", "head", "z")] == 0.0
    assert crit[("x", "head", "x")] == pytest.approx(1.0 / 2.1)  # (2 - 1) / ((2 + 0.1) * 1^2)
    assert res.total == pytest.approx((3 * 0.0 + 1 * (1.0 / 2.1)) / 4)


def test_compare_band_and_missing_curve():
    model = _table({("z", "head", "z"): ([0.5, 20.0], [1.0, 1.0], 1.0)})
    data = _table({("z", "head", "z"): ([0.5, 15.0], [2.0, 100.0], 1.0)}, "measured")
    # 15 Hz lies outside the default 0.1-12 Hz band: only the 0.5 Hz point counts.
    assert compare(data, model).curves[0].n_freq == 1
    with pytest.raises(InputError, match="no curve for seat y -> head roll"):
        compare(_table({("y", "head", "roll"): ([1.0], [1.0], 1.0)}, "measured"), model)


def test_frf_csv_round_trip(tmp_path):
    t = _table({("y", "trunk", "yaw"): ([0.5, 1.0, 2.0], [0.1, 0.2, 0.3], 1.0)})
    t.to_csv(tmp_path / "a.csv")
    back = read_frf_csv(tmp_path / "a.csv")
    c = back.curve("y", "trunk", "yaw")
    np.testing.assert_allclose(c.freq_hz, [0.5, 1.0, 2.0])
    np.testing.assert_allclose(c.gain, [0.1, 0.2, 0.3])


@pytest.mark.parametrize("row, expected", [
    ("z,neck,z,1,1,,", r"line 3, column point: unknown point 'neck'"),
    ("z,head,surge,1,1,,", r"line 3, column dof: unknown dof 'surge'"),
    ("w,head,z,1,1,,", r"line 3, column input_axis"),
    ("z,head,z,0,1,,", r"line 3, column freq_hz: frequency 0 Hz must be positive"),
    ("z,head,z,-1,1,,", r"line 3, column freq_hz"),
    ("z,head,z,2,nan,,", r"line 3, column gain: 'nan' is not a finite number"),
    ("z,head,z,2,abc,,", r"line 3, column gain: 'abc' is not a number"),
    ("z,head,z,1,1,,", r"line 3, column freq_hz: frequency 1 Hz appears twice"),
])
def test_measured_file_errors(tmp_path, row, expected):
    path = tmp_path / "exp.csv"
    path.write_text(HEADER + "z,head,z,1,1.2,,\n" + row + "\n")
    with pytest.raises(InputError, match=expected) as err:
        read_frf_csv(path)
    assert "exp.csv" in str(err.value)


def test_measured_file_missing_column(tmp_path):
    path = tmp_path / "exp.csv"
    path.write_text("input_axis,point,dof,freq_hz\nz,head,z,1\n")
    with pytest.raises(InputError, match="missing column 'gain'"):
        read_frf_csv(path)
