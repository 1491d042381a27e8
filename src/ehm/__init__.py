"""ehm: an efficient seated human model for whole-body vibration and motion comfort, on MuJoCo.

The model is the 12-segment, 28-degree-of-freedom seated person of Desai et al. ("Computationally
efficient human body modelling for real time motion comfort assessment", TU Delft), with ellipsoid
contacts to a seat pan, a two-pad backrest and the floor.

Public API
----------
Person             who sits where, as one value (parameters, size, posture, back support, head control, locks,
                   step): every entry point below takes it
SeatedHuman        one person on one seat: ``info()``, ``simulate(motion)``, ``stream``, ``linear_model()``
simulate_parallel  a long nonlinear run in segments on several processes or a Dask cluster
RunResult          a run's time histories by name: ``run.point("head").acc_mps2``
PointMotion        acceleration, displacement and rotation of pelvis, trunk, head or lumbar spine
Simulator, StepState    step by step (one seat acceleration per call) and real time
SeatMotion         a seat acceleration history (``resample``: anti-aliased polyphase)
random_vibration, sine, sweep    generated seat motions
read_motion        a measured motion from .csv/.txt, .parquet, .mat, .mf4/.mdf or a DataFrame, any names,
                   units and rate (``load_motion_csv``: the same with the default names)
from_imu           the seat's motion from an IMU log (specific force and gyro rates)
city_drive, rough_road    SYNTHETIC drives
assess, Assessment       ISO 2631-1 comfort, ISO 2631-5 spinal dose and motion sickness of a drive, seat and body
read_assessment    an ``ehm assess`` run folder back as an Assessment (or a DataFrame, ``as_frame=True``)
fit_sickness, read_ratings    one person's MISC parameters (K1, T1) fitted to their ratings of a drive
MiscParameters, read_sickness_params    the MISC accumulation model's parameters: the group's, or a person's file
FrfTable, linear_frf, time_domain_frf, read_frf    transmissibility and apparent mass tables
compare            the paper's criterion (Eqs. 2-3) of measured against model curves
check_step, StepWarning    transfer functions at a time step against the same model at finer steps
validate, Validation    the person against the standards' reference curves and the paper's findings (``ehm validate``)
LinearRouteError   an input too large for the linear route (a contact lifts off or slides)
Parameters         a checked parameter file (``Parameters.load``, ``.with_values``, ``.export``)
at_level           the parameters at a seat vibration level (the ``[level]`` table: tissue and muscle soften as the
                   vibration grows; ``Person(vibration_rms_mps2=...)`` builds a person at one)
BodySize           individual body sizes (stature, mass, sitting height)
load_body          the body tables (segments, joints, contacts)
Curve, h1_estimate seat-to-body transfer function from time histories
EhmError, InputError, DivergenceError    what goes wrong, in one sentence
EhmWarning         the category of ehm's warnings (StepWarning, LinearRouteWarning, the readers' notes)

Modules
-------
ehm.inputs.readers  outside data formats (the one door for them)
ehm.inputs.imu     IMU logs to seat motion
ehm.analysis.frf   FRF tables: time_domain_frf, linear_frf, read_frf_csv, read_frf
ehm.analysis.criterion  the paper's criterion (Eqs. 2-3): compare, curve_criterion, small_curves
ehm.analysis.fit   parameter identification: fit, write_identified
ehm.analysis.study  the joint-locking study: locking_study
ehm.standards.comfort  ISO 2631-1 weightings (any sampling rate) and metrics; ISO 2631-5 spinal dose
(ehm.standards.comfort.spine)
ehm.standards.references  reference curves, bands and the paper's findings, with their sources
ehm.analysis.validation  the person against them: validate, band_checks, locking_checks
ehm.standards.sickness  subjective vertical conflict motion sickness model (whole record, or piece by piece:
                   SicknessAccumulator), MSI and a predicted MISC rating
ehm.routes.linear         the linearised person as a state-space model (the linear route)
ehm.analysis.convergence  is the time step small enough? (``ehm check-step``)
ehm.interfaces.batch  batch studies on Dask; ehm.interfaces.fmu FMI export; ehm.outputs.animation pictures;
ehm.outputs.plotting figures
ehm.outputs.dataframes  results out: ``to_dataframe()`` (pandas), ``to_xarray()``, the tables a notebook shows

Conventions: SI units, radians inside; axes x forward, y left, z up; origin at the pelvis centre of
gravity of the reference posture.
"""

from . import _compat

_compat.install()  # the modules' old paths keep working for one release, with a DeprecationWarning
__getattr__ = _compat.old_attribute

__version__ = "0.1.0"

from .analysis.assessment import Assessment, assess, read_assessment
from .analysis.convergence import StepWarning, check_step
from .analysis.criterion import compare
from .analysis.frf import FrfTable, linear_frf, read_frf, time_domain_frf
from .analysis.sickness_fit import fit_sickness, read_ratings
from .analysis.stepping import Simulator, StepState
from .analysis.validation import Validation, validate
from .body.level import at_level
from .body.params import Parameters
from .body.tables import load_body
from .errors import DivergenceError, EhmError, EhmWarning, InputError
from .inputs.drives import city_drive, rough_road
from .inputs.imu import from_imu
from .inputs.motion import SeatMotion, random_vibration, sine, sweep
from .inputs.readers import load_motion_csv, read_motion
from .person import Person
from .person.scaling import BodySize
from .routes.linear import LinearRouteError
from .routes.parallel import simulate_parallel
from .simulation import PointMotion, RunResult, SeatedHuman
from .standards.sickness import MiscParameters, read_sickness_params
from .standards.transfer import Curve, h1_estimate

__all__ = [
    "DivergenceError", "EhmError", "EhmWarning", "InputError",
    "Person", "SeatedHuman", "RunResult", "PointMotion", "simulate_parallel", "Simulator", "StepState",
    "SeatMotion", "random_vibration", "sine", "sweep", "read_motion", "load_motion_csv", "from_imu",
    "city_drive", "rough_road", "assess", "Assessment", "read_assessment", "fit_sickness", "read_ratings",
    "read_sickness_params", "MiscParameters",
    "FrfTable", "linear_frf", "time_domain_frf", "read_frf", "compare",
    "Parameters", "at_level", "BodySize", "load_body", "Curve", "h1_estimate", "check_step", "StepWarning",
    "LinearRouteError", "validate", "Validation", "__version__",
]
