"""The MuJoCo engine: builds the seated human from the tables and parameters, settles it, runs it.

This package is the only place that imports :mod:`mujoco`; the rest of ehm uses the names re-exported here
(``from . import engine``; ``engine.build``, ``engine.run``, ...).

Map of the package (each module one idea; underscore names are private to the package):

* :mod:`.model`: the :class:`Model` record and the shared names (:data:`G0`, :data:`POINTS` with
  :data:`POINT_JOINTS`, :data:`SUPPORT_GROUPS`).
* :mod:`.seat_geometry`: the seat surfaces as planes (:class:`SeatGeometry`), their checks (:func:`check_seat`) and the
  rotating seat's constants (:data:`SEAT_DOFS`, :data:`SEAT_INERTIA_KGM2`).
* :mod:`.inertia`: a segment's own mass properties with its tissue pads taken out, and the rigid-body check
  (:func:`inertia_problem`).
* :mod:`.builder`: :func:`build`, in named steps: solver options, seat surfaces, segments with joints, mass
  and pads, contact pairs, actuators, sensors.
* :mod:`.laws`: the force laws set into MuJoCo: trapezoidal joint damping (:data:`TRAPEZOIDAL_JOINTS`) and the
  contacts' spring, damper and friction (:func:`contact_solver_params`, :data:`FRICTION_SOFTNESS`).
* :mod:`.diagnostics`: MuJoCo's warnings captured (:func:`captured_warnings`, :func:`take_warnings`), the
  compiler's refusal and the divergence check as sentences (:data:`DIVERGED_M`, :data:`CHECK_EVERY`).
* :mod:`.state`: a fresh state, settling into the seat (:func:`settle`, :func:`settled_data`,
  :func:`settled_point_poses`), the integration state to save and restore (:func:`get_state`,
  :func:`set_state`).
* :mod:`.sensors`: sensor addresses, support forces and contact forces of a state.
* :mod:`.stepper`: :func:`step`, :func:`run` (a :class:`RawRun`), the point accelerations of the
  integrated motion, and the drawn bodies' poses in a linear model's states (:func:`deviation_poses`).
* :mod:`.control`: the head-in-space control as the engine applies it (:class:`HeadControl`, after every step), and
  :mod:`.control_linear` its linear model (:func:`feedback`, the delay as Padé states) and :func:`close_loop`; the
  delay handed between the models: the engine's line of torques (:func:`line_torques`, :func:`load_line`, the torques
  of recorded states :func:`control_torques`) and the Padé states a torque history leaves (:func:`pade_steps`).
* :mod:`.linearisation`: :func:`linearize` into a :class:`LinearModel`, optionally with the seat rotation's
  fictitious loads about :func:`seat_pivot` as inputs (:func:`rotation_loads`).
* :mod:`.export`: the compiled model as an MJB file, the MuJoCo C library (both for the native FMU) and the
  geometry for pictures.
* :mod:`.native`: :func:`run`'s stepping loop compiled (``native/ehm_steps.c``, built at first use and cached), so
  that Python stays outside the per-step loop; the Python loop where no C compiler is found.

How the paper's model maps onto MuJoCo (measured in the project's feasibility study and re-checked by
the tests):

* Segments are bodies whose frames sit at their parent joint, axes parallel to the global axes in the
  reference posture, so every joint angle is zero in that posture.  The pelvis has a free joint.
* Spherical joints are three hinges (roll x, pitch y, yaw z), the universal lower neck two (roll, pitch),
  T12 a vertical slide plus three hinges, knees and ankles one hinge about y.  A locked joint is left out:
  its child is welded to its parent.
* Every degree of freedom has a linear spring and damper (MuJoCo joint stiffness and damping: the P and
  D of the paper's PID posture control).  The I part is MuJoCo's PID actuator with zero P and D gains
  (ki = k / Ti) on the open-chain joints named in ``posture.integral_joints``.
* The damping of trunk and neck joints is integrated by the trapezoidal rule, so that the step's error is
  of second order in it: half of it is MuJoCo joint damping, which the Euler integrator treats implicitly
  (the velocity at the step's end), and half an actuator whose bias force is -c/2 times the joint velocity,
  which it treats explicitly (the velocity at the step's start) (:func:`split_damping`).  The other
  joints' damping is implicit.
* Contacts are explicit ellipsoid-plane pairs with a linear spring K and damper B on penetration,
  elliptic friction cones and the NoSlip solver; seat and backrest ellipsoids ride on soft-tissue pads
  (two tangential slide springs) so that friction neither creeps nor locks.  On the tissue pads the
  contact force is the trapezoidal one, f = -K r - B (v + v') / 2 with v' the velocity at the step's
  end, which MuJoCo's soft constraint gives exactly with regulariser R = 2 / (B h) and reference
  acceleration -(2 K / (B h)) r - (2 / h) v (:func:`contact_solver_params`); as h goes to 0 it is the
  spring and damper.  The feet keep the explicit f = -K r - B v.  The pads' slide joints carry an
  armature (``simulation.pad_armature_kg``): the NoSlip solver makes a pad stick for the mass matrix M,
  while the integrator advances with M + h D; the armature keeps h D small against the pad's inertia so
  that a stuck pad stays put.
* Point accelerations are taken from the integrated motion (velocity change over the step plus the seat
  acceleration, :func:`point_accelerations`), not from MuJoCo's acceleration sensors, which report the
  explicit acceleration of the step's start.
* Seat translation is applied as a d'Alembert load: the seat stays put and gravity becomes
  ``g0 - a_seat(t)``.
"""

