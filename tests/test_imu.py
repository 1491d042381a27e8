"""IMU logs: ehm.from_imu on a SYNTHETIC rotating-seat drive whose true seat motion is known."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

import ehm
from ehm.drives import city_drive
from ehm.errors import InputError
from ehm.motion import seat_kinematics, seat_rotation_matrices

G = 9.80665


def rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def imu_of(truth, mounting: Rotation, seed: int = 0):
    """What an IMU fixed to the seat (turned by ``mounting``) would log: specific force f = a - R^T g and gyro
    rates, with a gyro bias (0.3, -0.2, 0.25 deg/s), gyro noise (0.02 deg/s) and accelerometer noise (0.01
    m/s^2), in the sensor's axes.  The true attitude R comes from the drive's own rates (seat_kinematics)."""
    rng = np.random.default_rng(seed)
    R = seat_rotation_matrices(seat_kinematics(truth.time_s, truth.angvel_radps).angles_rad)
    f = truth.acc_mps2 - np.einsum("nji,j->ni", R, np.array([0.0, 0.0, -G]))
    f += 0.01 * rng.standard_normal(f.shape)
    w = truth.angvel_radps + np.radians([0.3, -0.2, 0.25]) + np.radians(0.02) * rng.standard_normal(f.shape)
    return mounting.inv().apply(f), mounting.inv().apply(w), f


@pytest.fixture(scope="module")
def drive():
    # 120 s of the SYNTHETIC city drive: 2-3.5 m/s^2 manoeuvres, body roll 0.5 deg and pitch 0.6 deg per m/s^2,
    # starting with 2 s without manoeuvres (the rest from_imu needs)
    return city_drive(120.0, seed=0)


def test_from_imu_recovers_fore_aft_and_lateral_acceleration(drive):
    """Within 3 % rms (the issue's target; measured 2.4 % fore-aft, 1.6 % lateral with the bias and noise above,
    0.9-2.4 % over five noise draws: the gyro bias estimated from 1 s of noisy rest leaves a small drift).
    Ignoring the attitude leaves gravity in them: g sin(0.6 deg/(m/s^2)) = 10.3 % of the fore-aft and
    g sin(0.5 deg/(m/s^2)) = 8.6 % of the lateral acceleration, the drive's pitch and roll gradients (the 0.15 s
    lag of the body's tilt lowers that slightly; measured 10.2 % and 8.6 %)."""
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
    assert "gyro bias" in m.description


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
    # the same log without its units: the rest check catches the accelerometers in g
    with pytest.raises(InputError, match=r"the specific force over the first 1 s is 1 m/s\^2, not about 9\.80665"):
        ehm.read_motion(path, names, {k: "deg/s" for k in ("wx", "wy", "wz")}, imu=True)


def test_from_imu_bad_input_is_one_sentence(drive):
    f, w, _ = imu_of(drive, Rotation.identity())
    spinning = w + np.radians([0.0, 0.0, 20.0])
    with pytest.raises(InputError, match=r"the gyro turns at 20\.\d deg/s over the first 1 s"):
        ehm.from_imu(drive.time_s, f, spinning)
    with pytest.raises(InputError, match="mounting must be a proper 3x3 rotation matrix"):
        ehm.from_imu(drive.time_s, f, w, mounting=np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(InputError, match=r"specific_force_mps2 must have shape \(n, 3\)"):
        ehm.from_imu(drive.time_s, f[:, :2], w)
    with pytest.raises(InputError, match=r"must be longer than its rest at the start"):
        ehm.from_imu(drive.time_s[:50], f[:50], w[:50])
