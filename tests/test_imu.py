"""IMU logs: ehm.from_imu on SYNTHETIC rotating-seat drives whose true seat motion is known.

Every log here is SYNTHETIC, generated in the test: a drive's seat motion (ehm.inputs.drives or the turning drive
below) and what an IMU fixed to the seat would log for it."""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest
from scipy import signal
from scipy.spatial.transform import Rotation

import ehm
from ehm.errors import InputError
from ehm.inputs.drives import city_drive, rough_road
from ehm.inputs.motion import SeatMotion, integrate_attitude, seat_kinematics, seat_rotation_matrices

pytest.importorskip("imufusion")

G = 9.80665
BIAS_DEG_S = np.array([0.3, -0.2, 0.25])


def rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def imu_of(truth, mounting: Rotation, seed: int = 0, R=None, bias_deg_s=BIAS_DEG_S, gyro_noise_deg_s=0.02):
    """What an IMU fixed to the seat (turned by ``mounting``) would log: specific force f = a - R^T g and gyro
    rates, with a gyro bias (default 0.3, -0.2, 0.25 deg/s: constant, or an (n, 3) array), gyro noise
    (0.02 deg/s) and accelerometer noise (0.01 m/s^2), in the sensor's axes.  The true attitude R comes from
    the drive's own rates (seat_kinematics) unless given."""
    rng = np.random.default_rng(seed)
    if R is None:
        R = seat_rotation_matrices(seat_kinematics(truth.time_s, truth.angvel_radps).angles_rad)
    f = truth.acc_mps2 - np.einsum("nji,j->ni", R, np.array([0.0, 0.0, -G]))
    f += 0.01 * rng.standard_normal(f.shape)
    w = truth.angvel_radps + np.radians(bias_deg_s) + np.radians(gyro_noise_deg_s) * rng.standard_normal(f.shape)
    return mounting.inv().apply(f), mounting.inv().apply(w), f


def turning_start_drive(duration_s: float = 60.0, dt: float = 0.01, speed: float = 27.8, seed: int = 0):
    """A SYNTHETIC motorway drive that is already moving at t = 0, in a corner: 27.8 m/s with a yaw rate of
    2.5 deg/s (lateral acceleration 1.2 m/s^2) for the first 10 s, eased out over 3 s, then straight with a
    lane change at 35 s; the body rolls 0.5 deg per m/s^2 (outward); light vertical vibration.  Returns the
    seat motion and the true seat -> world rotation matrices (the roll at t = 0 is that of the corner)."""
    t = np.arange(0.0, duration_s + dt / 2, dt)
    ease = np.clip((t - 10.0) / 3.0, 0.0, 1.0)
    yaw_rate = np.radians(2.5) * (1.0 - (3 * ease ** 2 - 2 * ease ** 3))
    lane = np.exp(-0.5 * ((t - 35.0) / 0.8) ** 2) - np.exp(-0.5 * ((t - 37.0) / 0.8) ** 2)
    yaw_rate = yaw_rate + np.radians(3.0) * lane
    ay = speed * yaw_rate
    roll = np.radians(0.5) * ay  # rolls outward: right (negative) in a left turn... sign as city_drive: + with ay
    pitch = np.zeros_like(t)
    yaw = np.concatenate([[0.0], np.cumsum(0.5 * (yaw_rate[1:] + yaw_rate[:-1]) * dt)])
    droll = np.gradient(roll, dt)
    wx = droll - yaw_rate * np.sin(pitch)
    wy = yaw_rate * np.cos(pitch) * np.sin(roll)
    wz = yaw_rate * np.cos(pitch) * np.cos(roll)
    rng = np.random.default_rng(seed)
    band = signal.butter(4, (0.5, 15.0), btype="band", fs=1 / dt, output="sos")
    az = signal.sosfiltfilt(band, rng.standard_normal(t.size))
    az *= 0.15 / rms(az)
    R = Rotation.from_euler("ZYX", np.column_stack([yaw, pitch, roll])).as_matrix()
    truth = SeatMotion(t, np.column_stack([np.zeros_like(t), ay, az]), "SYNTHETIC turning start",
                       np.column_stack([wx, wy, wz]))
    return truth, R


