"""Where a person's check-step error comes from: the step's own error, or where the person comes to rest.

``ehm check-step`` compares the person linearised at its rest at the step under test with the same person at step / 8,
each settled at its own step.  Friction holds the body where settling leaves it, so the two rests differ by some
tens of micrometres; this script separates the two causes for one posture and back support:

1. the worst path's error against step / 8 at the step, step / 2 and step / 4: a step error falls with the step
   (by 4 per halving if of second order), a difference of rests need not;
2. the same comparison with the rests swapped: the step-h model linearised at the step / 8 rest, and the step / 8
   model at the step-h rest (each against the step / 8 model at its own rest);
3. each touching contact's normal force and friction use at rest, |tangential| / (mu normal), at both steps (1:
   at the friction limit).

Takes about ten seconds at the default 1 ms.

    python benchmarks/step_error_source.py --posture slouched --back-support high
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

import ehm
from ehm import engine
from ehm.analysis.convergence import path_errors
from ehm.analysis.frf import linear_frf
from ehm.body.timestep import StepWarning

FREQ_HZ = np.arange(0.2, 12.0 + 1e-9, 0.05)  # check_step's band


def person(posture: str, back_support: str, dt_s: float) -> ehm.SeatedHuman:
    """The person at step ``dt_s``, settled."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", StepWarning)  # coarse steps are what is being compared
        human = ehm.SeatedHuman(posture=posture, back_support=back_support, dt_s=dt_s)
    human.settle()
    return human


def frf_at(human: ehm.SeatedHuman, rest: dict | None = None):
    """The discrete-time transfer functions of ``human`` linearised at ``rest`` (default: its own rest)."""
    own = human.model.settled
    human.model.settled = own if rest is None else rest
    try:
        return linear_frf(human, freq_hz=FREQ_HZ, discrete=True)
    finally:
        human.model.settled = own


def worst(table, reference) -> str:
    errors, at_hz = path_errors(table, reference)
    path = max(errors, key=errors.get)
    return f"{100 * errors[path]:.2f} % (seat {path[0]} -> {path[1]} {path[2]} at {at_hz[path]:.2f} Hz)"


def friction_use(human: ehm.SeatedHuman) -> dict:
    """Touching contact -> (normal force [N], |tangential| / (mu normal)) at rest."""
    model = human.model
    names = engine.touching_contacts(model)
    forces = engine.contact_forces(model, engine.settled_data(model), names).reshape(-1, 3)
    out = {}
    for name, (fn, f1, f2) in zip(names, forces):
        mu = float(model.params.value(f"contacts.{name}.friction"))
        out[name] = (fn, float(np.hypot(f1, f2) / (mu * fn)) if fn > 0 else float("nan"))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--posture", default="erect")
    parser.add_argument("--back-support", default="high")
    parser.add_argument("--dt", type=float, default=0.001, help="the step under test [s]")
    args = parser.parse_args()
    humans = {r: person(args.posture, args.back_support, args.dt / r) for r in (1, 2, 4, 8)}
    tables = {r: frf_at(h) for r, h in humans.items()}
    fine, coarse = humans[8], humans[1]
    print(f"{args.posture}, back support {args.back_support}: worst path against step / 8 = {args.dt / 8:g} s")
    for r in (1, 2, 4):
        print(f"  {f'step {args.dt / r:g} s at its own rest':36s} {worst(tables[r], tables[8])}")
    print(f"  {f'step {args.dt:g} s at the step / 8 rest':36s} {worst(frf_at(coarse, fine.model.settled), tables[8])}")
    print(f"  {f'step / 8 at the step {args.dt:g} s rest':36s} {worst(frf_at(fine, coarse.model.settled), tables[8])}")
    dq = coarse.model.settled["qpos"] - fine.model.settled["qpos"]
    print(f"  rests apart by up to {1e6 * np.abs(dq).max():.1f} (um or urad, largest position coordinate)")
    print("friction use at rest, |tangential| / (mu normal), step and step / 8:")
    uses = [friction_use(coarse), friction_use(fine)]
    for name in uses[0]:
        (fn, u), (_, u8) = uses[0][name], uses[1].get(name, (0.0, float("nan")))
        print(f"  {name:12s} normal {fn:6.1f} N   {u:.3f}   {u8:.3f}")


if __name__ == "__main__":
    main()
