"""Identify the default person's vertical path against the standards' reference curves, reproducibly.

The references (:mod:`ehm.standards.references`) describe people sitting erect without a back support, feet supported:
ISO 2631-5:2018's seat-to-lumbar transfer function and the one-mass fit to measured apparent mass of Fairley &
Griffin (1989).  The person is identified in that condition, in two stages, from ``START`` (the values an
exploratory search reached from the ehm authors' hand-tuned ones):

1. **Band search.**  Least squares (scipy, trust-region reflective, in log space within the bounds of ``FREE``, in
   the two ``ROUNDS``) on how far each check of :func:`ehm.validate` lies outside its band (by a margin of a
   tenth of the band inside it), plus
   the distance of the lumbar gain from ISO 2631-5's and of the apparent mass from the one-mass fit, and a
   bound on the low-frequency gains (below 1.5 Hz the body follows the seat: lumbar and head gains at most
   1.12, which keeps the unsupported trunk upright).  The checks include the seat-to-head bands on the
   person's own seat (the paper's, high back support) and the paper's joint-locking findings there.
2. **ehm fit.**  The paper's criterion (Eqs. 2-3) on the two reference curves (written to
   ``reference_curves.csv``: ISO 2631-5's |H| at 1-12 Hz and the one-mass apparent mass with a fifth of the mass
   on the frame, the legs' share, scaled by the person's own apparent mass at 0.5 Hz), from stage 1's result
   with bounds of a quarter either way, through the ``ehm fit`` command as a user would run it.

Then :func:`ehm.validate` on both results; the one that passes every check (stage 2's, when it does) is the
identified person.  Everything goes to ``--out``, a new folder: the reference curves, both stages' parameter
files, the validation tables and their figures (``validation_<stage>_<axis>.png``), and the identified person as a
whole parameter file, ``identified_params.toml`` (the shipped file's text with the identified values, graded
``identified``).  Takes about 6 minutes on two cores (stage 1: 106 evaluations of about 1.5 s; stage 2: 162
evaluations and a time-domain check).

    python tools/identify_default_person.py --out identified/

**Every seat** (``--every-seat``, how the shipped person was identified): one parameter set on every posture and
back support at once (``EVERY_SEAT``), from ``--start`` (default: the shipped file), with the values of
``EVERY_SEAT_NAMES`` free (the weight-bearing contacts, the spine, hips and necks, the back pads, the trunk's and
hips' lateral bending and the two trunk tone factors): least squares on every band of :func:`ehm.validate` where
its source applies (:func:`ehm.analysis.validation.bands_applying`), the lumbar and apparent-mass curves' distance
from the references without back support, the low-frequency gains, the trunk's and head's lean under sustained
manoeuvres (at most ``LEAN_MAX_DEG`` per m/s^2 at 0.1 Hz), slouched's resonance below erect's, the head's fore-aft
motion on the low back support no more than on the high one, and the paper's locking findings on its seat.  The
derivatives run in ``--workers`` processes; the best person so far is kept in ``every_seat_best.toml``.

    python tools/identify_default_person.py --every-seat --out identified/ --workers 2

The shipped parameters (``src/ehm/data/default_params.toml``) change only when their path is named:
``--write-defaults src/ehm/data/default_params.toml`` writes the identified values into that file as well.
"""

from __future__ import annotations

import argparse
import copy
import json
import re
import sys
import time
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

import ehm
from ehm.analysis.frf import FrfTable
from ehm.analysis.validation import validate
from ehm.body.params import Parameters, default_params_path
from ehm.interfaces.cli import main as ehm_main
from ehm.outputs.plotting import plot_validation
from ehm.standards import references
from ehm.standards.transfer import Curve

