"""Parameter identification: fit joint, posture-control and contact parameters to measured gains.

The paper identifies its model by minimising the criterion of Eqs. 2-3 over head, trunk and pelvis
gains in all measured directions.  Here each candidate parameter set is built, settled and linearised,
and its exact frequency response is evaluated at the measured frequencies (tens of milliseconds after
settling); the search runs in log space within each parameter's bounds with
:func:`scipy.optimize.least_squares` (trust-region reflective).  The least-squares objective is the
weighted mean of the curves' squared criteria; the reported figure is the paper's total criterion (the
weighted mean of the curves' criteria).  The result is checked with time-domain runs.
"""

from __future__ import annotations

import fnmatch
import hashlib
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from .criterion import DEFAULT_BAND_HZ, band_select, compare, residuals
from .errors import EhmError, InputError
from .frf import AXES, FrfTable, linear_frf, time_domain_frf
from .params import Parameters
from .tables import Body, load_body, resolve_locks

#: Sections whose numeric values may be fitted.
FITTABLE = ("joints.*", "contacts.*", "posture.integral_time_s")
DEFAULT_BOUND_FACTOR = 10.0  #: Without explicit bounds a value may move by this factor either way.
_FAILED = 1e3  #: Residual given to a candidate that cannot be simulated.


def free_parameters(params: Parameters, patterns: list[str], locked=frozenset()) -> list[str]:
    """Dotted paths matching the glob patterns (e.g. ``joints.t12.*.stiffness_*``), fittable ones only.

    Parameters of ``locked`` joints are left out (a welded joint has no spring to fit).
    """
    candidates = [p for p in params.numeric_paths() if any(fnmatch.fnmatch(p, f) for f in FITTABLE)
                  and not (p.startswith("joints.") and p.split(".")[1] in locked)]
    chosen: list[str] = []
    for pat in patterns:
        hits = [p for p in candidates if fnmatch.fnmatch(p, pat)]
        if not hits:
            raise InputError(f"--free {pat!r} matches no fittable parameter (joints.* of unlocked joints, "
                             "contacts.*, posture.integral_time_s); see 'ehm params' for the names.")
        chosen += [h for h in hits if h not in chosen]
    for p in chosen:
        if params.value(p) <= 0:
            raise InputError(f"parameter {p} is {params.value(p)}; only positive values can be fitted (in log space).")
    return chosen


def bounds(params: Parameters, path: str) -> tuple[float, float]:
    """Search bounds of a parameter: ``bounds`` in its entry, else value / 10 to value * 10."""
    b = params.bounds(path)
    v = float(params.value(path))
    lo, hi = b if b is not None else (v / DEFAULT_BOUND_FACTOR, v * DEFAULT_BOUND_FACTOR)
    if not 0 < lo <= v <= hi:
        raise InputError(f"parameter {path} = {v:g} lies outside its bounds [{lo:g}, {hi:g}] (or a bound is not positive).")
    return lo, hi


@dataclass(frozen=True)
class FitResult:
    """Outcome of :func:`fit`.

    Attributes
    ----------
    params : Parameters
        The identified parameter set (grade ``identified`` on the fitted values).
    free : tuple of str
    start, final : dict
        Free parameter values before and after.
    crit_before, crit_after : float
        Total criterion (linear model) before and after.
    crit_after_time : float or None
        Total criterion of the fitted model from time-domain runs.
    trace : list of float
        Least-squares objective sqrt(sum of squared weighted residuals) of every candidate the optimiser
        evaluated (finite-difference columns excluded), in order.
    status, message : int, str
        From :func:`scipy.optimize.least_squares`.
    n_eval : int
    wall_s : float
    """

    params: Parameters
    free: tuple
    start: dict
    final: dict
    crit_before: float
    crit_after: float
    crit_after_time: float | None
    trace: list = field(repr=False)
    status: int = 0
    message: str = ""
    n_eval: int = 0
    wall_s: float = 0.0


