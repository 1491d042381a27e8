"""Issue 32, items 3-5: poses from every route, one set of defaults, progress that fits where it goes.

Every drive here is SYNTHETIC (ehm.random_vibration, ehm.drives.city_drive, labelled so by their descriptions)."""

from __future__ import annotations

import inspect

import numpy as np
import pandas as pd
import pytest

import ehm
from ehm.cli import main
from ehm.cli import progress as cli_progress
from ehm.cli.parser import build_parser
from ehm.routes.hybrid import LinearRouteWarning
from ehm.imu import mounting_matrix
from ehm.readers import mounting_rotation, read_motion


@pytest.fixture(scope="module")
def human():
    h = ehm.SeatedHuman()
    h.linear_model()
    return h


def _write_drive(path, motion):
    pd.DataFrame({"time_s": motion.time_s, "ax_mps2": motion.acc_mps2[:, 0], "ay_mps2": motion.acc_mps2[:, 1],
                  "az_mps2": motion.acc_mps2[:, 2]}).to_csv(path, index=False)


# --- 3. poses from every route ----------------------------------------------------------------------------------

def test_simulate_with_defaults_then_animate_writes_a_gif(tmp_path, capsys):
    """Issue 32: `ehm simulate --motion log.csv --out run` (default route: hybrid) followed by `ehm animate run --out
    run.gif` failed, because the hybrid route wrote no poses."""
    log = tmp_path / "log.csv"
    _write_drive(log, ehm.random_vibration("xyz", 3.0, 0.3, seed=1, dt_s=0.01))
    run = tmp_path / "run"
    assert main(["simulate", "--motion", str(log), "--out", str(run)]) == 0
    assert "poses.npz" in capsys.readouterr().out
    gif = tmp_path / "run.gif"
    assert main(["animate", str(run), "--out", str(gif), "--max-frames", "3"]) == 0
    assert gif.read_bytes()[:4] == b"GIF8"
    with np.load(run / "poses.npz") as poses:
        np.testing.assert_allclose(np.diff(poses["time_s"]), 0.04, atol=1e-12)  # 25 per second, as the nonlinear route


@pytest.mark.parametrize("method", ["linear", "auto"])
def test_linear_poses_agree_with_the_nonlinear_route(human, method):
    """Issue 32: the linear route's poses come from its state through the model's kinematics; on a small input
    (0.3 m/s^2 z, where no contact nears its friction limit) they agree with the nonlinear route's.

    Tolerance: 3 % of the largest segment displacement (about 1 mm here).  The linear model differs from MuJoCo's
    stepping by its linearisation (terms of second order in a displacement of a millimetre) and by its exact
    discretisation against the integrator's first-order step, which ehm.routes.hybrid measures at about 1 % of rms on the
    accelerations; measured here: 1.7 % of the displacement, orientations equal within 1e-9."""
    motion = ehm.random_vibration("z", 4.0, 0.3, seed=0)
    nl = human.simulate(motion, method="nonlinear", pose_rate_hz=25.0)
    lin = human.simulate(motion, method=method, pose_rate_hz=25.0)
    assert lin.extra["route"]["windows_s"] == []  # the linear model carried all of it
    np.testing.assert_array_equal(lin.poses["time_s"], nl.poses["time_s"])
    motion_m = np.abs(nl.poses["pos"] - nl.poses["pos"][:1]).max()
    assert motion_m > 5e-4
    assert np.abs(lin.poses["pos"] - nl.poses["pos"]).max() < 0.03 * motion_m
    dot = np.abs(np.sum(lin.poses["quat"] * nl.poses["quat"], axis=-1))
    assert dot.min() > 1 - 1e-6
    assert set(lin.poses) == set(nl.poses)  # the drawing geometry too