SIDES = ("r", "l")
#: The values identified, those that shape the vertical response: the normal stiffness and damping of the contacts
#: that carry the body's weight, and the joints whose compliance the vertical mode moves (the spine's vertical
#: slide and the pitch of spine, hips and neck).  name -> (dotted paths, lower bound, upper bound).  Both sides of
#: the body move together.  Bounds: physiological orders of magnitude (contact stiffness of seated buttock tissue
#: some tens of kN/m; joint rotational stiffness some tens to thousands of Nm/rad), wide enough not to decide the
#: result.
FREE = {
    "buttock stiffness": (["contacts.buttock_{s}.stiffness_N_per_m"], 15e3, 150e3),
    "buttock damping": (["contacts.buttock_{s}.damping_Ns_per_m"], 100.0, 3000.0),
    "thigh stiffness": (["contacts.thigh_{s}.stiffness_N_per_m"], 20e3, 500e3),
    "thigh damping": (["contacts.thigh_{s}.damping_Ns_per_m"], 100.0, 5000.0),
    "foot stiffness": (["contacts.foot_{s}.stiffness_N_per_m"], 10e3, 500e3),
    "foot damping": (["contacts.foot_{s}.damping_Ns_per_m"], 50.0, 5000.0),
    "T12 vertical stiffness": (["joints.t12.z.stiffness_N_per_m"], 8e3, 150e3),
    "T12 vertical damping": (["joints.t12.z.damping_Ns_per_m"], 50.0, 3000.0),
    "T12 pitch stiffness": (["joints.t12.pitch.stiffness_Nm_per_rad"], 100.0, 3000.0),
    "T12 pitch damping": (["joints.t12.pitch.damping_Nms_per_rad"], 10.0, 300.0),
    "L4-L5 pitch stiffness": (["joints.l4_l5.pitch.stiffness_Nm_per_rad"], 150.0, 6000.0),
    "L4-L5 pitch damping": (["joints.l4_l5.pitch.damping_Nms_per_rad"], 2.0, 300.0),
    "hip pitch stiffness": (["joints.hip_{s}.pitch.stiffness_Nm_per_rad"], 50.0, 1000.0),
    "hip pitch damping": (["joints.hip_{s}.pitch.damping_Nms_per_rad"], 2.0, 100.0),
    "lower neck pitch stiffness": (["joints.lower_neck.pitch.stiffness_Nm_per_rad"], 100.0, 800.0),
    "lower neck pitch damping": (["joints.lower_neck.pitch.damping_Nms_per_rad"], 2.0, 40.0),
    "upper neck pitch stiffness": (["joints.upper_neck.pitch.stiffness_Nm_per_rad"], 40.0, 300.0),
    "upper neck pitch damping": (["joints.upper_neck.pitch.damping_Nms_per_rad"], 1.0, 30.0),
    "buttock shear stiffness": (["contacts.buttock_{s}.shear_stiffness_N_per_m"], 3e3, 80e3),
    "buttock shear damping": (["contacts.buttock_{s}.shear_damping_Ns_per_m"], 50.0, 3000.0),
    "thigh shear stiffness": (["contacts.thigh_{s}.shear_stiffness_N_per_m"], 2e3, 60e3),
    "thigh shear damping": (["contacts.thigh_{s}.shear_damping_Ns_per_m"], 50.0, 3000.0),
    "knee pitch stiffness": (["joints.knee_{s}.pitch.stiffness_Nm_per_rad"], 10.0, 300.0),
    "knee pitch damping": (["joints.knee_{s}.pitch.damping_Nms_per_rad"], 0.5, 30.0),
    "ankle pitch stiffness": (["joints.ankle_{s}.pitch.stiffness_Nm_per_rad"], 5.0, 200.0),
    "ankle pitch damping": (["joints.ankle_{s}.pitch.damping_Nms_per_rad"], 0.2, 20.0),
}
#: Stage 1's start: the values an exploratory search on the linear model reached (CHANGELOG, "The default person
#: identified"), with every other value as shipped.  From the earlier hand-tuned values the same search stops in a
#: local minimum with four checks failing; ``--start FILE`` starts from a parameter file instead.
START = {"buttock stiffness": 45940.0, "buttock damping": 545.1, "thigh stiffness": 210900.0, "thigh damping": 830.7,
         "foot stiffness": 50000.0, "foot damping": 500.0, "T12 vertical stiffness": 31440.0,
         "T12 vertical damping": 467.0, "T12 pitch stiffness": 157.3, "T12 pitch damping": 88.36,
         "L4-L5 pitch stiffness": 3093.0, "L4-L5 pitch damping": 5.104, "hip pitch stiffness": 90.5,
         "hip pitch damping": 6.979, "lower neck pitch stiffness": 284.3, "lower neck pitch damping": 8.937,
         "upper neck pitch stiffness": 68.91, "upper neck pitch damping": 2.292}
