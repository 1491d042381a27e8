"""The time step's known error: how far the default person's transfer functions are off at a given step, and the
warning a step coarser than the converged one gives.

A leaf below :mod:`ehm.simulation` (which warns when a person is built) and :mod:`ehm.convergence` (which measures
the error for any person: ``ehm check-step``); both take these names from here.
"""

from __future__ import annotations

import warnings

import numpy as np

__all__ = ["CONVERGED_STEP_S", "DEFAULT_STEP_ERRORS", "StepWarning", "expected_error", "warn_if_coarse"]

#: ``ehm check-step`` on the default person, worst path against step / 8, by step [s] (measured with
#: ehm 0.1 on this formulation: trapezoidal contacts and trunk/neck damping, Euler; README "Time step and
#: accuracy").  Between the steps listed the error is interpolated, beyond them extrapolated in proportion
#: to the step.
DEFAULT_STEP_ERRORS = {0.0005: 0.0066, 0.001: 0.0166, 0.0015: 0.045, 0.002: 0.091, 0.004: 0.43}
#: The largest step at which the default person is converged [s].
CONVERGED_STEP_S = 0.001


class StepWarning(UserWarning):
    """A time step coarser than the one at which the model is converged."""


def expected_error(dt_s: float) -> float:
    """The default person's worst transfer-function error at step ``dt_s`` against step / 8 (fraction)."""
    steps = np.array(sorted(DEFAULT_STEP_ERRORS))
    errors = np.array([DEFAULT_STEP_ERRORS[s] for s in steps])
    if dt_s >= steps[-1]:
        return float(errors[-1] * dt_s / steps[-1])
    if dt_s <= steps[0]:
        return float(errors[0] * dt_s / steps[0])
    return float(np.interp(dt_s, steps, errors))


def warn_if_coarse(dt_s: float, where: str = "the time step") -> None:
    """Warn (:class:`StepWarning`, one sentence) when ``dt_s`` is coarser than the converged step."""
    if dt_s > CONVERGED_STEP_S * (1 + 1e-9):
        warnings.warn(
            f"{where} dt = {dt_s * 1e3:g} ms is coarser than the {CONVERGED_STEP_S * 1e3:g} ms at which the model "
            f"is converged: expect transfer functions to be off by up to about {100 * expected_error(dt_s):.0f} % "
            f"of their peak (run 'ehm check-step --dt {dt_s:g}' to measure it for this person).",
            StepWarning, stacklevel=3)
