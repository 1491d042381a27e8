"""The person as built: what every route reads, handed down by the door (:class:`ehm.SeatedHuman`).

A route takes the person as data: a :class:`BuiltPerson` holds the body tables and parameters as built (scaled,
with the time step), the locked joints, the body size, the MuJoCo model (``ehm.engine.build``), the static-seat
model a rotating seat's linearisation runs on (built on demand, :attr:`BuiltPerson.static_model`) and the cache of
the linear models (:attr:`BuiltPerson.linear`, filled by :func:`ehm.routes.linear.linear_model`).  The routes read
its public attributes and never call back into the door.
"""

from __future__ import annotations

import numpy as np

from .. import engine
from ..errors import InputError, describe


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
    """

    def __init__(self, body, params, locked, model: engine.Model, size=None):
        self.body, self.params, self.locked, self.model, self.size = body, params, locked, model, size
        #: the linear route's models ("translation", "rotation"), built on first use (ehm.routes.linear.linear_model)
        self.linear = {}
        self._static = None

    @classmethod
    def build(cls, body, params, locked, rotating_seat: bool = False, size=None) -> BuiltPerson:
        """The person built from its tables and parameters (``ehm.engine.build``)."""
        return cls(body, params, locked, engine.build(body, params, locked, rotating_seat=rotating_seat),
                   size)

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
                "settled": None if settled is None else {k: (v.copy() if isinstance(v, np.ndarray) else v)
                                                         for k, v in settled.items()}}

    @classmethod
    def from_recipe(cls, recipe: dict) -> BuiltPerson:
        """The person of :meth:`recipe`, built anew (the same MuJoCo model, and settled if it was)."""
        built = cls.build(recipe["body"], recipe["params"], frozenset(recipe["locked"]), recipe["rotating_seat"],
                          recipe["size"])
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
