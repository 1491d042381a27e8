"""Body tables (paper Tables 1 and 2) and their compiled MuJoCo form, checked against the paper.

Independent source of every expected number: Desai et al., "Computationally efficient human body
modelling for real time motion comfort assessment" (/work/shared/paper/efficient-human-model-paper.md),
Table 1 (joints) and Table 2 (segments), typed in below by hand.  The paper's y axis points to the
person's right (its right-side rows have +y); this project's y axis points LEFT, so every paper y value
is negated (y_here = -y_paper; midline rows have y = 0 either way).  Mirroring y leaves the principal
moments of inertia unchanged.

The compiled model is read through MuJoCo only (body masses, inertial frames after ``mj_forward``), not
through the loader, so a loader or builder mistake cannot cancel out.
"""

from __future__ import annotations

import re
from pathlib import Path

import mujoco
import numpy as np
import pytest

from ehm.body.tables import load_body, load_joints, load_segments
from ehm.errors import InputError

DATA = Path(__file__).resolve().parents[1] / "src" / "ehm" / "data"

# Paper Table 2: name -> (mass [kg], (Ixx, Iyy, Izz) [kg m^2], (x, y, z) [cm] in the PAPER's axes).
PAPER_TABLE2 = {
    "head": (6.23, (0.031, 0.031, 0.020), (-5.461, 0, 69.104)),
    "neck": (1.6, (0.003, 0.004, 0.005), (-9.420, 0, 57.393)),
    "upper_torso": (8.93, (0.238, 0.146, 0.181), (-8.231, 0, 34.692)),
    "middle_torso": (7.7, (0.238, 0.146, 0.181), (-3.827, 0, 15.927)),
    "lower_torso": (10.70, (0.137, 0.078, 0.117), (0.2164, 0, 5.172)),
    "pelvis": (10.93, (0.115, 0.050, 0.151), (0, 0, 0)),
    "thigh_r": (7.7, (0.007, 0.129, 0.129), (21.859, 11.24, 3.450)),
    "thigh_l": (7.7, (0.007, 0.129, 0.129), (21.859, -11.24, 3.450)),
    "leg_r": (3.58, (0.031, 0.031, 0.020), (55.405, 14.8, -9.823)),
    "leg_l": (3.58, (0.031, 0.031, 0.020), (55.405, -14.8, -9.823)),
    "foot_r": (1.116, (0.001, 0.005, 0.004), (75.409, 16.59, -31.332)),
    "foot_l": (1.116, (0.001, 0.005, 0.004), (75.409, -16.59, -31.332)),
}

# Paper Table 1: name -> (connected segments, paper joint type, (x, y, z) [cm] in the PAPER's axes).
PAPER_TABLE1 = {
    "upper_neck": ({"head", "neck"}, "Spherical", (-8.85, 0, 63.04)),
    "lower_neck": ({"neck", "upper_torso"}, "Universal", (-10.85, 0, 51.39)),
    "t12": ({"upper_torso", "middle_torso"}, "Spherical + Trans", (-16.01, 0, 22.90)),
    "l4_l5": ({"middle_torso", "lower_torso"}, "Spherical", (-12.50, 0, 8.14)),
    "waist": ({"lower_torso", "pelvis"}, "Spherical (Lock)", (-7.95, 0, -0.21)),
    "hip_r": ({"pelvis", "thigh_r"}, "Spherical", (2.54, 8.86, 1.78)),
    "hip_l": ({"pelvis", "thigh_l"}, "Spherical", (2.54, -8.86, 1.78)),
    "knee_r": ({"thigh_r", "leg_r"}, "Revolute", (43.08, 14.01, 8.65)),
    "knee_l": ({"thigh_l", "leg_l"}, "Revolute", (43.08, -14.01, 8.65)),
    "ankle_r": ({"leg_r", "foot_r"}, "Revolute", (69.40, 15.75, -30.67)),
    "ankle_l": ({"leg_l", "foot_l"}, "Revolute", (69.40, -15.75, -30.67)),
}
# Paper joint-type wording -> this project's type names (paper section 2).
PAPER_TYPE = {"Spherical": "spherical", "Spherical (Lock)": "spherical", "Universal": "universal",
              "Spherical + Trans": "spherical_vertical", "Revolute": "revolute"}

# Sum of the paper's Table 2 mass column, added by hand:
# 6.23 + 1.6 + 8.93 + 7.7 + 10.70 + 10.93 + 2 * (7.7 + 3.58 + 1.116) = 70.882 kg.
PAPER_TOTAL_MASS_KG = 70.882

MASS_TOL_KG = 1e-9
POS_TOL_M = 1e-6
INERTIA_TOL_KGM2 = 1e-9


