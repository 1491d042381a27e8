"""Results where the user works (issue 32, items 1 and 2): ``to_dataframe()`` with units in the column names and
the run's description and route in ``attrs``, ``to_xarray()`` for a run's points x axes x time, and the short
``_repr_html_`` table a notebook shows.

Values are compared exactly (``np.testing.assert_array_equal``): the frames copy the arrays they come from, so any
difference is a row or a column in the wrong place, not rounding.  The html tables print figures to 4 significant
digits, so they are searched for the figure formatted that way.
"""

from __future__ import annotations

import sys

import numpy as np
import pytest

import ehm
from ehm.analysis.frf import COLUMNS, read_frf_csv
from ehm.analysis.study import STUDY_PATHS, locking_study
from ehm.interfaces.batch import output_fields, read_results, write_table


@pytest.fixture(scope="module")
def run(human):
    """A short linear-route run (milliseconds): every signal a RunResult holds."""
    return human.simulate(ehm.random_vibration("z", 2.0, 0.5, seed=3), method="linear")


@pytest.fixture(scope="module")
def assessment():
    """An assessment of a 3 s vertical vibration on the linear route (the fast one)."""
    with pytest.warns(ehm.EhmWarning):  # 3 s cannot cover the Wf band: warned, as it should be
        return ehm.assess(ehm.random_vibration("z", 3.0, 0.5, seed=4), method="linear")


def _figure(x: float) -> str:
    return f"{x:.4g}"


def test_run_long_frame_has_units_in_its_columns_and_the_arrays_values(run):
    """"to_dataframe() (tidy, long format ...; units in the column names)" on RunResult: one row per sample,
    location and axis; each quantity's column holds exactly the array it comes from."""
    df = run.to_dataframe()
    assert list(df.columns) == ["time_s", "location", "axis", "acc_mps2", "disp_m", "rot_rad", "angacc_radps2",
                                "force_N"]
    assert list(df["location"].cat.categories) == ["seat", "pelvis", "trunk", "head", "lumbar", *run.support_N]
    assert len(df) == len(run.time_s) * 3 * (1 + len(run.points) + len(run.support_N))
    head_z = df[(df.location == "head") & (df.axis == "z")]
    np.testing.assert_array_equal(head_z.time_s, run.time_s)
    np.testing.assert_array_equal(head_z.acc_mps2, run.point("head").acc_mps2[:, 2])
    np.testing.assert_array_equal(head_z.rot_rad, run.point("head").rot_rad[:, 2])
    trunk_x = df[(df.location == "trunk") & (df.axis == "x")]
    np.testing.assert_array_equal(trunk_x.disp_m, run.point("trunk").disp_m[:, 0])
    np.testing.assert_array_equal(trunk_x.angacc_radps2, run.point("trunk").angacc_radps2[:, 0])
    seat = df[df.location == "seat"]
    np.testing.assert_array_equal(seat[seat.axis == "z"].acc_mps2, run.seat_acc_mps2[:, 2])
    assert seat.disp_m.isna().all() and seat.force_N.isna().all()  # the seat has no displacement or force
    pan_z = df[(df.location == "seat_pan") & (df.axis == "z")]
    np.testing.assert_array_equal(pan_z.force_N, run.support_N["seat_pan"][:, 2])


def test_run_frame_attrs_hold_description_and_route(human, run):
    """"the run's description and route in DataFrame.attrs": the linear route and the nonlinear one."""
    attrs = run.to_dataframe().attrs
    assert attrs["description"] == run.description and attrs["route"] == "linear"
    assert attrs["dt_s"] == run.dt_s and attrs["mass_kg"] == run.mass_kg and attrs["locked"] == "+".join(run.locked)
    nonlinear = human.simulate(ehm.sine("z", 2.0, 0.5, 0.3), method="nonlinear")
    assert nonlinear.to_dataframe(wide=True).attrs["route"] == "nonlinear"


def test_run_wide_frame_is_timeseries_csv(run, tmp_path):
    """"an option wide=True for one column per signal": the columns of timeseries.csv, the same numbers."""
    wide = run.to_dataframe(wide=True)
    header, data = run.columns()
    assert list(wide.columns) == header and "head_az_mps2" in header and "seat_pan_fz_N" in header
    np.testing.assert_array_equal(wide.to_numpy(), data)
    run.write(tmp_path / "run")
    on_disk = (tmp_path / "run" / "timeseries.csv").read_text().splitlines()[0].split(",")
    assert on_disk == list(wide.columns)


@pytest.mark.requires_xarray
def test_run_to_xarray_is_points_by_axes_by_time(run):
    """"to_xarray() where the data are naturally labelled arrays (a run's points x axes x time)"."""
    ds = run.to_xarray()
    assert ds["acc_mps2"].dims == ("point", "axis", "time_s") and ds["acc_mps2"].attrs["units"] == "m/s^2"
    np.testing.assert_array_equal(ds["acc_mps2"].sel(point="head", axis="z"), run.point("head").acc_mps2[:, 2])
    np.testing.assert_array_equal(ds["gia_mps2"].sel(point="trunk", axis="y"), run.point("trunk").gia_mps2[:, 1])
    np.testing.assert_array_equal(ds["force_N"].sel(support="floor", axis="x"), run.support_N["floor"][:, 0])
    np.testing.assert_array_equal(ds["seat_acc_mps2"].sel(axis="z"), run.seat_acc_mps2[:, 2])
    assert ds.attrs["route"] == "linear" and ds.attrs["description"] == run.description


