"""Log layouts read with options only (ehm.inputs.readers.layout): headerless text, a column of time since the previous
row, held samples, irregular time stamps, a gyro in a file of its own, sign flips, the sensor's mounting, a cut.

Every log here is SYNTHETIC, made by the tests in the layouts real loggers write (a phone app writing
``x y z delay_ms`` rows without a header at 200 Hz from a sensor of about 51 Hz; an Android logger writing the
accelerometer and the gyro to two files with ``uptimeNanos`` time stamps).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import ehm
from ehm.errors import EhmWarning, InputError
from ehm.inputs.imu import mounting_matrix
from ehm.inputs.readers import HELD_RUN_MAX, HELD_SHARE, mounting_rotation, read_motion
from ehm.interfaces.cli import main

G = 9.80665
PHONE = {"ax": "x", "ay": "y", "az": "z", "dt": "delay_ms"}


def one_sentence(exc) -> str:
    msg = str(exc.value)
    assert msg.endswith(".") and "\n" not in msg and exc.value.__cause__ is None
    return msg


def sensor(t):
    """SYNTHETIC phone acceleration [m/s^2] at times t: slow sways and a 1.5 Hz bounce (gravity taken out: a
    log with gravity is levelled by the readers, which tests/test_gravity.py checks; here the layouts alone)."""
    return np.column_stack([0.4 * np.sin(2 * np.pi * 0.3 * t), 0.3 * np.sin(2 * np.pi * 0.7 * t + 1.0),
                            0.5 * np.sin(2 * np.pi * 1.5 * t)])


def phone_log(path, duration_s=20.0, sensor_hz=51.2, seed=0, settle_s=0.0, gravity=False):
    """SYNTHETIC phone log as the app writes it: no header, ``x y z delay_ms``, a row every 4-6 ms (200 Hz), each
    row holding the sensor's latest sample (a sensor of ``sensor_hz``, so most rows repeat the one before);
    ``settle_s``: the first seconds shaken hard (the phone being put in place).  Returns the row times, the
    sensor's sample times and its samples."""
    rng = np.random.default_rng(seed)
    delay = rng.choice([4, 5, 6], size=int(duration_s * 200), p=[0.04, 0.92, 0.04]).astype(float)
    delay[0] = 0.0
    t_rows = np.cumsum(delay) / 1000.0
    t_sensor = np.arange(0.0, t_rows[-1] + 1.0, 1.0 / sensor_hz)
    samples = np.round(sensor(t_sensor) + [0, 0, G if gravity else 0] + 0.01 * rng.standard_normal((t_sensor.size, 3)),
                       3)
    if settle_s:
        samples[t_sensor < settle_s] += rng.uniform(-10.0, 10.0, (int(np.sum(t_sensor < settle_s)), 3))
    idx = np.searchsorted(t_sensor, t_rows, side="right") - 1  # the latest sample at each row
    rows = np.column_stack([samples[idx], delay])
    path.write_text("".join(f"{x:g} {y:g} {z:g} {d:g}\n" for x, y, z, d in rows))
    return t_rows, t_sensor, samples


# --------------------------------------------------------------------------
# headerless text, a column of time since the previous row, held samples
# --------------------------------------------------------------------------


