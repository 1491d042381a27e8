"""FRF tables as files and as values: the person recorded, ehm's own tables told from measured ones, the peaks,
a short repr, and what ``ehm frf`` and ``ehm plot-frf`` say (issue 38, item 4); what the transfer-function
functions refuse (issue 38, item 5)."""

from __future__ import annotations

import numpy as np
import pytest

import ehm
from ehm.analysis.frf import FrfTable, read_frf, read_frf_csv
from ehm.errors import InputError
from ehm.interfaces.cli import main
from ehm.standards.transfer import Curve

FREQ_HZ = np.arange(0.5, 10.01, 0.5)


@pytest.fixture(scope="module")
def slouched():
    """The linear route's z table of a slouched person without back support, head control on."""
    person = ehm.Person(posture="slouched", back_support="none", head_control=True)
    return person, ehm.linear_frf(person, "z", freq_hz=FREQ_HZ)


def test_csv_records_the_person_and_reads_back_as_ehms_own(slouched, tmp_path):
    """The CSV's comment lines record the method and Person.to_dict(); read_frf gives the method and the person
    back (not "measured"), with the same curves; the posture, back support and head control as they took
    effect are there too."""
    person, table = slouched
    path = tmp_path / "frf.csv"
    table.write(path)
    back = read_frf(path)
    assert back.method == "linear" and back.meta["written_by"] == "ehm" and back.meta["file"] == str(path)
    assert back.meta["person"] == person.to_dict()
    assert ehm.Person.from_dict(back.meta["person"]) == person
    assert back.meta["seated"] == {"posture": "slouched", "back_support": "none", "head_control": True}
    assert set(back.curves) == set(table.curves)
    np.testing.assert_allclose(back.curve("z", "head", "z").gain, table.curve("z", "head", "z").gain, rtol=1e-7)


@pytest.mark.requires_pyarrow
def test_parquet_records_the_person_too(slouched, tmp_path):
    person, table = slouched
    table.write(tmp_path / "frf.parquet")
    back = read_frf(tmp_path / "frf.parquet")
    assert back.method == "linear" and back.meta["person"] == person.to_dict()


def test_a_measured_file_stays_measured(tmp_path):
    """A long-format table without ehm's record (SYNTHETIC numbers) is measured; a measured table that ehm writes
    records "measured" and reads back as such; a record that is not ehm's (a comment that is not JSON) is ignored."""
    path = tmp_path / "measured.csv"
    path.write_text("# SYNTHETIC gains\n# ehm: not json\ninput_axis,point,dof,freq_hz,gain\nz,head,z,1,1.0\n"
                    "z,head,z,2,1.5\n")
    assert read_frf_csv(path).method == "measured" and "person" not in read_frf_csv(path).meta
    curve = Curve(np.array([1.0, 2.0]), np.array([1.0, 1.5]), np.full(2, np.nan), np.full(2, np.nan))
    FrfTable({("z", "head", "z"): curve}, method="measured").to_csv(tmp_path / "m.csv")
    assert read_frf(tmp_path / "m.csv").method == "measured"


def test_peaks_and_a_short_repr(slouched):
    """peaks(): one row per path along its input axis, each the curve's own peak; repr: one line of at most 300
    characters with the posture and the head's peak (the dataclass repr printed every array: 988 kB)."""
    _, table = slouched
    peaks = {key: (f, g, unit) for key, f, g, unit in table.peaks()}
    assert set(peaks) == {("z", p, "z") for p in ("pelvis", "trunk", "head", "lumbar", "support", "seat_pan")}
    f, g = table.curve("z", "head", "z").peak((0.5, 10.0))
    assert peaks[("z", "head", "z")] == (f, g, "(m/s^2)/(m/s^2)") and peaks[("z", "support", "z")][2] == "kg"
    text = repr(table)
    assert "\n" not in text and len(text) < 300
    assert "slouched" in text and "back support none" in text and f"{g:.3g} at {f:.3g} Hz" in text


def test_cli_frf_prints_the_peaks(tmp_path, capsys):
    out = tmp_path / "f.csv"
    assert main(["frf", "--axis", "z", "--df", "0.5", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    table = read_frf(out)
    f, g = table.curve("z", "head", "z").peak((float(FREQ_HZ[0]) - 0.4, 12.0))
    assert "peaks along each input axis (erect, back support high" in text
    assert "seat z -> head" in text and f"{g:8.3g} (m/s^2)/(m/s^2) at {f:5.2f} Hz" in text
    assert "apparent mass (all supports)" in text and "the person recorded in the file" in text
    assert table.method == "linear"


def test_plot_frf_marks_paths_without_a_response(slouched, tmp_path, capsys):
    """Under vertical input a symmetric person's sideways paths hold round-off gains (below 1e-4 of the largest):
    empty_paths names exactly those (y, roll, yaw of each point), plot-frf says how many it drew empty."""
    from ehm.outputs.plotting import NO_RESPONSE_SHARE, empty_paths

    _, table = slouched
    empty = empty_paths([("model", table)], "z")
    assert set(empty) == {(p, d) for p in ("pelvis", "trunk", "head", "lumbar") for d in ("y", "roll", "yaw")}
    gains = {(p, d): float(c.gain.max()) for (_, p, d), c in table.curves.items() if p not in ("support", "seat_pan")}
    for kind in (("x", "y", "z"), ("roll", "pitch", "yaw")):  # each kind against its own largest gain
        largest = max(g for (p, d), g in gains.items() if d in kind)
        assert all((g < NO_RESPONSE_SHARE * largest) == ((p, d) in empty) for (p, d), g in gains.items() if d in kind)
    table.write(tmp_path / "f.csv")
    assert main(["plot-frf", str(tmp_path / "f.csv"), "--out", str(tmp_path / "g.png")]) == 0
    out = capsys.readouterr().out
    assert "12 paths without a response" in out and "12 under seat z" in out and (tmp_path / "g.png").is_file()


@pytest.mark.parametrize("freq, bad", [([-1.0, 0.0, 1.0], "-1 Hz"), ([0.0, 1.0], "0 Hz"), (0.0, "0 Hz")])
def test_linear_frf_refuses_frequencies_at_or_below_zero(human, freq, bad):
    # issue 38: linear_frf(freq_hz=[-1, 0, 1]) returned gains at -1 and 0 Hz
    with pytest.raises(InputError, match=f"freq_hz holds {bad}: a frequency response needs frequencies above 0 Hz"):
        ehm.linear_frf(human, "z", freq_hz=freq)


def test_linear_frf_takes_one_positive_frequency(human):
    table = ehm.linear_frf(human, "z", freq_hz=5.0)
    assert table.curve("z", "head", "z").freq_hz.tolist() == [5.0]


@pytest.mark.parametrize("band", [(0.0, 12.0), (-1.0, 12.0), (12.0, 1.0), (1.0,)])
def test_time_domain_frf_refuses_a_band_at_or_below_zero(human, band):
    with pytest.raises(InputError, match="band_hz"):
        ehm.time_domain_frf(human, "z", duration_s=10.0, band_hz=band)
