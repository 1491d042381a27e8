"""Messages a user can act on: MuJoCo's own output folded into ehm's one sentence, build errors translated, seat
geometry checked, truncated or foreign files, running out of memory."""

from __future__ import annotations

import re

import numpy as np
import pytest

import ehm
from ehm import engine
from ehm.cli import main
from ehm.errors import InputError
from ehm.params import Parameters


def _one_line(err: str) -> str:
    assert "Traceback" not in err and "WARNING" not in err, err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("ehm: error: "), err
    return lines[0]


def test_mujoco_warning_is_folded_into_the_divergence_sentence(tmp_path, capfd):
    # An ankle spring of 3e9 N m/rad on a 1 kg foot cannot be integrated at 1 ms: MuJoCo warns of a bad
    # acceleration and resets its state; the user sees ehm's sentence with MuJoCo's finding in it, nothing raw.
    path = tmp_path / "stiff.toml"
    Parameters.load().with_values({"joints.ankle_r.pitch.stiffness_Nm_per_rad": 3e9}).export(path)
    assert main(["simulate", "--params", str(path), "--duration", "1", "--out", str(tmp_path / "run")]) == 2
    out, err = capfd.readouterr()  # the file descriptors: MuJoCo prints from C
    line = _one_line(err)
    assert "diverged at t =" in line and "MuJoCo: Nan, Inf or huge value in QACC at degree of freedom" in line
    assert re.search(r"degree of freedom \w+\.\w+", line), line  # a named joint dof (which one: the step's)
    assert "WARNING" not in out and engine.take_warnings() == []


def test_build_errors_are_translated():
    exc = ValueError("Error: inertia must satisfy A + B >= C; use 'balanceinertia' to fix\nElement name 'pelvis', id 9")
    from ehm.engine.diagnostics import build_error

    msg = str(build_error(exc))
    assert "\n" not in msg and "balanceinertia" not in msg
    assert "'pelvis'" in msg and "inertia must satisfy A + B >= C" in msg


def test_impossible_body_size_names_segment_and_masses_that_build(tmp_path, capsys):
    # Scaled segments stay rigid bodies (ehm.scaling.stretched_inertia), but what is left of a segment once its
    # tissue pads are taken out may not be: with 0.9 kg pads the pelvis is no rigid body at any size.  The
    # sentence names the segment and says which masses would build at that stature (here: none).
    from ehm.scaling import BodySize

    pads = ("buttock_r", "buttock_l", "thigh_r", "thigh_l", "lower_back", "upper_back")
    heavy = ehm.Parameters.load().with_values({f"contacts.{c}.pad_mass_kg": 0.9 for c in pads})
    path = tmp_path / "heavy_pads.toml"
    path.write_text(heavy.to_toml())
    stature, mass = 1.6, 60.0
    with pytest.raises(InputError):
        ehm.SeatedHuman(params=heavy, size=BodySize(stature, mass))
    assert main(["info", "--params", str(path), "--stature", f"{stature:g}", "--mass", f"{mass:g}"]) == 2
    line = _one_line(capsys.readouterr().err)
    assert "cannot be built" in line and "which no rigid body has" in line
    seg = re.search(r"segment '(\w+)'", line).group(1)
    assert seg == "pelvis"
    assert "no mass from 33 to 128 kg can be built" in line  # the masses of body mass index 13-50 at 1.6 m
    # the defaults build at any size (the corners of the WHO body mass index classes, 16-40 kg/m^2)
    for stature, mass in [(1.5, 90.0), (2.1, 70.6), (1.76, 50.0), (1.2, 57.6)]:
        ehm.SeatedHuman(size=BodySize(stature, mass))


def test_impossible_segment_inertia_is_named(tmp_path, capsys):
    # Izz = 0.05 > Ixx + Iyy = 0.002: no rigid body has these moments (MuJoCo: "inertia must satisfy A + B >= C")
    from importlib import resources

    src = (resources.files("ehm") / "data" / "segments.csv").read_text().splitlines()
    header_i = next(i for i, ln in enumerate(src) if ln.startswith("name,"))
    cols = src[header_i].split(",")
    fields = src[header_i + 1].split(",")
    for col, value in (("ixx_kgm2", "0.001"), ("iyy_kgm2", "0.001"), ("izz_kgm2", "0.05")):
        fields[cols.index(col)] = value
    src[header_i + 1] = ",".join(fields)
    path = tmp_path / "segments.csv"
    path.write_text("\n".join(src) + "\n")
    assert main(["info", "--segments", str(path)]) == 2
    line = _one_line(capsys.readouterr().err)
    assert "segments.csv, line" in line and "no rigid body has them" in line  # the table's own check, first


