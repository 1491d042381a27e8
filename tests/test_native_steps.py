"""The compiled stepping loop (ehm.engine.native): the same numbers as the Python loop, bit for bit, on the default
person, with head-in-space control and on a rotating seat; the Python loop with one warning where no compiler is
found or the build fails; the cache built once."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import ehm
from ehm.engine import native
from ehm.outputs.results import concatenate_runs


def _run_both(human, motion, monkeypatch):
    """The nonlinear route with the compiled loop (checked to be the one that ran) and with the Python loop."""
    native._loaded.cache_clear()
    assert native.available(), "the compiled loop should build on a machine with a C compiler"
    given = []
    original = native.advancer

    def spy(*args, **kwargs):
        given.append(original(*args, **kwargs))
        return given[-1]

    monkeypatch.setattr(native, "advancer", spy)
    compiled = human.simulate(motion, method="nonlinear")
    monkeypatch.setattr(native, "advancer", original)
    assert given and all(a is not None for a in given)  # every block of the run went through the compiled loop
    monkeypatch.setenv(native.SWITCH, "0")
    native._loaded.cache_clear()
    assert not native.available()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # EHM_NATIVE_STEPS=0: the Python loop without a warning
        python = human.simulate(motion, method="nonlinear")
    monkeypatch.delenv(native.SWITCH)
    native._loaded.cache_clear()
    return compiled, python


def _assert_identical(a, b):
    for p in a.points:
        for field in ("acc_mps2", "disp_m", "rot_rad", "angvel_radps"):
            np.testing.assert_array_equal(getattr(a.points[p], field), getattr(b.points[p], field), err_msg=p + field)
    for s in a.support_N:
        np.testing.assert_array_equal(a.support_N[s], b.support_N[s])


@pytest.mark.parametrize("kind", ["default", "head_control", "rotating_seat"])
def test_compiled_loop_gives_the_python_loops_numbers(kind, monkeypatch):
    if kind == "rotating_seat":
        human = ehm.SeatedHuman(rotating_seat=True)
        motion = ehm.city_drive(12.0, seed=1)  # SYNTHETIC drive with seat rotation
    else:
        human = ehm.SeatedHuman(head_control=True if kind == "head_control" else None)
        motion = ehm.random_vibration("xyz", 2.0, 0.5, seed=3)  # SYNTHETIC
    compiled, python = _run_both(human, motion, monkeypatch)
    assert np.abs(compiled.points["head"].acc_mps2).max() > 0.1  # the run moved the person
    _assert_identical(compiled, python)


def test_chunked_runs_continue_the_same_way(monkeypatch):
    """Several chunks (the state carried between calls of the loop) still give the Python loop's numbers."""
    human = ehm.SeatedHuman()
    motion = ehm.random_vibration("z", 3.0, 0.5, seed=4)  # SYNTHETIC
    native._loaded.cache_clear()
    compiled = concatenate_runs(list(human.stream(motion, chunk_s=0.7, method="nonlinear")))
    monkeypatch.setenv(native.SWITCH, "0")
    native._loaded.cache_clear()
    python = concatenate_runs(list(human.stream(motion, chunk_s=0.7, method="nonlinear")))
    native._loaded.cache_clear()
    _assert_identical(compiled, python)


def test_without_a_compiler_the_python_loop_runs_after_one_warning(tmp_path, monkeypatch):
    human = ehm.SeatedHuman()
    motion = ehm.random_vibration("z", 0.3, 0.5, seed=5)  # SYNTHETIC
    monkeypatch.setenv("EHM_CACHE_DIR", str(tmp_path / "empty-cache"))
    monkeypatch.delenv("CC", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path / "no-compilers-here"))
    monkeypatch.setattr(native, "_warned", [])
    native._loaded.cache_clear()
    try:
        with pytest.warns(native.NativeStepWarning, match="no C compiler was found") as record:
            first = human.simulate(motion, method="nonlinear")
            human.simulate(motion, method="nonlinear")
        assert len(record) == 1  # once per process
        assert str(record[0].message).count(".") >= 1 and "\n" not in str(record[0].message)
        assert np.isfinite(first.points["head"].acc_mps2).all()
    finally:
        native._loaded.cache_clear()