#: Stage 1 in rounds: first the contacts' normal springs and the spine's, hips' and neck's, then with the tissue
#: pads' shear and the legs' joints as well (each round from the one before).
ROUNDS = (list(START), list(FREE))
#: Share of the body's mass on the rigid frame of the one-mass fit in the reference curve (stage 2): the
#: lower legs and feet with half the thighs, which move with the seat and the floor (24 % of this body).
FRAME_SHARE = 0.2
CURVE_HZ = np.round(np.arange(1.0, 12.0 + 1e-9, 0.25), 6)  # the paper's band for the ISO comparison, 1-12 Hz
MASS_HZ = np.round(np.arange(1.0, 20.0 + 1e-9, 0.25), 6)
LOW_HZ = (0.5, 1.5)
LOW_GAIN_MAX = 1.12
#: The shipped parameter file: the template of ``identified_params.toml`` (never written unless named).
SHIPPED = Path(default_params_path())


def paths(name: str) -> list[str]:
    return [t.format(s=s) for t in SPEC[name][0] for s in (SIDES if "{s}" in t else ("",))]


def with_free(base: Parameters, x: np.ndarray, names=None) -> Parameters:
    """The parameters with the free values ``x`` of ``names`` (default: all of ``FREE``, in its order)."""
    return base.with_values({p: float(v) for name, v in zip(names or list(FREE), x) for p in paths(name)})


def start_values(base: Parameters, names=None) -> np.ndarray:
    return np.array([float(base.value(paths(name)[0])) for name in names or list(FREE)])


def _hinge(value: float, low: float, high: float, margin: float) -> float:
    """How far ``value`` lies outside [low + margin, high - margin], in margins (0 inside)."""
    lo = -np.inf if np.isnan(low) else low + margin
    hi = np.inf if np.isnan(high) else high - margin
    return float(max(0.0, lo - value, value - hi) / margin)


def _margin(check) -> float:
    if np.isfinite(check.low) and np.isfinite(check.high):
        return 0.1 * (check.high - check.low)
    limit = check.low if np.isfinite(check.low) else check.high
    return {"Hz": 0.2, "%": 2.0}.get(check.unit, 0.05 * max(abs(limit), 0.1))


def search_residuals(v) -> np.ndarray:
    """Stage 1's residuals of one validation: checks outside their bands, curve distances, low-frequency gains."""
    r = [3.0 * _hinge(c.value, c.low, c.high, _margin(c)) for c in v.checks]
    r += curve_residuals(v.tables[v.person["conditions"][0]], 0.6, 0.3)
    for table in v.tables.values():
        r += low_gain_residuals(table)
    return np.array(r)


def curve_residuals(table: FrfTable, lumbar_weight: float, mass_weight: float) -> list:
    """The lumbar gain's distance from ISO 2631-5's at ``CURVE_HZ`` (per 0.2) and the normalised apparent mass's
    from the one-mass fit at ``MASS_HZ`` (per 0.15), each times its weight."""
    lumbar = table.curve("z", "lumbar", "z")
    g = np.interp(CURVE_HZ, lumbar.freq_hz, lumbar.gain)
    am = table.curve("z", "support", "z")
    m = np.interp(MASS_HZ, am.freq_hz, am.gain) / np.interp(0.5, am.freq_hz, am.gain)
    return (list(lumbar_weight * (g - np.abs(references.iso2631_5_lumbar_tf(CURVE_HZ))) / 0.2)
            + list(mass_weight * (m - np.abs(references.apparent_mass_one_mass(MASS_HZ, FRAME_SHARE))) / 0.15))


