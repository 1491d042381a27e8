"""Joint-locking study (paper section 4): which joints matter for which responses.

The paper locks the T12 spherical-and-compression joint ("spine locked", SL) and the lower neck ("neck
locked", NL) and compares the responses with the full model.  :func:`locking_study` does the same on
this model, for those variants and any others named, and tabulates per path the peak frequency, the
peak gain and the mean gain over a band, with their change from the baseline.
"""

from __future__ import annotations

from dataclasses import astuple, dataclass, fields

import numpy as np

from ..body.tables import joint_names
from ..errors import InputError
from ..person.person import as_person
from ..standards.references import LOCKING_FINDINGS
from ..standards.references import LOCKING_VARIANTS as PAPER_VARIANTS  # the paper's variants: name -> joints locked
from .frf import AXES, DOFS, POINTS, FrfTable, gain_unit, linear_frf, time_domain_frf

#: Reported beside the findings, though the paper states nothing on it: (label, path).
_ALSO_REPORTED = (("SL: vertical pelvis peak frequency [Hz]", ("z", "pelvis", "z")),)

#: Paths reported (input axis, point, dof): the in-plane responses of the paper's Figs. 3-5.
STUDY_PATHS = tuple(
    [(a, p, d) for a in ("x", "z") for p in ("pelvis", "trunk", "head") for d in ("x", "z", "pitch")]
    + [("y", p, d) for p in ("pelvis", "trunk", "head") for d in ("y", "roll", "yaw")]
)


@dataclass(frozen=True)
class StudyRow:
    """One path of one variant."""

    variant: str
    locked: tuple
    input_axis: str
    point: str
    dof: str
    peak_hz: float
    peak_gain: float
    band_mean_gain: float
    peak_hz_change_pct: float
    peak_gain_change_pct: float
    band_mean_change_pct: float


@dataclass(frozen=True)
class LockingStudy:
    """Rows for every variant and path, the FRF tables, and the settings."""

    rows: tuple
    tables: dict
    method: str
    band_hz: tuple

    def row(self, variant: str, input_axis: str, point: str, dof: str) -> StudyRow:
        for r in self.rows:
            if (r.variant, r.input_axis, r.point, r.dof) == (variant, input_axis, point, dof):
                return r
        raise InputError(f"no study row for {variant} seat {input_axis} -> {point} {dof}.")

    def _attrs(self) -> dict:
        return {"description": f"joint-locking study of {', '.join(self.tables)}", "method": self.method,
                "route": "linear" if self.method == "linear" else "nonlinear", "band_hz": self.band_hz}

    def to_dataframe(self):
        """The rows as a pandas DataFrame, one per variant and path: the columns of :class:`StudyRow`
        (``variant``, ``locked`` (joints joined by ``+``), ``input_axis``, ``point``, ``dof``, ``peak_hz``,
        ``peak_gain``, ``band_mean_gain``, ``peak_hz_change_pct``, ``peak_gain_change_pct``,
        ``band_mean_change_pct``) and ``gain_unit`` (as :meth:`ehm.FrfTable.to_dataframe`); the method and the
        band of the band-mean gain in ``DataFrame.attrs``."""
        from ..outputs.dataframes import frame

        names = [f.name for f in fields(StudyRow)]
        columns = {n: list(col) for n, col in zip(names, zip(*(astuple(r) for r in self.rows)))}
        columns["locked"] = ["+".join(v) or "none" for v in columns["locked"]]
        columns["gain_unit"] = [gain_unit(p, d) for p, d in zip(columns["point"], columns["dof"])]
        return frame(columns, self._attrs(), labels={"variant": tuple(self.tables), "input_axis": AXES,
                                                     "point": POINTS, "dof": DOFS})

    def _repr_html_(self) -> str:
        from ..outputs.dataframes import html_table

        headline = [(("z", "trunk", "z"), "peak_hz"), (("z", "head", "z"), "peak_hz"),
                    (("y", "head", "roll"), "peak_gain_change_pct"), (("x", "head", "pitch"), "peak_gain_change_pct")]
        rows = [[name, ", ".join(self.row(name, *headline[0][0]).locked) or "none",
                 *(getattr(self.row(name, *key), what) for key, what in headline)] for name in self.tables]
        facts = {"method": self.method, "band of the band-mean gain": f"{self.band_hz[0]:g}-{self.band_hz[1]:g} Hz",
                 "paths": f"{len(STUDY_PATHS)} per variant (to_dataframe() holds them all)"}
        return html_table("ehm joint-locking study", facts,
                          ["variant", "locked", "z -> trunk z peak [Hz]", "z -> head z peak [Hz]",
                           "y -> head roll peak gain change [%]", "x -> head pitch peak gain change [%]"], rows)

    def findings(self) -> dict:
        """The paper's findings (section 4, ``ehm.standards.references.LOCKING_FINDINGS``), each as measured on this
        model: a peak frequency as [baseline, variant] in Hz, gains as their changes from the baseline in %."""
        out = {}
        for finding in LOCKING_FINDINGS:
            key = (finding.input_axis, finding.point, finding.dof)
            base, var = self.row("baseline", *key), self.row(finding.variant, *key)
            if finding.quantities == ("peak_hz",):
                out[finding.label] = [base.peak_hz, var.peak_hz]
            else:
                out[finding.label] = {f"{q}_change_pct": finding.change(q, getattr(base, q), getattr(var, q))
                                      for q in finding.quantities}
        out.update({label: [self.row("baseline", *path).peak_hz, self.row("SL", *path).peak_hz]
                    for label, path in _ALSO_REPORTED})
        return out


