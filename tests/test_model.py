"""The compiled seated human: degrees of freedom, statics, posture, contact law, determinism, divergence.

One default model is built and settled once for the module; tests that need other parameters build their own.
Each expected value names its independent source and a tolerance in physical units.
"""

from __future__ import annotations

import re

import mujoco
import numpy as np
import pytest

from ehm import engine
from ehm.body.params import Parameters
from ehm.body.timestep import StepWarning
from ehm.engine.sensors import contact_name
from ehm.errors import DivergenceError, InputError
from ehm.inputs.motion import random_vibration
from ehm.simulation import POINT_NAMES, SeatedHuman

G = 9.81  # m/s^2, the project's standard gravity (engine.G0), also the paper's MADYMO default
PAPER_TOTAL_MASS_KG = 70.882  # paper Table 2, sum of the mass column

# Degrees of freedom per joint type, from the paper (section 2 and 2.1): "each spherical joint has 3 DoF,
# each revolute or translational joint has 1 DoF"; the lower-neck universal joint captures "roll-pitch
# motion" (2); T12 is "spherical-translational" (3 + 1 = 4); the free pelvis has 6.
DOF_PER_TYPE = {"spherical": 3, "universal": 2, "spherical_vertical": 4, "revolute": 1}
PAPER_JOINT_TYPES = {  # paper Table 1
    "upper_neck": "spherical", "lower_neck": "universal", "t12": "spherical_vertical", "l4_l5": "spherical",
    "waist": "spherical", "hip_r": "spherical", "hip_l": "spherical", "knee_r": "revolute",
    "knee_l": "revolute", "ankle_r": "revolute", "ankle_l": "revolute",
}


def expected_dof(locked: set[str]) -> int:
    return 6 + sum(DOF_PER_TYPE[t] for j, t in PAPER_JOINT_TYPES.items() if j not in locked)



def _geom(m, name: str) -> int:
    gid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, name)
    assert gid >= 0, name
    return gid


def _contact_forces(m, d):
    """(surface geom name, body geom name) -> (normal force [N], dist [m], normal velocity [m/s],
    force on the body in world axes [N]) for every active contact, via mj_contactForce."""
    out = {}
    for i in range(d.ncon):
        c = d.contact[i]
        f = np.zeros(6)
        mujoco.mj_contactForce(m, d, i, f)
        # contact.frame rows are the normal (pointing from geom1 to geom2) and two tangents, so frame^T f is
        # the force that geom1 (the seat surface) exerts on geom2 (the body ellipsoid), world axes.
        world = c.frame.reshape(3, 3).T @ f[:3]
        key = (mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, c.geom1),
               mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, c.geom2))
        assert key not in out, key
        out[key] = (f[0], c.dist, d.efc_vel[c.efc_address], world)
    return out


# ----------------------------------------------------------------------------- degrees of freedom


@pytest.mark.parametrize("lock, unlock, dof", [
    ((), (), 28),                 # 31 (paper) - 3 (waist locked by default)
    ((), ("waist",), 31),         # the paper's full 31 DoF
    (("t12",), (), 24),           # 28 - 4 (spherical + vertical translation)
    (("lower_neck",), (), 26),    # 28 - 2 (universal)
])
def test_degrees_of_freedom(lock, unlock, dof):
    h = SeatedHuman(lock=lock, unlock=unlock)
    locked = ({"waist"} | set(lock)) - set(unlock)
    assert expected_dof(locked) == dof
    assert h.dof == dof
    # Independent route: MuJoCo's own count, minus the two tangential slides of each of the 6 tissue pads
    # (contacts.csv: buttock_r, buttock_l, thigh_r, thigh_l, lower_back, upper_back have tissue_pad = 1).
    assert h.model.mj.nv - 2 * 6 == dof
    joints = {j["name"]: j for j in h.info()["joints"]}
    for name, jtype in PAPER_JOINT_TYPES.items():
        if name in locked:
            assert joints[name]["locked"] is True and joints[name]["dof"] == 0, name
        else:
            assert joints[name]["locked"] is False and joints[name]["dof"] == DOF_PER_TYPE[jtype], name
    assert h.info()["dof"] == dof
    assert sorted(h.info()["locked"]) == sorted(locked)


