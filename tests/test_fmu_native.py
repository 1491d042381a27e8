"""The native FMU (ehm.interfaces.fmu_native): a C binary on the MuJoCo C library, no Python when it runs.

Checked here: (a) the binary links no libpython; (b) a plain C host (ehm's native/fmu_host.c, compiled in the
test, run with an empty environment) gives the outputs of SeatedHuman.simulate for the same input, with one
and with several model steps per communication step; (c) fmpy's model-description validation and
simulate_fmu; (d) what a host relies on: bad inputs, a doStep at the wrong time, bad resources, divergence,
reset, terminate twice, re-instantiation, two instances, FMU state.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import zipfile
from importlib import resources

import numpy as np
import pytest

import ehm
from ehm.errors import InputError
from ehm.interfaces.cli import main
from ehm.interfaces.fmu_native import INPUTS, MAX_SEAT_ACC_MPS2, MODEL_IDENTIFIER, OUTPUTS, PLATFORM, POINTS, SUPPORTS
from ehm.routes.nonlinear import chunk_result

fmpy = pytest.importorskip("fmpy",
                           reason="the FMI headers and the test host library come from fmpy (pip install -e '.[test]')")

from fmpy.fmi1 import FMICallException  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402

from ehm.interfaces import fmu_native  # noqa: E402

if not fmu_native.native_platform_supported():
    pytest.skip("the native FMU is built for 64-bit Linux on x86", allow_module_level=True)
try:
    CC = fmu_native.find_compiler()
except InputError as exc:  # pragma: no cover - a machine without a C compiler
    pytest.skip(str(exc), allow_module_level=True)

#: (PointMotion field, output suffixes) compared per point.
FIELDS = {"acc_mps2": ("ax_mps2", "ay_mps2", "az_mps2"), "rot_rad": ("roll_rad", "pitch_rad", "yaw_rad"),
          "disp_m": ("x_m", "y_m", "z_m"), "angvel_radps": ("wx_radps", "wy_radps", "wz_radps"),
          "angacc_radps2": ("roll_acc_radps2", "pitch_acc_radps2", "yaw_acc_radps2")}
DISCARD, ERROR = 2, 3  # fmi2Status


@pytest.fixture(scope="module")
def human() -> ehm.SeatedHuman:
    """The default person at the reference vibration level, given (conftest's takes each drive's level): a unit has
    no drive to take a level from, so the whole runs it is compared with run at the reference level too."""
    h = ehm.SeatedHuman(ehm.Person(vibration_rms_mps2=1.0))
    h.settle()
    return h


@pytest.fixture(scope="module")
def unit(tmp_path_factory):
    """The default person's native unit: (fmu path, unzipped folder, model description)."""
    folder = tmp_path_factory.mktemp("native")
    path = fmu_native.export_native_fmu(folder / "person.fmu")
    unzipped = folder / "unzipped"
    with zipfile.ZipFile(path) as z:
        z.extractall(unzipped)
    os.chmod(unzipped / "binaries" / PLATFORM / f"{MODEL_IDENTIFIER}.so", 0o755)
    return path, unzipped, fmpy.read_model_description(str(path))


@pytest.fixture(scope="module")
def host(tmp_path_factory):
    """ehm's example C host, compiled with the system compiler (it links only libc and libdl)."""
    folder = tmp_path_factory.mktemp("host")
    src = folder / "fmu_host.c"
    src.write_bytes(resources.files("ehm").joinpath("native", "fmu_host.c").read_bytes())
    exe = folder / "fmu_host"
    subprocess.run([*CC, "-std=c11", "-O2", "-I", str(fmu_native.fmi_headers()), str(src), "-o", str(exe), "-ldl"],
                   check=True, capture_output=True, text=True)
    return exe



