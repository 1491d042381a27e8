"""Units and time stamps of measured logs: read right, or refused in one sentence naming the --unit that fixes it.

Every log here is SYNTHETIC (random vibration made by the tests), written in the layouts that loggers and phone
apps export: units in brackets, parentheses, suffixes or words; time in s, ms, µs, ns, Unix time, uptime since
boot and date-time strings.
"""

from __future__ import annotations

import contextlib
import warnings

import numpy as np
import pandas as pd
import pytest

from ehm.errors import EhmWarning, InputError
from ehm.inputs.imu import from_imu
from ehm.inputs.readers import read_motion

G = 9.80665
DEFAULT = {"time": "time_s", "ax": "ax_mps2", "ay": "ay_mps2", "az": "az_mps2",
           "wx": "wx_radps", "wy": "wy_radps", "wz": "wz_radps"}


def synthetic(n: int = 1500, fs_hz: float = 100.0, seed: int = 0, gravity: bool = False):
    """SYNTHETIC seat log: time [s], acceleration [m/s^2] (0.3 m/s^2 rms vibration, + gravity on z when asked)
    and angular velocity [rad/s] (0.05 rad/s rms)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs_hz
    acc = 0.3 * rng.standard_normal((n, 3))
    if gravity:
        acc[:, 2] += G
    return t, acc, 0.05 * rng.standard_normal((n, 3))


def as_read(t, acc):
    """The same motion given in SI under ehm's own names, read as ehm reads it (gravity levelled alike)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (the levelling's note)
        return read_motion(pd.DataFrame({"time_s": t, "ax_mps2": acc[:, 0], "ay_mps2": acc[:, 1],
                                         "az_mps2": acc[:, 2]})).acc_mps2


def write(tmp_path, columns: dict, name: str = "log.csv"):
    path = tmp_path / name
    pd.DataFrame(columns).to_csv(path, index=False, float_format="%.17g")
    return path


def si_columns(t, acc, w) -> dict:
    return {"time_s": t, **{DEFAULT[k]: acc[:, j] for j, k in enumerate(("ax", "ay", "az"))},
            **{DEFAULT[k]: w[:, j] for j, k in enumerate(("wx", "wy", "wz"))}}


def one_sentence(exc) -> str:
    text = str(exc.value)
    assert "\n" not in text and text.endswith(".")
    return text


# --------------------------------------------------------------------------
# a unit from a column's name, in every common form
# --------------------------------------------------------------------------

NAME_FORMS = [  # (key, the column's name, one of its units in SI)
    ("ax", "acc_x [g]", G), ("ax", "Accelerometer X (g)", G),
    ("ax", "accelerometerAccelerationX(G)", -G),  # Core Motion's: the negative of the specific force
    ("ax", "acc_x_g", G), ("ax", "Acceleration X in g", G), ("ax", "acc_x (m/s^2)", 1.0), ("ax", "acc_x m/s2", 1.0),
    ("ax", "acc_x (m/s²)", 1.0), ("ax", "acc_x [mg]", G / 1000), ("ax", "acc_x_mg", G / 1000),
    ("ax", "AccX (mG)", G / 1000), ("ax", "ax_mps2", 1.0), ("ax", "Acc X in m/s2", 1.0),
    ("wx", "Gyroscope X (deg/s)", np.pi / 180), ("wx", "gyro_x °/s", np.pi / 180),
    ("wx", "gyro_x [°/s]", np.pi / 180),
    ("wx", "gyro_x_dps", np.pi / 180), ("wx", "GyroX (dps)", np.pi / 180), ("wx", "gyro_x (rad/s)", 1.0),
    ("wx", "wx_radps", 1.0),
    ("time", "Time (s)", 1.0), ("time", "t (ms)", 1e-3), ("time", "t (us)", 1e-6), ("time", "t (µs)", 1e-6),
    ("time", "t [μs]", 1e-6), ("time", "t (ns)", 1e-9), ("time", "time_s", 1.0), ("time", "time_ms", 1e-3),
    ("time", "t_ns", 1e-9), ("time", "elapsed in ms", 1e-3),
]


