"""What a seated person's model should show: reference curves, bands and findings, as data with their sources.

Each reference says where it comes from and what condition it describes, so that a validation can evaluate a
model against it and say why a figure is expected.  A numerical leaf: numpy and the standard library only (the
package's data files are read with ``csv``); no engine, no plotting.

Public API
----------
ISO2631_5_ZERO, ISO2631_5_POLES         Formula 1 of ISO 2631-5:2018: (natural frequency [rad/s], damping ratio)
ISO2631_5_ANNEX_D_B, _A, _FS_HZ         the standard's digital realisation of Formula 1 at 256 Hz (Annex D)
ISO2631_5_SOURCE                        where those numbers come from
iso2631_5_lumbar_tf(freq_hz)            seat-to-lumbar-spine vertical transfer function (complex)
iso2631_5_annex_d_tf(freq_hz)           the Annex D filter's frequency response (complex)
FAIRLEY_GRIFFIN_NATURAL_FREQUENCY_HZ, FAIRLEY_GRIFFIN_DAMPING_RATIO    the one-mass apparent-mass fit
apparent_mass_one_mass(freq_hz, frame_share=0.0, normalise_at_hz=0.5)  that fit's normalised apparent mass
SPINE_FIRST_RESONANCE_HZ                the seated spine's first resonance band (low, high) [Hz]
Band, BANDS                             the bands a person should meet, each with where it applies
Comparison, COMPARISONS                 findings across two conditions (a slouched posture's lower resonance)
PAPER_SEAT                              the paper's posture and back support (its locking study's seat)
LockingFinding, LOCKING_FINDINGS, LOCKING_VARIANTS    the paper's joint-locking findings (section 4)
literature_anchors()                    the rows of the shipped table of literature figures

Paths are named as in :class:`ehm.FrfTable`: (seat input axis, point, degree of freedom); the apparent mass
of all supports is the point ``support``.
"""

from __future__ import annotations

import csv
import functools
from dataclasses import dataclass
from importlib import resources

import numpy as np

from ..errors import InputError, frequencies_hz

__all__ = [
    "ISO2631_5_ZERO", "ISO2631_5_POLES", "ISO2631_5_ANNEX_D_B", "ISO2631_5_ANNEX_D_A", "ISO2631_5_ANNEX_D_FS_HZ",
    "ISO2631_5_SOURCE", "iso2631_5_lumbar_tf", "iso2631_5_annex_d_tf",
    "FAIRLEY_GRIFFIN_NATURAL_FREQUENCY_HZ", "FAIRLEY_GRIFFIN_DAMPING_RATIO", "FAIRLEY_GRIFFIN_SOURCE",
    "apparent_mass_one_mass", "SPINE_FIRST_RESONANCE_HZ", "SPINE_FIRST_RESONANCE_SOURCE",
    "Band", "BANDS", "Comparison", "COMPARISONS", "KITAZAKI_GRIFFIN_SOURCE", "PAPER_SEAT", "LockingFinding",
    "LOCKING_FINDINGS", "LOCKING_VARIANTS", "literature_anchors",
]

_ISO_FILE = "iso2631_5_2018_seat_to_spine.csv"
_ANCHOR_FILE = "literature_anchors.csv"


def _rows(name: str) -> list[dict]:
    """The rows of a shipped CSV file (lines starting with ``#`` are its description); a ``same`` cell takes the
    value of the row above."""
    text = (resources.files("ehm") / "data" / name).read_text(encoding="utf-8")
    rows, previous = [], {}
    for row in csv.DictReader(line for line in text.splitlines() if not line.startswith("#")):
        row = {k: (previous.get(k, v) if v == "same" else v) for k, v in row.items()}
        rows.append(row)
        previous = row
    return rows


def literature_anchors() -> tuple[dict, ...]:
    """The shipped table of single figures from the literature, one dict per row.

    Columns: ``source``, ``quantity``, ``direction``, ``frequency_hz``, ``value``, ``lower``, ``upper``,
    ``unit``, ``note``, ``condition``, ``location`` (the address where the figure was read); all text, as in
    the file (``src/ehm/data/literature_anchors.csv``).

    Returns
    -------
    tuple of dict
    """
    return tuple(_anchor_rows())


