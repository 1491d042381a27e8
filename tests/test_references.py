"""ehm.standards.references (issue 29, item 1): the reference curves, bands and findings in the package, each with its
source
and the condition it describes, as data a validation can evaluate."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest
from scipy import signal

from ehm.errors import InputError
from ehm.standards import references as ref


def test_iso2631_5_transfer_function_has_the_standards_figures():
    """"The ISO 2631-5:2018 seat-to-lumbar transfer function (from its poles and zero)": |H| at the frequencies the
    project's notes quote from the standard's curve (two decimals: tolerance 0.005), 1 at 0 Hz."""
    f = np.array([0.0, 1.0, 2.0, 4.0, 4.7, 6.0, 8.0, 10.0, 15.0, 20.0])
    expected = [1.0, 1.01, 1.06, 1.42, 1.59, 1.14, 0.87, 0.82, 0.77, 0.71]
    np.testing.assert_allclose(np.abs(ref.iso2631_5_lumbar_tf(f)), expected, atol=0.005)
    grid = np.arange(0.5, 20.0, 0.01)
    gain = np.abs(ref.iso2631_5_lumbar_tf(grid))
    assert grid[np.argmax(gain)] == pytest.approx(4.7, abs=0.05) and gain.max() == pytest.approx(1.59, abs=0.005)


def test_iso2631_5_formula_1_equals_its_polynomials_and_annex_d():
    """Independent routes to the same curve: Formula 1 multiplied out into polynomials in s and evaluated by
    scipy.signal.freqs (1e-12: round-off), and the standard's own 256 Hz filter of Annex D evaluated by
    scipy.signal.freqz (within 0.0016 in modulus and 0.08 degrees up to 80 Hz, as evaluated; 0.002 and 0.1 allowed:
    a typo in either transcription would show by far more)."""
    (w1, z1), poles = ref.ISO2631_5_ZERO, ref.ISO2631_5_POLES
    num = np.array([1 / w1**2, 2 * z1 / w1, 1.0])
    den = np.array([1.0])
    for w, z in poles:
        den = np.polymul(den, [1 / w**2, 2 * z / w, 1.0])
    f = np.linspace(0.05, 80.0, 1600)
    _, h_poly = signal.freqs(num, den, worN=2 * np.pi * f)
    h = ref.iso2631_5_lumbar_tf(f)
    np.testing.assert_allclose(h, h_poly, rtol=1e-12)
    _, h_d = signal.freqz(ref.ISO2631_5_ANNEX_D_B, ref.ISO2631_5_ANNEX_D_A, worN=f, fs=ref.ISO2631_5_ANNEX_D_FS_HZ)
    assert np.max(np.abs(np.abs(h_d) - np.abs(h))) < 0.002
    assert np.max(np.abs(np.degrees(np.angle(h_d / h)))) < 0.1
    np.testing.assert_allclose(ref.iso2631_5_annex_d_tf(f), h_d, rtol=1e-9)
    assert "ISO 2631-5:2018" in ref.ISO2631_5_SOURCE and "phonometry" in ref.ISO2631_5_SOURCE
    with pytest.raises(InputError, match="Annex D filter's band"):
        ref.iso2631_5_annex_d_tf(200.0)
    with pytest.raises(InputError, match="freq_hz"):
        ref.iso2631_5_lumbar_tf(-1.0)


def test_one_mass_apparent_mass_gives_the_issues_figures():
    """"Fairley & Griffin 1989, one-mass fit (5 Hz, damping ratio 0.475): 1.51 at 4.3 Hz without a frame mass, 1.38
    with a fifth of the mass on the frame; at most 0.61 / 0.53 at 10 / 15 Hz with a frame mass of up to half the
    body".  Those figures hold normalised by the static mass (at 0 Hz), to their two decimals (0.005); normalised at
    0.5 Hz, the fit's own way, each is about 1 % lower (1.49, 1.37)."""
    f = np.arange(0.5, 20.0, 0.01)

    def peak(share, at):
        m = np.abs(ref.apparent_mass_one_mass(f, share, at))
        return m.max(), f[np.argmax(m)]

    assert peak(0.0, 0.0)[0] == pytest.approx(1.51, abs=0.005) and peak(0.0, 0.0)[1] == pytest.approx(4.3, abs=0.05)
    assert peak(0.2, 0.0)[0] == pytest.approx(1.38, abs=0.005)
    assert peak(0.0, 0.5)[0] == pytest.approx(1.49, abs=0.005) and peak(0.2, 0.5)[0] == pytest.approx(1.37, abs=0.005)
    shares = np.linspace(0.0, 0.5, 51)
    for at_hz in (0.0, 0.5):  # "at most": the largest over the frame shares, to two decimals, either normalisation
        worst = {fq: max(abs(ref.apparent_mass_one_mass(fq, s, at_hz)) for s in shares) for fq in (10.0, 15.0)}
        assert round(worst[10.0], 2) <= 0.61 and round(worst[15.0], 2) <= 0.53, (at_hz, worst)
        assert worst[10.0] > 0.59 and worst[15.0] > 0.52  # and near them: the bound is reached (0.60, 0.53)
    # hand computation: without a frame, at the natural frequency |M| / m = |1 + 2j zeta| / |2j zeta|
    z = ref.FAIRLEY_GRIFFIN_DAMPING_RATIO
    assert abs(ref.apparent_mass_one_mass(5.0, 0.0, 0.0)) == pytest.approx(np.hypot(1, 2 * z) / (2 * z), rel=1e-12)
    assert abs(ref.apparent_mass_one_mass(0.5, 0.3)) == pytest.approx(1.0, rel=1e-12)
    with pytest.raises(InputError, match="frame_share"):
        ref.apparent_mass_one_mass(f, 0.6)


