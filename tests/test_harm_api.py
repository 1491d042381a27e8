"""Issue 31, part 4: tracebacks and misleading results outside the readers and output folders.

Each case gives the right answer or one sentence (an InputError naming what is wrong and what to do), never a
traceback.  Every test here failed on main before these fixes.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import textwrap
import warnings
import zipfile

import numpy as np
import pandas as pd
import pytest

import ehm
from ehm.cli import main
from ehm.errors import DivergenceError, EhmWarning, InputError
from ehm.tables import joint_names


def _one_line(text: str) -> str:
    lines = [ln for ln in text.strip().splitlines() if ln.strip()]
    assert len(lines) == 1, text
    return lines[0]


# ------------------------------------------------------------------ 1. tracebacks in the Python API and --dt
@pytest.mark.parametrize("call, words", [
    (lambda: ehm.assess(None), "assess() needs a SeatMotion, not None"),
    (lambda: ehm.assess("city"), "assess() needs a SeatMotion, not 'city'"),
    (lambda: ehm.SeatedHuman(params=42), "params must be a parameter file's path"),
    (lambda: ehm.h1_estimate("abc", np.zeros(100), fs_hz=100.0), "x (the input) must be a 1-D array of numbers"),
    (lambda: ehm.h1_estimate(np.ones(2000), np.ones(2000), fs_hz=0), "fs_hz must be > 0"),
    (lambda: ehm.h1_estimate(np.ones(2000), np.ones(2000), fs_hz=-100.0), "fs_hz must be > 0"),
    (lambda: ehm.h1_estimate(np.ones(2000), np.ones(2000), fs_hz=math.nan), "fs_hz must be finite"),
    (lambda: ehm.h1_estimate(np.ones(2000), np.ones(2000), fs_hz=True), "fs_hz must be a number, got True"),
])
def test_api_arguments_are_refused_in_one_sentence(call, words):
    """'ehm.assess(None), SeatedHuman(params=42), h1_estimate("abc", ...), h1_estimate(x, y, fs_hz=0) (also
    negative, NaN, bool)': AttributeError, TypeError, ValueError, ZeroDivisionError on main (and fs_hz=True ran
    as 1 Hz, fs_hz=-100 blamed the record's length)."""
    with pytest.raises(InputError) as info:
        call()
    assert words in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize("dt", ["1e-9", "10", "0.02"])
def test_implausible_time_step_is_refused_with_the_range(dt, tmp_path, capsys):
    """'ehm simulate --dt 1e-9' (and a huge --dt): main blamed the generated motion's sample count (1e-9) or its
    band (10 s), and a motion file at 1e-9 s would have settled for days; 20 ms diverges while settling.  One
    sentence with the range, from the one check every time step passes (parameter file, dt_s=, --dt)."""
    assert main(["simulate", "--dt", dt, "--out", str(tmp_path / "run")]) == 2
    line = _one_line(capsys.readouterr().err)
    assert line.startswith(f"ehm: error: --dt = {float(dt)!r} is not a plausible time step")
    assert "from 1 us to 10 ms" in line
    assert not (tmp_path / "run").exists()
    with pytest.raises(InputError, match="dt_s = 1e-09 is not a plausible time step"):
        ehm.SeatedHuman(dt_s=1e-9)
    with pytest.raises(InputError, match="simulation.dt_s = 0.5 is not a plausible"):
        ehm.Parameters.load().with_values({"simulation.dt_s": 0.5})


# ------------------------------------------------------------------ 2. one NaN in h1_estimate
def test_h1_estimate_names_the_non_finite_sample():
    """'h1_estimate with one NaN in the input returns an all-NaN curve': refused, naming the sample."""
    rng = np.random.default_rng(0)
    x = rng.standard_normal(4000)
    y = 0.5 * x
    y[1234] = np.nan
    with pytest.raises(InputError, match=r"y \(the output\) has a non-finite value \(nan\) at sample 1234;"):
        ehm.h1_estimate(x, y, fs_hz=100.0)
    y[1234] = 0.5 * x[1234]  # and without it the answer is right: gain 0.5 (exact, same samples)
    np.testing.assert_allclose(ehm.h1_estimate(x, y, fs_hz=100.0).gain, 0.5, rtol=1e-9)


# ------------------------------------------------------------------ 3. bodies outside the scaling's range
def test_body_outside_the_body_mass_index_range_is_refused(capsys):
    """'A 30 kg, 2.2 m body is accepted': its body mass index is 6.2 kg/m^2; the scaling builds 13-50 (ehm.scaling).
    The sentence names the masses that fit the stature (13 times 2.2^2, and the 200 kg mass limit)."""
    from ehm.scaling import BodySize

    with pytest.raises(InputError) as info:
        BodySize(stature_m=2.2, mass_kg=30.0)
    assert "body mass index of 6.2 kg/m^2" in str(info.value) and "13-50 kg/m^2" in str(info.value)
    assert "choose a mass from 62.9 to 200.0 kg" in str(info.value)
    assert main(["info", "--stature", "2.2", "--mass", "30"]) == 2
    assert "body mass index of 6.2" in _one_line(capsys.readouterr().err)
    BodySize(1.52, 50.0)  # a 5th-percentile woman (index 21.6) and the reference stay accepted
    BodySize(1.76, 70.882)


