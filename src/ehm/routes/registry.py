"""The routes by name: what :meth:`ehm.SeatedHuman.stream` (and through it :func:`ehm.assess`) asks for.

=============  =====================================================================  ===========================
name           route                                                                  options
=============  =====================================================================  ===========================
``nonlinear``  the MuJoCo model stepped throughout (:mod:`ehm.routes.nonlinear`); a    ``workers``
               long drive in segments on the machine's cores (:mod:`.parallel`)
``linear``     the linearised person, checked against the nonlinear model where a     ``tolerance``
               contact reaches its friction limit (:mod:`ehm.routes.hybrid`)
``auto``,      the linear model where the contacts hold, the nonlinear one where      ``tolerance``,
``hybrid``     they slide or lift off (:mod:`ehm.routes.hybrid`; the default); a      ``workers``
               long drive it runs nonlinear from the start in segments
``parallel``   the nonlinear route in segments on several processes or a Dask         ``workers``, ``client``,
               cluster (:mod:`ehm.routes.parallel`)                                   ``lead_in_s``, ``segment_s``
=============  =====================================================================  ===========================

Every route takes the person as built (:class:`ehm.routes.built.BuiltPerson`) and the drive as data, and yields
the run's chunks (:class:`ehm.outputs.results.RunResult`, absolute times) one at a time.  ``workers`` of 2 or more or a
``client`` with ``nonlinear`` is the ``parallel`` route (:func:`choose`).  ``workers=None`` (the default) runs a drive
of :data:`ehm.routes.parallel.DEFAULT_SEGMENTS_FROM_S` or more that goes to the nonlinear model from its start in
segments on the machine's cores (:func:`ehm.routes.parallel.default_workers`); ``workers=1`` keeps one process.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from numbers import Integral

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
            tolerance: float | None = None, workers: int | None = None, lead_in_s: float | None = None):
        # on the model's step, resampled as the nonlinear route resamples (the same input either way)
        try:
            yield from hybrid.stream_checked(person, motion, method=method, chunk_s=chunk_s, progress=progress,
                                             tolerance=hybrid.TOLERANCE if tolerance is None else tolerance,
                                             pose_rate_hz=pose_rate_hz, workers=workers, lead_in_s=lead_in_s)
        except DivergenceError as exc:
            raise nonlinear.with_input_cause(exc, motion, motion.duration_s) from None
    return run


def _nonlinear(person, motion, chunk_s: float = 10.0, progress=None, pose_rate_hz: float | None = None,
               workers: int | None = None, lead_in_s: float | None = None):
    """The nonlinear route; a long drive (:func:`ehm.routes.parallel.default_workers`) in segments on the machine's
    cores, each after ``lead_in_s``, unless ``workers`` says otherwise."""
    n = parallel.default_workers(motion.duration_s, workers)
    if n > 1:
        yield from parallel.stream_parallel(person, motion, workers=n, chunk_s=chunk_s, progress=progress,
                                            pose_rate_hz=pose_rate_hz, lead_in_s=lead_in_s)
    else:
        yield from nonlinear.stream(person, motion, chunk_s=chunk_s, progress=progress, pose_rate_hz=pose_rate_hz)


def _parallel(person, motion, chunk_s: float = 10.0, progress=None, pose_rate_hz: float | None = None,
              workers: int | None = None, client=None, lead_in_s: float | None = None, segment_s: float | None = None):
    n = max(2, parallel.default_workers(motion.duration_s)) if workers is None else workers
    yield from parallel.stream_parallel(person, motion, workers=n, segment_s=segment_s, lead_in_s=lead_in_s,
                                        client=client, progress=progress, chunk_s=chunk_s,
                                        pose_rate_hz=pose_rate_hz)


_HYBRID = Route("auto", _checked("auto"), ("tolerance", "workers", "lead_in_s"),
                "the linear model where the contacts hold, the nonlinear one where they slide or lift off")
#: The routes by name.
ROUTES: dict[str, Route] = {
    "nonlinear": Route("nonlinear", _nonlinear, ("workers", "lead_in_s"),
                       "the MuJoCo model throughout (a long drive in segments on the machine's cores)"),
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


def choose(method: str = "auto", tolerance: float | None = None, workers: int | None = None, client=None,
           lead_in_s: float | None = None, segment_s: float | None = None) -> tuple[Route, dict]:
    """The route asked for and the options it takes: ``method`` by name, except that a ``client`` or ``workers`` of 2
    or more turn ``nonlinear`` into ``parallel``.  A ``client`` is refused with the linear and hybrid routes, which
    run in one process, and ``workers`` or ``lead_in_s`` with the linear route; the hybrid route's count where it runs
    the nonlinear model (from a drive's start, or for its long rest).  Options a route does not take are left out.
    ``workers=None`` (the default) leaves it to the drive's length (:func:`ehm.routes.parallel.default_workers`);
    ``workers=1`` keeps one process."""
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, Integral) or workers < 1):
        raise InputError(f"workers must be a whole number of processes, 1 or more (or None: as the drive's length "
                         f"says), not {workers!r}.")
    workers = None if workers is None else int(workers)
    if client is not None and method not in ("nonlinear", "parallel"):
        raise InputError(f"a Dask client runs the nonlinear route in segments; pass method='nonlinear' (the {method} "
                         "route runs in one process).")
    if method == "linear" and ((workers or 1) > 1 or lead_in_s is not None):
        raise InputError("workers and lead_in_s split the nonlinear model's runs into segments; the linear route runs "
                         "in one process: leave them out, or pass method='nonlinear' or 'auto'.")
    if method == "nonlinear" and ((workers or 1) > 1 or client is not None):
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
