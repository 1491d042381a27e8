"""Is the person like people?  The model against the standards' reference curves, published fits and findings.

:func:`ehm.validate` builds a person (any parameter file, size, posture and seat), computes the exact frequency
response of its linearised model (:func:`ehm.linear_frf`, 0.1-20 Hz) and evaluates the bands of
:data:`ehm.standards.references.BANDS` (ISO 2631-5's seat-to-lumbar transfer function, the one-mass apparent-mass fit of
Fairley & Griffin, the vertical whole-body mode, the seat-to-head ranges), the findings across two conditions
(:data:`ehm.standards.references.COMPARISONS`) and the joint-locking findings of the paper
(:data:`ehm.standards.references.LOCKING_FINDINGS`, through :func:`ehm.analysis.study.locking_study`).  The result is
a table: each check's figure, its band, and whether it passes.

Each band says on which postures and back supports its source applies (:meth:`ehm.standards.references.Band.applies`),
and is graded only there: the lumbar, apparent-mass peak and whole-body-mode bands without a back support (erect or
slouched), the apparent mass above its resonance and the seat-to-head bands on every seat, the locking findings on
the paper's seat (erect, high back support).  By default the person is evaluated in the references' condition (erect,
back support ``none``) and on its own seat (the default person: the paper's seat); ``posture`` or ``back_support``
evaluates that one condition; ``every_condition=True`` (``ehm validate --all``) every posture the parameter file
defines on every back support, with the findings across two conditions (a slouched posture's lower resonance).

>>> import ehm
>>> v = ehm.validate()                                   # the default person
>>> v.person["conditions"]
['erect, back support none', 'erect, back support high']
>>> print(v.format_table())                              # doctest: +ELLIPSIS
condition                 check ...
erect, back support none  lumbar_gain_vs_iso2631_5 ...
...
sources (each check's figures in validation.csv's source column; ...):
  [1] ISO 2631-5:2018 cl. 5.2 Formula 1 ...
...
>>> import shutil
>>> _ = shutil.copy(ehm.body.params.default_params_path(), "my.toml")  # a parameter file of one's own
>>> v = ehm.validate("my.toml", size=ehm.BodySize(1.62, 58.0))   # a parameter file, a body size
>>> every = ehm.validate(every_condition=True, locking=False)   # every posture on every back support
>>> len(every.tables), every.check("slouched_resonance_below_erect").condition
(8, 'slouched, back support none vs erect, back support none')

``ehm validate`` runs it from the command line (:doc:`/validation`), with a figure per seat input axis
(:func:`ehm.outputs.plotting.plot_validation`); ``ehm validate --all`` with one figure grid, a row per condition
(:func:`ehm.outputs.plotting.plot_validation_grid`).
"""

from __future__ import annotations

import csv
import io
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from ..body.params import Parameters
from ..body.supports import BACK_SUPPORTS
from ..errors import InputError, checked, checked_class
from ..files import write_text_atomic
from ..person.person import Person, as_person
from ..standards import references
from .frf import AXES, FrfTable, linear_frf

#: Frequencies the model is evaluated at [Hz]: 0.1-20 Hz in 0.05 Hz steps (the bands reach 20 Hz).
FREQ_HZ = np.round(np.arange(0.1, 20.0 + 1e-9, 0.05), 10)
#: The condition the reference curves describe: posture and back support.
REFERENCE_CONDITION = ("erect", "none")
#: The bands whose sources speak of every seat and posture (graded wherever the person is evaluated).
ANY_SEAT_BANDS = tuple(b.name for b in references.BANDS if b.postures is None and b.back_supports is None)


