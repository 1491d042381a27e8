"""Motion sickness incidence from a six-degree-of-freedom subjective vertical conflict (SVC) model.

The subjective vertical conflict theory of Bos and Bles (1998) states that motion sickness is driven
by the difference between the vertical sensed by the vestibular organs and the vertical expected by
an internal model of those organs (the *subjective vertical*).  Bos and Bles detailed the model for
vertical motion; Kamiji et al. (2007) and Wada, Kamiji and Doi (2015) extended it to six degrees of
freedom by adding the semicircular canals and the otolith-canal interaction of Bos and Bles (2002).
This module implements that six-degree-of-freedom structure.

References
----------
Bos, J.E. and Bles, W. (1998).  Modelling motion sickness and subjective vertical mismatch detailed
    for vertical motions.  Brain Research Bulletin 47(5), 537-542.
Bos, J.E. and Bles, W. (2002).  Theoretical considerations on canal-otolith interaction and an
    observer model.  Biological Cybernetics 86, 191-207.
Kamiji, N., Kurata, Y., Wada, T. and Doi, S. (2007).  Modeling and validation of carsickness
    mitigation mechanism.  Proc. IEEE Int. Conf. Systems, Man and Cybernetics, 1740-1745.  (The
    6-DOF SVC model whose parameter set is the default here; see "Where the literature differs".)
Braccesi, C. and Cianetti, F. (2011).  Motion sickness.  Part I: development of a model for predicting
    motion sickness incidence.  Int. J. Human Factors Modelling and Simulation 2(3), 163-187.  (The UNIPG
    model, with a time constant and gain per axis; its values as in the MIT-licensed parameter file
    ``Kinetose-Modelle/Modell_Barccesi/ParameterBarccesiUNIPG.m`` of ``Sseidel248/Kinetosis_Optimization``.)
Golding, J.F., Mueller, A.G. and Gresty, M.A. (2001).  A motion sickness maximum around the 0.2 Hz
    frequency range of horizontal translational oscillation.  Aviat. Space Environ. Med. 72(3), 188-192.
Wada, T., Kamiji, N. and Doi, S. (2015).  A mathematical model of motion sickness in 6DOF motion and
    its application to vehicle passengers.  arXiv:1504.05261.
Irmak, T., Pool, D.M. and Happee, R. (2022).  Amplitude and temporal dynamics of motion sickness.  Front. Syst.
    Neurosci. 16, 866503.  (Fast and slow time constants 66.2 s and 502 s, output exponent 0.4: the abstract.)
Kotian, V., Pool, D.M. and Happee, R. (2025).  Personalizing motion sickness models: estimation and statistical
    modeling of individual-specific parameters.  Front. Syst. Neurosci. 19, 1531795.  (Two individual parameters,
    K1 and T1, fit individuals about 1.7 times better than the group model.)
Oman, C.M. (1990).  Motion sickness: a synthesis and evaluation of the sensory conflict theory.  Can. J. Physiol.
    Pharmacol. 68, 294-303.  (The accumulation of conflict in a fast and a slow path; not read here.)
Newman, M.C. et al. (2009).  J Neurophysiol 102(4), 2232-2244, Table 4 (canal time constants of the
    observer model, quoted for comparison only).

Axes and signs
--------------
Head axes x forward, y left, z up (right-handed, as in the rest of ``ehm``).  The input
``gia_mps2`` is the gravito-inertial acceleration (specific force) ``f = a - g`` in head axes, where
``a`` is the head's linear acceleration and ``g`` the gravitational acceleration vector (pointing
down).  A person sitting upright at rest therefore has ``f = (0, 0, +9.81)`` m/s^2.  ``omega_radps``
is the head's angular velocity in head axes.  A vector fixed in the world, seen in head axes, changes
as ``dx/dt = -omega x x``.  All verticals in this module point *up* and are in m/s^2.

Model (all vectors in head axes)
--------------------------------
Sense organs::

    otolith        f_s = f                                   (unity)
    canals         w_s = S(s) w,   S(s) = td s / (td s + 1) * ta s / (ta s + 1)
    sensed vertical    dv_s/dt = -w_s x v_s + (f_s - v_s) / tau        (Bos and Bles 2002)

Internal model (copies of the organs, driven by efference copies ``K_a a`` and ``K_w w`` and
corrected by the conflicts ``da = f_s - f^_s``, ``dw = w_s - w^_s``, ``dv = v_s - v^_s``)::

    w^  = K_w w + K_wc dw                 (angular velocity estimate)
    a^  = K_a a + K_ac da                 (linear acceleration estimate)
    du^/dt = -w^ x u^ + K_vc dv           (estimate of the gravity reaction, "up")
    f^_s = a^ + u^,   w^_s = S(s) w^
    dv^/dt = -w^_s x v^ + (f^_s - v^) / tau      (the subjective vertical v^_s)

``a = f - u`` uses the true gravity reaction ``u``, which turns with the head (``du/dt = -w x u``)
from ``u = f`` at the first sample: the head is taken to be at rest, and every internal state
adapted, at ``time_s[0]``.  The two static feedbacks are solved in closed form, so no algebraic loop
remains: ``w^ = (K_w + K_wc S) / (1 + K_wc S) w`` and ``a^ = (K_a a + K_ac (f - u^)) / (1 + K_ac)``.

Sickness::

    c    = v^ - v_s                    (conflict, reported as subjective minus sensed vertical)
    |c|  = |(g_h c_x, g_h c_y, c_z)|   (g_h: horizontal_conflict_gain, 1 by default)
    h    = P (|c|/b)^n / (1 + (|c|/b)^n)                  (Hill function)
    MSI  = h / (tau_I s + 1)^2                            (second-order lag, unit DC gain)

For motion without rotation the model is linear and the conflict per axis is a band-pass of the
acceleration, ``|c/a| = (1 - K_a) w / ((1 + K_ac) |K_vc/(1 + K_ac) - tau w^2 + j w|)``, which peaks at
``sqrt(K_vc / ((1 + K_ac) tau))``; vertically (z) that is 1.29 rad/s = 0.21 Hz with the default values, where
O'Hanlon and McCauley's seasickness data peak (reproduced by Bos and Bles 1998).

Horizontal axes
---------------
``tau`` and ``K_vc`` are set per head axis: the vertical values above on z, the horizontal ones
(``horizontal_time_constant_s``, ``k_vc_horizontal_per_s``) on x and y.  Why: with one value for every axis
(as in Kamiji et al. 2007) the model is isotropic in translation, and its band-pass is narrow (damping ratio
``1 / (2 sqrt(tau K_vc / (1 + K_ac)))`` = 0.19, a conflict amplitude 4.2 times as large at 0.2 Hz as at 0.1 Hz),
which the Hill function (square law below b) turns into ten times less sickness at 0.1 and 0.4 Hz than at
0.2 Hz.  That fits McCauley's vertical data, on which the parameters rest, but not horizontal oscillation:
Golding, Mueller and Gresty (2001) found moderate nausea under fore-aft oscillation at 1.0 m/s^2 peak after a
mean 18.0, 11.2 and 20.2 min at 0.1, 0.2 and 0.4 Hz, 1.6-1.8 times as long off the peak, not ten times less
sickness.  The UNIPG model (Braccesi and Cianetti 2011) has its own time constant and loop gain per axis:
2.4 s and 3.36 1/s vertically (close to this model's 2 s and 5 / 1.5 = 3.33 1/s), 0.6 s and 0.84 1/s on both
horizontal axes (values as in the MIT-licensed parameter file of ``Sseidel248/Kinetosis_Optimization``).  Its
per-axis structure is the one above with loop gain ``K_vc / (1 + K_ac)``, so the horizontal axes here take
``tau`` = 0.6 s and ``K_vc`` = 0.84 (1 + K_ac) = 1.26 1/s: the peak stays near 0.19 Hz, the damping ratio is
0.70.  Fore-aft or lateral at 1.0 m/s^2 peak then reaches the MSI that 0.2 Hz reaches after 11 min after 14.6
min at 0.1 Hz and 16.4 min at 0.4 Hz (1.33 and 1.49 times as long; before: never within 30 min), and 0.2 Hz
stays the most provocative; vertical oscillation is untouched (tested against the isotropic model to 1e-12).
The UNIPG model also scales horizontal acceleration by 1.414 before its filters (``horizontal_conflict_gain``
here, default 1): with it the 0.1 Hz case takes only 1.24 times as long as 0.2 Hz, below Golding's figure, so
it is not adopted.

Where the literature differs
----------------------------
* The placement of the feedback gains above is this module's own formulation of the block diagram
  of Kamiji et al. (2007); its frequency response peaks near 0.2 Hz, as the papers report.
* Default values are attributed to Kamiji et al. (2007), as used by Wada et al. (2015), but could
  not be checked against the original table here.  They were cross-checked against two public
  re-implementations.  A Simulink set for the visual-vertical extension by Wada's group has
  K_a = 0.1, K_wc = 10, K_ac = 0.5, tau = 2 s, td = 7 s, ta = 190 s, b = 0.5 m/s^2,
  tau_I = 720 s, P = 85 %, splits the vertical feedback into a vestibular 2.5 and a visual 2.5
  (hence K_vc = 5 here for the vestibular-only model) and uses K_w = 0.1.  A set labelled as
  Kamiji et al. (2007) lists K_w = 0.9, K_ac = 1.2, K_vc = 6, K_wc = 4, tau = 0.1 s, which in the
  structure above would put the sickness peak near 0.8 Hz, not 0.2 Hz.  K_w = 0.8 is the value
  usually quoted for Kamiji et al. (2007); it is an assumption here, and it matters only when the
  head rotates.
* Bos and Bles (1998) are quoted as fitting vertical-motion seasickness with b = 0.7 m/s^2 in their
  one-dimensional model (not checked against the paper here); this module keeps b = 0.5 m/s^2 of
  the 6-DOF parameter set, whose gains were identified with it.  Set
  ``SvcParameters(hill_b_mps2=0.7)`` for the 1998 value.
* The canal cupula time constant is 7 s with a 190 s adaptation stage in the Kamiji line; other
  observer models use 5.7 s and 80 s (Newman et al. 2009, Table 4).

MISC
----
Beside the MSI, the conflict magnitude drives an accumulation model that predicts a rating on the misery scale
(MISC, 0-10), what experiments record (:class:`ehm.MiscParameters`: Oman's fast and slow paths with the group time
constants and output exponent of Irmak, Pool and Happee 2022, the gain fitted in ehm to Golding et al. 2001).
:func:`fit_misc` fits one person's K1 and T1 to their ratings (the individual model of Kotian, Pool and Happee
2025), with standard errors; :func:`ehm.read_sickness_params` reads the file ``ehm fit-sickness`` writes.

Numerics
--------
The linear angular-velocity paths (canals and the internal angular-velocity loop) and the MSI lag
are discretised exactly for a piecewise-linear input (``scipy.signal.cont2discrete``, first-order
hold).  The remaining states (sensed vertical, internal gravity reaction, subjective vertical) form
a linear system whose matrix varies with the angular velocities; it is advanced with the classical
fourth-order Runge-Kutta scheme, written as one affine map per sample interval (inputs linearly
interpolated at the mid-step), and the true gravity reaction is turned exactly (Rodrigues) so that
its length is kept.  The sample interval must resolve the model: at most 0.5 rad of rotation and
0.5 times the fastest linear time scale per sample.

A long record can be fed in pieces (:class:`SicknessAccumulator`): the filters' states, the last sample
of every path and the nine vertical states are carried from piece to piece, so the pieces take the same
steps as the whole record (equal to round-off, tested to 1e-10) in memory set by the piece;
:func:`subjective_vertical_conflict` is the whole record as one piece.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from pathlib import Path

import numpy as np
from scipy import signal

from ..errors import InputError, checked, checked_class

__all__ = ["SvcParameters", "MiscParameters", "SicknessResult", "SicknessTrace", "SicknessAccumulator",
           "subjective_vertical_conflict", "hill_percent", "misc_rating"]

_MAX_STEP_RAD = 0.5  # largest accepted (rate x sample interval), rad
_CHUNK = 2048  # samples per batch of step maps (memory: about 10 arrays of _CHUNK x 9 x 9 floats, 13 MB)


@dataclass(frozen=True)
class SvcParameters:
    """Parameters of the six-degree-of-freedom SVC model (defaults: Kamiji et al. 2007).

    Attributes
    ----------
    scc_cupula_time_constant_s : float
        Canal cupula time constant td [s].  7 s: Kamiji et al. (2007); 5.7 s in other observer
        models (Newman et al. 2009, Table 4).
    scc_adaptation_time_constant_s : float
        Canal adaptation time constant ta [s].  190 s: Kamiji et al. (2007).
    vertical_time_constant_s : float
        Time constant tau [s] of the low-pass filter that extracts the vertical from the GIA in the
        otolith-canal interaction.  2 s: Kamiji et al. (2007).
    k_a : float
        Gain of the efference copy of linear acceleration into the internal model [-].  0.1:
        Kamiji et al. (2007).
    k_omega : float
        Gain of the efference copy of angular velocity into the internal model [-].  0.8: the value
        usually quoted for Kamiji et al. (2007), not confirmed here (0.1 and 0.9 also appear; see
        the module docstring).  It acts only when the head rotates.
    k_ac : float
        Feedback gain of the otolith (GIA) conflict on the internal acceleration [-].  0.5:
        Kamiji et al. (2007).
    k_omega_c : float
        Feedback gain of the canal conflict on the internal angular velocity [-].  10:
        Kamiji et al. (2007).
    k_vc_per_s : float
        Feedback gain of the vertical conflict on the internal gravity estimate [1/s].  5:
        Kamiji et al. (2007) (split 2.5 + 2.5 between vestibular and visual verticals in the
        later visual-vertical extension).
    hill_b_mps2 : float
        Conflict at which the Hill function is half its maximum, b [m/s^2].  0.5: Kamiji et al.
        (2007); Bos and Bles (1998) are quoted with 0.7 for vertical motion.
    hill_n : float
        Hill exponent n [-].  2: Bos and Bles (1998), Kamiji et al. (2007).
    msi_max_percent : float
        Asymptotic incidence P [%], the Hill function's maximum.  85 %: Bos and Bles (1998)
        (seasickness data of O'Hanlon and McCauley), kept by Kamiji et al. (2007).
    msi_time_constant_s : float
        Time constant tau_I [s] of the second-order lag (1 / (tau_I s + 1)^2) from Hill output to
        MSI.  720 s: Bos and Bles (1998), Kamiji et al. (2007).
    horizontal_time_constant_s : float
        ``tau`` of the head's x and y axes [s] (``vertical_time_constant_s`` is z's).  0.6 s: the UNIPG
        model's horizontal time constant (Braccesi and Cianetti 2011).
    k_vc_horizontal_per_s : float
        ``K_vc`` of the head's x and y axes [1/s] (``k_vc_per_s`` is z's).  1.26 1/s: the UNIPG model's
        horizontal loop gain 0.84 1/s (Braccesi and Cianetti 2011) times ``1 + k_ac``, this structure's loop
        gain being ``K_vc / (1 + K_ac)``.
    horizontal_conflict_gain : float
        Weight of the conflict's x and y components in the Hill function's argument [-].  1 (the UNIPG model
        has 1.414; see "Horizontal axes" in the module docstring for why it is not the default).
    """

    scc_cupula_time_constant_s: float = 7.0  # Kamiji et al. 2007 (5.7 s: Newman et al. 2009)
    scc_adaptation_time_constant_s: float = 190.0  # Kamiji et al. 2007 (80 s: Newman et al. 2009)
    vertical_time_constant_s: float = 2.0  # Kamiji et al. 2007
    k_a: float = 0.1  # Kamiji et al. 2007
    k_omega: float = 0.8  # usually quoted for Kamiji et al. 2007; assumption (see module docstring)
    k_ac: float = 0.5  # Kamiji et al. 2007
    k_omega_c: float = 10.0  # Kamiji et al. 2007
    k_vc_per_s: float = 5.0  # Kamiji et al. 2007 (2.5 vestibular + 2.5 visual in the visual extension)
    hill_b_mps2: float = 0.5  # Kamiji et al. 2007 (0.7 quoted for Bos and Bles 1998)
    hill_n: float = 2.0  # Bos and Bles 1998; Kamiji et al. 2007
    msi_max_percent: float = 85.0  # Bos and Bles 1998; Kamiji et al. 2007
    msi_time_constant_s: float = 720.0  # Bos and Bles 1998; Kamiji et al. 2007
    horizontal_time_constant_s: float = 0.6  # UNIPG model, Braccesi and Cianetti 2011 (x and y)
    k_vc_horizontal_per_s: float = 1.26  # UNIPG horizontal loop gain 0.84 1/s times (1 + k_ac)
    horizontal_conflict_gain: float = 1.0  # 1.414 in the UNIPG model; not adopted (see the module docstring)

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
                raise InputError(f"SvcParameters.{f.name} must be a number, got {value!r}.")
            if not np.isfinite(value):
                raise InputError(f"SvcParameters.{f.name} must be finite, got {value!r}.")
        positive = ("scc_cupula_time_constant_s", "scc_adaptation_time_constant_s", "vertical_time_constant_s",
                    "hill_b_mps2", "hill_n", "msi_time_constant_s", "horizontal_time_constant_s")
        for name in positive:
            if getattr(self, name) <= 0:
                raise InputError(f"SvcParameters.{name} must be positive, got {getattr(self, name)!r}.")
        for name in ("k_a", "k_omega", "k_ac", "k_omega_c", "k_vc_per_s", "k_vc_horizontal_per_s",
                     "horizontal_conflict_gain"):
            if getattr(self, name) < 0:
                raise InputError(f"SvcParameters.{name} must not be negative, got {getattr(self, name)!r}.")
        if not 0 < self.msi_max_percent <= 100:
            raise InputError(f"SvcParameters.msi_max_percent must lie in (0, 100] %, got {self.msi_max_percent!r}.")


MISC_MAX = 10.0  #: top of the MISC scale (vomiting)


@checked_class
@dataclass(frozen=True)
class MiscParameters:
    """Parameters of the accumulation model that turns the conflict into a MISC rating (0-10).

    ``y = K1 |c| / (T1 s + 1)^2 + K2 |c| / (T2 s + 1)^2``, ``MISC = min(y^p, 10)``: a fast and a slow path (the
    accumulation model of Oman 1990 with the output power law of Irmak et al. 2022), fed the conflict magnitude
    of the SVC model (as in Kotian, Pool and Happee 2025, whose individual model frees K1 and T1 alone).
    The defaults are a group's (see the attributes); :func:`ehm.fit_sickness` gives a
    person's K1 and T1.

    Attributes
    ----------
    fast_gain : float
        K1 [(m/s^2)^-1]: 246, fitted in ehm so that fore-aft oscillation at 0.2 Hz, 1.0 m/s^2 peak reaches
        MISC 7 ("medium nausea") after 11.2 min, the mean time to moderate nausea of Golding, Mueller and Gresty
        (2001) (12 susceptible people: the group is a susceptible one), with K2 = K1 (an assumption: the
        published group gains could not be read here).
    fast_time_constant_s : float
        T1 [s]: 66.2 s, the group's fast time constant of Irmak, Pool and Happee (2022).
    slow_gain : float
        K2 [(m/s^2)^-1]: equal to K1 (assumption, see ``fast_gain``).
    slow_time_constant_s : float
        T2 [s]: 502 s, the group's slow time constant of Irmak, Pool and Happee (2022).
    exponent : float
        p [-]: 0.4, the output power law that described MISC better than Oman's 2 (Irmak, Pool and Happee 2022).
    """

    fast_gain: float = 246.0  # fitted in ehm to Golding et al. 2001's 11.2 min at 0.2 Hz (benchmarks/sickness_misc.py)
    fast_time_constant_s: float = 66.2  # Irmak, Pool and Happee 2022 (group)
    slow_gain: float = 246.0  # = fast_gain (assumption)
    slow_time_constant_s: float = 502.0  # Irmak, Pool and Happee 2022 (group)
    exponent: float = 0.4  # Irmak, Pool and Happee 2022

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
                    or not np.isfinite(value):
                raise InputError(f"MiscParameters.{f.name} must be a finite number, got {value!r}.")
            if f.name.endswith("_gain") and value < 0:
                raise InputError(f"MiscParameters.{f.name} must not be negative, got {value!r}.")
            if not f.name.endswith("_gain") and value <= 0:
                raise InputError(f"MiscParameters.{f.name} must be positive, got {value!r}.")


def _misc_params(params) -> MiscParameters:
    p = MiscParameters() if params is None else params
    if not isinstance(p, MiscParameters):
        raise InputError(f"misc_params must be a MiscParameters instance or None, got {type(params).__name__}.")
    return p


def misc_filters(params: MiscParameters | None, dt_s: float) -> tuple:
    """Discrete (b, a) of the accumulation model's fast and slow paths (gain included) at the interval ``dt_s``.

    Each path's ``1/(T s + 1)^2`` is two first-order lags in cascade, each exact for an input linear between samples
    (first-order hold): ``y[n+1] = e y[n] + u[n+1] - e u[n] - (T/h)(1 - e)(u[n+1] - u[n])``, ``e = exp(-h/T)``;
    written out, not by ``scipy.signal.cont2discrete``, which takes a thousand times as long (the fit calls this
    for every candidate)."""
    p = _misc_params(params)
    out = []
    for gain, tau in ((p.fast_gain, p.fast_time_constant_s), (p.slow_gain, p.slow_time_constant_s)):
        e = float(np.exp(-dt_s / tau))
        k = tau / dt_s * (1.0 - e)  # tau/h (1 - e), 1 - h/(2 tau) + ... for h << tau
        b1, a1 = np.array([1.0 - k, k - e]), np.array([1.0, -e])
        out.append((gain * np.convolve(b1, b1), np.convolve(a1, a1)))
    return tuple(out)


def misc_rating(conflict_magnitude_mps2, dt_s: float, params: MiscParameters | None = None) -> np.ndarray:
    """The MISC rating (0-10) over time from the conflict magnitude [m/s^2] sampled every ``dt_s`` [s] from rest
    (the accumulation model of :class:`ehm.MiscParameters`)."""
    c = np.asarray(conflict_magnitude_mps2, dtype=float)
    p = _misc_params(params)
    y = sum(signal.lfilter(b, a, c) for b, a in misc_filters(p, dt_s))
    return misc_of_accumulated(y, p)


def misc_of_accumulated(y: np.ndarray, params: MiscParameters | None = None) -> np.ndarray:
    """``min(y^p, 10)`` of the summed paths (round-off below zero taken as zero)."""
    p = _misc_params(params)
    return np.minimum(np.maximum(y, 0.0) ** p.exponent, MISC_MAX)


@dataclass(frozen=True)
class SicknessResult:
    """Time histories of the SVC model.

    Attributes
    ----------
    time_s : (n,) array
        Sample times [s].
    msi_percent : (n,) array
        Motion sickness incidence [%] (predicted share of people who would vomit).
    conflict_mps2 : (n, 3) array
        Vertical conflict vector, subjective vertical minus sensed vertical, head axes [m/s^2].
    subjective_vertical : (n, 3) array
        Subjective vertical (internal model's estimate of the vertical, pointing up), head axes
        [m/s^2].
    sensed_vertical_mps2 : (n, 3) array
        Vertical sensed by the otolith-canal interaction, head axes [m/s^2].
    misc : (n,) array
        Predicted MISC rating (0-10) of the accumulation model (:class:`ehm.MiscParameters`).
    """

    time_s: np.ndarray
    msi_percent: np.ndarray
    conflict_mps2: np.ndarray
    subjective_vertical: np.ndarray
    sensed_vertical_mps2: np.ndarray
    misc: np.ndarray

    @property
    def final_msi_percent(self) -> float:
        """MSI at the last sample [%]."""
        return float(self.msi_percent[-1])

    @property
    def final_misc(self) -> float:
        """MISC rating at the last sample (0-10)."""
        return float(self.misc[-1])

    @property
    def conflict_magnitude_mps2(self) -> np.ndarray:
        """``|conflict|`` per sample [m/s^2]: the Hill function's argument when ``horizontal_conflict_gain`` is 1
        (the default)."""
        return np.linalg.norm(self.conflict_mps2, axis=1)


def _params(params) -> SvcParameters:
    p = SvcParameters() if params is None else params
    if not isinstance(p, SvcParameters):
        raise InputError(f"params must be an SvcParameters instance or None, got {type(params).__name__}.")
    return p


def hill_percent(conflict_magnitude_mps2: np.ndarray | float, params: SvcParameters | None = None) -> np.ndarray:
    """Hill function of the conflict magnitude, scaled to the asymptotic incidence [%].

    ``P (|c|/b)^n / (1 + (|c|/b)^n)``; its time mean under steady excitation is the MSI that the
    second-order lag approaches.
    """
    p = _params(params)
    x = (np.abs(np.asarray(conflict_magnitude_mps2, dtype=float)) / p.hill_b_mps2) ** p.hill_n
    return p.msi_max_percent * x / (1.0 + x)


def subjective_vertical_conflict(time_s, gia_mps2, omega_radps, params: SvcParameters | None = None,
                                 misc_params: MiscParameters | None = None) -> SicknessResult:
    """Run the six-degree-of-freedom SVC model and predict the motion sickness incidence.

    The whole record in one piece; :class:`SicknessAccumulator` gives the same numbers for a record fed
    in pieces, in memory that does not grow with the record.

    Parameters
    ----------
    time_s : (n,) array_like
        Uniformly sampled, increasing times [s] (steps equal within 1 %), n >= 2.
    gia_mps2 : (n, 3) array_like
        Gravito-inertial acceleration ``f = a - g`` at the head in head axes [m/s^2]
        (upright at rest: (0, 0, +9.81)).
    omega_radps : (n, 3) array_like
        Head angular velocity in head axes [rad/s].
    params : SvcParameters, optional
        Model parameters; defaults to Kamiji et al. (2007).
    misc_params : MiscParameters, optional
        The accumulation model's parameters of the MISC rating (default: the group's).

    Returns
    -------
    SicknessResult

    Raises
    ------
    InputError
        For malformed, non-finite or non-uniformly sampled inputs, or a sample interval too coarse
        for the model's dynamics.

    Notes
    -----
    The head is taken to be at rest, with every state adapted, at ``time_s[0]``: the true and
    internal gravity reactions and both verticals start equal to ``gia_mps2[0]``.  The model runs
    at the mean sample interval; ``time_s`` is returned as given.
    """
    p = _params(params)
    t, f, w, h = _check_inputs(time_s, gia_mps2, omega_radps)
    model = SicknessAccumulator(h, p, start_s=float(t[0]), keep_trace=False, misc_params=misc_params,
                                _interval_name="time_s")
    return replace(model._advance(f, w), time_s=t)


@dataclass(frozen=True)
class SicknessTrace:
    """What a streamed run of the SVC model keeps: the MSI and the conflict magnitude over time.

    Attributes
    ----------
    time_s : (n,) array
        Sample times [s].
    msi_percent : (n,) array
        Motion sickness incidence [%].
    conflict_magnitude_mps2 : (n,) array
        ``|subjective minus sensed vertical|`` [m/s^2], its horizontal components weighted by
        ``horizontal_conflict_gain``: the argument of the Hill function.
    misc : (n,) array or None
        Predicted MISC rating (0-10) of the accumulation model; None in a trace read from a run folder written
        before ehm predicted it.
    """

    time_s: np.ndarray
    msi_percent: np.ndarray
    conflict_magnitude_mps2: np.ndarray
    misc: np.ndarray | None = None

    @property
    def final_msi_percent(self) -> float:
        """MSI at the last sample [%]."""
        return float(self.msi_percent[-1])

    @property
    def final_misc(self) -> float | None:
        """MISC rating at the last sample (0-10); None without a MISC trace."""
        return None if self.misc is None else float(self.misc[-1])


class SicknessAccumulator:
    """The SVC model of :func:`subjective_vertical_conflict` fed a record piece by piece.

    Every filter and state is carried from one piece to the next, so the pieces give the same time
    histories as the whole record in one run (same arithmetic, per sample), in working memory
    proportional to the piece, not to the record.  What grows with the record is only the kept trace
    (MSI, conflict magnitude and MISC, 24 bytes per sample; ``keep_trace=False`` keeps none of it).

    Parameters
    ----------
    dt_s : float
        Sample interval of the pieces' rows [s]; must resolve the model (see the module docstring).
    params : SvcParameters, optional
        Model parameters; defaults to Kamiji et al. (2007).
    start_s : float
        Time of the first sample [s]; the head is taken to be at rest, every state adapted, there.
    keep_trace : bool
        Keep the MSI, the conflict magnitude and the MISC rating of every sample for :meth:`result`.
    misc_params : MiscParameters, optional
        The accumulation model's parameters of the MISC rating (default: the group's).

    Raises
    ------
    InputError
        For a sample interval that is not a positive number or too coarse for the model's dynamics.
    """

    def __init__(self, dt_s: float, params: SvcParameters | None = None, start_s: float = 0.0,
                 keep_trace: bool = True, misc_params: MiscParameters | None = None, _interval_name: str = "dt_s"):
        self.params = p = _params(params)
        self.misc_params = _misc_params(misc_params)
        self._name = _interval_name
        if isinstance(dt_s, bool) or not isinstance(dt_s, (int, float, np.integer, np.floating)) \
                or not np.isfinite(dt_s) or dt_s <= 0:
            raise InputError(f"dt_s must be a positive number of seconds, got {dt_s!r}.")
        if isinstance(start_s, bool) or not isinstance(start_s, (int, float, np.integer, np.floating)) \
                or not np.isfinite(start_s):
            raise InputError(f"start_s must be a finite number of seconds, got {start_s!r}.")
        self.dt_s = h = float(dt_s)
        self.start_s = float(start_s)
        self._check_linear_rate()
        self._filters = _discrete_filters(p, h)
        self._zi = {k: np.zeros((max(b.size, a.size) - 1, *(() if k == "msi" else (3,))))
                    for k, (b, a) in self._filters.items()}
        self._misc_filters = misc_filters(self.misc_params, h)
        self._misc_zi = [np.zeros(max(b.size, a.size) - 1) for b, a in self._misc_filters]
        self._last = None  # the previous piece's last sample: w, u, w_s, w_hat, w_hat_s, g and the 9 states
        self._keep = bool(keep_trace)
        self._msi: list[np.ndarray] = []
        self._conflict: list[np.ndarray] = []
        self._misc: list[np.ndarray] = []
        #: Samples fed so far.
        self.n_samples = 0
        #: MSI at the latest sample [%] (0 before any sample).
        self.last_msi_percent = 0.0
        #: Largest conflict magnitude so far [m/s^2].
        self.max_conflict_mps2 = 0.0
        #: MISC rating at the latest sample (0 before any sample).
        self.last_misc = 0.0

    def add(self, gia_mps2, omega_radps) -> SicknessResult:
        """Feed the next samples: gravito-inertial acceleration and angular velocity, (m, 3) each, head axes
        [m/s^2, rad/s], at ``dt_s``; returns their time histories.

        A piece that raises leaves the accumulator as it was.
        """
        f = _vectors("gia_mps2", gia_mps2)
        w = _vectors("omega_radps", omega_radps, f.shape[0])
        return self._advance(f, w)

    def result(self) -> SicknessTrace:
        """The kept trace of everything fed so far."""
        if self.n_samples == 0:
            raise InputError("no samples were added.")
        if not self._keep:
            raise InputError("this SicknessAccumulator keeps no trace (keep_trace=False).")
        msi, conflict, misc = (np.concatenate(x) for x in (self._msi, self._conflict, self._misc))
        self._msi, self._conflict, self._misc = [msi], [conflict], [misc]
        return SicknessTrace(time_s=self.start_s + np.arange(self.n_samples) * self.dt_s, msi_percent=msi,
                             conflict_magnitude_mps2=conflict, misc=misc)

    # -- steps of one piece ------------------------------------------------------------------------

    def _check_linear_rate(self) -> None:
        p, h = self.params, self.dt_s
        tau, kvc = axis_time_constants_s(p), axis_feedback_gains_per_s(p)
        # fastest eigenvalue magnitude of the linear part, over the axes: the low-pass 1/tau and the
        # vertical-feedback loop s^2 + s/tau + K_vc / ((1 + K_ac) tau) = 0
        linear_rate = float(np.max(np.maximum(1.0 / tau, np.sqrt(kvc / ((1.0 + p.k_ac) * tau)))))
        if h * linear_rate > _MAX_STEP_RAD:
            raise InputError(f"{self._name} has a sample interval of {h:g} s, too coarse for the model's fastest time "
                             f"scale of {1.0 / linear_rate:g} s; sample at {_MAX_STEP_RAD / linear_rate:g} s or finer.")

    def _check_rotation_rate(self, *rates: np.ndarray) -> None:
        h = self.dt_s
        rot_rate = max(float(np.max(np.linalg.norm(a, axis=1))) for a in rates)
        if h * rot_rate > _MAX_STEP_RAD:
            raise InputError(f"{self._name} has a sample interval of {h:g} s, too coarse for angular velocities up "
                             f"to {rot_rate:g} rad/s; sample at {_MAX_STEP_RAD / rot_rate:g} s or finer.")

    def _angular_paths(self, w: np.ndarray):
        """Canal and internal angular-velocity paths of the piece, with the filter states after it."""
        (b_scc, a_scc), (b_int, a_int) = self._filters["scc"], self._filters["int"]
        zi = self._zi
        if self._last is None:  # the first piece: every filter in the steady state for the first sample
            w_hat0 = w[0] * (np.sum(b_int) / np.sum(a_int))  # the internal loop's steady output for w[0]
            zi = {"scc": _steady(b_scc, a_scc, w[0]), "int": _steady(b_int, a_int, w[0]),
                  "scc_hat": _steady(b_scc, a_scc, w_hat0)}
        w_s, zi_scc = signal.lfilter(b_scc, a_scc, w, axis=0, zi=zi["scc"])
        w_hat, zi_int = signal.lfilter(b_int, a_int, w, axis=0, zi=zi["int"])
        w_hat_s, zi_hat = signal.lfilter(b_scc, a_scc, w_hat, axis=0, zi=zi["scc_hat"])
        return (w_s, w_hat, w_hat_s), {"scc": zi_scc, "int": zi_int, "scc_hat": zi_hat}

    def _advance(self, f: np.ndarray, w: np.ndarray) -> SicknessResult:
        """One checked piece through the model; the state is committed only when nothing raised."""
        m, p, h = f.shape[0], self.params, self.dt_s
        if m == 0:
            return _empty_result()
        (w_s, w_hat, w_hat_s), zi = self._angular_paths(w)
        self._check_rotation_rate(w, w_s, w_hat, w_hat_s)
        last = self._last
        if last is None:  # the first sample: at rest, adapted
            u = _turn_with_head(f[0], w, h)
            x0 = np.concatenate([f[0], u[0], f[0]])
            states = _vertical_states(p, f, u, w_s, w_hat, w_hat_s, h, x0)
        else:  # steps from the previous piece's last sample
            ext = [np.concatenate([last[k][None], x]) for k, x in (("f", f), ("w", w), ("w_s", w_s),
                                                                   ("w_hat", w_hat), ("w_hat_s", w_hat_s))]
            u = _turn_with_head(last["u"], ext[1], h)
            states = _vertical_states(p, ext[0], u, ext[2], ext[3], ext[4], h, last["x"])[1:]
            u = u[1:]
        vs, vh = states[:, 0:3], states[:, 6:9]
        conflict = vh - vs
        magnitude = np.linalg.norm(conflict * axis_conflict_weights(p), axis=1)
        b_msi, a_msi = self._filters["msi"]
        msi, zi_msi = signal.lfilter(b_msi, a_msi, hill_percent(magnitude, p), zi=self._zi["msi"])
        # Round-off of the recursive filter must not turn a zero or a bounded input into a value outside
        # the lag's exact range [0, P].
        msi = np.clip(msi, 0.0, p.msi_max_percent)
        paths = [signal.lfilter(b, a, magnitude, zi=z) for (b, a), z in zip(self._misc_filters, self._misc_zi)]
        misc = misc_of_accumulated(paths[0][0] + paths[1][0], self.misc_params)
        # commit
        self._misc_zi = [path[1] for path in paths]
        self._zi = {**zi, "msi": zi_msi}
        self._last = {"f": f[-1].copy(), "w": w[-1].copy(), "w_s": w_s[-1].copy(), "w_hat": w_hat[-1].copy(),
                      "w_hat_s": w_hat_s[-1].copy(), "u": u[-1].copy(), "x": states[-1].copy()}
        t = self.start_s + (self.n_samples + np.arange(m)) * h
        self.n_samples += m
        self.last_msi_percent = float(msi[-1])
        self.max_conflict_mps2 = max(self.max_conflict_mps2, float(magnitude.max()))
        self.last_misc = float(misc[-1])
        if self._keep:
            self._msi.append(msi.copy())
            self._conflict.append(magnitude.copy())
            self._misc.append(misc.copy())
        return SicknessResult(time_s=t, msi_percent=msi, conflict_mps2=conflict, subjective_vertical=vh,
                              sensed_vertical_mps2=vs, misc=misc)


# ----------------------------------------------------------------------------------------------------
# helpers


def axis_time_constants_s(params: SvcParameters | None = None) -> np.ndarray:
    """The otolith-canal interaction's time constant per head axis x, y, z [s]: the horizontal one on x and y,
    the vertical one on z."""
    p = _params(params)
    return np.array([p.horizontal_time_constant_s, p.horizontal_time_constant_s, p.vertical_time_constant_s])


def axis_feedback_gains_per_s(params: SvcParameters | None = None) -> np.ndarray:
    """The vertical-conflict feedback gain K_vc per head axis x, y, z [1/s]."""
    p = _params(params)
    return np.array([p.k_vc_horizontal_per_s, p.k_vc_horizontal_per_s, p.k_vc_per_s])


def axis_conflict_weights(params: SvcParameters | None = None) -> np.ndarray:
    """The weight of the conflict's x, y, z components in the Hill function's argument [-]."""
    p = _params(params)
    return np.array([p.horizontal_conflict_gain, p.horizontal_conflict_gain, 1.0])


def _check_inputs(time_s, gia_mps2, omega_radps):
    try:
        t = np.asarray(time_s, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"time_s must be a 1-D array of numbers, got {type(time_s).__name__} "
                         f"{str(time_s)[:40]!r}.") from None
    if t.ndim != 1 or t.size < 2:
        raise InputError(f"time_s must be a 1-D array of at least 2 samples, got shape {t.shape}.")
    if not np.all(np.isfinite(t)):
        k = int(np.argmin(np.isfinite(t)))
        raise InputError(f"time_s must be finite, but sample {k} is {t[k]}.")
    dt = np.diff(t)
    if np.any(dt <= 0):
        k = int(np.argmax(dt <= 0))
        raise InputError(f"time_s must increase, but sample {k + 1} ({t[k + 1]:g} s) does not exceed "
                         f"sample {k} ({t[k]:g} s).")
    h = float((t[-1] - t[0]) / (t.size - 1))
    dev = float(np.max(np.abs(dt - h)) / h)
    if dev > 0.01:
        raise InputError(f"time_s must be uniformly sampled within 1 %, but a step deviates by {100 * dev:.3g} % "
                         f"from the mean step of {h:g} s.")
    return (t, _vectors("gia_mps2", gia_mps2, t.size, "time_s"), _vectors("omega_radps", omega_radps, t.size, "time_s"),
            h)


def _vectors(name: str, value, n: int | None = None, against: str = "gia_mps2") -> np.ndarray:
    """An (n, 3) array of finite numbers (any n when None), or an InputError naming the argument."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be an (n, 3) array of numbers, got {type(value).__name__} "
                         f"{str(value)[:40]!r}.") from None
    if n is not None and a.shape != (n, 3):
        raise InputError(f"{name} must have shape ({n}, 3) to match {against}, got {a.shape}.")
    if a.ndim != 2 or a.shape[1] != 3:
        raise InputError(f"{name} must have shape (n, 3), got {a.shape}.")
    if not np.all(np.isfinite(a)):
        k = int(np.argmin(np.all(np.isfinite(a), axis=1)))
        raise InputError(f"{name} must be finite, but row {k} is {a[k].tolist()}.")
    return a