@functools.cache
def _anchor_rows() -> tuple[dict, ...]:
    return tuple(_rows(_ANCHOR_FILE))


def _anchor(quantity: str) -> dict:
    return next(r for r in _anchor_rows() if r["quantity"] == quantity)


# --------------------------------------------------------------------------------------------------------------
# ISO 2631-5:2018, seat to lumbar spine
# --------------------------------------------------------------------------------------------------------------

def _iso_tables() -> tuple:
    rows = _rows(_ISO_FILE)
    pairs = {k: tuple((float(r["value_a"]), float(r["value_b"])) for r in rows if r["kind"] == k)
             for k in ("formula1_zero", "formula1_pole")}
    coefficients = {k: tuple(float(r["value_a"]) for r in sorted((r for r in rows if r["kind"] == k),
                                                                   key=lambda r: int(r["index"])))
                    for k in ("annexD_b", "annexD_a")}
    sources = tuple(dict.fromkeys(r["source"].split(" (_")[0] for r in rows))  # without the names of the constants
    return pairs["formula1_zero"][0], pairs["formula1_pole"], coefficients["annexD_b"], coefficients["annexD_a"], \
        sources


_ZERO, _POLES, _ANNEX_D_B, _ANNEX_D_A, _ISO_SOURCES = _iso_tables()
#: Formula 1's zero pair: (natural frequency w1 [rad/s], damping ratio).
ISO2631_5_ZERO: tuple[float, float] = _ZERO
#: Formula 1's six pole pairs: (natural frequency wk [rad/s], damping ratio) each.
ISO2631_5_POLES: tuple[tuple[float, float], ...] = _POLES
#: Numerator of Annex D's digital filter at 256 Hz (Table D.1), in powers of z^-1.
ISO2631_5_ANNEX_D_B: tuple[float, ...] = _ANNEX_D_B
#: Denominator of Annex D's digital filter at 256 Hz (Table D.1), in powers of z^-1.
ISO2631_5_ANNEX_D_A: tuple[float, ...] = _ANNEX_D_A
#: Sample rate of Annex D's filter [Hz].
ISO2631_5_ANNEX_D_FS_HZ = 256.0
#: Where the ISO 2631-5 numbers come from (the standard's clause, and the repository they were transcribed from).
ISO2631_5_SOURCE = "; ".join(_ISO_SOURCES)


def _second_order(s: np.ndarray, w: float, zeta: float) -> np.ndarray:
    """``1 + 2 zeta s / w + (s / w)^2``."""
    return 1.0 + 2.0 * zeta * s / w + (s / w) ** 2


def iso2631_5_lumbar_tf(freq_hz) -> np.ndarray:
    """The ISO 2631-5:2018 vertical transfer function from seat acceleration to the lumbar spine's response.

    Clause 5.2, Formula 1: with ``s = j 2 pi f``,
    ``H(s) = (1 + 2 z1 s / w1 + (s / w1)^2) / prod_k (1 + 2 zk s / wk + (s / wk)^2)`` over the zero pair
    ``ISO2631_5_ZERO`` and the six pole pairs ``ISO2631_5_POLES``; ``H = 1`` at 0 Hz.  ``|H|`` is 1.01
    at 1 Hz, peaks at 1.59 at 4.7 Hz and falls to 0.87 at 8 Hz and 0.82 at 10 Hz.

    Condition: the standard's model of seated people exposed to vertical seat vibration and shocks; it maps
    the seat's vertical acceleration to the lumbar spine's acceleration response, from which the standard
    computes the spinal dose (:mod:`ehm.standards.comfort.spine`).

    Parameters
    ----------
    freq_hz : float or array_like
        Frequencies [Hz], finite and non-negative.

    Returns
    -------
    ndarray of complex
        ``H(j 2 pi f)``, same shape as ``freq_hz``.
    """
    s = 2j * np.pi * frequencies_hz(freq_hz)
    out = _second_order(s, *ISO2631_5_ZERO)
    for w, zeta in ISO2631_5_POLES:
        out = out / _second_order(s, w, zeta)
    return out