def _run_host(host, unit, time_s, acc, out_csv):
    """Run the C host with an empty environment: one communication step per row (start time, seat
    acceleration), the step size being the time to the next row.  Returns the output rows (first: after
    initialisation) as a dict name -> array."""
    _, unzipped, md = unit
    inp = out_csv.with_suffix(".in.csv")
    with open(inp, "w") as f:
        f.write("time_s," + ",".join(INPUTS) + "\n")
        for t, a in zip(time_s, acc):
            f.write(",".join(repr(float(v)) for v in (t, *a, 0.0, 0.0, 0.0)) + "\n")
    done = subprocess.run(["env", "-i", str(host), str(unzipped), MODEL_IDENTIFIER, md.guid, str(len(OUTPUTS)),
                           str(inp), str(out_csv)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    data = np.loadtxt(out_csv, delimiter=",", skiprows=1)
    return {name: data[:, 1 + j] for j, name in enumerate(OUTPUTS)} | {"host_time_s": data[:, 0]}


def _assert_outputs_equal(got, rows, whole, atol, peak_rel=0.0):
    """``got[name][k]`` against the whole run's sample ``rows[k]``, for every output: within ``atol`` plus
    ``peak_rel`` times that output's largest magnitude over the compared samples (round-off carried through the
    dynamics scales with the size of the signal, not with its value at one sample, which may cross zero)."""
    def close(actual, desired, name):
        tol = atol + peak_rel * (np.abs(desired).max() if desired.size else 0.0)
        np.testing.assert_allclose(actual, desired, rtol=0, atol=tol, err_msg=name)

    for p in POINTS:
        pm = whole.point(p)
        for field, suffixes in FIELDS.items():
            ref = getattr(pm, field)
            for j, s in enumerate(suffixes):
                close(got[f"{p}_{s}"], ref[rows, j], f"{p}_{s}")
    for g in SUPPORTS:
        for j, a in enumerate("xyz"):
            close(got[f"{g}_f{a}_N"], whole.support_N[g][rows, j], f"{g}_f{a}_N")
    np.testing.assert_allclose(got["output_time_s"], whole.time_s[rows], rtol=0, atol=1e-12)


# ---------------------------------------------------------------------------------------------- (a) binary
def test_binary_links_mujoco_not_python(unit):
    _, unzipped, md = unit
    binaries = unzipped / "binaries" / PLATFORM
    if shutil.which("readelf") is None:
        pytest.skip("readelf (binutils) is not installed")
    dyn = subprocess.run(["readelf", "-d", str(binaries / f"{MODEL_IDENTIFIER}.so")], capture_output=True, text=True,
                         check=True).stdout
    needed = [line.split("[")[1].rstrip("]") for line in dyn.splitlines() if "(NEEDED)" in line]
    assert not any("python" in n.lower() for n in needed), needed
    lib = [n for n in needed if n.startswith("libmujoco")]
    assert lib and (binaries / lib[0]).is_file()  # libmujoco travels with the unit ...
    assert "Library rpath: [$ORIGIN]" in dyn  # ... and is found next to the binary
    symbols = subprocess.run(["readelf", "--dyn-syms", "-W", str(binaries / f"{MODEL_IDENTIFIER}.so")],
                             capture_output=True, text=True, check=True).stdout
    for f in ("fmi2Instantiate", "fmi2DoStep", "fmi2GetReal", "fmi2SetReal", "fmi2Reset", "fmi2GetFMUstate"):
        assert f" {f}" in symbols
    with zipfile.ZipFile(unit[0]) as z:
        names = z.namelist()
        setup = json.loads(z.read("resources/ehm_fmu.json"))
    for name in ("resources/ehm_model.mjb", "resources/ehm_state.txt", "resources/ehm_params.toml",
                 "sources/ehm_fmu.c", "sources/ehm_fmu_config.h", "sources/CMakeLists.txt",
                 "documentation/licenses/mujoco-LICENSE"):
        assert name in names
    assert setup["dt_s"] == ehm.Parameters.load().value("simulation.dt_s")  # the model step from the parameters
    assert md.defaultExperiment.stepSize == repr(setup["dt_s"])


# ------------------------------------------------------------------------------------------ (b) C host
def test_c_host_equals_whole_run(unit, host, human, tmp_path):
    # 10 s of SYNTHETIC random seat vibration in x, y and z.  The whole run's own (interpolated) seat input is
    # fed to the unit, one model step per communication step: the same engine, the same operations, so the
    # outputs agree to round-off (measured: accelerations, displacements and forces bit-identical, angles within
    # 4e-16 rad, from quaternion-to-angle arithmetic in C against scipy).  Bit-identical dynamics is the claim
    # here, not luck: both routes step the same libmujoco with the same gravity bits (G0 - a, one IEEE
    # subtraction, for a seat that does not rotate), so only the read-out arithmetic differs, and it is not fed
    # back; 1e-10 in SI units (thousands of ulps of the largest output, a 700 N force) allows for compilers.
    whole = human.simulate(ehm.random_vibration("xyz", 10.0, 0.5, seed=3), method="nonlinear")
    n, dt = whole.time_s.size, whole.dt_s
    assert n == int(round(10.0 / dt)) + 1
    got = _run_host(host, unit, whole.time_s, whole.seat_acc_mps2, tmp_path / "out.csv")
    # Row 0: after initialisation, the sample at t = 0 (the response to the start input); row k + 1: after
    # doStep(t_k, dt), the sample at t_k.  The last step (from t_{n-1}) has no whole-run counterpart.
    rows = np.concatenate([[0], np.arange(n)])
    assert got["output_time_s"].size == n + 1
    _assert_outputs_equal({k: v[:-1] for k, v in got.items()}, rows[:-1], whole, atol=1e-10)
    np.testing.assert_allclose(got["host_time_s"][1:], whole.time_s + dt, rtol=0, atol=1e-12)
    assert np.abs(got["head_az_mps2"]).max() > 0.1  # the input drove the model
    assert got["seat_pan_fz_N"].mean() > 0.5 * human.mass_kg * 9.81  # the seat carries most of the weight


def test_c_host_sub_steps(unit, host, human, tmp_path):
    # Communication steps of 10 model steps: the unit holds the input over the 10 steps and reports the sample
    # of the last one.  The whole run gets the same held input (a staircase sampled at the model step).
    k, dt = 10, human.model.mj.opt.timestep
    n_comm = 200  # 2 s at the default 1 ms step
    rng = np.random.default_rng(7)
    held = rng.normal(0.0, 0.5, (n_comm, 3))  # SYNTHETIC white seat acceleration [m/s^2]
    time_s = np.arange(n_comm * k + 1) * dt
    acc = np.vstack([np.repeat(held, k, axis=0), held[-1:]])
    whole = human.simulate(ehm.SeatMotion(time_s, acc, "SYNTHETIC staircase"), method="nonlinear")
    got = _run_host(host, unit, time_s[:-1:k], held, tmp_path / "sub.csv")
    rows = np.concatenate([[0], np.arange(1, n_comm + 1) * k - 1])
    _assert_outputs_equal(got, rows, whole, atol=1e-10)


# ------------------------------------------------------------------------------------------- (c) fmpy
def test_fmpy_validates_and_simulates(unit, human):
    from fmpy.validation import validate_fmu

    path, _, md = unit
    assert validate_fmu(str(path)) == []
    assert md.fmiVersion == "2.0" and md.coSimulation is not None and md.modelExchange is None
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    kinds = {v.name: (v.causality, v.variability, v.type, v.unit) for v in md.modelVariables}
    assert [v.name for v in md.modelVariables] == list(INPUTS + OUTPUTS)
    assert kinds["seat_az_mps2"] == ("input", "continuous", "Real", "m/s2")
    assert kinds["head_az_mps2"] == ("output", "continuous", "Real", "m/s2")
    assert kinds["seat_pan_fz_N"] == ("output", "continuous", "Real", "N")
    assert kinds["head_pitch_acc_radps2"][3] == "rad/s2"

    whole = human.simulate(ehm.random_vibration("xyz", 1.0, 0.5, seed=4), method="nonlinear")
    sig = np.zeros(whole.time_s.size, dtype=[("time", float)] + [(n, float) for n in INPUTS])
    sig["time"] = whole.time_s
    for j, a in enumerate("xyz"):
        sig[f"seat_a{a}_mps2"] = whole.seat_acc_mps2[:, j]
    res = fmpy.simulate_fmu(str(path), start_time=0.0, stop_time=whole.time_s[-1], step_size=whole.dt_s,
                            output_interval=whole.dt_s, input=sig, output=list(OUTPUTS))
    # fmpy records the outputs after initialisation and after each doStep(t_k, dt): the samples 0, 0, 1, 2, ...
    n = whole.time_s.size
    assert res.shape[0] == n
    got = {name: res[name] for name in OUTPUTS}
    # fmpy interpolates the input signal at its own step times (equal to the samples within round-off)
    _assert_outputs_equal(got, np.concatenate([[0], np.arange(n - 1)]), whole, atol=1e-9)
    coarse = fmpy.simulate_fmu(str(path), stop_time=0.5, output_interval=20 * whole.dt_s, output=["head_az_mps2"])
    assert coarse.shape[0] == round(0.5 / (20 * whole.dt_s)) + 1 and np.isfinite(coarse["head_az_mps2"]).all()


# ------------------------------------------------------------------------------------- (d) host behaviour
def _slave(unit, name="ehm", unzipped=None):
    _, folder, md = unit
    s = FMU2Slave(guid=md.guid, unzipDirectory=str(unzipped or folder), modelIdentifier=MODEL_IDENTIFIER,
                  instanceName=name)
    s.instantiate(loggingOn=True)
    return s


def _start(s, t0=0.0):
    s.setupExperiment(startTime=t0)
    s.enterInitializationMode()
    s.exitInitializationMode()


VR = {name: k for k, name in enumerate(INPUTS + OUTPUTS)}
ALL_OUT = [VR[n] for n in OUTPUTS]


def _drive(s, seat_acc, t0, h):
    """doStep with each row of seat_acc in turn; returns the outputs after each step (rows)."""
    out = []
    for k, a in enumerate(seat_acc):
        s.setReal([VR["seat_ax_mps2"], VR["seat_ay_mps2"], VR["seat_az_mps2"]], list(a))
        s.doStep(currentCommunicationPoint=t0 + k * h, communicationStepSize=h)
        out.append(s.getReal(ALL_OUT))
    return np.array(out)


def _status(excinfo):
    return excinfo.value.status


def test_bad_inputs_are_refused_and_the_unit_stays(unit, capfd):
    s = _slave(unit)
    try:
        _start(s)
        h = 10 * s_dt(unit)
        good = _drive(s, [[0.1, 0.0, 0.2]], 0.0, h)
        for name, value, words in (("seat_az_mps2", float("nan"), "must be finite"),
                                   ("seat_ax_mps2", float("inf"), "must be finite"),
                                   ("seat_ay_mps2", 1e6, "beyond the model's range"),
                                   ("seat_wz_radps", 0.1, "seat translation only")):
            s.setReal([VR[name]], [value])
            with pytest.raises(FMICallException) as exc:
                s.doStep(currentCommunicationPoint=h, communicationStepSize=h)
            assert _status(exc) == DISCARD
            assert words in capfd.readouterr().out
            assert s.getRealStatus(fmpy.fmi2.fmi2LastSuccessfulTime) == pytest.approx(h, abs=1e-15)
            s.setReal([VR[name]], [0.0])
        # nothing moved: the next step from the same time gives what a fresh unit gives
        after = _drive(s, [[0.0, 0.0, 0.0]], h, h)
        assert np.isfinite(after).all() and np.isfinite(good).all()
        fresh = _slave(unit, "fresh")
        _start(fresh)
        ref = _drive(fresh, [[0.1, 0.0, 0.2], [0.0, 0.0, 0.0]], 0.0, h)
        np.testing.assert_array_equal(after[0], ref[1])
        fresh.terminate()
        fresh.freeInstance()

        # a step that does not start at the unit's own time, and one that is not a whole number of model steps
        with pytest.raises(FMICallException) as exc:
            s.doStep(currentCommunicationPoint=2 * h + 4.0, communicationStepSize=h)
        assert _status(exc) == ERROR
        assert f"but the unit is at t = {2 * h:.9g} s" in capfd.readouterr().out
        with pytest.raises(FMICallException) as exc:
            s.doStep(currentCommunicationPoint=2 * h, communicationStepSize=0.3 * s_dt(unit))
        assert _status(exc) == ERROR and "whole multiple of the model step" in capfd.readouterr().out
        with pytest.raises(FMICallException) as exc:
            s.setReal([VR["head_az_mps2"]], [1.0])
        assert _status(exc) == ERROR and "is an output" in capfd.readouterr().out
        s.terminate()
        s.terminate()  # terminating twice is harmless
    finally:
        s.freeInstance()


def s_dt(unit) -> float:
    return float(unit[2].defaultExperiment.stepSize)


def test_bad_resources_give_errors_not_crashes(unit, tmp_path, capfd):
    _, unzipped, _ = unit
    cases = {
        "missing model": lambda res: (res / "ehm_model.mjb").unlink(),
        "garbage model": lambda res: (res / "ehm_model.mjb").write_bytes(b"not an MJB" * 100),
        "short state": lambda res: (res / "ehm_state.txt").write_text(
            re.sub(r"^qpos (\d+) \S+", lambda m: f"qpos {int(m[1]) - 1}", (res / "ehm_state.txt").read_text(),
                   flags=re.M)),
        "bad number": lambda res: (res / "ehm_state.txt").write_text(
            (res / "ehm_state.txt").read_text().replace("diverged_m 0.5", "diverged_m x", 1)),
    }
    expected = {"missing model": "cannot load the MuJoCo model", "garbage model": "cannot load the MuJoCo model",
                "short state": "qpos has",  "bad number": "not a finite number"}
    for case, spoil in cases.items():
        copy = tmp_path / case.replace(" ", "_")
        shutil.copytree(unzipped, copy)
        spoil(copy / "resources")
        s = _slave(unit, case, copy)
        try:
            with pytest.raises(FMICallException) as exc:
                s.setupExperiment(startTime=0.0)
            assert _status(exc) == ERROR, case
            with pytest.raises(FMICallException) as exc:
                s.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.01)
            assert _status(exc) == ERROR, case
            out = capfd.readouterr().out
            assert expected[case] in out and "export the unit again" in out, (case, out)
        finally:
            s.freeInstance()


def test_divergence_is_an_error_and_reset_recovers(unit, capfd):
    # 95 m/s^2 of downward seat acceleration (within the accepted range) throws the unbelted person off the
    # seat: the pelvis leaves its position by more than 0.5 m within a fraction of a second.
    s = _slave(unit)
    try:
        _start(s)
        h = 20 * s_dt(unit)
        with pytest.raises(FMICallException) as exc:
            _drive(s, [[0.0, 0.0, -0.95 * MAX_SEAT_ACC_MPS2]] * 100, 0.0, h)
        assert _status(exc) == ERROR
        assert "the simulation diverged at t = " in capfd.readouterr().out
        with pytest.raises(FMICallException) as exc:  # it stays stopped ...
            s.doStep(currentCommunicationPoint=s.getRealStatus(fmpy.fmi2.fmi2LastSuccessfulTime),
                     communicationStepSize=h)
        assert _status(exc) == ERROR and "cannot go on" in capfd.readouterr().out
        s.reset()  # ... until reset: then it runs as a fresh unit
        _start(s)
        again = _drive(s, [[0.2, 0.1, 0.3]] * 5, 0.0, h)
        fresh = _slave(unit, "fresh")
        _start(fresh)
        np.testing.assert_array_equal(again, _drive(fresh, [[0.2, 0.1, 0.3]] * 5, 0.0, h))
        fresh.terminate()
        fresh.freeInstance()
    finally:
        s.freeInstance()


def test_two_instances_reinstantiation_and_fmu_state(unit):
    h = 10 * s_dt(unit)
    x_in = [[0.5, 0.0, 0.0]] * 10 + [[-0.5, 0.0, 0.0]] * 10
    z_in = [[0.0, 0.0, 0.8]] * 20
    alone = {}
    for name, seat in (("x", x_in), ("z", z_in)):
        s = _slave(unit, name)
        _start(s)
        alone[name] = _drive(s, seat, 0.0, h)
        s.terminate()
        s.freeInstance()  # and instantiate again in the next round
    a, b = _slave(unit, "a"), _slave(unit, "b")
    try:
        _start(a)
        _start(b)
        ya, yb = [], []
        for k in range(20):  # interleaved, in one process
            ya.append(_drive_at(a, x_in[k], k * h, h))
            yb.append(_drive_at(b, z_in[k], k * h, h))
        np.testing.assert_array_equal(np.array(ya), alone["x"])
        np.testing.assert_array_equal(np.array(yb), alone["z"])
        assert np.abs(alone["x"] - alone["z"]).max() > 1e-3  # the two runs differ

        # FMU state: save at 0.2 s, run on, go back, run on again: the same outputs; serialized too
        state = a.getFMUstate()
        blob = a.serializeFMUstate(state)
        first = _drive(a, z_in[:5], 20 * h, h)
        a.setFMUstate(state)
        np.testing.assert_array_equal(_drive(a, z_in[:5], 20 * h, h), first)
        restored = a.deSerializeFMUstate(blob)
        a.setFMUstate(restored)
        np.testing.assert_array_equal(_drive(a, z_in[:5], 20 * h, h), first)
        a.freeFMUstate(state)
        a.freeFMUstate(restored)
    finally:
        a.freeInstance()
        b.freeInstance()


def test_resource_path_with_spaces_and_host_clock_round_off(unit, tmp_path):
    # fmpy passes resources/ as a percent-encoded file: URI; a host adding h to its clock carries round-off.
    copy = tmp_path / "a folder with spaces"
    shutil.copytree(unit[1], copy)
    s = _slave(unit, "spaces", copy)
    try:
        _start(s)
        h, t = 10 * s_dt(unit), 0.0
        for _ in range(30):
            s.setReal([VR["seat_az_mps2"]], [0.3])
            s.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            t += h
        assert t != 30 * h  # the clock did drift from the exact multiple, and the unit accepted it
        assert s.getRealStatus(fmpy.fmi2.fmi2LastSuccessfulTime) == pytest.approx(30 * h, abs=1e-12)
        assert np.isfinite(s.getReal(ALL_OUT)).all()
    finally:
        s.freeInstance()


def _drive_at(s, seat, t, h):
    return _drive(s, [seat], t, h)[0]


# ---------------------------------------------------------------------------------- export and the CLI
def test_cli_exports_native_unit_with_person_options(tmp_path, capsys):
    out = tmp_path / "sub" / "small.fmu"
    assert main(["export-fmu", "--out", str(out), "--lock", "lower_neck", "--stature", "1.52", "--mass", "50",
                 "--dt", "0.00025"]) == 0
    msg = capsys.readouterr().out
    assert "native C on MuJoCo" in msg and "50.0 kg" in msg and "no Python" in msg
    with zipfile.ZipFile(out) as z:
        setup = json.loads(z.read("resources/ehm_fmu.json"))
        state = z.read("resources/ehm_state.txt").decode()
    assert setup["dt_s"] == 0.00025 and "lower_neck" in setup["locked"] and setup["mass_kg"] == pytest.approx(50.0)
    assert "dt_s 0.00025" in state
    assert sorted(os.listdir(out.parent)) == ["small.fmu"]  # no temporary file left behind


def test_export_errors(tmp_path, monkeypatch, capsys):
    out = tmp_path / "e.fmu"
    out.write_bytes(b"old")
    monkeypatch.delenv("CC", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path / "empty"))  # no compiler anywhere
    assert main(["export-fmu", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "needs a C compiler" in err and err.count("\n") == 1
    monkeypatch.setenv("CC", "no-such-cc")
    with pytest.raises(InputError, match="no-such-cc"):
        fmu_native.find_compiler()
    monkeypatch.setenv("CC", CC[0])
    original = fmu_native._native_file
    monkeypatch.setattr(fmu_native, "_native_file",  # a C source that does not compile
                        lambda name: b"this is not C;\n" if name == fmu_native.C_SOURCE else original(name))
    with pytest.raises(InputError, match="could not build the FMU binary"):
        fmu_native.export_native_fmu(out, ehm.SeatedHuman(params=ehm.Parameters.load()))
    assert out.read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["e.fmu"]


def test_cmake_build_description_builds_a_working_binary(unit, host, tmp_path):
    # What a user on another platform does with a unit's sources/ (here: on Linux again, with CMake).
    if shutil.which("cmake") is None:
        pytest.skip("cmake is not installed")
    _, unzipped, md = unit
    lib = ehm.engine.c_library()
    build = tmp_path / "build"
    subprocess.run(["cmake", "-S", str(unzipped / "sources"), "-B", str(build), f"-DMUJOCO_DIR={lib['library'].parent}",
                    f"-DFMI_HEADERS={fmu_native.fmi_headers()}", "-DCMAKE_BUILD_TYPE=Release"],
                   check=True, capture_output=True, text=True)
    subprocess.run(["cmake", "--build", str(build)], check=True, capture_output=True, text=True)
    copy = tmp_path / "unit"
    shutil.copytree(unzipped, copy)
    shutil.copyfile(build / f"{MODEL_IDENTIFIER}.so", copy / "binaries" / PLATFORM / f"{MODEL_IDENTIFIER}.so")
    time_s = np.arange(50) * s_dt(unit)
    acc = np.tile([0.2, -0.1, 0.4], (50, 1))
    got = _run_host(host, (None, copy, md), time_s, acc, tmp_path / "cmake.csv")
    ref = _run_host(host, unit, time_s, acc, tmp_path / "ref.csv")
    for name in OUTPUTS:
        np.testing.assert_allclose(got[name], ref[name], rtol=0, atol=1e-12, err_msg=name)


# ------------------------------------------------------------------------------------------ rotating seat
def _rotating_reference(human, acc_seat, w):
    """The rotating-seat unit's definition, computed independently with scipy and ehm's Python engine: per
    model step, the seat attitude q at the step's start gives z-y-x angles (yaw unwrapped), the held body rates
    w give the angle rates, their backward difference the angle accelerations; q then advances by exp(w dt / 2).
    Returns the RunResult of ``engine.run`` with that seat rotation, in seat axes (SeatedHuman's own transform)."""
    from scipy.spatial.transform import Rotation

    from ehm import engine

    model, dt = human.model, human.model.mj.opt.timestep
    n = len(acc_seat)
    q = Rotation.identity()
    angles, rates, R = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3, 3))
    for i in range(n):
        yaw, pitch, roll = q.as_euler("ZYX")
        if i:
            yaw = angles[i - 1, 0] + np.remainder(yaw - angles[i - 1, 0] + np.pi, 2 * np.pi) - np.pi
        turn = w[i, 1] * np.sin(roll) + w[i, 2] * np.cos(roll)
        angles[i] = yaw, pitch, roll
        rates[i] = turn / np.cos(pitch), w[i, 1] * np.cos(roll) - w[i, 2] * np.sin(roll), w[i, 0] + np.tan(pitch) * turn
        R[i] = q.as_matrix()
        q = q * Rotation.from_rotvec(w[i] * dt)
    accs = np.vstack([np.zeros((1, 3)), np.diff(rates, axis=0) / dt])
    raw = engine.run(model, np.einsum("nij,nj->ni", R, acc_seat), d=engine.settled_data(model),
                     seat_rotation=(angles, rates, accs))
    t = np.arange(n) * dt
    return chunk_result(human.built, raw, t, np.asarray(acc_seat, float), R, angles,
                        engine.settled_point_poses(model), model.seat["pivot"], 0.0, "reference")


