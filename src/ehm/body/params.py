"""Model parameters: joint springs and dampers, posture control, contacts, seat geometry, solver options.

A parameter file is TOML (see the shipped ``data/default_params.toml``).  Every entry carries its values
with the unit in the key name, plus ``grade`` (``literature``, ``assumed``, ``identified``, or ``at bound`` for a
fitted value that ended on its search bound) and
``source`` (a key of the file's ``[sources]`` table).  Values are addressed by dotted paths, e.g.
``joints.upper_neck.pitch.stiffness_Nm_per_rad``, ``contacts.buttock.stiffness_N_per_m`` or
``seat.pan_angle_deg``.
"""

from __future__ import annotations

import copy
import functools
import math
import os
import re
import tomllib
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

from ..errors import InputError, checked_class, describe
from .posture import DEFAULT_POSTURE, OPTIONAL_KEYS, STEP_KEY, TONE_KEY, TONE_RANGE, check_posture
from .supports import BACK_SUPPORTS, DEFAULT_BACK_SUPPORT
from .tables import JOINT_NAMES, Body
from .timestep import CONVERGED_STEP_S, check_time_step

GRADES = ("literature", "assumed", "identified", "at bound")
_META = ("grade", "source", "bounds", "grades", "sources")
_SECTIONS = ("simulation", "posture", "seat", "joints", "contacts")  #: the sections every parameter file has

#: Numeric keys allowed in each section, with the check they must pass.
_SIMULATION = {"dt_s": "time_step", "settle_s": "nonnegative", "back_slide_s": "nonnegative",
               "noslip_iterations": "count", "solver_iterations": "count", "contact_impedance": "fraction",
               "pad_armature_kg": "nonnegative"}
#: Keys a file may leave out (added after files were first exported), with the value they then take; load()
#: fills them in (grade assumed, source "ehm").
OPTIONAL = {"simulation.back_slide_s": 0.0, "simulation.pad_armature_kg": 0.0,
            "posture.name": DEFAULT_POSTURE, "seat.back_support": DEFAULT_BACK_SUPPORT,
            "posture.unsupported_integral_joints": ["hip_r", "hip_l"], "posture.tone_joints": [],
            "posture.supported_tone": 1.0}
_POSTURE = {"name": "posture", "integral_time_s": "positive", "integral_joints": "joints",
            "unsupported_integral_joints": "joints", "tone_joints": "joints", "supported_tone": "tone"}
_SEAT = {"back_support": "back_support",
         "pan_angle_deg": "finite", "pan_height_m": "finite", "backrest_angle_deg": "finite",
         "backrest_x_m": "finite", "lower_pad_height_m": "finite", "lower_pad_thickness_m": "nonnegative",
         "upper_pad_height_m": "finite", "upper_pad_thickness_m": "nonnegative", "floor_height_m": "finite",
         "bolster_angle_deg": "finite", "back_bolster_angle_deg": "finite", "bolster_gap_m": "nonnegative"}
_CONTACT = {"stiffness_N_per_m": "positive", "damping_Ns_per_m": "nonnegative", "friction": "nonnegative",
            "shear_stiffness_N_per_m": "positive", "shear_damping_Ns_per_m": "nonnegative",
            "pad_mass_kg": "positive"}
#: [head_control] (``ehm.engine.control``): optional in a file (load() fills in the shipped section, off).
HEAD_CONTROL = {"enabled": "bool", "tilt_stiffness_Nm_per_rad": "nonnegative",
                "tilt_damping_Nms_per_rad": "nonnegative", "yaw_damping_Nms_per_rad": "nonnegative",
                "delay_s": "delay"}
#: The longest head-control delay a parameter file may give [s]: a person's sensory delay is tens of milliseconds;
#: far longer ones would fill memory with the delay line (1e7 s overflowed MuJoCo's sizes).
MAX_DELAY_S = 10.0
#: [level] (``ehm.body.level``, the vibration magnitude): optional in a file; a file without it keeps its values at
#: every level (it is not filled in from the shipped file).
LEVEL = {"reference_rms_mps2": "positive", "stiffness_exponent": "nonnegative", "damping_exponent": "nonnegative",
         "least_rms_mps2": "positive", "greatest_rms_mps2": "positive", "scaled": "scaled"}