def _discrete_filters(p: SvcParameters, h: float) -> dict:
    """Discrete (b, a) of the linear paths at the interval h: canals ("scc", also applied to w^ as "scc_hat"),
    the internal angular-velocity loop ("int") and the MSI lag ("msi").

    Exact for an input that is linear between samples (first-order hold).  The angular-velocity filters start
    in the steady state for the first sample (adapted to it, as the vertical states are), so a record that
    starts turning has no start-up step; the MSI lag starts from zero (a dose: its input, the Hill output of
    the first sample's conflict, is zero since the verticals start equal).
    """
    td, ta = p.scc_cupula_time_constant_s, p.scc_adaptation_time_constant_s
    scc_num = np.array([td * ta, 0.0, 0.0])
    scc_den = np.polymul([td, 1.0], [ta, 1.0])
    # w^ = K_w w + K_wc (w_s - S w^)  =>  w^ = (K_w + K_wc S) / (1 + K_wc S) w
    int_num = np.polyadd(p.k_omega * scc_den, p.k_omega_c * scc_num)
    int_den = np.polyadd(scc_den, p.k_omega_c * scc_num)
    tau_i = p.msi_time_constant_s
    out = {}
    for key, (num, den) in {"scc": (scc_num, scc_den), "int": (int_num, int_den),
                            "msi": (np.array([1.0]), np.polymul([tau_i, 1.0], [tau_i, 1.0]))}.items():
        numd, dend, _ = signal.cont2discrete((np.atleast_1d(num), np.atleast_1d(den)), h, method="foh")
        out[key] = (np.ravel(numd), np.asarray(dend, dtype=float))
    out["scc_hat"] = out["scc"]
    return out


