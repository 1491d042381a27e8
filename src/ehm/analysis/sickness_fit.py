"""One person's motion sickness susceptibility: the MISC accumulation model fitted to their ratings of a drive.

A drive and the MISC ratings one person gave during it (``time_s,misc``: seconds from the drive's start, MISC 0-10)
in; that person's K1 and T1 out (:data:`ehm.standards.sickness.FITTED`, the two parameters of the individual
accumulation model of Kotian, Pool and Happee 2025), with their standard errors, written to a file that
``ehm assess --sickness-params FILE``, batch studies and :func:`ehm.read_sickness_params` read.

The drive is assessed (:func:`ehm.assess`) to get the conflict of the SVC model driven by the head's motion (or
by the seat's, ``location="seat"``); the fit itself is :func:`ehm.standards.sickness.fit_misc`.  A ratings file that
does not fit the drive (a time before its start or after its end, a value off the scale, times out of order) is
refused in one sentence naming the file, the row and the value.
"""

from __future__ import annotations

import csv
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError, checked, checked_class
from ..inputs.motion import SeatMotion
from ..standards.sickness import MISC_MAX, MiscFit, MiscParameters, fit_misc, misc_rating, sickness_params_text
from .assessment import Assessment, assess

#: The files ``ehm fit-sickness --out DIR`` writes.
PARAMS_FILE = "sickness_params.toml"
FIT_CSV = "sickness_fit.csv"
FIT_FIGURE = "sickness_fit.png"


