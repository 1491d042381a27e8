"""The checked linear route and the hybrid route (ehm.routes.hybrid) against one continuous nonlinear run.

Every drive here is SYNTHETIC (ehm.random_vibration, labelled so by its description)."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import ehm
from ehm import engine
from ehm.inputs.drives import city_drive
from ehm.inputs.motion import SeatMotion
from ehm.interfaces.cli import main
from ehm.routes import hybrid, linear
from ehm.routes.hybrid import LinearRouteWarning, RouteReport
from ehm.routes.linear import simulate_linear
from ehm.standards.comfort import total_value


@pytest.fixture(scope="module")
def human() -> ehm.SeatedHuman:
    """The default person at the reference vibration level, given (conftest's takes each drive's level): the drives
    here differ in level, and the hand-over's figures below were measured at one (tests/test_level.py checks the
    hybrid route's two models at a drive's own level)."""
    h = ehm.SeatedHuman(ehm.Person(vibration_rms_mps2=1.0))
    h.settle()
    return h


@pytest.fixture(scope="module")
def sliding(human):
    """A SYNTHETIC 20 s fore-aft drive at 0.85 m/s^2 rms: the feet (0.44 of their friction used at rest) reach their
    friction limit now and then (measured: 8 windows, 7.3 s on the nonlinear model; the plain
    linear route is off by 2.2 % of rms there), run three ways.  Fore-aft: the identified person's contacts hold a
    three-axis 0.5 m/s^2 drive (no window), and sideways input large enough to slide them brings the body against
    the backrest's side bolster, a contact the linear model does not watch (see
    test_a_contact_that_closes_during_a_drive_is_not_watched).  Its sideways accelerations have no content (1e-5 of
    the fore-aft rms, round-off): the comparisons below are on x and z (:data:`CONTENT`)."""
    motion = ehm.random_vibration("x", 20.0, 0.85, seed=0, dt_s=0.001)
    return motion, human.simulate(motion, method="nonlinear"), human.simulate(motion, method="auto")


#: The axes with content under the fore-aft drive above (x, z).
CONTENT = [0, 2]


def _share(a, b, axes=slice(None)):
    """rms of a - b as a share of b's rms, per axis (of ``axes``)."""
    return (np.sqrt(np.mean((a - b) ** 2, axis=0)) / b.std(axis=0))[axes]


def test_state_hand_over_round_trips(human):
    # linear state <-> modal state of a time run, and linear state <-> MuJoCo data: exact inverses on what the
    # time run keeps; a state in the modes it leaves out is what P_unreached projects onto.
    ss = human.linear_model()
    blk = linear.block_form(ss, 0.001)
    rng = np.random.default_rng(1)
    m = linear.modal_form(ss)
    carry = m.W @ rng.standard_normal(ss.A.shape[0]) * 1e-3
    u = np.array([0.3, -0.2, 0.1])
    x = linear.state_of(ss, blk, carry, u)
    np.testing.assert_allclose(linear.carry_of(ss, blk, x, u), carry, rtol=0, atol=1e-12)
    d = engine.data_at_deviation(human.model, x)
    np.testing.assert_allclose(engine.deviation_of(human.model, d), x, rtol=0, atol=1e-12)
    assert np.abs(m.P_unreached @ x).max() < 1e-9 * np.abs(x).max()  # nothing in the modes left out
    np.testing.assert_allclose(m.P_unreached @ m.P_unreached, m.P_unreached, atol=1e-8)  # a projection


def test_small_input_runs_linear_only(human):
    # 0.1 m/s^2 rms: no contact comes near its limit, no window; the answer is the plain linear route's.
    motion = ehm.random_vibration("xyz", 8.0, 0.1, seed=2, dt_s=0.001)
    run = human.simulate(motion, method="auto")
    route = run.extra["route"]
    assert route["windows_s"] == [] and route["nonlinear_s"] == 0 and route["linear_share"] == 1.0
    plain = simulate_linear(human.built.for_motion(motion), motion, dt_s=0.001)  # the person at the drive's level
    for p in engine.POINTS:
        np.testing.assert_allclose(run.point(p).acc_mps2, plain.point(p).acc_mps2, rtol=0, atol=1e-12)
    assert "linear model for the whole drive" in route["summary_line"]