#: What a posture's name may hold: it is a key of [postures] and part of dotted paths (postures.NAME.dt_s).
_POSTURE_NAME = re.compile(r"[A-Za-z0-9_-]+")
_ROT = {"stiffness_Nm_per_rad": "nonnegative", "damping_Nms_per_rad": "nonnegative"}
_TRANS = {"stiffness_N_per_m": "nonnegative", "damping_Ns_per_m": "nonnegative"}
#: The source recorded on a time step given by the caller (SeatedHuman(dt_s=...), --dt): it then wins over a
#: posture's own step (Parameters.time_step).
CALLER_SOURCE = ("caller", "the caller: a time step given explicitly (SeatedHuman(dt_s=...), --dt)")


def default_params_path() -> Path:
    """Path of the shipped default parameter file."""
    return Path(str(resources.files("ehm") / "data" / "default_params.toml"))


def refuse_defaults(path: Path | str) -> None:
    """Refuse ``path`` as an output when it is the shipped default parameter file.

    Raises
    ------
    InputError
        ``path`` resolves to :func:`default_params_path`.
    """
    if Path(path).resolve() == default_params_path().resolve():
        raise InputError(f"{path} is the shipped default parameter file; write to another file.")


@checked_class
@dataclass(frozen=True)
class Parameters:
    """A checked parameter set.

    Use :meth:`load` to read one, :meth:`value` to read a value by dotted path, :meth:`with_values` to
    derive a changed copy and :meth:`export` to write it as TOML.
    """

    data: dict = field(repr=False)
    origin: str = "default"

    # ----------------------------------------------------------------- reading
    @classmethod
    def load(cls, path: Path | str | None = None) -> Parameters:
        """Read and check a parameter file (default: the shipped one)."""
        if path is not None and not isinstance(path, (str, os.PathLike)):
            raise InputError(f"params must be a parameter file's path, an ehm.Parameters or None (the shipped "
                             f"defaults), not {describe(path)}.")
        p = Path(path) if path is not None else default_params_path()
        label = p.name if path is None else str(path)
        try:
            raw = p.read_bytes()
        except OSError as exc:
            raise InputError(f"{label}: cannot read the parameter file ({exc.strerror or exc}).") from None
        try:
            data = tomllib.loads(raw.decode("utf-8"))
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
            raise InputError(f"{label}: not a valid TOML file ({exc}).") from None
        for key, default in OPTIONAL.items():  # fill keys the file leaves out, saying so
            section, _, name = key.partition(".")
            if isinstance(data.get(section), dict) and name not in data[section]:
                data.setdefault("sources", {}).setdefault(
                    "ehm", "ehm: the value a key takes when a parameter file leaves it out")
                data[section][name] = {"value": default, "grade": "assumed", "source": "ehm"}
        if path is not None:
            _fill_postures(data)
            _fill_section(data, "head_control")
        params = cls(data, "default" if path is None else str(path))
        params._check(label)
        return params

    def value(self, path: str) -> Any:
        """The value at a dotted path, e.g. ``joints.t12.z.stiffness_N_per_m`` or ``seat.pan_angle_deg``."""
        node, key = self._locate(path)
        v = node[key]
        return v["value"] if isinstance(v, dict) and "value" in v else v

    def with_values(self, updates: Mapping[str, Any], grade: str | None = None,
                    source: str | None = None) -> Parameters:
        """A copy with the values at the given dotted paths replaced (and re-checked).

        ``grade`` and ``source``, when given, are recorded on every changed entry.
        """
        data = copy.deepcopy(self.data)
        new = Parameters(data, self.origin)
        for path, v in updates.items():
            node, key = new._locate(path)
            entry = node[key]
            if isinstance(entry, dict) and "value" in entry:
                entry["value"] = v
                if grade is not None:
                    entry["grade"] = grade
                if source is not None:
                    entry["source"] = source
            else:  # one of several values of an entry (a joint degree of freedom): provenance per value
                node[key] = v
                if grade is not None:
                    node.setdefault("grades", {})[key] = grade
                if source is not None:
                    node.setdefault("sources", {})[key] = source
        new._check("changed parameters")
        return new

    def bounds(self, path: str) -> tuple[float, float] | None:
        """Fitting bounds of a value, from ``bounds`` in its entry, or None when the entry gives none.

        An entry with one value gives ``bounds = [lo, hi]``; a joint degree of freedom gives
        ``bounds = { stiffness_Nm_per_rad = [lo, hi], damping_Nms_per_rad = [lo, hi] }``.
        """
        node, key = self._locate(path)
        entry = node[key]
        b = entry.get("bounds") if isinstance(entry, dict) else node.get("bounds", {}).get(key)
        return None if b is None else (float(b[0]), float(b[1]))

    def with_source(self, key: str, text: str) -> Parameters:
        """A copy with one more entry in ``[sources]``."""
        data = copy.deepcopy(self.data)
        data.setdefault("sources", {})[key] = text
        return Parameters(data, self.origin)

    def with_about(self, info: Mapping[str, Any]) -> Parameters:
        """A copy with entries added to ``[about]`` (free-form provenance)."""
        data = copy.deepcopy(self.data)
        data.setdefault("about", {}).update(info)
        return Parameters(data, self.origin)

    def provenance(self, path: str) -> tuple[str, str]:
        """(grade, source) of the value at a dotted path."""
        node, key = self._locate(path)
        entry = node[key]
        if isinstance(entry, dict):
            return entry["grade"], entry["source"]
        return node.get("grades", {}).get(key, node["grade"]), node.get("sources", {}).get(key, node["source"])

    def numeric_paths(self) -> Iterator[str]:
        """Dotted paths of all numeric values (the candidates for fitting and sweeps)."""
        def walk(node: dict, prefix: str):
            for k, v in node.items():
                if k in _META or k in ("about", "sources"):
                    continue
                p = f"{prefix}.{k}" if prefix else k
                if isinstance(v, dict):
                    if "value" in v:
                        if isinstance(v["value"], (int, float)) and not isinstance(v["value"], bool):
                            yield p
                    else:
                        yield from walk(v, p)
                elif isinstance(v, (int, float)) and not isinstance(v, bool):
                    yield p
        yield from walk(self.data, "")

    def joint_dof(self, joint: str, dof: str) -> tuple[float, float]:
        """(stiffness, damping) of one joint degree of freedom, SI units.

        Rotational: [N m/rad], [N m s/rad]; the t12 ``z`` slide: [N/m], [N s/m].
        """
        joints = self.data["joints"]
        if joint not in joints or not isinstance(joints[joint], dict):
            raise InputError(f"Parameters.joint_dof: no joint {joint!r}; the joints are {', '.join(joints)}.")
        dofs = [k for k in joints[joint] if k not in _META]
        if dof not in dofs:
            raise InputError(f"Parameters.joint_dof: joint {joint} has no degree of freedom {dof!r}; it has "
                             f"{', '.join(dofs)}.")
        entry = joints[joint][dof]
        keys = _TRANS if dof == "z" else _ROT
        k, c = (float(entry[key]) for key in keys)
        if joint in self.value("posture.tone_joints"):
            tone = self.tone()
            return k * tone, c * tone
        return k, c

    #: Back supports that carry the upper back (a pad at the scapula, or the whole backrest).
    UPPER_BACK_SUPPORTS = ("high", "full")

    def tone(self) -> float:
        """The trunk muscle tone of the person as seated: the factor on the stiffness and damping of every degree of
        freedom of the joints of ``posture.tone_joints`` (:meth:`joint_dof` applies it; the file keeps the values at
        tone 1).

        The posture's own (``postures.NAME.tone``, 1 when not given) times ``posture.supported_tone`` when the back
        support carries the upper back (``high``, ``full``): the trunk's muscles work less in a slumped posture
        and when a backrest carries the upper body (docs/model.md, "Muscle tone")."""
        own = float(self.section(f"postures.{self.posture}").get(TONE_KEY, 1.0))
        if self.back_support in self.UPPER_BACK_SUPPORTS:
            own *= float(self.value("posture.supported_tone"))
        return own

    @property
    def posture(self) -> str:
        """Name of the posture the person sits in (``posture.name``; see :mod:`ehm.body.posture`)."""
        return str(self.value("posture.name"))

    def integral_joints(self) -> set[str]:
        """Joints with integral action in the posture control: ``posture.integral_joints``, and on a seat without
        back support also ``posture.unsupported_integral_joints`` (the hips, which then hold the trunk upright)."""
        joints = set(self.value("posture.integral_joints"))
        if self.back_support == "none":
            joints |= set(self.value("posture.unsupported_integral_joints"))
        return joints

    @property
    def back_support(self) -> str:
        """The seat's back support (``seat.back_support``; see :mod:`ehm.body.supports`)."""
        return str(self.value("seat.back_support"))

    def posture_angles(self, name: str | None = None) -> dict[str, float]:
        """The angles [deg] and slide [m] of a posture (default: the one in use), from ``[postures.NAME]``."""
        return {k: float(v) for k, v in self.section(f"postures.{name or self.posture}").items()
                if k not in OPTIONAL_KEYS}

    def converged_step(self) -> float:
        """The largest time step [s] at which the person in its posture is converged (``ehm check-step`` within 2 %):
        the posture's own (``postures.NAME.dt_s``) when it has one, else ``ehm.body.timestep.CONVERGED_STEP_S``."""
        own = self.section(f"postures.{self.posture}").get(STEP_KEY)
        return CONVERGED_STEP_S if own is None else float(own)

    def time_step(self) -> float:
        """The time step [s] a person with these parameters runs at when no step is given (``dt_s=``, ``--dt``).

        In order: ``simulation.dt_s`` when it is not the shipped entry (a file or :meth:`with_values` that sets its
        own value, grade or source, and a step given to :meth:`at_step`); else the posture's own converged step
        (``postures.NAME.dt_s``) when it has one; else ``simulation.dt_s`` (the shipped 1 ms).
        """
        own_posture_step = STEP_KEY in self.section(f"postures.{self.posture}")
        if own_posture_step and self.data["simulation"]["dt_s"] == _shipped()["simulation"]["dt_s"]:
            return self.converged_step()
        return float(self.value("simulation.dt_s"))

    def at_step(self, dt_s=None, name: str = "dt_s") -> Parameters:
        """A copy whose ``simulation.dt_s`` is the step a person runs at: ``dt_s`` [s] when the caller gives one
        (checked, ``name`` in the sentence if it is refused; recorded with the source ``caller``, so that it also
        wins over a posture's own step when the copy builds another person), else :meth:`time_step` (a posture's
        own step recorded with its grade and source; the parameters themselves when that is ``simulation.dt_s``)."""
        if dt_s is not None:
            key, text = CALLER_SOURCE
            return self.with_source(key, text).with_values({"simulation.dt_s": check_time_step(dt_s, name)},
                                                           grade="assumed", source=key)
        dt = self.time_step()
        if dt == self.value("simulation.dt_s"):
            return self
        grade, source = self.provenance(f"postures.{self.posture}.{STEP_KEY}")
        return self.with_values({"simulation.dt_s": dt}, grade=grade, source=source)

    def seated(self, posture: str | None = None, back_support: str | None = None) -> Parameters:
        """A copy with another posture (a name of :meth:`postures`) and/or back support
        (:data:`ehm.body.supports.BACK_SUPPORTS`); None keeps the file's.  Either one not known is refused in one
        sentence
        naming the known ones."""
        updates = {}
        if posture is not None:
            if posture not in self.postures():
                raise InputError(f"unknown posture {posture!r}; the parameter file ({self.origin}) defines "
                                 f"{', '.join(self.postures())} (define more in a [postures.NAME] table of a parameter "
                                 "file: ehm params --export FILE.toml).")
            updates["posture.name"] = posture
        if back_support is not None:
            if back_support not in BACK_SUPPORTS:
                raise InputError(f"unknown back support {back_support!r}; use one of {', '.join(BACK_SUPPORTS)}.")
            updates["seat.back_support"] = back_support
        if all(self.value(k) == v for k, v in updates.items()):
            return self
        return self.with_values(updates)

    def with_head_control(self, head_control=None) -> Parameters:
        """A copy with the head-in-space control (``ehm.engine.control``) switched: None keeps the file's
        ``head_control.enabled``; True or False switches it on or off with the file's gains; a dict of gains (keys of
        [head_control] but ``enabled``, e.g. ``{"tilt_stiffness_Nm_per_rad": 30.0, "delay_s": 0.03}``) switches it on
        with those gains.  A gain that is not a key of [head_control] or not a valid value is refused in one
        sentence."""
        if head_control is None:
            return self
        base = self
        if "head_control" not in self.data:  # parameters made before the section existed
            base = Parameters(copy.deepcopy(self.data), self.origin)
            _fill_section(base.data, "head_control")
        if isinstance(head_control, bool):
            updates = {"head_control.enabled": head_control}
        elif isinstance(head_control, Mapping):
            gains = [k for k in HEAD_CONTROL if k != "enabled"]
            for key, v in head_control.items():
                if key not in gains:
                    raise InputError(f"unknown head-control gain {key!r}; use {', '.join(gains)}.")
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                    raise InputError(f"head-control gain {key} = {v!r} is not a finite number.")
            updates = {"head_control.enabled": True, **{f"head_control.{k}": float(v) for k, v in head_control.items()}}
        else:
            raise InputError("head_control must be True, False, None or a dict of gains, not "
                             f"{describe(head_control)}.")
        if all(base.value(k) == v for k, v in updates.items()):
            return base
        if len(updates) == 1:
            return base.with_values(updates)
        key, text = CALLER_SOURCE
        return base.with_source(key, text).with_values(updates, source=key)

    def postures(self) -> tuple[str, ...]:
        """Names of the postures the file defines."""
        return tuple(self.data.get("postures", {}))

    def section(self, name: str) -> dict[str, Any]:
        """The plain values of a section (``simulation``, ``posture``, ``seat``, ``contacts.<name>``)."""
        node = self.data
        for part in name.split("."):
            node = node.get(part) if isinstance(node, dict) else None
            if not isinstance(node, dict) or part in _META:
                raise InputError(f"unknown parameter section {name!r} (no {part!r}); sections are "
                                 f"{', '.join(k for k in self.data if k not in _META)}.")
        if "value" in node:
            raise InputError(f"{name!r} is a parameter, not a section; read it with Parameters.value({name!r}).")
        return {k: (v["value"] if isinstance(v, dict) and "value" in v else v)
                for k, v in node.items() if k not in _META}

    # ----------------------------------------------------------------- writing
    def to_toml(self) -> str:
        """The parameter set as TOML text."""
        import tomli_w

        header = ("# ehm parameter file (exported). Units are in the key names; every entry has a grade\n"
                  "# (literature, assumed, identified, at bound) and a source (a key of [sources]).\n")
        return header + tomli_w.dumps(self.data)

    def export(self, path: Path | str) -> None:
        """Write the parameter set as a TOML file (written whole or not at all); never onto the shipped defaults."""
        from ..files import write_text_atomic

        refuse_defaults(path)
        write_text_atomic(path, self.to_toml())

    # ----------------------------------------------------------------- checks
    def check_against(self, body: Body) -> None:
        """Check that every joint degree of freedom and contact of ``body`` has parameters."""
        for j in body.joints:
            entries = self.data.get("joints", {}).get(j.name)
            if entries is None:
                raise InputError(f"{self.origin}: no [joints.{j.name}] entry for joint {j.name!r}.")
            for dof in j.dofs:
                if dof not in entries:
                    raise InputError(f"{self.origin}: joint {j.name!r} needs an entry {dof!r} in [joints.{j.name}].")
        for c in body.contacts:
            entry = self.data.get("contacts", {}).get(c.name)
            if entry is None:
                raise InputError(f"{self.origin}: no [contacts.{c.name}] entry for contact {c.name!r}.")
            need = [k for k in _CONTACT if c.tissue_pad or not k.startswith(("shear", "pad"))]
            for k in need:
                if k not in entry:
                    raise InputError(f"{self.origin}: contact {c.name!r} needs {k!r} in [contacts.{c.name}].")

    def _locate(self, path: str) -> tuple[dict, str]:
        parts = path.split(".")
        node = self.data
        for i, part in enumerate(parts[:-1]):
            nxt = node.get(part) if isinstance(node, dict) else None
            if not isinstance(nxt, dict):
                raise InputError(f"unknown parameter {path!r} (no {'.'.join(parts[:i + 1])!r}).")
            node = nxt
        if not isinstance(node, dict) or parts[-1] not in node or parts[-1] in _META:
            raise InputError(f"unknown parameter {path!r}.")
        target = node[parts[-1]]
        if isinstance(target, dict) and "value" not in target:
            raise InputError(f"{path!r} is a section, not a parameter; name one of its values.")
        return node, parts[-1]

    def _check(self, label: str) -> None:
        """Refuse a parameter file that is not complete and valid, in one sentence naming the first problem."""
        d = self.data
        sources = _check_sections(label, d)
        _check_flat_sections(label, d, sources)
        settle_s, slide_s = self.value("simulation.settle_s"), self.value("simulation.back_slide_s")
        if slide_s > 0 and slide_s >= settle_s:
            raise InputError(f"{label}: simulation.back_slide_s ({slide_s:g} s) must be shorter than "
                             "simulation.settle_s "
                             f"({settle_s:g} s): the back needs the rest of the settling time with friction on.")
        _check_joints(label, d, sources)
        _check_contacts(label, d, sources)
        _check_postures(label, d, sources)
        _check_level(label, d)