def _steady(b: np.ndarray, a: np.ndarray, first: np.ndarray) -> np.ndarray:
    """lfilter state (order, 3) of the filter (b, a) in the steady state for the constant input ``first`` (3,)."""
    return np.outer(signal.lfilter_zi(b, a), first)


def _empty_result() -> SicknessResult:
    z1, z3 = np.zeros(0), np.zeros((0, 3))
    return SicknessResult(time_s=z1, msi_percent=z1, conflict_mps2=z3, subjective_vertical=z3, sensed_vertical_mps2=z3,
                          misc=z1)


def _skew(v):
    """(m, 3) vectors -> (m, 3, 3) matrices with skew(v) @ x = v x x."""
    z = np.zeros(v.shape[:-1])
    return np.stack([np.stack([z, -v[..., 2], v[..., 1]], -1),
                     np.stack([v[..., 2], z, -v[..., 0]], -1),
                     np.stack([-v[..., 1], v[..., 0], z], -1)], -2)


def _turn_with_head(u0, w, h):
    """Gravity reaction in head axes: du/dt = -w x u from u0, turned exactly per step (mid-step w)."""
    n = w.shape[0]
    rv = -0.5 * (w[1:] + w[:-1]) * h  # rotation vector of each step
    theta = np.linalg.norm(rv, axis=1)
    small = theta < 1e-8
    th = np.where(small, 1.0, theta)
    s1 = np.where(small, 1.0 - theta**2 / 6.0, np.sin(th) / th)
    s2 = np.where(small, 0.5 - theta**2 / 24.0, (1.0 - np.cos(th)) / th**2)
    k = _skew(rv)
    rot = np.eye(3) + s1[:, None, None] * k + s2[:, None, None] * (k @ k)
    u = np.empty((n, 3))
    u[0] = u0
    x = np.array(u0, dtype=float)
    for i in range(n - 1):
        x = rot[i] @ x
        u[i + 1] = x
    return u