def test_a_failing_build_is_named_and_leaves_no_file(tmp_path, monkeypatch):
    cache = tmp_path / "cache"
    monkeypatch.setenv("EHM_CACHE_DIR", str(cache))
    monkeypatch.setenv("CC", "false")  # a "compiler" that fails
    monkeypatch.setattr(native, "_warned", [])
    native._loaded.cache_clear()
    try:
        with pytest.warns(native.NativeStepWarning, match="could not build it"):
            ehm.SeatedHuman().simulate(ehm.random_vibration("z", 0.2, 0.5, seed=6), method="nonlinear")
        assert not list(cache.glob("*.so"))
        assert not [p for p in cache.iterdir() if p.is_dir()]  # the build folder went away
    finally:
        native._loaded.cache_clear()


def test_the_cache_is_built_once(tmp_path, monkeypatch):
    monkeypatch.setenv("EHM_CACHE_DIR", str(tmp_path))
    native._loaded.cache_clear()
    try:
        assert native.available()
        built = list(tmp_path.glob("ehm_steps-*"))
        assert len(built) == 1
        stamp = built[0].stat().st_mtime_ns
        native._loaded.cache_clear()
        assert native.available()
        assert built[0].stat().st_mtime_ns == stamp
    finally:
        native._loaded.cache_clear()


def test_a_mujoco_error_in_the_loop_is_raised_as_the_bindings_raise_it():
    # SYNTHETIC: a model whose arena is too small for its contacts; MuJoCo's own handler would end the process
    import mujoco

    xml = ('<mujoco><size memory="6K"/><worldbody><geom type="plane" size="1 1 .1"/>'
           + "".join(f'<body pos="{0.05 * i} 0 .1"><freejoint/><geom type="box" size=".05 .05 .05"/></body>'
                     for i in range(6)) + "</worldbody></mujoco>")
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    n = 500
    gravity = np.tile(np.array([0.0, 0.0, -9.81]), (n, 1))
    advance = native.advancer(m, d, gravity, np.empty((n, m.nsensordata)), None, None)
    assert advance is not None
    with pytest.raises(mujoco.FatalError, match="out of memory"):
        advance(0, n)
    # and the loop runs on afterwards, with MuJoCo's handlers and clock as they were
    human = ehm.SeatedHuman()
    run = human.simulate(ehm.random_vibration("z", 0.5, 0.3, seed=7), method="nonlinear")  # SYNTHETIC
    assert np.isfinite(run.points["head"].acc_mps2).all()


def test_two_threads_in_the_loop_leave_mujocos_clock_as_it_was():
    import ctypes
    import threading

    lib = ctypes.CDLL(str(ehm.engine.c_library()["library"]))
    clock = ctypes.c_void_p.in_dll(lib, "mjcb_time").value
    people = [ehm.SeatedHuman(), ehm.SeatedHuman()]
    motion = ehm.random_vibration("z", 3.0, 0.3, seed=8)  # SYNTHETIC
    runs = [None, None]

    def go(k):
        runs[k] = people[k].simulate(motion, method="nonlinear")

    threads = [threading.Thread(target=go, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(120)
    assert ctypes.c_void_p.in_dll(lib, "mjcb_time").value == clock
    np.testing.assert_array_equal(runs[0].points["head"].acc_mps2, runs[1].points["head"].acc_mps2)


def test_two_threads_stepping_one_person_take_turns():
    # a run writes the seat's load into the model's gravity at every step: sharing one person between threads gave
    # garbage (head accelerations off by several times their rms) before runs took turns
    import threading

    human = ehm.SeatedHuman()
    motions = [ehm.random_vibration("z", 3.0, 0.3, seed=9), ehm.random_vibration("x", 3.0, 0.3, seed=10)]  # SYNTHETIC
    alone = [human.simulate(m, method="nonlinear") for m in motions]
    runs = [None, None]

    def go(k):
        runs[k] = human.simulate(motions[k], method="nonlinear")

    threads = [threading.Thread(target=go, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(120)
    for k in range(2):
        np.testing.assert_array_equal(runs[k].points["head"].acc_mps2, alone[k].points["head"].acc_mps2)
