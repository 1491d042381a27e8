"""The head-in-space control on the linear and hybrid routes: its delay handed between the nonlinear model's delay
line (ehm.engine.control) and the linear model's Padé states (ehm.engine.control_linear), both ways.

Every drive here is SYNTHETIC (ehm.random_vibration, plus a SYNTHETIC braking pulse)."""

from __future__ import annotations

import numpy as np
import pytest

import ehm
from ehm import engine
from ehm.inputs.motion import SeatMotion
from ehm.routes import linear


@pytest.fixture(scope="module")
def on() -> ehm.SeatedHuman:
    h = ehm.SeatedHuman(head_control=True)
    h.settle()
    return h


def _rms(x, axis=None):
    return np.sqrt(np.mean(np.asarray(x) ** 2, axis=axis))


def braking_drive() -> SeatMotion:
    """12 s of three-axis random vibration at 0.3 m/s^2 rms with a 1.5 s braking pulse of 2 m/s^2 at 5 s: the pulse
    and a later stretch bring contacts to their friction limit (measured: two windows, 5.26-6.41 s and
    10.67-11.45 s, the linear model 84 % of the drive)."""
    m = ehm.random_vibration("xyz", 12.0, 0.3, seed=0, dt_s=0.001)
    t = m.time_s
    acc = m.acc_mps2.copy()
    acc[:, 0] -= np.where((t > 5.0) & (t < 6.5), 2.0 * np.sin(np.pi * (t - 5.0) / 1.5) ** 2, 0.0)
    return SeatMotion(t, acc, f"SYNTHETIC {m.description}, a 2 m/s^2 braking pulse at 5 s")


@pytest.fixture(scope="module")
def braking(on):
    motion = braking_drive()
    return motion, on.simulate(motion, method="nonlinear"), on.simulate(motion, method="auto")


def test_the_delay_line_round_trips_through_the_linear_state(on):
    # The nonlinear model's delay line read as the torques of the last N states and written back into a fresh
    # MjData at the same state (through the linear model's state, as a window's start is made): the line comes back
    # to round-off, and the run continues as the one it was taken from (measured: 3e-9 of the head's rms tilt,
    # the state's own round trip; with an empty line instead 0.10).
    model, c = on.model, on.model.head_control
    rng = np.random.default_rng(3)
    acc = 0.5 * rng.standard_normal((600, 3))
    d = engine.settled_data(model)
    engine.run(model, acc[:400], d=d)
    torques = engine.line_torques(c, d)
    assert torques.shape == (c.delay_steps, 3) and np.abs(torques).max() > 1e-3
    x = engine.deviation_of(model, d)
    d2, d3 = engine.data_at_deviation(model, x), engine.data_at_deviation(model, x)
    engine.load_line(c, d2, torques)
    np.testing.assert_allclose(engine.line_torques(c, d2), torques, rtol=0, atol=1e-14 * np.abs(torques).max())
    ref = engine.run(model, acc[400:], d=d).sensors["head_framequat"]
    handed = engine.run(model, acc[400:], d=d2).sensors["head_framequat"]
    empty = engine.run(model, acc[400:], d=d3).sensors["head_framequat"]
    scale = _rms(ref[:, 1:3] - ref[:, 1:3].mean(axis=0))
    assert _rms(handed[:, 1:3] - ref[:, 1:3]) < 1e-6 * scale
    assert _rms(empty[:, 1:3] - ref[:, 1:3]) > 100 * _rms(handed[:, 1:3] - ref[:, 1:3])


def test_the_torques_of_recorded_states_are_the_laws(on):
    # What the law computed from each state of a run (its torques come back out of the delay line N steps later)
    # equals ehm.engine.control_torques of the run's recorded sensors, to round-off.
    model, c = on.model, on.model.head_control
    acc = np.tile([0.3, -0.6, 0.2], (300, 1))
    d = engine.settled_data(model)
    raw = engine.run(model, acc, d=d)
    tau = engine.control_torques(c, d, raw.sensors["head_framequat"], raw.sensors["head_frameangvel"])
    np.testing.assert_allclose(engine.line_torques(c, d), tau[-c.delay_steps:], rtol=0,
                               atol=1e-12 * np.abs(tau).max())


def test_the_pade_states_follow_from_the_torque_history(on):
    # Nonlinear -> linear: the linear model's Padé states at a sample from those at an earlier one and the law's
    # torques in between (the linear model's own sensed outputs here, whose Padé states are known): the first-order
    # hold of the torque history gives them within 1e-3 of their largest (measured 1.8e-4 over 0.5 s, the hold's
    # own error at the 1 ms step; the states of a history longer than ten delays forget its start: the same from
    # zero states).
    ss = linear.linear_model(on.built)
    dt = on.model.mj.opt.timestep
    blk = linear.block_form(ss, dt)
    motion = ehm.random_vibration("xyz", 2.0, 0.3, seed=5, dt_s=dt)
    u = motion.acc_mps2
    carry = linear.initial_state(blk, u[0])
    y = linear.block_chunk(blk, u, carry.copy())
    tau = linear.head_sensed(y, u.shape[0]) @ engine.control_gains(on.model.head_control).T
    pade = engine.pade_steps(on.model, dt)
    n_body = ss.A.shape[0] - 3 * engine.control_linear.PADE_ORDER

    def z_at(k):
        c = carry.copy()
        linear.advance(blk, u[:k], c)
        return linear.state_of(ss, blk, c, u[k])[n_body:]

    a, b = 1000, 1500
    z_b = z_at(b)
    assert np.abs(z_b).max() > 0
    np.testing.assert_allclose(pade.after(z_at(a), tau[a:b + 1]), z_b, rtol=0, atol=1e-3 * np.abs(z_b).max())
    np.testing.assert_allclose(pade.after(np.zeros_like(z_b), tau[a:b + 1]), z_b, rtol=0,
                               atol=1e-3 * np.abs(z_b).max())
    np.testing.assert_array_equal(pade.after(z_b, tau[b:b + 1]), z_b)  # no step: the same states