def test_a_headerless_file_is_refused_without_columns_and_read_with_them(tmp_path):
    path = tmp_path / "phone.csv"
    phone_log(path)
    with pytest.raises(InputError) as exc:
        read_motion(path, channels=PHONE, units={"dt": "ms"})
    assert one_sentence(exc) == (f"{path}, line 1: the first row holds 4 numbers, not column names; for a file "
                                 "without a header row, name its columns with --columns NAME,NAME,... (columns=[...] "
                                 "in Python), e.g. --columns c1,c2,c3,c4.")
    with pytest.warns(UserWarning):
        m = read_motion(path, columns="x,y,z,delay_ms", channels=PHONE, units={"dt": "ms"})
    assert m.acc_mps2[:, 2].mean() == pytest.approx(0.0, abs=0.05)
    # the names must match the fields; a file with a header row is not read with columns
    with pytest.raises(InputError, match=r"line 1: --columns \(columns=\) names 3 columns but the row has 4 fields\."):
        read_motion(path, columns=["x", "y", "z"], channels=PHONE)
    headed = tmp_path / "headed.csv"
    headed.write_text("x y z delay_ms\n" + path.read_text())
    with pytest.raises(InputError, match="the file has a header row .*--channel KEY=NAME"):
        read_motion(headed, columns="x,y,z,delay_ms", channels=PHONE)
    with pytest.raises(InputError, match="y is named twice"):
        read_motion(path, columns="x,y,y,delay_ms", channels=PHONE)
    # a header of the default names a DataFrame is written with (0, 1, 2, ...) is a header
    frame = pd.DataFrame(np.column_stack([np.arange(5) * 0.01, np.zeros((5, 3))]))
    frame.to_csv(tmp_path / "numbered.csv", index=False)
    m = read_motion(tmp_path / "numbered.csv", channels={"time": "0", "ax": "1", "ay": "2", "az": "3"})
    assert m.n_samples == 5


def test_a_phone_log_with_held_samples_reads_at_the_sensors_own_rate(tmp_path):
    path = tmp_path / "phone.csv"
    t_rows, t_sensor, samples = phone_log(path, duration_s=20.0, sensor_hz=51.2)
    with pytest.warns(UserWarning) as record:
        m = read_motion(path, columns=["x", "y", "z", "delay_ms"], channels=PHONE, units={"dt": "ms"})
    notes = [str(r.message) for r in record]
    assert len(notes) == 2
    assert "% of the rows repeat the previous row's ax, ay, az exactly (runs of 4 rows at the median): a sensor " \
           "of about 51" in notes[0]
    assert "held in a log written at 200 Hz; the repeats are dropped" in notes[0]
    assert "the time stamps are irregular (steps from" in notes[1] and "median 20 ms" in notes[1]
    # one sample per sensor sample (not per written row), on a uniform grid at the median step
    assert m.n_samples == pytest.approx(20.0 * 50, rel=0.01)
    np.testing.assert_allclose(np.diff(m.time_s), 0.02)
    # the kept samples are the sensor's, at the rows they first appear: within one row (6 ms) of the truth
    truth = sensor(m.time_s)
    lag = np.max(np.abs(np.gradient(truth, axis=0) / 0.02), axis=0) * 0.006
    assert np.all(np.abs(m.acc_mps2 - truth).max(axis=0) < lag + 0.05)


def test_old_arguments_only_a_headerless_file_is_refused_naming_columns(tmp_path):
    # read with the arguments read_motion always had: it used to take the first row of numbers for column names
    path = tmp_path / "phone.csv"
    phone_log(path, duration_s=10.0)
    with pytest.raises(InputError) as exc:
        read_motion(path)
    assert "the first row holds 4 numbers, not column names" in one_sentence(exc) and "--columns" in str(exc.value)


def test_old_arguments_only_held_repeats_are_dropped(tmp_path):
    # read with the arguments read_motion always had: a held sensor's repeats used to be read as samples
    path = tmp_path / "phone.csv"
    phone_log(path, duration_s=10.0)
    rows = np.loadtxt(path)
    t = np.concatenate([[0.0], np.cumsum(rows[1:, 3])]) / 1000.0
    frame = pd.DataFrame({"time_s": t, "ax_mps2": rows[:, 0], "ay_mps2": rows[:, 1], "az_mps2": rows[:, 2]})
    with pytest.warns(UserWarning) as record:
        m = read_motion(frame)
    assert "a sensor of about 51" in str(record[0].message) and "irregular" in str(record[1].message)
    assert m.n_samples == pytest.approx(10.0 * 50, rel=0.01)  # not the 2000 rows written
    # the same as the log with its repeats dropped by hand (each sample at the first row that holds it)
    first_rows = np.flatnonzero(np.concatenate([[True], np.any(np.diff(rows[:, :3], axis=0) != 0, axis=1)]))
    with pytest.warns(UserWarning, match="irregular"):
        by_hand = read_motion(frame.iloc[first_rows])
    np.testing.assert_allclose(m.acc_mps2, by_hand.acc_mps2, atol=1e-12)