def _vertical_states(p: SvcParameters, f, u, w_s, w_hat, w_hat_s, h, x0):
    """States x = (v_s, u^, v^) at every sample, (n, 9), from x0 at the first, by RK4 written as one affine
    map per step.

    dx/dt = A(t) x + g(t) with
        dv_s/dt = -w_s x v_s + (f - v_s) / tau
        du^/dt  = -w^ x u^ + K_vc (v_s - v^)
        dv^/dt  = -w^_s x v^ + (f^ - v^) / tau,  f^ = (K_a (f - u) + K_ac f + u^) / (1 + K_ac)
    """
    n = f.shape[0]
    rate, kvc = 1.0 / axis_time_constants_s(p), axis_feedback_gains_per_s(p)  # (3,) each: x, y, z of the head
    c = 1.0 / (1.0 + p.k_ac)
    a_lin = np.zeros((9, 9))
    a_lin[0:3, 0:3] = -np.diag(rate)
    a_lin[3:6, 0:3] = np.diag(kvc)
    a_lin[3:6, 6:9] = -np.diag(kvc)
    a_lin[6:9, 3:6] = c * np.diag(rate)
    a_lin[6:9, 6:9] = -np.diag(rate)
    # forcing g = (f / tau, 0, (K_a (f - u) + K_ac f) c / tau), per axis
    g = np.zeros((n, 9))
    g[:, 0:3] = f * rate
    g[:, 6:9] = (p.k_a * (f - u) + p.k_ac * f) * (c * rate)

    def a_of(ws, wh, whs):
        m = ws.shape[0]
        a = np.broadcast_to(a_lin, (m, 9, 9)).copy()
        a[:, 0:3, 0:3] -= _skew(ws)
        a[:, 3:6, 3:6] -= _skew(wh)
        a[:, 6:9, 6:9] -= _skew(whs)
        return a

    x = np.array(x0, dtype=float)
    out = np.empty((n, 9))
    out[0] = x
    eye9 = np.eye(9)
    for start in range(0, n - 1, _CHUNK):
        stop = min(start + _CHUNK, n - 1)  # steps start..stop-1
        i0, i1 = slice(start, stop), slice(start + 1, stop + 1)
        a0 = a_of(w_s[i0], w_hat[i0], w_hat_s[i0])
        a1 = a_of(w_s[i1], w_hat[i1], w_hat_s[i1])
        am = 0.5 * (a0 + a1)  # A is linear in the angular velocities, which are linear in time per step
        g0, g1 = g[i0], g[i1]
        gm = 0.5 * (g0 + g1)
        k1 = a0
        k2 = am + 0.5 * h * (am @ k1)
        k3 = am + 0.5 * h * (am @ k2)
        k4 = a1 + h * (a1 @ k3)
        step = eye9 + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        c1 = g0
        c2 = gm + 0.5 * h * np.einsum("mij,mj->mi", am, c1)
        c3 = gm + 0.5 * h * np.einsum("mij,mj->mi", am, c2)
        c4 = g1 + h * np.einsum("mij,mj->mi", a1, c3)
        shift = (h / 6.0) * (c1 + 2.0 * c2 + 2.0 * c3 + c4)
        for j in range(stop - start):
            x = step[j] @ x + shift[j]
            out[start + j + 1] = x
    return out