@pytest.mark.parametrize(("key", "name", "unit_si"), NAME_FORMS, ids=[f[1] for f in NAME_FORMS])
def test_a_unit_in_a_column_name_is_read_in_every_form(tmp_path, key, name, unit_si):
    t, acc, w = synthetic()
    t0 = 12.5  # a logger's clock: the time axis starts at 0 at the first sample
    columns = si_columns(t + t0, acc, w)
    if key == "time":
        counts = columns.pop("time_s") / unit_si
        columns = {name: np.round(counts).astype(np.int64) if unit_si < 1 else counts, **columns}
    else:
        columns[name] = columns.pop(DEFAULT[key]) / unit_si
    # Apple's Core Motion columns hold the negative of the specific force: read flipped, with a word
    apple = name.startswith("accelerometerAcceleration")
    with pytest.warns(EhmWarning, match="Apple Core Motion column") if apple else contextlib.nullcontext():
        m = read_motion(write(tmp_path, columns), channels={key: name})
    np.testing.assert_allclose(m.acc_mps2, acc, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(m.angvel_radps, w, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(m.time_s - m.time_s[0], t, rtol=0, atol=1e-9)
    assert m.time_s[0] == 0.0  # the time axis starts at 0 at the first sample


def test_the_units_argument_wins_over_the_name(tmp_path):
    # SYNTHETIC: a column named in g that holds m/s^2 (converted by hand, the name left as it was)
    t, acc, w = synthetic(gravity=True)
    path = write(tmp_path, {"Time (s)": t, "Accelerometer X (g)": acc[:, 0], "Accelerometer Y (g)": acc[:, 1],
                            "Accelerometer Z (g)": acc[:, 2]})
    names = {"time": "Time (s)", "ax": "Accelerometer X (g)", "ay": "Accelerometer Y (g)", "az": "Accelerometer Z (g)"}
    with pytest.warns(UserWarning, match="taken to include gravity"):  # (1 g on z: levelled, as any such log)
        m = read_motion(path, names, units={"ax": "m/s^2", "ay": "m/s^2", "az": "m/s^2"})
    np.testing.assert_allclose(m.acc_mps2, as_read(t, acc), rtol=1e-12, atol=1e-12)
    # the name's g: a warning on the unit, then (gravity auto) a mean z of 96 m/s^2 is refused as an offset
    with pytest.warns(UserWarning, match=r"are in m/s\^2, as their names say, .* a median of 96\.24 m/s\^2, over 5 g"):
        with pytest.raises(InputError, match=r"mean z of 96\.2 m/s\^2 .* check the acceleration's unit, --unit"):
            read_motion(path, names)
    with pytest.warns(UserWarning, match=r"over 5 g"):  # taken as it is where the caller says there is no gravity
        with pytest.raises(InputError, match="gravity removed"):
            read_motion(path, names, gravity="removed")


def test_words_in_parentheses_that_are_no_unit_are_passed_over(tmp_path):
    # SYNTHETIC: "(seat pad)" and "(1)" describe, they do not measure; SI is taken
    t, acc, w = synthetic()
    path = write(tmp_path, {"t": t, "Acc X (seat pad)": acc[:, 0], "Acc Y (1)": acc[:, 1], "Acc Z": acc[:, 2]})
    m = read_motion(path, {"time": "t", "ax": "Acc X (seat pad)", "ay": "Acc Y (1)", "az": "Acc Z"})
    np.testing.assert_allclose(m.acc_mps2, acc, rtol=1e-12)
    # a unit of another kind in a name is refused: a magnetometer is no accelerometer
    path = write(tmp_path, {"t": t, "Mag X (uT)": acc[:, 0], "ay": acc[:, 1], "az": acc[:, 2]})
    with pytest.raises(InputError) as exc:
        read_motion(path, {"time": "t", "ax": "Mag X (uT)", "ay": "ay", "az": "az"})
    assert "channel ax ('Mag X (uT)'): unit 'uT' is not an acceleration" in one_sentence(exc)


def test_a_phone_app_log_in_g_with_units_in_parentheses_read_as_an_imu(tmp_path):
    # SYNTHETIC, the layout of an iPhone sensor app: a text time column "(txt)", seconds since reboot, g and rad/s,
    # and Core Motion's sign: its accelerometer reads minus the specific force (-1 g on z lying face up)
    t, acc, w = synthetic(n=3000, gravity=True)
    acc[:100], w[:] = (0.0, 0.0, G), 0.0  # the first second at rest; the seat does not turn
    path = write(tmp_path, {"loggingTime(txt)": [f"2026-11-25 14:03:{7 + i / 100:06.3f}" for i in range(t.size)],
                            "accelerometerTimestamp_sinceReboot(s)": 8123.25 + t,
                            **{f"accelerometerAcceleration{a}(G)": -acc[:, j] / G for j, a in enumerate("XYZ")},
                            **{f"gyroRotation{a}(rad/s)": w[:, j] for j, a in enumerate("XYZ")}})
    names = {"time": "accelerometerTimestamp_sinceReboot(s)",
             **{k: f"accelerometerAcceleration{a}(G)" for k, a in zip(("ax", "ay", "az"), "XYZ")},
             **{k: f"gyroRotation{a}(rad/s)" for k, a in zip(("wx", "wy", "wz"), "XYZ")}}
    with pytest.warns(UserWarning, match=r"ax \('accelerometerAccelerationX\(G\)'\), ay .* are Apple Core Motion "
                      r"columns, which hold the negative of the specific force .*: ax, ay, az read with the sign "
                      r"flipped"):
        m = read_motion(path, names, imu=True)
    reference = from_imu(t, acc, w)
    np.testing.assert_allclose(m.time_s, t, atol=1e-9)
    np.testing.assert_allclose(m.acc_mps2, reference.acc_mps2, rtol=1e-9, atol=1e-12)
    # before: the (G) was passed over, g read as m/s^2, and the IMU refused (gravity 1 m/s^2 at rest); and the
    # sign was taken as it is: upside down, refused (roll 180 deg); '-' before the names keeps the file's sign
    with pytest.raises(InputError, match="roll"), pytest.warns(EhmWarning, match="Apple Core Motion columns"):
        read_motion(path, {**names, **{k: "-" + names[k] for k in ("ax", "ay", "az")}}, imu=True)


# --------------------------------------------------------------------------
# time stamps: ms, µs, ns, Unix time, uptime, date-time strings; from 0
# --------------------------------------------------------------------------


def acc_columns(acc) -> dict:
    return {"x": acc[:, 0], "y": acc[:, 1], "z": acc[:, 2]}


XYZ = {"ax": "x", "ay": "y", "az": "z"}


def test_uptime_in_ns_is_read_from_its_name(tmp_path):
    # SYNTHETIC Android log: uptimeNanos (ns since boot, 3.6 h), irregular steps of 19-21 ms, and a date-time
    # column of whole seconds; the old reader took ns for s and ran out of memory
    t, acc, _ = synthetic(n=2000)
    # steps of 19 and 21 ms in turn: irregular, but within 5 % of a step of the uniform grid (more is resampled)
    ns = 12_893_233_616_460 + np.cumsum(np.r_[0, np.where(np.arange(t.size - 1) % 2, 19_000_000, 21_000_000)])
    stamps = pd.to_datetime(1_463_224_629 + (ns - ns[0]) // 1_000_000_000, unit="s").strftime("%d/%m/%Y %H:%M:%S")
    path = write(tmp_path, {"timestamp": stamps, "uptimeNanos": ns, **acc_columns(acc)})
    m = read_motion(path, {"time": "uptimeNanos", **XYZ})
    np.testing.assert_allclose(m.time_s, (ns - ns[0]) / 1e9, rtol=1e-15, atol=0)  # to the ns
    np.testing.assert_allclose(m.acc_mps2, acc, rtol=1e-15)
    # the date-time column holds whole seconds at 50 Hz: refused, naming what to take instead
    with pytest.raises(InputError) as exc:
        read_motion(path, {"time": "timestamp", **XYZ})
    assert "line 3, column timestamp (channel time): " in one_sentence(exc)
    assert "time stamps repeat the one before" in str(exc.value) and "whole seconds" in str(exc.value)
    assert "--channel time=NAME" in str(exc.value)


@pytest.mark.parametrize(("name", "unit", "per_s", "origin"), [
    ("timestamp", None, 1e9, 1_764_079_387_123_000_000),     # Unix time in ns: inferred from its size
    ("timestamp", "ms", 1e3, 1_764_079_387_123),             # Unix time in ms: given
    ("timestamp", "us", 1e6, 1_764_079_387_123_000),         # Unix time in µs: given
    ("timestamp", None, 1.0, 1_764_079_387.123),             # Unix time in s (floats)
    ("t", "ns", 1e9, 12_893_233_616_460),                     # uptime in ns, unnamed: given
    ("elapsedRealtimeNanos", None, 1e9, 5_000_000_000_000),   # Android's name for uptime in ns
    ("timestampMillis", None, 1e3, 1_764_079_387_123),       # a name counting ms
    ("micros", None, 1e6, 3_000_000),                         # Arduino's micros(), by its name
])
def test_time_counts_of_every_origin_and_unit_start_at_0(tmp_path, name, unit, per_s, origin):
    t, acc, _ = synthetic(n=1200, fs_hz=200.0)
    counts = origin + np.round(t * per_s).astype(np.int64) if per_s > 1 else origin + t
    m = read_motion(write(tmp_path, {name: counts, **acc_columns(acc)}), {"time": name, **XYZ},
                    units={"time": unit} if unit else None)
    np.testing.assert_allclose(m.time_s, t, rtol=0, atol=1e-6 if per_s == 1 else 1e-12)


@pytest.mark.parametrize(("stamps", "units"), [
    (lambda d: d.strftime("%d/%m/%Y %H:%M:%S.%f"), None),        # 25/11/2026 23:59:55.000000: day first
    (lambda d: d.strftime("%d/%m/%Y %H:%M:%S.%f").str[:-3], None),   # ... .123 (ms)
    (lambda d: d.strftime("%Y-%m-%dT%H:%M:%S.%fZ"), None),        # ISO 8601 in UTC
    (lambda d: d.strftime("%Y-%m-%d %H:%M:%S.%f+01:00"), None),   # ISO 8601 with an offset
    (lambda d: d.strftime("%d.%m.%Y %H:%M:%S,%f"), None),         # German: 25.11.2026 23:59:55,000000
    (lambda d: d.strftime("%m/%d/%Y %H:%M:%S.%f"), None),         # US: 11/25/2026 (25 is no month)
    (lambda d: d.strftime("%Y|%m|%d %H-%M-%S.%f"), {"time": "%Y|%m|%d %H-%M-%S.%f"}),  # any, by its format
])
def test_date_time_strings_over_midnight(tmp_path, stamps, units):
    t, acc, _ = synthetic(n=1000)
    dates = pd.Series(pd.to_datetime("2026-11-25 23:59:55") + pd.to_timedelta(t, unit="s"))
    path = write(tmp_path, {"date": stamps(dates.dt), **acc_columns(acc)})
    m = read_motion(path, {"time": "date", **XYZ}, units=units)
    np.testing.assert_allclose(m.time_s, t, rtol=0, atol=1e-9)


def test_date_times_that_read_two_ways_are_refused(tmp_path):
    # SYNTHETIC: 01/12/2026 23:59:59 to 02/12/2026 00:00:09: the next day or the next month
    t, acc, _ = synthetic(n=1000, fs_hz=100.0)
    dates = pd.Series(pd.to_datetime("2026-12-01 23:59:59") + pd.to_timedelta(t, unit="s"))
    path = write(tmp_path, {"date": dates.dt.strftime("%d/%m/%Y %H:%M:%S.%f"), **acc_columns(acc)})
    with pytest.raises(InputError) as exc:
        read_motion(path, {"time": "date", **XYZ})
    assert one_sentence(exc).endswith("column date (channel time): the dates read as '%d/%m/%Y %H:%M:%S.%f' and as "
                                      "'%m/%d/%Y %H:%M:%S.%f' give different times (day and month swapped); give "
                                      "their format, e.g. --unit 'time=%d/%m/%Y %H:%M:%S.%f'.")
    m = read_motion(path, {"time": "date", **XYZ}, units={"time": "%d/%m/%Y %H:%M:%S.%f"})
    np.testing.assert_allclose(m.time_s, t, atol=1e-9)
    # a date-time column and a unit that is no format: refused
    with pytest.raises(InputError, match=r"line 2, column date \(channel time\): the time stamps are dates and times "
                                         r"\('01/12/2026 23:59:59.000000'\), the units argument 'ms'"):
        read_motion(path, {"time": "date", **XYZ}, units={"time": "ms"})
    # text that is no time at all
    path = write(tmp_path, {"date": ["start"] + [str(v) for v in t[1:]], **acc_columns(acc)}, "words.csv")
    with pytest.raises(InputError) as exc:
        read_motion(path, {"time": "date", **XYZ})
    assert "line 2, column date (channel time): 'start' is not a number or a date and time ehm reads" in \
        one_sentence(exc)
    # numbers with one that is not: that one is named
    path = write(tmp_path, {"date": [str(v) for v in t[:5]] + ["abc"] + [str(v) for v in t[6:]], **acc_columns(acc)},
                 "numbers.csv")
    with pytest.raises(InputError, match=r"line 7, column date \(channel time\): 'abc' is not a number\.$"):
        read_motion(path, {"time": "date", **XYZ})


def test_dataframe_date_time_columns_naive_and_with_a_time_zone():
    t, acc, _ = synthetic(n=1000)
    start = pd.Timestamp("2026-03-29 00:59:55")  # over the switch to summer time in Europe: UTC keeps the steps
    for dates in (start + pd.to_timedelta(t, unit="s"),
                  (start + pd.to_timedelta(t, unit="s")).tz_localize("UTC").tz_convert("Europe/Berlin")):
        frame = pd.DataFrame({"when": dates, **acc_columns(acc)})
        m = read_motion(frame, {"time": "when", **XYZ})
        np.testing.assert_allclose(m.time_s, t, rtol=0, atol=1e-9)


def test_a_negative_start_is_moved_to_0(tmp_path):
    # SYNTHETIC: a logger with 0.5 s of pre-trigger samples (it was refused: "time -0.5 s is negative")
    t, acc, w = synthetic(n=300)
    m = read_motion(write(tmp_path, si_columns(t - 0.5, acc, w)))
    np.testing.assert_allclose(m.time_s, t, atol=1e-12)


# --------------------------------------------------------------------------
# plausibility: refused when the unit was assumed, warned when the name said it, silent when it was given
# --------------------------------------------------------------------------


@pytest.mark.parametrize(("counts_per_s", "fix", "step"), [(1e9, "ns", "1e+07"), (1e6, "us", "1e+04"),
                                                           (1e3, "ms", "10")])
def test_a_time_step_implausible_in_seconds_is_refused(tmp_path, counts_per_s, fix, step):
    # SYNTHETIC 100 Hz log stamped in ns, µs or ms under a name that does not say so
    t, acc, _ = synthetic(n=1500)
    counts = 4_000_000 + np.round(t * counts_per_s).astype(np.int64)
    path = write(tmp_path, {"t": counts, **acc_columns(acc)})
    with pytest.raises(InputError) as exc:
        read_motion(path, {"time": "t", **XYZ})
    assert one_sentence(exc) == (f"{path}, column t (channel time): the median time step is {step} s if the time "
                                 f"column is in s, as no unit is given; give its unit, e.g. --unit time={fix} "
                                 f"(units={{'time': '{fix}'}}), which makes it 0.01 s.")
    np.testing.assert_allclose(read_motion(path, {"time": "t", **XYZ}, {"time": fix}).time_s, t, atol=1e-12)
    # a name that says seconds does not make it so
    path = write(tmp_path, {"Time (s)": counts, **acc_columns(acc)}, "named.csv")
    with pytest.raises(InputError, match=rf"if the time column is in s, as its name says; give its unit, e.g. "
                                         rf"--unit time={fix} "):
        read_motion(path, {"time": "Time (s)", **XYZ})


def test_a_short_hand_written_table_may_step_slowly(tmp_path):
    # SYNTHETIC: a few rows a second apart are a table written by hand, not a logger's recording
    path = tmp_path / "steps.csv"
    path.write_text("time_s,ax_mps2,ay_mps2,az_mps2\n0,0,0,0\n1,0,0,0.5\n2,0,0,0\n")
    assert read_motion(path).duration_s == 2.0
    path.write_text("time_s,ax_mps2,ay_mps2,az_mps2\n0,0,0,0\n100,0,0,0.5\n200,0,0,0\n")  # ms: 100 s steps
    with pytest.raises(InputError, match=r"the median time step is 100 s .* e\.g\. --unit time=ms"):
        read_motion(path)


def test_a_logged_table_named_in_seconds_holding_milliseconds_is_refused_naming_ms(tmp_path):
    # SYNTHETIC: issue 38: a 301-row table whose time_s column holds milliseconds (a 100 Hz log) ran as a 3000 s drive
    # and wrote 509 MB; a hand table steps slowly in a few rows, a logger's 301 rows are no hand table
    path = tmp_path / "ms.csv"
    t = np.arange(301) * 10.0
    acc = 0.3 * np.random.default_rng(0).standard_normal((t.size, 3))
    np.savetxt(path, np.column_stack([t, acc]), delimiter=",", header="time_s,ax_mps2,ay_mps2,az_mps2", comments="")
    with pytest.raises(InputError) as exc:
        read_motion(path)
    assert one_sentence(exc) == (f"{path}, column time_s: the median time step is 10 s if the time column is in s, as "
                                 "its name says; give its unit, e.g. --unit time=ms (units={'time': 'ms'}), which "
                                 "makes it 0.01 s.")
    assert read_motion(path, units={"time": "ms"}).duration_s == pytest.approx(3.0)


def test_a_log_in_g_read_as_m_s2_is_refused_warned_or_taken(tmp_path):
    # SYNTHETIC IMU in g with gravity (z about 1), under names without a unit
    t, acc, _ = synthetic(gravity=True)
    in_g = {"t": t, **acc_columns(acc / G)}
    path = write(tmp_path, in_g)
    names = {"time": "t", **XYZ}
    with pytest.raises(InputError) as exc:
        read_motion(path, names)
    assert one_sentence(exc) == (
        f"{path}: if ax ('x'), ay ('y'), az ('z') are in m/s^2, as no unit is given, the norm of the acceleration has "
        "a median of 1 and a steady part of 1: gravity in g; give the unit, e.g. --unit ax=g --unit ay=g --unit az=g "
        "(units={'ax': 'g', 'ay': 'g', 'az': 'g'}), or m/s^2 if that is what it is.")
    with pytest.warns(UserWarning, match="taken to include gravity"):
        in_si = read_motion(path, names, {"ax": "g", "ay": "g", "az": "g"}).acc_mps2
    np.testing.assert_allclose(in_si, as_read(t, acc), rtol=1e-9, atol=1e-9)
    with warnings.catch_warnings():  # the caller's m/s^2 is taken as it is
        warnings.simplefilter("error")
        read_motion(path, names, {"ax": "m/s^2", "ay": "m/s^2", "az": "m/s^2"})
    # only the channel left without a unit is judged: z carries gravity
    with pytest.raises(InputError, match=r"if az \('z'\) is in m/s\^2, as no unit is given, .* --unit az=g "):
        read_motion(path, names, {"ax": "g", "ay": "g"})
    # the name says m/s^2: read as it is, with a warning
    path = write(tmp_path, {"time_s": t, **{f"a{c}_mps2": acc[:, j] / G for j, c in enumerate("xyz")}}, "named.csv")
    with pytest.warns(UserWarning, match=r"if ax \('ax_mps2'\), ay \('ay_mps2'\), az \('az_mps2'\) are in m/s\^2, as "
                                         r"their names say, .* gravity in g; .* \(read as it is\)\.$"):
        read_motion(path)


def test_a_vibration_of_about_1_m_s2_without_gravity_is_not_taken_for_g(tmp_path):
    # SYNTHETIC seat vibration without gravity: the norm's median is 1.0 m/s^2, but it has no steady part
    rng = np.random.default_rng(4)
    acc = rng.standard_normal((3000, 3))
    acc *= 1.0 / np.median(np.linalg.norm(acc, axis=1))
    path = write(tmp_path, {"t": np.arange(3000) / 100, **acc_columns(acc)})
    np.testing.assert_allclose(read_motion(path, {"time": "t", **XYZ}).acc_mps2, acc, rtol=1e-12)


def test_a_log_in_mg_read_as_m_s2_is_refused(tmp_path):
    t, acc, _ = synthetic(gravity=True)
    path = write(tmp_path, {"t": t, **acc_columns(acc / G * 1000)})
    with pytest.raises(InputError) as exc:
        read_motion(path, {"time": "t", **XYZ})
    assert "the norm of the acceleration has a median of 1001 m/s^2, over 5 g for half the log; give the unit, " \
           "e.g. --unit ax=mg --unit ay=mg --unit az=mg" in one_sentence(exc)


@pytest.mark.parametrize(("scale", "words"), [
    (1.0, "a median of 0.0788 rad/s (4 deg/s)"),   # a car's rates: median 4 deg/s read as rad/s is 4 rad/s
    (0.1, "99th percentile of 40.9 rad/s"),        # an IMU turned by hand: mostly still, peaks of 400 deg/s
])
def test_a_gyro_in_deg_s_read_as_rad_s_is_refused(tmp_path, scale, words):
    t, acc, w = synthetic()
    rng = np.random.default_rng(2)
    if scale == 1.0:
        deg = np.degrees(w) + np.degrees(0.05) * rng.standard_normal(w.shape)  # a car turning: a few deg/s
    else:  # still, with turns by hand of up to 400 deg/s in 3 % of the samples
        deg = 0.5 * rng.standard_normal(w.shape)
        deg[::30] = 400 * rng.uniform(-1, 1, (deg[::30].shape[0], 3))
    path = write(tmp_path, {"t": t, **acc_columns(acc), "p": deg[:, 0], "q": deg[:, 1], "r": deg[:, 2]})
    names = {"time": "t", **XYZ, "wx": "p", "wy": "q", "wz": "r"}
    with pytest.raises(InputError) as exc:
        read_motion(path, names)
    text = one_sentence(exc)
    assert text.startswith(f"{path}: if wx ('p'), wy ('q'), wz ('r') are in rad/s, as no unit is given, the norm of "
                           "the angular velocity has a median of ")
    assert "give the unit, e.g. --unit wx=deg/s --unit wy=deg/s --unit wz=deg/s (units={'wx': 'deg/s', " \
           "'wy': 'deg/s', 'wz': 'deg/s'}), or rad/s if that is what it is." in text
    m = read_motion(path, names, {"wx": "deg/s", "wy": "deg/s", "wz": "deg/s"})
    np.testing.assert_allclose(m.angvel_radps, np.radians(deg), rtol=1e-12)
    del words


def test_the_command_line_takes_a_date_time_format_as_the_time_unit(tmp_path):
    from ehm.inputs.readers import parse_assignments

    assert parse_assignments(["time=%d/%m/%Y %H:%M:%S.%f"], "--unit") == {"time": "%d/%m/%Y %H:%M:%S.%f"}


@pytest.mark.filterwarnings("always::ehm.errors.EhmWarning")  # the command line prints them: read on stderr
def test_the_command_line_refuses_in_one_line_and_reads_with_unit(tmp_path, capsys):
    from ehm.interfaces.cli import main

    t, acc, _ = synthetic(n=1500)
    dates = pd.Series(pd.to_datetime("2026-11-25 14:03:07") + pd.to_timedelta(t, unit="s"))
    path = write(tmp_path, {"Zeitstempel": dates.dt.strftime("%Y|%m|%d %H:%M:%S.%f"),
                            "t": 4_000_000 + np.round(t * 1e6).astype(np.int64), **acc_columns(acc)})
    argv = ["assess", "--motion", str(path), "--method", "linear", "--channel", "ax=x", "--channel", "ay=y",
            "--channel", "az=z"]
    assert main([*argv, "--channel", "time=t", "--out", str(tmp_path / "a")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.endswith("give its unit, e.g. --unit time=us (units={'time': 'us'}), which makes "
                                            "it 0.01 s.")
    assert main([*argv, "--channel", "time=Zeitstempel", "--unit", "time=%Y|%m|%d %H:%M:%S.%f",
                 "--out", str(tmp_path / "b")]) == 0
    assert (tmp_path / "b" / "assessment.json").exists()
    assert "not all of the Wk band" in capsys.readouterr().err  # the log's 100 Hz: up to 40 Hz