@dataclass(frozen=True)
class Check:
    """One check of the model against a reference.

    Attributes
    ----------
    name : str
        The band's or finding's name (``ehm.standards.references``).
    condition : str
        Where the person was evaluated: ``"erect, back support none"``.
    what : str
        The check in words.
    value : float
        The model's figure: a frequency [Hz], a gain, a gain's deviation from the reference curve at its
        worst frequency, or a locking finding's change (Hz, or % of the baseline).
    at_hz : float
        Where the figure was taken (the peak's or the worst deviation's frequency) [Hz]; NaN for a locking
        finding.
    low, high : float
        The band (NaN: no limit that side).
    unit : str
        The unit of ``value``, ``low`` and ``high``.
    passed : bool
    source : str
        Where the reference comes from.
    """

    name: str
    condition: str
    what: str
    value: float
    at_hz: float
    low: float
    high: float
    unit: str
    passed: bool
    source: str


@checked_class
@dataclass(frozen=True)
class Validation:
    """Every check of a person against the references, and the frequency responses they were taken from.

    Attributes
    ----------
    checks : tuple of Check
    tables : dict
        ``condition -> FrfTable``: the linear route's responses of the person in each condition, with the
        ``lumbar`` point and the apparent mass (``support``).
    person : dict
        What was evaluated: the parameter file's name, size, conditions.
    """

    checks: tuple
    tables: dict
    person: dict = field(default_factory=dict)

    @property
    def passed(self) -> bool:
        """Whether every check passes."""
        return all(c.passed for c in self.checks)

    @property
    def failed(self) -> tuple:
        """The checks that do not pass."""
        return tuple(c for c in self.checks if not c.passed)

    def check(self, name: str, condition: str | None = None) -> Check:
        """The check called ``name`` (in ``condition``, default the first one evaluated)."""
        for c in self.checks:
            if c.name == name and (condition is None or c.condition == condition):
                return c
        raise InputError(f"no check {name!r}{'' if condition is None else ' in ' + condition}; the checks are "
                         f"{', '.join(sorted({c.name for c in self.checks}))}.")

    def conditions(self) -> tuple:
        """The conditions the checks were taken in, in order, each once (a comparison's names both)."""
        return tuple(dict.fromkeys(c.condition for c in self.checks))

    def counts(self) -> dict:
        """``condition -> (checks passing, checks)``, in the order of :meth:`conditions`."""
        out = {}
        for c in self.checks:
            passing, n = out.get(c.condition, (0, 0))
            out[c.condition] = (passing + bool(c.passed), n + 1)
        return out

    def format_counts(self) -> str:
        """One line per condition: how many of its checks pass (of them the paper's locking findings, on its seat),
        and which fail."""
        w = max(len(c) for c in self.conditions()) + 2 if self.checks else 0
        lines = []
        for condition, (passing, n) in self.counts().items():
            here = [c for c in self.checks if c.condition == condition]
            failed = [c.name for c in here if not c.passed]
            locking = [c for c in here if c.name.startswith("locking_")]
            line = f"{condition:<{w}}{passing:>3} of {n:<3} pass"
            if locking:
                line += f" (locking findings {sum(c.passed for c in locking)} of {len(locking)})"
            lines.append(line + (f"; FAIL: {', '.join(failed)}" if failed else ""))
        return "\n".join(lines)

    def on_axis(self, axis: str) -> tuple:
        """The checks of one seat input axis (``x``, ``y`` or ``z``): the bands on its paths and the locking
        findings under it."""
        if axis not in AXES:
            raise InputError(f"axis {axis!r}: use one of {', '.join(AXES)}.")
        return tuple(c for c in self.checks if _CHECK_AXIS.get(c.name) == axis)

    def as_dict(self) -> dict:
        """Plain data for JSON output (a limit a band does not have, or a locking finding's frequency: None)."""
        plain = lambda v: None if isinstance(v, float) and np.isnan(v) else v  # noqa: E731
        return {"passed": self.passed, "n_checks": len(self.checks), "n_failed": len(self.failed),
                "person": self.person, "checks": [{k: plain(v) for k, v in asdict(c).items()} for c in self.checks]}

    def to_dataframe(self):
        """The checks as a pandas DataFrame, one row each, with the columns of
        :class:`~ehm.analysis.validation.Check`."""
        from ..outputs.dataframes import frame

        names = list(Check.__dataclass_fields__)
        columns = {n: [getattr(c, n) for c in self.checks] for n in names}
        return frame(columns, {"description": "the person against the standards' reference curves",
                               "passed": self.passed, **{k: str(v) for k, v in self.person.items()}})

    def to_csv(self, path: Path | str) -> None:
        """Write the checks as CSV (whole or not at all), one row each, with the columns of
        :class:`~ehm.analysis.validation.Check`; a limit a band does not have is an empty cell."""
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        names = list(Check.__dataclass_fields__)
        writer.writerow(names)
        for c in self.checks:
            writer.writerow([_csv_cell(getattr(c, n)) for n in names])
        write_text_atomic(path, buffer.getvalue())

    def sources(self) -> list[str]:
        """The works the checks cite (``citation`` of each check's source), each once, in the order the checks
        first cite them (``[1]`` is the first): what :meth:`format_table` lists under the table."""
        return list(dict.fromkeys(work for c in self.checks for work in citations(c.source)))

    def format_table(self) -> str:
        """The checks as a fixed-width text table, one line each (the model's figure with its unit, the frequency it
        was taken at, the band, pass or FAIL, the source by number), a line with the count, and the sources."""
        w = max([len("condition"), *(len(c.condition) for c in self.checks)]) + 2
        u = max([len("unit"), *(len(c.unit) for c in self.checks)]) + 2
        sources = self.sources()
        lines = [f"{'condition':<{w}}{'check':<44}{'model':>9}  {'unit':<{u}}{'at Hz':>6}  {'band':<14}{'':<6}source"]
        for c in self.checks:
            where = "" if np.isnan(c.at_hz) else f"{c.at_hz:.2f}"
            lines.append(f"{c.condition:<{w}}{c.name:<44}{c.value:>9.3g}  {c.unit:<{u}}{where:>6}  "
                         f"{band_text(c):<14}{'pass' if c.passed else 'FAIL':<6}"
                         f"[{', '.join(str(sources.index(w) + 1) for w in citations(c.source))}]")
        lines.append(f"{len(self.checks) - len(self.failed)} of {len(self.checks)} checks pass.")
        lines.append("sources (each check's figures in validation.csv's source column; the band widths are ehm's "
                     "choice round them, docs/validation.md):")
        lines += [f"  [{i}] {text}" for i, text in enumerate(sources, 1)]
        return "\n".join(lines)

    def __repr__(self) -> str:
        failed = ", ".join(dict.fromkeys(c.name for c in self.failed))
        return (f"<Validation: {len(self.checks) - len(self.failed)} of {len(self.checks)} checks pass"
                + (f"; failed: {failed}" if failed else "") + ">")

    def _repr_html_(self) -> str:
        return self.to_dataframe().to_html(index=False)


