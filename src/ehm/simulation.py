"""The seated human as a Python object: build it, ask about it, shake it, read the results by name.

>>> from ehm import SeatedHuman, random_vibration
>>> human = SeatedHuman()                       # the paper's default person and seat
>>> run = human.simulate(random_vibration("z", duration_s=10, rms_mps2=0.3, seed=0))
>>> head_z = run.point("head").acc_mps2[:, 2]   # absolute vertical head acceleration [m/s^2]
>>> head_z.shape                                # 10 s at the default 1 ms step
(10001,)
>>> print(f"{(head_z ** 2).mean() ** 0.5:.1f} m/s^2 rms")
0.4 m/s^2 rms
>>> run.extra["vibration_level"]["line"]       # the person ran at the drive's own level (docs/model.md)
'vibration level 0.29 m/s^2 rms (from the drive).'
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np

from . import engine
from .body.params import Parameters
from .body.tables import Body
from .errors import InputError, checked, checked_class, describe
from .inputs.motion import SeatMotion
from .outputs.results import (  # noqa: F401 - POINT_NAMES, PointMotion, concatenate_runs: also importable from here
    POINT_NAMES,
    PointMotion,
    RunResult,
    concatenate_runs,
)
from .person.person import Person, as_person
from .routes import registry as routes
from .routes.built import BuiltPerson
from .routes.linear import linear_model
from .routes.nonlinear import (  # noqa: F401 - also importable from here
    UNUSUAL_ACC_MPS2,
    UNUSUAL_JUMP_MPS2,
    UNUSUAL_TILT_DEG,
)


@checked_class(skip=("__init__",))
class SeatedHuman:
    """One person on one seat, ready to simulate.

    Parameters
    ----------
    params : Person, Parameters, path or None
        The person (:class:`ehm.Person`), or its parameter set or TOML file (default: the shipped defaults).  The
        other keyword arguments but ``rotating_seat`` are shortcuts that build the :class:`ehm.Person` (given
        with a Person, they replace its fields); :attr:`person` gives it back.
    person : Person, optional
        The person, by name (instead of the first argument).
    lock, unlock : iterable of str
        Joints to lock or unlock on top of the body table's defaults (the waist is locked by default).
    body : Body, optional
        Body tables (default: the paper's Tables 1 and 2 and the shipped contact ellipsoids).
    rotating_seat : bool
        Build the seat so that it can rotate (for motions with angular velocity; about 40 % slower).
    size : ehm.person.scaling.BodySize, optional
        Scale the person (and the seat's fit) to a stature, mass and sitting height.
    dt_s : float, optional
        Time step [s].  Default: the parameter file's ``simulation.dt_s`` when the file sets its own, else the
        posture's own converged step when it has one (the shipped ``slouched``: 0.5 ms), else the shipped 1 ms
        (:meth:`ehm.Parameters.time_step`); the person's ``params`` record the step it runs at.  A step coarser
        than the one at which the person in its posture is converged gives a :class:`ehm.body.timestep.StepWarning`
        with the error to expect; ``ehm check-step`` measures it.
    posture, back_support : str, optional
        The reference posture (``"erect"``, the default, ``"slouched"``, or one the parameter file defines;
        :mod:`ehm.body.posture`) and the seat's back support (``"none"``, ``"low"``, ``"high"``, the default, or
        ``"full"``; :mod:`ehm.body.supports`).  None: the parameter file's (``posture.name``, ``seat.back_support``);
        the
        person's ``params`` record them.
    head_control : bool or dict, optional
        Head-in-space control on top of the joint PID (``ehm.engine.control``, docs/model.md "Head-in-space
        control"): True with the parameter file's gains ([head_control]), a dict of gains (e.g.
        ``{"tilt_stiffness_Nm_per_rad": 30.0, "delay_s": 0.03}``) to switch it on with those, False off; None (the
        default) keeps the file's ``head_control.enabled`` (off in the shipped file).

    Attributes
    ----------
    built : ehm.routes.built.BuiltPerson
        The person as built, what the routes read: the MuJoCo model (also :attr:`model`), the static-seat model of
        a rotating seat's linearisation, the linear models' cache.
    """

    # the person's arguments are ehm.Person's, which checks each itself and names its range
    @checked(only=("rotating_seat", "person"))
    def __init__(self, params: Person | Parameters | str | Path | None = None, lock=(), unlock=(),
                 body: Body | None = None, rotating_seat: bool = False, size=None, dt_s: float | None = None,
                 posture: str | None = None, back_support: str | None = None, head_control=None, *,
                 person: Person | None = None):
        if person is not None and params is not None:
            raise InputError("SeatedHuman: give the person either first or as person=, not both.")
        self.person = as_person(person if person is not None else params, lock=lock, unlock=unlock, body=body,
                                size=size, dt_s=dt_s, posture=posture, back_support=back_support,
                                head_control=head_control)
        built = self.person.resolved()  # seated, head control, step (and its warning), size, locks
        self.body, self.params, self.locked, self.size = built.body, built.params, built.locked, built.size
        # the person as built, what the routes read (ehm.routes.built): the model, the linear models' cache, ...
        self.built = BuiltPerson.build(self.body, self.params, self.locked, rotating_seat=rotating_seat,
                                       size=self.size, vibration_rms_mps2=self.person.vibration_rms_mps2)

    def recipe(self) -> dict:
        """What rebuilds this person in another process (:meth:`from_recipe`), as plain picklable data: the body
        tables and parameters as built (scaled, with the time step), the locked joints, the seat kind, the body
        size, and the settled state when the person has settled (so that a rebuilt person need not settle again:
        settling is deterministic, so this is the state it would reach)."""
        settled = self.model.settled
        return {"person": self.person, "body": self.body, "params": self.params, "locked": frozenset(self.locked),
                "rotating_seat": self.model.seat is not None, "size": self.size,
                "vibration_rms_mps2": self.built.vibration_rms_mps2, "level_origin": self.built.level_origin,
                "settled": None if settled is None else {k: (v.copy() if isinstance(v, np.ndarray) else v)
                                                         for k, v in settled.items()}}

    @classmethod
    def from_recipe(cls, recipe: dict) -> SeatedHuman:
        """The person of :meth:`recipe`, built anew (the same MuJoCo model, and settled if it was)."""
        keys = ("body", "params", "size", "locked", "rotating_seat")
        if not all(k in recipe for k in keys):
            raise InputError(f"SeatedHuman.from_recipe: recipe must be what SeatedHuman.recipe() returns (with "
                             f"{', '.join(keys)}), not {describe(recipe)}.")
        human = cls.__new__(cls)
        human.body, human.params, human.size = recipe["body"], recipe["params"], recipe["size"]
        human.person = recipe.get("person")
        human.locked = frozenset(recipe["locked"])
        human.built = BuiltPerson.from_recipe(recipe)
        return human

    @property
    def model(self) -> engine.Model:
        """The MuJoCo model of the person as built (``ehm.engine.build``; ``built``'s)."""
        return self.built.model

    @property
    def head_control(self) -> bool:
        """Whether the person's head-in-space control is on (``ehm.engine.control``)."""
        return self.model.head_control is not None

    @property
    def dof(self) -> int:
        """Degrees of freedom of the person (28 by default, 31 with the waist unlocked)."""
        return self.model.dof

    @property
    def mass_kg(self) -> float:
        """Total body mass as built [kg]."""
        return self.model.mass_kg

    def info(self) -> dict:
        """Segments, joints and totals as plain data (what ``ehm info --json`` prints), in the person's posture."""
        body = self.model.body  # the tables in the posture, with the back support's contacts
        return {
            "mass_kg": self.mass_kg,
            "dof": self.dof,
            "locked": sorted(self.locked),
            "dt_s": float(self.params.value("simulation.dt_s")),
            "params": self.params.origin,
            "posture": self.params.posture,
            "back_support": self.params.back_support,
            "vibration_rms_mps2": self.built.vibration_rms_mps2,  # None: the file's reference, a drive's own on a run
            "segments": [{"name": s.name, "mass_kg": s.mass_kg, "com_m": s.com_m.tolist(),
                          "inertia_kgm2": s.inertia_kgm2.tolist()} for s in body.segments],
            "joints": [{"name": j.name, "parent": j.parent, "child": j.child, "type": j.type,
                        "dof": 0 if j.name in self.locked else len(j.dofs), "dofs": list(j.dofs),
                        "locked": j.name in self.locked, "pos_m": j.pos_m.tolist(),
                        "axes_pitch_rad": j.axes_pitch_rad} for j in body.joints],
            "contacts": [{"name": c.name, "segment": c.segment, "surface": c.surface} for c in body.contacts],
            "points": {p: engine.POINTS[p] for p in POINT_NAMES},  # point -> its segment
            "point_joints": dict(engine.POINT_JOINTS),  # a point at a joint's centre (else the segment's COG)
        }

    def settle(self) -> None:
        """Let the person sink into the seat (done automatically before the first run)."""
        engine.settle(self.model)

    def linear_model(self, rotation: bool = False):
        """The person linearised at the settled posture, continuous time (:func:`ehm.routes.linear.continuous_model`;
        computed once, about 0.1 s after settling).

        Parameters
        ----------
        rotation : bool
            False: the model of seat translation (three inputs, the seat's acceleration).  True: with the
            seat's rotation about its pivot (``ehm.engine.seat_pivot``) in the seat's own frame, twelve
            inputs (see :func:`ehm.routes.linear.stream_linear`), what a motion with angular velocities runs on.

        Both are linearised on the person on a static seat: for a person built with ``rotating_seat=True`` a
        static-seat build of the same person is made (and settled) once for it.
        """
        return linear_model(self.built, rotation=rotation)

    def simulate(self, motion: SeatMotion, progress: Callable | None = None, pose_rate_hz: float | None = None,
                 method: str = "auto", tolerance: float | None = None, **options) -> RunResult:
        """Run the settled person with a seat motion.

        ``method="auto"`` (the default, as for :func:`ehm.assess`, ``ehm simulate`` and ``ehm assess``) is the
        hybrid route, described below: the linear model where the contacts stick, the nonlinear one where they
        slide or lift off, checked at every step.  ``method="nonlinear"`` steps the MuJoCo model throughout (the
        motion resampled to the model's time step); a motion with angular velocity needs a person built with
        ``rotating_seat=True``.  For long drives use :meth:`stream`, which holds one chunk at a time.

        ``method="linear"`` runs the person linearised at rest (:mod:`ehm.routes.linear`) on the same input (the
        motion resampled to the model's step, anti-aliased), exactly discretised, about a thousand times
        faster than real time, and checks it by its effect (:mod:`ehm.routes.hybrid`): wherever a contact reaches its
        friction limit or lifts off, the nonlinear model runs too and the two answers are compared; above
        ``tolerance`` (share of each point acceleration's rms, default 1 %) it warns
        (:class:`ehm.routes.hybrid.LinearRouteWarning`) with the figure.  ``method="auto"`` (the hybrid route) keeps the
        nonlinear answer in those windows and the linear one elsewhere.  Both record what they checked in
        ``result.extra["route"]`` (:class:`ehm.routes.hybrid.RouteReport`).  Every route records the segments' poses at
        ``pose_rate_hz`` when asked (for ``ehm.outputs.animation``; the linear pieces through the model's kinematics,
        :mod:`ehm.routes.poses`).  A motion that rotates
        the seat runs on the linear model of the seat's rotation in the seat's own frame (whether or not the
        person was built with ``rotating_seat=True``): see :func:`ehm.routes.linear.stream_linear` for what it assumes;
        its estimate of the terms it leaves out is in ``result.extra["linear_check"]``.

        A person without a vibration level of its own (``Person(vibration_rms_mps2=None)``, the default) runs at the
        drive's (:attr:`ehm.SeatMotion.vibration_rms_mps2` of the whole motion, to two significant digits), built
        once per level and kept (docs/model.md, "Vibration magnitude"); ``result.extra["vibration_level"]`` records
        it.

        ``method`` names a route of :mod:`ehm.routes.registry`: ``"auto"`` (or ``"hybrid"``, the same route),
        ``"linear"``, ``"nonlinear"``, or ``"parallel"``, the nonlinear route in segments on several processes or a
        Dask cluster (:mod:`ehm.routes.parallel`), whose ``options`` are ``workers``, ``client``, ``lead_in_s`` and
        ``segment_s`` (``workers`` of 2 or more or a ``client`` with ``"nonlinear"`` runs it too).

        The machine's cores by default: a drive of three minutes or more
        (:data:`ehm.routes.parallel.DEFAULT_SEGMENTS_FROM_S`) that runs on the nonlinear model from its start
        (``"nonlinear"``, or ``"auto"`` when its manoeuvres hold the contacts at their limits) runs in segments on the
        machine's cores, up to :data:`ehm.routes.parallel.MAX_DEFAULT_WORKERS` processes
        (:func:`ehm.routes.parallel.default_workers`; comfort and sickness figures within 1 % of one continuous run);
        ``workers=1`` keeps one process, ``workers=N`` asks for N.
        """
        return concatenate_runs(list(self.stream(motion, progress=progress, method=method, tolerance=tolerance,
                                                 pose_rate_hz=pose_rate_hz, **options)))

    def simulate_to(self, out_dir: Path | str, motion: SeatMotion, output_rate_hz: float | None = None,
                    formats: str | tuple | list = ("csv",), pose_rate_hz: float | None = 25.0,
                    progress: Callable | None = None, chunk_s: float = 10.0, plot=None, method: str = "auto",
                    tolerance: float | None = None, chunks: Iterable | None = None,
                    workers: int | None = None, lead_in_s: float | None = None) -> dict:
        """Run a seat motion and write its run folder while it runs; returns the summary.

        Chunks of ``chunk_s`` go to disk as they are computed (:mod:`ehm.outputs.runfiles`), so memory does not grow
        with the motion's length; the folder ``out_dir`` is put in place as one unit when the run has ended
        (:mod:`ehm.outputs.outdir`), and a failure or an interrupt leaves an earlier folder there as it was.
        ``output_rate_hz`` thins the time series (it must divide the model's rate; default
        :data:`ehm.outputs.runfiles.DEFAULT_OUTPUT_RATE_HZ`, or the nearest whole fraction of the model's rate above
        it);
        ``formats``: ``"csv"`` and/or ``"parquet"``.  ``method``, ``tolerance``, ``workers`` and ``lead_in_s`` as for
        :meth:`simulate` (every route records poses at ``pose_rate_hz``).

        ``plot`` draws figures into the folder before it is put in place: a callable ``plot(preview, folder)``
        that gets a :class:`RunResult` of at most :data:`ehm.outputs.runfiles.PREVIEW_ROWS` evenly spread rows and the
        folder being written, e.g. ``ehm.outputs.plotting.plot_run_preview`` (``time_histories.png``).  Computing
        and drawing stay apart: this module does not import matplotlib.

        ``chunks``: the run's chunks made elsewhere, in order (e.g. :func:`ehm.routes.parallel.stream_parallel` with the
        same ``chunk_s`` and ``pose_rate_hz``), written instead of this person's own :meth:`stream`.
        """
        from .outputs.outdir import RunFolder, check_output_folder
        from .outputs.runfiles import (
            PREVIEW_ROWS,
            check_formats,
            default_output_every,
            output_every,
            pyarrow_modules,
            write_run,
        )

        formats = check_formats(formats)
        if chunks is not None:
            chunks = _run_chunks(chunks)
        if plot is not None and plot is not False and not callable(plot):
            raise InputError("plot must be a function plot(preview, folder), e.g. "
                             "ehm.outputs.plotting.plot_run_preview; simulate_to does not draw by itself.")
        dt = float(self.model.mj.opt.timestep)
        every = default_output_every(dt) if output_rate_hz is None else output_every(output_rate_hz, dt)
        if "parquet" in formats:
            pyarrow_modules()
        check_output_folder(out_dir)
        n_steps = int(np.floor(motion.duration_s / dt + 1e-9)) + 1 if isinstance(motion, SeatMotion) else None
        with RunFolder(out_dir) as tmp:
            if chunks is None:
                chunks = self.stream(motion, chunk_s=chunk_s, progress=progress, pose_rate_hz=pose_rate_hz,
                                     method=method, tolerance=tolerance, workers=workers, lead_in_s=lead_in_s)
            summary, pieces = write_run(tmp, chunks, output_every=every, formats=formats,
                                        preview_rows=PREVIEW_ROWS if plot else 0, n_steps=n_steps)
            if plot and pieces:
                plot(concatenate_runs(pieces), tmp)
        return summary

    def stream(self, motion: SeatMotion, chunk_s: float = 10.0, progress: Callable | None = None,
               pose_rate_hz: float | None = None, method: str = "auto", tolerance: float | None = None, **options):
        """Run a seat motion chunk by chunk; yields one :class:`RunResult` per chunk (absolute times).

        Memory stays constant whatever the motion's length: the motion is resampled onto the model's time
        step (anti-aliased polyphase filter, :class:`ehm.inputs.resampling.Resampler`) one chunk at a time.
        ``progress(done_s, total_s)`` is called after every chunk.  ``method`` and ``options`` as
        for :meth:`simulate` (default ``"auto"``, the hybrid route; every route takes the motion resampled to the
        model's step): the route of that name (:func:`ehm.routes.registry.stream`) runs on the person as built,
        ``built``.
        """
        yield from routes.stream(self.built, motion, method, chunk_s=chunk_s, progress=progress,
                                 pose_rate_hz=pose_rate_hz, tolerance=tolerance, **options)

    def check_nonlinear_motion(self, motion: SeatMotion) -> float:
        """Refuse, in one sentence, a motion the nonlinear model cannot run on this person: one that turns the seat
        of a person built without ``rotating_seat=True``, or one shorter than a time step; returns the step [s]
        (:meth:`ehm.routes.built.BuiltPerson.check_nonlinear_motion`)."""
        return self.built.check_nonlinear_motion(motion)


def _run_chunks(chunks):
    """``chunks`` (simulate_to's) one by one, each checked to be a piece of a run."""
    for chunk in chunks:
        if not isinstance(chunk, RunResult):
            raise InputError(f"SeatedHuman.simulate_to: chunks must give the run's pieces as ehm.RunResult objects "
                             f"(e.g. from SeatedHuman.stream), not {describe(chunk)}.")
        yield chunk
