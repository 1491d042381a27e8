"""The paper's joint-locking findings (section 4), measured on this model with its default parameters."""

from __future__ import annotations

import pytest

from ehm.cli import main
from ehm.study import locking_study


@pytest.fixture(scope="module")
def study():
    return locking_study(method="linear")


def test_spine_locked_raises_the_vertical_mode(study):
    # Paper: with T12 locked (SL) the vertical response peaks at an unrealistically high frequency (~8 Hz).
    # Here: trunk and head z peaks must move up by more than 1 Hz.
    for point in ("trunk", "head"):
        base = study.row("baseline", "z", point, "z").peak_hz
        sl = study.row("SL", "z", point, "z").peak_hz
        assert sl > base + 1.0, (point, base, sl)


def test_neck_locked_lowers_head_roll_under_lateral_input(study):
    # Paper: with the lower neck locked (NL) head roll under lateral loading drops.
    assert study.row("NL", "y", "head", "roll").band_mean_change_pct < -5
    assert study.row("NL", "y", "head", "roll").peak_gain_change_pct < 0


def test_neck_locked_lowers_head_pitch(study):
    # Paper: NL slightly reduces head pitch in fore-aft and vertical loading (0.5-4 Hz mean gain here).
    assert study.row("NL", "x", "head", "pitch").band_mean_change_pct < 0
    assert study.row("NL", "x", "head", "pitch").peak_gain_change_pct < 0
    assert study.row("NL", "z", "head", "pitch").band_mean_change_pct < 0


def test_cli_study_writes_table_and_figure(tmp_path, capsys):
    out = tmp_path / "lock"
    assert main(["study", "locking", "--out", str(out), "--variant", "NL2=lower_neck,upper_neck"]) == 0
    for name in ("locking.csv", "locking.json", "locking.png", "frf_baseline.csv", "frf_NL2.csv"):
        assert (out / name).stat().st_size > 0
    import csv

    from ehm.frf import read_frf_csv
    from ehm.study import STUDY_PATHS

    rows = list(csv.DictReader(open(out / "locking.csv")))
    assert len(rows) == 4 * len(STUDY_PATHS)  # baseline, SL, NL, NL2
    # Independent route: the peak in the written FRF file equals the table's peak for that path.
    row = next(r for r in rows if (r["variant"], r["input_axis"], r["point"], r["dof"]) == ("SL", "z", "trunk", "z"))
    f_pk, g_pk = read_frf_csv(out / "frf_SL.csv").curve("z", "trunk", "z").peak((0.3, 15.0))
    assert float(row["peak_hz"]) == pytest.approx(f_pk, abs=0.02)
    assert float(row["peak_gain"]) == pytest.approx(g_pk, rel=1e-5)
    assert main(["study", "locking", "--out", str(out), "--variant", "bad"]) == 2
    assert "NAME=JOINT" in capsys.readouterr().err