def test_hybrid_agrees_with_one_continuous_nonlinear_run(sliding):
    motion, nl, hy = sliding
    route = hy.extra["route"]
    assert hy.time_s.shape == nl.time_s.shape
    np.testing.assert_array_equal(hy.time_s, nl.time_s)
    assert route["windows_s"] and 0 < route["nonlinear_s"] < 0.5 * motion.duration_s
    # the linear answer alone would be off by more than 1 % of rms in the windows: the check found real work
    assert route["largest_discrepancy"]["share_of_rms"] > 0.01
    inside = np.zeros(hy.time_s.size, bool)
    for start, end in route["windows_s"]:
        inside |= (hy.time_s >= start) & (hy.time_s <= end)
    for p in engine.POINTS:
        a, b = hy.point(p).acc_mps2, nl.point(p).acc_mps2
        # in the windows (counted over the whole drive, as the route counts its discrepancy) the hybrid answer is
        # the nonlinear run's, started from the linear state: measured at most 0.36 % of rms (head z)
        part = np.sqrt(np.sum((a[inside] - b[inside]) ** 2, axis=0) / b.shape[0]) / b.std(axis=0)
        assert part[CONTENT].max() < 0.01, p
        # over the whole drive: measured at most 2.28 % (head z; trunk z 1.39 %, lumbar z 1.24 %), nearly
        # all of it outside the windows, where the answer is the linear model's: the identified person's linear
        # model is itself that far from the nonlinear one with no contact near its limit (head z on this
        # fore-aft input, first 5 s, no window: 0.9 % at 0.02 m/s^2 rms, 1.5 % at 0.2, 2.5 % at 0.4), which the
        # earlier, assumed person kept below 2 %.  3 %: above the figure; the hand-over itself is checked by the
        # windows' bound above, the jump check below and test_the_left_out_modes_are_carried_over.
        assert _share(a, b, CONTENT).max() < 0.03, p
        assert total_value(*a.T, 1000.0) == pytest.approx(total_value(*b.T, 1000.0), rel=0.005), p
        # no jump where the routes hand over: the largest sample-to-sample change stays the nonlinear run's
        assert np.abs(np.diff(a, axis=0)).max() < 1.2 * np.abs(np.diff(b, axis=0)).max(), p
    # windows in time order, inside the drive, not overlapping
    w = np.array(route["windows_s"])
    assert (w[:, 0] < w[:, 1]).all() and (w[1:, 0] >= w[:-1, 1] - 1e-9).all() and w.min() >= 0
    assert w.max() <= motion.duration_s + 1e-9


@pytest.mark.xfail(strict=True, reason="a real defect of the hybrid route, reported: it watches only the contacts "
                   "that touch at rest, and the backrest's side bolster (back_side_l) is not one of them")
def test_a_contact_that_closes_during_a_drive_is_not_watched(human):
    # SYNTHETIC three-axis 0.5 m/s^2 drive: every contact touching at rest holds in the linear model (no window, "linear
    # model for the whole drive"), but in the nonlinear run the trunk sways against the side bolster back_side_l at
    # t = 4.71-4.79 s (not touching at rest, so the linear model has no rows for it) and slides there: the answer is
    # off by 5.0 % of trunk y rms over the drive (21 % in that second), five times the route's 1 % tolerance,
    # unreported.  Strict: once the route watches such a contact (a window there), this test passes and must go.
    motion = ehm.random_vibration("xyz", 20.0, 0.5, seed=0, dt_s=0.001)
    hy, nl = human.simulate(motion, method="auto"), human.simulate(motion, method="nonlinear")
    assert hy.extra["route"]["windows_s"] or _share(hy.point("trunk").acc_mps2, nl.point("trunk").acc_mps2).max() < 0.02


def test_the_left_out_sentence_says_what_to_do_and_is_left_out_below_the_tolerance():
    report = hybrid.RouteReport(method="auto", duration_s=10.0, tolerance=0.01)
    report.left_out = {"share": 0.004}
    assert "leaves out" not in report.line()
    report.left_out = {"share": 0.05}
    assert report.line().endswith("reach 5.0% of a point's rms acceleration on the linear model's share of the drive "
                                  "(rms against rms, above the 1% tolerance), so its figures there may be off by "
                                  "about as much; --method nonlinear (method='nonlinear') includes them.")