def iso2631_5_annex_d_tf(freq_hz) -> np.ndarray:
    """The frequency response of ISO 2631-5:2018 Annex D's digital filter (256 Hz, Table D.1).

    The standard's own digital realisation of Formula 1; it follows :func:`iso2631_5_lumbar_tf` within 0.0016 in
    modulus from 0.1 to 80 Hz, so either is a check on the other's coefficients.

    Parameters
    ----------
    freq_hz : float or array_like
        Frequencies [Hz], finite, from 0 to 128 Hz (the filter's Nyquist frequency).

    Returns
    -------
    ndarray of complex
        ``B(z) / A(z)`` at ``z = exp(j 2 pi f / 256 Hz)``, same shape as ``freq_hz``.
    """
    f = frequencies_hz(freq_hz)
    if np.any(f > ISO2631_5_ANNEX_D_FS_HZ / 2):
        raise InputError(f"freq_hz must lie within the Annex D filter's band, 0 to {ISO2631_5_ANNEX_D_FS_HZ / 2:g} Hz; "
                         f"got up to {float(np.max(f)):g} Hz.")
    z_inv = np.exp(-2j * np.pi * f / ISO2631_5_ANNEX_D_FS_HZ)
    return np.polyval(ISO2631_5_ANNEX_D_B[::-1], z_inv) / np.polyval(ISO2631_5_ANNEX_D_A[::-1], z_inv)


# --------------------------------------------------------------------------------------------------------------
# Apparent mass: the one-mass fit of Fairley & Griffin (1989)
# --------------------------------------------------------------------------------------------------------------

#: Natural frequency [Hz] of the one-mass fit to the mean vertical apparent mass of 60 seated people.
FAIRLEY_GRIFFIN_NATURAL_FREQUENCY_HZ = float(_anchor("normalised_apparent_mass_sdof_fit_natural_frequency")["value"])
#: Damping ratio of that fit.
FAIRLEY_GRIFFIN_DAMPING_RATIO = float(_anchor("normalised_apparent_mass_sdof_fit_damping_ratio")["value"])
#: Where the fit comes from, and the address where it was read.
FAIRLEY_GRIFFIN_SOURCE = (f"{_anchor('normalised_apparent_mass_sdof_fit_damping_ratio')['source']} "
                          f"({_anchor('normalised_apparent_mass_sdof_fit_damping_ratio')['location']})")
#: Largest share of the body's mass on the rigid frame that :func:`apparent_mass_one_mass` accepts.
MAX_FRAME_SHARE = 0.5


def apparent_mass_one_mass(freq_hz, frame_share: float = 0.0, normalise_at_hz: float = 0.5) -> np.ndarray:
    """The vertical apparent mass of Fairley & Griffin's (1989) one-mass fit, normalised.

    A mass ``m`` on a spring ``k`` and damper ``c`` over the seat, with natural frequency
    ``FAIRLEY_GRIFFIN_NATURAL_FREQUENCY_HZ`` (5 Hz) and damping ratio ``FAIRLEY_GRIFFIN_DAMPING_RATIO``
    (0.475), beside a rigid frame mass ``m0`` moving with the seat:
    ``M(jw) = m0 + m (k + jwc) / (k - w^2 m + jwc)``, divided by ``|M|`` at ``normalise_at_hz``.

    Condition: fitted to the mean apparent mass of 60 seated people (24 men, 24 women, 12 children), legs
    moving with the seat, normalised by the apparent mass at 0.5 Hz (``FAIRLEY_GRIFFIN_SOURCE``).  The
    page read does not give the frame's share, hence ``frame_share``.

    Normalised by the static mass (``normalise_at_hz=0``) the peak is 1.51 at 4.3 Hz without a frame mass and
    1.38 with a fifth of the mass on the frame; at 10 and 15 Hz the modulus stays at most 0.61 and 0.53 for
    any frame share up to a half.  Normalised at 0.5 Hz (the paper's way) each is about 1 % lower: 1.49, 1.37.

    Parameters
    ----------
    freq_hz : float or array_like
        Frequencies [Hz], finite and non-negative.
    frame_share : float
        ``m0 / (m0 + m)``: the share of the body's mass on the rigid frame, 0 to 0.5 (default 0).
    normalise_at_hz : float
        Frequency whose modulus the result is divided by [Hz] (default 0.5, as the fit; 0: the static mass).

    Returns
    -------
    ndarray of complex
        Normalised apparent mass, same shape as ``freq_hz``; ``abs`` gives the curve the bands speak of.
    """
    f = frequencies_hz(freq_hz)
    share = float(frame_share)
    if not 0.0 <= share <= MAX_FRAME_SHARE:
        raise InputError(f"frame_share is the frame's share of the body's mass, 0 to {MAX_FRAME_SHARE:g}; "
                         f"got {frame_share!r}.")
    f0 = float(frequencies_hz(normalise_at_hz, "normalise_at_hz"))

    def mass(freq):
        r = freq / FAIRLEY_GRIFFIN_NATURAL_FREQUENCY_HZ  # k = m wn^2, c = 2 zeta m wn
        damping = 2j * FAIRLEY_GRIFFIN_DAMPING_RATIO * r
        return share + (1.0 - share) * (1.0 + damping) / (1.0 - r * r + damping)

    return mass(f) / abs(mass(f0))