def test_unknown_joint_name_is_refused():
    with pytest.raises(InputError, match="elbow"):
        SeatedHuman(lock=["elbow"])
    with pytest.raises(InputError, match="elbow"):
        SeatedHuman(unlock=["elbow"])


# ----------------------------------------------------------------------------- statics


def test_static_equilibrium_mean_support_force_equals_weight(human):
    # Newton: at rest the supports carry the weight, m g = 70.882 kg x 9.81 m/s^2 = 695.35 N straight up
    # (mass from paper Table 2).  Tolerance 1 % of the weight (6.95 N) on each component.
    run = human.simulate(random_vibration("z", 2, 0.0, seed=0), method="nonlinear")
    weight = PAPER_TOTAL_MASS_KG * G
    mean = run.support_total_N().mean(axis=0)
    np.testing.assert_allclose(mean, [0.0, 0.0, weight], rtol=0, atol=0.01 * weight)
    # The run's own summary reports the same thing, from other sums: 1e-9 N is above the worst-case round-off
    # of either (the weight: ~30 segment masses, ~30 eps x 695 N = 5e-12 N; the means: 2001 samples summed in
    # another order, n eps |f| = 3e-10 N; measured 1.1e-13 and 1.1e-12 N).
    s = run.summary()
    assert s["body_weight_N"] == pytest.approx(weight, abs=1e-9)
    np.testing.assert_allclose(s["support_force_mean_N"], mean, rtol=0, atol=1e-9)


def test_contact_forces_by_hand_equal_support_forces(human):
    # Independent route: mj_contactForce per contact, rotated to world axes with contact.frame and summed by
    # seat surface, against engine.support_forces (cfrc_ext of the surface bodies).  Tolerance 1e-6 N.
    m = human.model.mj
    d = engine.settled_data(human.model)
    forces = _contact_forces(m, d)
    sf = engine.support_forces(human.model, d)
    # every surface named in the contact table (contacts.csv) is a seat body with its own force
    surfaces = {c.surface for c in human.body.contacts}
    assert set(sf) == surfaces
    for surface in surfaces:
        by_hand = sum((v[3] for (s, _), v in forces.items() if s == surface), np.zeros(3))
        np.testing.assert_allclose(sf[surface], by_hand, rtol=0, atol=1e-6, err_msg=surface)
    # At rest every contact is closed except the side bolsters, which sit a gap away from the body
    # (contacts.csv: hip_side_*, back_side_*; [seat] bolster_gap_m) and carry load only in sustained
    # lateral acceleration.
    bolsters = {c.name for c in human.body.contacts if "bolster" in c.surface}
    assert len(bolsters) == 4
    assert {g2 for _, g2 in forces} == {c.name for c in human.body.contacts} - bolsters
    total = sum(sf.values())
    np.testing.assert_allclose(total, [0, 0, PAPER_TOTAL_MASS_KG * G], rtol=0, atol=0.01 * PAPER_TOTAL_MASS_KG * G)


def test_posture_holds_for_60_s(human):
    # Paper section 2: the PID posture control's integral action removes postural drift.  After settling,
    # 60 s without input: head, trunk and pelvis rotate < 0.1 deg; the pelvis moves < 1 mm.
    motion = random_vibration("z", 60, 0.0, seed=0, dt_s=human.model.mj.opt.timestep)
    run = human.simulate(motion, method="nonlinear")
    assert run.time_s.shape == (motion.n_samples,) and run.time_s[-1] >= 60.0 - 1e-9
    for p in POINT_NAMES:
        drift_deg = np.degrees(np.abs(run.point(p).rot_rad).max())
        assert drift_deg < 0.1, (p, drift_deg)
    pelvis_mm = 1000 * np.linalg.norm(run.point("pelvis").disp_m, axis=1).max()
    assert pelvis_mm < 1.0


# ----------------------------------------------------------------------------- contact law


def _spring_ratio(model, contact: str) -> tuple[float, float, float]:
    """(normal force / penetration [N/m], normal force [N], damping share of it) of one contact, settled."""
    m = model.mj
    d = engine.settled_data(model)
    forces = _contact_forces(m, d)
    surface = next(c.surface for c in model.body.contacts if c.name == contact)
    fn, dist, vn, _ = forces[(surface, contact)]
    assert dist < 0  # contact.dist is minus the penetration
    damping = float(model.params.value(f"contacts.{contact}.damping_Ns_per_m"))
    return fn / -dist, fn, abs(damping * vn) / fn


