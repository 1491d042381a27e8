"""The model's answers do not depend on its time step: the default step against finer steps."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import ehm
from ehm.analysis.convergence import CONVERGED_STEP_S, TOLERANCE, StepWarning, check_step, expected_error
from ehm.errors import InputError
from ehm.interfaces.cli import main
from ehm.standards.transfer import h1_estimate


@pytest.fixture(scope="module")
def default_check():
    return check_step()


def test_default_person_is_converged_at_its_step(default_check):
    # Issue 11: every seat-to-body path (3 axes x 3 points x 6 dofs, less symmetric zeros and paths below 5 % of
    # the largest of their kind) within 2 % of its peak gain of the same model at step / 8, linear route.
    assert default_check.dt_s == CONVERGED_STEP_S
    path, err = default_check.worst(8)
    assert err <= TOLERANCE, (path, err)
    assert default_check.converged(8)
    # the paths checked: at least the same-axis translations of every point on every axis
    for a in "xyz":
        for p in ehm.engine.POINTS:
            assert (a, p, a) in default_check.errors[8]
    # symmetric zeros are left out: lateral input does not pitch the head, fore-aft input does not roll it
    assert ("y", "head", "pitch") not in default_check.errors[8]
    assert ("x", "head", "roll") not in default_check.errors[8]


def test_a_coarse_step_is_not_converged_and_says_so():
    # At 2 ms (twice the converged step) the worst path is well outside 2 % (measured 7.35 %); the check must see
    # it, and building the person warns with the expected error.
    with pytest.warns(StepWarning, match=r"dt = 2 ms is coarser than the 1 ms .* about 7 %"):
        ehm.SeatedHuman(dt_s=0.002)
    check = check_step(dt_s=0.002, ratios=(8,))
    assert not check.converged(8)
    assert check.worst(8)[1] > 0.05
    # the first-order rule the warning uses stays within a factor 2 of the measured error
    assert 0.5 < check.worst(8)[1] / expected_error(0.002) < 2.0


def test_default_step_builds_without_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error", StepWarning)
        human = ehm.SeatedHuman()
        finer = ehm.SeatedHuman(dt_s=0.00025)
    assert finer.model.mj.opt.timestep == 0.00025 and human.model.mj.opt.timestep == CONVERGED_STEP_S


@pytest.mark.parametrize("bad", [0.0, -1e-3, float("nan"), "1ms"])
def test_bad_step_is_one_sentence(bad):
    with pytest.raises(InputError, match="dt_s = .* is not a plausible time step: it must be a number of seconds"):
        ehm.SeatedHuman(dt_s=bad)


def test_time_domain_route_is_converged_on_the_main_paths():
    # Issue 11: the main paths within 4 % in the time-domain route, step against step / 4, same input (here 30 s
    # of 0.3 m/s^2 rms fore-aft and vertical input; H1 gains over 1-10 Hz as a share of each path's peak).
    coarse, fine = ehm.SeatedHuman(), ehm.SeatedHuman(dt_s=CONVERGED_STEP_S / 4)
    for axis, paths in (("x", [("pelvis", 0), ("trunk", 0), ("head", 0)]), ("z", [("pelvis", 2), ("head", 2)])):
        k = "xyz".index(axis)
        gains = []
        for human in (coarse, fine):
            dt = human.model.mj.opt.timestep
            run = human.simulate(ehm.random_vibration(axis, 30.0, 0.3, seed=2, dt_s=CONVERGED_STEP_S),
                                 method="nonlinear")
            assert run.dt_s == dt
            gains.append({p: h1_estimate(run.seat_acc_mps2[:, k], run.point(p).acc_mps2[:, j], 1 / dt, segment_s=5.0)
                          for p, j in paths})
        for p, _ in paths:
            a, b = gains[0][p], gains[1][p]
            band = (b.freq_hz >= 1) & (b.freq_hz <= 10)
            ga = np.interp(b.freq_hz[band], a.freq_hz, a.gain)
            err = np.abs(ga - b.gain[band]).max() / b.gain[band].max()
            assert err < 0.04, (axis, p, err)


def test_check_step_cli_json(capsys):
    assert main(["check-step", "--dt", "0.001", "--ratio", "4", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["dt_s"] == 0.001 and out["tolerance_pct"] == 100 * TOLERANCE
    worst = out["worst"]["step_over_4"]
    assert worst["error_pct"] == pytest.approx(max(r["error_vs_step_over_4_pct"] for r in out["paths"]))


def test_check_step_cli_bad_step(capsys):
    assert main(["check-step", "--dt", "-1"]) == 2
    assert "--dt = -1.0 is not a plausible time step" in capsys.readouterr().err


def test_a_person_without_input_comes_to_rest():
    # Stuck contacts must not creep: with too few NoSlip sweeps the pelvis pitched on at 11 urad/s at 1 ms (2.5 urad/s
    # at 0.5 ms), still growing after 20 s; with enough it rests (measured: 31.5 urad after 20 s, < 0.1 urad in the
    # last 10 s, and the pelvis 0.3 um).  Bounds: 3 urad and 5 um over the last 10 s of 20 s without input.
    human = ehm.SeatedHuman()
    run = human.simulate(ehm.random_vibration("z", 20.0, 0.0), method="nonlinear")
    pitch = run.point("pelvis").rot_rad[:, 1]
    half = pitch.size // 2
    assert abs(pitch[-1] - pitch[half]) < 3e-6, (pitch[half], pitch[-1])
    assert np.abs(run.point("pelvis").disp_m[half:] - run.point("pelvis").disp_m[half]).max() < 5e-6