# --------------------------------------------------------------------------------------------------------------
# Bands
# --------------------------------------------------------------------------------------------------------------

_spine = _anchor("seated_spine_first_resonance_band")
#: The seated spine's first resonance band (low, high) [Hz].
SPINE_FIRST_RESONANCE_HZ = (float(_spine["lower"]), float(_spine["upper"]))
#: Where that band comes from, and the address where it was read.
SPINE_FIRST_RESONANCE_SOURCE = f"{_spine['source']} ({_spine['location']})"

#: The seat-to-head ranges as ehm states them: the 'tuned' source of the shipped parameter file names them; no
#: measured curve or paper behind them ships with ehm (the horizontal peak gains have a source of their own).
_SEATED_RANGES = ("ranges reported for seated people, as ehm states them (the 'tuned' source of default_params.toml; "
                  "no measured seat-to-head curve, ISO 5982 table or paper behind these figures ships with ehm)")
_ISO_CONDITION = ("the standard's model of seated people under vertical seat vibration; compared with a person "
                  "sitting erect without back support, feet supported")
_AM_CONDITION = ("60 seated people (24 men, 24 women, 12 children), legs moving with the seat; the one-mass fit "
                 "normalised at 0.5 Hz, frame share 0 to 0.5")
#: The band widths are ehm's own choice round the sources' figures, documented with the checks.
_BAND_WIDTH = "band width: ehm's choice (docs/validation.md, 'The person against the standards')"