def here_m(paper_cm) -> np.ndarray:
    """Paper coordinates [cm] -> this project's axes [m] (y mirrored)."""
    x, y, z = paper_cm
    return np.array([x, -y, z]) * 0.01



@pytest.fixture(scope="module")
def compiled(human):
    """MjModel and a fresh MjData at qpos0 (the reference posture), after mj_forward."""
    m = human.model.mj
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    return m, d


def composite(m, d, body_ids):
    """Mass [kg], centre of mass [m] and inertia tensor about it [kg m^2, world axes] of a group of bodies.

    Each body's inertia is rotated to world axes with its inertial frame d.ximat and moved to the group's
    centre of mass with the parallel-axis theorem.
    """
    ids = list(body_ids)
    masses = m.body_mass[ids]
    mass = float(masses.sum())
    com = (masses[:, None] * d.xipos[ids]).sum(axis=0) / mass
    inertia = np.zeros((3, 3))
    for b in ids:
        rot = d.ximat[b].reshape(3, 3)
        r = d.xipos[b] - com
        inertia += rot @ np.diag(m.body_inertia[b]) @ rot.T + m.body_mass[b] * (r @ r * np.eye(3) - np.outer(r, r))
    return mass, com, inertia


# ----------------------------------------------------------------------------- the tables as loaded


def test_paper_table2_total_mass_is_70_882_kg():
    # Source: paper Table 2 mass column summed by hand (see PAPER_TOTAL_MASS_KG); tolerance 1e-9 kg.
    assert sum(v[0] for v in PAPER_TABLE2.values()) == pytest.approx(PAPER_TOTAL_MASS_KG, abs=MASS_TOL_KG)
    assert load_body().mass_kg == pytest.approx(PAPER_TOTAL_MASS_KG, abs=MASS_TOL_KG)


def test_loaded_segments_match_paper_table2():
    # Source: paper Table 2; tolerances 1e-9 kg, 1e-9 kg m^2, 1e-6 m.
    segs = {s.name: s for s in load_segments()}
    assert set(segs) == set(PAPER_TABLE2)
    for name, (mass, inertia, com_cm) in PAPER_TABLE2.items():
        s = segs[name]
        assert s.mass_kg == pytest.approx(mass, abs=MASS_TOL_KG), name
        np.testing.assert_allclose(s.inertia_kgm2, inertia, rtol=0, atol=INERTIA_TOL_KGM2, err_msg=name)
        np.testing.assert_allclose(s.com_m, here_m(com_cm), rtol=0, atol=POS_TOL_M, err_msg=name)


def test_loaded_joints_match_paper_table1():
    # Source: paper Table 1 (segments joined, type, position); tolerance 1e-6 m.  The paper locks only the
    # waist ("Spherical (Lock)").
    joints = {j.name: j for j in load_joints()}
    assert set(joints) == set(PAPER_TABLE1)
    for name, (segments, ptype, pos_cm) in PAPER_TABLE1.items():
        j = joints[name]
        assert {j.parent, j.child} == segments, name
        assert j.type == PAPER_TYPE[ptype], name
        assert j.locked == ("Lock" in ptype), name
        np.testing.assert_allclose(j.pos_m, here_m(pos_cm), rtol=0, atol=POS_TOL_M, err_msg=name)


# ----------------------------------------------------------------------------- the compiled model


def test_compiled_total_mass_is_70_882_kg(human, compiled):
    # Source: paper Table 2 sum; read as the sum of every non-world, non-seat body mass in the MjModel.
    m, _ = compiled
    human_bodies = [b for ids in human.model.segment_bodies.values() for b in ids]
    assert len(set(human_bodies)) == len(human_bodies)
    assert float(m.body_mass[human_bodies].sum()) == pytest.approx(PAPER_TOTAL_MASS_KG, abs=MASS_TOL_KG)
    assert float(m.body_mass.sum()) == pytest.approx(PAPER_TOTAL_MASS_KG, abs=MASS_TOL_KG)  # seat bodies weigh 0
    assert human.mass_kg == pytest.approx(PAPER_TOTAL_MASS_KG, abs=MASS_TOL_KG)


@pytest.mark.parametrize("segment", list(PAPER_TABLE2))
def test_compiled_segment_mass_matches_paper_table2(human, compiled, segment):
    # Source: paper Table 2 mass; the segment body plus its soft-tissue pad bodies; tolerance 1e-9 kg.
    m, d = compiled
    mass, _, _ = composite(m, d, human.model.segment_bodies[segment])
    assert mass == pytest.approx(PAPER_TABLE2[segment][0], abs=MASS_TOL_KG)