def test_hybrid_poses_in_a_window_are_the_nonlinear_models(human):
    """Issue 32: where the hybrid route hands a window to the nonlinear model (three-axis 1.5 m/s^2: the pads slide),
    its poses there are that model's, on the same grid of steps as the nonlinear route (a window starts off the
    grid).  Tolerance 1e-4 m: the window starts from the linear state at its start, which differs from the
    continuous nonlinear run by the linear route's own small error (3e-5 m measured)."""
    motion = ehm.random_vibration("xyz", 4.0, 1.5, seed=2)
    nl = human.simulate(motion, method="nonlinear", pose_rate_hz=25.0)
    hy = human.simulate(motion, method="auto", pose_rate_hz=25.0)
    windows = hy.extra["route"]["windows_s"]
    assert windows and any(abs(w0 / 0.04 - round(w0 / 0.04)) > 1e-6 for w0, _ in windows)
    np.testing.assert_allclose(hy.poses["time_s"], nl.poses["time_s"], atol=1e-12)
    assert np.abs(hy.poses["pos"] - nl.poses["pos"]).max() < 1e-4
    with pytest.warns(LinearRouteWarning):  # the linear route keeps its own poses there, on the grid
        lin = human.simulate(motion, method="linear", pose_rate_hz=25.0)
    np.testing.assert_allclose(lin.poses["time_s"], nl.poses["time_s"], atol=1e-12)


def test_poses_on_a_turning_seat(tmp_path):
    """Issue 32: a drive that turns the seat (a person on the rotating seat, as the command line builds it): the
    linear route's world poses, the seat's frame among them, agree with the nonlinear route's (tolerance as in
    test_linear_poses_agree_with_the_nonlinear_route: 3 % of the largest displacement, 1.8e-5 m measured)."""
    t = np.arange(0.0, 4.0, 0.01)
    base = ehm.random_vibration("xyz", 4.0, 0.2, seed=4, dt_s=0.01)
    w = np.column_stack([0.05 * np.sin(2 * np.pi * 0.5 * t), 0.03 * np.sin(2 * np.pi * 0.3 * t),
                         0.2 * np.sin(2 * np.pi * 0.25 * t)])  # a seat rolling, pitching and turning
    motion = ehm.SeatMotion(t, base.acc_mps2[:t.size], "SYNTHETIC turning seat", angvel_radps=w)
    human = ehm.SeatedHuman(rotating_seat=True)
    nl = human.simulate(motion, method="nonlinear", pose_rate_hz=25.0)
    hy = human.simulate(motion, method="auto", pose_rate_hz=25.0)
    assert hy.poses["pos"].shape == nl.poses["pos"].shape  # segments and the seat frame
    motion_m = np.abs(nl.poses["pos"] - nl.poses["pos"][:1]).max()
    assert np.abs(hy.poses["pos"] - nl.poses["pos"]).max() < 0.03 * max(motion_m, 5e-4)


# --- 4. one set of defaults --------------------------------------------------------------------------------------

def test_the_same_route_by_default_everywhere(human):
    """Issue 32: SeatedHuman.simulate defaulted to the nonlinear route, ehm simulate and ehm.assess to the hybrid
    route: the same call gave different routes from Python and from the command line."""
    defaults = {f.__qualname__: inspect.signature(f).parameters["method"].default
                for f in (ehm.SeatedHuman.simulate, ehm.SeatedHuman.stream, ehm.SeatedHuman.simulate_to, ehm.assess)}
    assert set(defaults.values()) == {"auto"}, defaults
    parser = build_parser()
    for command in (["simulate", "--out", "x"], ["assess", "--motion", "city", "--out", "x"]):
        assert parser.parse_args(command).method == "auto"
    run = human.simulate(ehm.random_vibration("z", 1.0, 0.3, seed=0))
    assert run.extra["route"]["method"] == "auto"


