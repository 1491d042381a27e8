"""Parameter identification: fit joint, posture-control and contact parameters to measured gains.

The paper identifies its model by minimising the criterion of Eqs. 2-3 over head, trunk and pelvis
gains in all measured directions.  Here each candidate parameter set is built, settled and linearised,
and its exact frequency response is evaluated at the measured frequencies (tens of milliseconds after
settling); the search runs in log space within each parameter's bounds with
:func:`scipy.optimize.least_squares` (trust-region reflective).  The least-squares objective is the
weighted mean of the curves' squared criteria; the reported figure is the paper's total criterion (the
weighted mean of the curves' criteria).  The result is checked with time-domain runs.

Honest outcomes: the evaluation budget ``max_evals`` counts every evaluation of the linearised model (the
start, each candidate, each finite-difference column) and is never exceeded; the time-domain check (one
set of random-vibration runs for the start and one for the result) comes on top of it.  The result says
how the search ended (``FitResult.stopped``: ``"converged"`` or ``"budget"``) and which values count
as identified (``FitResult.identified``): those that moved from their start, when the search converged,
lowered the criterion and, if the time-domain check ran, lowered its criterion too, and no free value
ended on its search bound.  A value within :data:`AT_BOUND_REL` of a bound (``FitResult.at_bound``) is
pinned there by the bound, not placed by the data: it is written with grade ``at bound`` and nothing of that
fit counts as identified.  Other values that moved without meeting all that are written with grade
``assumed`` and a source saying why.
"""

from __future__ import annotations

import fnmatch
import hashlib
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from ..body.params import Parameters
from ..body.tables import Body, load_body, resolve_locks
from ..errors import EhmError, InputError
from .criterion import DEFAULT_BAND_HZ, band_select, compare, curves_to_compare, residuals
from .frf import AXES, FrfTable, linear_frf, time_domain_frf