def test_to_xarray_without_xarray_is_one_sentence(run, monkeypatch):
    """"imported inside the method with one clear sentence when missing"."""
    monkeypatch.setitem(sys.modules, "xarray", None)  # import xarray now raises ImportError
    with pytest.raises(ehm.InputError, match=r"needs xarray: pip install 'ehm\[xarray\]'"):
        run.to_xarray()


def test_run_repr_html_shows_what_was_run_and_rms(run):
    """"_repr_html_ (a short table: what was run, the headline figures)"."""
    page = run._repr_html_()
    assert "linear" in page and "random" in page
    assert _figure(np.sqrt(np.mean(run.point("head").acc_mps2[:, 2] ** 2))) in page
    assert _figure(np.sqrt(np.mean(run.seat_acc_mps2[:, 2] ** 2))) in page


def test_frf_frame_reuses_the_csv_columns(human, tmp_path):
    """FrfTable "has a long format CSV already: reuse the same columns", plus the gain's unit per row."""
    table = ehm.linear_frf(human, "z", freq_hz=np.arange(0.5, 10.01, 0.5))
    df = table.to_dataframe()
    table.to_csv(tmp_path / "frf.csv")
    lines = (tmp_path / "frf.csv").read_text().splitlines()
    header = lines[2].split(",")  # after the two comment lines that record how ehm made the table
    assert lines[0].startswith("# ehm FRF table (linear method)") and lines[1].startswith("# ehm: {")
    assert list(df.columns) == header + ["gain_unit"] and header == list(COLUMNS)
    rows = df[(df.point == "head") & (df.dof == "pitch")]
    np.testing.assert_array_equal(rows.gain, table.curve("z", "head", "pitch").gain)
    np.testing.assert_array_equal(rows.freq_hz, table.curve("z", "head", "pitch").freq_hz)
    assert set(rows.gain_unit) == {"(rad/s^2)/(m/s^2)"}
    assert set(df[df.point == "support"].gain_unit) == {"kg"}
    assert df.attrs["route"] == "linear" and df.attrs["method"] == "linear"
    f, g = table.curve("z", "head", "z").peak((0.5, 10.0))
    page = table._repr_html_()
    assert _figure(f) in page and _figure(g) in page


def test_measured_frf_frame_keeps_sd_and_weight(tmp_path):
    """A measured table (SYNTHETIC file) carries gain_sd and weight, like its CSV."""
    path = tmp_path / "measured.csv"
    path.write_text("input_axis,point,dof,freq_hz,gain,gain_sd,weight\n"
                    "z,head,z,1,1.0,0.1,2\nz,head,z,2,1.5,0.2,2\n")
    df = read_frf_csv(path).to_dataframe()
    assert list(df.columns) == list(COLUMNS) + ["gain_sd", "weight", "gain_unit"]
    np.testing.assert_array_equal(df.gain_sd, [0.1, 0.2])
    assert df.attrs["description"] == str(path) and df.attrs["method"] == "measured"


def test_assessment_frame_is_location_axis_metric_value_unit(assessment):
    """Assessment.to_dataframe: "location, axis, metric, value, unit; sickness too", the values of
    assessment.json (summary())."""
    df = assessment.to_dataframe()
    assert list(df.columns) == ["location", "axis", "metric", "value", "unit"]
    s = assessment.summary()
    get = lambda loc, axis, metric: df[(df.location == loc) & (df.axis == axis) & (df.metric == metric)]  # noqa: E731
    aw = get("head", "z", "a_w")
    assert aw.value.item() == s["locations"]["head"]["axes"]["z"]["a_w_mps2"] and aw.unit.item() == "m/s^2"
    vdv = get("seat", "z", "vdv")
    assert vdv.value.item() == s["locations"]["seat"]["axes"]["z"]["vdv_mps175"] and vdv.unit.item() == "m/s^1.75"
    assert get("trunk", "xyz", "total_value").value.item() == s["locations"]["trunk"]["total_value_mps2"]
    assert get("head", "z", "msdv").unit.item() == "m/s^1.5"
    msi = get("head", "xyz", "msi_final")
    assert msi.value.item() == s["sickness"]["head"]["final_msi_percent"] and msi.unit.item() == "%"
    assert get("seat", "xyz", "conflict_max").value.item() == s["sickness"]["seat"]["max_conflict_mps2"]
    assert np.isnan(get("seat", "x", "crest_factor").value.item())  # no x motion: undefined, NaN
    assert df.attrs["route"] == "linear" and df.attrs["description"] == assessment.description


