"""A person's MISC parameters from their ratings of a drive (issue 37, item 4), and the MISC rating in an assessment
(item 3): ``ehm.fit_sickness``, ``ehm read_ratings``, ``ehm fit-sickness``, ``ehm assess --sickness-params``.

Every drive and rating here is SYNTHETIC: sinusoidal seat motion, and ratings made from the accumulation model of a
known person."""

from __future__ import annotations

import json

import numpy as np
import pytest

import ehm
from ehm.errors import InputError
from ehm.interfaces.cli import main
from ehm.standards.sickness import MiscParameters, misc_rating


@pytest.fixture(scope="module")
def foreaft_assessment():
    """SYNTHETIC: fore-aft at 0.2 Hz, 1 m/s^2 peak, 240 s, the default person on the linear route."""
    return ehm.assess(ehm.sine("x", 240.0, 1.0, 0.2), method="linear")


def _write(path, text: str):
    path.write_text(text, encoding="utf-8")
    return path


def test_the_assessment_carries_misc_beside_msi(foreaft_assessment, tmp_path):
    a = foreaft_assessment
    for key in ("head", "seat"):
        trace = a.sickness[key]
        assert trace.misc.shape == trace.msi_percent.shape and 0.0 < trace.final_misc <= 10.0
        np.testing.assert_allclose(trace.misc, misc_rating(trace.conflict_magnitude_mps2, trace.time_s[1]), atol=1e-9)
        assert a.summary()["sickness"][key]["final_misc"] == trace.final_misc
    frame = a.to_dataframe()
    row = frame[(frame.metric == "misc_final") & (frame.location == "head")]
    assert row.value.item() == a.sickness["head"].final_misc and row.unit.item() == "MISC"
    assert a.summary()["sickness_misc_params"]["whose"] == "group"
    from ehm.analysis.assessment import write_sickness_csv

    path = write_sickness_csv(a, tmp_path)[0]
    header, *rows = path.read_text().splitlines()
    assert header == "time_s,msi_percent,conflict_mps2,misc" and len(rows) == a.sickness["head"].time_s.size


def test_a_persons_parameters_change_the_assessments_misc():
    drive = ehm.sine("x", 60.0, 1.0, 0.2)
    group = ehm.assess(drive, method="linear")
    sensitive = ehm.assess(drive, method="linear", sickness_params=MiscParameters(fast_gain=2000.0))
    assert sensitive.sickness["head"].final_misc > group.sickness["head"].final_misc
    np.testing.assert_array_equal(sensitive.sickness["head"].msi_percent, group.sickness["head"].msi_percent)
    with pytest.raises(InputError, match="sickness_params must be an ehm.MiscParameters or None"):
        ehm.assess(drive, method="linear", sickness_params={"fast_gain": 1.0})


def test_fit_sickness_gives_back_the_person_the_ratings_were_made_from(foreaft_assessment):
    # SYNTHETIC ratings: the model's MISC of a known person (K1 500, T1 60 s) every 20 s, from the head's conflict.
    trace = foreaft_assessment.sickness["head"]
    person = MiscParameters(fast_gain=500.0, fast_time_constant_s=60.0)
    times = np.arange(20.0, 240.0, 20.0)
    rated = np.interp(times, trace.time_s, misc_rating(trace.conflict_magnitude_mps2, trace.time_s[1], person))
    result = ehm.fit_sickness(foreaft_assessment, (times, rated))
    assert result.params.fast_gain == pytest.approx(500.0, rel=1e-3)
    assert result.params.fast_time_constant_s == pytest.approx(60.0, rel=1e-3)
    assert result.fit.rms_misc < 1e-3 < result.fit.rms_misc_group
    with pytest.raises(InputError, match=r"rating 3: time_s 300 s lies outside the drive .*\(0-239.95 s\)"):
        ehm.fit_sickness(foreaft_assessment, ([20.0, 40.0, 300.0], [1.0, 2.0, 3.0]))