def citations(source: str) -> list[str]:
    """The works a check's source cites, as a reader can look them up: the source without the figures read from it
    (after ``": "``) and without the note on the band's width, split where it joins two works (``") and "``)."""
    head = source.split("; band width")[0].partition(": ")[0]
    parts = head.split(") and ")
    return [p + ")" for p in parts[:-1]] + [parts[-1]]


def _csv_cell(value) -> str:
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, float):
        return "" if np.isnan(value) else f"{value:.6g}"
    return str(value)


def _is_strict(check: Check) -> bool:
    """Whether a check's limit excludes the limit itself: a locking finding asks for more than its least change, a
    finding across two conditions for a figure strictly lower (a band includes its limits)."""
    return check.name.startswith("locking_") or check.name in _COMPARISON_NAMES


@checked
def band_text(check: Check) -> str:
    """A check's band as the table prints it: ``"4 to 5.5"``, ``"<= 0.75"``, ``"< 0"`` (a strict limit: a locking
    finding, a finding across two conditions)."""
    return _band_text(check.low, check.high, strict=_is_strict(check))


def _band_text(low: float, high: float, strict: bool = False) -> str:
    if np.isnan(low):
        return f"{'<' if strict else '<='} {high:g}"
    if np.isnan(high):
        return f"{'>' if strict else '>='} {low:g}"
    return f"{low:g} to {high:g}"