@dataclass(frozen=True)
class Band:
    """A band a quantity of the model should lie in.

    Attributes
    ----------
    name : str
        Short identifier.
    quantity : str
        What is compared: ``peak_hz`` (the frequency of the largest gain within ``freq_range_hz``),
        ``peak_gain`` (that gain), ``gain`` (the gain at every frequency of ``freq_range_hz``, both ends
        included) or ``gain_minus_reference`` (the gain minus ``|reference(f)|`` there).
    path : tuple
        (seat input axis, point, degree of freedom), as in :class:`ehm.FrfTable`.
    low, high : float or None
        The band's limits in the quantity's unit (Hz, or the gain's own); None: no limit that side.
    freq_range_hz : tuple
        (low, high) frequencies [Hz] the quantity is taken over.
    source : str
        Where the reference value (and the band's width) comes from, with the address it was read at.
    condition : str
        The condition the reference describes (posture, support, people).
    normalise_at_hz : float or None
        Divide the gain by its value at this frequency first (the apparent mass over its 0.5 Hz value).
    reference : str or None
        Name of the function of this module giving the reference curve (``gain_minus_reference``).
    postures : tuple of str or None
        The postures the band applies to (names of a parameter file's ``[postures.NAME]``); None: every posture.
    back_supports : tuple of str or None
        The back supports it applies to (``none``, ``low``, ``high``, ``full``); None: every back support.
        A validation grades the band only where both hold (:meth:`applies`).
    """

    name: str
    quantity: str
    path: tuple
    low: float | None
    high: float | None
    freq_range_hz: tuple
    source: str
    condition: str
    normalise_at_hz: float | None = None
    reference: str | None = None
    postures: tuple[str, ...] | None = None
    back_supports: tuple[str, ...] | None = None

    def applies(self, posture: str, back_support: str) -> bool:
        """Whether the band's source speaks of a person in ``posture`` on ``back_support`` (so that a validation
        grades the band there)."""
        return ((self.postures is None or posture in self.postures)
                and (self.back_supports is None or back_support in self.back_supports))

    def where(self) -> str:
        """Where the band applies, in words: ``"postures erect, slouched; back support none"``."""
        return _where(self.postures, self.back_supports)

    def holds(self, value) -> bool:
        """Whether ``value`` (a number, or every number of an array) lies within the band, limits included."""
        v = np.asarray(value, dtype=float)
        return bool(np.all(np.isfinite(v)) and (self.low is None or np.all(v >= self.low))
                    and (self.high is None or np.all(v <= self.high)))

    def describe(self) -> str:
        """The band in words, e.g. ``peak_hz of z->lumbar z over 0.5-20 Hz within 4-5.5``."""
        lo = "" if self.low is None else f"{self.low:g}"
        hi = "" if self.high is None else f"{self.high:g}"
        limits = f"within {lo}-{hi}" if lo and hi else (f"at least {lo}" if lo else f"at most {hi}")
        f0, f1 = self.freq_range_hz
        where = f"at {f0:g} Hz" if f0 == f1 else f"over {f0:g}-{f1:g} Hz"
        a, p, d = self.path
        norm = f" over its {self.normalise_at_hz:g} Hz value" if self.normalise_at_hz is not None else ""
        return f"{self.quantity} of {a}->{p} {d}{norm} {where} {limits}"


def _where(postures, back_supports) -> str:
    """Where a reference applies, in words (None: every one)."""
    if postures is None and back_supports is None:
        return "every posture and back support"
    post = "every posture" if postures is None else "posture" + ("s " if len(postures) > 1 else " ") + \
        ", ".join(postures)
    back = "every back support" if back_supports is None else "back support" + \
        ("s " if len(back_supports) > 1 else " ") + ", ".join(back_supports)
    return f"{post}; {back}"


_LUMBAR = ("z", "lumbar", "z")
_SUPPORT = ("z", "support", "z")
#: The postures the measurements without back support speak of: sitting erect (the references' posture), and
#: slouched (the same bands asked of it: a slouched posture changes where the resonance lies, not that there is one).
_UNSUPPORTED_POSTURES = ("erect", "slouched")
#: Where the references measured without a back support apply: those postures, no back support.
_UNSUPPORTED = {"postures": _UNSUPPORTED_POSTURES, "back_supports": ("none",)}

#: The paper's seat: its posture and back support (where its joint-locking study ran).
PAPER_SEAT = ("erect", "high")

#: The paper ehm implements, as a reader can look it up; its section 4 is the joint-locking study.
PAPER_SOURCE = ("paper section 4, the joint-locking study (Desai, Cvetkovic, Wu, Papaioannou, Happee, 'Computationally "
                "efficient human body modelling for real time motion comfort assessment', TU Delft)")

#: A measured fore-and-aft seat-to-head transmissibility, as a reader can look it up (the page read shows the
#: abstract, not the authors).
_FORE_AFT_STUDY = ("16 seated men under fore-and-aft sinusoidal vibration at 2-6 Hz, 0.31-2.43 m/s^2 rms, abstract "
                   "(authors not shown on the page read, https://katalog.lib.cas.cz/KNAV/EdsRecord/edsair,"
                   "edsair.doi.dedup.....d872e48dfa7beeff2bf8d1a30639e9e7)")