def _check_sections(label: str, d: dict) -> dict:
    """The file's sections: [sources] a table, every required section present, none unknown; returns [sources]."""
    sources = d.get("sources", {})
    if not isinstance(sources, dict):
        raise InputError(f"{label}: [sources] must be a table of source names and citations.")
    required = _SECTIONS
    if not any(isinstance(d.get(section), dict) for section in required):
        raise InputError(f"{label}: not an ehm parameter file (none of its sections [{'], ['.join(required)}]); "
                         "write one with 'ehm params --export FILE.toml'.")
    for section in required:
        if not isinstance(d.get(section), dict):
            raise InputError(f"{label}: missing section [{section}].")
    unknown = set(d) - {"about", "sources", "postures", "head_control", "level", *required}
    if unknown:
        raise InputError(f"{label}: unknown section [{sorted(unknown)[0]}].")
    return sources


def _check_flat_sections(label: str, d: dict, sources: dict) -> None:
    """[simulation], [posture] and [seat]: every key known and present, each one entry with its value."""
    flat = (("simulation", _SIMULATION), ("posture", _POSTURE), ("seat", _SEAT))
    if "head_control" in d:
        if not isinstance(d["head_control"], dict):
            raise InputError(f"{label}: [head_control] must be a table.")
        flat += (("head_control", HEAD_CONTROL),)
    if "level" in d:
        if not isinstance(d["level"], dict):
            raise InputError(f"{label}: [level] must be a table.")
        flat += (("level", LEVEL),)
    for section, allowed in flat:
        for key, entry in d[section].items():
            if key not in allowed:
                raise InputError(f"{label}: unknown key {key!r} in [{section}].")
            _check_entry(label, sources, f"{section}.{key}", entry, allowed[key], True)
        for key in allowed:
            if key not in d[section]:
                raise InputError(f"{label}: [{section}] needs {key!r}.")