@pytest.fixture(scope="module")
def rotating_unit(tmp_path_factory):
    human = ehm.SeatedHuman(ehm.Person(vibration_rms_mps2=1.0), rotating_seat=True)  # the unit's level (above)
    folder = tmp_path_factory.mktemp("rotating")
    path = fmu_native.export_native_fmu(folder / "rotating.fmu", human)
    unzipped = folder / "unzipped"
    with zipfile.ZipFile(path) as z:
        z.extractall(unzipped)
    return (path, unzipped, fmpy.read_model_description(str(path))), human


def test_rotating_seat_unit_equals_its_definition_in_python(rotating_unit):
    # 1 s of SYNTHETIC seat motion: random translation plus roll, pitch and yaw rates of 0.2-0.6 rad/s, one
    # model step per communication step.  The unit's outputs equal the independent Python computation of the same
    # definition to round-off; the seat really turned (yaw 0.6 rad) and the outputs are in seat axes.
    unit, human = rotating_unit
    dt = human.model.mj.opt.timestep
    n = int(round(1.0 / dt))
    t = np.arange(n) * dt
    rng = np.random.default_rng(11)
    acc = rng.normal(0.0, 0.5, (n, 3))
    w = np.column_stack([0.2 * np.sin(2 * np.pi * 1.5 * t), 0.3 * np.sin(2 * np.pi * 0.8 * t), 0.6 * np.ones(n)])
    s = _slave(unit)
    try:
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.setReal([VR[k] for k in INPUTS], [*acc[0], *w[0]])
        s.exitInitializationMode()
        rows = [s.getReal(ALL_OUT)]
        for k in range(n):
            s.setReal([VR[name] for name in INPUTS], [*acc[k], *w[k]])
            s.doStep(currentCommunicationPoint=k * dt, communicationStepSize=dt)
            rows.append(s.getReal(ALL_OUT))
    finally:
        s.terminate()
        s.freeInstance()
    got = np.array(rows)
    ref = _rotating_reference(human, acc, w)
    got = {name: got[1:, j] for j, name in enumerate(OUTPUTS)}  # row k + 1: the sample at t_k
    # Not bit-identical: the unit turns the seat by quaternion integration in C, the reference by scipy's
    # rotation vectors, and the angles come from differently ordered arithmetic; a few ulps of difference in the
    # gravity vector per step, which the dynamics (stiff pads, sliding feet) carry on.  Their size, measured by
    # perturbing the Python route alone: seat acceleration or rates times (1 + eps) move every output by up to
    # 1.3e-10 of its peak over the run (forces; accelerations 3e-11), i.e. ~6e5 eps per unit relative input
    # error; C against Python measured 1.0e-10 (a floor force of 0.02 N at a zero crossing differed by 1.2e-9 N,
    # which failed the old pointwise rtol=1e-9).  1e-8 of each output's peak is ~75 times that spread (a few
    # tens of ulps of input difference per step).  A wrong unit is orders larger: yaw rate with the wrong sign
    # 2 x peak, rates half a step late 1e-2 to 1 x peak, even seat acceleration off by 1e-6: up to 3e-7 x peak.
    _assert_outputs_equal(got, np.arange(n), ref, atol=0.0, peak_rel=1e-8)
    assert ref.seat_angles_rad[-1, 0] == pytest.approx(0.6, rel=0.01)  # 0.6 rad/s about seat z for 1 s
    # in seat axes the seat pan carries the weight along seat z whichever way the seat has turned
    assert got["seat_pan_fz_N"].mean() > 0.5 * human.mass_kg * 9.81
    assert abs(got["seat_pan_fy_N"].mean()) < 0.1 * got["seat_pan_fz_N"].mean()