@checked
def read_ratings(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """A person's MISC ratings from a CSV file with the columns ``time_s`` (seconds from the drive's start) and
    ``misc`` (0-10; other columns are ignored): ``(time_s, misc)``.  A fault is refused in one sentence naming the
    file, the row (the file's line) and the value."""
    times, values, _ = rating_rows(path)
    return times, values


def rating_rows(path: str | Path) -> tuple[np.ndarray, np.ndarray, list[int]]:
    """:func:`ehm.read_ratings` with the file's line of each rating (for messages)."""
    path = Path(path)
    try:
        with open(path, newline="", encoding="utf-8-sig") as fh:
            rows = list(csv.reader(fh))
    except FileNotFoundError:
        raise InputError(f"{path}: no such ratings file (--ratings, ratings=).") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read the ratings ({type(exc).__name__}: {exc}).") from None
    if not rows:
        raise InputError(f"{path}: the ratings file is empty; give a header time_s,misc and one row per rating.")
    header = [h.strip() for h in rows[0]]
    missing = [c for c in ("time_s", "misc") if c not in header]
    if missing:
        shown = ", ".join(repr(re.split(r"[.!?]\s", h)[0][:24]) for h in header[:6]) or "none"
        raise InputError(f"{path}: the header has no column {missing[0]!r} (it has {shown}); ratings need time_s "
                         "(seconds from the drive's start) and misc (0-10).")
    it, im = header.index("time_s"), header.index("misc")
    times, values, lines = [], [], []
    for line, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        cells = {}
        for name, j in (("time_s", it), ("misc", im)):
            text = row[j].strip() if j < len(row) else ""
            try:
                cells[name] = float(text)
            except ValueError:
                raise InputError(f"{path} row {line}: {name} {text!r} is not a number.") from None
            if not np.isfinite(cells[name]):
                raise InputError(f"{path} row {line}: {name} {text!r} is not a finite number.")
        if not 0.0 <= cells["misc"] <= MISC_MAX:
            raise InputError(f"{path} row {line}: misc {cells['misc']:g} lies outside the MISC scale's 0-10.")
        if times and cells["time_s"] <= times[-1]:
            raise InputError(f"{path} row {line}: time_s {cells['time_s']:g} s does not follow the row before's "
                             f"{times[-1]:g} s; give the ratings in the order they were given.")
        times.append(cells["time_s"])
        values.append(cells["misc"])
        lines.append(line)
    if not times:
        raise InputError(f"{path}: the ratings file has a header but no ratings.")
    return np.array(times), np.array(values), lines


@checked_class
@dataclass(frozen=True)
class SicknessFit:
    """A person's fitted MISC parameters (``fit.params``, ``fit.std``) with what they were fitted to."""

    fit: MiscFit
    drive: str
    ratings: str
    location: str
    trace_time_s: np.ndarray  # the conflict's and the fitted model's times [s]
    trace_misc: np.ndarray  # the fitted model's MISC over the whole drive

    @property
    def params(self) -> MiscParameters:
        """The person's parameters (what ``assess(..., sickness_params=)`` takes)."""
        return self.fit.params

    def summary_lines(self) -> list[str]:
        """The fit in a few lines, for the console."""
        f = self.fit
        p = f.params
        lo_k, hi_k = f.interval("fast_gain")
        lo_t, hi_t = f.interval("fast_time_constant_s")
        return [f"K1 (fast_gain) {p.fast_gain:.4g} (m/s^2)^-1, +/- {f.std['fast_gain']:.3g} (2 std: {lo_k:.4g} to "
                f"{hi_k:.4g})",
                f"T1 (fast_time_constant_s) {p.fast_time_constant_s:.4g} s, +/- {f.std['fast_time_constant_s']:.3g} s "
                f"(2 std: {lo_t:.4g} to {hi_t:.4g} s)",
                f"{f.n_ratings} ratings; rms of rating minus model {f.rms_misc:.3g} MISC (the group's parameters: "
                f"{f.rms_misc_group:.3g})"]

    def write(self, folder) -> list[Path]:
        """``sickness_params.toml`` (the person's parameters) and ``sickness_fit.csv`` (the ratings beside the fitted
        model: ``time_s,misc,misc_model``) into ``folder``; returns the paths."""
        from ..files import write_csv_atomic, write_text_atomic

        folder = Path(folder)
        params = folder / PARAMS_FILE
        write_text_atomic(params, sickness_params_text(self.fit, {"drive": self.drive, "ratings": self.ratings,
                                                                  "conflict_of": self.location}))
        table = folder / FIT_CSV
        write_csv_atomic(table, ["time_s", "misc", "misc_model"],
                         np.column_stack([self.fit.time_s, self.fit.misc_rated, self.fit.misc_model]))
        return [params, table]


@checked
def fit_sickness(drive, ratings, human=None, method: str = "auto", location: str = "head",
                 misc_params: MiscParameters | None = None) -> SicknessFit:
    """Fit one person's MISC parameters (K1, T1) to their ratings of a drive.

    Parameters
    ----------
    drive : SeatMotion or Assessment
        The drive the person rated (assessed here), or its assessment (:func:`ehm.assess`,
        :func:`ehm.read_assessment`).
    ratings : path or (time_s, misc)
        A CSV file with ``time_s,misc`` (:func:`ehm.read_ratings`), or the two arrays: seconds from the drive's start
        and MISC 0-10.
    human : Person or SeatedHuman, optional
        Who sat there (for a drive; default the default person).
    method : str
        The route of :func:`ehm.assess` (for a drive).
    location : str
        Whose conflict: ``head`` (through the body, default) or ``seat`` (the head fixed to the seat).
    misc_params : MiscParameters, optional
        The values kept (all but K1 and T1) and the starting point (default the group's).
    """
    if location not in ("head", "seat"):
        raise InputError(f"fit_sickness: location is 'head' or 'seat', not {location!r}.")
    if isinstance(ratings, (str, os.PathLike)):
        where = str(ratings)
        times, values, lines = rating_rows(ratings)
    else:
        try:
            times, values = (np.asarray(x, dtype=float) for x in ratings)
        except (TypeError, ValueError):
            raise InputError("fit_sickness: give ratings as a CSV path (time_s,misc) or as (time_s, misc) arrays of "
                             "numbers.") from None
        where = "fit_sickness: the ratings given,"
        lines = None
    if isinstance(drive, Assessment):
        assessment = drive
    elif isinstance(drive, SeatMotion):
        assessment = assess(drive, human, method=method, sickness_params=misc_params)
    else:
        raise InputError(f"fit_sickness: drive is {type(drive).__name__}; give the ehm.SeatMotion the person rated "
                         "or its ehm.Assessment.")
    trace = assessment.sickness[location]
    end = float(trace.time_s[-1])
    late = np.flatnonzero((times < 0) | (times > end + 1e-9))
    if late.size:
        k = int(late[0])
        row = f"row {lines[k]}" if lines else f"rating {k + 1}"
        raise InputError(f"{where} {row}: time_s {times[k]:g} s lies outside the drive '{assessment.description}' "
                         f"(0-{end:g} s); ratings are seconds from the drive's start (--ratings, ratings=).")
    fit = fit_misc(trace.time_s, trace.conflict_magnitude_mps2, times, values, misc_params)
    dt = float(trace.time_s[1] - trace.time_s[0])
    return SicknessFit(fit=fit, drive=assessment.description, ratings=where, location=location,
                       trace_time_s=np.asarray(trace.time_s), trace_misc=misc_rating(trace.conflict_magnitude_mps2,
                                                                                    dt, fit.params))