from .builder import build
from .control import HeadControl, line_torques, load_line
from .control import torques_of as control_torques
from .control_linear import (
                             CONTROL_INPUTS,
                             Feedback,
                             PadeSteps,
                             close_loop,
                             closed_linear_model,
                             delay_line,
                             feedback,
                             pade_steps,
)
from .control_linear import gains as control_gains
from .diagnostics import CHECK_EVERY, DIVERGED_M, captured_warnings, dof_name, take_warnings
from .export import c_library, drawing_geometry, save_binary
from .inertia import PAD_INERTIA_KGM2, ImpossibleInertia, inertia_problem, segment_mass_properties
from .laws import FRICTION_SOFTNESS, TRAPEZOIDAL_JOINTS, contact_solver_params
from .linearisation import (
                             FIELD_INPUTS,
                             OUTPUT_DOFS,
                             ROTATION_INPUTS,
                             S_ENTRIES,
                             LinearModel,
                             linearize,
                             rotation_loads,
                             seat_pivot,
)
from .model import G0, POINT_JOINTS, POINTS, SUPPORT_GROUPS, Model
from .native import NativeStepWarning, compiler_command
from .native import available as native_steps_available
from .seat_geometry import SEAT_DOFS, SEAT_INERTIA_KGM2, SeatGeometry, check_seat, seated_body
from .sensors import (
                             SENSOR_KINDS,
                             contact_forces,
                             sensor_slices,
                             sliding_contacts,
                             support_forces,
                             support_slices,
                             touching_contacts,
)
from .state import (
                             data_at_deviation,
                             deviation_of,
                             get_state,
                             new_data,
                             qpos_at_deviation,
                             rotating_data_at,
                             rotating_qpos,
                             set_seat,
                             set_state,
                             settle,
                             settled_data,
                             settled_point_poses,
                             static_deviation_of,
)
from .stepper import RawRun, deviation_poses, evaluate_velocities, point_accelerations, run, step

__all__ = [
    "CHECK_EVERY", "CONTROL_INPUTS", "DIVERGED_M", "Feedback", "HeadControl", "close_loop", "closed_linear_model",
    "control_gains", "control_torques", "delay_line", "feedback", "line_torques", "load_line", "PadeSteps",
    "pade_steps", "FIELD_INPUTS", "FRICTION_SOFTNESS", "G0", "OUTPUT_DOFS", "ROTATION_INPUTS",
    "S_ENTRIES", "PAD_INERTIA_KGM2", "POINT_JOINTS", "POINTS",
    "SEAT_DOFS", "SEAT_INERTIA_KGM2", "SENSOR_KINDS", "SUPPORT_GROUPS", "TRAPEZOIDAL_JOINTS",
    "ImpossibleInertia", "LinearModel", "Model", "NativeStepWarning", "RawRun", "SeatGeometry",
    "build", "c_library", "compiler_command", "captured_warnings", "check_seat", "contact_forces",
    "contact_solver_params",
    "data_at_deviation", "deviation_of", "deviation_poses", "dof_name", "drawing_geometry", "evaluate_velocities",
    "get_state", "inertia_problem", "linearize", "native_steps_available", "new_data", "point_accelerations",
    "qpos_at_deviation",
    "rotating_data_at", "rotating_qpos", "rotation_loads", "run",
    "save_binary", "seat_pivot", "seated_body", "segment_mass_properties", "sensor_slices", "set_seat", "set_state",
    "settle", "settled_data", "settled_point_poses", "sliding_contacts", "static_deviation_of", "step",
    "support_forces", "support_slices", "take_warnings", "touching_contacts",
]