def test_rotating_seat_unit_against_a_whole_drive(rotating_unit):
    # SeatedHuman.simulate of a rotating drive takes the angle accelerations by central differences over the whole
    # drive; the unit, which sees no future inputs, by backward differences.  Over 2 s of SYNTHETIC roll and
    # pitch motion they agree closely (head and pelvis accelerations within 2 % of their rms; measured 1.1 % at the
    # 1 ms step: the backward difference lags by half a step).
    unit, human = rotating_unit
    dt = human.model.mj.opt.timestep
    n = int(round(2.0 / dt)) + 1
    t = np.arange(n) * dt
    acc = np.column_stack([0.5 * np.sin(2 * np.pi * 1.1 * t), 0.4 * np.sin(2 * np.pi * 0.7 * t), np.zeros(n)])
    w = np.column_stack([0.3 * np.sin(2 * np.pi * 0.9 * t), 0.2 * np.sin(2 * np.pi * 1.3 * t), np.zeros(n)])
    whole = human.simulate(ehm.SeatMotion(t, acc, "SYNTHETIC roll and pitch", angvel_radps=w), method="nonlinear")
    ref = _rotating_reference(human, acc, w)
    for p in ("head", "pelvis"):
        a, b = whole.point(p).acc_mps2, ref.point(p).acc_mps2
        assert np.sqrt(np.mean((a - b) ** 2)) < 0.02 * np.sqrt(np.mean(a ** 2)), p


def test_rotating_seat_unit_refuses_bad_rates(rotating_unit, capfd):
    unit, _ = rotating_unit
    s = _slave(unit)
    try:
        _start(s)
        h = s_dt(unit)
        s.setReal([VR["seat_wz_radps"]], [float("nan")])
        with pytest.raises(FMICallException) as exc:
            s.doStep(currentCommunicationPoint=0.0, communicationStepSize=h)
        assert _status(exc) == DISCARD and "not a seat angular velocity" in capfd.readouterr().out
        s.setReal([VR["seat_wz_radps"]], [0.5])
        s.doStep(currentCommunicationPoint=0.0, communicationStepSize=h)  # a turning seat is fine
    finally:
        s.terminate()
        s.freeInstance()