def test_a_column_of_time_since_the_previous_row(tmp_path):
    # SYNTHETIC: a 100 Hz log with a 'ms since the previous row' column and no time column
    path = tmp_path / "steps.csv"
    n = 300
    t = np.arange(n) * 0.01
    az = np.sin(2 * np.pi * 2 * t)
    rows = "".join(f"{10 if i else 0},0,0,{az[i]:.6f}\n" for i in range(n))
    path.write_text("step_ms,ax,ay,az\n" + rows)
    m = read_motion(path, channels={"dt": "step_ms", "ax": "ax", "ay": "ay", "az": "az"}, units={"dt": "ms"})
    np.testing.assert_allclose(m.time_s, t, atol=1e-12)
    np.testing.assert_allclose(m.acc_mps2[:, 2], az, atol=1e-6)
    bad = tmp_path / "bad.csv"
    bad.write_text("step_ms,ax,ay,az\n0,0,0,0\n10,0,0,0\n0,0,0,0\n10,0,0,0\n")
    with pytest.raises(InputError) as exc:
        read_motion(bad, channels={"dt": "step_ms", "ax": "ax", "ay": "ay", "az": "az"}, units={"dt": "ms"})
    assert one_sentence(exc) == (f"{bad}, line 4, column step_ms (channel dt): time step '0' is not positive; each "
                                 "row's time since the previous row must be > 0.")
    with pytest.raises(InputError, match="give the time channel .* or the dt channel"):
        read_motion(path, channels={"time": "step_ms", "dt": "step_ms", "ax": "ax", "ay": "ay", "az": "az"})


def test_repeats_that_are_not_a_held_sensor_are_kept():
    # SYNTHETIC: a step input (long runs of one value) and a pulse in a log of zeros: rows repeat, but not in
    # the short regular runs of a held sensor
    t = np.arange(2000) * 0.001
    step = np.where(t < 1.0, 0.0, 1.0)
    pulse = np.where((t > 0.5) & (t < 0.6), np.sin(2 * np.pi * 10 * t), 0.0)
    for az in (step, pulse):
        frame = pd.DataFrame({"time_s": t, "ax_mps2": 0 * t, "ay_mps2": 0 * t, "az_mps2": az})
        assert read_motion(frame).n_samples == t.size  # no note, no row dropped
    # a sensor at 0.8 of the written rate repeats 20 % of the rows (under HELD_SHARE): left as it is
    written = np.arange(2000) / 200.0
    held = np.floor(written * 160.0) / 160.0
    frame = pd.DataFrame({"time_s": written, "ax_mps2": np.sin(held), "ay_mps2": np.cos(held),
                          "az_mps2": np.sin(2 * held)})  # (bounded: a mean of 0.5-2 g is refused as unclear gravity)
    assert 0.1 < HELD_SHARE and HELD_RUN_MAX >= 4
    assert read_motion(frame).n_samples == written.size


# --------------------------------------------------------------------------
# a gyro in a file of its own
# --------------------------------------------------------------------------


def _android(path, t_ns, values):
    frame = pd.DataFrame({"timestamp": "14/05/2016 11:17:09", "uptimeNanos": t_ns,
                          "x": values[:, 0], "y": values[:, 1], "z": values[:, 2]})
    frame.to_csv(path, index=False)


def rates(t):
    return np.column_stack([0.2 * np.sin(2 * np.pi * 0.5 * t), 0.1 * np.cos(2 * np.pi * 0.3 * t), 0.05 * t])