def _condition_label(posture: str, back_support: str) -> str:
    return f"{posture}, back support {back_support}"


def band_gain(table: FrfTable, band: references.Band) -> np.ndarray:
    """The model's curve a band speaks of: the gain of the band's path, over its value at
    ``band.normalise_at_hz`` when the band says so (the apparent mass over its 0.5 Hz value)."""
    c = table.curve(*band.path)
    g = np.asarray(c.gain, dtype=float)
    if band.normalise_at_hz is not None:
        g = g / np.interp(band.normalise_at_hz, c.freq_hz, g)
    return g


def band_figure(table: FrfTable, band: references.Band) -> tuple[float, float]:
    """The model's figure for one band and where it was taken: ``(value, frequency [Hz])``.

    ``peak_hz``/``peak_gain``: the largest gain in the band's frequency range, its frequency or gain;
    ``gain``: the gain nearest the band's open side over the range (its largest against an upper limit);
    ``gain_minus_reference``: the deviation from the reference curve with the largest modulus.
    """
    f = np.asarray(table.curve(*band.path).freq_hz, dtype=float)
    g = band_gain(table, band)
    lo, hi = band.freq_range_hz
    sel = (f >= lo - 1e-9) & (f <= hi + 1e-9)
    if not sel.any():
        raise InputError(f"the model's responses do not reach {lo:g}-{hi:g} Hz for the band {band.name}.")
    f, g = f[sel], g[sel]
    if band.quantity in ("peak_hz", "peak_gain"):
        i = int(np.argmax(g))
        return (float(f[i]) if band.quantity == "peak_hz" else float(g[i])), float(f[i])
    if band.quantity == "gain":
        i = int(np.argmax(g)) if band.low is None else int(np.argmin(g))
        return float(g[i]), float(f[i])
    if band.quantity == "gain_minus_reference":
        d = g - np.abs(getattr(references, band.reference)(f))
        i = int(np.argmax(np.abs(d)))
        return float(d[i]), float(f[i])
    raise InputError(f"band {band.name} has an unknown quantity {band.quantity!r}.")


def _unit(band: references.Band) -> str:
    """The unit of a band's figure: ``Hz`` (a peak's frequency), ``kg`` (an apparent mass), ``(m/s^2)/(m/s^2)`` (a
    seat-to-body gain, or a gain's difference from a reference curve), ``1`` (a ratio: the apparent mass over its
    value at ``normalise_at_hz``)."""
    if band.quantity == "peak_hz":
        return "Hz"
    if band.normalise_at_hz is not None:
        return "1"
    return "kg" if band.path[1] == "support" else "(m/s^2)/(m/s^2)"


@checked
def bands_applying(posture: str, back_support: str) -> tuple:
    """The bands of :data:`ehm.standards.references.BANDS` whose sources speak of a person in ``posture`` on
    ``back_support`` (:meth:`ehm.standards.references.Band.applies`): the bands a validation grades there."""
    return tuple(b for b in references.BANDS if b.applies(posture, back_support))


def band_checks(table: FrfTable, condition: str, bands=None) -> list[Check]:
    """Bands (default every band of :data:`ehm.standards.references.BANDS`, wherever it applies: give
    :func:`bands_applying`'s to grade only those) evaluated on one frequency-response table."""
    out = []
    for b in references.BANDS if bands is None else bands:
        value, at = band_figure(table, b)
        out.append(Check(b.name, condition, b.describe(), value, at,
                         np.nan if b.low is None else float(b.low), np.nan if b.high is None else float(b.high),
                         _unit(b), b.holds(value), b.source))
    return out


def _locking_name(finding: references.LockingFinding, quantity: str) -> str:
    return f"locking_{finding.variant}_{finding.input_axis}_{finding.point}_{finding.dof}_{quantity}"