def _check_level(label: str, d: dict) -> None:
    """[level]: least <= reference <= greatest, and every name of ``scaled`` a contact or a joint's degree of freedom
    of the file (each entry's own value is checked with the flat sections)."""
    if "level" not in d:
        return
    v = {k: e["value"] for k, e in d["level"].items()}
    least, ref, greatest = v["least_rms_mps2"], v["reference_rms_mps2"], v["greatest_rms_mps2"]
    if not least <= greatest:
        raise InputError(f"{label}: level.least_rms_mps2 ({least:g}) is above level.greatest_rms_mps2 ({greatest:g}); "
                         "give the lower level first.")
    if not least <= ref <= greatest:
        raise InputError(f"{label}: level.reference_rms_mps2 ({ref:g}) lies outside level.least_rms_mps2 to "
                         f"level.greatest_rms_mps2 ({least:g} to {greatest:g} m/s^2); the reference must be a level "
                         "the person can be at.")
    for name in v["scaled"]:
        parts = name.split(".")
        ok = (len(parts) == 2 and parts[0] == "contacts" and isinstance(d["contacts"].get(parts[1]), dict)) or (
            len(parts) == 3 and parts[0] == "joints" and isinstance(d["joints"].get(parts[1]), dict)
            and isinstance(d["joints"][parts[1]].get(parts[2]), dict) and parts[2] not in _META)
        if not ok:
            raise InputError(f"{label}: level.scaled names {name!r}, which is no contact (contacts.NAME) or joint "
                             "degree of freedom (joints.NAME.DOF, e.g. joints.t12.z) of the file.")
    if len(set(v["scaled"])) != len(v["scaled"]):
        twice = next(n for n in v["scaled"] if v["scaled"].count(n) > 1)
        raise InputError(f"{label}: level.scaled names {twice!r} twice; name each entry once.")


