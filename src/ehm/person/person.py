"""The person as one value: who sits where (parameters, body tables and size, posture, back support, head
control, locked joints, time step), checked once, passed to every entry point, recorded as plain data.

>>> from ehm import Person
>>> person = Person(posture="slouched", lock=["lower_neck"])
>>> person.replace(head_control=True).head_control
True
>>> Person.from_dict(person.to_dict()) == person
True
"""

from __future__ import annotations

import os
import pickle
from collections.abc import Mapping
from dataclasses import dataclass
from dataclasses import replace as _dataclass_replace
from typing import Any

from ..body.level import applied_level, at_level, check_level, has_level
from ..body.params import Parameters
from ..body.tables import Body, joint_names, load_body, resolve_locks
from ..body.timestep import check_time_step, warn_if_coarse
from ..errors import InputError, checked_class, describe
from .scaling import BodySize

#: The fields of :class:`Person`, in order (what :meth:`Person.replace` accepts).
FIELDS = ("params", "body", "size", "posture", "back_support", "head_control", "lock", "unlock", "dt_s",
          "vibration_rms_mps2")


@dataclass(frozen=True)
class Built:
    """What the model builder (``ehm.engine.build``) needs of a person, as plain data (:meth:`Person.resolved`).

    Attributes
    ----------
    body : Body
        The body tables, scaled to the person's size.
    params : Parameters
        The parameters in the person's posture and back support, with its head control and time step (and scaled).
    locked : frozenset of str
        Every locked joint (the tables' defaults, plus ``lock``, minus ``unlock``).
    size : BodySize or None
        The body size the tables and parameters were scaled to.
    """

    body: Body
    params: Parameters
    locked: frozenset
    size: BodySize | None