def test_the_left_out_modes_are_carried_over(human, sliding, monkeypatch):
    # Without the offset in the modes the time run leaves out (where the body sits and turns on the seat after
    # a slide), the hybrid answer drifts from the nonlinear run: the hand-over is what holds it there.  On the
    # identified person the offset barely shows in the accelerations of this drive (measured: head z 2.26 % of rms
    # without it, 2.28 % with it) but it does in where the body sits: the displacement of pelvis and lumbar spine
    # from the nonlinear run, measured without the offset 6.3 % and 5.7 % of their rms fore-aft, 5.7 % and 4.1 %
    # vertically; with it 1.3 % and 0.8 %, 2.0 % and 2.5 % (largest 6.3 % against 2.5 %; the earlier, assumed
    # person's accelerations alone showed it).
    motion, nl, hy = sliding
    ss = linear.linear_model(human.built.for_motion(motion))  # the person at the drive's level, as the run takes it
    m = linear.modal_form(ss)
    monkeypatch.setitem(ss.cache, "modes", linear._Modes(**{**m.__dict__, "P_unreached": 0 * m.P_unreached}))
    dropped = human.simulate(motion, method="auto")
    worse = max(_share(dropped.point(p).disp_m, nl.point(p).disp_m, CONTENT).max() for p in ("pelvis", "lumbar"))
    kept = max(_share(hy.point(p).disp_m, nl.point(p).disp_m, CONTENT).max() for p in ("pelvis", "lumbar"))
    assert worse > 2 * kept, (worse, kept)


def test_linear_method_reports_its_discrepancy_and_warns_above_tolerance(human, sliding):
    motion, nl, hy = sliding
    with pytest.warns(LinearRouteWarning, match=r"off by [0-9.]+% of rms .* more than the tolerance 1%"):
        lin = human.simulate(motion, method="linear")
    route = lin.extra["route"]
    assert route["method"] == "linear" and not route["within_tolerance"]
    assert route["windows_s"] and route["nonlinear_s"] > 0
    # the answer is the linear one everywhere: the plain linear route's, its contact check switched off
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(linear, "_validity", lambda *a, **k: None)
        plain = simulate_linear(human.built.for_motion(motion), motion, dt_s=0.001)  # at the drive's level
    np.testing.assert_allclose(lin.point("head").acc_mps2, plain.point("head").acc_mps2, rtol=0, atol=1e-12)
    # the discrepancy it reports is the one a direct comparison gives, counted over the whole drive
    for p in ("pelvis", "head"):
        direct = np.sqrt(np.sum((lin.point(p).acc_mps2 - nl.point(p).acc_mps2) ** 2, axis=0) / nl.time_s.size)
        reported = np.array(route["discrepancy_share_of_rms"][p]) * lin.point(p).acc_mps2.std(axis=0)
        # the windows start from the linear state, so the direct difference is the larger (it also holds the
        # nonlinear run's own memory of earlier slides); the reported one is of the same size
        assert (reported <= 1.05 * direct).all() and reported.max() > 0.3 * direct.max(), p
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        loose = human.simulate(motion, method="linear", tolerance=0.9)  # nothing to warn about
    assert loose.extra["route"]["within_tolerance"]


def test_most_of_the_drive_near_the_limit_goes_on_on_the_nonlinear_model(human):
    # 1 m/s^2 rms on three axes: the back pads are at their limit most of the time; once the windows cover more
    # than half of the drive so far (after 30 s, or a third of a shorter drive: 15 s of this one), the rest runs on
    # the nonlinear model, from the state reached.
    motion = ehm.random_vibration("xyz", 45.0, 1.0, seed=0, dt_s=0.001)
    run = human.simulate(motion, method="auto")
    route = run.extra["route"]
    assert route["fallback"].startswith("from t = ") and route["linear_share"] < 0.5
    start = float(route["fallback"].split()[3])
    last = route["windows_s"][-1]
    assert min(hybrid.FALLBACK_AFTER_S, hybrid.FALLBACK_AFTER_SHARE * 45.0) <= start < 45.0
    assert last[0] == pytest.approx(start, abs=0.05) and last[1] == pytest.approx(45.0, abs=0.01)
    nl = human.simulate(motion, method="nonlinear")
    for p in ("pelvis", "head"):
        a, b = run.point(p).acc_mps2, nl.point(p).acc_mps2
        assert total_value(*a.T, 1000.0) == pytest.approx(total_value(*b.T, 1000.0), rel=0.01), p


@pytest.fixture(scope="module")
def turning():
    h = ehm.SeatedHuman(rotating_seat=True)
    h.linear_model(rotation=True)
    return h