class _Objective:
    """Residuals of one candidate: build, settle, linearise, compare at the measured frequencies."""

    def __init__(self, data: FrfTable, base: Parameters, free: list[str], lock, unlock, body: Body,
                 band_hz: tuple[float, float]):
        self.data, self.base, self.free, self.body, self.band = data, base, free, body, band_hz
        self.lock, self.unlock = tuple(lock), tuple(unlock)
        self.keys = [k for k in data.keys() if band_select(data.curves[k].freq_hz, band_hz).any()]
        if not self.keys:
            raise InputError(f"no measured frequencies lie in {band_hz[0]:g}-{band_hz[1]:g} Hz.")
        w = np.array([data.curves[k].weight for k in self.keys])
        if w.sum() <= 0:
            raise InputError("all curve weights of the measured data are zero.")
        self.scale = [math.sqrt(wi / w.sum() / band_select(data.curves[k].freq_hz, band_hz).sum())
                      for k, wi in zip(self.keys, w)]
        self.freqs = np.unique(np.concatenate([data.curves[k].freq_hz for k in self.keys]))

    def params_at(self, log_x: np.ndarray) -> Parameters:
        return self.base.with_values({p: float(math.exp(v)) for p, v in zip(self.free, log_x)})

    def model_table(self, log_x: np.ndarray) -> FrfTable:
        from .simulation import SeatedHuman

        human = SeatedHuman(params=self.params_at(log_x), body=self.body, lock=self.lock, unlock=self.unlock)
        human.settle()
        axes = sorted({k[0] for k in self.keys}, key=AXES.index)
        return linear_frf(human, "all" if len(axes) > 1 else axes[0], freq_hz=self.freqs)

    def __call__(self, log_x: np.ndarray) -> np.ndarray:
        try:
            table = self.model_table(log_x)
        except EhmError:
            return np.full(sum(band_select(self.data.curves[k].freq_hz, self.band).sum() for k in self.keys), _FAILED)
        out = []
        for k, s in zip(self.keys, self.scale):
            m = self.data.curves[k]
            sel = band_select(m.freq_hz, self.band)
            mod = table.curve(*k)
            out.append(s * residuals(m.freq_hz[sel], m.gain[sel], np.interp(m.freq_hz[sel], mod.freq_hz, mod.gain)))
        return np.concatenate(out)

    def total(self, log_x: np.ndarray) -> float:
        return compare(self.data, self.model_table(log_x), self.band).total


_WORKER_OBJECTIVE: _Objective | None = None


def _init_worker(objective: _Objective) -> None:
    global _WORKER_OBJECTIVE
    _WORKER_OBJECTIVE = objective


def _worker_eval(log_x: np.ndarray) -> np.ndarray:
    return _WORKER_OBJECTIVE(log_x)


def _eval_with(objective: _Objective, log_x: np.ndarray) -> np.ndarray:
    return objective(log_x)


