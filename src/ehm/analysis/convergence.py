"""Is the time step small enough?  The model's transfer functions against the same model at a finer step.

A figure the model prints (a transmissibility peak, a fitted stiffness, a comfort value) should belong to
the person and the seat, not to the integrator's step.  :func:`~ehm.check_step` builds the same person at the
step under test and at finer steps (step / 8 and step / 4 by default), computes the exact frequency
response of each linearised model (:func:`ehm.linear_frf`) and reports, for every seat-to-body path,
the largest gain difference over the band as a share of the finer model's peak gain::

    error = max_f |G_dt(f) - G_fine(f)| / max_f G_fine(f)

Paths count unless they are symmetric zeros or below 5 % of the largest path of the same kind
(translation or rotation) for that input axis.  The default person is converged (every path within 2 %)
at its default step of 1 ms, the paper's step (``DEFAULT_STEP_ERRORS``).

>>> from ehm.analysis.convergence import check_step
>>> check = check_step()                     # the default person at its default step
>>> path, error = check.worst(8)             # the path furthest from the model at step / 8, and its error
>>> path, round(error, 3)
(('x', 'pelvis', 'z'), 0.01)
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..body.params import Parameters
from ..body.timestep import (  # noqa: F401 - re-exported: ehm.analysis.convergence.StepWarning etc.
    CONVERGED_STEP_S,
    DEFAULT_STEP_ERRORS,
    MIN_STEP_S,
    StepWarning,
    check_time_step,
    expected_error,
    warn_if_coarse,
)
from ..errors import InputError, checked, describe, frequency_grid
from ..person.person import Person, as_person
from .frf import AXES, DOFS, POINTS, linear_frf

#: Largest error of a transfer function against step / 8 [fraction of the path's peak gain] that counts as
#: converged.
TOLERANCE = 0.02
#: Paths whose peak gain is below this share of the largest path of the same kind are left out.
SMALL_PATH = 0.05
_FREQ_HZ = np.arange(0.2, 12.0 + 1e-9, 0.05)


@dataclass(frozen=True)
class StepCheck:
    """Transfer-function errors of a step against finer steps of the same model.

    Attributes
    ----------
    dt_s : float
        The step under test [s].
    errors : dict
        ``ratio -> {(input_axis, point, dof): error}``: error against step / ratio, as a fraction of the
        finer model's peak gain on that path.
    at_hz : dict
        ``ratio -> {path: frequency [Hz] of the largest difference}``.
    peaks : dict
        ``path -> (frequency [Hz], peak gain)`` of the finest model.
    """

    dt_s: float
    errors: dict
    at_hz: dict
    peaks: dict

    def worst(self, ratio: int = 8) -> tuple[tuple, float]:
        """The path with the largest error against step / ``ratio`` and that error (fraction)."""
        path = max(self.errors[ratio], key=self.errors[ratio].get)
        return path, float(self.errors[ratio][path])

    def converged(self, ratio: int = 8, tolerance: float = TOLERANCE) -> bool:
        """Whether every path is within ``tolerance`` of step / ``ratio``."""
        return self.worst(ratio)[1] <= tolerance

    def rows(self) -> list[dict]:
        """One dict per path: path, peak, and the error [%] against each finer step (for tables and JSON)."""
        ratios = sorted(self.errors, reverse=True)
        out = []
        for path in sorted(self.errors[ratios[0]], key=lambda p: -self.errors[ratios[0]][p]):
            f, g = self.peaks[path]
            row = {"input_axis": path[0], "point": path[1], "dof": path[2], "peak_hz": f, "peak_gain": g}
            for r in ratios:
                row[f"error_vs_step_over_{r}_pct"] = 100 * self.errors[r][path]
                row[f"at_hz_vs_step_over_{r}"] = self.at_hz[r][path]
            out.append(row)
        return out


def path_errors(table, reference, small_path: float = SMALL_PATH) -> tuple[dict, dict]:
    """Per path: largest |gain - reference gain| over the reference's peak gain, and where it occurs [Hz].

    Both tables must share their frequencies.  Paths below ``small_path`` of the largest path of the same
    kind (translation or rotation) for the same input axis are left out.
    """
    peaks = {k: float(c.gain.max()) for k, c in reference.curves.items()}
    errors, at_hz = {}, {}
    for axis in AXES:
        for kind in (DOFS[:3], DOFS[3:]):
            paths = [(axis, p, d) for p in POINTS for d in kind if (axis, p, d) in reference.curves]
            if not paths:
                continue
            big = max(peaks[k] for k in paths)
            for k in paths:
                if peaks[k] < small_path * big or peaks[k] == 0:
                    continue
                diff = np.abs(table.curves[k].gain - reference.curves[k].gain)
                i = int(np.argmax(diff))
                errors[k], at_hz[k] = float(diff[i] / peaks[k]), float(reference.curves[k].freq_hz[i])
    return errors, at_hz


@checked
def check_step(params: Person | Parameters | str | None = None, dt_s: float | None = None, lock=(), unlock=(),
               size=None, ratios=(8, 4), freq_hz: np.ndarray | None = None) -> StepCheck:
    """Compare the linearised model at ``dt_s`` with the same model at ``dt_s / ratio`` for each ratio.

    Parameters
    ----------
    params : Person, Parameters, path or None
        The person (:class:`ehm.Person`: its posture, back support, head control, locks and size are checked as
        they are), or its parameters (default: the shipped defaults).
    dt_s : float, optional
        Step to check [s] (default: the person's own ``dt_s``, else the step it runs at,
        :meth:`ehm.Parameters.time_step`: for the shipped slouched posture its own 0.5 ms).
    lock, unlock, size
        Shortcuts that build (or change) the :class:`ehm.Person`, as for :class:`ehm.SeatedHuman`.
    ratios : sequence of int
        Finer steps to compare with, as divisors of ``dt_s``.
    freq_hz : array, optional
        Frequencies [Hz] (default 0.2 to 12 Hz in 0.05 Hz steps).

    Costs a settling run at each step (10 s of simulated time; the whole check about 3 s at the default 1 ms).
    """
    from ..simulation import SeatedHuman

    person = as_person(params, lock=lock, unlock=unlock, size=size)
    if dt_s is None:
        dt_s = person.dt_s
    dt = person.seated_params().time_step() if dt_s is None else check_time_step(dt_s, "dt_s")
    try:
        ratios = tuple(int(r) for r in ratios)
    except (TypeError, ValueError):
        raise InputError(f"check_step: ratios must be whole numbers, the divisors of the step (e.g. (8, 4)), not "
                         f"{describe(ratios)}.") from None
    if not ratios or min(ratios) < 2:
        raise InputError(f"the finer steps are given as divisors of the step, each 2 or more; got {ratios}.")
    if dt / max(ratios) < MIN_STEP_S:
        raise InputError(f"the step to check, {dt:g} s, is too short to compare with a step {max(ratios)} times "
                         f"finer: steps below {MIN_STEP_S * 1e6:g} us are not run (check {MIN_STEP_S * max(ratios):g} "
                         "s or longer).")
    f = _FREQ_HZ if freq_hz is None else frequency_grid("check_step", freq_hz)

    def table(step_s: float):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", StepWarning)  # the coarse step is what is being checked
            human = SeatedHuman(person.replace(dt_s=step_s))
        return linear_frf(human, freq_hz=f, discrete=True)

    tables = {r: table(dt / r) for r in ratios}
    finest = tables[max(ratios)]
    at_step = table(dt)
    errors, at_hz = {}, {}
    for r in ratios:
        errors[r], at_hz[r] = path_errors(at_step, tables[r])
    peaks = {}
    for k in errors[max(ratios)]:
        c = finest.curves[k]
        i = int(np.argmax(c.gain))
        peaks[k] = (float(c.freq_hz[i]), float(c.gain[i]))
    return StepCheck(dt_s=dt, errors=errors, at_hz=at_hz, peaks=peaks)