def test_a_gyro_in_its_own_file_is_joined_on_the_accelerometers_time_stamps(tmp_path, capsys):
    # SYNTHETIC Android logger: accelerometer and gyro in two files, each with its own uptimeNanos (ns since boot)
    clock0 = 12_893_233_616_460
    t_acc = np.arange(0, 30.0, 0.02)
    t_gyr = np.arange(-0.013, 30.0, 0.0197)  # starts a little earlier, at its own rate
    _android(tmp_path / "acc.csv", clock0 + np.round(t_acc * 1e9).astype(np.int64), sensor(t_acc))
    _android(tmp_path / "gyro.csv", clock0 + np.round(t_gyr * 1e9).astype(np.int64), rates(t_gyr))
    channels = {"time": "uptimeNanos", "ax": "x", "ay": "y", "az": "z", "wx": "x", "wy": "y", "wz": "z"}
    m = read_motion(tmp_path / "acc.csv", gyro=tmp_path / "gyro.csv", channels=channels, units={"time": "ns"})
    t = m.time_s  # the time axis starts at 0 (the accelerometer's first sample)
    np.testing.assert_allclose(t, t_acc[: t.size], atol=1e-6)
    np.testing.assert_allclose(m.acc_mps2, sensor(t_acc[: t.size]), atol=1e-9)
    np.testing.assert_allclose(m.angvel_radps, rates(t), atol=2e-4)  # linear interpolation of the gyro
    assert "with the gyro of gyro.csv" in m.description
    # a gyro file covering much less than the accelerometer's span is another recording
    late = t_gyr[t_gyr > 10.0]
    _android(tmp_path / "late.csv", clock0 + np.round(late * 1e9).astype(np.int64), rates(late))
    with pytest.raises(InputError) as exc:
        read_motion(tmp_path / "acc.csv", gyro=tmp_path / "late.csv", channels=channels, units={"time": "ns"})
    assert ("their time stamps overlap for 19.9657 s of the 29.9901 s they span (67 %): the accelerometer's run "
            "from 0 to 29.98 s, the gyro's from 10.01 to 29.99 s after the accelerometer's first sample; "
            "ehm joins them over their common span") in one_sentence(exc)
    assert "must cover 90 % of theirs" in str(exc.value)
    # the same on the command line (2 s of the files, gravity taken out: a seat motion)
    short = t_acc < 2.0
    _android(tmp_path / "acc2.csv", clock0 + np.round(t_acc[short] * 1e9).astype(np.int64),
             sensor(t_acc[short]))
    out = tmp_path / "out"
    argv = ["simulate", "--motion", str(tmp_path / "acc2.csv"), "--gyro", str(tmp_path / "gyro.csv"), "--out",
            str(out), "--unit", "time=ns"]
    argv += [f"--channel={k}={v}" for k, v in channels.items()]
    assert main(argv) == 2  # the gyro file spans 30 s, the accelerometer's 2 s
    assert "their time stamps overlap for 1.98 s of the 30" in capsys.readouterr().err
    argv[4] = str(tmp_path / "gyro2.csv")
    keep = t_gyr < 2.0
    _android(tmp_path / "gyro2.csv", clock0 + np.round(t_gyr[keep] * 1e9).astype(np.int64), rates(t_gyr[keep]))
    assert main(argv) == 0
    assert "simulated 1.98 s" in capsys.readouterr().out


# --------------------------------------------------------------------------
# a sign flip, the sensor's mounting
# --------------------------------------------------------------------------


def _plain(t, acc, w=None):
    cols = {"time_s": t, "AccX": acc[:, 0], "AccY": acc[:, 1], "AccZ": acc[:, 2]}
    if w is not None:
        cols.update({"GyrX": w[:, 0], "GyrY": w[:, 1], "GyrZ": w[:, 2]})
    return pd.DataFrame(cols)


NAMES = {"ax": "AccX", "ay": "AccY", "az": "AccZ", "wx": "GyrX", "wy": "GyrY", "wz": "GyrZ"}