_BAND_BY_NAME = {b.name: b for b in references.BANDS}
_COMPARISON_NAMES = frozenset(c.name for c in references.COMPARISONS)
#: Each check's seat input axis, by name: the bands' paths, the locking findings' input axes, the comparisons' bands'.
_CHECK_AXIS = {**{b.name: b.path[0] for b in references.BANDS},
               **{_locking_name(f, q): f.input_axis for f in references.LOCKING_FINDINGS for q in f.quantities},
               **{c.name: _BAND_BY_NAME[c.band].path[0] for c in references.COMPARISONS}}


def _comparison_label(comparison: references.Comparison) -> str:
    """The condition column of a comparison's check: both conditions it compares, ``"slouched, back support none vs
    erect, back support none"`` (the one expected lower first)."""
    return f"{_condition_label(*comparison.lower)} vs {_condition_label(*comparison.higher)}"


@checked
def comparison_checks(tables: dict, comparisons: tuple | list | None = None) -> list[Check]:
    """The findings across two conditions (default :data:`ehm.standards.references.COMPARISONS`) in ``tables``
    (``condition label -> FrfTable``, as a :class:`~ehm.Validation`'s ``tables``): one check per finding whose two
    conditions are both there, each one row naming both conditions (the one expected lower first: ``"slouched, back
    support none vs erect, back support none"``).  Its figure is the band's figure in the lower condition minus that
    in the higher one (its unit's), taken from the tables whether or not the band is graded in either condition; it
    passes when strictly below 0."""
    out = []
    for comp in references.COMPARISONS if comparisons is None else comparisons:
        lower, higher = _condition_label(*comp.lower), _condition_label(*comp.higher)
        if lower not in tables or higher not in tables:
            continue
        band = _BAND_BY_NAME.get(comp.band)
        if band is None:
            raise InputError(f"the comparison {comp.name} names the band {comp.band!r}; the bands are "
                             f"{', '.join(_BAND_BY_NAME)}.")
        a, b = band_figure(tables[lower], band)[0], band_figure(tables[higher], band)[0]
        out.append(Check(comp.name, _comparison_label(comp), f"{comp.describe()} ({a:.3g} against {b:.3g})",
                         comp.difference(a, b), np.nan, np.nan, 0.0, _unit(band), comp.holds(a, b),
                         comp.source))
    return out


def locking_checks(study, condition: str) -> list[Check]:
    """The paper's locking findings (:data:`ehm.standards.references.LOCKING_FINDINGS`) in a locking study: one check
    per
    finding and quantity, the change from the baseline (Hz, or % of the baseline's gain)."""
    out = []
    for finding in references.LOCKING_FINDINGS:
        key = (finding.input_axis, finding.point, finding.dof)
        base, var = study.row("baseline", *key), study.row(finding.variant, *key)
        for q in finding.quantities:
            change = finding.change(q, getattr(base, q), getattr(var, q))
            bound = float(finding.least_change) * finding.direction + 0.0  # no -0
            low, high = (bound, np.nan) if finding.direction > 0 else (np.nan, bound)
            passed = finding.direction * change > finding.least_change
            out.append(Check(_locking_name(finding, q), condition, f"{finding.label}: {q} change", float(change),
                             np.nan, low, high, "Hz" if q == "peak_hz" else "%", bool(passed),
                             f"{finding.source}: {finding.paper}"))
    return out


def _person(person: Person, posture, back_support):
    from ..simulation import SeatedHuman

    return SeatedHuman(person.replace(posture=posture, back_support=back_support))


def _conditions(params: Parameters, posture, back_support, every_condition: bool) -> list[tuple[str, str]]:
    """(posture, back support) of each condition to evaluate."""
    if every_condition:
        if posture is not None or back_support is not None:
            raise InputError("every_condition=True (--all) evaluates every posture on every back support: leave out "
                             "posture and back_support (--posture, --back-support), or evaluate that one condition "
                             "without every_condition (--all).")
        return [(post, back) for post in params.postures() for back in BACK_SUPPORTS]
    if posture is not None or back_support is not None:
        return [(posture or params.posture, back_support or params.back_support)]
    own = (params.posture, params.back_support)
    return [REFERENCE_CONDITION] + ([own] if own != REFERENCE_CONDITION else [])