#: Sections whose numeric values may be fitted.
FITTABLE = ("joints.*", "contacts.*", "posture.integral_time_s")
DEFAULT_BOUND_FACTOR = 10.0  #: Without explicit bounds a value may move by this factor either way.
_FAILED = 1e3  #: Residual given to a candidate that cannot be simulated.
MOVED_REL = 1e-4  #: A value counts as moved when it changed by more than this share of its start value.
_FD_STEP = 1e-3  #: Finite-difference step in log space.
#: A fitted value counts as on its search bound when it lies within this share of the bound (0.1 %: the size of
#: the finite-difference step in log space, ten times the optimiser's step tolerance).
AT_BOUND_REL = 1e-3


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
        raise InputError(f"parameter {path} = {v:g} lies outside its bounds [{lo:g}, {hi:g}] "
                         "(or a bound is not positive).")
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
        From :func:`scipy.optimize.least_squares` (status 0 and a message saying so when the budget ran out).
    n_eval : int
        Evaluations of the linearised model, never more than ``max_evals``.
    wall_s : float
    stopped : str
        ``"converged"`` (the optimiser's tolerances were met) or ``"budget"`` (``max_evals`` ran out first).
    max_evals : int
    crit_before_time : float or None
        Time-domain criterion of the start values (when the time-domain check ran).
    moved : tuple of str
        Free parameters whose value changed by more than :data:`MOVED_REL` of the start value (the others
        keep their start value exactly).
    identified : tuple of str
        The moved values that count as identified (see the module docstring).
    at_bound : tuple of (str, str, float)
        Free parameters that ended within :data:`AT_BOUND_REL` of a search bound: (path, ``"lower"`` or
        ``"upper"``, the bound).  When any is there, nothing is identified.
    verdict : str
        One sentence: how the fit ended and what it identified.
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
    stopped: str = "converged"
    max_evals: int = 0
    crit_before_time: float | None = None
    moved: tuple = ()
    identified: tuple = ()
    verdict: str = ""
    at_bound: tuple = ()

    @property
    def improved(self) -> bool:
        """The criterion went down (linear model; and in the time domain, when checked)."""
        linear = bool(self.moved) and self.crit_after < self.crit_before
        timed = (self.crit_after_time is None or self.crit_before_time is None
                 or self.crit_after_time < self.crit_before_time)
        return linear and timed

    @property
    def ok(self) -> bool:
        """Converged, improved and every moved value identified."""
        return self.stopped == "converged" and self.improved and bool(self.identified)


class _BudgetSpent(Exception):
    """The next evaluation would exceed the evaluation budget."""


class _Objective:
    """Residuals of one candidate: build, settle, linearise, compare at the measured frequencies."""

    def __init__(self, data: FrfTable, base: Parameters, free: list[str], lock, unlock, body: Body,
                 band_hz: tuple[float, float], keep_small: bool = False):
        self.data, self.base, self.free, self.body, self.band = data, base, free, body, band_hz
        self.lock, self.unlock, self.keep_small = tuple(lock), tuple(unlock), keep_small
        used, _ = curves_to_compare(data, band_hz, keep_small)  # curves too small to carry signal: left out
        self.keys = [k for k in used if band_select(data.curves[k].freq_hz, band_hz).any()]
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
        from ..simulation import SeatedHuman

        human = SeatedHuman(params=self.params_at(log_x), body=self.body, lock=self.lock, unlock=self.unlock)
        human.settle()
        axes = sorted({k[0] for k in self.keys}, key=AXES.index)
        return linear_frf(human, "all" if len(axes) > 1 else axes[0], freq_hz=self.freqs)

    def __call__(self, log_x: np.ndarray) -> np.ndarray:
        return self.evaluate(log_x)[0]

    def evaluate(self, log_x: np.ndarray) -> tuple[np.ndarray, float]:
        """Residuals and total criterion of one candidate, from one model evaluation (inf: cannot be simulated)."""
        try:
            table = self.model_table(log_x)
        except EhmError:
            n = sum(band_select(self.data.curves[k].freq_hz, self.band).sum() for k in self.keys)
            return np.full(n, _FAILED), math.inf
        out = []
        for k, s in zip(self.keys, self.scale):
            m = self.data.curves[k]
            sel = band_select(m.freq_hz, self.band)
            mod = table.curve(*k)
            out.append(s * residuals(m.freq_hz[sel], m.gain[sel], np.interp(m.freq_hz[sel], mod.freq_hz, mod.gain)))
        return np.concatenate(out), compare(self.data, table, self.band, self.keep_small, warn=False).total


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
        workers: int | None = None, time_check: bool = True, progress=None, executor=None,
        keep_small_curves: bool = False) -> FitResult:
    """Identify the free parameters that minimise the criterion against measured gains.

    Parameters
    ----------
    data : FrfTable
        Measured gains (:func:`ehm.analysis.frf.read_frf_csv`).
    params : Parameters
        Start values and bounds (default: the shipped defaults).
    free : list of str
        Glob patterns of the parameters to fit (default: every joint stiffness and damping of the spine and
        neck).
    max_evals : int
        Budget of linearised-model evaluations: the start, every candidate and every finite-difference
        column count, and the fit stops before it would exceed the budget (``stopped = "budget"``).  The
        time-domain check comes on top.
    workers : int
        Processes evaluating finite-difference columns in parallel (default: min(2, number of cores)).
    time_check : bool
        Check start and result with time-domain runs (random vibration, H1 estimates).
    progress : callable(str) or None
        Receives one line per optimiser iteration.
    executor : concurrent.futures.Executor, optional
        Where to evaluate the finite-difference columns instead of local processes, e.g. a Dask cluster's
        ``client.get_executor()``.
    keep_small_curves : bool
        Keep measured curves whose peak is below :data:`ehm.analysis.criterion.SMALL_CURVE_FRACTION` of the largest of
        their kind for the same seat axis (left out with a warning by default).
    """
    t0 = time.perf_counter()
    base = params if params is not None else Parameters.load()
    body = body if body is not None else load_body()
    locked = resolve_locks(body, lock, unlock)
    _check_budget(max_evals, workers)
    patterns = free or ["joints.upper_neck.*", "joints.lower_neck.*", "joints.t12.*", "joints.l4_l5.*"]
    free_paths = free_parameters(base, patterns, locked)
    lohi = np.log(np.array([bounds(base, p) for p in free_paths]))
    x0 = np.log(np.array([float(base.value(p)) for p in free_paths]))
    objective = _Objective(data, base, free_paths, lock, unlock, body, band_hz, keep_small_curves)
    say = progress or (lambda line: None)
    n_workers = workers if workers is not None else min(2, os.cpu_count() or 1)
    search = _Search(objective, max_evals, say, t0, executor, n_workers)
    crit_before, x_end, status, message = _run_search(search, x0, lohi, max_evals, say, len(free_paths))
    stopped = "converged" if status > 0 else "budget"
    if not search.known(x_end) or search.objective_of(x_end) > search.objective_of(search.best_x):
        x_end = search.best_x  # the best candidate evaluated
    moved = tuple(p for p, a, b in zip(free_paths, x0, x_end) if abs(math.expm1(b - a)) > MOVED_REL)
    x_end = np.array([b if p in moved else a for p, a, b in zip(free_paths, x0, x_end)])  # others: start values
    crit_after = search.final_total(x_end) if moved else crit_before
    final = {p: float(math.exp(v)) if p in moved else float(base.value(p)) for p, v in zip(free_paths, x_end)}
    fitted = base.with_values({p: final[p] for p in moved}) if moved else base
    crit_time = crit_time_before = None
    if time_check and moved and crit_after < crit_before:
        crit_time_before = _time_criterion(objective, base, body, lock, unlock, band_hz)
        crit_time = _time_criterion(objective, fitted, body, lock, unlock, band_hz)
    start = {p: float(base.value(p)) for p in free_paths}
    result = FitResult(params=fitted, free=tuple(free_paths), start=start, final=final, crit_before=crit_before,
                       crit_after=crit_after, crit_after_time=crit_time, trace=search.trace, status=status,
                       message=message, n_eval=search.n_eval, wall_s=time.perf_counter() - t0, stopped=stopped,
                       max_evals=max_evals, crit_before_time=crit_time_before, moved=moved,
                       at_bound=on_bounds(final, {p: bounds(base, p) for p in free_paths}))
    identified = moved if stopped == "converged" and result.improved and not result.at_bound else ()
    return replace(result, identified=identified, verdict=_verdict(replace(result, identified=identified)))


