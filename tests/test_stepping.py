"""The stepping interface against whole runs, and its state handling."""

from __future__ import annotations

import numpy as np
import pytest

import ehm
from ehm.analysis.stepping import Simulator, run_realtime
from ehm.errors import InputError
from ehm.standards.comfort import ComfortAccumulator


@pytest.fixture(scope="module")
def motion():
    return ehm.random_vibration("xyz", 2.0, 0.3, seed=7, dt_s=ehm.Parameters.load().value("simulation.dt_s"))


def _at_reference() -> ehm.SeatedHuman:
    """The default person at the reference vibration level, given: the Simulator has no drive to take a level from
    (it runs at the reference level), so the whole run it is compared with runs there too."""
    return ehm.SeatedHuman(ehm.Person(vibration_rms_mps2=1.0))


def _collect(sim, acc):
    return [sim.step(a) for a in acc]


def test_steps_equal_whole_run(motion):
    # Two routes, same operations: SeatedHuman.simulate (whole run) and Simulator.step (sample by sample)
    # must give the same numbers to round-off (1e-12 in SI units).
    whole = _at_reference().simulate(motion, method="nonlinear")
    states = _collect(Simulator(comfort=False), motion.acc_mps2)
    assert len(states) == whole.time_s.size
    np.testing.assert_allclose([s.time_s for s in states], whole.time_s, atol=1e-12)
    for p in ("pelvis", "trunk", "head"):
        pm = whole.point(p)
        for field in ("acc_mps2", "disp_m", "rot_rad", "angvel_radps"):
            got = np.array([getattr(getattr(s, p), field) for s in states])
            np.testing.assert_allclose(got, getattr(pm, field), rtol=0, atol=1e-12, err_msg=f"{p}.{field}")


def test_save_restore_and_reset(motion):
    sim = Simulator(comfort=True)
    acc = motion.acc_mps2
    _collect(sim, acc[:500])
    snap = sim.save_state()
    first = _collect(sim, acc[500:800])
    sim.restore_state(snap)
    again = _collect(sim, acc[500:800])
    for a, b in zip(first, again):
        np.testing.assert_array_equal(a.head.acc_mps2, b.head.acc_mps2)
        assert a.comfort == b.comfort
    sim.reset()
    fresh = Simulator(comfort=True)
    for x, y in zip(_collect(sim, acc[:50]), _collect(fresh, acc[:50])):
        np.testing.assert_array_equal(x.trunk.rot_rad, y.trunk.rot_rad)
    with pytest.raises(InputError, match="save_state"):
        sim.restore_state({})


def test_running_comfort_equals_accumulator(motion):
    # Running figures kept step by step (state-space cascade of the weighting sections) against the block
    # accumulator (scipy sosfilt): equal to round-off.
    sim = Simulator(comfort=True, comfort_every=1)
    last = _collect(sim, motion.acc_mps2)[-1]
    whole = _at_reference().simulate(motion, method="nonlinear")
    signals = {"seat": motion.acc_mps2, "head": whole.point("head").acc_mps2, "pelvis": whole.point("pelvis").acc_mps2}
    for loc, acc_xyz in signals.items():
        for j, axis in enumerate("xyz"):
            acc = ComfortAccumulator("Wk" if axis == "z" else "Wd", 1 / sim.dt_s)
            acc.add(acc_xyz[:1, j])  # the stepper starts in the steady state for its first row: a first block
            acc.add(acc_xyz[1:, j])  # of one row makes the accumulator start from the same level
            rr, aw = last.comfort[loc][axis]
            assert rr == pytest.approx(acc.last_running_rms, rel=1e-9), (loc, axis)
            assert aw == pytest.approx(acc.a_w_so_far, rel=1e-9), (loc, axis)


def test_bad_step_input():
    sim = Simulator(comfort=False)
    with pytest.raises(InputError, match="3 finite numbers"):
        sim.step([0.0, np.nan, 0.0])
    with pytest.raises(InputError, match="translation only"):
        sim.step([0.0, 0.0, 0.0], seat_angvel_radps=[0.0, 0.0, 0.1])



@pytest.mark.parametrize("value", ["abc", None, [1.0, 2.0], [[0.0, 0.0, 0.0]], [0.0, "x", 0.0], {"z": 1.0},
                                   [0.0, 0.0, np.inf]])
def test_step_input_that_is_not_three_finite_numbers_is_one_sentence(value):
    sim = Simulator(comfort=False)
    with pytest.raises(InputError, match=r"^Simulator.step: seat_acc_mps2 must be 3 finite numbers") as exc:
        sim.step(value)
    assert repr(value) in str(exc.value)
    if value is not None:  # None: no seat rotation
        with pytest.raises(InputError, match=r"^Simulator.step: seat_angvel_radps must be 3 finite numbers"):
            sim.step([0.0, 0.0, 0.0], seat_angvel_radps=value)
    assert sim.step([0.0, 0.0, 0.1]).time_s == 0.0  # refused steps do not advance the simulator


def test_realtime_report_counts_steps_and_overruns(motion):
    report = run_realtime(Simulator(comfort=True), motion.acc_mps2[:200], pace=False)
    assert report.n_steps == 200
    assert 0 < report.median_s <= report.p99_s <= report.worst_s

    class Slow:  # a step that takes 2 ms against a 1 ms clock must miss every deadline
        dt_s = 0.001

        def step(self, a):
            import time

            time.sleep(0.002)
            return None

    slow = run_realtime(Slow(), motion.acc_mps2[:20], pace=True)
    assert slow.overruns == 20 and slow.median_s >= 0.002