def _check_joints(label: str, d: dict, sources: dict) -> None:
    """[joints.NAME.DOF]: known joints and degrees of freedom, each entry with all its values."""
    for jname, dofs in d["joints"].items():
        if jname not in JOINT_NAMES:
            raise InputError(f"{label}: unknown joint {jname!r} in [joints]; joints are {', '.join(JOINT_NAMES)}.")
        if not isinstance(dofs, dict):
            raise InputError(f"{label}: [joints.{jname}] must be a table of degrees of freedom, not {dofs!r}.")
        for dof, entry in dofs.items():
            if dof not in ("z", "roll", "pitch", "yaw"):
                raise InputError(f"{label}: unknown degree of freedom {dof!r} in [joints.{jname}].")
            allowed = _TRANS if dof == "z" else _ROT
            _check_entry(label, sources, f"joints.{jname}.{dof}", entry, allowed, False)
            for key in allowed:
                if key not in entry:
                    raise InputError(f"{label}: joints.{jname}.{dof} needs {key!r}.")


def _check_contacts(label: str, d: dict, sources: dict) -> None:
    """[contacts.NAME]: tables of known keys, each one entry with its value."""
    for cname, entries in d["contacts"].items():
        if not isinstance(entries, dict):
            raise InputError(f"{label}: [contacts.{cname}] must be a table.")
        for key, entry in entries.items():
            if key not in _CONTACT:
                raise InputError(f"{label}: unknown key {key!r} in [contacts.{cname}].")
            _check_entry(label, sources, f"contacts.{cname}.{key}", entry, _CONTACT[key], True)


