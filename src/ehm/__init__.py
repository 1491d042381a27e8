"""ehm: an efficient seated human model for whole-body vibration and motion comfort, on MuJoCo.

The model is the 12-segment, 28-degree-of-freedom seated person of Desai et al. ("Computationally
efficient human body modelling for real time motion comfort assessment", TU Delft), with ellipsoid
contacts to a seat pan, a two-pad backrest and the floor.

Public API
----------
SeatedHuman        one person on one seat: ``info()``, ``simulate(motion)``
RunResult          a run's time histories by name: ``run.point("head").acc_mps2``
PointMotion        acceleration, displacement and rotation of pelvis, trunk or head
SeatMotion         a seat acceleration history
random_vibration, sine, sweep, load_motion_csv    seat motions
Parameters         a checked parameter file (``Parameters.load``, ``.with_values``, ``.export``)
load_body          the body tables (segments, joints, contacts)
h1_estimate        seat-to-body transfer function from time histories

Modules
-------
ehm.frf            FRF tables: time_domain_frf, linear_frf, read_frf_csv
ehm.criterion      the paper's criterion (Eqs. 2-3): compare, curve_criterion
ehm.fit            parameter identification: fit, write_identified
ehm.study          the joint-locking study: locking_study
ehm.comfort        ISO 2631-1 weightings and metrics
ehm.sickness       subjective vertical conflict motion sickness model
EhmError, InputError, DivergenceError    what goes wrong, in one sentence

Conventions: SI units, radians inside; axes x forward, y left, z up; origin at the pelvis centre of
gravity of the reference posture.
"""

__version__ = "0.1.0"

from .errors import DivergenceError, EhmError, InputError
from .motion import SeatMotion, load_motion_csv, random_vibration, sine, sweep
from .params import Parameters
from .simulation import PointMotion, RunResult, SeatedHuman
from .tables import load_body
from .transfer import Curve, h1_estimate

__all__ = [
    "DivergenceError", "EhmError", "InputError", "SeatMotion", "load_motion_csv", "random_vibration", "sine",
    "sweep", "Parameters", "PointMotion", "RunResult", "SeatedHuman", "load_body", "Curve",
    "h1_estimate", "__version__",
]
