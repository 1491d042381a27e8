"""The time step's known error: how far the default person's transfer functions are off at a given step, and the
warning a step coarser than the converged one gives.

A leaf below :mod:`ehm.simulation` (which warns when a person is built) and :mod:`ehm.analysis.convergence` (which
measures
the error for any person: ``ehm check-step``); both take these names from here.
"""

from __future__ import annotations

from numbers import Real

import numpy as np

from ..errors import EhmWarning, InputError, describe, warn

__all__ = ["CONVERGED_STEP_S", "DEFAULT_STEP_ERRORS", "MAX_STEP_S", "MIN_STEP_S", "POSTURE_STEP_ERRORS", "StepWarning",
           "check_time_step", "expected_error", "warn_if_coarse"]

#: ``ehm check-step`` on the default person, worst path against step / 8, by step [s] (measured with
#: ehm 0.1 on this formulation: trapezoidal contacts and trunk/neck damping, Euler; README "Time step and
#: accuracy").  Between the steps listed the error is interpolated, beyond them extrapolated in proportion
#: to the step.
DEFAULT_STEP_ERRORS = {0.0005: 0.0090, 0.001: 0.0100, 0.0015: 0.0341, 0.002: 0.0735, 0.004: 0.391}
#: The largest step at which the default person is converged [s] (a posture may have its own: postures.NAME.dt_s).
CONVERGED_STEP_S = 0.001
#: The same for postures with a converged step of their own (postures.NAME.dt_s), measured, by posture name: none
#: of the shipped postures has one (each converges at the shipped 1 ms, docs/model.md, postures); a posture not
#: listed gets the default person's errors scaled by the ratio of the converged steps (:func:`expected_error`).
POSTURE_STEP_ERRORS: dict = {}


#: The shortest time step taken [s]: a step costs about 30 us of wall time (measured, default person), so the
#: 10 s of settling alone take about 5 min at 1 us and hours below, for no accuracy to gain (0.6 % at 0.5 ms).
MIN_STEP_S = 1e-6
#: The longest time step taken [s]: the default person still settles at 10 ms (its transfer functions off by up to
#: 363 % of their peak) and diverges at 20 ms (measured), and 10 ms resolves the 0.5-80 Hz of ISO 2631-1 no longer
#: (Nyquist 50 Hz).
MAX_STEP_S = 0.01


def check_time_step(dt_s, name: str = "dt_s") -> float:
    """``dt_s`` as a float within :data:`MIN_STEP_S` ... :data:`MAX_STEP_S`, or one sentence naming ``name`` and the
    range (the one check of a time step, wherever it enters: a parameter file, ``dt_s=``, ``--dt``)."""
    ok = isinstance(dt_s, Real) and not isinstance(dt_s, bool) and MIN_STEP_S <= dt_s <= MAX_STEP_S  # NaN: False
    if not ok:
        raise InputError(f"{name} = {describe(dt_s)} is not a plausible time step: it must be a number of seconds from "
                         f"{MIN_STEP_S * 1e6:g} us to {MAX_STEP_S * 1e3:g} ms (the model is converged at "
                         f"{CONVERGED_STEP_S * 1e3:g} ms; below {MIN_STEP_S * 1e6:g} us settling alone takes hours, "
                         f"above {MAX_STEP_S * 1e3:g} ms the answers are off by more than their size and the person "
                         "soon diverges).")
    dt = float(dt_s)
    return dt


class StepWarning(EhmWarning):
    """A time step coarser than the one at which the model is converged."""


def expected_error(dt_s: float, converged_s: float = CONVERGED_STEP_S, posture: str | None = None) -> float:
    """The worst transfer-function error at step ``dt_s`` against step / 8 (fraction) of the default person, or of a
    person in ``posture`` converged at ``converged_s``: measured for the postures of :data:`POSTURE_STEP_ERRORS`;
    for another one, the default person's error at the step scaled by the ratio of the converged steps."""
    table = POSTURE_STEP_ERRORS.get(posture) if converged_s != CONVERGED_STEP_S else None
    if table is None:
        table, dt_s = DEFAULT_STEP_ERRORS, dt_s * CONVERGED_STEP_S / converged_s
    steps = np.array(sorted(table))
    errors = np.array([table[s] for s in steps])
    if dt_s >= steps[-1]:
        return float(errors[-1] * dt_s / steps[-1])
    if dt_s <= steps[0]:
        return float(errors[0] * dt_s / steps[0])
    return float(np.interp(dt_s, steps, errors))


def warn_if_coarse(dt_s: float, where: str = "the time step", converged_s: float = CONVERGED_STEP_S,
                   posture: str | None = None) -> None:
    """Warn (:class:`StepWarning`, one sentence) when ``dt_s`` is coarser than the converged step ``converged_s`` (a
    posture's own, :meth:`ehm.Parameters.converged_step`, named by ``posture``)."""
    if dt_s > converged_s * (1 + 1e-9):
        own = converged_s != CONVERGED_STEP_S and posture is not None
        model, option = (f"the model in the {posture} posture", f" --posture {posture}") if own else ("the model", "")
        error = expected_error(dt_s, converged_s, posture)
        warn(
            f"{where} dt = {dt_s * 1e3:g} ms is coarser than the {converged_s * 1e3:g} ms at which {model} "
            f"is converged: expect transfer functions to be off by up to about {100 * error:.0f} % "
            f"of their peak (run 'ehm check-step --dt {dt_s:g}{option}' to measure it for this person).",
            StepWarning, stacklevel=3)