@functools.lru_cache(maxsize=1)
def _shipped() -> dict:
    """The shipped parameter file as read (not to be changed: copy what you take)."""
    return tomllib.loads(default_params_path().read_text(encoding="utf-8"))


def _fill_section(data: dict, name: str) -> None:
    """Give a file that has no section ``name`` the shipped one (files exported before it existed), with its
    sources."""
    shipped = _shipped()
    if name in data or name not in shipped or not isinstance(data.get("sources"), dict):
        return
    data[name] = copy.deepcopy(shipped[name])
    for entry in shipped[name].values():
        src = entry.get("source")
        if src not in data["sources"]:
            data["sources"][src] = shipped["sources"][src]


def _fill_postures(data: dict) -> None:
    """Give a file the shipped postures it does not define itself (files exported before postures existed), with
    their sources."""
    shipped = _shipped()
    own = data.setdefault("postures", {})
    if not isinstance(own, dict):
        return  # refused by the checks
    for name, entries in shipped.get("postures", {}).items():
        if name not in own:
            own[name] = copy.deepcopy(entries)
            for entry in entries.values():
                src = entry.get("source")
                if isinstance(data.get("sources"), dict) and src not in data["sources"]:
                    data["sources"][src] = shipped["sources"][src]


def _check_postures(label: str, d: dict, sources: dict) -> None:
    """[postures.NAME]: each a table of the posture's angles (:data:`ehm.body.posture.POSTURE_KEYS`), and posture.name
    one of them."""
    postures = d.get("postures", {})
    if not isinstance(postures, dict) or any(not isinstance(v, dict) for v in postures.values()):
        raise InputError(f"{label}: [postures] must hold one table per posture, [postures.NAME].")
    for name, entries in postures.items():
        if not _POSTURE_NAME.fullmatch(name):
            raise InputError(f"{label}: posture name {name!r} in [postures] must be letters, digits, '_' or '-' "
                             "(no dots, spaces or path characters); rename the table, e.g. [postures.my_posture].")
        for key, entry in entries.items():
            rule = {STEP_KEY: "time_step", TONE_KEY: "tone"}.get(key, "finite")
            _check_entry(label, sources, f"postures.{name}.{key}", entry, rule, True)
        check_posture(name, {k: e["value"] for k, e in entries.items()}, label)
    name = d["posture"]["name"]["value"]
    if name not in postures:
        raise InputError(f"{label}: posture.name = {name!r} is not a posture of the file; postures are "
                         f"{', '.join(postures) or 'none'} (define it in a [postures.{name}] table).")