def test_body_outside_the_who_classes_is_built_with_a_warning():
    """A real user of 1.75 m and 130 kg (index 42.4, WHO obesity class III) is built, with one warning that the
    scaling keeps the reference's mass fractions (it was refused when the range ended at 40)."""
    from ehm.errors import EhmWarning
    from ehm.scaling import BodySize

    with pytest.warns(EhmWarning,
                      match=r"body mass index of 42\.4 kg/m\^2, above the 16-40 kg/m\^2 .*obesity class III"):
        BodySize(1.75, 130.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        BodySize(1.87, 98.0)  # index 28.0: no warning


# ------------------------------------------------------------------ 4. lock="t12"
def test_lock_given_as_one_name_is_that_joint(tmp_path):
    """'lock="t12" is split into letters' (unknown joint 't'): one name is one joint, in SeatedHuman (so
    Simulator, check_step), the locking study and the FMU export; anything else that is no name is refused."""
    assert ehm.SeatedHuman(lock="t12").locked == {"t12", "waist"}
    with pytest.raises(InputError, match="lock must be a joint name or a list of joint names"):
        ehm.SeatedHuman(lock=5)
    from ehm.study import locking_study

    study = locking_study(variants={"SL": "t12"})
    assert {r.variant: r.locked for r in study.rows} == {"baseline": (), "SL": ("t12",)}
    pytest.importorskip("pythonfmu")
    from ehm.fmu import SETUP_RESOURCE, export_fmu

    out = export_fmu(tmp_path / "neck.fmu", lock="lower_neck", python=True)
    setup = json.loads(zipfile.ZipFile(out).read(f"resources/{SETUP_RESOURCE}"))
    assert setup["lock"] == ["lower_neck"] and setup["locked"] == ["lower_neck", "waist"]


# ------------------------------------------------------------------ 5. the linear route's round-off channels
def test_linear_route_does_not_judge_a_round_off_channel_by_its_own_rms():
    """'The linear route warns that its answer is off by 22 % of the rms of a channel whose rms is round-off
    (trunk y under vertical input)'.  Here (10 s, 1.0 m/s^2 vertical: one window on the identified person; 0.8 m/s^2
    made two on the earlier one, and none now) the sideways accelerations are small beside the vertical ones; every
    channel with content is within 1 % (measured 0.90 %), so a 2 % tolerance must pass and the sideways channels,
    against the run's scale, are far below it (measured 0.03 %; bound 0.1 %)."""
    from ehm.hybrid import LinearRouteWarning

    human = ehm.SeatedHuman()
    with warnings.catch_warnings():
        warnings.simplefilter("error", LinearRouteWarning)
        run = human.simulate(ehm.random_vibration("z", 10.0, 1.0, seed=0), method="linear", tolerance=0.02)
    route = run.extra["route"]
    assert len(route["windows_s"]) >= 1  # the check did run
    assert route["largest_discrepancy"]["share_of_rms"] < 0.02
    assert all(route["discrepancy_share_of_rms"][p][1] < 1e-3 for p in ("pelvis", "trunk", "head"))


# ------------------------------------------------------------------ 6. the pythonfmu unit after a fatal error
_HOST = textwrap.dedent("""
    import sys
    if sys.argv[2] == "no-ehm":
        sys.modules["ehm.fmu"] = None  # a host whose Python cannot import ehm
    import fmpy
    from fmpy.fmi2 import FMU2Slave
    md = fmpy.read_model_description(sys.argv[1])
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=fmpy.extract(sys.argv[1]),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="unit")
    try:
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.getReal([99999])  # no such variable: pythonfmu answers fmi2Fatal
    except Exception as exc:
        print("failed:", exc)
    try:
        fmu.setReal([99999], [1.0])  # a host that goes on after the error: a second fatal call
    except Exception as exc:
        print("failed:", exc)
    fmu.terminate()
    fmu.freeInstance()
    print("freed")
""")


@pytest.fixture(scope="module")
def python_fmu(tmp_path_factory):
    pytest.importorskip("pythonfmu")
    pytest.importorskip("fmpy")
    from ehm.fmu import export_fmu

    return export_fmu(tmp_path_factory.mktemp("fmu") / "unit.fmu", python=True)


@pytest.mark.parametrize("case", ["bad-variable", "no-ehm"])
def test_python_fmu_survives_being_freed_after_a_fatal_error(python_fmu, tmp_path, case):
    """'The legacy --python FMU crashes its host when freed after a fatal error': pythonfmu 0.7 releases the slave
    at each fatal error and again at fmi2FreeInstance (two fatal calls, then freeing: segmentation fault, exit -11,
    on main), and a unit that
    failed to instantiate (no ehm in the host) left a null instance that crashed fmi2Terminate; and the reference
    that balanced pythonfmu's extra release was itself released at the host's exit, while the garbage collector
    still walked the objects (segmentation fault after "freed").  The host runs in a subprocess, so that a crash
    fails this test instead of ending pytest."""
    host = tmp_path / "host.py"
    host.write_text(_HOST)
    # Python's debug allocator makes a release of freed memory crash every time (with the default allocator the
    # crash at the host's exit came in about one run of three on Python 3.12 and 3.13).
    env = {**os.environ, "PYTHONMALLOC": "debug"}
    done = subprocess.run([sys.executable, str(host), str(python_fmu), case], capture_output=True, text=True,
                          timeout=300, env=env)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "failed: fmi2" in done.stdout and done.stdout.rstrip().endswith("freed")


def test_simulator_refuses_the_step_after_a_divergence(tmp_path, monkeypatch):
    """'a step that diverges': MuJoCo resets a state whose accelerations blow up, and main's Simulator then
    reported the reset state as the person's for up to 99 steps (checked every 100); now the next step raises,
    at the time MuJoCo found it (the step's start, 3 ms).  MuJoCo writes MUJOCO_LOG.TXT into the working directory
    on that warning, so the test runs in tmp_path."""
    monkeypatch.chdir(tmp_path)
    sim = ehm.Simulator(comfort=False)
    sim.step([0.0, 0.0, 0.0])
    sim.step([0.0, 0.0, 0.0])
    with pytest.raises(DivergenceError, match=r"diverged at t = 0\.003 s"):
        for _ in range(3):
            sim.step([0.0, 0.0, 1e9])


# ------------------------------------------------------------------ 7. other packages' warnings
def test_only_ehm_warnings_are_printed_as_ehm_warnings(capsys):
    """'numpy's and matplotlib's own warnings are printed as ehm's': ehm's own (EhmWarning: StepWarning,
    LinearRouteWarning, the readers' notes ...) stay 'ehm: warning:', numpy's keep their origin."""
    from ehm.cli.entry import _show_warning

    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = _show_warning
        np.mean(np.array([]))  # numpy: "Mean of empty slice" (RuntimeWarning)
        warnings.warn("the drive is short.", EhmWarning, stacklevel=1)
        ehm.SeatedHuman(dt_s=0.002)  # a StepWarning
    err = capsys.readouterr().err.splitlines()
    assert any(ln.startswith("ehm: note: RuntimeWarning from numpy/") and "Mean of empty slice" in ln for ln in err)
    assert "ehm: warning: the drive is short." in err
    assert any(ln.startswith("ehm: warning: the time step dt = 2 ms is coarser") for ln in err)
    assert not any(ln.startswith("ehm: warning:") and "empty slice" in ln for ln in err)


# ------------------------------------------------------------------ review: values named in messages, TOML words
@pytest.mark.parametrize("call, words", [
    (lambda: ehm.SeatedHuman().simulate(np.zeros((100, 3))), "simulate() needs a SeatMotion, not a float64 array of "
     "shape (100, 3):"),
    (lambda: ehm.assess(pd.DataFrame(np.zeros((10, 3)))), "not a DataFrame of shape (10, 3):"),
    (lambda: ehm.h1_estimate(pd.DataFrame({"a": ["x", "y"] * 600}), np.zeros(1200), fs_hz=100.0),
     "must be a 1-D array of numbers, not a DataFrame of shape (1200, 1)."),
    (lambda: joint_names(np.arange(3)), "list of joint names, e.g. ['t12', 'lower_neck'], not an int64 "
     "array of shape (3,)."),
])
def test_messages_name_a_values_type_not_a_cut_off_repr(call, words):
    """Review 4: "h.simulate(np.zeros((100,3))) gives 'simulate() needs a SeatMotion, not array([[0., 0., 0.],\\n
    [0., ...'" (the repr cut at 60 characters, over two lines): the type and shape are named, on one line."""
    with pytest.raises(InputError) as info:
        call()
    assert words in str(info.value) and "\n" not in str(info.value)


def test_a_batch_flag_that_is_no_boolean_is_refused_in_toml_words(tmp_path):
    """Review 5: 'a batch study's drop_held = "no" gets a command-line sentence: "[input] drive: drop_held
    (--no-drop-held) must be True or False"': the study's words instead (true or false, no quotes)."""
    from ehm.batch import load_study

    for key in ("drop_held", "fill_gaps", "imu"):
        study = tmp_path / "study.toml"
        study.write_text(f'[study]\nname = "s"\ncompute = ["transmissibility"]\n[input]\n{key} = "no"\n')
        with pytest.raises(InputError) as info:
            load_study(study)
        msg = str(info.value)
        assert f"[input] {key} must be true or false (a TOML boolean, no quotes); got 'no'." in msg, msg
        assert "--" not in msg and "True" not in msg and "\n" not in msg


def test_a_size_that_is_no_body_size_is_one_sentence():
    """The reviewer's case: SeatedHuman(size=(1.7, 70)) ended in AttributeError ('tuple' object has no attribute
    'is_reference'), as params=42 did before."""
    with pytest.raises(InputError, match=r"size must be an ehm\.scaling\.BodySize.*not a tuple"):
        ehm.SeatedHuman(size=(1.7, 70))