@checked_class(skip=("__init__",))  # the constructor checks every field itself, naming more
@dataclass(frozen=True, eq=False)
class Person:
    """One person on one seat, as a value: what :class:`ehm.SeatedHuman` builds, and every entry point takes.

    Every field is checked when the person is made; a bad value is refused in one sentence
    (:class:`ehm.InputError`) that names the field, the value and what to give instead.  A person is immutable
    (:meth:`replace` makes a changed copy), compares by value, hashes, and pickles (for worker processes).

    Parameters
    ----------
    params : Parameters, path or None
        The parameter set, or a TOML parameter file to read (None: the shipped defaults); kept as a
        :class:`ehm.Parameters`.
    body : Body, optional
        Body tables (:func:`ehm.load_body`); None: the shipped ones (the paper's Tables 1 and 2).
    size : BodySize, optional
        An individual body size (stature, mass, sitting height); None: the reference person.
    posture : str, optional
        The reference posture (``"erect"``, ``"slouched"`` or one the parameter file defines); None: the file's.
    back_support : str, optional
        ``"none"``, ``"low"``, ``"high"`` or ``"full"`` (:mod:`ehm.body.supports`); None: the file's.
    head_control : bool or mapping, optional
        Head-in-space control: True or False switch it with the file's gains, a mapping of gains (e.g.
        ``{"tilt_stiffness_Nm_per_rad": 30.0}``) switches it on with those (kept as sorted ``(name, value)`` pairs);
        None: the file's.
    lock, unlock : joint name or iterable of names
        Joints to lock or unlock on top of the body table's defaults (the waist is locked by default); kept sorted.
    dt_s : float, optional
        Time step [s]; None: the step the parameters run at (:meth:`ehm.Parameters.time_step`).
    vibration_rms_mps2 : float, optional
        The seat's vibration level the person is built at [m/s^2 rms] (:func:`ehm.body.level.at_level`: the soft
        tissue and muscle named in the parameter file's ``[level]`` soften as the vibration grows; docs/model.md,
        "Vibration magnitude").  None (the default): the drive's own level on every route that runs one
        (:attr:`ehm.SeatMotion.vibration_rms_mps2`), the file's reference level where there is no drive
        (``linear_frf``, ``validate``, ``check_step``, ``Simulator``, the FMUs).

    Examples
    --------
    >>> from ehm import Person, SeatedHuman
    >>> person = Person(posture="slouched", back_support="none")
    >>> person
    Person(posture='slouched', back_support='none')
    >>> SeatedHuman(person).person == person
    True
    >>> person.replace(dt_s=2.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ehm.errors.InputError: dt_s = 2.0 is not a plausible time step: ...
    """

    params: Parameters | None = None
    body: Body | None = None
    size: BodySize | None = None
    posture: str | None = None
    back_support: str | None = None
    head_control: bool | dict | tuple | None = None
    lock: tuple = ()
    unlock: tuple = ()
    dt_s: float | None = None
    vibration_rms_mps2: float | None = None

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        params = self.params
        if not isinstance(params, Parameters):
            if params is not None and not isinstance(params, (str, os.PathLike)):
                raise InputError(f"Person: params must be a parameter file's path, an ehm.Parameters or None (the "
                                 f"shipped defaults), not {describe(params)}.")
            params = Parameters.load(params)
            set_(self, "params", params)
        if self.body is not None and not isinstance(self.body, Body):
            raise InputError(f"Person: body = {describe(self.body)} is not body tables; give ehm.load_body(...) or "
                             "None for the shipped tables.")
        if self.size is not None and not isinstance(self.size, BodySize):
            raise InputError(f"Person: size must be an ehm.person.scaling.BodySize, e.g. BodySize(stature_m=1.7, "
                             f"mass_kg=70), or None for the reference person, not {describe(self.size)}.")
        for name in ("posture", "back_support"):
            value = getattr(self, name)
            if value is not None and not isinstance(value, str):
                raise InputError(f"Person: {name} = {describe(value)} is not a name; give one, e.g. "
                                 f"{'slouched' if name == 'posture' else 'none'} (or None for the file's).")
        params.seated(self.posture, self.back_support)  # an unknown one: one sentence naming the known ones
        set_(self, "head_control", _head_control(self.head_control, params))
        set_(self, "lock", tuple(sorted(set(joint_names(self.lock, "Person: lock")))))
        set_(self, "unlock", tuple(sorted(set(joint_names(self.unlock, "Person: unlock")))))
        if self.lock or self.unlock:  # the names checked against the tables
            resolve_locks(self.body if self.body is not None else load_body(), self.lock, self.unlock)
        if self.dt_s is not None:
            set_(self, "dt_s", check_time_step(self.dt_s, "dt_s"))
        if self.vibration_rms_mps2 is not None:
            set_(self, "vibration_rms_mps2", check_level(self.vibration_rms_mps2, "Person: vibration_rms_mps2"))

    # ------------------------------------------------------------------ value semantics
    def _key(self) -> tuple:
        size = None if self.size is None else (self.size.stature_m, self.size.mass_kg, self.size.sitting_height_m)
        return (self.params.origin, self.posture, self.back_support, self.head_control, self.lock, self.unlock,
                self.dt_s, size, self.vibration_rms_mps2)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Person):
            return NotImplemented
        if self._key() != other._key() or self.params.data != other.params.data:
            return False
        if self.body is other.body:
            return True
        if self.body is None or other.body is None:
            return False
        return pickle.dumps(self.body) == pickle.dumps(other.body)  # the tables hold arrays: compare their bytes

    def __hash__(self) -> int:
        return hash(self._key())

    def __repr__(self) -> str:
        parts = [] if self.params.origin == "default" else [f"params={self.params.origin!r}"]
        if self.body is not None:
            parts.append("body=<custom tables>")
        if self.size is not None:
            s = self.size
            parts.append(f"size=BodySize({s.stature_m:g}, {s.mass_kg:g}, {s.sitting_height_m:g})")
        for name in ("posture", "back_support", "head_control", "lock", "unlock", "dt_s", "vibration_rms_mps2"):
            value = getattr(self, name)
            if value not in (None, ()):
                parts.append(f"{name}={value!r}")
        return f"Person({', '.join(parts)})"

    # ------------------------------------------------------------------ changes
    @classmethod
    def default(cls) -> Person:
        """The paper's default person on the shipped seat (the shipped parameters and tables)."""
        return cls()

    def replace(self, **changes) -> Person:
        """A copy with some fields changed (checked as when made); an unknown field is refused in one sentence."""
        unknown = sorted(set(changes) - set(FIELDS))
        if unknown:
            raise InputError(f"Person has no field {unknown[0]!r}; change one of {', '.join(FIELDS)}.")
        return _dataclass_replace(self, **changes)

    @property
    def head_control_gains(self) -> dict[str, float]:
        """The head-control gains the person sets (empty when it keeps the file's gains)."""
        return dict(self.head_control) if isinstance(self.head_control, tuple) else {}

    # ------------------------------------------------------------------ what the builder needs
    def seated_params(self) -> Parameters:
        """The parameters in the person's posture and back support, with its head control (step and size not yet
        applied)."""
        hc = self.head_control_gains if isinstance(self.head_control, tuple) else self.head_control
        return self.params.seated(self.posture, self.back_support).with_head_control(hc)

    def resolved(self) -> Built:
        """What the model builder needs, as plain data (``Built``): the parameters seated in the posture and
        back support, with the head control and the time step (a step coarser than the converged one gives a
        :class:`ehm.body.timestep.StepWarning`), the tables and parameters scaled to the body size (refused in one
        sentence if that body cannot be built), then at the person's vibration level when it has one
        (:func:`ehm.body.level.at_level`; None: the file's reference level, what the routes change to a drive's own),
        and the locked joints resolved."""
        body = self.body if self.body is not None else load_body()
        params = self.seated_params().at_step(self.dt_s)
        warn_if_coarse(float(params.value("simulation.dt_s")), converged_s=params.converged_step(),
                       posture=params.posture)
        if self.size is not None:
            from .scaling import check_buildable, scale_body, scale_params

            body0, params0 = body, params
            body, params = scale_body(body, self.size), scale_params(params, self.size, body)
            check_buildable(self.size, body0, params0, body, params)  # one sentence, with masses that work
        if self.vibration_rms_mps2 is not None:
            params = at_level(params, self.vibration_rms_mps2)
        return Built(body=body, params=params, locked=resolve_locks(body, self.lock, self.unlock), size=self.size)

    # ------------------------------------------------------------------ records
    def level_words(self) -> str:
        """The person's vibration level in words: ``vibration level 0.5 m/s^2 rms``, or where it comes from."""
        if not has_level(self.params):
            fixed = applied_level(self.params)
            return ("vibration level not modelled (the parameter file has no [level])" if fixed is None else
                    f"vibration level {fixed:g} m/s^2 rms (the parameter file's values, written at that level)")
        if self.vibration_rms_mps2 is None:
            return (f"vibration level from the drive (without one: the reference, "
                    f"{float(self.params.value('level.reference_rms_mps2')):g} m/s^2 rms)")
        return f"vibration level {self.vibration_rms_mps2:g} m/s^2 rms"

    def describe(self) -> str:
        """The person in one line, every setting as it takes effect (the file's where the person keeps it)."""
        p = self.seated_params()
        hc = "off" if not p.value("head_control.enabled") else (
            "on" if not self.head_control_gains else
            "on (" + ", ".join(f"{k}={v:g}" for k, v in self.head_control) + ")")
        size = "reference size" if self.size is None else (
            f"{self.size.stature_m:g} m, {self.size.mass_kg:g} kg, sitting height {self.size.sitting_height_m:g} m")
        dt = self.dt_s if self.dt_s is not None else p.time_step()
        joints = "".join([f", locked {', '.join(self.lock)}" if self.lock else "",
                          f", unlocked {', '.join(self.unlock)}" if self.unlock else ""])
        return (f"{p.posture}, back support {p.back_support}, {size}, head control {hc}{joints}, "
                f"step {dt * 1e3:g} ms, {self.level_words()}, parameters {self.params.origin}"
                + ("" if self.body is None else ", custom body tables"))

    def to_dict(self) -> dict[str, Any]:
        """The person as plain JSON-ready data (what run folders, FRF files, batch studies and ``--json`` record).

        ``params`` is the parameter file's origin (``"default"``: the shipped file), ``body`` ``"shipped"`` or
        ``"custom"``; :meth:`from_dict` rebuilds the person from it (a custom body must be given again)."""
        size = None if self.size is None else {"stature_m": self.size.stature_m, "mass_kg": self.size.mass_kg,
                                               "sitting_height_m": self.size.sitting_height_m}
        hc = self.head_control_gains if isinstance(self.head_control, tuple) else self.head_control
        return {"params": self.params.origin, "body": "shipped" if self.body is None else "custom", "size": size,
                "posture": self.posture, "back_support": self.back_support, "head_control": hc,
                "lock": list(self.lock), "unlock": list(self.unlock), "dt_s": self.dt_s,
                "vibration_rms_mps2": self.vibration_rms_mps2}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], body: Body | None = None) -> Person:
        """The person of :meth:`to_dict` (``body``: the tables of a person recorded with ``"body": "custom"``)."""
        if not isinstance(data, Mapping):
            raise InputError(f"Person.from_dict: {describe(data)} is not a mapping; give what Person.to_dict() "
                             "returned.")
        unknown = sorted(set(data) - set(FIELDS))
        if unknown:
            raise InputError(f"Person.from_dict: unknown key {unknown[0]!r}; the keys are {', '.join(FIELDS)}.")
        if data.get("body", "shipped") not in ("shipped", "custom"):
            raise InputError(f"Person.from_dict: body = {describe(data['body'])}; it is 'shipped' or 'custom'.")
        if data.get("body") == "custom" and body is None:
            raise InputError("Person.from_dict: the person was recorded with custom body tables; give them as "
                             "body=ehm.load_body(...).")
        kw = {k: v for k, v in data.items() if k != "body"}
        if kw.get("params") == "default":
            kw["params"] = None
        size = kw.get("size")
        if size is not None:
            if not isinstance(size, Mapping):
                raise InputError(f"Person.from_dict: size = {describe(size)}; give stature_m, mass_kg and "
                                 "sitting_height_m as a mapping.")
            kw["size"] = BodySize(size["stature_m"], size["mass_kg"], size.get("sitting_height_m"))
        for k in ("lock", "unlock"):
            if isinstance(kw.get(k), list):
                kw[k] = tuple(kw[k])
        return cls(body=body if data.get("body") == "custom" else None, **kw)


