"""Individual body sizes."""

from __future__ import annotations

import json

import numpy as np
import pytest

import ehm
from ehm.body.params import Parameters
from ehm.body.tables import load_body
from ehm.errors import InputError
from ehm.interfaces.cli import main
from ehm.person.scaling import BodySize, scale_body, scale_params


def test_reference_size_changes_nothing():
    body, params = load_body(), Parameters.load()
    size = BodySize(1.76, 70.882, 0.92)  # the paper's person (sections 1 and Table 2)
    assert scale_body(body, size) is body and scale_params(params, size) is params
    # and a size within round-off of it builds the same model
    near = BodySize(1.76 * (1 + 1e-15), 70.882)
    m1 = ehm.SeatedHuman().model.mj
    m2 = ehm.SeatedHuman(size=near).model.mj
    np.testing.assert_allclose(m2.body_mass, m1.body_mass, rtol=1e-12)
    np.testing.assert_allclose(m2.body_pos, m1.body_pos, atol=1e-12)


def test_scaled_mass_and_lengths():
    size = BodySize(1.90, 95.0)
    h = ehm.SeatedHuman(size=size)
    assert h.mass_kg == pytest.approx(95.0, rel=1e-12)
    head_ref = load_body().segment("head").com_m[2]
    # head height above the pelvis scales with sitting height, here in proportion to stature
    assert h.body.segment("head").com_m[2] == pytest.approx(head_ref * 1.90 / 1.76, rel=1e-12)


@pytest.mark.parametrize("stature, mass, sitting", [(1.52, 50.0, 0.79), (1.87, 98.0, 0.97)])
def test_extremes_settle_and_run(stature, mass, sitting):
    # 5th-percentile female and 95th-percentile male (stature, mass and sitting height as in common
    # anthropometric tables, e.g. NASA-STD-3000 / Pheasant 'Bodyspace' orders of magnitude).
    size = BodySize(stature, mass, sitting)
    h = ehm.SeatedHuman(size=size)
    run = h.simulate(ehm.random_vibration("z", 4.0, 0.3, seed=0), method="nonlinear")
    weight = mass * 9.81
    assert run.support_total_N().mean(axis=0)[2] == pytest.approx(weight, rel=0.01)
    assert np.abs(run.point("pelvis").disp_m).max() < 0.005
    # Hof (1996) scaling keeps natural frequencies ~ sqrt(g / L): the vertical trunk mode moves with
    # 1 / sqrt(sitting-height ratio) from the reference's (linear model), within 10 % (widths scale apart).
    from ehm.analysis.frf import linear_frf

    ref = linear_frf(ehm.SeatedHuman(), "z").curve("z", "trunk", "z").peak((2, 12))[0]
    got = linear_frf(h, "z").curve("z", "trunk", "z").peak((2, 12))[0]
    assert got == pytest.approx(ref / np.sqrt(sitting / 0.92), rel=0.10)


def test_bad_sizes():
    with pytest.raises(InputError, match="stature_m"):
        BodySize(3.0, 70.0)
    with pytest.raises(InputError, match="mass_kg"):
        BodySize(1.7, float("nan"))


def test_cli_info_scaled(capsys):
    assert main(["info", "--stature", "1.90", "--mass", "95", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["mass_kg"] == pytest.approx(95.0)


def test_stretched_inertia_is_that_of_the_stretched_body():
    # a solid box a x b x c of mass m: I_xx = m (b^2 + c^2) / 12 (hand formula); stretched by (2, 1, 0.5) and
    # with 1.5 times the mass it is a box 2a x b x 0.5c of mass 1.5 m
    from ehm.person.scaling import stretched_inertia

    def box(m, a, b, c):
        return m / 12 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])

    got = stretched_inertia(box(3.0, 0.4, 0.2, 0.1), 1.5, np.array([2.0, 1.0, 0.5]))
    np.testing.assert_allclose(got, box(4.5, 0.8, 0.2, 0.05), rtol=1e-12)


@pytest.mark.parametrize("stature_m, mass_kg", [(1.76, 70.0), (1.76, 120.0), (2.0, 64.0), (1.5, 90.0), (1.2, 30.0),
                                                (2.2, 193.6)])  # within body mass index 16-40 kg/m^2
def test_sizes_across_the_documented_range_build(stature_m, mass_kg):
    # 1.76 m and 70 kg used to fail: the table's foot sits on the rigid-body bound (I_yy = I_xx + I_zz) and the
    # earlier per-axis rule pushed it across
    h = ehm.SeatedHuman(size=BodySize(stature_m=stature_m, mass_kg=mass_kg))
    assert h.mass_kg == pytest.approx(mass_kg, rel=1e-9)