def _check_entry(label: str, sources: dict, where: str, entry: Any, allowed: Any, inline_value: bool) -> None:
    """One entry: its grade and source, its keys, bounds and values.

    ``allowed``: the rule of the entry's ``value`` (inline) or a dict of key -> rule.
    """
    if not isinstance(entry, dict):
        raise InputError(f"{label}: {where} must be a table with its value, grade and source.")
    grade = entry.get("grade")
    if grade not in GRADES:
        raise InputError(f"{label}: {where} has grade {grade!r}; use one of {', '.join(GRADES)}.")
    src = entry.get("source")
    if src not in sources:
        raise InputError(f"{label}: {where} names source {src!r}, which is not in [sources].")
    for sub, allowed_values in (("grades", GRADES), ("sources", tuple(sources))):
        per_value = entry.get(sub, {})
        if sub in entry and (inline_value or not isinstance(per_value, dict)):
            raise InputError(f"{label}: {where}.{sub} is only allowed as a table in a joint entry.")
        for k, v in per_value.items():
            if k not in allowed:
                raise InputError(f"{label}: unknown key {k!r} in {where}.{sub}.")
            if v not in allowed_values:
                raise InputError(f"{label}: {where}.{sub}.{k} = {v!r} is not one of {', '.join(allowed_values)}.")
    keys = ("value",) if inline_value else allowed
    for key in entry:
        if key not in _META and key not in keys:
            raise InputError(f"{label}: unknown key {key!r} in {where}.")
    if "bounds" in entry:
        _check_bounds(label, where, entry["bounds"], None if inline_value else allowed)
    if inline_value:
        if "value" not in entry:
            raise InputError(f"{label}: {where} has no 'value'.")
        _check_value(label, where, entry["value"], allowed)
    else:
        for key, rule in allowed.items():
            if key in entry:
                _check_value(label, f"{where}.{key}", entry[key], rule)