def test_mounting_as_roll_pitch_yaw_in_degrees():
    """Issue 32: read_motion(..., mounting=(0, 90, -180)) was refused ("mounting must be a scipy Rotation or a 3x3
    rotation matrix") while --mounting=0,90,-180 is the documented way on the command line.  Exact: the same
    rotation applied to the same samples."""
    t = np.arange(0, 3.0, 0.01)
    rng = np.random.default_rng(0)
    acc = 0.3 * rng.standard_normal((t.size, 3))
    frame = pd.DataFrame({"time_s": t, "ax_mps2": acc[:, 0], "ay_mps2": acc[:, 1], "az_mps2": acc[:, 2]})
    R = mounting_rotation("0,90,-180").as_matrix()
    expected = read_motion(frame, mounting=mounting_rotation(0, 90, -180)).acc_mps2
    np.testing.assert_allclose(expected, acc @ R.T, atol=1e-12)
    for mounting in ((0, 90, -180), [0, 90, -180], np.array([0.0, 90.0, -180.0]), "0,90,-180"):
        np.testing.assert_array_equal(read_motion(frame, mounting=mounting).acc_mps2, expected)
    np.testing.assert_array_equal(mounting_matrix((0, 90, -180)), R)  # ehm.from_imu takes it the same way
    with pytest.raises(ehm.errors.InputError, match=r"give three angles ROLL,PITCH,YAW \(degrees\)"):
        read_motion(frame, mounting=(0, 90))


# --- 5. progress that fits where it goes -------------------------------------------------------------------------

def test_piped_assess_prints_no_carriage_returns(tmp_path, capsys):
    """Issue 32: piped into a file or a CI log (stderr not a terminal, as here), ehm assess printed its progress
    updates joined by carriage returns on one line."""
    log = tmp_path / "drive.csv"
    _write_drive(log, ehm.random_vibration("xyz", 12.0, 0.3, seed=3, dt_s=0.01))
    assert main(["assess", "--motion", str(log), "--out", str(tmp_path / "a")]) == 0
    out, err = capsys.readouterr()
    assert "\r" not in out + err and "a_v" in out


def test_progress_on_a_pipe_is_a_few_lines(monkeypatch, capsys):
    """Issue 32: a 342 s assessment's ~60 progress updates, piped: at most a line every 10 s of wall time, at a new
    tenth of the drive (here the updates come every 5 s: at most one line per 10 s and per tenth, 10 or fewer)."""
    clock = iter(np.arange(0.0, 1000.0, 5.0))
    monkeypatch.setattr(cli_progress.time, "monotonic", lambda: float(next(clock)))
    show = cli_progress.progress_bar("assess")
    for done in np.linspace(342 / 60, 342, 60):
        show(done, 342.0)
    err = capsys.readouterr().err
    lines = err.splitlines()
    assert "\r" not in err and 3 <= len(lines) <= 10
    assert lines[-1] == "assess: 100 % (342 / 342 s of the drive)"


def test_progress_on_a_terminal_is_a_bar(monkeypatch, capsys):
    """Issue 32: on a terminal the bar stays (rewritten in place)."""
    monkeypatch.setattr(cli_progress.sys.stderr, "isatty", lambda: True, raising=False)
    show = cli_progress.progress_bar("simulate")
    show(5.0, 10.0)
    show(10.0, 10.0)
    err = capsys.readouterr().err
    assert err.count("\r") == 2 and err.endswith("10 / 10 s\n")


def test_quiet_prints_no_progress_and_a_short_pipe_run_none(tmp_path, capsys):
    """Issue 32: --quiet on the commands that print progress; a run shorter than a progress interval prints no
    progress line on a pipe either."""
    assert cli_progress.progress_bar("simulate", quiet=True) is None
    for args in (["simulate", "--duration", "2", "--quiet"], ["simulate", "--duration", "2"]):
        assert main([*args, "--out", str(tmp_path / "run")]) == 0
        assert capsys.readouterr().err == ""
    parser = build_parser()
    for command in (["assess", "--motion", "city", "--out", "x", "-q"], ["batch", "s.toml", "--out", "x", "-q"],
                    ["fit", "--data", "d.csv", "--out", "f.toml", "--quiet"]):
        assert parser.parse_args(command).quiet


def test_library_calls_print_nothing_unless_asked(human, capsys):
    """Issue 32: library calls print nothing unless given progress=."""
    motion = ehm.random_vibration("z", 2.0, 0.3, seed=0)
    ehm.assess(motion, human)
    assert capsys.readouterr() == ("", "")
    seen = []
    human.simulate(motion, progress=lambda done, total: seen.append(done))
    assert seen and seen[-1] == pytest.approx(2.0)