def test_bands_carry_their_source_and_condition():
    """"Each with its source and what condition it describes": every band names both; the literature's own bands
    carry the address where they were read; names are unique; holds() takes limits as inclusive and refuses NaN."""
    names = [b.name for b in ref.BANDS]
    assert len(names) == len(set(names)) == 14
    for band in ref.BANDS:
        assert band.source and band.condition and (band.low is not None or band.high is not None), band
        assert band.quantity in ("peak_hz", "peak_gain", "gain", "gain_minus_reference"), band
    by = {b.name: b for b in ref.BANDS}
    assert by["spine_first_resonance"].low == 4.5 and by["spine_first_resonance"].high == 5.5
    assert "https://www.taylorfrancis.com" in by["spine_first_resonance"].source
    assert "Fairley & Griffin 1989" in by["apparent_mass_peak"].source and "https://" in by["apparent_mass_peak"].source
    assert by["apparent_mass_peak"].holds(1.3) and by["apparent_mass_peak"].holds(1.7)
    assert not by["apparent_mass_peak"].holds(1.71) and not by["apparent_mass_peak"].holds(np.nan)
    assert by["apparent_mass_15_20hz"].holds([0.5, 0.6]) and not by["apparent_mass_15_20hz"].holds([0.5, 0.61])
    assert by["lumbar_gain_vs_iso2631_5"].describe() == \
        "gain_minus_reference of z->lumbar z over 1-12 Hz within -0.2-0.2"


def test_each_band_says_where_its_source_applies():
    """"Where each band applies, as data": postures and back supports (None: every one), read by applies() and
    where(); the measurements without back support (ISO 2631-5, the apparent-mass peak, the spine's resonance, the
    whole-body mode) apply there only, erect or slouched; the apparent mass above resonance and the seat-to-head bands
    everywhere; the horizontal head gains at most 3, their source saying the limit is ehm's choice; the locking
    findings on the paper's seat."""
    by = {b.name: b for b in ref.BANDS}
    for name in ("lumbar_gain_vs_iso2631_5", "lumbar_peak_frequency", "spine_first_resonance",
                 "apparent_mass_peak_frequency", "apparent_mass_peak", "pelvis_peak_frequency"):
        b = by[name]
        assert (b.postures, b.back_supports) == (("erect", "slouched"), ("none",)), name
        assert b.applies("slouched", "none") and not b.applies("erect", "low") and not b.applies("reclined", "none")
        assert b.where() == "postures erect, slouched; back support none"
    for name in ("apparent_mass_10hz", "apparent_mass_15_20hz", "head_vertical_peak_gain",
                 "head_vertical_peak_frequency", "head_fore_aft_peak_frequency", "head_lateral_peak_frequency",
                 "head_fore_aft_peak_gain", "head_lateral_peak_gain"):
        assert by[name].applies("reclined", "full") and by[name].where() == "every posture and back support", name
    for name in ("head_fore_aft_peak_gain", "head_lateral_peak_gain"):
        b = by[name]
        assert (b.quantity, b.low, b.high) == ("peak_gain", None, 3.0)
        assert "ehm's choice" in b.source and "https://" in b.source
    assert "no source ehm has read gives a lateral" in by["head_lateral_peak_gain"].source
    assert ref.PAPER_SEAT == ("erect", "high")
    assert all(f.seat == ref.PAPER_SEAT for f in ref.LOCKING_FINDINGS)