# ----------------------------------------------------------------------------------------------------
# a person's MISC parameters: the fit and its file

#: What ``fit_misc`` frees: the individual accumulation model's two parameters (Kotian, Pool and Happee 2025).
FITTED = ("fast_gain", "fast_time_constant_s")
_FIT_BOUNDS = ((1e-6, 1.0), (1e9, 1e5))  #: (lower, upper) of (K1 [(m/s^2)^-1], T1 [s]) in the search
SICKNESS_PARAMS_KIND = "ehm sickness parameters"


@dataclass(frozen=True)
class MiscFit:
    """One person's MISC parameters fitted to their ratings (:func:`fit_misc`).

    Attributes
    ----------
    params : MiscParameters
        The person's parameters: ``fast_gain`` (K1) and ``fast_time_constant_s`` (T1) fitted, the rest as given.
    std : dict
        Standard error of each fitted parameter (name -> value in its unit), from the residuals and the
        Jacobian at the optimum (linearised, ``s^2 (J^T J)^-1``).
    rms_misc : float
        Root mean square of rating minus model at the rating times [MISC].
    rms_misc_group : float
        The same for the group's (the starting) parameters.
    n_ratings : int
        Ratings used.
    time_s, misc_rated, misc_model : (n,) arrays
        The ratings and the fitted model at their times.
    """

    params: MiscParameters
    std: dict
    rms_misc: float
    rms_misc_group: float
    n_ratings: int
    time_s: np.ndarray
    misc_rated: np.ndarray
    misc_model: np.ndarray

    def interval(self, name: str, k: float = 2.0) -> tuple[float, float]:
        """``value -/+ k std`` of a fitted parameter (k = 2: about 95 %)."""
        value = getattr(self.params, name)
        return value - k * self.std[name], value + k * self.std[name]


