"""The person as built: what every route reads, handed down by the door (:class:`ehm.SeatedHuman`).

A route takes the person as data: a :class:`BuiltPerson` holds the body tables and parameters as built (scaled,
with the time step), the locked joints, the body size, the MuJoCo model (``ehm.engine.build``), the static-seat
model a rotating seat's linearisation runs on (built on demand, :attr:`BuiltPerson.static_model`) and the cache of
the linear models (:attr:`BuiltPerson.linear`, filled by :func:`ehm.routes.linear.linear_model`).  The routes read
its public attributes and never call back into the door.
"""

from __future__ import annotations

import copy
from collections import OrderedDict

import numpy as np

from .. import engine
from ..body.level import applied_level, at_level, has_level, quantised
from ..errors import InputError, describe

#: The people a :class:`BuiltPerson` keeps built at the drives' levels (:meth:`BuiltPerson.at_level`), the most
#: recently used first; each holds its MuJoCo model and settled state (a few MB).
KEPT_LEVELS = 8
#: Where a run's vibration level came from (``RunResult.extra["vibration_level"]["origin"]``).
GIVEN, FROM_DRIVE = "given", "from the drive"


class BuiltPerson:
    """One person built on one seat, as the routes read it.

    Parameters
    ----------
    body : ehm.body.tables.Body
        The body tables as built (scaled when the person has a body size).
    params : ehm.body.params.Parameters
        The parameters as built (posture, back support, head control, time step).
    locked : frozenset of str
        The locked joints.
    model : ehm.engine.Model
        The MuJoCo model built from them (``ehm.engine.build``).
    size : ehm.person.scaling.BodySize, optional
        The body size the tables were scaled to, if any.
    vibration_rms_mps2 : float, optional
        The vibration level [m/s^2 rms] the parameters are at (:func:`ehm.body.level.at_level`); None: the
        parameter file's reference level, and a drive runs on the person at its own level (:meth:`for_motion`).
    level_origin : str
        Where that level came from: ``"given"`` (the person's own), ``"from the drive"``.
    """

    def __init__(self, body, params, locked, model: engine.Model, size=None, vibration_rms_mps2: float | None = None,
                 level_origin: str = GIVEN):
        self.body, self.params, self.locked, self.model, self.size = body, params, locked, model, size
        self.vibration_rms_mps2, self.level_origin = vibration_rms_mps2, level_origin
        #: the linear route's models ("translation", "rotation"), built on first use (ehm.routes.linear.linear_model)
        self.linear = {}
        self._static = None
        self._levels = OrderedDict()  # quantised level -> the person built at it (at_level)

    @classmethod
    def build(cls, body, params, locked, rotating_seat: bool = False, size=None,
              vibration_rms_mps2: float | None = None, level_origin: str = GIVEN) -> BuiltPerson:
        """The person built from its tables and parameters (``ehm.engine.build``); ``vibration_rms_mps2``: the
        level the parameters are at (None: the reference level, following a drive's own)."""
        return cls(body, params, locked, engine.build(body, params, locked, rotating_seat=rotating_seat),
                   size, vibration_rms_mps2, level_origin)

    # ------------------------------------------------------------------ the vibration level
    def for_motion(self, motion) -> BuiltPerson:
        """The person a drive runs on: itself when its level is fixed (given, or already a drive's), else the person
        at the drive's own level (:attr:`ehm.SeatMotion.vibration_rms_mps2` of the WHOLE motion, quantised to two
        significant digits, :meth:`at_level`)."""
        if self.vibration_rms_mps2 is not None:
            return self
        return self.at_level(quantised(motion.vibration_rms_mps2))

    def at_level(self, rms_mps2: float, origin: str = FROM_DRIVE) -> BuiltPerson:
        """This person (built at the reference level) built at the level ``rms_mps2`` [m/s^2 rms]: the parameters
        as built scaled by :func:`ehm.body.level.at_level`, kept per level (the last ``KEPT_LEVELS``), so that
        a second run at the same level neither rebuilds nor settles again.  At the reference level (or for
        parameters without ``[level]``) the values are the same: the person shares this one's model, settled state
        and linear models."""
        if self.vibration_rms_mps2 is not None:
            raise InputError(f"this person is built at {self.vibration_rms_mps2:g} m/s^2 rms; build the person "
                             "without a level (vibration_rms_mps2=None) to run it at another.")
        key = float(rms_mps2)
        if key in self._levels:
            self._levels.move_to_end(key)
            return self._levels[key]
        params = at_level(self.params, rms_mps2)
        if params is self.params:  # the same values: the same model (its settled state and linear models too)
            person = copy.copy(self)
            person._levels = OrderedDict()
            person.vibration_rms_mps2, person.level_origin = float(rms_mps2), origin
        else:
            person = BuiltPerson.build(self.body, params, self.locked, rotating_seat=self.rotating_seat,
                                       size=self.size, vibration_rms_mps2=float(rms_mps2), level_origin=origin)
        self._levels[key] = person
        while len(self._levels) > KEPT_LEVELS:
            self._levels.popitem(last=False)
        return person

    @property
    def kept_levels(self) -> tuple[float, ...]:
        """The levels [m/s^2 rms] at which this person is kept built (:meth:`at_level`), least recently used first."""
        return tuple(self._levels)

    def level_record(self) -> dict:
        """The vibration level a run ran at, as plain data (``RunResult.extra["vibration_level"]``, ``summary.json``,
        ``assessment.json``): ``rms_mps2`` (None: the parameter file's reference level), ``origin``, ``scaled``
        (whether the parameters were changed for it, :func:`ehm.body.level.at_level`) and ``line``, one sentence."""
        level, origin = self.vibration_rms_mps2, self.level_origin
        scaled = applied_level(self.params) is not None
        if level is None:
            line = "vibration level: the parameter file's reference level"
        else:
            line = f"vibration level {level:g} m/s^2 rms ({origin})"
            if not scaled:
                line += ("; the parameter file's reference level, its values as they are" if has_level(self.params)
                         else "; the parameter file has no [level], its values hold at every level")
        return {"rms_mps2": level, "origin": origin, "scaled": scaled, "line": line + "."}

    def recorded(self, chunks):
        """``chunks`` (a route's), each with :meth:`level_record` in ``extra["vibration_level"]``."""
        record = self.level_record()
        for chunk in chunks:
            chunk.extra["vibration_level"] = record
            yield chunk

    @property
    def static_model(self) -> engine.Model:
        """The person on a static seat: its own model, or for a person built on a rotating seat a static-seat build
        of the same person (made once, on first use), on which the linearisation runs (in the seat's frame)."""
        if self.model.seat is None:
            return self.model
        if self._static is None:
            self._static = engine.build(self.body, self.params, self.locked, rotating_seat=False)
        return self._static

    @property
    def rotating_seat(self) -> bool:
        """Whether the person was built on a seat that can rotate."""
        return self.model.seat is not None

    @property
    def dof(self) -> int:
        """Degrees of freedom of the person."""
        return self.model.dof

    @property
    def mass_kg(self) -> float:
        """Total body mass as built [kg]."""
        return self.model.mass_kg

    @property
    def dt_s(self) -> float:
        """The model's time step [s]."""
        return float(self.model.mj.opt.timestep)

    def settle(self) -> None:
        """Let the person sink into the seat (done automatically before the first run)."""
        engine.settle(self.model)

    def check_nonlinear_motion(self, motion) -> float:
        """Refuse, in one sentence, a motion the nonlinear model cannot run on this person: one that turns the seat
        of a person built without ``rotating_seat=True``, or one shorter than a time step; returns the step [s]."""
        if motion.angvel_radps is not None and self.model.seat is None:
            raise InputError("this motion rotates the seat (it has angular velocities); build the person with "
                             "SeatedHuman(rotating_seat=True).")
        dt = self.dt_s
        if dt > motion.duration_s:
            raise InputError(f"the motion lasts {motion.duration_s:g} s, less than one time step ({dt:g} s).")
        return dt

    def recipe(self) -> dict:
        """What rebuilds this person in another process (:meth:`from_recipe`), as plain picklable data: the body
        tables and parameters as built, the locked joints, the seat kind, the body size, and the settled state when
        the person has settled (settling is deterministic, so this is the state a rebuilt person would reach)."""
        settled = self.model.settled
        return {"body": self.body, "params": self.params, "locked": frozenset(self.locked),
                "rotating_seat": self.model.seat is not None, "size": self.size,
                "vibration_rms_mps2": self.vibration_rms_mps2, "level_origin": self.level_origin,
                "settled": None if settled is None else {k: (v.copy() if isinstance(v, np.ndarray) else v)
                                                         for k, v in settled.items()}}

    @classmethod
    def from_recipe(cls, recipe: dict) -> BuiltPerson:
        """The person of :meth:`recipe`, built anew (the same MuJoCo model, and settled if it was)."""
        built = cls.build(recipe["body"], recipe["params"], frozenset(recipe["locked"]), recipe["rotating_seat"],
                          recipe["size"], recipe.get("vibration_rms_mps2"), recipe.get("level_origin", GIVEN))
        if recipe.get("settled") is not None:
            built.model.settled = {k: (v.copy() if isinstance(v, np.ndarray) else v)
                                   for k, v in recipe["settled"].items()}
        return built


def built_of(person) -> BuiltPerson:
    """The :class:`BuiltPerson` of ``person``: itself, or the one a door (:class:`ehm.SeatedHuman`) holds in its
    ``built`` attribute (so that the routes' functions take either)."""
    if isinstance(person, BuiltPerson):
        return person
    built = getattr(person, "built", None)
    if not isinstance(built, BuiltPerson):
        raise InputError(f"the person must be an ehm.SeatedHuman (or its built person), not {describe(person)}.")
    return built
