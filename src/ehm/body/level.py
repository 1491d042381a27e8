"""The vibration magnitude as part of the person: the stiffness and damping that soften as the vibration grows.

The seated body softens as the vibration grows (its vertical apparent-mass resonance falls from about 6 Hz at
0.25 m/s^2 rms to about 4 Hz at 2.0 m/s^2: Fairley & Griffin 1989; Mansfield & Griffin 2000); the mechanism taken is
that the stiffness of soft tissue and muscle falls with the amplitude of the motion (muscle thixotropy).  A parameter
file's ``[level]`` table names the entries that follow the level (``scaled``) and the law: with the seat's vibration
rms ``a`` clipped to ``[least_rms_mps2, greatest_rms_mps2]``, a stiffness ``k`` becomes
``k * (a / reference_rms_mps2) ** -stiffness_exponent`` and a damping ``c`` becomes
``c * (a / reference_rms_mps2) ** -damping_exponent`` (docs/model.md, "Vibration magnitude").

>>> from ehm import Parameters
>>> from ehm.body.level import at_level, level_factors
>>> p = Parameters.load()
>>> at_level(p, 1.0) is p                     # the reference level: the parameters themselves
True
>>> k_factor, c_factor = level_factors(p, 2.0)
>>> print(f"{k_factor:.4f} {c_factor:.4f}")    # 2 ** -0.3, 2 ** -0.15
0.8123 0.9013
>>> q = at_level(p, 2.0)
>>> q.value("contacts.buttock_r.stiffness_N_per_m") == p.value("contacts.buttock_r.stiffness_N_per_m") * k_factor
True
"""

from __future__ import annotations

import math

from ..errors import InputError, checked, describe
from .params import Parameters

#: The key of ``[about]`` that records the level a parameter set was scaled to [m/s^2 rms] (:func:`at_level`).
APPLIED_KEY = "vibration_rms_mps2"


def check_level(value: object, name: str = "vibration_rms_mps2", option: str = "--vibration-rms",
                still: bool = False) -> float:
    """``value`` as a vibration level [m/s^2 rms]: a positive finite number (``still``: or 0, a drive without
    vibration, which the law clips to ``level.least_rms_mps2``), else one sentence naming the Python argument
    ``name`` and the command-line option."""
    ok = not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)
    if not ok or value < 0 or (value == 0 and not still):
        raise InputError(f"{name} ({option}) = {describe(value)} is not a vibration level; give the seat's "
                         "vibration as a positive number in m/s^2 rms (e.g. 0.5), or None to take the drive's own.")
    return float(value)


def quantised(rms_mps2: float) -> float:
    """The level rounded to two significant digits (so that runs of similar drives share one build).

    >>> quantised(0.5349), quantised(1.0), quantised(12.34)
    (0.53, 1.0, 12.0)
    """
    return float(f"{check_level(rms_mps2, 'rms_mps2', still=True):.2g}")


def has_level(params: Parameters) -> bool:
    """Whether the parameters scale with the vibration level (their file has a ``[level]`` table)."""
    return isinstance(params.data.get("level"), dict)


def clipped(params: Parameters, rms_mps2: float) -> float:
    """The level the law uses: ``rms_mps2`` clipped to ``[level.least_rms_mps2, level.greatest_rms_mps2]`` (the
    level itself for parameters without ``[level]``)."""
    rms = check_level(rms_mps2, "rms_mps2", still=True)
    if not has_level(params):
        return rms
    return min(max(rms, float(params.value("level.least_rms_mps2"))), float(params.value("level.greatest_rms_mps2")))


def level_factors(params: Parameters, rms_mps2: float) -> tuple[float, float]:
    """(stiffness factor, damping factor) at the level ``rms_mps2`` [m/s^2 rms]: ``(a / a_ref) ** -n`` and
    ``(a / a_ref) ** -m`` of the clipped level (1, 1 for parameters without ``[level]``)."""
    if not has_level(params):
        check_level(rms_mps2, "rms_mps2", still=True)
        return 1.0, 1.0
    ratio = clipped(params, rms_mps2) / float(params.value("level.reference_rms_mps2"))
    return (ratio ** -float(params.value("level.stiffness_exponent")),
            ratio ** -float(params.value("level.damping_exponent")))


def scaled_paths(params: Parameters) -> tuple[list[str], list[str]]:
    """The dotted paths of the stiffness and of the damping values that follow the level (``level.scaled``: a
    contact's normal and shear stiffness and damping, a joint degree of freedom's stiffness and damping)."""
    stiffness, damping = [], []
    if not has_level(params):
        return stiffness, damping
    for name in params.value("level.scaled"):
        for key in params.section(name):
            if "stiffness" in key:
                stiffness.append(f"{name}.{key}")
            elif "damping" in key:
                damping.append(f"{name}.{key}")
    return stiffness, damping


@checked
def at_level(params: Parameters, rms_mps2: float) -> Parameters:
    """The parameters of a person at the seat's vibration level ``rms_mps2`` [m/s^2 rms]: a copy with the entries of
    ``level.scaled`` scaled by the law of ``[level]`` (module docstring).  At the reference level, and for
    parameters without ``[level]``, the parameters themselves, bit for bit.

    The copy holds the values at that level: its ``[level]`` table is left out (so that a level is never applied
    on top of another one: the copy, exported and read back, keeps its values at every level) and ``[about]``
    records the level (``vibration_rms_mps2``, the level asked for; the law used it clipped, ``clipped``).
    """
    rms = check_level(rms_mps2, "rms_mps2", still=True)
    k_factor, c_factor = level_factors(params, rms)
    if k_factor == 1.0 and c_factor == 1.0:
        return params
    stiffness, damping = scaled_paths(params)
    updates = {path: float(params.value(path)) * k_factor for path in stiffness}
    updates.update({path: float(params.value(path)) * c_factor for path in damping})
    scaled = params.with_values(updates)  # a deep copy, checked: its data is this function's own
    del scaled.data["level"]
    return scaled.with_about({APPLIED_KEY: rms})


def applied_level(params: Parameters) -> float | None:
    """The level [m/s^2 rms] parameters were scaled to by :func:`at_level` (``[about]``), or None."""
    about = params.data.get("about", {})
    value = about.get(APPLIED_KEY) if isinstance(about, dict) else None
    return None if value is None else float(value)


__all__ = ["APPLIED_KEY", "applied_level", "at_level", "check_level", "clipped", "has_level", "level_factors",
           "quantised", "scaled_paths"]
