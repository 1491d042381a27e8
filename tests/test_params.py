"""Parameter files: checks on bad files, export/load round trip, dotted-path updates.

Every bad file is the shipped default_params.toml with exactly one edit, so each test checks that the one
problem is reported (InputError naming the file and the entry) and that nothing else is.
"""

from __future__ import annotations

import math
import tomllib

import pytest

from ehm.body.params import Parameters, default_params_path
from ehm.errors import InputError

DEFAULT_TEXT = default_params_path().read_text(encoding="utf-8")


def _write(tmp_path, text: str, name: str = "my_params.toml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _replace_once(old: str, new: str) -> str:
    assert DEFAULT_TEXT.count(old) == 1, old
    return DEFAULT_TEXT.replace(old, new)


def _load_error(tmp_path, text: str) -> str:
    path = _write(tmp_path, text)
    with pytest.raises(InputError) as exc:
        Parameters.load(path)
    msg = str(exc.value)
    assert path.name in msg, msg  # names the file
    return msg


def test_unedited_copy_loads(tmp_path):
    # Control: a byte-for-byte copy loads, so every failure below is due to its one edit.
    p = Parameters.load(_write(tmp_path, DEFAULT_TEXT))
    assert p.value("simulation.dt_s") == 0.001  # the converged step (README "Time step and accuracy")


@pytest.mark.parametrize("old, new, words", [
    pytest.param('dt_s = { value = 0.001, grade = "assumed"', 'dt_s = { value = 0.001, grade = "guessed"',
                 ("simulation.dt_s", "'guessed'", "grade"), id="bad grade"),
    pytest.param("[simulation]\n", '[simulation]\ndt_ms = { value = 1.0, grade = "assumed", source = "assumed" }\n',
                 ("'dt_ms'", "[simulation]", "unknown key"), id="unknown key"),
    pytest.param("[contacts.buttock_r]\n",
                 '[contacts.buttock_r]\nstifness_N_per_m = { value = 1.0, grade = "assumed", source = "assumed" }\n',
                 ("'stifness_N_per_m'", "contacts.buttock_r"), id="unknown key in a contact"),
    pytest.param("[contacts.buttock_r]\nstiffness_N_per_m = { value = 70650.0",
                 "[contacts.buttock_r]\nstiffness_N_per_m = { value = -70650.0",
                 ("contacts.buttock_r.stiffness_N_per_m", "-70650.0", "positive"), id="negative contact stiffness"),
    pytest.param("roll = { stiffness_Nm_per_rad = 40.0,", "roll = { stiffness_Nm_per_rad = -90.0,",
                 ("joints.upper_neck.roll.stiffness_Nm_per_rad", "-90.0", "negative"), id="negative joint stiffness"),
    pytest.param('dt_s = { value = 0.001, grade = "assumed", source = "convergence" }',
                 'dt_s = { value = 0.001, grade = "assumed", source = "nowhere" }',
                 ("simulation.dt_s", "'nowhere'", "[sources]"), id="unknown source"),
    pytest.param('settle_s = { value = 10.0, grade = "assumed", source = "assumed" }',
                 'settle_s = { value = 10.0, grade = "assumed", source = "assumed"', ("TOML",), id="invalid TOML"),
])
def test_one_bad_edit_one_sentence(tmp_path, old, new, words):
    msg = _load_error(tmp_path, _replace_once(old, new))
    for w in words:
        assert w in msg, (w, msg)


def test_missing_file_names_it(tmp_path):
    path = tmp_path / "absent.toml"
    with pytest.raises(InputError, match="absent.toml"):
        Parameters.load(path)


def test_export_load_round_trip_every_numeric_value(tmp_path):
    p = Parameters.load()
    paths = list(p.numeric_paths())
    # The default file holds 7 simulation + 2 posture (integral time, supported tone) + 12 seat values, 25 joint DOFs
    # x 2 (t12 z counts as one DOF), 6 padded contacts x 6 + 2 feet x 3 + 4 bolster contacts x 3 values, 2 postures
    # x 7 angles and slide, the slouched posture's tone, the head-in-space control's 4 gains, and the vibration
    # level's 5 values ([level]: reference, two exponents, the clip's two ends): 21 + 50 + 54 + 14 + 1 + 4 + 5 = 149.
    assert len(paths) == 149
    out = tmp_path / "exported.toml"
    p.export(out)
    q = Parameters.load(out)
    assert list(q.numeric_paths()) == paths
    for path in paths:
        a, b = p.value(path), q.value(path)
        assert type(a) is type(b), path
        assert a == b, path  # exact: TOML floats round-trip bit for bit
    assert q.value("posture.integral_joints") == p.value("posture.integral_joints")
    assert q.data == p.data


def test_with_values_changes_a_copy():
    p = Parameters.load()
    q = p.with_values({"contacts.buttock_r.stiffness_N_per_m": 90000.0,
                       "joints.t12.z.stiffness_N_per_m": 12000.0}, grade="identified", source="tuned")
    assert q.value("contacts.buttock_r.stiffness_N_per_m") == 90000.0
    assert q.value("joints.t12.z.stiffness_N_per_m") == 12000.0
    assert q.joint_dof("t12", "z") == (12000.0 * q.tone(), p.joint_dof("t12", "z")[1])  # damping untouched; x tone
    assert q.data["contacts"]["buttock_r"]["stiffness_N_per_m"]["grade"] == "identified"
    shipped = tomllib.loads(default_params_path().read_text())["contacts"]["buttock_r"]["stiffness_N_per_m"]["value"]
    assert p.value("contacts.buttock_r.stiffness_N_per_m") == shipped != 90000.0  # original untouched


@pytest.mark.parametrize("path", ["contacts.buttock_r.stifness_N_per_m", "joints.elbow.pitch.stiffness_Nm_per_rad",
                                  "simulation.dt", "contacts.buttock_r.stiffness_N_per_m.grade"])
def test_with_values_unknown_path(path):
    with pytest.raises(InputError) as exc:
        Parameters.load().with_values({path: 1.0})
    assert "unknown parameter" in str(exc.value)
    assert repr(path) in str(exc.value)


def test_with_values_on_a_section_path_is_refused():
    # A section is not a value: replacing [seat] by a number must not be accepted.
    with pytest.raises(InputError, match="seat"):
        Parameters.load().with_values({"seat": 1.0})


def test_with_values_rechecks_values():
    with pytest.raises(InputError, match="simulation.dt_s"):
        Parameters.load().with_values({"simulation.dt_s": -0.001})
    with pytest.raises(InputError, match="contact_impedance"):
        Parameters.load().with_values({"simulation.contact_impedance": 1.5})
    with pytest.raises(InputError, match="not a finite number"):
        Parameters.load().with_values({"seat.pan_angle_deg": math.nan})


def test_back_slide_longer_than_settling_is_refused(tmp_path):
    msg = _load_error(tmp_path, _replace_once("back_slide_s = { value = 5.0,", "back_slide_s = { value = 10.0,"))
    assert "simulation.back_slide_s" in msg and "settle_s" in msg and "shorter" in msg


def test_file_without_back_slide_loads_with_no_sliding(tmp_path):
    # Files exported before back_slide_s existed leave it out: they load, and settling keeps friction on
    # throughout (the behaviour they were made with).
    line = next(ln for ln in DEFAULT_TEXT.splitlines(keepends=True) if ln.startswith("back_slide_s ="))
    p = Parameters.load(_write(tmp_path, _replace_once(line, "")))
    assert p.value("simulation.back_slide_s") == 0.0
    assert Parameters.load().value("simulation.back_slide_s") == 5.0


def test_left_out_back_slide_is_filled_in_with_provenance(tmp_path):
    line = next(ln for ln in DEFAULT_TEXT.splitlines(keepends=True) if ln.startswith("back_slide_s ="))
    p = Parameters.load(_write(tmp_path, _replace_once(line, "")))
    assert p.provenance("simulation.back_slide_s") == ("assumed", "ehm")
    assert p.with_values({"simulation.back_slide_s": 1.0}).value("simulation.back_slide_s") == 1.0
    out = tmp_path / "exported.toml"
    p.export(out)
    assert Parameters.load(out).value("simulation.back_slide_s") == 0.0


@pytest.mark.parametrize("name", ['""', '"a.b"', '"../up"', '"a/b"', '"with space"'])
def test_a_posture_name_with_a_dot_or_path_characters_is_refused(tmp_path, name):
    """Issue 38: a posture named '' or with a dot in a parameter file ended in a KeyError in Parameters.section
    (its name is part of dotted paths such as postures.NAME.dt_s); refused now in one sentence naming it."""
    path = tmp_path / "postures.toml"
    text = default_params_path().read_text()
    assert "[postures.slouched]" in text
    path.write_text(text.replace("[postures.slouched]", f"[postures.{name}]"))
    with pytest.raises(InputError, match=r"posture name .* must be letters, digits, '_' or '-'") as info:
        Parameters.load(path)
    assert "\n" not in str(info.value) and str(path) in str(info.value)


def test_a_posture_name_of_letters_digits_and_dashes_is_read(tmp_path):
    path = tmp_path / "postures.toml"
    path.write_text(default_params_path().read_text().replace("[postures.slouched]", "[postures.slouched-2_b]"))
    assert "slouched-2_b" in Parameters.load(path).postures()


@pytest.mark.parametrize("name, words", [("postures.a.b", "unknown parameter section 'postures.a.b' (no 'a')"),
                                         ("nosuch", "unknown parameter section"), ("", "unknown parameter section"),
                                         ("simulation.dt_s", "is a parameter, not a section")])
def test_a_section_that_is_none_is_one_sentence(name, words):
    with pytest.raises(InputError) as info:
        Parameters.load().section(name)
    assert words in str(info.value)


@pytest.mark.parametrize("delay_s, words", [(1e7, "is longer than 10 s"), (0.0, "must be positive"),
                                           (-0.03, "must be positive")])
def test_a_head_control_delay_out_of_range_is_one_sentence(delay_s, words):
    """Issue 38: a head-control delay of 1e7 s overflowed an integer inside MuJoCo (a TypeError from its bindings);
    refused now when the parameters are changed, before anything is built."""
    with pytest.raises(InputError, match=f"head_control.delay_s = .* {words}"):
        Parameters.load().with_head_control({"delay_s": delay_s})


def test_trunk_tone_multiplies_the_trunk_joints_per_posture_and_back_support():
    # the file keeps the values at tone 1; joint_dof gives them as seated: the posture's tone times supported_tone
    # when the backrest carries the upper back; the joints outside tone_joints keep theirs
    p = Parameters.load().with_values({"postures.slouched.tone": 0.7, "posture.supported_tone": 0.9})
    raw = p.data["joints"]["l4_l5"]["pitch"]
    for posture, support, tone in (("erect", "none", 1.0), ("erect", "low", 1.0), ("erect", "high", 0.9),
                                   ("erect", "full", 0.9), ("slouched", "none", 0.7), ("slouched", "high", 0.63)):
        q = p.seated(posture, support)
        assert q.tone() == pytest.approx(tone)
        k, c = q.joint_dof("l4_l5", "pitch")
        assert (k, c) == pytest.approx((tone * raw["stiffness_Nm_per_rad"], tone * raw["damping_Nms_per_rad"]))
        k, c = q.joint_dof("t12", "z")  # the spine's vertical slide too: the trunk's muscles act beside the discs
        assert (k, c) == pytest.approx((tone * p.data["joints"]["t12"]["z"]["stiffness_N_per_m"],
                                        tone * p.data["joints"]["t12"]["z"]["damping_Ns_per_m"]))
        assert q.joint_dof("upper_neck", "pitch") == p.joint_dof("upper_neck", "pitch")
        assert "tone" not in q.posture_angles()


@pytest.mark.parametrize("path, value", [("postures.slouched.tone", 0.0), ("posture.supported_tone", 50.0)])
def test_an_implausible_tone_is_one_sentence(path, value):
    with pytest.raises(InputError, match=r"is not a plausible muscle tone factor: give one from 0\.1 to 10"):
        Parameters.load().with_values({path: value})


def test_a_file_without_tone_keeps_its_joints(tmp_path):
    # a file exported before the tone existed: no [posture] tone entries, no posture tone; every joint as written
    text = default_params_path().read_text()
    text = "\n".join(line for line in text.splitlines()
                     if not line.startswith(("tone_joints", "supported_tone", "tone =")))
    (tmp_path / "old.toml").write_text(text)
    p = Parameters.load(tmp_path / "old.toml").seated("slouched", "high")
    assert p.tone() == 1.0
    raw = p.data["joints"]["t12"]["pitch"]
    assert p.joint_dof("t12", "pitch") == (raw["stiffness_Nm_per_rad"], raw["damping_Nms_per_rad"])