_HEAD_GAIN_LIMIT = ("the limit of 3 is ehm's choice round that median (1.5 times it: people vary widely), not a figure "
                    "of the source")

#: The bands a person should meet, each with its source, the condition it describes and where it applies.
BANDS: tuple[Band, ...] = (
    Band("lumbar_gain_vs_iso2631_5", "gain_minus_reference", _LUMBAR, -0.20, 0.20, (1.0, 12.0),
         f"ISO 2631-5:2018 cl. 5.2 Formula 1 ({ISO2631_5_SOURCE}); {_BAND_WIDTH}", _ISO_CONDITION,
         reference="iso2631_5_lumbar_tf", **_UNSUPPORTED),
    Band("lumbar_peak_frequency", "peak_hz", _LUMBAR, 4.0, 5.5, (0.5, 20.0),
         f"ISO 2631-5:2018 cl. 5.2 Formula 1 ({ISO2631_5_SOURCE}): peak at 4.7 Hz; {_BAND_WIDTH}", _ISO_CONDITION,
         **_UNSUPPORTED),
    Band("spine_first_resonance", "peak_hz", _LUMBAR, *SPINE_FIRST_RESONANCE_HZ, (0.5, 20.0),
         SPINE_FIRST_RESONANCE_SOURCE, _spine["condition"], **_UNSUPPORTED),
    Band("apparent_mass_peak_frequency", "peak_hz", _SUPPORT, 4.0, 6.5, (0.5, 20.0),
         f"{FAIRLEY_GRIFFIN_SOURCE}; {_BAND_WIDTH}", _AM_CONDITION, normalise_at_hz=0.5, **_UNSUPPORTED),
    Band("apparent_mass_peak", "peak_gain", _SUPPORT, 1.3, 1.7, (0.5, 20.0),
         f"{FAIRLEY_GRIFFIN_SOURCE}: 1.49 at 4.3 Hz without, 1.37 with a fifth of the mass on the frame; "
         f"{_BAND_WIDTH}", _AM_CONDITION, normalise_at_hz=0.5, **_UNSUPPORTED),
    Band("apparent_mass_10hz", "gain", _SUPPORT, None, 0.75, (10.0, 10.0),
         f"{FAIRLEY_GRIFFIN_SOURCE}: at most 0.61 with a frame share up to 0.5; {_BAND_WIDTH}",
         f"{_AM_CONDITION}; on every seat (above the whole-body resonance the body decouples from the seat through "
         "the soft tissue under it, with or without a backrest; every support the person touches)",
         normalise_at_hz=0.5),
    Band("apparent_mass_15_20hz", "gain", _SUPPORT, None, 0.6, (15.0, 20.0),
         f"{FAIRLEY_GRIFFIN_SOURCE}: at most 0.53 at 15 Hz with a frame share up to 0.5; {_BAND_WIDTH}",
         f"{_AM_CONDITION}; on every seat (as at 10 Hz)", normalise_at_hz=0.5),
    Band("pelvis_peak_frequency", "peak_hz", ("z", "pelvis", "z"), None, 6.5, (0.5, 20.0),
         f"ISO 2631-5:2018 cl. 5.2 Formula 1 ({ISO2631_5_SOURCE}) and {SPINE_FIRST_RESONANCE_SOURCE}: seated people "
         "move in one whole-body mode near 5 Hz (the standard's lumbar peak at 4.7 Hz, the seated spine's first "
         f"resonance at 4.5-5.5 Hz); {_BAND_WIDTH}", _ISO_CONDITION, **_UNSUPPORTED),
    Band("head_vertical_peak_gain", "peak_gain", ("z", "head", "z"), 1.5, 2.0, (0.5, 20.0), _SEATED_RANGES,
         "seated people, vertical seat vibration; on every seat"),
    Band("head_vertical_peak_frequency", "peak_hz", ("z", "head", "z"), 4.0, 6.0, (0.5, 20.0), _SEATED_RANGES,
         "seated people, vertical seat vibration; on every seat"),
    Band("head_fore_aft_peak_frequency", "peak_hz", ("x", "head", "x"), None, 3.0, (0.5, 12.0), _SEATED_RANGES,
         "seated people, fore-aft seat vibration; on every seat"),
    Band("head_lateral_peak_frequency", "peak_hz", ("y", "head", "y"), None, 3.0, (0.5, 12.0), _SEATED_RANGES,
         "seated people, lateral seat vibration; on every seat"),
    Band("head_fore_aft_peak_gain", "peak_gain", ("x", "head", "x"), None, 3.0, (0.5, 20.0),
         f"{_FORE_AFT_STUDY}: the fore-and-aft seat-to-head transmissibility peaks at 2-2.4 Hz, median peak 2, with "
         f"high variability between people; {_HEAD_GAIN_LIMIT}",
         "seated men, fore-and-aft seat vibration; on every seat (a head moving several times as far as the seat "
         "would leave it)"),
    Band("head_lateral_peak_gain", "peak_gain", ("y", "head", "y"), None, 3.0, (0.5, 20.0),
         f"{_FORE_AFT_STUDY}: the fore-and-aft seat-to-head transmissibility peaks at median 2; no source ehm has "
         "read gives a lateral seat-to-head peak gain, so the fore-and-aft limit is carried over to lateral input, "
         f"{_HEAD_GAIN_LIMIT}",
         "seated people, lateral seat vibration; on every seat"),
)