@pytest.fixture(scope="module")
def drive():
    # 120 s of the SYNTHETIC city drive: 2-3.5 m/s^2 manoeuvres, body roll 0.5 deg and pitch 0.6 deg per m/s^2
    return city_drive(120.0, seed=0)


def test_from_imu_recovers_fore_aft_and_lateral_acceleration(drive):
    """Within 3 % rms (the issue's target; measured 1.0 % fore-aft, 1.2 % lateral with the bias and noise
    above).  Ignoring the attitude leaves gravity in them: g sin(0.6 deg/(m/s^2)) = 10.3 % of the fore-aft and
    g sin(0.5 deg/(m/s^2)) = 8.6 % of the lateral acceleration, the drive's pitch and roll gradients."""
    mounting = Rotation.from_euler("zx", [90.0, 180.0], degrees=True)  # sensor turned and upside down
    f_sensor, w_sensor, f_seat = imu_of(drive, mounting)
    m = ehm.from_imu(drive.time_s, f_sensor, w_sensor, mounting=mounting)
    for j, (expected_leak, name) in enumerate(((G * np.sin(np.radians(0.6)), "fore-aft"),
                                               (G * np.sin(np.radians(0.5)), "lateral"))):
        truth = drive.acc_mps2[:, j]
        assert rms(m.acc_mps2[:, j] - truth) < 0.03 * rms(truth), name
        naive = f_seat[:, j] - (0.0 if j < 2 else G)  # no attitude: gravity assumed along seat z
        assert rms(naive - truth) / rms(truth) == pytest.approx(expected_leak, abs=0.01), name
    # the angular velocity comes back in seat axes without the bias (noise 0.02 deg/s remains)
    assert rms(m.angvel_radps - drive.angvel_radps) < np.radians(0.03)
    assert "gyro bias 0.4" in m.description and "rest at" in m.description
    assert "gravity-aided filter" in m.description


def test_drive_that_starts_moving_in_a_corner():
    """SYNTHETIC: the log starts at 27.8 m/s in a 2.5 deg/s corner (the tester's case).  The old method took
    the first second as rest: the corner's yaw rate became 'gyro bias' and the tilt of the specific force
    (7 deg) the seat's roll, so the lateral acceleration was off by about 1 m/s^2.  Now the bias comes from
    the straight part (rests anywhere) and the filter runs from the whole log: within 0.05 m/s^2 rms."""
    truth, R = turning_start_drive()
    f, w, _ = imu_of(truth, Rotation.identity(), R=R)
    m = ehm.from_imu(truth.time_s, f, w)
    err = m.acc_mps2[:, :2] - truth.acc_mps2[:, :2]
    assert rms(np.linalg.norm(err, axis=1)) < 0.05
    assert rms(m.angvel_radps - truth.angvel_radps) < np.radians(0.05)  # the corner's yaw rate is kept
    assert "rest at" in m.description and "0.0-" not in m.description.split("rest at")[1][:5]


def test_long_drive_does_not_drift():
    """SYNTHETIC 20 min city drive at 50 Hz whose gyro bias drifts from (0.3, -0.2, 0.25) deg/s to twice that
    (warming up), with noise.  Gyro-only integration with the bias of the first rest drifts by tens of
    degrees; with the bias interpolated between the rests and the filter, the seat's tilt error stays within
    1 deg (horizontal acceleration error below g sin 1 deg = 0.17 m/s^2 at every sample, apart from the
    0.01 m/s^2 accelerometer noise; measured 0.16 m/s^2 at most, 0.04 rms)."""
    truth = city_drive(1200.0, seed=3, dt_s=0.02)
    n = truth.time_s.size
    bias = np.outer(1.0 + truth.time_s / truth.time_s[-1], BIAS_DEG_S)
    R = seat_rotation_matrices(seat_kinematics(truth.time_s, truth.angvel_radps).angles_rad)
    f, w, _ = imu_of(truth, Rotation.identity(), R=R, bias_deg_s=bias)
    m = ehm.from_imu(truth.time_s, f, w)
    err = np.linalg.norm(m.acc_mps2[:, :2] - truth.acc_mps2[:, :2], axis=1)
    assert err.max() < G * np.sin(np.radians(1.0)) + 0.03
    assert rms(err) < 0.06
    assert "interpolated between the rests" in m.description
    # gyro-only, with the mean rate of the first second removed (the old method): drifts
    first = truth.time_s <= 1.0
    q = integrate_attitude(truth.time_s, w - w[first].mean(axis=0))
    up_est = Rotation.from_quat(q).inv().apply([0.0, 0.0, 1.0])
    tilt_err = np.degrees(np.arccos(np.clip(np.sum(up_est * R[:, 2, :], axis=1), -1, 1)))
    assert tilt_err.max() > 20.0
    assert n == f.shape[0]