def test_a_rotating_drive_hands_over_to_the_rotating_seat_and_back(turning, monkeypatch):
    # The SYNTHETIC city drive turns, brakes and accelerates at 1-3.5 m/s^2: the upper back slides in its
    # corners.  The windows run on the rotating seat from the linear state carried into the world, and back.
    # (Its level alone would send it to the nonlinear model from the start: that decision is switched off here,
    # so that the hand-over itself is what is tested; so is the early switch to the nonlinear model of a short drive.)
    monkeypatch.setattr(hybrid, "SUSTAINED_SHARE", 1.0)
    monkeypatch.setattr(hybrid, "FALLBACK_AFTER_SHARE", 1.0)
    motion = city_drive(30.0, seed=0, dt_s=0.01)
    nl, hy = turning.simulate(motion, method="nonlinear"), turning.simulate(motion, method="auto")
    route = hy.extra["route"]
    assert route["windows_s"] and 0 < route["linear_share"] < 1 and not route["fallback"]
    assert 0 < route["left_out"]["share"] < 1
    # the console line names what the linear model leaves out only where it reaches the tolerance
    assert ("leaves out" in route["summary_line"]) == (route["left_out"]["share"] >= route["tolerance_share_of_rms"])
    np.testing.assert_array_equal(hy.time_s, nl.time_s)
    np.testing.assert_allclose(hy.seat_angles_rad, nl.seat_angles_rad, rtol=0, atol=1e-12)
    # Measured on the identified person: acceleration and gia at most 2.19 % and 2.10 % (head z), angular velocity
    # 3.36 % (head roll; pelvis roll 2.10 %, head pitch 2.14 %); the earlier, assumed person kept all below 2 %.
    # Most of it is one window that opens late: the continuous nonlinear run leaves the linear answer at 7.98-8.00 s
    # (pelvis roll rate 2e-5 rad/s apart at 7.976 s, 1.7e-3 at 8.001 s; the seat turning at 1.25 m/s^2 sideways
    # and rising), the window opens at 8.016 s (LEAD_S = 0.25 s before the linear
    # model's first sample at its friction limit), and the pelvis roll rate is off by up to 10 % of its value in the
    # 0.2 s after (the 8-9 s second: 9.7 % of rms).  With LEAD_S = 0.5 s the same drive gives head roll 1.5 % and
    # every acceleration below 1 %: a tuning of the route for this person, reported, not changed here.  Bounds:
    # 3 % (acc, gia) and 4 % (angvel), above the figures at the defaults.
    bound = {"acc_mps2": 0.03, "gia_mps2": 0.03, "angvel_radps": 0.04}
    for p in engine.POINTS:
        for field in ("acc_mps2", "gia_mps2", "angvel_radps"):
            a, b = getattr(hy.point(p), field), getattr(nl.point(p), field)
            assert _share(a, b).max() < bound[field], (p, field, _share(a, b))
        assert total_value(*hy.point(p).acc_mps2.T, 1000.0) == pytest.approx(
            total_value(*nl.point(p).acc_mps2.T, 1000.0), rel=0.003), p


def test_a_turn_without_a_rotating_seat_build_is_one_sentence_when_a_window_needs_it(human):
    motion = city_drive(30.0, seed=0, dt_s=0.01)
    with pytest.raises(ehm.errors.InputError, match=r"SeatedHuman\(rotating_seat=True\)"):
        human.simulate(motion, method="auto")
    gentle = SeatMotion(motion.time_s, 0.2 * motion.acc_mps2, "SYNTHETIC gentle turn", 0.2 * motion.angvel_radps)
    run = human.simulate(gentle, method="auto")  # no window needed: the linear model of the seat's rotation
    assert run.extra["route"]["windows_s"] == [] and "linear_check" in run.extra


def test_bad_method_and_tolerance_are_one_sentence(human):
    motion = ehm.random_vibration("z", 3.0, 0.1, seed=0, dt_s=0.001)
    with pytest.raises(ehm.errors.InputError, match="method must be"):
        human.simulate(motion, method="fast")
    with pytest.raises(ehm.errors.InputError, match="tolerance must be a share of rms between 0 and 1"):
        human.simulate(motion, method="auto", tolerance=5)