def _head_control(value, params: Parameters):
    """None, a bool, or a mapping of gains checked (by the parameters, as a parameter file's) and kept as sorted
    (name, value) pairs; an empty mapping is True (on with the file's gains)."""
    if value is None or isinstance(value, bool):
        return value
    if isinstance(value, tuple) and all(isinstance(x, tuple) and len(x) == 2 for x in value):
        value = dict(value)
    if not isinstance(value, Mapping):
        raise InputError(f"Person: head_control must be True, False, None or a dict of gains, not {describe(value)}; "
                         "give e.g. {'tilt_stiffness_Nm_per_rad': 30.0}.")
    if not value:
        return True
    params.with_head_control(dict(value))  # the gains' names and values, in the parameter file's sentences
    return tuple(sorted((k, float(v)) for k, v in value.items()))


def as_person(person=None, *, lock=(), unlock=(), body=None, size=None, dt_s=None, posture=None,
              back_support=None, head_control=None) -> Person:
    """The :class:`Person` an entry point was given: ``person`` itself (a Person, with the keyword shortcuts given
    replacing its fields), or one built from parameters (a :class:`ehm.Parameters`, a path or None) and the
    shortcuts (the keyword arguments entry points keep)."""
    changes = {k: v for k, v in (("lock", lock), ("unlock", unlock), ("body", body), ("size", size),
                                 ("dt_s", dt_s), ("posture", posture), ("back_support", back_support),
                                 ("head_control", head_control))
               if v is not None and not (k in ("lock", "unlock") and _empty(v))}
    if isinstance(person, Person):
        return person.replace(**changes) if changes else person
    if person is not None and not isinstance(person, (Parameters, str, os.PathLike)):
        raise InputError(f"params must be a parameter file's path, an ehm.Parameters, an ehm.Person or None (the "
                         f"shipped defaults), not {describe(person)}.")
    return Person(params=person, **changes)


def _empty(value) -> bool:
    try:
        return not isinstance(value, str) and len(value) == 0
    except TypeError:
        return False


__all__ = ["Built", "FIELDS", "Person", "as_person"]