@pytest.mark.parametrize("stiffness", [None, 60000.0, 240000.0])
def test_buttock_contact_is_a_linear_spring(human, stiffness):
    # (the right buttock; the left one is its mirror image)
    # Paper section 2: contacts are "linear force-deflection characteristics with stiffness in N/m".  At rest
    # the damper carries nothing, so normal force / penetration must equal the configured stiffness
    # (default 60 kN/m, then two other values in fresh builds).  Tolerance 2 %.
    if stiffness is None:
        model = human.model
        stiffness = float(model.params.value("contacts.buttock_r.stiffness_N_per_m"))
    else:
        params = Parameters.load().with_values({"contacts.buttock_r.stiffness_N_per_m": stiffness})
        model = SeatedHuman(params).model
        engine.settle(model)
    ratio, fn, damping_share = _spring_ratio(model, "buttock_r")
    assert damping_share < 0.002  # velocities ~ 0: the damper carries < 0.2 % of the force
    assert fn > 100.0  # the buttock carries a real share of the 695 N weight
    assert ratio == pytest.approx(stiffness, rel=0.02)


@pytest.mark.parametrize("contact", ["buttock_r", "buttock_l", "thigh_r", "thigh_l", "lower_back", "upper_back",
                                     "foot_r", "foot_l"])
def test_every_contact_spring_has_its_configured_stiffness(human, contact):
    # Same law as above for every contact pair of the default model, each against ITS OWN entry in
    # default_params.toml (contacts.<name>.stiffness_N_per_m).  Tolerance 2 %.
    stiffness = float(human.params.value(f"contacts.{contact}.stiffness_N_per_m"))
    ratio, _, damping_share = _spring_ratio(human.model, contact)
    assert damping_share < 0.002
    assert ratio == pytest.approx(stiffness, rel=0.02), f"{contact}: {ratio:.0f} N/m, configured {stiffness:.0f} N/m"


@pytest.mark.parametrize("contact", ["buttock_r", "thigh_l", "lower_back", "upper_back", "foot_r"])
def test_contact_rows_carry_the_intended_law(human, contact):
    # engine.contact_solver_params, checked on MuJoCo's own constraint rows against the hand formulas
    # (README "Time step and accuracy"): on a tissue-pad contact the normal row has R = 2 / (B h) and
    # a_ref = -(2 K / (B h)) r - (2 / h) v (the trapezoidal contact force), its friction rows R = 2 / (B *
    # FRICTION_SOFTNESS) whatever the step; a foot keeps the explicit law (R = (1 - d) / d * A0, tiny d).
    mj = human.model.mj
    d = engine.settled_data(human.model)
    d.qvel[:] += 0.01 * np.sin(np.arange(mj.nv))  # a moving state, so that the damping term counts
    mujoco.mj_forward(mj, d)
    k = float(human.params.value(f"contacts.{contact}.stiffness_N_per_m"))
    b = float(human.params.value(f"contacts.{contact}.damping_Ns_per_m"))
    pad = next(c for c in human.model.body.contacts if c.name == contact).tissue_pad
    h = mj.opt.timestep
    rows = [i for i in range(d.ncon) if contact_name(human.model, d.contact[i]) == contact]
    assert len(rows) == 1
    r = d.contact[rows[0]].efc_address
    assert pad == (contact != "foot_r")
    if pad:
        assert d.efc_R[r] == pytest.approx(2 / (b * h), rel=1e-9)
        assert d.efc_aref[r] == pytest.approx(-(2 * k / (b * h)) * d.efc_pos[r] - (2 / h) * d.efc_vel[r], rel=1e-9)
        assert d.efc_R[r + 1] == pytest.approx(2 / (b * engine.FRICTION_SOFTNESS), rel=1e-9)
    else:
        i = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_PAIR, contact)
        a0 = sum(mj.body_invweight0[mj.geom_bodyid[g], 0] for g in (mj.pair_geom1[i], mj.pair_geom2[i]))
        imp = float(human.params.value("simulation.contact_impedance"))
        assert d.efc_R[r] == pytest.approx((1 - imp) / imp * a0, rel=1e-9)
    assert abs(d.efc_vel[r]) > 1e-4  # the state moves along the normal


# ----------------------------------------------------------------------------- determinism