_KITAZAKI = _anchor("principal_resonance_posture_effect")
#: Where the posture's effect on the principal resonance comes from (no page stored: a literature summary).
KITAZAKI_GRIFFIN_SOURCE = f"{_KITAZAKI['source']} ({_KITAZAKI['location']})"


@dataclass(frozen=True)
class Comparison:
    """A finding across two conditions: one band's figure lower in one condition than in another.

    Attributes
    ----------
    name : str
        Short identifier.
    band : str
        The name of the band (of :data:`BANDS`) whose figure is compared.
    lower, higher : tuple
        (posture, back support) of the condition whose figure should be the lower, and of the other one.
    source : str
        Where the finding comes from.
    condition : str
        The people and vibration it describes.
    """

    name: str
    band: str
    lower: tuple
    higher: tuple
    source: str
    condition: str

    def difference(self, lower_value: float, higher_value: float) -> float:
        """The figure in ``lower`` minus the figure in ``higher`` (negative when the finding holds)."""
        return float(lower_value) - float(higher_value)

    def holds(self, lower_value: float, higher_value: float) -> bool:
        """Whether the figure in ``lower`` lies strictly below the one in ``higher`` (equal: not lower)."""
        d = self.difference(lower_value, higher_value)
        return bool(np.isfinite(d) and d < 0.0)

    def describe(self) -> str:
        """The finding in words."""
        return (f"{self.band} lower in {self.lower[0]}, back support {self.lower[1]} than in {self.higher[0]}, "
                f"back support {self.higher[1]}")


#: Findings across two conditions, each graded where both conditions are evaluated (``ehm validate --all``).
COMPARISONS: tuple[Comparison, ...] = (
    Comparison("slouched_resonance_below_erect", "apparent_mass_peak_frequency", ("slouched", "none"),
               ("erect", "none"), f"{KITAZAKI_GRIFFIN_SOURCE}: a slouched posture lowers the principal resonance",
               "seated people under vertical vibration, without a back support; the principal resonance read as the "
               "apparent mass's peak frequency"),
)


# --------------------------------------------------------------------------------------------------------------
# The paper's joint-locking findings
# --------------------------------------------------------------------------------------------------------------

#: The paper's locking variants: name -> joints locked on top of the default (waist) lock.
LOCKING_VARIANTS: dict[str, tuple[str, ...]] = {"baseline": (), "SL": ("t12",), "NL": ("lower_neck",)}


