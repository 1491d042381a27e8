"""The linear route with a rotating seat (issue 22, item 3) against the nonlinear rotating-seat route.

All motions here are SYNTHETIC: the shipped city drive (ehm.inputs.drives.city_drive, itself synthetic) scaled so that
every contact stays stuck, and a smooth roll or pitch tilt of the seat.
"""

from __future__ import annotations

import numpy as np
import pytest

import ehm
from ehm import engine
from ehm.inputs.drives import city_drive
from ehm.inputs.motion import SeatMotion
from ehm.outputs.results import concatenate_runs
from ehm.routes import linear

#: The city drive scaled to this stays within the linear route (its contacts stuck; 0.35 is the limit).
SCALE = 0.3
POINTS = tuple(engine.POINTS)
#: Largest rms difference from the nonlinear route, as a share of the nonlinear rms (vector over x, y, z), per
#: output.  Measured on the drive below: acc 0.04-0.10 %, gia 0.06-0.16 %, angvel 0.2-0.6 %, rot 0.5-0.7 %,
#: disp 0.4-0.8 %, angacc 2.4-3.5 % (the nonlinear seat tracks its angular acceleration within its 20 Hz
#: controller's bandwidth only).
TOLERANCE = {"acc_mps2": 0.005, "gia_mps2": 0.005, "angvel_radps": 0.02, "rot_rad": 0.02, "disp_m": 0.02,
             "angacc_radps2": 0.05}
#: The trunk's angular acceleration, its own bound.  Measured on the identified person: 12.9 % (pelvis and lumbar
#: 4.1 %, head 3.0 %; the other outputs: acc 0.05-0.18 %, gia 0.08-0.21 %, angvel 0.4-0.95 %, rot 0.9-1.3 %, disp
#: 0.3-1.1 %).  The trunk turns little on this drive (angular acceleration 0.043 rad/s^2 rms, the pelvis's 0.083,
#: the head's 0.21) and the difference is nearly all about the vertical: 0.005 rad/s^2 rms (26 % of the trunk's
#: yaw), with peaks of 0.21 rad/s^2 at 7.30 s and 13.63 s, where the seat is quiet (0.03 m/s^2, 0.004 rad/s), in
#: the nonlinear run only; below 2 Hz it is 2.7 %.  No contact opens, closes or slides there (the same translation
#: stepped on the static seat), and the support forces differ by 0.02 N: not explained, reported, not a tolerance
#: of the route.  The bound is above the figure so that the test still catches a route that loses the seat's
#: rotation (the sign of alpha turned: 77 %).
TRUNK_ANGACC = 0.15


def _share(ref: np.ndarray, x: np.ndarray, centre: bool = False) -> float:
    """rms of the vector difference over the rms of the reference vector (means removed if ``centre``)."""
    if centre:
        ref, x = ref - ref.mean(axis=0), x - x.mean(axis=0)
    return float(np.sqrt(np.sum((x - ref) ** 2) / np.sum(ref ** 2)))


def _errors(nl, lin) -> dict:
    """(point, output) -> share; gia with its mean removed (its mean is gravity, which both carry)."""
    return {(p, f): _share(getattr(nl.point(p), f), getattr(lin.point(p), f), centre=f == "gia_mps2")
            for p in POINTS for f in TOLERANCE}


@pytest.fixture(scope="module")
def human():
    # at the reference vibration level, given: the steady drives here have almost no vibration (their own level
    # would be the clip's least, a stiffer person), and the figures below were measured at the reference level
    h = ehm.SeatedHuman(ehm.Person(vibration_rms_mps2=1.0), rotating_seat=True)
    h.settle()
    return h


@pytest.fixture(scope="module")
def drive():
    """SYNTHETIC: the first 15 s of the city drive (a pull-away and a corner: yaw, roll and pitch), scaled."""
    full = city_drive(duration_s=30.0, seed=0)
    n = int(round(15.0 / 0.01)) + 1
    return SeatMotion(full.time_s[:n], SCALE * full.acc_mps2[:n], f"SYNTHETIC city drive x{SCALE}",
                      angvel_radps=SCALE * full.angvel_radps[:n])


@pytest.fixture(scope="module")
def nonlinear(human, drive):
    return human.simulate(drive, method="nonlinear")


