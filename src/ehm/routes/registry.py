"""The routes by name: what :meth:`ehm.SeatedHuman.stream` (and through it :func:`ehm.assess`) asks for.

=============  =====================================================================  ===========================
name           route                                                                  options
=============  =====================================================================  ===========================
``nonlinear``  the MuJoCo model stepped throughout (:mod:`ehm.routes.nonlinear`)       none
``linear``     the linearised person, checked against the nonlinear model where a     ``tolerance``
               contact reaches its friction limit (:mod:`ehm.routes.hybrid`)
``auto``,      the linear model where the contacts hold, the nonlinear one where      ``tolerance``
``hybrid``     they slide or lift off (:mod:`ehm.routes.hybrid`; the default)
``parallel``   the nonlinear route in segments on several processes or a Dask         ``workers``, ``client``,
               cluster (:mod:`ehm.routes.parallel`)                                   ``lead_in_s``, ``segment_s``
=============  =====================================================================  ===========================

Every route takes the person as built (:class:`ehm.routes.built.BuiltPerson`) and the drive as data, and yields
the run's chunks (:class:`ehm.outputs.results.RunResult`, absolute times) one at a time.  ``workers`` other than 1 or a
``client`` with ``nonlinear`` is the ``parallel`` route (:func:`choose`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ..errors import DivergenceError, InputError
from ..inputs.motion import require_motion
from ..processes import on_one_blas_thread
from . import hybrid, nonlinear, parallel
from .built import built_of


@dataclass(frozen=True)
class Route:
    """One route: its name, what runs it and the options it takes.

    ``run(person, motion, chunk_s=, progress=, pose_rate_hz=, **options)`` yields the run's chunks.
    """

    name: str
    run: Callable
    options: tuple[str, ...] = ()
    summary: str = ""


def _checked(method: str):
    def run(person, motion, chunk_s: float = 10.0, progress=None, pose_rate_hz: float | None = None,
            tolerance: float | None = None):
        # on the model's step, resampled as the nonlinear route resamples (the same input either way)
        try:
            yield from hybrid.stream_checked(person, motion, method=method, chunk_s=chunk_s, progress=progress,
                                             tolerance=hybrid.TOLERANCE if tolerance is None else tolerance,
                                             pose_rate_hz=pose_rate_hz)
        except DivergenceError as exc:
            raise nonlinear.with_input_cause(exc, motion, motion.duration_s) from None
    return run


def _parallel(person, motion, chunk_s: float = 10.0, progress=None, pose_rate_hz: float | None = None,
              workers: int = 1, client=None, lead_in_s: float | None = None, segment_s: float | None = None):
    yield from parallel.stream_parallel(person, motion, workers=workers, segment_s=segment_s, lead_in_s=lead_in_s,
                                        client=client, progress=progress, chunk_s=chunk_s,
                                        pose_rate_hz=pose_rate_hz)


_HYBRID = Route("auto", _checked("auto"), ("tolerance",),
                "the linear model where the contacts hold, the nonlinear one where they slide or lift off")
#: The routes by name.
ROUTES: dict[str, Route] = {
    "nonlinear": Route("nonlinear", nonlinear.stream, (), "the MuJoCo model throughout"),
    "linear": Route("linear", _checked("linear"), ("tolerance",),
                    "the linearised person throughout, checked against the nonlinear model"),
    "auto": _HYBRID,
    "hybrid": _HYBRID,
    "parallel": Route("parallel", _parallel, ("workers", "client", "lead_in_s", "segment_s"),
                      "the nonlinear route in segments on several processes or a Dask cluster"),
}


def route(name: str) -> Route:
    """The route called ``name`` (:data:`ROUTES`); one sentence for a name that is none."""
    if name not in ROUTES:
        raise InputError(f"method must be 'nonlinear', 'linear' or 'auto' ('hybrid'), or 'parallel', not {name!r}.")
    return ROUTES[name]


#: The options of a run that pick or shape its route (:func:`choose`'s keywords after ``method``).
OPTIONS = ("tolerance", "workers", "client", "lead_in_s", "segment_s")


def choose(method: str = "auto", tolerance: float | None = None, workers: int = 1, client=None,
           lead_in_s: float | None = None, segment_s: float | None = None) -> tuple[Route, dict]:
    """The route asked for and the options it takes: ``method`` by name, except that ``workers`` other than 1 or a
    ``client`` turn ``nonlinear`` into ``parallel`` (and are refused with the linear and hybrid routes, which run in
    one process); options a route does not take are left out."""
    if workers != 1 or client is not None:
        if method not in ("nonlinear", "parallel"):
            raise InputError(f"workers and client split the nonlinear route into segments; pass method='nonlinear' "
                             f"(the {method} route runs in one process).")
        method = "parallel"
    chosen = route(method)
    given = {"tolerance": tolerance, "workers": workers, "client": client, "lead_in_s": lead_in_s,
             "segment_s": segment_s}
    return chosen, {k: given[k] for k in chosen.options}


def stream(person, motion, method: str = "auto", chunk_s: float = 10.0, progress=None,
           pose_rate_hz: float | None = None, **options):
    """The run of ``motion`` by the route :func:`choose` picks for ``method`` and ``options`` (``tolerance``,
    ``workers``, ``client``, ``lead_in_s``, ``segment_s``), chunk by chunk; a ``motion`` that is no
    :class:`ehm.SeatMotion` is refused in one sentence.

    A person without a vibration level of its own runs at the drive's (:meth:`ehm.routes.built.BuiltPerson.for_motion`:
    the rms of the whole motion above 0.5 Hz, :attr:`ehm.SeatMotion.vibration_rms_mps2`, to two significant digits);
    every chunk records the level in ``extra["vibration_level"]``
    (:meth:`ehm.routes.built.BuiltPerson.level_record`)."""
    require_motion("simulate()", motion)
    unknown = sorted(set(options) - set(OPTIONS))
    if unknown:
        raise InputError(f"unknown option {unknown[0]!r} of a run; the options are method, chunk_s, progress, "
                         f"pose_rate_hz, {', '.join(OPTIONS)}.")
    chosen, kept = choose(method, **options)
    # the person at the vibration level of the WHOLE drive, taken once here (unless the person's own is given), so
    # that every route, the parallel route's segments and the hybrid route's two models run at one level
    person = built_of(person).for_motion(motion)
    # the route's small matrix products on one BLAS thread (a threaded BLAS oversubscribes the cores with them)
    yield from on_one_blas_thread(person.recorded(chosen.run(person, motion, chunk_s=chunk_s, progress=progress,
                                          pose_rate_hz=pose_rate_hz, **kept)))