def test_a_sign_is_flipped_with_a_leading_minus(tmp_path):
    t = np.arange(0, 5.0, 0.01)
    acc, w = sensor(t), rates(t)
    m = read_motion(_plain(t, acc, w), channels={**NAMES, "ax": "-AccX", "wz": "-GyrZ"})
    np.testing.assert_allclose(m.acc_mps2, acc * [-1, 1, 1])
    np.testing.assert_allclose(m.angvel_radps, w * [1, 1, -1])
    # a column whose own name starts with '-' is taken as it is
    frame = _plain(t, acc).rename(columns={"AccY": "-AccY"})
    m = read_motion(frame, channels={"ax": "AccX", "ay": "-AccY", "az": "AccZ"})
    np.testing.assert_allclose(m.acc_mps2, acc)
    with pytest.raises(InputError, match="a time cannot change its sign"):
        read_motion(_plain(t, acc), channels={"time": "-time_s", "ax": "AccX", "ay": "AccY", "az": "AccZ"})
    # the command line: --channel ax=-AccX
    path = tmp_path / "log.csv"
    _plain(t, acc).to_csv(path, index=False)
    out = tmp_path / "out"
    assert main(["simulate", "--motion", str(path), "--channel", "ax=-AccX", "--channel", "ay=AccY", "--channel",
                 "az=AccZ", "--method", "linear", "--out", str(out)]) == 0


def test_the_mounting_turns_accelerations_and_rates_into_seat_axes(tmp_path):
    # SYNTHETIC: a sensor lying with its x axis to the seat's left (yaw 90 deg): seat x = -sensor y, seat y = sensor x
    t = np.arange(0, 5.0, 0.01)
    seat_acc, seat_w = sensor(t), rates(t)
    sensor_acc = np.column_stack([seat_acc[:, 1], -seat_acc[:, 0], seat_acc[:, 2]])
    sensor_w = np.column_stack([seat_w[:, 1], -seat_w[:, 0], seat_w[:, 2]])
    frame = _plain(t, sensor_acc, sensor_w)
    for mounting in (mounting_rotation(0, 0, 90), mounting_rotation("0,0,90"), mounting_rotation(0, 0, 90).as_matrix(),
                     mounting_rotation([0, 0, np.pi / 2], degrees=False), [0, 0, 90], (0, 0, 90), "0,0,90"):
        m = read_motion(frame, channels=NAMES, mounting=mounting)
        np.testing.assert_allclose(m.acc_mps2, seat_acc, atol=1e-12)
        np.testing.assert_allclose(m.angvel_radps, seat_w, atol=1e-12)
    with pytest.raises(InputError, match=r"mounting must be \(roll, pitch, yaw\) in degrees, a scipy Rotation"):
        read_motion(frame, channels=NAMES, mounting=[[1, 0], [0, 1]])  # (roll, pitch, yaw) as the CLI: issue 32
    with pytest.raises(InputError, match="give three angles ROLL,PITCH,YAW"):
        mounting_rotation("0,90")
    # the command line: --mounting in degrees
    path = tmp_path / "log.csv"
    _plain(t, sensor_acc).to_csv(path, index=False)
    out = tmp_path / "out"
    argv = ["simulate", "--motion", str(path), "--channel", "ax=AccX", "--channel", "ay=AccY", "--channel", "az=AccZ",
            "--mounting", "0,0,90", "--method", "linear", "--out", str(out)]
    assert main(argv) == 0


# --------------------------------------------------------------------------
# a cut
# --------------------------------------------------------------------------