def low_gain_residuals(table: FrfTable) -> list:
    """How far the lumbar and head vertical gains over ``LOW_HZ`` exceed ``LOW_GAIN_MAX`` (the body follows the
    seat there)."""
    out = []
    for point in ("lumbar", "head"):
        c = table.curve("z", point, "z")
        low = (c.freq_hz >= LOW_HZ[0]) & (c.freq_hz <= LOW_HZ[1])
        out.append(_hinge(float(c.gain[low].max()), np.nan, LOW_GAIN_MAX, 0.02))
    return out


#: Every seat: the conditions the person is identified on together (one parameter set for all of them: the
#: ``full`` back support of the erect person is its ``high`` one, of the slouched person nearly so).
EVERY_SEAT = tuple((p, s) for p in ("erect", "slouched") for s in ("none", "low", "high"))
#: Values free on every seat, beyond ``FREE``: the back pads' tissue (both pads together) and the trunk's and hips'
#: lateral bending, which hold the trunk sideways where no backrest does.
EVERY_SEAT_FREE = {
    "back pad stiffness": (["contacts.lower_back.stiffness_N_per_m", "contacts.upper_back.stiffness_N_per_m"],
                           5e3, 80e3),
    "back pad damping": (["contacts.lower_back.damping_Ns_per_m", "contacts.upper_back.damping_Ns_per_m"],
                         50.0, 2000.0),
    "back pad shear stiffness": (["contacts.lower_back.shear_stiffness_N_per_m",
                                  "contacts.upper_back.shear_stiffness_N_per_m"], 500.0, 20e3),
    "back pad shear damping": (["contacts.lower_back.shear_damping_Ns_per_m",
                                "contacts.upper_back.shear_damping_Ns_per_m"], 10.0, 1000.0),
    "T12 roll stiffness": (["joints.t12.roll.stiffness_Nm_per_rad"], 200.0, 5000.0),
    "T12 roll damping": (["joints.t12.roll.damping_Nms_per_rad"], 10.0, 400.0),
    "L4-L5 roll stiffness": (["joints.l4_l5.roll.stiffness_Nm_per_rad"], 200.0, 6000.0),
    "L4-L5 roll damping": (["joints.l4_l5.roll.damping_Nms_per_rad"], 10.0, 400.0),
    "hip roll stiffness": (["joints.hip_{s}.roll.stiffness_Nm_per_rad"], 20.0, 1000.0),
    "hip roll damping": (["joints.hip_{s}.roll.damping_Nms_per_rad"], 1.0, 100.0),
    "slouched tone": (["postures.slouched.tone"], 0.3, 1.5),
    "supported tone": (["posture.supported_tone"], 0.3, 1.5),
}
#: Every value this script can free: ``FREE`` and ``EVERY_SEAT_FREE`` (name -> paths, bounds).
SPEC = {**FREE, **EVERY_SEAT_FREE}
#: The values free in the every-seat search: those that shape the vertical response on every seat, the back pads,
#: and the trunk's and hips' bending (the legs' joints, the pads' shear under the pelvis and the feet stay).
EVERY_SEAT_NAMES = ["buttock stiffness", "buttock damping", "thigh stiffness", "thigh damping",
                    "T12 vertical stiffness", "T12 vertical damping", "T12 pitch stiffness", "T12 pitch damping",
                    "L4-L5 pitch stiffness", "L4-L5 pitch damping", "hip pitch stiffness", "hip pitch damping",
                    "lower neck pitch stiffness", "upper neck pitch stiffness", *EVERY_SEAT_FREE]
#: Fore-aft head motion: the low back support moves the head no more than the high one (Mirakhorlo et al. 2022);
#: graded on the rms of the head's fore-aft gain over this band (a flat input spectrum).
FORE_AFT_BAND_HZ = (0.5, 10.0)
#: Sustained manoeuvres (braking, cornering: 0.1 Hz) lean the trunk and the head by at most this much per m/s^2 of
#: seat acceleration [deg/(m/s^2)]: a seated body holds itself up against a slowly tilting gravito-inertial force
#: (an upper body with too soft a hip and spine is an inverted pendulum that falls over in a city drive's 0.18 g);
#: the head, on its neck, may lean further.
LEAN_HZ = 0.1
LEAN_MAX_DEG = {"trunk": 2.0, "head": 3.0}


