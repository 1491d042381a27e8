"""The head-in-space control on the default (hybrid) route against the nonlinear route: accuracy and speed, and the
speed with the control as a share of the speed without it.  Inputs are SYNTHETIC (ehm.random_vibration, the
SYNTHETIC city drive ehm.city_drive).

    python benchmarks/bench_head_control_routes.py     # about a minute and a half on one core

For each drive, the default person with the control (``head_control=True``) and without, on ``method="auto"`` and
``method="nonlinear"``:

* wall time [s] and real-time factor (drive length over wall time), the person settled and linearised beforehand;
* the route: the linear model's share of the drive and why the nonlinear model ran (the route's report);
* auto against nonlinear, with the control and without: the worst point acceleration's rms difference as a share
  of its rms (channels whose rms is below 1e-4 of the largest, round-off under the drive, against the largest: as
  the route's own discrepancy measure), the head's pitch and roll (rotation relative to the seat) rms difference as
  a share of their rms, and the route's own discrepancy;
* the speed with the control as a ratio of the speed without it, on the same drive and route.

Then the accuracy these figures hold at: ``ehm check-step``'s worst path at 1 ms against dt/8 for the person with the
control (and without).

BLAS as installed: the routes keep their small matrix products on one BLAS thread themselves (threadpoolctl).
"""

from __future__ import annotations

import time

import numpy as np

import ehm
from ehm.analysis.assessment import needs_rotating_seat
from ehm.analysis.convergence import check_step
from ehm.inputs.motion import SeatMotion
from ehm.routes.linear import linear_model

POINTS = ("pelvis", "trunk", "head", "lumbar")
def braking_drive():
    """As tests/test_head_control_routes.py's: 12 s of three-axis vibration at 0.3 m/s^2 rms with a 2 m/s^2 braking
    pulse at 5 s, which brings contacts to their friction limit (windows, the linear model between them)."""
    m = ehm.random_vibration("xyz", 12.0, 0.3, seed=0, dt_s=0.001)
    t, acc = m.time_s, m.acc_mps2.copy()
    acc[:, 0] -= np.where((t > 5.0) & (t < 6.5), 2.0 * np.sin(np.pi * (t - 5.0) / 1.5) ** 2, 0.0)
    return SeatMotion(t, acc, f"SYNTHETIC {m.description}, a 2 m/s^2 braking pulse at 5 s")


DRIVES = {"three-axis 60 s at 0.3 m/s^2 rms": lambda: ehm.random_vibration("xyz", 60.0, 0.3, seed=0),
          "city drive 120 s": lambda: ehm.city_drive(),
          "three-axis 12 s at 0.3 m/s^2 rms with a braking pulse": braking_drive}


def rms(x, axis=0):
    return np.sqrt(np.mean(np.asarray(x) ** 2, axis=axis))


def worst_acc_share(a_run, b_run) -> tuple[str, float]:
    """The worst point acceleration's rms difference over the reference ``b_run``'s rms (channels without content
    against the largest rms)."""
    ref = np.array([rms(b_run.point(p).acc_mps2 - b_run.point(p).acc_mps2.mean(axis=0)) for p in POINTS])
    diff = np.array([rms(a_run.point(p).acc_mps2 - b_run.point(p).acc_mps2) for p in POINTS])
    share = diff / np.maximum(ref, 1e-4 * ref.max())
    i, k = np.unravel_index(int(np.argmax(share)), share.shape)
    return f"{POINTS[i]} {'xyz'[k]}", float(share[i, k])


def timed(humans: dict, motion, method: str, repeat: int = 5) -> dict:
    """head control -> (the run, its wall time [s]), the people with and without the control run in turn: the least
    of ``repeat`` runs each when one takes under a second, else of two (a run's time varies with what else runs on
    the machine; taking turns gives both the same conditions)."""
    best, runs = {hc: np.inf for hc in humans}, {}
    for k in range(repeat):
        for hc, human in humans.items():
            t0 = time.perf_counter()
            runs[hc] = human.simulate(motion, method=method)
            best[hc] = min(best[hc], time.perf_counter() - t0)
        if k >= 1 and max(best.values()) > 1.0:
            break
    return {hc: (runs[hc], best[hc]) for hc in humans}


def compare(auto, nl) -> str:
    """auto against nonlinear: the worst point acceleration, the head's pitch and roll, the route's discrepancy."""
    where, share = worst_acc_share(auto, nl)
    rot = [rms(auto.point("head").rot_rad[:, k] - nl.point("head").rot_rad[:, k])
           / rms(nl.point("head").rot_rad[:, k] - nl.point("head").rot_rad[:, k].mean()) for k in (0, 1)]
    route = auto.extra["route"]
    return (f"worst point acceleration {share:.2%} of rms ({where}); head pitch {rot[1]:.2%}, head roll {rot[0]:.2%} "
            f"of rms; the route's own discrepancy {route['largest_discrepancy']['share_of_rms']:.2%}")


def main() -> None:
    for label, make in DRIVES.items():
        motion = make()
        print(f"{label} ({motion.description})")
        humans = {}
        for hc in (False, True):
            humans[hc] = ehm.SeatedHuman(head_control=hc, rotating_seat=needs_rotating_seat(motion, "auto"))
            person = humans[hc].built.for_motion(motion)
            person.settle()
            linear_model(person)  # the linearisation is kept with the person: not timed below
        runs = {}
        for method in ("auto", "nonlinear"):
            for hc, (run, wall) in timed(humans, motion, method).items():
                runs[hc, method] = run, wall
                route = run.extra.get("route", {})
                how = (f"linear share {route['linear_share']:.1%}" + (f", {route['fallback']}" if route.get(
                    "fallback") else "")) if route else "nonlinear route"
                print(f"  head control {'on ' if hc else 'off'} {method:9s}: {wall:6.3f} s, "
                      f"{motion.duration_s / wall:5.0f}x real time; {how}")
        for hc in (True, False):
            print(f"  head control {'on ' if hc else 'off'}, auto against nonlinear: "
                  + compare(runs[hc, "auto"][0], runs[hc, "nonlinear"][0]))
        for method in ("auto", "nonlinear"):
            ratio = runs[False, method][1] / runs[True, method][1]
            print(f"  speed with the control / without, {method}: {ratio:.2f}")
    for hc in (True, False):
        path, err = check_step(ehm.Person(head_control=hc), dt_s=0.001, ratios=(8,)).worst(8)
        print(f"check-step at 1 ms, head control {'on' if hc else 'off'}: worst path {path}, {err:.2%} of its peak "
              "against dt/8")


if __name__ == "__main__":
    main()