def _check_budget(max_evals, workers) -> None:
    """Refuse an evaluation budget or a number of workers that is not a whole number >= 1."""
    if isinstance(max_evals, bool) or not isinstance(max_evals, int) or max_evals < 1:
        raise InputError(f"the evaluation budget must be a whole number >= 1, not {max_evals!r}.")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise InputError(f"workers = {workers!r}: use 1 or more processes.")


def _run_search(search, x0: np.ndarray, lohi: np.ndarray, max_evals: int, say, n_free: int):
    """The bounded least-squares search from ``x0``; returns the start criterion, the end point, status and message.

    A search that spends its budget ends at the best candidate evaluated (status 0).
    """
    try:
        crit_before = search.start(x0)
        say(f"start: criterion {crit_before:.5g} with {n_free} free parameters "
            f"(budget {max_evals} evaluations)")
        try:
            sol = least_squares(search.fun, x0, jac=search.jac, bounds=(lohi[:, 0], lohi[:, 1]), method="trf",
                                x_scale=1.0, max_nfev=max_evals, xtol=1e-4, ftol=1e-6, gtol=1e-8)
            x_end, status, message = sol.x, int(sol.status), str(sol.message)
        except _BudgetSpent:
            x_end, status = search.best_x, 0
            message = f"the evaluation budget ({max_evals}) ran out before the optimiser converged"
            if max_evals < n_free + 2:
                message += (f" (one step of the search needs {n_free + 2} evaluations with {n_free} free values: the "
                            "start, one finite difference per value and the step; give --max-evals "
                            f"{10 * (n_free + 2)} or more)")
    finally:
        search.close()
    return crit_before, x_end, status, message


def on_bounds(values: dict, limits: dict) -> tuple:
    """The values that lie on their search bound.

    Parameters
    ----------
    values : dict
        Dotted path -> fitted value.
    limits : dict
        Dotted path -> (lower, upper) search bound.

    Returns
    -------
    tuple of (str, str, float)
        (path, ``"lower"`` or ``"upper"``, bound) of every value within :data:`AT_BOUND_REL` of a bound.
    """
    out = []
    for p, v in values.items():
        lo, hi = limits[p]
        if v <= lo * (1 + AT_BOUND_REL):
            out.append((p, "lower", float(lo)))
        elif v >= hi / (1 + AT_BOUND_REL):
            out.append((p, "upper", float(hi)))
    return tuple(out)