def fit_misc(conflict_time_s, conflict_magnitude_mps2, rating_time_s, rating_misc,
             params: MiscParameters | None = None) -> MiscFit:
    """Fit a person's K1 (``fast_gain``) and T1 (``fast_time_constant_s``) to their MISC ratings.

    The conflict magnitude is the SVC model's over a drive (uniformly sampled from the drive's start, when the
    person was well: MISC 0); the ratings are the person's MISC at their times within that span.  The model's MISC
    is linearly interpolated at the rating times; the two parameters are searched in log space
    (``scipy.optimize.least_squares``), the others kept at ``params`` (default the group's).

    Raises
    ------
    InputError
        Fewer than 3 ratings, ratings outside 0-10 or the conflict's time span, or a fit that cannot be made.
    """
    from scipy.optimize import least_squares

    p0 = _misc_params(params)
    t = np.asarray(conflict_time_s, dtype=float)
    c = np.asarray(conflict_magnitude_mps2, dtype=float)
    tr = np.asarray(rating_time_s, dtype=float)
    r = np.asarray(rating_misc, dtype=float)
    if t.ndim != 1 or t.size < 2 or c.shape != t.shape or not np.all(np.isfinite(c)):
        raise InputError("fit_misc: give the conflict as two 1-D arrays of equal length (at least 2 samples), "
                         "time_s and |conflict| [m/s^2], finite.")
    if tr.ndim != 1 or tr.shape != r.shape:
        raise InputError("fit_misc: give the ratings as two 1-D arrays of equal length, their times and MISC values.")
    if tr.size < 3:
        raise InputError(f"fit_misc: {tr.size} rating(s); two parameters need at least 3 ratings.")
    if np.any(tr < t[0] - 1e-9) or np.any(tr > t[-1] + 1e-9):
        k = int(np.flatnonzero((tr < t[0] - 1e-9) | (tr > t[-1] + 1e-9))[0])
        raise InputError(f"fit_misc: rating {k} at {tr[k]:g} s lies outside the drive's {t[0]:g}-{t[-1]:g} s.")
    if np.any((r < 0) | (r > MISC_MAX)):
        k = int(np.flatnonzero((r < 0) | (r > MISC_MAX))[0])
        raise InputError(f"fit_misc: rating {k} is MISC {r[k]:g}, outside the scale's 0-10.")
    dt = float((t[-1] - t[0]) / (t.size - 1))

    def model(theta):
        q = replace(p0, fast_gain=float(np.exp(theta[0])), fast_time_constant_s=float(np.exp(theta[1])))
        return np.interp(tr, t, misc_rating(c, dt, q))

    theta0 = np.log([max(p0.fast_gain, 1e-6), p0.fast_time_constant_s])
    group = model(theta0)
    # a few starts over the gain: the power law and the 10 cap make the sum of squares flat far from the data
    best = None
    lower, upper = np.log(_FIT_BOUNDS[0]), np.log(_FIT_BOUNDS[1])
    for shift in (0.0, -2.0, 2.0):
        start = theta0 + np.array([shift, 0.0])
        sol = least_squares(lambda th: model(th) - r, start, method="trf", x_scale=1.0, bounds=(lower, upper))
        if best is None or sol.cost < best.cost:
            best = sol
    residual = best.fun
    dof = max(tr.size - 2, 1)
    s2 = float(residual @ residual) / dof
    jac = best.jac
    try:
        cov_log = s2 * np.linalg.inv(jac.T @ jac)
    except np.linalg.LinAlgError:
        raise InputError("fit_misc: the ratings do not determine K1 and T1 (the model does not change at the "
                         "ratings' times with them); give ratings over the time the person's sickness grew.") from None
    values = np.exp(best.x)
    std_log = np.sqrt(np.maximum(np.diag(cov_log), 0.0))
    fitted = replace(p0, fast_gain=float(values[0]), fast_time_constant_s=float(values[1]))
    # undetermined: pinned on a search bound (within 1 %), or a standard error beyond the value itself
    loose = [name for name, x, lo, hi, sd in zip(FITTED, best.x, lower, upper, std_log)
             if min(x - lo, hi - x) < 0.01 or sd > 1.0]
    if loose:
        from ..errors import EhmWarning, warn

        warn(f"fit_misc: the ratings do not determine {' and '.join(loose)} (on the search bound, K1 "
             f"{_FIT_BOUNDS[0][0]:g}-{_FIT_BOUNDS[1][0]:g} (m/s^2)^-1, T1 {_FIT_BOUNDS[0][1]:g}-{_FIT_BOUNDS[1][1]:g} "
             "s, or a standard error beyond the value): ratings that grow without levelling off fit a path slower "
             "than the drive, so the values are not the person's; rate a longer drive, or use the group's.",
             EhmWarning, stacklevel=2)
    return MiscFit(params=fitted, std={"fast_gain": float(values[0] * std_log[0]),
                                       "fast_time_constant_s": float(values[1] * std_log[1])},
                   rms_misc=float(np.sqrt(np.mean(residual**2))),
                   rms_misc_group=float(np.sqrt(np.mean((group - r) ** 2))), n_ratings=int(tr.size),
                   time_s=tr, misc_rated=r, misc_model=residual + r)