def test_accelerometer_only_log_is_levelled():
    """SYNTHETIC board lying tilted (3 deg pitch, 2 deg roll, like a board on a bus floor) on a straight rough
    road: no gyro.  Levelled with the static tilt of its quietest part, the seat taken as not rotating: the
    horizontal acceleration comes back within 2 % of the vertical's rms (the tilt gone), with a warning."""
    truth = rough_road(30.0, speed_mps=15.0, road_class="B", seed=0)
    tilt = Rotation.from_euler("yx", [3.0, 2.0], degrees=True)  # sensor -> seat
    f_seat = truth.acc_mps2 + np.array([0.0, 0.0, G])
    f_sensor = tilt.inv().apply(f_seat)
    with pytest.warns(UserWarning, match="without gyro rates the seat is taken as not rotating"):
        m = ehm.from_imu(truth.time_s, f_sensor, None)
    assert m.angvel_radps is None
    level = tilt.apply(np.array(m.acc_mps2))  # back in seat axes
    assert rms(level[:, :2]) < 0.02 * rms(truth.acc_mps2[:, 2])
    assert rms(m.acc_mps2[:, 2] - truth.acc_mps2[:, 2]) < 0.01 * rms(truth.acc_mps2[:, 2]) + 0.01
    assert "no gyro: levelled with the static tilt" in m.description
    # without levelling the tilt would leave g sin 3 deg = 0.51 m/s^2 in x
    assert abs(np.mean(f_sensor[:, 0])) > 0.4


def test_gyro_in_deg_per_s_read_as_rad_per_s_is_refused(drive):
    """SYNTHETIC: the city drive's corners (up to 67 deg/s of yaw) read as rad/s are caught by their size;
    a straight rough road's small roll and pitch rates by the tilt gravity's direction does not show."""
    f, w, _ = imu_of(drive, Rotation.identity())
    with pytest.raises(InputError, match=r"probably in deg/s, not read in rad/s, as no unit is given: give the gyro's "
                                         r"unit \(e\.g\. units=\{'wx': 'deg/s'"):
        ehm.from_imu(drive.time_s, f, np.degrees(w))
    road = rough_road(30.0, speed_mps=20.0, road_class="C", seed=1)
    f, w, _ = imu_of(road, Rotation.identity())
    second = np.convolve(np.linalg.norm(np.degrees(w), axis=1), np.ones(200) / 200, mode="valid")
    assert second.max() < 10.0  # not caught by size: below 10 (deg/s read as rad/s) over every second
    with pytest.raises(InputError, match=r"read in rad/s, as no unit is given, the gyro tilts the seat by \d+ deg rms "
                                         r"per second more than gravity's direction shows.*units=\{'wx': 'deg/s'"):
        ehm.from_imu(road.time_s, f, np.degrees(w))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ehm.from_imu(road.time_s, f, w)  # in rad/s it passes