@checked
def validate(params: Person | Parameters | str | None = None, size=None, posture: str | None = None,
             back_support: str | None = None, locking: bool = True, dt_s: float | None = None,
             progress: Callable | None = None, every_condition: bool = False) -> Validation:
    """The person against every reference of :mod:`ehm.standards.references`, each where its source applies.

    Parameters
    ----------
    params : Person, Parameters or path, optional
        The person (:class:`ehm.Person`: its size, posture, back support, head control, locks and step apply), or
        its parameters (default: the shipped default person).
    size : ehm.BodySize, optional
        An individual body size; default the reference person (a shortcut that changes the Person).
    posture, back_support : str, optional
        Evaluate this condition only (the bands that apply there).  Default: the references' condition (erect, no
        back support) and the person's own seat, each with the bands that apply there.
    locking : bool
        Evaluate the paper's joint-locking findings, on the paper's seat (erect, high back support: three more
        linearisations of the person there).
    dt_s : float, optional
        The time step the person is linearised at (default: its own; a shortcut that changes the Person).
    progress : callable, optional
        ``progress(done, total)`` after each linearisation (one per condition, and one per locking variant).
    every_condition : bool
        Evaluate every posture the parameter file defines (the shipped file: erect, slouched) on every back support
        (none, low, high, full), each with the bands that apply there, and the findings across two conditions
        (:data:`ehm.standards.references.COMPARISONS`); ``ehm validate --all``.  Not together with ``posture`` or
        ``back_support``.

    Returns
    -------
    Validation
        Its checks in order: each condition's bands, the findings across two conditions evaluated, then the
        locking findings.
    """
    person = as_person(params, size=size, dt_s=dt_s, posture=posture, back_support=back_support)
    p = person.params
    conditions = _conditions(p, person.posture, person.back_support, bool(every_condition))
    total = len(conditions) + (len(references.LOCKING_VARIANTS) if locking else 0)
    done = _Counter(progress, total)
    checks, tables = [], {}
    for post, back in conditions:
        label = _condition_label(post, back)
        table = linear_frf(_person(person, post, back), "all", freq_hz=FREQ_HZ)
        tables[label] = table
        checks += band_checks(table, label, bands_applying(post, back))
        done()
    checks += comparison_checks(tables)
    if locking:
        post, back = references.PAPER_SEAT  # where the paper's locking study ran
        checks += locking_checks(_locking_study(person.replace(posture=post, back_support=back), done),
                                 _condition_label(post, back))
    record = {"params": p.value("about.name") if _has(p, "about.name") else "custom", "origin": str(p.origin),
              "size": None if person.size is None else repr(person.size), "dt_s": person.dt_s,
              "locking": bool(locking), "every_condition": bool(every_condition),
              "conditions": [_condition_label(a, b) for a, b in conditions],
              "head_control": person.to_dict()["head_control"], "lock": list(person.lock),
              "unlock": list(person.unlock)}
    return Validation(checks=tuple(checks), tables=tables, person=record)


class _Counter:
    """``progress(done, total)`` one step further at each call (nothing without a ``progress``)."""

    def __init__(self, progress, total: int):
        self.progress, self.total, self.done = progress, total, 0

    def __call__(self, *_) -> None:
        self.done += 1
        if self.progress is not None:
            self.progress(min(self.done, self.total), self.total)


def _locking_study(person: Person, done: _Counter):
    """The paper's locking study of the person on its own seat (linear method); ``done`` after each variant."""
    from .study import PAPER_VARIANTS, locking_study

    started = []  # the study announces each variant before linearising it: count the previous one as done

    def step(_text):
        if started:
            done()
        started.append(True)

    study = locking_study(params=person, variants=dict(PAPER_VARIANTS), method="linear", progress=step)
    done()
    return study


def _has(p: Parameters, path: str) -> bool:
    try:
        p.value(path)
    except (KeyError, InputError):
        return False
    return True