def test_rotating_drive_agrees_with_the_nonlinear_route(human, drive, nonlinear):
    lin = human.simulate(drive, method="linear")
    assert lin.time_s.shape == nonlinear.time_s.shape and "linear route" in lin.description
    np.testing.assert_allclose(lin.seat_angles_rad, nonlinear.seat_angles_rad, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(lin.seat_acc_mps2, nonlinear.seat_acc_mps2)
    for (p, f), e in _errors(nonlinear, lin).items():
        assert e <= TRUNK_ANGACC if (p, f) == ("trunk", "angacc_radps2") else TOLERANCE[f], (p, f, e)
    # the support forces about their weight-bearing mean: seat pan 3.4 %, backrest 0.7 %, floor 18 % measured on the
    # identified person (1.5 %, 0.7 %, 7 % on the earlier, assumed one; the floor carries 66 N and its feet use 0.44
    # of their friction at rest: the least linear of the supports), as for the translation alone
    for g, tol in (("seat_pan", 0.045), ("backrest", 0.03), ("floor", 0.2)):
        assert _share(nonlinear.support_N[g], lin.support_N[g], centre=True) <= tol, g
    # what it leaves out, as it estimates it: below 2 % of the rms (1.6 % measured, the angular share)
    check = lin.extra["linear_check"]
    assert 0 < check["share"] <= 0.02
    assert set(POINTS) <= set(check) and all(check[p]["share"] < 0.01 for p in POINTS)


def test_the_rotation_matters_and_a_sign_error_is_caught(human, drive, nonlinear, monkeypatch):
    # The comparison above can fail: the translation alone (measured: head acceleration 1.0 %, twice the
    # tolerance, gia 10 %, angular velocity 99 %), or the seat's rotation with a sign turned (tilt: acceleration
    # 20 %; alpha: angular acceleration 77 %), misses the nonlinear route by far more than the tolerance.
    still = SeatMotion(drive.time_s, drive.acc_mps2, "translation only")
    errs = _errors(nonlinear, human.simulate(still, method="linear"))
    assert errs[("head", "angvel_radps")] > 10 * TOLERANCE["angvel_radps"]
    assert errs[("head", "gia_mps2")] > 10 * TOLERANCE["gia_mps2"]
    assert errs[("head", "acc_mps2")] > 1.5 * TOLERANCE["acc_mps2"]
    for name, change, output in (("tilt", _turn_tilt, "acc_mps2"), ("alpha", _turned(slice(3, 6)), "angacc_radps2")):
        with monkeypatch.context() as m:
            m.setattr(linear.SeatRotation, "at", change)
            wrong = _errors(nonlinear, human.simulate(drive, method="linear"))
        assert max(wrong[(p, output)] for p in POINTS) > 3 * TOLERANCE[output], name


_AT = linear.SeatRotation.at.__func__


def _turned(columns, factor=-1.0):
    """SeatRotation.at with the inputs ``columns`` multiplied by ``factor``: a sign error (or a term left out)."""
    def at(cls, kin, t_s, acc):
        seat = _AT(cls, kin, t_s, acc)
        seat.inputs[:, columns] *= factor
        return seat
    return classmethod(at)


@classmethod
def _turn_tilt(cls, kin, t_s, acc):
    """SeatRotation.at with the tilt's share of the uniform field turned (the seat's acceleration kept)."""
    seat = _AT(cls, kin, t_s, acc)
    seat.inputs[:, :3] = acc - (engine.G0 - seat.g_seat_mps2)
    return seat


def _spin_up() -> SeatMotion:
    """SYNTHETIC: the seat spins up to 0.6 rad/s about its vertical in 1 s (a smoothstep) and keeps turning, 3 s."""
    t = np.arange(0.0, 3.0 + 1e-9, 0.002)
    s = np.clip(t, 0.0, 1.0)
    w = np.zeros((t.size, 3))
    w[:, 2] = 0.6 * s * s * (3 - 2 * s)
    return SeatMotion(t, np.zeros((t.size, 3)), "SYNTHETIC yaw spin-up to 0.6 rad/s", angvel_radps=w)


def test_a_steady_yaw_carries_the_centripetal_field(human, monkeypatch):
    # SYNTHETIC: the seat spins up to 0.6 rad/s about its vertical in 1 s and keeps turning (a tight, fast turn;
    # the city drive's yaw rates are too small to show the centripetal term).  Trunk and head (off the yaw axis)
    # follow the nonlinear route; without the centripetal inputs, or with their sign turned, they do not.
    spin = _spin_up()
    nl = human.simulate(spin, method="nonlinear")
    lin = human.simulate(spin, method="linear")
    ok = _errors(nl, lin)
    for p in ("trunk", "head"):
        # measured on the identified person 1.52 % and 3.82 % (0.4 % and 1.5 % on the earlier, assumed one), in
        # the first half second and from the end of the spin-up on, nearly all sideways: 0.0006 and 0.0011 m/s^2
        # rms, the same at 0.06, 0.2 and 0.6 rad/s (so neither the centripetal nor the Coriolis term, which scale
        # with the spin; at rest both routes give 0).  The route's own estimate of what it leaves out (0.39 % and
        # 1.09 %, rms against rms) no longer covers it: see test_the_estimate_of_what_is_left_out_covers_a_steady_yaw.
        # 5 %: above the figures; the centripetal inputs left out or turned miss by 64 % and 127 %.
        assert ok[(p, "acc_mps2")] <= 0.05, (p, ok[(p, "acc_mps2")])
        assert ok[(p, "angvel_radps")] <= 0.005
    for factor in (0.0, -1.0):
        with monkeypatch.context() as m:
            m.setattr(linear.SeatRotation, "at", _turned(slice(6, 12), factor))
            wrong = _errors(nl, human.simulate(spin, method="linear"))
        assert min(wrong[(p, "acc_mps2")] for p in ("trunk", "head")) > 0.1, factor


@pytest.mark.xfail(strict=True, reason="reported: on the identified person the linear route is off by a "
                   "spin-independent 0.0006 m/s^2 sideways (trunk) that its estimate of what it leaves out "
                   "does not include")
def test_the_estimate_of_what_is_left_out_covers_a_steady_yaw(human):
    # The spin-up above: the route's estimate of what it leaves out (0.39 % trunk, 1.09 % head) was above its
    # actual distance from the nonlinear route on the earlier person (0.4 % against 0.8 %, 1.5 % against 2.6 %);
    # on the identified one it is not (1.52 %, 3.82 %).  Strict: once it covers it again this passes and must go.
    spin = _spin_up()
    lin = human.simulate(spin, method="linear")
    ok = _errors(human.simulate(spin, method="nonlinear"), lin)
    for p in ("trunk", "head"):
        assert ok[(p, "acc_mps2")] <= lin.extra["linear_check"][p]["share"], p


def _tilt(axis: int, degrees: float = 3.0) -> SeatMotion:
    """SYNTHETIC: the seat tilts by ``degrees`` about ``axis`` in 1 s (a half-sine rate) and stays; 4 s."""
    t = np.arange(0.0, 4.0 + 1e-9, 0.002)
    w = np.zeros((t.size, 3))
    w[:, axis] = np.where(t < 1.0, np.radians(degrees) * np.pi / 2 * np.sin(np.pi * t), 0.0)
    return SeatMotion(t, np.zeros((t.size, 3)), f"SYNTHETIC {degrees:g} deg tilt about {'xyz'[axis]}",
                      angvel_radps=w)


@pytest.mark.parametrize("axis", [0, 1])
def test_a_static_tilt_shifts_the_equilibrium_as_the_nonlinear_model_does(human, axis):
    # Roll 3 deg: the head moves 4.1 mm sideways in both routes (measured 4.141 / 4.134 mm), the seat pan takes
    # 26 N sideways; pitch 3 deg: the head moves 1.0 mm forward (0.985 / 1.005 mm).
    motion = _tilt(axis)
    nl, lin = human.simulate(motion, method="nonlinear"), human.simulate(motion, method="linear")
    assert np.degrees(nl.seat_angles_rad[-1, 2 - axis]) == pytest.approx(3.0, abs=1e-3)
    late = nl.time_s > 3.0
    for p in POINTS:
        a, b = nl.point(p).disp_m[late].mean(axis=0), lin.point(p).disp_m[late].mean(axis=0)
        assert np.linalg.norm(a) > 2e-4, p  # a shift of 0.2 mm or more: the test sees it
        assert np.linalg.norm(b - a) <= 0.03 * np.linalg.norm(a), (p, a, b)
        ra, rb = nl.point(p).rot_rad[late].mean(axis=0), lin.point(p).rot_rad[late].mean(axis=0)
        assert np.linalg.norm(rb - ra) <= 0.05 * np.linalg.norm(ra) + 2e-5, (p, ra, rb)
    for g in engine.SUPPORT_GROUPS:
        a, b = nl.support_N[g][late].mean(axis=0), lin.support_N[g][late].mean(axis=0)
        assert np.linalg.norm(b - a) <= 0.005 * np.linalg.norm(a), (g, a, b)
    # the shift is the tilt's: without it (its share of the uniform field left out) the sideways shift is gone
    lateral = 1 - axis  # roll moves the body along y, pitch along x
    assert abs(lin.point("head").disp_m[late, lateral].mean()) > 0.9 * abs(
        nl.point("head").disp_m[late, lateral].mean())


def test_zero_angular_velocity_is_exactly_the_translation_route(human):
    vib = ehm.random_vibration("xyz", 3.0, 0.3, seed=2, dt_s=0.001)
    zero = SeatMotion(vib.time_s, vib.acc_mps2, vib.description, angvel_radps=np.zeros_like(vib.acc_mps2))
    a, b = human.simulate(vib, method="linear"), human.simulate(zero, method="linear")
    static = ehm.SeatedHuman(human.person).simulate(vib, method="linear")  # the same person on a static seat
    for p in POINTS:
        for f in TOLERANCE:
            np.testing.assert_array_equal(getattr(a.point(p), f), getattr(b.point(p), f))
            np.testing.assert_array_equal(getattr(a.point(p), f), getattr(static.point(p), f))
    assert "linear_check" not in b.extra and b.seat_angles_rad is None


def test_linear_models_of_a_rotating_seat_person(human):
    ss = human.linear_model(rotation=True)
    assert ss.B.shape[1] == 12 and ss.input_names == engine.FIELD_INPUTS + engine.ROTATION_INPUTS
    np.testing.assert_allclose(ss.pivot_m, human.model.seat["pivot"])
    plain = human.linear_model()
    assert plain.B.shape[1] == 3 and plain.pivot_m is None
    # the static build's pivot is the rotating build's
    np.testing.assert_array_equal(engine.seat_pivot(human.built.static_model), human.model.seat["pivot"])
    # the uniform field's columns are those of the translation model (same linearisation, a larger logarithm)
    assert np.abs(ss.B[:, :3] - plain.B).max() <= 1e-6 * np.abs(plain.B).max()
    # at a slow rocking of the seat the body turns with it: absolute angular acceleration = the seat's, and the
    # pelvis's acceleration alpha x r (r from the pivot to the pelvis, rest positions)
    H = linear.frequency_response(ss, np.array([0.2]))[0]
    rows = ss.rows([f"pelvis.{k}_acc" for k in ("roll", "pitch", "yaw")])
    np.testing.assert_allclose(H[np.ix_(rows, [3, 4, 5])].real, np.eye(3), atol=0.05)
    r = engine.settled_point_poses(human.built.static_model)["pelvis"][0] - ss.pivot_m
    rows = ss.rows([f"pelvis.a{k}" for k in "xyz"])
    for k in range(3):
        e = np.eye(3)[k]
        np.testing.assert_allclose(H[rows, 3 + k].real, np.cross(e, r), atol=0.05 * np.linalg.norm(r))


@pytest.mark.filterwarnings("ignore:.*Wk band:UserWarning")  # a 15 s drive at 100 Hz does not cover Wk's band
def test_assessment_of_a_rotating_drive_on_the_linear_route(drive):
    # assess(method="linear") of a rotating drive: the seat turns (its angles and angular velocity feed the
    # seat's motion sickness as in the nonlinear route), and the comfort figures agree with the nonlinear route.
    from ehm.analysis.assessment import assess

    lin, nl = assess(drive, method="linear", chunk_s=5.0), assess(drive, chunk_s=5.0)
    for loc in ("seat", *POINTS):
        for a in "xyz":
            assert nl.metrics[loc][a].a_w > 1e-3, (loc, a)
            assert lin.metrics[loc][a].a_w == pytest.approx(nl.metrics[loc][a].a_w, rel=0.01), (loc, a)
    for key in ("head", "seat"):
        assert lin.sickness[key].final_msi_percent == pytest.approx(nl.sickness[key].final_msi_percent, rel=0.02)


def test_streamed_rotating_run_is_the_whole_run(human, drive):
    # chunk by chunk (the seat's kinematics taken per chunk, the modal state carried over) as in one piece; the
    # chunks' estimates of what is left out merge into the whole run's
    whole = human.simulate(drive, method="linear")
    pieces = concatenate_runs(list(human.stream(drive, chunk_s=4.0, method="linear")))
    for p in POINTS:
        for f in TOLERANCE:
            a, b = getattr(whole.point(p), f), getattr(pieces.point(p), f)
            np.testing.assert_allclose(b, a, rtol=0, atol=1e-9 * np.abs(a).max(), err_msg=f"{p} {f}")
    np.testing.assert_array_equal(pieces.seat_angles_rad, whole.seat_angles_rad)
    a, b = whole.extra["linear_check"], pieces.extra["linear_check"]
    assert b["share"] == pytest.approx(a["share"], rel=0.05)
    for p in POINTS:
        assert b[p]["acc_rms_mps2"] == pytest.approx(a[p]["acc_rms_mps2"], rel=1e-9)
        assert b[p]["n"] == a[p]["n"] == drive.time_s.size * 10 - 9