def sickness_params_text(fit: MiscFit, about: dict) -> str:
    """The TOML text of a person's parameter file: ``[misc]`` (every value of the accumulation model, what
    :func:`ehm.read_sickness_params` reads), ``[fit]`` (which were fitted, their standard errors, the rms) and
    ``[about]`` (``about``: where the drive and the ratings came from)."""
    from dataclasses import asdict

    import tomli_w

    doc = {"about": {"kind": SICKNESS_PARAMS_KIND, **{k: str(v) for k, v in about.items()}},
           "misc": asdict(fit.params),
           "fit": {"fitted": list(FITTED), "grade": "fitted to this person's ratings",
                   "source": "K1 and T1 of the individual accumulation model (Kotian, Pool and Happee 2025); "
                             "the other values the group's (ehm.standards.sickness.MiscParameters)",
                   **{f"{k}_std": v for k, v in fit.std.items()},
                   "rms_misc": fit.rms_misc, "rms_misc_group": fit.rms_misc_group, "n_ratings": fit.n_ratings}}
    return ("# One person's MISC accumulation model, written by 'ehm fit-sickness'; read by\n"
            "# 'ehm assess --sickness-params FILE', batch studies and ehm.read_sickness_params.\n" + tomli_w.dumps(doc))


@checked
def read_sickness_params(path: str | Path) -> MiscParameters:
    """A person's MISC parameters from the file ``ehm fit-sickness`` wrote (``[misc]``; a value left out is the
    group's).  Anything else is refused in one sentence naming the file and what to do."""
    import tomllib

    path = Path(path)
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"{path}: no such sickness parameter file (--sickness-params, sickness_params=); "
                         "'ehm fit-sickness' writes one.") from None
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise InputError(f"{path}: not a sickness parameter file ehm can read ({type(exc).__name__}: {exc}); "
                         "'ehm fit-sickness' writes one.") from None
    misc = doc.get("misc")
    if not isinstance(misc, dict):
        raise InputError(f"{path}: no [misc] table of MISC parameters (--sickness-params, sickness_params=); "
                         "'ehm fit-sickness' writes one.")
    known = {f.name for f in fields(MiscParameters)}
    unknown = sorted(set(misc) - known)
    if unknown:
        raise InputError(f"{path}: [misc] has no parameter {unknown[0]!r}; it knows {', '.join(sorted(known))}.")
    try:
        return MiscParameters(**misc)
    except InputError as exc:
        raise InputError(f"{path}: {str(exc).rstrip('.')}; correct it, or write the file again with 'ehm "
                         "fit-sickness' (--sickness-params, sickness_params=).") from None