@pytest.mark.parametrize(("text", "words"), [
    ("time_s,rating\n1,2\n", "the header has no column 'misc' (it has 'time_s', 'rating')"),
    ("time_s,misc\n10,1\n20,x\n", "row 3: misc 'x' is not a number"),
    ("time_s,misc\n10,1\n20,11\n", "row 3: misc 11 lies outside the MISC scale's 0-10"),
    ("time_s,misc\n10,1\n\n5,2\n", "row 4: time_s 5 s does not follow the row before's 10 s"),
    ("time_s,misc\n", "a header but no ratings"),
    ("", "the ratings file is empty"),
])
def test_bad_ratings_are_one_sentence_naming_file_row_and_value(tmp_path, text, words):
    path = _write(tmp_path / "ratings.csv", text)
    with pytest.raises(InputError, match="ratings.csv") as info:
        ehm.read_ratings(path)
    assert words in str(info.value) and "\n" not in str(info.value)


@pytest.mark.filterwarnings("always::ehm.errors.EhmWarning")  # the command line prints them (a 100 Hz file)
def test_cli_fit_sickness_writes_the_file_assess_reads(tmp_path, capsys):
    # SYNTHETIC: a 120 s fore-aft drive and ratings of a person more susceptible than the group.
    t = np.arange(0.0, 120.0, 0.01)
    drive = tmp_path / "drive.csv"
    np.savetxt(drive, np.column_stack([t, np.sin(2 * np.pi * 0.2 * t), 0 * t, 0 * t]), delimiter=",",
               header="time_s,ax_mps2,ay_mps2,az_mps2", comments="", fmt="%.6g")
    ratings = _write(tmp_path / "ratings.csv", "time_s,misc\n" + "".join(
        f"{s},{m}\n" for s, m in ((15, 1), (30, 2), (45, 3), (60, 3), (75, 4), (90, 4), (105, 4))))
    out = tmp_path / "fit"
    assert main(["fit-sickness", "--motion", str(drive), "--ratings", str(ratings), "--out", str(out), "--quiet",
                 "--method", "linear"]) == 0
    printed = capsys.readouterr().out
    assert "K1 (fast_gain)" in printed and "T1 (fast_time_constant_s)" in printed
    for name in ("sickness_params.toml", "sickness_fit.csv", "sickness_fit.png"):
        assert (out / name).stat().st_size > 0
    person = ehm.read_sickness_params(out / "sickness_params.toml")
    assert person != MiscParameters() and person.slow_gain == MiscParameters().slow_gain
    assessed = tmp_path / "assessed"
    assert main(["assess", "--motion", str(drive), "--out", str(assessed), "--quiet", "--method", "linear",
                 "--sickness-params", str(out / "sickness_params.toml")]) == 0
    printed = capsys.readouterr().out
    assert "predicted MISC rating at the end (0-10, person (" in printed
    summary = json.loads((assessed / "assessment.json").read_text())
    assert summary["sickness_misc_params"]["fast_gain"] == person.fast_gain
    assert summary["sickness_misc_params"]["whose"].startswith("person (")
    header = (assessed / "sickness_head.csv").read_text().splitlines()[0]
    assert header == "time_s,msi_percent,conflict_mps2,misc"
    assert "Predicted MISC rating" in (assessed / "report.html").read_text()
    back = ehm.read_assessment(assessed)
    assert back.sickness["head"].final_misc == pytest.approx(summary["sickness"]["head"]["final_misc"], rel=1e-12)


def test_cli_refuses_ratings_after_the_drive_before_running_it(tmp_path, capsys):
    ratings = _write(tmp_path / "ratings.csv", "time_s,misc\n10,1\n20,2\n99999,3\n")
    assert main(["fit-sickness", "--motion", "road", "--ratings", str(ratings), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("ehm: error: ") and "\n" not in err
    assert "ratings.csv row 4: time_s 99999 s lies after the end of the drive" in err


def test_cli_assess_refuses_a_bad_sickness_params_file(tmp_path, capsys):
    bad = _write(tmp_path / "p.toml", "[misc]\nfast_gain = 'high'\n")
    assert main(["assess", "--motion", "road", "--out", str(tmp_path / "o"), "--sickness-params", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "p.toml: MiscParameters: fast_gain must be a number, got 'high'; correct it" in err