def test_a_cut_comes_before_the_checks(tmp_path):
    # SYNTHETIC IMU log: the first 3 s the phone is put in place (shaken, turned), then 2.5 s at rest, then a drive
    rng = np.random.default_rng(3)
    t = np.arange(0, 12.0, 0.01)
    acc = np.column_stack([0 * t, 0 * t, G + 0 * t]) + 0.005 * rng.standard_normal((t.size, 3))
    w = 0.001 * rng.standard_normal((t.size, 3))
    settle = t < 3.0
    acc[settle] += rng.uniform(-8, 8, (settle.sum(), 3))
    w[settle] += rng.uniform(-2, 2, (settle.sum(), 3))
    drive = t >= 5.5
    acc[drive, 2] += 0.5 * np.sin(2 * np.pi * 1.5 * t[drive])
    frame = _plain(t, acc, w)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        whole = read_motion(frame, channels=NAMES, imu=True)
    assert "rest at 3.0-11.5 s" in whole.description  # the rest is found after the shaking (the level at rest: the
    assert np.abs(whole.acc_mps2[: 300]).max() > 5.0  # steady, quiet windows'), but the shaking stays in the motion

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # cut: no note, the rest found
        m = read_motion(frame, channels=NAMES, imu=True, start_s=3.0, end_s=11.0)
    assert m.time_s[0] == 0.0 and m.time_s[-1] == pytest.approx(8.0)  # the time axis starts at 0, at the cut
    assert np.abs(m.acc_mps2[: 250]).max() < 0.05  # the shaking is gone, gravity taken out
    assert np.abs(m.acc_mps2[300:, 2]).max() == pytest.approx(0.5, abs=0.03)  # the drive
    assert "cut from 3 s to 11 s" in m.description
    # a cut outside the log, or too short, is refused in one sentence
    with pytest.raises(InputError) as exc:
        read_motion(frame, channels=NAMES, start_s=20.0)
    assert one_sentence(exc) == ("DataFrame: --start 20 s (start_s) is not within the log, which lasts 11.99 s from "
                                 "its first sample.")
    with pytest.raises(InputError, match=r"--end 15 s \(end_s\) is after the end of the log, which lasts 11.99 s"):
        read_motion(frame, channels=NAMES, end_s=15.0)
    with pytest.raises(InputError, match="must be after start_s"):
        read_motion(frame, channels=NAMES, start_s=5.0, end_s=4.0)
    with pytest.raises(InputError, match="the cut from 5 s to 5.001 s holds 1 sample"):
        read_motion(frame, channels=NAMES, start_s=5.0, end_s=5.001)
    # a bad value in the cut-away part is not read; one in the kept part is named at its line in the file
    path = tmp_path / "log.csv"
    bad = frame.astype(object)
    bad.loc[10, "AccX"] = "x"
    bad.to_csv(path, index=False)
    with pytest.warns(EhmWarning, match="taken to include gravity and is levelled"):
        assert read_motion(path, channels=NAMES, start_s=1.0).n_samples == t.size - 100
    with pytest.raises(InputError, match=r"log.csv, line 12, column AccX \(channel ax\): 'x' is not a number\."):
        read_motion(path, channels=NAMES, start_s=0.05)


@pytest.mark.filterwarnings("always::ehm.errors.EhmWarning")  # the command line prints them: read on stderr
def test_the_cut_on_the_command_line_and_in_a_study_file(tmp_path, capsys):
    path = tmp_path / "phone.csv"
    phone_log(path, duration_s=12.0, settle_s=3.0, gravity=False)  # (the linear route's small inputs)
    out = tmp_path / "out"
    argv = ["simulate", "--motion", str(path), "--columns", "x,y,z,delay_ms", "--channel", "ax=x", "--channel",
            "ay=y", "--channel", "az=z", "--channel", "dt=delay_ms", "--unit", "dt=ms", "--start", "3.5",
            "--method", "linear", "--out", str(out)]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert "ehm: warning:" in err and "a sensor of about 51" in err and "the time stamps are irregular" in err
    assert main(argv[:-6] + ["--start", "30", "--method", "linear", "--out", str(out)]) == 2
    assert "--start 30 s (start_s) is not within the log" in capsys.readouterr().err
    # a study file's [input] takes the same options
    from ehm.interfaces.batch import load_study

    study = tmp_path / "study.toml"
    study.write_text('[study]\ncompute = ["comfort"]\n[input]\ndrive = "phone.csv"\nduration_s = 3.0\n'
                     'columns = ["x", "y", "z", "delay_ms"]\nchannels = { ax = "-x", ay = "y", az = "z", '
                     'dt = "delay_ms" }\nunits = { dt = "ms" }\nmounting = [0.0, 0.0, 90.0]\nstart_s = 3.5\n'
                     'end_s = 10.0\n')
    with pytest.warns(UserWarning):
        _, specs = load_study(study)
    assert specs[0].input["start_s"] == 3.5
    study.write_text(study.read_text().replace("start_s = 3.5", "start_s = 11.5"))
    with pytest.raises(InputError, match=r"\[input\] drive: end_s \(10 s, --end\) must be after start_s"):
        load_study(study)