def test_assessment_repr_html_has_the_headline_figures(assessment):
    """Notebook display of an assessment: the total values, a_w per axis and the head's MSI."""
    page = assessment._repr_html_()
    assert _figure(assessment.total_value("head")) in page
    assert _figure(assessment.metrics["pelvis"]["z"].a_w) in page
    assert _figure(assessment.sickness["head"].final_msi_percent) in page and "comfort reaction" in page


def test_locking_study_frame_and_display():
    """The locking study's result: one row per variant and path, the StudyRow's columns, units in names."""
    study = locking_study()
    df = study.to_dataframe()
    assert list(df.columns) == ["variant", "locked", "input_axis", "point", "dof", "peak_hz", "peak_gain",
                                "band_mean_gain", "peak_hz_change_pct", "peak_gain_change_pct",
                                "band_mean_change_pct", "gain_unit"]
    assert len(df) == 3 * len(STUDY_PATHS)
    sl = df[(df.variant == "SL") & (df.input_axis == "z") & (df.point == "trunk") & (df.dof == "z")]
    row = study.row("SL", "z", "trunk", "z")
    assert sl.peak_hz.item() == row.peak_hz and sl.locked.item() == "t12"
    assert df.attrs["method"] == "linear" and df.attrs["band_hz"] == (0.5, 4.0)
    assert _figure(row.peak_hz) in study._repr_html_()


def test_batch_table_has_the_same_shape(tmp_path):
    """The batch result "already a table: make it the same shape": location, axis, metric, value, unit."""
    records = [{"inputs": {"run_id": "a1", "lock": "none"}, "error": None,
                "outputs": {"seat_z->head_z.peak_hz": 5.1, "seat_z->head_z.peak_gain": 1.6, "head.a_v_mps2": 0.4,
                            "trunk.a_w_y_mps2": 0.1, "head.msi_percent": 2.0, "route.linear_share": 0.9}},
               {"inputs": {"run_id": "b2", "lock": "t12"}, "error": "the run diverged.", "outputs": {}}]
    write_table(records, tmp_path)
    df = read_results(tmp_path)
    assert list(df.columns)[:8] == ["run_id", "output", "location", "axis", "metric", "value", "unit", "error"]
    by = df.set_index("output")
    assert tuple(by.loc["seat_z->head_z.peak_hz", ["location", "axis", "metric", "unit"]]) == (
        "head", "z", "peak_frequency", "Hz")
    assert tuple(by.loc["head.a_v_mps2", ["location", "axis", "metric", "unit"]]) == ("head", "xyz", "total_value",
                                                                                     "m/s^2")
    assert tuple(by.loc["trunk.a_w_y_mps2", ["axis", "metric"]]) == ("y", "a_w")
    assert by.loc["error", "error"] == "the run diverged." and np.isnan(by.loc["error", "value"])
    assert df.attrs["source"] == str(tmp_path / "results.parquet")
    assert output_fields("something.else") == {"location": "", "axis": "", "metric": "something.else", "unit": ""}


def test_read_results_without_a_table_is_one_sentence(tmp_path):
    with pytest.raises(ehm.InputError, match="no results.parquet there; run the study first"):
        read_results(tmp_path)


@pytest.mark.requires_pyarrow
def test_read_results_names_the_outputs_of_an_earlier_table(tmp_path):
    """A results.parquet written before issue 32 (run_id, output, value, error only) reads in the same shape."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    pq.write_table(pa.table({"run_id": ["a1", "a1"], "output": ["seat.a_v_mps2", "seat_x->trunk_x.peak_gain"],
                             "value": [0.3, 1.2], "error": ["", ""], "lock": ["none", "none"]}),
                   tmp_path / "results.parquet")
    df = read_results(tmp_path)
    assert list(df.columns) == ["run_id", "output", "location", "axis", "metric", "value", "unit", "error", "lock"]
    assert list(df.unit) == ["m/s^2", "(m/s^2)/(m/s^2)"] and list(df.location) == ["seat", "trunk"]


def test_reprs_are_one_line_with_the_key_figures(run, assessment):
    """repr() outside a notebook (issue 38, item 4: 12 kB of arrays for a RunResult, 94 kB for an Assessment): one
    line with what was run and the headline figures, each computed here independently of the repr."""
    text = repr(run)
    rms = float(np.sqrt(np.mean(run.seat_acc_mps2[:, 2] ** 2)))
    head = float(np.sqrt(np.mean(run.point("head").acc_mps2[:, 2] ** 2)))
    assert "\n" not in text and len(text) < 400 and text.startswith("<RunResult 'band-limited random")
    assert f"rms a_z seat {rms:.3g}, head {head:.3g} m/s^2" in text and "(linear route)" in text
    text = repr(assessment)
    s = assessment.summary()["locations"]
    assert "\n" not in text and len(text) < 400
    assert f"a_v seat {s['seat']['total_value_mps2']:.3g} m/s^2 ({s['seat']['comfort_reaction']})" in text
    assert f"head {s['head']['total_value_mps2']:.3g} m/s^2" in text
    assert f"VDV_z seat {s['seat']['axes']['z']['vdv_mps175']:.3g}" in text