def test_the_hybrid_route_with_head_control_agrees_with_the_nonlinear_route(braking):
    # "figures within 1 % of the nonlinear route": the hybrid route now runs the controlled person on the linear model
    # where the contacts hold, with the delay handed over at each window's start and end.  Measured: windows
    # 5.26-6.41 s and 10.67-11.45 s (linear share 84 %); every point acceleration within 0.96 % of its rms over the
    # drive (head y; with an empty delay line at the windows' starts 1.88 %, with the Padé states zeroed at their
    # ends 1.59 %), within 0.19 % inside the windows
    # (counted over the whole drive, as the route counts its discrepancy; 1.73 % with the empty line); the head's
    # pitch within 0.56 % and its roll within 0.55 % of their rms.
    motion, nl, hy = braking
    route = hy.extra["route"]
    assert route["windows_s"] and 0.5 < route["linear_share"] < 1.0 and not route["nonlinear_from_start"]
    assert route["windows_s"][0][1] < 7.0 < route["windows_s"][-1][0]  # the linear model ran on after a window
    inside = np.zeros(hy.time_s.size, bool)
    for start, end in route["windows_s"]:
        inside |= (hy.time_s >= start) & (hy.time_s <= end)
    for p in engine.POINTS:
        a, b = hy.point(p).acc_mps2, nl.point(p).acc_mps2
        scale = b.std(axis=0)
        assert (_rms(a - b, axis=0) < 0.01 * scale).all(), p
        assert (np.sqrt(np.sum((a[inside] - b[inside]) ** 2, axis=0) / b.shape[0]) < 0.004 * scale).all(), p
    for k in (0, 1):  # head roll, pitch (relative to the seat)
        a, b = hy.point("head").rot_rad[:, k], nl.point("head").rot_rad[:, k]
        assert _rms(a - b) < 0.01 * b.std(), k


def test_a_drive_that_stays_linear_runs_linear_with_head_control(on):
    # No contact near its limit: the controlled person runs on the linear model for the whole drive (the nonlinear
    # model from the start was the only way before), its answer the plain linear route's.
    motion = ehm.random_vibration("xyz", 4.0, 0.3, seed=1, dt_s=0.001)
    run = on.simulate(motion)
    route = run.extra["route"]
    assert route["linear_share"] == 1.0 and not route["nonlinear_from_start"] and route["windows_s"] == []
    plain = on.simulate(motion, method="linear")
    np.testing.assert_allclose(run.point("head").rot_rad, plain.point("head").rot_rad, rtol=0, atol=1e-12)


def test_a_turning_drive_with_head_control_runs_nonlinear_from_the_start_and_says_why():
    # The linear model of a turning seat senses the head on the seat, not in space: the nonlinear model from the
    # start, with the reason in the route's report.
    human = ehm.SeatedHuman(head_control=True, rotating_seat=True)
    motion = ehm.city_drive(duration_s=20.0)
    run = human.simulate(motion)
    route = run.extra["route"]
    assert route["nonlinear_from_start"] and "head-in-space control" in route["fallback"]
    assert route["linear_share"] == 0.0


def test_a_rotating_seat_held_level_hands_the_delay_over_too():
    # A person built on the rotating seat whose drive does not turn it runs the windows on the rotating-seat model
    # (ehm.engine.rotating_data_at), which takes the law's reference up of its own settled state.  Measured on the
    # braking drive: the same two windows, point accelerations within 0.99 % of rms of the nonlinear route (head y),
    # head roll 0.99 %, pitch 0.59 %.
    human = ehm.SeatedHuman(head_control=True, rotating_seat=True)
    motion = braking_drive()
    hy, nl = human.simulate(motion), human.simulate(motion, method="nonlinear")
    assert len(hy.extra["route"]["windows_s"]) >= 1 and hy.extra["route"]["linear_share"] > 0.5
    for p in engine.POINTS:
        a, b = hy.point(p).acc_mps2, nl.point(p).acc_mps2
        assert (_rms(a - b, axis=0) < 0.015 * b.std(axis=0)).all(), p
    for k in (0, 1):
        a, b = hy.point("head").rot_rad[:, k], nl.point("head").rot_rad[:, k]
        assert _rms(a - b) < 0.015 * b.std(), k