FLOOR_M = Parameters.load().value("seat.floor_height_m")


@pytest.mark.parametrize("values, words", [
    ({"seat.pan_height_m": FLOOR_M - 1.0}, r"seat\.pan_height_m = .* puts the seat pan 1 m below the floor"),
    ({"seat.backrest_x_m": 0.3}, r"pad lies .* in front of the pelvis.*backrest must be behind the pelvis"),
    ({"seat.lower_pad_height_m": 0.5}, r"backrest pads must sit on the backrest above the seat pan"),
    ({"seat.pan_height_m": 0.05}, r"contact 'buttock_\w' .* below the seat pan surface"),
])
def test_seat_geometry_is_checked(values, words):
    with pytest.raises(InputError, match=words):
        ehm.SeatedHuman(params=Parameters.load().with_values(values))


@pytest.mark.parametrize("damage", ["truncated", "crc", "random", "empty"])
def test_truncated_or_foreign_pose_file_is_one_sentence(tmp_path, capsys, damage):
    run = tmp_path / "run"
    human = ehm.SeatedHuman()
    human.simulate_to(run, ehm.random_vibration("z", 1.0, 0.3, seed=0), method="nonlinear")
    data = bytearray((run / "poses.npz").read_bytes())
    if damage == "truncated":
        data = data[: len(data) // 2]
    elif damage == "crc":
        data[len(data) // 2] ^= 0xFF
    elif damage == "random":
        data = bytearray(np.random.default_rng(0).integers(0, 256, 4000, dtype=np.uint8).tobytes())
    else:
        data = bytearray()
    (run / "poses.npz").write_bytes(bytes(data))
    assert main(["animate", str(run), "--out", str(tmp_path / "a.gif"), "--max-frames", "2"]) == 2
    line = _one_line(capsys.readouterr().err)
    assert "poses.npz: cannot read it as a pose file" in line
    assert not (tmp_path / "a.gif").exists()


def test_foreign_parameter_and_study_files_are_one_sentence(tmp_path, capsys):
    study = tmp_path / "study.toml"
    study.write_text('[study]\nname = "x"\n[input]\naxes = ["z"]\n')
    assert main(["info", "--params", str(study)]) == 2
    assert "not an ehm parameter file" in _one_line(capsys.readouterr().err)
    params = tmp_path / "params.toml"
    Parameters.load().export(params)
    assert main(["batch", str(params), "--out", str(tmp_path / "res")]) == 2
    assert "unknown section" in _one_line(capsys.readouterr().err)
    truncated = tmp_path / "half.toml"
    truncated.write_text(params.read_text()[:1000])
    assert main(["info", "--params", str(truncated)]) == 2
    assert "half.toml" in _one_line(capsys.readouterr().err)
    assert not (tmp_path / "res").exists()


def test_out_of_memory_is_one_sentence(monkeypatch, capsys):
    def exhausted(self):
        raise MemoryError()

    monkeypatch.setattr(ehm.SeatedHuman, "info", exhausted)
    assert main(["info"]) == 2
    assert "out of memory" in _one_line(capsys.readouterr().err)


def test_a_divergence_names_an_unusual_input_and_the_cut_that_removes_it():
    # SYNTHETIC log: 1 s of a phone being put in place (+-25 m/s^2 at random), then a quiet ride
    import ehm
    from ehm.errors import DivergenceError

    rng = np.random.default_rng(0)
    t = np.arange(0.0, 6.0, 0.01)
    acc = 0.1 * rng.standard_normal((t.size, 3))
    acc[t < 1.0] += rng.uniform(-40.0, 40.0, (int(np.sum(t < 1.0)), 3))
    motion = ehm.SeatMotion(t, acc, "SYNTHETIC phone being put in place")
    human = ehm.SeatedHuman()
    try:
        human.simulate(motion, method="nonlinear")
    except DivergenceError as exc:
        text = str(exc)
        assert "the seat input is out of the ordinary before it" in text and "above 2 g" in text
        assert "--start 2" in text and "time step" not in text
    else:  # the model rode it out: then nothing is blamed, and the cause check has nothing to say
        pass
    # the cause check itself, on a divergence raised by hand
    from ehm.routes.nonlinear import with_input_cause

    named = with_input_cause(DivergenceError("the simulation diverged at t = 0.500 s (a reason); try a smaller time "
                                              "step"), motion, 0.6)
    assert str(named).startswith("the simulation diverged at t = 0.500 s: the seat input is out of the ordinary")
    quiet = ehm.SeatMotion(t, 0.1 * rng.standard_normal((t.size, 3)), "SYNTHETIC quiet ride")
    plain = DivergenceError("the simulation diverged at t = 0.500 s (a reason); try a smaller time step")
    assert with_input_cause(plain, quiet, 0.6) is plain  # an ordinary input: the time step stays the suspect


def test_a_divergence_blames_only_the_input_before_it_and_names_a_tilted_seat(monkeypatch):
    # SYNTHETIC: the hybrid route diverging at 1 s (raised by hand) on a log with a 1.5 g jump at 5 s: the jump came
    # after, so the time step stays the suspect (it was named "before it"; a real case: a hand-moved IMU whose
    # seat rolled past 30 deg at 15.5 s while a jump came at 81 s); at 6 s the jump is named
    import ehm
    import ehm.routes.hybrid
    from ehm.errors import DivergenceError

    def diverging_at(time_s):
        def stream(*args, **kwargs):
            err = DivergenceError(f"the simulation diverged at t = {time_s:.3f} s (a reason); try a smaller time step")
            err.time_s = time_s
            raise err
            yield  # a generator, as stream_checked is

        return stream

    t = np.arange(0.0, 10.0, 0.01)
    acc = np.zeros((t.size, 3))
    acc[t >= 5.0, 2] = 15.0
    motion = ehm.SeatMotion(t, acc, "SYNTHETIC log with a jump at 5 s")
    human = ehm.SeatedHuman()
    monkeypatch.setattr(ehm.routes.hybrid, "stream_checked", diverging_at(1.0))
    with pytest.raises(DivergenceError) as exc:
        human.simulate(motion, method="auto")
    assert "time step" in str(exc.value) and "jump" not in str(exc.value)
    monkeypatch.setattr(ehm.routes.hybrid, "stream_checked", diverging_at(6.0))
    with pytest.raises(DivergenceError, match=r"out of the ordinary before it \(a jump of 15 m/s\^2"):
        human.simulate(motion, method="auto")
    # a motion whose clock starts at 100 s: the divergence's time counts from its first sample
    later = ehm.SeatMotion(t + 100.0, acc, "SYNTHETIC log with a jump at 105 s")
    with pytest.raises(DivergenceError, match=r"a jump of 15 m/s\^2 .* at t = 105.000 s.* --start 6 "):
        human.simulate(later, method="auto")
    # a seat that rolls at 10 deg/s passes 30 deg at 3 s: named, with what to check, and no time step
    turning = ehm.SeatMotion(t, np.zeros((t.size, 3)), "SYNTHETIC seat rolling over",
                             np.column_stack([np.radians(10.0) * np.ones(t.size), np.zeros(t.size), np.zeros(t.size)]))
    from ehm.routes.nonlinear import with_input_cause

    plain = DivergenceError("the simulation diverged at t = 4.000 s (a reason); try a smaller time step")
    text = str(with_input_cause(plain, turning, 4.0))
    assert "the seat is rolled beyond 30 deg from t = 3.0" in text and "up to 40 deg" in text
    assert "--mounting" in text and "time step" not in text
    assert with_input_cause(plain, turning, 2.5) is plain  # before 30 deg: ordinary


def test_a_seat_pitch_out_of_range_names_the_units_axes_and_frame():
    # SYNTHETIC: a 5 deg/s pitch rate written in deg/s and read as rad/s integrates to far beyond 80 deg
    from ehm.motion import seat_kinematics

    t = np.arange(0.0, 10.0, 0.01)
    w = np.zeros((t.size, 3))
    w[:, 1] = 5.0
    with pytest.raises(InputError) as exc:
        seat_kinematics(t, w)
    text = str(exc.value)
    assert text.startswith("the seat pitch reaches") and "--unit wx=deg/s" in text and "--mounting" in text
    assert "\n" not in text and text.endswith(".")