def test_roll_and_pitch_limits():
    """SYNTHETIC: a seat that rolls to 60 deg at 20-25 s, and an IMU pitched 60 deg whose mounting is not
    given, are refused with the time and a hint; max_tilt_deg lets them through."""
    dt = 0.01
    t = np.arange(0.0, 40.0 + dt / 2, dt)
    ramp = np.clip((t - 20.0) / 5.0, 0.0, 1.0)
    roll = np.radians(60.0) * (3 * ramp ** 2 - 2 * ramp ** 3)
    truth = SeatMotion(t, np.zeros((t.size, 3)), "SYNTHETIC rolling seat",
                       np.column_stack([np.gradient(roll, dt), np.zeros_like(t), np.zeros_like(t)]))
    R = Rotation.from_rotvec(np.outer(roll, [1.0, 0.0, 0.0])).as_matrix()
    f, w, _ = imu_of(truth, Rotation.identity(), R=R)
    with pytest.raises(InputError, match=r"at t = 2\d\.\d s the seat is rolled 45 deg, more than the 45 deg a seat "
                                         r"plausibly tilts: perhaps the IMU is not fixed.*; if the seat does tilt so "
                                         r"\(up to 60 deg in this log\), allow it with max_tilt_deg=65 \(read_motion: "
                                         r"imu_options=\{'max_tilt_deg': 65\}\) \(beyond about 30 deg the body model's "
                                         r"unbelted person slides off the seat and the run stops\)\.$"):
        ehm.from_imu(t, f, w)
    from ehm.inputs.vocabulary import command_line

    with command_line(), pytest.raises(InputError, match=r"not in rad/s \(taken as rad/s: in deg/s give --unit "
                                                         r"wx=deg/s --unit wy=deg/s --unit wz=deg/s\); if the seat "
                                                         r"does tilt so \(up to 60 deg in this log\), allow it with "
                                                         r"--max-tilt 65 \(beyond about 30"):
        ehm.from_imu(t, f, w)
    m = ehm.from_imu(t, f, w, max_tilt_deg=70.0)
    assert rms(m.acc_mps2[:, :2]) < 0.1
    truth = city_drive(60.0, seed=2)
    mounting = Rotation.from_euler("y", 60.0, degrees=True)
    f, w, _ = imu_of(truth, mounting)
    with pytest.raises(InputError, match=r"at t = 0\.0 s the seat is pitched -?60 deg.*mounting \(sensor axes -> "
                                         r"seat axes\) is not given"):
        ehm.from_imu(truth.time_s, f, w)
    m = ehm.from_imu(truth.time_s, f, w, mounting=mounting)
    assert rms(m.acc_mps2[:, 0] - truth.acc_mps2[:, 0]) < 0.03 * rms(truth.acc_mps2[:, 0])


def test_messages_name_no_internals(drive):
    """No message from_imu can give names the sickness model's or the simulation's internals."""
    f, w, _ = imu_of(drive, Rotation.identity())
    messages = []
    for args in ((f * 1e3, w), (f, np.degrees(w)), (f[:, [2, 1, 0]], w)):
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                ehm.from_imu(drive.time_s, *args)
            messages += [str(c.message) for c in caught]
        except InputError as exc:
            messages.append(str(exc))
    assert len(messages) == 3
    for text in messages:
        assert "dt_s" not in text and "simulation." not in text


def test_read_motion_imu_log_in_g_and_deg_per_s(drive, tmp_path):
    f_sensor, w_sensor, _ = imu_of(drive, Rotation.identity())
    df = pd.DataFrame({"t": drive.time_s, **{f"acc{a}": f_sensor[:, j] / G for j, a in enumerate("XYZ")},
                       **{f"gyr{a}": np.degrees(w_sensor[:, j]) for j, a in enumerate("XYZ")}})
    path = tmp_path / "imu.parquet"
    df.to_parquet(path)
    names = {"time": "t", "ax": "accX", "ay": "accY", "az": "accZ", "wx": "gyrX", "wy": "gyrY", "wz": "gyrZ"}
    units = {**{k: "g" for k in ("ax", "ay", "az")}, **{k: "deg/s" for k in ("wx", "wy", "wz")}}
    m = ehm.read_motion(path, names, units, imu=True)
    assert rms(m.acc_mps2[:, 1] - drive.acc_mps2[:, 1]) < 0.03 * rms(drive.acc_mps2[:, 1])
    assert m.description.startswith("IMU log from imu.parquet")
    # the same log without its units: the accelerometers in g are caught
    with pytest.raises(InputError, match=r"the accelerometers read 1.01 m/s\^2 for gravity .*units=\{'ax': 'g'"):
        ehm.read_motion(path, names, {k: "deg/s" for k in ("wx", "wy", "wz")}, imu=True)