def fit(data: FrfTable, params: Parameters | None = None, free: list[str] | None = None, lock=(), unlock=(),
        body: Body | None = None, band_hz: tuple[float, float] = DEFAULT_BAND_HZ, max_evals: int = 400,
        workers: int | None = None, time_check: bool = True, progress=None, executor=None) -> FitResult:
    """Identify the free parameters that minimise the criterion against measured gains.

    Parameters
    ----------
    data : FrfTable
        Measured gains (:func:`ehm.frf.read_frf_csv`).
    params : Parameters
        Start values and bounds (default: the shipped defaults).
    free : list of str
        Glob patterns of the parameters to fit (default: every joint stiffness and damping of the spine and
        neck).
    max_evals : int
        Budget of model evaluations, finite-difference columns included (the optimiser's iteration limit
        is derived from it: max_evals / (n_free + 1)).
    workers : int
        Processes evaluating finite-difference columns in parallel (default: min(2, number of cores)).
    progress : callable(str) or None
        Receives one line per optimiser iteration.
    executor : concurrent.futures.Executor, optional
        Where to evaluate the finite-difference columns instead of local processes, e.g. a Dask cluster's
        ``client.get_executor()``.
    """
    t0 = time.perf_counter()
    base = params if params is not None else Parameters.load()
    body = body if body is not None else load_body()
    locked = resolve_locks(body, lock, unlock)
    if not isinstance(max_evals, int) or max_evals < 1:
        raise InputError(f"the evaluation budget must be a whole number >= 1, not {max_evals!r}.")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise InputError(f"workers = {workers!r}: use 1 or more processes.")
    patterns = free or ["joints.upper_neck.*", "joints.lower_neck.*", "joints.t12.*", "joints.l4_l5.*"]
    free_paths = free_parameters(base, patterns, locked)
    lohi = np.log(np.array([bounds(base, p) for p in free_paths]))
    x0 = np.log(np.array([float(base.value(p)) for p in free_paths]))
    objective = _Objective(data, base, free_paths, lock, unlock, body, band_hz)
    trace: list[float] = []
    n_evals = [0]
    say = progress or (lambda line: None)
    n_workers = workers if workers is not None else min(2, os.cpu_count() or 1)

    last: dict = {}

    def fun(x):
        r = objective(x)
        n_evals[0] += 1
        trace.append(float(np.sqrt(np.sum(r ** 2))))
        last["x"], last["r"] = x.copy(), r
        return r

    pool = ProcessPoolExecutor(max_workers=n_workers, initializer=_init_worker, initargs=(objective,)) \
        if n_workers > 1 and executor is None else None
    step = 1e-3

    def jac(x):
        cols = [x + step * np.eye(x.size)[i] for i in range(x.size)]
        f0 = last["r"] if "x" in last and np.array_equal(last["x"], x) else fun(x)
        if executor is not None:
            from functools import partial

            results = list(executor.map(partial(_eval_with, objective), cols))
        elif pool:
            results = list(pool.map(_worker_eval, cols))
        else:
            results = [objective(c) for c in cols]
        n_evals[0] += len(cols)
        J = np.column_stack([(r - f0) / step for r in results])
        say(f"  iteration {len(jac_calls) + 1}: objective {np.sqrt(np.sum(f0 ** 2)):.5g} "
            f"({n_evals[0]} evaluations, {time.perf_counter() - t0:.0f} s)")
        jac_calls.append(1)
        return J

    jac_calls: list[int] = []
    try:
        crit_before = objective.total(x0)
        say(f"start: criterion {crit_before:.5g} with {len(free_paths)} free parameters")
        sol = least_squares(fun, x0, jac=jac, bounds=(lohi[:, 0], lohi[:, 1]), method="trf", x_scale=1.0,
                            max_nfev=max(1, max_evals // (len(free_paths) + 1)), xtol=1e-4, ftol=1e-6, gtol=1e-8)
    finally:
        if pool:
            pool.shutdown()
    crit_after = objective.total(sol.x)
    fitted = objective.params_at(sol.x)
    crit_time = None
    if time_check:
        from .simulation import SeatedHuman

        human = SeatedHuman(params=fitted, body=body, lock=lock, unlock=unlock)
        axes = sorted({k[0] for k in objective.keys}, key=AXES.index)
        # excite the fitting band, starting one estimate bin (0.1 Hz) lower so that its edge is covered
        table = time_domain_frf(human, "all" if len(axes) > 1 else axes[0],
                                band_hz=(max(band_hz[0] - 0.1, 0.05), band_hz[1] + 0.1))
        crit_time = compare(data, table, band_hz).total
    start = {p: float(math.exp(v)) for p, v in zip(free_paths, x0)}
    final = {p: float(math.exp(v)) for p, v in zip(free_paths, sol.x)}
    return FitResult(params=fitted, free=tuple(free_paths), start=start, final=final, crit_before=crit_before,
                     crit_after=crit_after, crit_after_time=crit_time, trace=trace, status=int(sol.status),
                     message=str(sol.message), n_eval=n_evals[0], wall_s=time.perf_counter() - t0)


def file_sha256(path: Path | str) -> str:
    """SHA-256 of a file's bytes."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def identified_parameters(result: FitResult, data_path: Path | str) -> Parameters:
    """The fitted parameter set with its provenance recorded: grade ``identified`` on every fitted value,
    a ``[sources]`` entry naming the data file and its hash, and the criteria in ``[about]``."""
    digest = file_sha256(data_path)
    key = f"fit_{digest[:12]}"
    stamp = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    text = (f"ehm fit to {Path(data_path).name} (sha256 {digest}) on {stamp}: criterion (Eqs. 2-3) "
            f"{result.crit_before:.6g} -> {result.crit_after:.6g} (linear model)")
    if result.crit_after_time is not None:
        text += f", {result.crit_after_time:.6g} (time-domain check)"
    p = result.params.with_source(key, text)
    p = p.with_values(result.final, grade="identified", source=key)
    return p.with_about({
        "fit_data": Path(data_path).name, "fit_data_sha256": digest, "fit_date": stamp,
        "fit_free": list(result.free), "fit_criterion_before": result.crit_before,
        "fit_criterion_after": result.crit_after,
        **({"fit_criterion_after_time_domain": result.crit_after_time} if result.crit_after_time is not None else {}),
    })


def write_identified(result: FitResult, data_path: Path | str, out: Path | str) -> Parameters:
    """Write the identified parameter file; refuses to overwrite the shipped defaults."""
    p = identified_parameters(result, data_path)
    p.export(out)
    return p


def print_progress(line: str) -> None:
    """Progress lines to stderr (the fit's default reporter on the command line)."""
    print(line, file=sys.stderr, flush=True)