@pytest.mark.parametrize("segment", list(PAPER_TABLE2))
def test_compiled_segment_centre_of_gravity_matches_paper_table2(human, compiled, segment):
    # Source: paper Table 2 coordinates (y mirrored); mass-weighted mean of d.xipos over the segment body and
    # its pads at qpos0 (the reference posture); tolerance 1e-6 m.
    m, d = compiled
    _, com, _ = composite(m, d, human.model.segment_bodies[segment])
    np.testing.assert_allclose(com, here_m(PAPER_TABLE2[segment][2]), rtol=0, atol=POS_TOL_M)


@pytest.mark.parametrize("segment", list(PAPER_TABLE2))
def test_compiled_segment_inertia_matches_paper_table2(human, compiled, segment):
    # Source: paper Table 2 moments of inertia about the segment's centre of gravity, axes parallel to the
    # global axes (so the tensor is diagonal).  Composite of segment body + pads built in world axes from
    # d.ximat, m.body_inertia and parallel-axis terms about the composite centre of mass at qpos0;
    # tolerance 1e-9 kg m^2.  The pelvis carries three pads (two buttocks, lower back), the upper torso and each
    # thigh one.
    m, d = compiled
    _, _, inertia = composite(m, d, human.model.segment_bodies[segment])
    np.testing.assert_allclose(inertia, np.diag(PAPER_TABLE2[segment][1]), rtol=0, atol=INERTIA_TOL_KGM2)


def test_pelvis_has_pads(human):
    # The composite checks above are only meaningful if some segments really are split into several bodies.
    # pelvis + two buttock pads + the lower back pad (contacts.csv)
    assert len(human.model.segment_bodies["pelvis"]) == 4


@pytest.mark.parametrize("joint", list(PAPER_TABLE1))
def test_compiled_joint_positions_match_paper_table1(human, compiled, joint):
    # Source: paper Table 1 (y mirrored).  Each segment body's frame sits at its parent joint, so at qpos0 the
    # child body's d.xpos is the joint centre; for unlocked joints every MuJoCo hinge/slide anchor
    # (d.xanchor) must be there as well.  Tolerance 1e-6 m.
    m, d = compiled
    segments, _, pos_cm = PAPER_TABLE1[joint]
    expected = here_m(pos_cm)
    child = human.body.joint(joint).child
    assert {human.body.joint(joint).parent, child} == segments
    np.testing.assert_allclose(d.xpos[human.model.segment_bodies[child][0]], expected, rtol=0, atol=POS_TOL_M)
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(m.njnt)]
    mine = [j for j, n in enumerate(names) if n and n.startswith(joint + ".")]
    if joint in human.model.locked:
        assert mine == []
    else:
        assert mine
        for j in mine:
            np.testing.assert_allclose(d.xanchor[j], expected, rtol=0, atol=POS_TOL_M, err_msg=names[j])


# ----------------------------------------------------------------------------- bad data files


def _lineno(text: str, prefix: str) -> int:
    """1-based line number of the first line starting with ``prefix``."""
    for i, line in enumerate(text.splitlines(), start=1):
        if line.startswith(prefix):
            return i
    raise AssertionError(f"no line starts with {prefix!r}")


def _edit_row(text: str, prefix: str, column: str, value: str) -> tuple[str, int]:
    """Replace one field of the row starting with ``prefix``; return the new text and that row's line."""
    lines = text.splitlines()
    header_i = next(i for i, ln in enumerate(lines) if ln and not ln.startswith("#"))
    header = lines[header_i].split(",")
    n = _lineno(text, prefix)
    fields = lines[n - 1].split(",")
    fields[header.index(column)] = value
    lines[n - 1] = ",".join(fields)
    return "\n".join(lines) + "\n", n


def _drop_column(text: str, column: str) -> str:
    lines = text.splitlines()
    header_i = next(i for i, ln in enumerate(lines) if ln and not ln.startswith("#"))
    k = lines[header_i].split(",").index(column)
    out = []
    for i, ln in enumerate(lines):
        if i >= header_i and ln.strip():
            f = ln.split(",")
            del f[k]
            ln = ",".join(f)
        out.append(ln)
    return "\n".join(out) + "\n"


SEGMENTS_TEXT = (DATA / "segments.csv").read_text(encoding="utf-8")
JOINTS_TEXT = (DATA / "joints.csv").read_text(encoding="utf-8")