def parse_variant(text: str) -> tuple[str, tuple]:
    """``NAME=joint1,joint2`` -> (name, joints)."""
    if "=" not in text:
        raise InputError(f"variant {text!r} must read NAME=JOINT[,JOINT...], e.g. NL2=lower_neck,upper_neck.")
    name, joints = text.split("=", 1)
    js = tuple(j.strip() for j in joints.split(",") if j.strip())
    if not name.strip() or not js:
        raise InputError(f"variant {text!r} must read NAME=JOINT[,JOINT...].")
    if name.strip() == "baseline":
        raise InputError("'baseline' is the unlocked reference of the study; give the variant another name.")
    return name.strip(), js


def locking_study(params=None, variants: dict | None = None, method: str = "linear",
                  band_hz: tuple[float, float] = (0.5, 4.0), duration_s: float = 60.0, progress=None,
                  size=None) -> LockingStudy:
    """Run the baseline and each variant; compare peak and band-mean gains with the baseline.

    Parameters
    ----------
    params : Person, Parameters or path, optional
        The person (:class:`ehm.Person`; each variant locks its joints on top of the person's own locks), or its
        parameters.
    variants : dict name -> joints to lock
        Default: the paper's (baseline, SL, NL).  A ``baseline`` entry is always added.
    method : ``linear`` (exact, fast) or ``time`` (random-vibration runs, H1 estimates)
    band_hz : band of the band-mean gain (default 0.5-4 Hz, where comfort matters most)
    progress : callable, optional
        Called with a line of text before each variant is linearised (or run).
    size : ehm.BodySize, optional
        An individual body size (:class:`ehm.BodySize`); default the reference person.
    """
    from ..simulation import SeatedHuman

    if method not in ("linear", "time"):
        raise InputError(f"unknown method {method!r}; use linear or time.")
    variants = dict(variants or PAPER_VARIANTS)
    if variants.get("baseline", ()) != ():
        raise InputError("'baseline' is the unlocked reference of the study; give the variant another name.")
    variants = {"baseline": (), **{k: joint_names(v, f"variant {k!r}") for k, v in variants.items() if k != "baseline"}}
    # built first: every variant's joint names are checked before any linearisation
    person = as_person(params, size=size)
    humans = {name: SeatedHuman(person.replace(lock=person.lock + tuple(locks)) if locks else person)
              for name, locks in variants.items()}
    tables: dict[str, FrfTable] = {}
    for name, human in humans.items():
        if progress:
            progress(f"  {name}: locked {', '.join(sorted(human.locked))}, {human.dof} dof")
        tables[name] = (linear_frf(human, "all", freq_hz=np.arange(0.2, 15.0 + 1e-9, 0.02)) if method == "linear"
                        else time_domain_frf(human, "all", duration_s=duration_s, band_hz=(0.1, 15.0)))
    rows = []
    base = tables["baseline"]
    for name, table in tables.items():
        for key in STUDY_PATHS:
            c, b = table.curve(*key), base.curve(*key)
            fp, gp = c.peak((0.3, 15.0))
            bfp, bgp = b.peak((0.3, 15.0))
            m, bm = c.mean_gain(band_hz), b.mean_gain(band_hz)
            rows.append(StudyRow(
                variant=name, locked=tuple(variants[name]), input_axis=key[0], point=key[1], dof=key[2],
                peak_hz=fp, peak_gain=gp, band_mean_gain=m,
                peak_hz_change_pct=100 * (fp / bfp - 1), peak_gain_change_pct=100 * (gp / bgp - 1),
                band_mean_change_pct=100 * (m / bm - 1),
            ))
    return LockingStudy(rows=tuple(rows), tables=tables, method=method, band_hz=tuple(band_hz))