@dataclass(frozen=True)
class LockingFinding:
    """One of the paper's joint-locking findings, as a change a locking study can measure.

    Attributes
    ----------
    label : str
        The finding as :meth:`ehm.analysis.study.LockingStudy.findings` reports it.
    variant : str
        The locked variant (a key of ``LOCKING_VARIANTS``).
    input_axis, point, dof : str
        The path, as in :class:`ehm.FrfTable`.
    quantities : tuple of str
        What changes: ``peak_hz``, ``peak_gain``, ``band_mean_gain`` (fields of :class:`ehm.analysis.study.StudyRow`).
    direction : int
        +1: rises with the joint locked; -1: drops.
    least_change : float
        The smallest change that counts, in the finding's direction: Hz for ``peak_hz``, % of the baseline for
        a gain (0: any change that way); ehm's reading of the paper's words, not a number of the paper.
    paper : str
        What the paper states.
    source : str
    seat : tuple
        (posture, back support) the finding was made on: the paper's seat, :data:`PAPER_SEAT`.
    """

    label: str
    variant: str
    input_axis: str
    point: str
    dof: str
    quantities: tuple
    direction: int
    least_change: float
    paper: str
    source: str = PAPER_SOURCE
    seat: tuple = PAPER_SEAT

    def applies(self, posture: str, back_support: str) -> bool:
        """Whether the finding speaks of a person in ``posture`` on ``back_support``: the paper's seat only."""
        return (posture, back_support) == tuple(self.seat)

    @property
    def locked(self) -> tuple[str, ...]:
        """The joints the finding's variant locks."""
        return LOCKING_VARIANTS[self.variant]

    def change(self, quantity: str, baseline: float, variant: float) -> float:
        """The change of ``quantity`` from ``baseline`` to ``variant``: Hz for ``peak_hz``, % for a gain."""
        return variant - baseline if quantity == "peak_hz" else 100.0 * (variant / baseline - 1.0)

    def holds(self, baseline: dict, variant: dict) -> bool:
        """Whether the finding holds for measured values: ``baseline`` and ``variant`` map each of
        ``quantities`` to its value (e.g. a study row's attributes)."""
        return all(self.direction * self.change(q, baseline[q], variant[q]) > self.least_change
                   for q in self.quantities)

    def holds_in(self, study) -> bool:
        """Whether the finding holds in a locking study (anything with ``row(variant, input_axis, point, dof)``
        returning rows with the ``quantities`` as attributes, e.g. :class:`ehm.analysis.study.LockingStudy`)."""
        key = (self.input_axis, self.point, self.dof)
        base, var = study.row("baseline", *key), study.row(self.variant, *key)
        return self.holds({q: getattr(base, q) for q in self.quantities}, {q: getattr(var, q) for q in self.quantities})


_GAINS = ("peak_gain", "band_mean_gain")

#: The paper's joint-locking findings (section 4), in the order the locking study reports them.
LOCKING_FINDINGS: tuple[LockingFinding, ...] = (
    LockingFinding("SL: vertical trunk peak frequency [Hz] (paper: rises to an unrealistic ~8 Hz)", "SL",
                   "z", "trunk", "z", ("peak_hz",), +1, 1.0,
                   "with T12 locked the vertical response peaks at an unrealistically high frequency (~8 Hz)"),
    LockingFinding("SL: vertical head peak frequency [Hz]", "SL", "z", "head", "z", ("peak_hz",), +1, 1.0,
                   "with T12 locked the vertical response peaks at an unrealistically high frequency (~8 Hz)"),
    LockingFinding("NL: head roll under lateral input (paper: drops clearly)", "NL", "y", "head", "roll", _GAINS,
                   -1, 10.0, "with the lower neck locked head roll under lateral loading is highly underestimated"),
    LockingFinding("NL: head yaw under lateral input (paper: drops clearly)", "NL", "y", "head", "yaw", _GAINS,
                   -1, 10.0, "with the lower neck locked head yaw under lateral loading is highly underestimated"),
    LockingFinding("NL: head pitch under fore-aft input (paper: drops slightly)", "NL", "x", "head", "pitch",
                   _GAINS, -1, 0.0, "with the lower neck locked head pitch under fore-aft loading drops slightly"),
    LockingFinding("NL: head pitch under vertical input (paper: drops slightly)", "NL", "z", "head", "pitch",
                   _GAINS, -1, 0.0, "with the lower neck locked head pitch under vertical loading drops slightly"),
)