def every_seat_residuals(params: Parameters) -> np.ndarray:
    """The residuals of one parameter set on every seat of ``EVERY_SEAT``: each band where its source applies
    (:func:`ehm.analysis.validation.bands_applying`), the curves' distance from the references without back
    support, the low-frequency gains, the lean under sustained manoeuvres, slouched's resonance below erect's, the
    head's fore-aft motion on the low against the high support, and the paper's locking findings on its seat."""
    from ehm.analysis.validation import FREQ_HZ, band_checks, bands_applying, locking_checks

    r, tables = [], {}
    for post, back in EVERY_SEAT:
        t = ehm.linear_frf(ehm.SeatedHuman(ehm.Person(params=params, posture=post, back_support=back)), "all",
                           freq_hz=FREQ_HZ)
        tables[post, back] = t
        checks = band_checks(t, f"{post}, {back}", bands_applying(post, back))
        r += [3.0 * _hinge(c.value, c.low, c.high, _margin(c)) for c in checks]
        if back == "none":
            r += curve_residuals(t, 0.4, 0.2)
        r += low_gain_residuals(t)
        for axis, dof in (("x", "pitch"), ("y", "roll")):  # sustained manoeuvres: the trunk leans, not falls
            for point, most in LEAN_MAX_DEG.items():
                r.append(3.0 * _hinge(_lean_deg(t.curve(axis, point, dof)), np.nan, most, 0.3))
    peak = {k: _peak_hz(t.curve("z", "support", "z")) for k, t in tables.items()}
    r.append(3.0 * max(0.0, peak["slouched", "none"] - peak["erect", "none"] + 0.1) / 0.2)
    for post in ("erect", "slouched"):
        low, high = (_rms_gain(tables[post, s].curve("x", "head", "x")) for s in ("low", "high"))
        r.append(3.0 * max(0.0, low - high) / (0.05 * high))
    from ehm.analysis.study import PAPER_VARIANTS, locking_study

    study = locking_study(params=ehm.Person(params=params, posture="erect", back_support="high"),
                          variants=dict(PAPER_VARIANTS), method="linear")
    r += [3.0 * _hinge(c.value, c.low, c.high, _margin(c)) for c in locking_checks(study, "erect, high")]
    return np.array(r)


def _residuals_at(args) -> np.ndarray:
    """``every_seat_residuals`` of ``with_free(*args)`` (in a worker process); a failing person costs 100 each."""
    base, x, names, size = args
    try:
        return every_seat_residuals(with_free(base, x, names))
    except ehm.EhmError:
        return np.full(size, 100.0)


def _lean_deg(curve) -> float:
    """The segment's rotation per m/s^2 of slow seat acceleration (at LEAN_HZ) [deg/(m/s^2)], from the gain of its
    angular acceleration."""
    g = float(np.interp(LEAN_HZ, curve.freq_hz, curve.gain))
    return float(np.degrees(g / (2 * np.pi * LEAN_HZ) ** 2))


def _peak_hz(curve) -> float:
    f, g = np.asarray(curve.freq_hz), np.asarray(curve.gain)
    sel = (f >= 2.0) & (f <= 12.0)
    return float(f[sel][int(np.argmax(g[sel]))])


def _rms_gain(curve) -> float:
    f, g = np.asarray(curve.freq_hz), np.asarray(curve.gain)
    sel = (f >= FORE_AFT_BAND_HZ[0]) & (f <= FORE_AFT_BAND_HZ[1])
    return float(np.sqrt(np.mean(g[sel] ** 2)))