def _arrays(run):
    out = {"seat": run.seat_acc_mps2}
    for p in POINT_NAMES:
        pm = run.point(p)
        out[f"{p}.acc"], out[f"{p}.disp"], out[f"{p}.rot"] = pm.acc_mps2, pm.disp_m, pm.rot_rad
    out.update({f"support.{k}": v for k, v in run.support_N.items()})
    return out


def test_same_seed_same_result_different_seed_different_result(human):
    a = _arrays(human.simulate(random_vibration("xyz", 1, 0.3, seed=1), method="nonlinear"))
    b = _arrays(human.simulate(random_vibration("xyz", 1, 0.3, seed=1), method="nonlinear"))
    c = _arrays(SeatedHuman().simulate(random_vibration("xyz", 1, 0.3, seed=1),
                                       method="nonlinear"))  # fresh build and settle
    other = _arrays(human.simulate(random_vibration("xyz", 1, 0.3, seed=2), method="nonlinear"))
    for k in a:
        assert np.array_equal(a[k], b[k]), k
        assert np.array_equal(a[k], c[k]), k
        assert np.all(np.isfinite(a[k])), k
    for k in ("seat", "head.acc", "trunk.acc", "pelvis.acc", "support.seat_pan"):
        assert not np.allclose(a[k], other[k], rtol=0, atol=1e-6), k


# ----------------------------------------------------------------------------- divergence


def _stiff_at_coarsest_step() -> Parameters:
    """The longest step taken (10 ms) with contacts 30x as stiff: unstable (measured on the identified person:
    diverges while settling, at t = 0.61 s; at 10x it still runs)."""
    p = Parameters.load()
    normal = [x for x in p.numeric_paths() if x.startswith("contacts.") and x.endswith(".stiffness_N_per_m")]
    return p.with_values({"simulation.dt_s": 0.01, **{x: 30 * p.value(x) for x in normal}})


def test_large_time_step_diverges_with_simulated_time(tmp_path, monkeypatch):
    # MuJoCo may write MUJOCO_LOG.TXT into the working directory on a warning, so run in tmp_path.
    monkeypatch.chdir(tmp_path)
    with pytest.warns(StepWarning, match="coarser than the 1 ms"):
        h = SeatedHuman(_stiff_at_coarsest_step())
    with pytest.raises(DivergenceError) as exc:
        h.simulate(random_vibration("z", 2, 0.3, seed=0, dt_s=0.01, band_hz=(0.1, 4.0)), method="nonlinear")
    msg = str(exc.value)
    match = re.search(r"t = (\d+(?:\.\d+)?) s", msg)
    assert match, msg
    t = float(match.group(1))
    assert 0.0 < t <= 10.0 + 2.0  # within settling (10 s) plus the run (2 s)
    assert "dt = 0.01 s" in msg  # names the time step to reduce


# ----------------------------------------------------------------------------- smoke test of every variant


@pytest.mark.parametrize("lock, unlock", [((), ()), ((), ("waist",)), (("t12",), ()), (("lower_neck",), ())],
                         ids=["default", "waist_unlocked", "t12_locked", "lower_neck_locked"])
def test_variant_builds_settles_and_runs(lock, unlock):
    h = SeatedHuman(lock=lock, unlock=unlock)
    h.settle()
    motion = random_vibration("xyz", 1, 0.3, seed=3, dt_s=h.model.mj.opt.timestep)
    run = h.simulate(motion, method="nonlinear")
    n = motion.n_samples  # samples at t = 0, dt, ..., 1 s
    assert run.time_s.shape == (n,)
    assert run.mass_kg == pytest.approx(PAPER_TOTAL_MASS_KG, abs=1e-9)
    for p in POINT_NAMES:
        pm = run.point(p)
        for arr in (pm.acc_mps2, pm.disp_m, pm.rot_rad):
            assert arr.shape == (n, 3) and np.all(np.isfinite(arr))
        # 0.3 m/s^2 rms input for 1 s cannot move a point of a seated person by 5 cm.
        assert np.abs(pm.disp_m).max() < 0.05, p
    for k, f in run.support_N.items():
        assert f.shape == (n, 3) and np.all(np.isfinite(f)), k
    weight = PAPER_TOTAL_MASS_KG * G
    assert run.support_total_N()[:, 2].mean() == pytest.approx(weight, rel=0.05)