def test_report_line_and_dict():
    r = RouteReport(method="auto", duration_s=100.0, nonlinear_s=20.0, windows_s=[[1.0, 21.0]],
                    discrepancy={"pelvis": [0.001, 0.002, 0.0], "head": [0.01, 0.05, 0.02]})
    d = r.as_dict()
    assert d["linear_share"] == pytest.approx(0.8) and d["largest_discrepancy"] == {
        "point": "head", "axis": "y", "share_of_rms": 0.05}
    assert not d["within_tolerance"] and json.loads(json.dumps(d)) == d
    assert "linear model 80.0% of the drive, nonlinear model in 1 window" in r.line() and ", head y)" in r.line()


def test_cli_default_route_and_its_record(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["simulate", "--axis", "xyz", "--rms", "0.5", "--duration", "10", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "route: linear model" in printed and "hybrid route" in printed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["route"]["method"] == "auto" and (out / "poses.npz").exists()  # every route records poses (issue 32)
    res = tmp_path / "assess"
    drive = tmp_path / "drive.csv"
    m = ehm.random_vibration("xyz", 12.0, 0.5, seed=3, dt_s=0.002)
    np.savetxt(drive, np.column_stack([m.time_s, m.acc_mps2]), delimiter=",",
               header="time_s,ax_mps2,ay_mps2,az_mps2", comments="")
    assert main(["assess", "--motion", str(drive), "--out", str(res)]) == 0
    assert "route: " in capsys.readouterr().out
    assessed = json.loads((res / "assessment.json").read_text())
    assert assessed["route"]["method"] == "auto" and "summary_line" in assessed["route"]
    assert main(["assess", "--motion", str(drive), "--tolerance", "0", "--out", str(tmp_path / "x")]) == 2
    assert "--tolerance is a percentage" in capsys.readouterr().err


def test_the_seat_figures_do_not_depend_on_the_route(human, sliding):
    # The seat's own comfort and sickness figures come from the seat motion alone: the hybrid route's pieces of
    # any length must give them exactly as the nonlinear route's whole chunks do (the sickness model's 20 Hz
    # blocks carried across pieces).
    from ehm.analysis.assessment import assess

    motion = sliding[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        nl, hy = assess(motion, human, method="nonlinear"), assess(motion, human, method="auto")
    a, b = nl.summary(), hy.summary()
    assert hy.route["windows_s"] and "route" in b and "route" not in a
    assert b["sickness"]["seat"]["final_msi_percent"] == pytest.approx(a["sickness"]["seat"]["final_msi_percent"],
                                                                        rel=1e-9)
    assert b["locations"]["seat"]["total_value_mps2"] == pytest.approx(a["locations"]["seat"]["total_value_mps2"],
                                                                       rel=1e-9)
    assert b["sickness"]["head"]["final_msi_percent"] == pytest.approx(a["sickness"]["head"]["final_msi_percent"],
                                                                        rel=0.01)


def test_a_rotating_seat_held_level_takes_the_windows_of_a_translation(turning, sliding):
    # A person built on the rotating seat, a motion without angular velocities: the translation's linear model,
    # its windows on the rotating seat held level (the state carried into its world frame at zero angles).
    motion, nl_static, _ = sliding
    nl, hy = turning.simulate(motion, method="nonlinear"), turning.simulate(motion, method="auto")
    assert hy.extra["route"]["windows_s"] and "linear_check" not in hy.extra
    for p in engine.POINTS:
        a, b = hy.point(p).acc_mps2, nl.point(p).acc_mps2
        # measured 2.36 % (head z; trunk z 1.57 %, pelvis z 1.20 %), as on the static seat (2.28 %, nearly all of
        # it outside the windows: the linear model's own distance from the nonlinear one, see
        # test_hybrid_agrees_with_one_continuous_nonlinear_run)
        assert _share(a, b, CONTENT).max() < 0.03, p
        assert total_value(*a.T, 1000.0) == pytest.approx(total_value(*b.T, 1000.0), rel=0.005), p


def test_a_drive_whose_contacts_slide_from_the_start_runs_nonlinear_from_the_start():
    """Issue 32 item 6: "the default route never slower than the route it falls back to: decide early ... when the
    nonlinear model will carry most of a drive, and run it from the start".  The SYNTHETIC city drive holds 1.5-3.5
    m/s^2 in its corners, braking and starts for about half its length (the back pads' friction limit is 1.1 m/s^2
    sideways): the default route runs it on the nonlinear model from t = 0, without building or running the linear
    model (the fixed cost the hybrid route paid before its 30 s decision), and its answer is the nonlinear route's
    exactly (the same run, so equal to the last bit)."""
    person = ehm.SeatedHuman(rotating_seat=True)
    motion = city_drive(30.0, seed=0, dt_s=0.01)
    assert hybrid.sustained_share(motion) > hybrid.SUSTAINED_SHARE
    hy = person.simulate(motion)  # the default route
    route = hy.extra["route"]
    assert route["method"] == "auto" and route["nonlinear_from_start"] and route["linear_share"] == 0.0
    assert route["windows_s"] == [[0.0, pytest.approx(30.0, abs=0.002)]]
    assert route["summary_line"].startswith("route: nonlinear model for the whole drive from the start: the seat's "
                                            "horizontal acceleration (in 1 s means) is above 1.5 m/s^2 over ")
    assert person.built.linear == {}  # never linearised
    nl = person.simulate(motion, method="nonlinear")
    for p in ("pelvis", "head"):
        np.testing.assert_array_equal(hy.point(p).acc_mps2, nl.point(p).acc_mps2)


def test_a_gentle_drive_keeps_its_linear_share(turning, sliding):
    """Issue 32 item 6: "on a drive that the linear route can carry, keep today's speed".  The same SYNTHETIC city
    drive scaled to 0.4 (its manoeuvres at most 1.4 m/s^2, in 1 s means never above 1.5) and the SYNTHETIC 0.5
    m/s^2 three-axis vibration (whose pads slide now and then, in short windows) stay on the hybrid route with
    the linear model carrying most of them."""
    full = city_drive(30.0, seed=0, dt_s=0.01)
    gentle = SeatMotion(full.time_s, 0.4 * full.acc_mps2, "SYNTHETIC gentle city drive", 0.4 * full.angvel_radps)
    assert hybrid.sustained_share(gentle) == 0.0
    for run in (turning.simulate(gentle), sliding[2]):
        route = run.extra["route"]
        assert not route["nonlinear_from_start"] and route["linear_share"] > 0.5, route["summary_line"]


def test_sustained_share_weighs_irregular_steps_by_their_length():
    """The level the early decision reads: the share of the drive's time where the seat's horizontal acceleration,
    in 1 s means, is above 1.5 m/s^2.  SYNTHETIC: 2 m/s^2 sideways for 40 of 100 s, sampled every 0.1 s there and
    every 0.01 s elsewhere (a count of samples would say 6 %); the means smear each edge over half a second on
    either side, so the share is within 0.01 of 0.4 (the grid's tenth of a second)."""
    t = np.concatenate([np.arange(0.0, 30.0, 0.01), np.arange(30.0, 70.0, 0.1), np.arange(70.0, 100.0, 0.01)])
    acc = np.zeros((t.size, 3))
    acc[(t >= 30.0) & (t < 70.0), 1] = 2.0
    share = hybrid.sustained_share(SeatMotion(t, acc, "SYNTHETIC sideways step"))
    assert share == pytest.approx(0.4, abs=0.01)
    assert hybrid.sustained_share(SeatMotion(t, 0.7 * acc, "SYNTHETIC sideways step, 1.4 m/s^2")) == 0.0


def test_a_divergence_on_the_nonlinear_run_from_the_start_names_the_input_once(monkeypatch):
    """The default route running the nonlinear model from the start of a drive (issue 32 item 6) inside the hybrid
    route: a divergence there is one sentence naming the input once (both routes add the input's cause: before,
    the hybrid route's own handler would have repeated it).  SYNTHETIC: the city drive with a 1.5 g vertical jump at
    5 s, the run diverging at 6 s (raised by hand)."""
    from ehm.errors import DivergenceError

    drive = city_drive(30.0, seed=0, dt_s=0.01)
    acc = drive.acc_mps2.copy()
    acc[drive.time_s >= 5.0, 2] += 15.0
    motion = SeatMotion(drive.time_s, acc, "SYNTHETIC city drive with a jump", drive.angvel_radps)
    person = ehm.SeatedHuman(rotating_seat=True)
    person.settle()

    def diverging(*args, **kwargs):
        err = DivergenceError("the simulation diverged at t = 6.000 s (a reason); try a smaller time step")
        err.time_s = 6.0
        raise err

    monkeypatch.setattr(engine, "run", diverging)
    with pytest.raises(DivergenceError) as exc:
        person.simulate(motion)
    assert str(exc.value).count("out of the ordinary") == 1, str(exc.value)
    assert "a jump of 15.1 m/s^2" in str(exc.value)  # the jump plus the drive's own step there