def test_the_posture_comparison_is_data_with_its_source():
    """Kitazaki & Griffin 1998: slouched's principal resonance below erect's, without back support; holds() is
    strict (equal is not lower) and refuses NaN."""
    (c,) = ref.COMPARISONS
    assert (c.band, c.lower, c.higher) == ("apparent_mass_peak_frequency", ("slouched", "none"), ("erect", "none"))
    assert c.band in {b.name for b in ref.BANDS}
    assert "Kitazaki & Griffin 1998" in c.source and "Kitazaki & Griffin 1998" in ref.KITAZAKI_GRIFFIN_SOURCE
    assert c.holds(4.0, 4.5) and not c.holds(4.5, 4.5) and not c.holds(5.0, 4.5) and not c.holds(np.nan, 4.5)
    assert c.difference(4.0, 4.5) == pytest.approx(-0.5)


def test_the_references_own_curves_meet_their_bands():
    """The bands are consistent with the curves they rest on: ISO 2631-5's curve meets the lumbar bands, and the
    one-mass fit (no frame mass, and a fifth of the mass on the frame) meets the apparent-mass bands."""
    f = np.arange(0.5, 20.0 + 1e-9, 0.01)
    by = {b.name: b for b in ref.BANDS}
    iso = np.abs(ref.iso2631_5_lumbar_tf(f))
    for name in ("lumbar_peak_frequency", "spine_first_resonance"):
        assert by[name].holds(f[np.argmax(iso)]), name
    for share in (0.0, 0.2):
        m = np.abs(ref.apparent_mass_one_mass(f, share))
        assert by["apparent_mass_peak"].holds(m.max()) and by["apparent_mass_peak_frequency"].holds(f[np.argmax(m)])
        assert by["apparent_mass_10hz"].holds(m[np.isclose(f, 10.0)])
        assert by["apparent_mass_15_20hz"].holds(m[(f >= 15.0) & (f <= 20.0)])


def test_locking_findings_are_the_studys_and_hold_on_the_default_person():
    """"The paper's locking findings; data, not prose": the study reports exactly these findings (and the pelvis
    beside them), each finding holds on the default person's locking study (linear route), and the same
    finding with the values swapped does not (holds() can fail)."""
    from ehm.analysis.study import PAPER_VARIANTS, locking_study

    assert PAPER_VARIANTS is ref.LOCKING_VARIANTS
    study = locking_study(method="linear")
    findings = study.findings()
    assert list(findings)[:len(ref.LOCKING_FINDINGS)] == [f.label for f in ref.LOCKING_FINDINGS]
    assert list(findings)[len(ref.LOCKING_FINDINGS):] == ["SL: vertical pelvis peak frequency [Hz]"]
    for finding in ref.LOCKING_FINDINGS:
        assert finding.holds_in(study), finding.label
        assert finding.source.startswith("paper section 4") and "Desai" in finding.source
        assert finding.locked == ref.LOCKING_VARIANTS[finding.variant]
        key = (finding.input_axis, finding.point, finding.dof)
        base, var = study.row("baseline", *key), study.row(finding.variant, *key)
        assert not finding.holds({q: getattr(var, q) for q in finding.quantities},
                                 {q: getattr(base, q) for q in finding.quantities}), finding.label
    roll = findings["NL: head roll under lateral input (paper: drops clearly)"]
    assert roll["peak_gain_change_pct"] == pytest.approx(study.row("NL", "y", "head", "roll").peak_gain_change_pct)


def test_references_is_a_numerical_leaf():
    """"A numerical leaf: numpy only, no MuJoCo, no matplotlib": the module imports the standard library, numpy
    and ehm.errors, nothing else (import-linter keeps it on its floor; this keeps scipy and the rest out too)."""
    import importlib.util

    name = "ehm.standards.references"  # by its dotted name, wherever its file lies; relative imports made absolute
    tree = ast.parse(Path(importlib.util.find_spec(name).origin).read_text(encoding="utf-8"))
    imported = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            imported |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            module = "." * node.level + (node.module or "")
            imported.add(importlib.util.resolve_name(module, name.rpartition(".")[0]) if node.level else module)
    assert imported == {"__future__", "csv", "functools", "dataclasses", "importlib", "numpy", "ehm.errors"}, imported
    assert {r["quantity"] for r in ref.literature_anchors()} >= {"seated_spine_first_resonance_band",
                                                                  "normalised_apparent_mass_sdof_fit_damping_ratio"}