def _check_bounds(label: str, where: str, b: Any, keys: Any) -> None:
    """``bounds``: [lo, hi] with 0 < lo <= hi, or for multi-value entries a table of such pairs."""
    pairs = {"": b} if keys is None else b
    if keys is not None and not isinstance(b, dict):
        raise InputError(f"{label}: {where}.bounds must be a table such as {{ {next(iter(keys))} = [lo, hi] }}.")
    for k, pair in pairs.items():
        name = f"{where}.bounds" + (f".{k}" if k else "")
        if keys is not None and k not in keys:
            raise InputError(f"{label}: unknown key {k!r} in {where}.bounds.")
        ok = (isinstance(pair, list) and len(pair) == 2
              and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in pair))
        if not ok or not 0 < pair[0] <= pair[1]:
            raise InputError(f"{label}: {name} = {pair!r} must be [lo, hi] with 0 < lo <= hi.")


def _check_value(label: str, where: str, value: Any, rule: str) -> None:
    if rule == "posture":
        if not isinstance(value, str) or not value:
            raise InputError(f"{label}: {where} = {value!r} must be the name of a posture, e.g. {DEFAULT_POSTURE!r}.")
        return
    if rule == "back_support":
        if value not in BACK_SUPPORTS:
            raise InputError(f"{label}: {where} = {value!r} is not a back support; use one of "
                             f"{', '.join(BACK_SUPPORTS)}.")
        return
    if rule == "joints":
        if not isinstance(value, list) or any(v not in JOINT_NAMES for v in value):
            raise InputError(f"{label}: {where} must be a list of joint names from {', '.join(JOINT_NAMES)}.")
        return
    if rule == "scaled":
        if not isinstance(value, list) or any(not isinstance(v, str) for v in value):
            raise InputError(f"{label}: {where} must be a list of dotted names, e.g. [\"contacts.buttock_r\", "
                             "\"joints.t12.z\"].")
        return
    if rule == "time_step":
        check_time_step(value, f"{label}: {where}")
        return
    if rule == "bool":
        if not isinstance(value, bool):
            raise InputError(f"{label}: {where} = {value!r} must be true or false.")
        return
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{label}: {where} = {value!r} is not a number.")
    if not math.isfinite(value):
        raise InputError(f"{label}: {where} = {value!r} is not a finite number.")
    if rule == "delay" and value > MAX_DELAY_S:
        raise InputError(f"{label}: {where} = {value!r} s is longer than {MAX_DELAY_S:g} s; a sensory delay is tens "
                         "of milliseconds (e.g. 0.03).")
    if rule in ("positive", "delay") and value <= 0:
        raise InputError(f"{label}: {where} = {value!r} must be positive.")
    if rule == "nonnegative" and value < 0:
        raise InputError(f"{label}: {where} = {value!r} must not be negative.")
    if rule == "count" and (value != int(value) or value < 0):
        raise InputError(f"{label}: {where} = {value!r} must be a whole number >= 0.")
    if rule == "tone" and not TONE_RANGE[0] <= value <= TONE_RANGE[1]:
        raise InputError(f"{label}: {where} = {value!r} is not a plausible muscle tone factor: give one from "
                         f"{TONE_RANGE[0]:g} to {TONE_RANGE[1]:g} (1: as the joints' values).")
    if rule == "fraction" and not 0 < value < 1:
        raise InputError(f"{label}: {where} = {value!r} must lie between 0 and 1.")