def test_a_gyro_file_with_nothing_inside_the_cut_is_refused_not_dropped():
    # SYNTHETIC: accelerometer 0-10 s, gyro 100-110 s on the same clock; a cut to 5 s leaves no gyro sample
    t = np.arange(0.0, 10.0, 0.01)
    acc = pd.DataFrame({"time_s": t, "ax_mps2": 0 * t, "ay_mps2": 0 * t, "az_mps2": 0.1 * np.sin(t)})
    tg = 100.0 + t
    gyro = pd.DataFrame({"time_s": tg, "wx_radps": 0 * tg, "wy_radps": 0 * tg, "wz_radps": 0.01 + 0 * tg})
    with pytest.raises(InputError) as exc:
        read_motion(acc, gyro=gyro, end_s=5.0)
    assert "at least 2 of each are needed to join them" in one_sentence(exc)


# --------------------------------------------------------------------------
# earth axes
# --------------------------------------------------------------------------


@pytest.mark.filterwarnings("always::ehm.errors.EhmWarning")  # the command line prints them: read on stderr
def test_an_earth_axis_log_is_read_as_it_is_with_one_note_and_what_it_cannot_take_is_refused(tmp_path, capsys):
    # SYNTHETIC Android log already turned into earth axes by the phone (x east, y north, z up, gravity on z)
    clock0 = 12_893_233_616_460
    t = np.arange(0, 20.0, 0.02)
    earth = sensor(t) + np.array([0.0, 0.0, G])
    _android(tmp_path / "earth.csv", clock0 + np.round(t * 1e9).astype(np.int64), earth)
    channels = {"time": "uptimeNanos", "ax": "x", "ay": "y", "az": "z"}
    with pytest.warns(UserWarning) as notes:
        m = read_motion(tmp_path / "earth.csv", channels=channels, frame="earth", gravity="included")
    said = [str(n.message) for n in notes if "earth axes" in str(n.message)]
    assert len(said) == 1 and "the seat's a_v, VDV and MSDV do not depend on it and are right" in said[0]
    assert "given for x east and y north" in said[0]
    assert "earth axes (x east, y north, z up)" in m.description
    np.testing.assert_allclose(m.acc_mps2, sensor(t), atol=1e-6)  # as it is, gravity taken off z
    # what an earth-axis log cannot be read with: each one sentence
    _android(tmp_path / "gyro.csv", clock0 + np.round(t * 1e9).astype(np.int64), rates(t))
    for kwargs, words in (({"gyro": tmp_path / "gyro.csv", "channels": {**channels, "wx": "x", "wy": "y", "wz": "z"}},
                           "angular rates in earth axes are not the seat's own"),
                          ({"imu": True}, "read it without --imu"),
                          ({"mounting": mounting_rotation(0, 0, 90)}, "not both"),
                          ({"frame": "north"}, "frame must be one of seat, earth")):
        with pytest.raises(InputError) as exc:
            read_motion(tmp_path / "earth.csv", **{"channels": channels, "frame": "earth", **kwargs})
        assert words in one_sentence(exc)
    # the same from the command line
    out = tmp_path / "out"
    assert main(["simulate", "--motion", str(tmp_path / "earth.csv"), "--frame", "earth",
                 "--channel", "time=uptimeNanos", "--channel", "ax=x", "--channel", "ay=y", "--channel", "az=z",
                 "--end", "2", "--out", str(out)]) == 0
    assert "earth axes (x east, y north, z up) are not the vehicle's" in capsys.readouterr().err


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