def test_joint_axes_follow_axes_pitch(human, compiled):
    # joints.csv: the lower neck's axes are turned 30 deg about y (roll axis front end down, so lateral bending
    # carries same-side axial rotation); every other joint keeps roll about x, pitch about y, yaw about z.
    # Read back from MuJoCo's world-frame hinge axes at qpos0; tolerance 1e-9.
    m, d = compiled
    t = np.radians(30.0)
    expected = {"roll": [np.cos(t), 0, -np.sin(t)], "pitch": [0, 1, 0], "yaw": [np.sin(t), 0, np.cos(t)]}
    plain = {"roll": [1, 0, 0], "pitch": [0, 1, 0], "yaw": [0, 0, 1]}
    checked = 0
    for j in range(m.njnt):
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) or ""
        joint, _, dof = name.partition(".")
        if dof not in plain or joint not in {jt.name for jt in human.body.joints}:
            continue
        want = expected[dof] if joint == "lower_neck" else plain[dof]
        np.testing.assert_allclose(d.xaxis[j], want, rtol=0, atol=1e-9, err_msg=name)
        checked += 1
    assert checked == sum(len(jt.dofs) for jt in human.body.joints if jt.name not in human.model.locked
                          and jt.type != "spherical_vertical") + 3  # t12: roll, pitch, yaw hinges besides its slide


def test_joint_table_without_axes_pitch_column_keeps_plain_axes(tmp_path):
    path = tmp_path / "joints.csv"
    path.write_text(_drop_column(JOINTS_TEXT, "axes_pitch_deg"), encoding="utf-8")
    assert all(j.axes_pitch_rad == 0.0 for j in load_joints(path))
    assert {j.name: j.axes_pitch_rad for j in load_joints()}["lower_neck"] == pytest.approx(np.radians(30.0))


@pytest.mark.parametrize("row, column, value, words", [
    ("neck,", "mass_kg", "-1.6", "must be positive"),                 # negative mass
    ("leg_r,", "iyy_kgm2", "0", "must be positive"),                  # zero inertia
    ("upper_torso,", "com_z_cm", "abc", "is not a number"),            # non-numeric value
    ("head,", "ixx_kgm2", "0.1", "triangle inequality"),               # 0.031 + 0.020 < 0.1
])
def test_bad_segment_value_names_file_and_line(tmp_path, row, column, value, words):
    text, line = _edit_row(SEGMENTS_TEXT, row, column, value)
    path = tmp_path / "bad_segments.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(InputError) as exc:
        load_body(segments=path)
    msg = str(exc.value)
    assert "bad_segments.csv" in msg
    assert re.search(rf"\bline {line}\b", msg), msg
    assert words in msg


def test_segments_missing_column_names_file_and_column(tmp_path):
    path = tmp_path / "bad_segments.csv"
    path.write_text(_drop_column(SEGMENTS_TEXT, "izz_kgm2"), encoding="utf-8")
    with pytest.raises(InputError) as exc:
        load_body(segments=path)
    msg = str(exc.value)
    assert "bad_segments.csv" in msg
    assert "izz" in msg and "missing column" in msg


@pytest.mark.parametrize("row, column, value, words", [
    ("t12,", "type", "ball", "'ball'"),                                    # unknown joint type
    ("lower_neck,", "axes_pitch_deg", "95", "between -90 and 90"),        # axes tilted past vertical
    ("lower_neck,", "axes_pitch_deg", "abc", "is not a number"),
])
def test_bad_joint_value_names_file_line_and_column(tmp_path, row, column, value, words):
    text, line = _edit_row(JOINTS_TEXT, row, column, value)
    path = tmp_path / "bad_joints.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(InputError) as exc:
        load_body(joints=path)
    msg = str(exc.value)
    assert "bad_joints.csv" in msg and re.search(rf"\bline {line}\b", msg), msg
    assert words in msg and (column == "type" or column in msg), msg


def test_joint_with_unknown_segment_names_file_and_line(tmp_path):
    text, line = _edit_row(JOINTS_TEXT, "knee_r,", "child", "shin_r")
    path = tmp_path / "bad_joints.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(InputError) as exc:
        load_body(joints=path)
    msg = str(exc.value)
    assert "shin_r" in msg
    # The module contract (tables.py docstring): problems name the file and line.
    assert "bad_joints.csv" in msg and re.search(rf"\bline {line}\b", msg), msg


def test_unedited_copies_load(tmp_path):
    # Control for the tests above: the unchanged copies written the same way load without error.
    seg = tmp_path / "segments_copy.csv"
    jnt = tmp_path / "joints_copy.csv"
    seg.write_text(SEGMENTS_TEXT, encoding="utf-8")
    jnt.write_text(JOINTS_TEXT, encoding="utf-8")
    body = load_body(segments=seg, joints=jnt)
    assert body.mass_kg == pytest.approx(PAPER_TOTAL_MASS_KG, abs=MASS_TOL_KG)