def every_seat_search(base: Parameters, max_evals: int, say, names) -> Parameters:
    """The band search on every seat at once (``every_seat_residuals``) over the values ``names``."""
    lo = np.log([SPEC[n][1] for n in names])
    hi = np.log([SPEC[n][2] for n in names])
    x0 = np.clip(np.log(start_values(base, names)), lo + 1e-9, hi - 1e-9)
    n_eval, t0, best = [0], time.perf_counter(), [np.inf, None]

    def residuals(log_x):
        n_eval[0] += 1
        p = with_free(base, np.exp(log_x), names)
        try:
            r = every_seat_residuals(p)
        except ehm.EhmError:
            r = np.full(residuals.size, 100.0)
        cost = float(r @ r)
        if cost < best[0]:
            best[:] = [cost, p]
            p.export(say.out / "every_seat_best.toml")
        if n_eval[0] % 10 == 1:
            say(f"every seat: {n_eval[0]} evaluations, cost {cost:.4g} (best {best[0]:.4g}), "
                f"{time.perf_counter() - t0:.0f} s")
        return r

    residuals.size = every_seat_residuals(with_free(base, np.exp(x0), names)).size
    from concurrent.futures import ProcessPoolExecutor

    pool = ProcessPoolExecutor(max_workers=say.workers)

    def jacobian(log_x):
        r0 = residuals(log_x)
        h = 1e-3 * np.maximum(1.0, np.abs(log_x))
        steps = [np.minimum(log_x + h[i] * np.eye(len(log_x))[i], hi) for i in range(len(log_x))]
        rows = list(pool.map(_residuals_at, [(base, np.exp(x), names, residuals.size) for x in steps]))
        n_eval[0] += len(steps)
        return np.column_stack([(r - r0) / (x[i] - log_x[i]) for i, (r, x) in enumerate(zip(rows, steps))])

    res = least_squares(residuals, x0, jac=jacobian, bounds=(lo, hi), max_nfev=max_evals)
    pool.shutdown()
    say(f"every seat: {res.message} after {n_eval[0]} evaluations, cost {2 * res.cost:.4g}")
    return with_free(base, np.exp(res.x), names)


def band_search(base: Parameters, max_evals: int, say, names=None) -> Parameters:
    """Stage 1 (see the module docstring) over the values ``names`` (default: all of ``FREE``)."""
    names = names or list(FREE)
    lo = np.log([FREE[n][1] for n in names])
    hi = np.log([FREE[n][2] for n in names])
    x0 = np.clip(np.log(start_values(base, names)), lo + 1e-9, hi - 1e-9)
    n_eval = [0]
    t0 = time.perf_counter()

    def residuals(log_x):
        n_eval[0] += 1
        try:
            r = search_residuals(validate(with_free(base, np.exp(log_x), names)))
        except ehm.EhmError:
            r = np.full(residuals.size, 100.0)
        if n_eval[0] % 17 == 1:
            say(f"stage 1: {n_eval[0]} evaluations, cost {float(r @ r):.4g}, {time.perf_counter() - t0:.0f} s")
        return r

    residuals.size = search_residuals(validate(with_free(base, np.exp(x0), names))).size
    res = least_squares(residuals, x0, bounds=(lo, hi), diff_step=1e-3, max_nfev=max_evals)
    say(f"stage 1: {res.message} after {n_eval[0]} evaluations, cost {2 * res.cost:.4g}")
    return with_free(base, np.exp(res.x), names)


def reference_table(person: Parameters) -> FrfTable:
    """The reference curves as 'measured' gains for ``ehm fit``: ISO 2631-5's seat-to-lumbar |H| at 1-12 Hz and
    the one-mass apparent mass (kg), scaled by the person's own apparent mass at 0.5 Hz."""
    human = ehm.SeatedHuman(person)
    am05 = ehm.linear_frf(human, "z", freq_hz=np.array([0.5])).curve("z", "support", "z").gain[0]
    nan = np.full(CURVE_HZ.size, np.nan)
    curves = {("z", "lumbar", "z"): Curve(CURVE_HZ, np.abs(references.iso2631_5_lumbar_tf(CURVE_HZ)), nan, nan),
              ("z", "support", "z"): Curve(CURVE_HZ, am05 * np.abs(references.apparent_mass_one_mass(CURVE_HZ,
                                                                                                   FRAME_SHARE)),
                                           nan, nan)}
    return FrfTable(curves=curves, method="measured",
                    meta={"input": "ISO 2631-5:2018 Formula 1 and the one-mass apparent-mass fit of Fairley & "
                                   f"Griffin (1989), frame share {FRAME_SHARE}"})