def test_from_imu_bad_input_is_one_sentence(drive):
    f, w, _ = imu_of(drive, Rotation.identity())
    with pytest.raises(InputError, match="mounting must be a proper 3x3 rotation matrix"):
        ehm.from_imu(drive.time_s, f, w, mounting=np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(InputError, match=r"specific_force_mps2 must have shape \(n, 3\)"):
        ehm.from_imu(drive.time_s, f[:, :2], w)
    with pytest.raises(InputError, match=r"max_tilt_deg must be a positive number"):
        ehm.from_imu(drive.time_s, f, w, max_tilt_deg=-1)
    # a gyro that is never quiet: no rest, said in one sentence
    spinning = w + np.radians([0.0, 0.0, 20.0])
    with pytest.warns(UserWarning, match=r"no rest of 2 s or more found"):
        m = ehm.from_imu(drive.time_s, f, spinning)
    assert "no rest of 2 s found" in m.description


def test_an_accelerometer_only_imu_log_reads_through_read_motion():
    # SYNTHETIC board tilted 3 deg about x on a rough road, no gyro: the three rates left out (wx= wy= wz=)
    import pandas as pd

    from ehm import read_motion

    rng = np.random.default_rng(5)
    t = np.arange(0.0, 60.0, 0.01)
    tilt = np.radians(3.0)
    gravity_in_sensor = 9.80665 * np.array([0.0, np.sin(tilt), np.cos(tilt)])
    f = gravity_in_sensor + 0.2 * rng.standard_normal((t.size, 3))
    frame = pd.DataFrame({"time_s": t, "ax_mps2": f[:, 0], "ay_mps2": f[:, 1], "az_mps2": f[:, 2]})
    with pytest.warns(UserWarning):
        m = read_motion(frame, channels={"wx": None, "wy": None, "wz": None}, imu=True)
    assert m.angvel_radps is None
    assert np.abs(m.acc_mps2.mean(axis=0)).max() < 0.05  # levelled: gravity and the tilt taken out
    with pytest.raises(ehm.InputError, match="leave out all three angular velocities"):
        read_motion(frame, channels={"wx": None}, imu=True)


def test_imu_options_reach_the_imu_route_from_read_motion_and_the_command_line(tmp_path, capsys):
    # SYNTHETIC IMU resting 50 deg rolled (beyond the default 45 deg limit), gyro quiet
    import pandas as pd

    from ehm import read_motion
    from ehm.interfaces.cli import main

    rng = np.random.default_rng(2)
    t = np.arange(0.0, 20.0, 0.01)
    roll = np.radians(50.0)
    f = 9.80665 * np.array([0.0, np.sin(roll), np.cos(roll)]) + 0.02 * rng.standard_normal((t.size, 3))
    w = 0.001 * rng.standard_normal((t.size, 3))
    frame = pd.DataFrame({"time_s": t, **{f"a{c}_mps2": f[:, j] for j, c in enumerate("xyz")},
                          **{f"w{c}_radps": w[:, j] for j, c in enumerate("xyz")}})
    with pytest.raises(ehm.InputError, match="roll"):
        read_motion(frame, imu=True)
    m = read_motion(frame, imu=True, imu_options={"max_tilt_deg": 60.0})
    assert np.abs(m.acc_mps2.mean(axis=0)).max() < 0.05
    with pytest.raises(ehm.InputError, match="not an option of the IMU route"):
        read_motion(frame, imu=True, imu_options={"tilt": 60.0})
    path = tmp_path / "imu.csv"
    frame.to_csv(path, index=False)
    out = tmp_path / "run"
    assert main(["simulate", "--motion", str(path), "--imu", "--out", str(out)]) == 2
    assert "roll" in capsys.readouterr().err
    assert main(["simulate", "--motion", str(path), "--imu", "--max-tilt", "60", "--rest", "1", "--out", str(out)]) == 0


def test_a_too_short_rest_is_refused_and_a_sparse_log_has_no_rest_to_find():
    # SYNTHETIC IMU at rest; before, rest_s of 1 ms (no window holds 2 samples) crashed the rest search
    rng = np.random.default_rng(6)
    t = np.arange(0.0, 20.0, 0.01)
    f = np.array([0.0, 0.0, 9.80665]) + 0.05 * rng.standard_normal((t.size, 3))
    w = 0.001 * rng.standard_normal((t.size, 3))
    with pytest.raises(ehm.InputError, match=r"rest_s \(--rest\) = 0.001 s; .* 0.5 s or more"):
        ehm.from_imu(t, f, w, rest_s=0.001)
    sparse = np.arange(0.0, 30.0, 1.0)  # one sample a second: a 2 s window holds 2 samples at most
    fs = np.array([0.0, 0.0, 9.80665]) + 0.05 * rng.standard_normal((sparse.size, 3))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = ehm.from_imu(sparse, fs, 0.001 * rng.standard_normal((sparse.size, 3)), rest_s=0.5)
    assert m.n_samples == sparse.size


def test_rests_are_found_when_a_rocking_mount_shortens_the_mean_specific_force():
    """SYNTHETIC phone on a rocking dash mount: while driving, the specific force (norm g) swings +-15 deg at
    1 Hz, so the norm of its mean over a 2 s window is g J0(0.26 rad) = 0.983 g; 60 s of that, then 20 s
    standing still with a gyro bias of 0.7 deg/s.  The gravity level at rest used to be the 10th percentile of
    those window norms (0.983 g), and the true rest, 1.7 % above it, was not found (a real 10 Hz iPhone drive
    had 90 s of stops and no rest found).  Now it is the median over steady, quiet windows: the rest is found
    and its bias measured."""
    t = np.arange(0.0, 80.0, 0.01)
    moving = t < 60.0
    phi = np.where(moving, np.radians(15.0) * np.sin(2 * np.pi * 1.0 * t), 0.0)
    f = G * np.column_stack([np.sin(phi), np.zeros_like(t), np.cos(phi)])
    w = np.zeros((t.size, 3))
    w[:, 1] = np.gradient(phi, t)
    w += np.radians([0.7, 0.0, 0.0])
    level = np.linalg.norm(ehm.inputs.attitude._window_stats(t, f, 2.0)[2], axis=1)
    assert np.percentile(level, 10) < 0.985 * G  # the old level: the rest lies outside its 1 % band
    rest = ehm.inputs.attitude.find_rests(t, f, w, 2.0)
    assert rest is not None
    assert rest.stretches[0].t0 >= 59.0 and rest.stretches[-1].t1 > 79.0
    np.testing.assert_allclose(np.degrees(rest.rate_radps[0]), [0.7, 0.0, 0.0], atol=1e-9)
    assert rest.gravity_mps2 == pytest.approx(G, rel=1e-9)


def test_the_simulated_seat_tilts_as_the_filtered_attitude_not_as_the_gyro_alone():
    """SYNTHETIC 20 min city drive, gyro bias doubling over the drive: the motion's angular velocity, integrated
    from the true start as the rotating seat does, keeps the seat's tilt within 1.5 deg of the truth (measured
    1.0 deg; the bias-corrected gyro alone, as before: 4.7 deg), and the rates themselves stay within
    0.03 deg/s rms of the truth (the gyro's 0.02 deg/s noise passes, as its vibration would)."""
    truth = city_drive(1200.0, seed=3, dt_s=0.02)
    bias = np.outer(1.0 + truth.time_s / truth.time_s[-1], BIAS_DEG_S)
    R = seat_rotation_matrices(seat_kinematics(truth.time_s, truth.angvel_radps).angles_rad)
    f, w, _ = imu_of(truth, Rotation.identity(), R=R, bias_deg_s=bias)
    m = ehm.from_imu(truth.time_s, f, w)
    q = integrate_attitude(truth.time_s, m.angvel_radps, Rotation.from_matrix(R[0]).as_quat())
    up = Rotation.from_quat(q).inv().apply([0.0, 0.0, 1.0])
    tilt_err = np.degrees(np.arccos(np.clip(np.sum(up * R[:, 2, :], axis=1), -1, 1)))
    assert tilt_err.max() < 1.5
    assert rms(m.angvel_radps - truth.angvel_radps) < np.radians(0.03)


def test_a_gyro_that_misses_the_tilt_from_rest_to_rest_makes_the_filter_lean_on_gravity():
    """SYNTHETIC: 10 s at rest, 30 s of driving (1 m/s^2 fore-aft at 0.3 Hz, the seat level), 10 s at rest.  A
    good gyro (1.5 deg/s noise while driving) carries the tilt from one rest to the next within 0.35 deg per
    square root of a second; one with an extra 0.3 deg/s while driving (as a 10 Hz phone gyro on a vibrating
    mount, measured 1.1) misses it by 9 deg, 1.6 deg/sqrt(s), so the filter leans on gravity (gain 0.1, rejection
    10 deg) and says why.  On a real iPhone drive at 10 Hz this brought the horizontal acceleration from 1.10 to
    0.73 m/s^2 rms off the car's own CAN-bus accelerometer."""
    rng = np.random.default_rng(8)
    t = np.arange(0.0, 50.0, 0.02)
    driving = (t >= 10.0) & (t < 40.0)
    f = np.tile([0.0, 0.0, G], (t.size, 1))
    f[:, 0] += np.where(driving, 1.0 * np.sin(2 * np.pi * 0.3 * (t - 10.0)), 0.0)
    good = np.radians(1.5) * rng.standard_normal((t.size, 3)) * driving[:, None]
    bad = good + np.radians([0.3, 0.0, 0.0]) * driving[:, None]
    rest = ehm.inputs.attitude.find_rests(t, f, good, 2.0)
    assert rest is not None and len(rest.stretches) == 2
    assert ehm.inputs.imu.gyro_drift(t, f, good, rest) < 0.35
    assert ehm.inputs.imu.gyro_drift(t, f, bad, rest) == pytest.approx(9.0 / np.sqrt(30.0), rel=0.2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no warning for the good gyro
        m = ehm.from_imu(t, f, good)
    assert "gain 0.05, acceleration rejection 5 deg" in m.description
    with pytest.warns(UserWarning, match=r"the gyro cannot carry the seat's attitude through manoeuvres, so the "
                                         r"attitude leans on gravity .* because its rates, integrated from one rest "
                                         r"to the next, miss the next rest's tilt by 1\.[4-9].*; it is noisy"):
        m = ehm.from_imu(t, f, bad)
    assert "gain 0.1, acceleration rejection 10 deg" in m.description and "a weak gyro" in m.description


def test_the_angular_velocity_keeps_the_gyros_vibration():
    """SYNTHETIC 100 Hz IMU: 10 s at rest, 10 s of a 20 Hz roll vibration (rates of 10 deg/s amplitude), 10 s
    at rest: the seat's angular velocity carries the vibration within 1 % rms (taken as the mean of the
    attitude's steps, it lost 24 %)."""
    t = np.arange(0.0, 30.0, 0.01)
    shaking = (t >= 10.0) & (t < 20.0)
    w = np.zeros((t.size, 3))
    w[:, 0] = np.where(shaking, np.radians(10.0) * np.sin(2 * np.pi * 20.0 * t), 0.0)
    roll = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:, 0] + w[:-1, 0]) * np.diff(t))])
    f = G * np.column_stack([np.zeros_like(t), np.sin(roll), np.cos(roll)])
    m = ehm.from_imu(t, f, w)
    k = shaking
    assert rms(m.angvel_radps[k, 0] - w[k, 0]) < 0.01 * rms(w[k, 0])