def _time_criterion(objective: _Objective, params: Parameters, body: Body, lock, unlock, band_hz) -> float:
    """Total criterion of a parameter set from time-domain runs (the fit's check), of the person at the parameter
    file's reference vibration level (where the linear route identifies it), not at the runs' own."""
    from ..body.level import has_level
    from ..person.person import Person
    from ..simulation import SeatedHuman

    level = float(params.value("level.reference_rms_mps2")) if has_level(params) else None
    human = SeatedHuman(Person(params=params, body=body, lock=lock, unlock=unlock, vibration_rms_mps2=level))
    axes = sorted({k[0] for k in objective.keys}, key=AXES.index)
    # excite the fitting band, starting one estimate bin (0.1 Hz) lower so that its edge is covered
    table = time_domain_frf(human, "all" if len(axes) > 1 else axes[0],
                            band_hz=(max(band_hz[0] - 0.1, 0.05), band_hz[1] + 0.1))
    return compare(objective.data, table, band_hz, objective.keep_small, warn=False).total


def _verdict(r: FitResult) -> str:
    """One sentence on how the fit ended."""
    used = f"{r.n_eval} of {r.max_evals} evaluations"
    if not r.moved:
        why = "stopped on its evaluation budget" if r.stopped == "budget" else "converged"
        return (f"the fit {why} ({used}) without moving any free value from its start (criterion "
                f"{r.crit_before:.5g}): nothing was identified.")
    if r.crit_after >= r.crit_before:
        return (f"the fit did not lower the criterion ({r.crit_before:.5g} -> {r.crit_after:.5g}, {used}): "
                "nothing was identified.")
    if r.crit_after_time is not None and r.crit_before_time is not None and r.crit_after_time >= r.crit_before_time:
        return (f"the time-domain check does not confirm the fit (criterion {r.crit_before_time:.5g} -> "
                f"{r.crit_after_time:.5g} from runs, {r.crit_before:.5g} -> {r.crit_after:.5g} linear): the "
                f"{len(r.moved)} moved values are not marked identified.")
    if r.stopped == "budget":
        return (f"the fit stopped on its evaluation budget ({used}) before converging (criterion "
                f"{r.crit_before:.5g} -> {r.crit_after:.5g}): the {len(r.moved)} moved values are not marked "
                "identified; raise the budget (--max-evals) to finish it.")
    if r.at_bound:
        where = ", ".join(f"{p} on its {side} bound {b:.5g}" for p, side, b in r.at_bound)
        return (f"the fit ended with {where} (criterion {r.crit_before:.5g} -> {r.crit_after:.5g}, {used}): the "
                "bound, not the data, placed that value, so nothing is marked identified; widen the bound "
                "('bounds' in the parameter file's entry, default a factor 10 either way of the start) or check "
                "the data, and fit again.")
    return (f"converged in {used}: criterion {r.crit_before:.5g} -> {r.crit_after:.5g}; "
            f"{len(r.identified)} of {len(r.free)} free values identified.")


