"""Speed of the transfer-function tools: linear FRF, time-domain FRF, and a fit of 24 free parameters.

The fit uses SYNTHETIC gains made by the model itself with 24 neck and spine parameters moved by up to
a factor exp(U(-0.3, 0.3)), i.e. -26 % to +35 % (seeded), and starts from the defaults.
Usage: python benchmarks/bench_frf_fit.py [--skip-fit]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import ehm
from ehm import engine
from ehm.analysis.fit import fit, free_parameters
from ehm.analysis.frf import FrfTable, linear_frf, time_domain_frf
from ehm.analysis.study import STUDY_PATHS
from ehm.body.params import Parameters


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--skip-fit", action="store_true")
    args = ap.parse_args()

    human = ehm.SeatedHuman()
    t0 = time.perf_counter()
    human.settle()
    t_settle = time.perf_counter() - t0
    t0 = time.perf_counter()
    lm = engine.linearize(human.model)
    t_lin = time.perf_counter() - t0
    t0 = time.perf_counter()
    table = linear_frf(human, "all", linear_model=lm)
    t_frf = time.perf_counter() - t0
    n_f = next(iter(table.curves.values())).freq_hz.size
    print(f"linear FRF, 3 axes x 3 points x 6 dofs x {n_f} frequencies: linearise {t_lin * 1000:.0f} ms + "
          f"response {t_frf * 1000:.0f} ms = {(t_lin + t_frf) * 1000:.0f} ms (after settling, {t_settle:.2f} s)")

    t0 = time.perf_counter()
    time_domain_frf(human, "all", duration_s=60.0)
    print(f"time-domain FRF, 3 axes x 60 s of random vibration: {time.perf_counter() - t0:.1f} s")

    if args.skip_fit:
        return
    p0 = Parameters.load()
    free = free_parameters(p0, ["joints.upper_neck.*", "joints.lower_neck.*", "joints.t12.*", "joints.l4_l5.*"])
    rng = np.random.default_rng(1)
    truth = {k: float(p0.value(k)) * float(np.exp(rng.uniform(-0.3, 0.3))) for k in free}
    synth = ehm.SeatedHuman(params=p0.with_values(truth))
    synth.settle()
    freq = np.round(np.arange(0.25, 12.01, 0.25), 3)
    tab = linear_frf(synth, "all", freq_hz=freq)
    data = FrfTable({k: tab.curves[k] for k in STUDY_PATHS}, method="measured")
    t0 = time.perf_counter()
    res = fit(data, free=free, time_check=False)
    wall = time.perf_counter() - t0
    err = max(abs(res.final[k] / truth[k] - 1) for k in free)
    print(f"fit of {len(free)} free parameters to synthetic gains "
          f"({len(STUDY_PATHS)} curves x {freq.size} frequencies): {wall:.0f} s, "
          f"{res.n_eval} model evaluations, criterion {res.crit_before:.4g} -> {res.crit_after:.2g}, "
          f"largest parameter error {100 * err:.3g} %")


if __name__ == "__main__":
    main()