def with_bounds(p: Parameters, factor: float) -> Parameters:
    """A copy whose free values carry fitting bounds of ``factor`` either way (``ehm fit`` reads them)."""
    data = copy.deepcopy(p.data)
    q = Parameters(data, p.origin)
    for name in FREE:
        for path in paths(name):
            node, key = q._locate(path)
            v = float(q.value(path))
            b = [v / factor, v * factor]
            entry = node[key]
            if isinstance(entry, dict) and "value" in entry:
                entry["bounds"] = b
            else:
                node.setdefault("bounds", {})[key] = b
    return q


def write_into_defaults(identified: Parameters, template: Path, target: Path, source: str = "identified",
                        names=None) -> None:
    """Write ``target``: the parameter file ``template``'s text with the free values of ``identified`` in it, graded
    ``identified`` with ``source`` (its comments and layout kept; each value's line found in its own section); the
    values of ``names`` (default: ``FREE``).
    ``template`` is only read (unless it is ``target``)."""
    lines = template.read_text(encoding="utf-8").splitlines()
    section = None
    for i, line in enumerate(lines):
        m = re.match(r"\[([^\]]+)\]", line)
        if m:
            section = m.group(1)
            continue
        m = re.match(r"(\w+) = \{(.*)\}\s*$", line)
        if section is None or not m:
            continue
        key, body = m.groups()
        changed = False
        for name in names or FREE:
            for dotted in paths(name):
                head, _, leaf = dotted.rpartition(".")
                # a contact's value: section contacts.X, key = leaf; a joint's: section joints.X, key = dof
                if head == section and key == leaf:
                    body = re.sub(r"value = [^,]+", f"value = {_fmt(identified.value(dotted))}", body)
                    changed = True
                elif head.rpartition(".")[0] == section and key == head.rpartition(".")[2]:
                    body = re.sub(rf"{leaf} = [^,]+", f"{leaf} = {_fmt(identified.value(dotted))}", body)
                    changed = True
        if changed:
            body = re.sub(r'grade = "[^"]*"', 'grade = "identified"', body)
            body = re.sub(r'source = "[^"]*"', f'source = "{source}"', body)
            lines[i] = f"{key} = {{{body}}}"
    target.write_text("\n".join(lines) + "\n", encoding="utf-8")