class _Search:
    """The objective as the optimiser sees it, counting every model evaluation against the budget.

    Candidates are cached by value, so the start and the optimiser's repeated points cost nothing twice;
    finite-difference columns run on the executor or the process pool.
    """

    def __init__(self, objective: _Objective, max_evals: int, say, t0: float, executor, n_workers: int):
        self.objective, self.max_evals, self.say, self.t0, self.executor = objective, max_evals, say, t0, executor
        self.pool = ProcessPoolExecutor(max_workers=n_workers, initializer=_init_worker, initargs=(objective,)) \
            if n_workers > 1 and executor is None else None
        self.n_eval = 0
        self.cache: dict[bytes, tuple[np.ndarray, float]] = {}
        self.trace: list[float] = []
        self.best_x: np.ndarray | None = None
        self.iterations = 0
        self.reserve = 0  # evaluations kept back during the search for the final point (see final_total)

    def _spend(self, n: int) -> None:
        if self.n_eval + n > self.max_evals - self.reserve:
            raise _BudgetSpent()
        self.n_eval += n

    def known(self, x: np.ndarray) -> bool:
        return np.asarray(x, dtype=float).tobytes() in self.cache

    def _evaluate(self, x: np.ndarray) -> tuple[np.ndarray, float]:
        key = np.asarray(x, dtype=float).tobytes()
        if key not in self.cache:
            self._spend(1)
            r, total = self.objective.evaluate(x)
            self.cache[key] = (r, total)
            self.trace.append(float(np.sqrt(np.sum(r ** 2))))
            if self.best_x is None or self.trace[-1] < self.objective_of(self.best_x):
                self.best_x = np.array(x, dtype=float)
        return self.cache[key]

    def objective_of(self, x: np.ndarray) -> float:
        """sqrt(sum of squared residuals) of an evaluated candidate."""
        r = self.cache[np.asarray(x, dtype=float).tobytes()][0]
        return float(np.sqrt(np.sum(r ** 2)))

    def final_total(self, x: np.ndarray) -> float:
        """The criterion at the result: known from the search, or (values that barely moved reset to their
        start) one more evaluation from the one kept in reserve."""
        self.reserve = 0
        return self._evaluate(x)[1]

    def start(self, x0: np.ndarray) -> float:
        total = self._evaluate(x0)[1]
        self.reserve = 1
        return total

    def fun(self, x: np.ndarray) -> np.ndarray:
        return self._evaluate(x)[0]

    def jac(self, x: np.ndarray) -> np.ndarray:
        f0 = self.fun(x)
        cols = [x + _FD_STEP * np.eye(x.size)[i] for i in range(x.size)]
        self._spend(len(cols))
        if self.executor is not None:
            from functools import partial

            results = list(self.executor.map(partial(_eval_with, self.objective), cols))
        elif self.pool:
            results = list(self.pool.map(_worker_eval, cols))
        else:
            results = [self.objective(c) for c in cols]
        self.iterations += 1
        self.say(f"  iteration {self.iterations}: objective {np.sqrt(np.sum(f0 ** 2)):.5g} "
                 f"({self.n_eval} of {self.max_evals} evaluations, {time.perf_counter() - self.t0:.0f} s)")
        return np.column_stack([(r - f0) / _FD_STEP for r in results])

    def close(self) -> None:
        if self.pool:
            self.pool.shutdown()


def file_sha256(path: Path | str) -> str:
    """SHA-256 of a file's bytes."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def identified_parameters(result: FitResult, data_path: Path | str) -> Parameters:
    """The fitted parameter set with its provenance recorded: a ``[sources]`` entry naming the data file, its
    hash and how the fit ended; grade ``identified`` on the identified values, ``at bound`` on moved values
    that ended on their search bound, ``assumed`` (with that source) on other values that moved without being
    identified; values that did not move keep their grade and source; the criteria and the outcome in
    ``[about]``."""
    digest = file_sha256(data_path)
    key = f"fit_{digest[:12]}"
    stamp = datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
    text = (f"ehm fit to {Path(data_path).name} (sha256 {digest}) on {stamp}: criterion (Eqs. 2-3) "
            f"{result.crit_before:.6g} -> {result.crit_after:.6g} (linear model)")
    if result.crit_after_time is not None:
        text += f", {result.crit_before_time:.6g} -> {result.crit_after_time:.6g} (time-domain check)"
    text += f"; {result.verdict}"
    p = result.params.with_source(key, text)
    pinned = {b[0] for b in result.at_bound}
    identified = {k: result.final[k] for k in result.identified}
    on_bound = {k: result.final[k] for k in result.moved if k in pinned}
    unconfirmed = {k: result.final[k] for k in result.moved if k not in result.identified and k not in pinned}
    for values, grade in ((identified, "identified"), (on_bound, "at bound"), (unconfirmed, "assumed")):
        if values:
            p = p.with_values(values, grade=grade, source=key)
    return p.with_about({
        "fit_data": Path(data_path).name, "fit_data_sha256": digest, "fit_date": stamp,
        "fit_free": list(result.free), "fit_identified": list(result.identified),
        "fit_at_bound": [p for p, _, _ in result.at_bound],
        "fit_stopped": result.stopped, "fit_evaluations": result.n_eval, "fit_max_evals": result.max_evals,
        "fit_verdict": result.verdict,
        "fit_criterion_before": result.crit_before, "fit_criterion_after": result.crit_after,
        **({"fit_criterion_before_time_domain": result.crit_before_time,
            "fit_criterion_after_time_domain": result.crit_after_time} if result.crit_after_time is not None else {}),
    })


def write_identified(result: FitResult, data_path: Path | str, out: Path | str) -> Parameters:
    """Write the fitted parameter file (see :func:`identified_parameters`); refuses to overwrite the shipped
    defaults."""
    p = identified_parameters(result, data_path)
    p.export(out)
    return p


def print_progress(line: str) -> None:
    """Progress lines to stderr (the fit's default reporter on the command line)."""
    print(line, file=sys.stderr, flush=True)