def _fmt(v: float) -> str:
    """Four significant figures, as a TOML float."""
    return repr(float(f"{float(v):.4g}"))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--start", type=Path, help="start parameter file (default: the shipped person with START's values)")
    ap.add_argument("--max-evals", type=int, default=300, help="stage 1's evaluations (default 300)")
    ap.add_argument("--skip-search", action="store_true", help="start stage 2 from --start (no stage 1)")
    ap.add_argument("--workers", type=int, default=2, help="processes for the every-seat search's derivatives")
    ap.add_argument("--every-seat", action="store_true",
                    help="identify on every posture and back support at once (EVERY_SEAT), from --start or the "
                         "shipped person, with the values of EVERY_SEAT_NAMES free; no stage 2")
    ap.add_argument("--write-defaults", type=Path, metavar="PATH",
                    help="also write the identified values into this parameter file (grade identified); the shipped "
                         "one changes only when named: --write-defaults src/ehm/data/default_params.toml")
    args = ap.parse_args(argv)
    out = args.out
    if args.write_defaults is not None and not args.write_defaults.is_file():
        ap.error(f"--write-defaults names {args.write_defaults}, which is no parameter file; name an existing one")
    if out.exists():
        ap.error(f"--out {out} exists; name a new folder (nothing is written into an earlier result)")
    out.mkdir(parents=True)
    say = lambda line: print(line, flush=True)  # noqa: E731
    if args.every_seat:
        return _every_seat_main(args, out)
    base = Parameters.load(args.start).seated("erect", "none")
    if args.start is None:
        base = with_free(base, np.array(list(START.values())), list(START))
    stage1 = base
    for names in ([] if args.skip_search else ROUNDS):
        stage1 = band_search(stage1, args.max_evals, say, names)
    stage1.export(out / "band_search.toml")
    _write_reference_csv(reference_table(stage1), out / "reference_curves.csv")
    with_bounds(stage1, 1.25).export(out / "fit_start.toml")
    free = [p for name in FREE for p in paths(name)]
    rc = ehm_main(["fit", "--data", str(out / "reference_curves.csv"), "--params", str(out / "fit_start.toml"),
                   "--free", *free, "--band", "1", "12", "--out", str(out / "fitted.toml")])
    say(f"ehm fit returned {rc}")
    results = {}
    for label, path in (("band search", out / "band_search.toml"), ("ehm fit", out / "fitted.toml")):
        if not path.exists():
            continue
        v = validate(Parameters.load(path).seated("erect", "high"))
        results[label] = v
        stem = f"validation_{label.replace(' ', '_')}"
        (out / f"{stem}.txt").write_text(v.format_table() + "\n")
        for axis in "zxy":  # the figures per axis, as ehm validate draws them
            plot_validation(v, axis, out / f"{stem}_{axis}.png")
        say(f"\n{label}: {path}\n{v.format_table()}")
    # the identified person: ehm fit's result when its fit converged and it passes every check, else the band
    # search's when it does
    chosen = next((label for label, ok in (("ehm fit", rc == 0), ("band search", True))
                   if label in results and ok and results[label].passed), None)
    say(f"\nidentified: {chosen or 'none (no stage passes every check)'}")
    (out / "summary.json").write_text(json.dumps({"identified": chosen, **{k: v.as_dict() for k, v in results.items()}},
                                                 indent=1, default=str))
    if chosen:
        identified = Parameters.load({"band search": out / "band_search.toml", "ehm fit": out / "fitted.toml"}[chosen])
        write_into_defaults(identified, SHIPPED, out / "identified_params.toml")
        say(f"wrote the identified person to {out / 'identified_params.toml'}")
        if args.write_defaults is not None:
            write_into_defaults(identified, args.write_defaults, args.write_defaults)
            say(f"wrote the identified values into {args.write_defaults}")
    return 0 if chosen else 1


def _every_seat_main(args, out: Path) -> int:
    """``--every-seat``: the search on every seat, its validation on every seat, the identified person."""
    def say(line):
        print(line, flush=True)

    say.out, say.workers = out, args.workers
    base = Parameters.load(args.start)
    found = every_seat_search(base, args.max_evals, say, EVERY_SEAT_NAMES)
    found.export(out / "every_seat.toml")
    write_into_defaults(found, SHIPPED, out / "identified_params.toml", names=EVERY_SEAT_NAMES)
    say(f"wrote the identified person to {out / 'identified_params.toml'}")
    if args.write_defaults is not None:
        write_into_defaults(found, args.write_defaults, args.write_defaults, names=EVERY_SEAT_NAMES)
        say(f"wrote the identified values into {args.write_defaults}")
    return 0


def _write_reference_csv(table: FrfTable, path: Path) -> None:
    """The table in ehm's long FRF CSV format (what ``ehm fit --data`` reads)."""
    from ehm.analysis.frf import gain_unit

    lines = ["input_axis,point,dof,freq_hz,gain,phase_deg,coherence"]
    for (a, p, d), c in table.curves.items():
        lines += [f"{a},{p},{d},{f:.6g},{g:.9g},," for f, g in zip(c.freq_hz, c.gain)]
    path.write_text("# SYNTHETIC reference curves (not measured people): " + table.meta["input"] + "\n"
                    + f"# gains: lumbar z {gain_unit('lumbar', 'z')}, support z {gain_unit('support', 'z')}\n"
                    + "\n".join(lines) + "\n")


if __name__ == "__main__":
    sys.exit(main())
