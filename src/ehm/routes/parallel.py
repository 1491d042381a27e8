r"""A long nonlinear run in segments on several cores: local processes or a Dask cluster.

>>> from ehm import SeatedHuman, random_vibration
>>> from ehm.routes.parallel import simulate_parallel
>>> motion = random_vibration("z", duration_s=10, rms_mps2=0.3, seed=0)
>>> run = simulate_parallel(SeatedHuman(), motion, workers=2)     # the same time axis and fields as simulate()
>>> run.time_s.shape
(10001,)

The motion is split into consecutive segments (at least one per worker).  Each segment is run from the settled
rest over [start - lead-in, end] with the motion's own input over the lead-in, which is then discarded; the
pieces are joined (``ehm.outputs.results.concatenate_runs``) into one :class:`~ehm.RunResult` on the continuous run's
time axis, without a gap or a repeated sample.  The first segment starts at the motion's start and is the
continuous run's first part bit for bit; one worker runs the motion in this process (the nonlinear route,
:func:`ehm.routes.nonlinear.stream`).  Workers rebuild the person from its recipe
(:meth:`ehm.routes.built.BuiltPerson.recipe`: the tables, parameters, locks, seat, size and the settled state: no
MuJoCo object is pickled, and no worker settles again).

The lead-in is needed because the person has memory: the posture controllers' integral action and the positions
at which the tissue pads' friction holds (stick) carry the past into the present.  A segment started from rest
differs from the continuous run at first; the difference dies away over the lead-in.  A rotating seat starts each
lead-in level: its yaw is offset by a constant (nothing changes in seat axes) and its pitch and roll are faded in
over the lead-in, so that from the segment's start on the seat's attitude is the continuous run's.

How long a lead-in?  Measured (``benchmarks/bench_parallel.py --lead-in``; default person, 1 ms step; the run in
4 segments of equal work, each after the lead-in, against the continuous run).  Per point, the rms of the
acceleration difference as a share of the continuous run's rms: pelvis / trunk / head, the 3 axes together and the
worst single axis, over the run; the largest share (3 axes together, any point) over the 10 s after a join; and
the largest relative difference of a_v (ISO 2631-1 total value), VDV_z and MSDV_z over pelvis, trunk and head and
of the head-driven final MSI; in %:

===========================  ===  ==================  ================  ======  ====  =====  ======  ====
drive                        L    acc over the run    worst axis        10 s    a_v   VDV_z  MSDV_z  MSI
                             [s]  (3 axes)                              after
                                                                        a join
===========================  ===  ==================  ================  ======  ====  =====  ======  ====
bus floor log (measured),    1    0.30 / 1.08 / 1.31  0.4 / 1.8 / 1.8   1.00    0.05  0.08   0.01    0.10
219 s                        2    0.30 / 1.08 / 1.31  0.4 / 1.8 / 1.8   0.30    0.05  0.08   0.01    0.04
\                            5    0.30 / 1.08 / 1.31  0.4 / 1.8 / 1.8   0.32    0.05  0.08   0.01    0.07
\                            10   0.30 / 1.08 / 1.31  0.4 / 1.8 / 1.8   0.32    0.05  0.08   0.01    0.07
\                            20   0.30 / 1.08 / 1.31  0.4 / 1.8 / 1.8   1.08    0.05  0.08   0.01    0.01
\                            40   0.30 / 1.08 / 1.31  0.4 / 1.8 / 1.8   3.18    0.05  0.08   0.01    0.01
city drive (SYNTHETIC,       2    0.29 / 1.21 / 1.77  1.0 / 4.6 / 7.0   5.40    0.27  0.42   0.07    0.05
rotating seat), 240 s        5    0.28 / 1.29 / 1.72  1.0 / 4.9 / 7.5   4.99    0.13  0.43   0.04    0.02
\                            10   0.24 / 1.05 / 1.18  0.7 / 4.1 / 5.7   1.68    0.13  0.50   0.01    0.01
\                            20   0.22 / 1.01 / 1.12  0.7 / 3.9 / 5.5   3.48    0.21  0.51   0.01    0.02
\                            40   0.14 / 0.79 / 0.77  0.6 / 3.0 / 4.8   1.38    0.04  0.11   0.01    0.00
\                            60   0.11 / 0.58 / 0.51  0.5 / 2.1 / 3.6   2.90    0.03  0.12   0.00    0.01
city drive, 60 s (a join     1    0.55 / 2.97 / 4.54  not measured      9.53    1.35  1.59   0.24    1.11
every 15 s: the extreme)     5    0.51 / 2.48 / 3.66                    5.83    0.66  1.42   0.22    0.14
\                            10   0.36 / 1.94 / 2.16                    3.32    0.20  1.40   0.71    0.13
\                            20   0.19 / 1.44 / 1.45                    2.86    0.23  1.45   0.05    0.07
===========================  ===  ==================  ================  ======  ====  =====  ======  ====

The worst axis is the vertical one on the city drive (and the bus's trunk; the bus's head: lateral): its
acceleration is small there (road vibration of 0.15 m/s^2 rms under horizontal pushes of 1-3.5 m/s^2), and what
differs is mostly above 5 Hz (on a 120 s city drive in 2 segments, head z: 0.026 of 0.097 m/s^2 rms above 5 Hz,
0.0015 of 0.0067 below 0.5 Hz), in bursts after the join (31 % of the head's z rms in the 10 s after it, 0.1 % 30 s
later).  Per axis over the 10 s after a join the share reaches 10-100 % on the city drive, in windows where
that axis hardly moves.

What it shows.  The part of the difference that dies away does so within a few seconds: the posture controllers'
integral action (Ti = 1 s) and the transient of starting from rest are gone after 2 s on the bus log (10 s after a
join: 1.00 % with 1 s, 0.30 % with 2 s) and after 10 s on the city drive (5.0 % with 5 s, 1.7 % with 10 s).  What
remains is the posture that friction holds: in the continuous run the pelvis turns and the hips roll by some
5-15 mrad under braking and cornering, and stay so (on the bus, at rest from 40 to 55 s, the pelvis stays turned
by 4.7 mrad), until a larger push moves them again.  A segment started from rest has not been pushed that way;
its lead-in gives that posture back only if it holds the push that set it, so a longer lead-in helps unevenly
(city drive: trunk and head 0.8 % with 40 s, 0.5-0.6 % with 60 s; bus log: 1.31 % with 40 s as with 1 s) and the
10 s after a join is not monotonic in it.  Not a rounding effect, nor chaos: the continuous run with its input
changed by a factor 1 + 1e-6 differs by 1e-6 (bus log: 1 + 1e-9, 1e-9).

So the 1 % holds for the comfort and sickness figures, not for the time histories.  Every figure (a_v, VDV_z,
MSDV_z, final MSI) stays within 0.5 % with 10 s (twice the margin to 1 %) on the bus log and the 240 s city drive;
the acceleration time histories of trunk and head do not stay within 1 % whatever the lead-in (1.05-1.31 % over the
run with 10 s, 3 axes together; up to 5.7 % in the vertical axis of the city drive).  A join every 15 s of a harsh
city drive (the 60 s drive in 4 segments) takes head VDV_z 1.4 % off at every lead-in up to 20 s: use segments of a
minute or more (two workers on a drive of a few minutes give one join).  Fading the input in over the lead-in (a
quintic ramp) did not help: the same or worse on both drives (city drive, 2 s: head 5.3 % against 3.7 %; bus
log, 1 s: MSI 0.33 % against 0.10 %), so the lead-in takes the motion's input as it is, from the settled, level
posture.  :data:`DEFAULT_LEAD_IN_S` is 10 s: the shortest after which the decaying part is gone on both drives; a
longer one costs little on a long drive (``lead_in_s``, ``--lead-in``) but does not reliably help.
"""

from __future__ import annotations

import math
import multiprocessing
import os
import sys
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from numbers import Integral, Real

import numpy as np

from ..errors import EhmWarning, InputError, checked, describe
from ..inputs.motion import SeatMotion, require_motion
from ..inputs.resampling import Resampler
from ..outputs.results import RunResult, concatenate_runs
from ..processes import (
    ONE_THREAD,
    capped_workers,
    environ_default,
    ignore_sigint,
    sigint_ignored,
    unguarded_script_line,
    worker_limit,
)
from .built import BuiltPerson, built_of
from .nonlinear import stream as stream_nonlinear
from .nonlinear import stream_span

__all__ = ["DEFAULT_LEAD_IN_S", "DEFAULT_SEGMENTS_FROM_S", "MAX_DEFAULT_WORKERS", "Span", "default_workers",
           "plan_segments", "simulate_parallel", "stream_parallel", "stream_rest"]

#: Lead-in of every segment but the first [s], chosen by measurement (module docstring).
DEFAULT_LEAD_IN_S = 10.0
#: A drive at least this long [s] runs its nonlinear stretch from the start in segments on the machine's cores
#: unless told otherwise (``workers=None``, the default; ``workers=1``, ``--workers 1``: one process).  Three minutes:
#: at two segments the lead-in (10 s) and a worker's start-up (1.5 s) are then under a tenth of the work, and the
#: comfort and sickness figures of the drives measured stay within 0.5 % of the continuous run (module docstring).
DEFAULT_SEGMENTS_FROM_S = 180.0
#: At most this many processes by default (a machine with more cores gains less per process: every segment but
#: the first runs its lead-in, and each process holds about 0.4 GB); ``workers=N`` asks for more.
MAX_DEFAULT_WORKERS = 8
#: Environment variable with the most processes a long drive uses by default (``1``: one process, e.g. for jobs that
#: share a machine by threads or a job scheduler's tasks).
WORKERS_VARIABLE = "EHM_WORKERS"
#: Wall time a local worker process costs before its segment [s]: spawning it, with Python, NumPy, SciPy, MuJoCo
#: and ehm imported and the person built (1.2-1.3 s measured, ``benchmarks/bench_parallel.py``), and a margin for
#: handing its result back; the first segment, run in this process meanwhile, is made longer by what this
#: process steps in that time.
WORKER_START_S = 1.5
#: Steps per wall second of the nonlinear route on a drive, static and rotating seat (``rotating_seat``): measured
#: 31 000 on the bus floor log and 28 000-32 000 on random vibration (static); 13 000-16 000 on the SYNTHETIC rough
#: road and 14 000-19 000 on the SYNTHETIC city drive (rotating); the lower end, so that the first segment does
#: not end last.
STEPS_PER_WALL_S = {False: 25_000, True: 14_000}


@dataclass(frozen=True)
class Span:
    """One segment of a run (a time slice of it): grid steps ``first`` ... ``stop - 1`` are kept, ``lead_steps``
    before them run first.

    Attributes
    ----------
    first, stop : int
        The kept steps (on the motion resampled to the model's step).
    lead_steps : int
        Steps of lead-in before ``first`` (0 for the first segment).
    """

    first: int
    stop: int
    lead_steps: int

    @property
    def work_steps(self) -> int:
        """Steps the segment's worker runs (lead-in included)."""
        return self.stop - self.first + self.lead_steps


def default_workers(duration_s: float, asked: int | None = None) -> int:
    """How many processes a nonlinear run of a drive of ``duration_s`` [s] uses: ``asked`` where the caller says,
    else (``workers=None``) the machine's (``ehm.processes.worker_limit``: its usable cores and its memory, at most
    :data:`MAX_DEFAULT_WORKERS`, or at most ``$EHM_WORKERS``) for a drive of :data:`DEFAULT_SEGMENTS_FROM_S` or more,
    else 1; always 1 inside a worker process (a batch study's, a Dask worker's: those already share the cores out)
    and for a script that calls ehm at its top level outside ``if __name__ == "__main__":`` (with a warning).
    Jobs that share a machine in other ways (threads, a job scheduler's tasks) say ``EHM_WORKERS=1``."""
    if asked is not None:
        return int(asked)
    if duration_s < DEFAULT_SEGMENTS_FROM_S:
        return 1
    if multiprocessing.parent_process() is not None or multiprocessing.current_process().name != "MainProcess":
        return 1  # (a spawned child has its name before it imports the script again; its parent only after)
    most = MAX_DEFAULT_WORKERS
    if os.environ.get(WORKERS_VARIABLE, "").strip():
        try:
            most = int(os.environ[WORKERS_VARIABLE])
        except ValueError:
            raise InputError(f"{WORKERS_VARIABLE}={os.environ[WORKERS_VARIABLE]!r} in the environment: give the most "
                             "processes a long drive may use by default, a whole number (1: one process).") from None
        if most < 1:
            raise InputError(f"{WORKERS_VARIABLE}={most} in the environment: use 1 or more.")
    n = max(1, min(worker_limit()[0], most))
    line = unguarded_script_line() if n > 1 else None
    if line is not None:  # every worker would run the script again from its top
        if not _unguarded_told:
            _unguarded_told.append(line)
            warnings.warn(f"a drive of {duration_s:.0f} s runs in one process, not on the machine's {n} cores: your "
                          f"script calls ehm at its top level (line {line} of {sys.modules['__main__'].__file__}), "
                          "which every worker process would run again; put that call under "
                          "'if __name__ == \"__main__\":' (or pass workers=1 to say one process is meant).",
                          EhmWarning, stacklevel=2)
        return 1
    return n


_unguarded_told: list[int] = []


def plan_segments(n_steps: int, n_segments: int, lead_steps: int, align_steps: int = 1,
                  first_extra_steps: int = 0) -> list[Span]:
    """Split ``n_steps`` grid steps into at most ``n_segments`` consecutive segments of about equal work.

    Every segment but the first runs ``lead_steps`` more steps before its own, and ``first_extra_steps`` more
    work is counted for each of them (a worker process's start-up, while the first segment runs here), so the
    first segment is longer by both; boundaries fall on multiples of ``align_steps`` (the chunks of the continuous
    run, so that the segmented run is cut into the same chunks).  Fewer segments come out when there are fewer
    aligned blocks.
    """
    blocks = math.ceil(n_steps / align_steps)
    k = max(1, min(int(n_segments), blocks))
    extra = lead_steps + first_extra_steps
    # equal work: the first keeps base + extra steps, the others base each (plus their lead-in and start-up)
    base = max(0.0, (n_steps - extra) / k)
    bounds = [0]
    for i in range(1, k):
        b = int(round((base * i + extra) / align_steps)) * align_steps
        bounds.append(min(max(b, bounds[-1] + align_steps), n_steps))
    bounds.append(n_steps)
    bounds = sorted(set(bounds))
    return [Span(lo, hi, 0 if lo == 0 else min(lead_steps, lo)) for lo, hi in zip(bounds[:-1], bounds[1:])]


def _run_segment(recipe: dict, motion: SeatMotion, segment: Span, chunk_s: float, pose_rate_hz, ramp: bool,
                 hand_over_dir: str | None = None):
    """A worker's task: the person rebuilt from ``recipe``, run over ``segment``; returns the kept part as its
    chunks (:class:`RunResult` each, not joined here: the joining is done once, by the caller) and the task's
    times: ``start`` and ``end`` (epoch seconds), ``build_s``.  With ``hand_over_dir`` the chunks' arrays go
    into a file there (:func:`_to_file`) and what is returned is the file's description."""
    start = time.time()
    person = BuiltPerson.from_recipe(recipe)
    built = time.time()
    pieces = list(stream_span(person, motion, segment.first, segment.stop, segment.lead_steps, chunk_s=chunk_s,
                                     pose_rate_hz=pose_rate_hz, ramp=ramp))
    times = {"start": start, "build_s": built - start, "end": time.time()}
    return (pieces if hand_over_dir is None else _to_file(pieces, hand_over_dir)), times


def _to_file(obj, folder: str) -> dict:
    """``obj`` pickled with its arrays' data out of band, into one file in ``folder``: a segment's result passed
    through a pipe came at about 130 MB/s here (2.6 s for 10 min of run), through a file in memory (/dev/shm)
    at the speed of copying memory."""
    import pickle
    import tempfile

    buffers = []
    meta = pickle.dumps(obj, protocol=5, buffer_callback=buffers.append)
    fd, path = tempfile.mkstemp(prefix="segment-", suffix=".bin", dir=folder)
    sizes = []
    with os.fdopen(fd, "wb") as f:
        for b in buffers:
            raw = b.raw()
            f.write(raw)
            sizes.append(raw.nbytes)
    return {"meta": meta, "path": path, "sizes": sizes}


def _from_file(handed: dict):
    """The object of :func:`_to_file`, its arrays mapped from the file (copy on write), the file removed."""
    import mmap
    import pickle

    try:
        views = []
        if sum(handed["sizes"]):
            with open(handed["path"], "rb") as f:
                whole = memoryview(mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_COPY))
            offset = 0
            for n in handed["sizes"]:
                views.append(whole[offset:offset + n])
                offset += n
        else:
            views = [memoryview(b"") for _ in handed["sizes"]]
        return pickle.loads(handed["meta"], buffers=views)
    finally:
        os.unlink(handed["path"])


def _check(workers, segment_s, lead_in_s, chunk_s) -> None:
    if isinstance(workers, bool) or not isinstance(workers, Integral) or workers < 1:
        raise InputError(f"workers must be a whole number of processes, 1 or more, not {describe(workers)}.")

    def time_s(v) -> bool:
        return not isinstance(v, bool) and isinstance(v, Real) and bool(np.isfinite(v))

    if lead_in_s is not None and not (time_s(lead_in_s) and lead_in_s >= 0):
        raise InputError(f"lead_in_s must be a time in seconds, 0 or more, not {describe(lead_in_s)}.")
    if segment_s is not None and not (time_s(segment_s) and segment_s > 0):
        raise InputError(f"segment_s must be a positive time in seconds, not {describe(segment_s)}.")
    if isinstance(chunk_s, bool) or not isinstance(chunk_s, Real) or not chunk_s > 0:
        raise InputError(f"chunk_s must be a positive time in seconds, not {describe(chunk_s)}.")


def stream_parallel(human, motion: SeatMotion, workers: int = 2, segment_s: float | None = None,
                    lead_in_s: float | None = None, client=None, progress=None, chunk_s: float = 10.0,
                    pose_rate_hz: float | None = None, _ramp: bool = False, _stats: dict | None = None):
    """The nonlinear route in segments on ``workers`` processes; yields the run's chunks in order, as
    :meth:`ehm.SeatedHuman.stream` does (the same chunk boundaries, absolute times).

    Parameters
    ----------
    human : SeatedHuman or BuiltPerson
        The person (its recipe, :meth:`ehm.routes.built.BuiltPerson.recipe`, goes to the workers; it is settled
        here first).
    motion : SeatMotion
    workers : int
        Processes to run on: this one (the first segment, streamed chunk by chunk as it is computed, while the
        others start) and ``workers - 1`` spawned worker processes, which ignore Ctrl-C and SIGHUP (they end the
        run here and stop them); no more than the machine holds (``ehm.processes.capped_workers``: its cores,
        and its memory at about 0.4 GB per worker), with a warning.  1, or a motion too short to gain from a
        second process (fewer steps than this process makes while a worker starts, :data:`WORKER_START_S`), runs
        in this process as one segment: bit for bit :meth:`~ehm.SeatedHuman.stream`.  With ``client``: at least
        one segment per worker of the cluster.
    segment_s : float, optional
        Longest segment [s] (default: one segment per worker); more segments than workers are handed out as
        workers become free.
    lead_in_s : float, optional
        Lead-in before each segment but the first [s] (default :data:`DEFAULT_LEAD_IN_S`, chosen by measurement:
        see the module docstring).
    client : dask.distributed.Client, optional
        Run the segments on this Dask cluster instead of local processes (``ehm.interfaces.cluster`` opens one for the
        command line's ``--scheduler``).
    progress : callable(done_s, total_s), optional
        Called as segments finish (simulated seconds kept so far).
    chunk_s : float
        Chunk length of the results [s], as for :meth:`~ehm.SeatedHuman.stream`; segment boundaries fall on
        whole chunks.
    pose_rate_hz : float, optional
        Poses for pictures, as for :meth:`~ehm.SeatedHuman.simulate`.
    """
    _check(workers, segment_s, lead_in_s, chunk_s)
    require_motion("simulate_parallel()", motion)
    # the person at the WHOLE drive's level (unless its own is given): every segment runs at that one level
    human = built_of(human).for_motion(motion)
    dt = human.check_nonlinear_motion(motion)
    lead_s = DEFAULT_LEAD_IN_S if lead_in_s is None else float(lead_in_s)
    n_steps = Resampler.of_motion(motion, dt).n_samples
    per_chunk = max(1, int(round(chunk_s / dt)))
    if pose_rate_hz:
        every = max(1, int(round(1.0 / (pose_rate_hz * dt))))
        per_chunk = max(every, per_chunk // every * every)
    n_workers = workers = int(workers) if client is not None else capped_workers(int(workers))
    if client is not None:
        if not all(callable(getattr(client, name, None)) for name in ("scheduler_info", "scatter", "submit")):
            raise InputError(f"client must be a dask.distributed Client (e.g. Client('tcp://host:8786'), "
                             f"--scheduler), not {describe(client)}.")
        n_workers = max(1, len(client.scheduler_info().get("workers", {})))
    n_seg = max(n_workers, math.ceil(motion.duration_s / segment_s) if segment_s else 1)
    local = client is None
    # locally the first segment runs in this process while the workers start, so it takes their start-up too
    start_up = int(WORKER_START_S * STEPS_PER_WALL_S[human.model.seat is not None]) if local else 0
    segments = plan_segments(n_steps, n_seg, int(round(lead_s / dt)), per_chunk, first_extra_steps=start_up)
    if _stats is not None:
        _stats.update(segments=segments, tasks=[])
    if len(segments) == 1 or (workers == 1 and local):
        yield from human.recorded(stream_nonlinear(human, motion, chunk_s=chunk_s, progress=progress,
                                                   pose_rate_hz=pose_rate_hz))
        return
    if human.model.settled is None:
        human.settle()  # once here, not in every worker: the recipe carries the settled state
    recipe = human.recipe()
    args = (chunk_s, pose_rate_hz, _ramp)
    done_s = 0.0
    remote = segments[1:] if local else segments
    with _Runner(client, min(n_workers - 1 if local else n_workers, len(remote))) as runner:
        submitted = time.time()
        futures = runner.submit_all(recipe, motion, remote, args)
        if local:  # the first segment here, chunk by chunk: the continuous run's start, bit for bit
            yield from human.recorded(stream_span(human, motion, 0, segments[0].stop, 0, chunk_s=chunk_s,
                                                  pose_rate_hz=pose_rate_hz))
            done_s = segments[0].stop * dt
            if _stats is not None:
                _stats["first_end"] = time.time()
            if progress:
                progress(min(done_s, motion.duration_s), motion.duration_s)
        for seg, fut in zip(remote, futures):
            pieces, times = runner.result(fut)
            if _stats is not None:
                _stats["tasks"].append({**times, "submitted": submitted, "received": time.time()})
            done_s += (seg.stop - seg.first) * dt
            while pieces:  # the segment's chunks, each let go once it is passed on
                yield from human.recorded([pieces.pop(0)])
            if progress:
                progress(min(done_s, motion.duration_s), motion.duration_s)


def stream_rest(human, motion: SeatMotion, start: int, workers: int, chunk_s: float, here,
                lead_in_s: float | None = None):
    """Grid steps ``start`` ... the end of ``motion`` on the nonlinear model in segments on ``workers`` processes,
    the first going on in this process from where the caller's run stands: ``here(stop)`` yields its chunks up to grid
    step ``stop``; every other segment runs on a worker from the settled rest after a lead-in of ``lead_in_s``
    (default :data:`DEFAULT_LEAD_IN_S`), as :func:`stream_parallel`'s do.  Yields the chunks in order, every
    ``chunk_s`` from ``start``.  (The hybrid route's rest of a drive, once its windows cover most of it.)"""
    human = built_of(human)
    dt = float(human.model.mj.opt.timestep)
    n_steps = Resampler.of_motion(motion, dt).n_samples
    per_chunk = max(1, int(round(chunk_s / dt)))
    lead = int(round((DEFAULT_LEAD_IN_S if lead_in_s is None else float(lead_in_s)) / dt))
    workers = capped_workers(int(workers))
    start_up = int(WORKER_START_S * STEPS_PER_WALL_S[human.model.seat is not None])
    spans = [Span(s.first + start, s.stop + start, 0 if s.first == 0 else min(lead, s.first + start))
             for s in plan_segments(n_steps - start, workers, lead, per_chunk, first_extra_steps=start_up)]
    if len(spans) == 1 or workers == 1:
        yield from here(n_steps)
        return
    if human.model.settled is None:
        human.settle()
    with _Runner(None, min(workers - 1, len(spans) - 1)) as runner:
        futures = runner.submit_all(human.recipe(), motion, spans[1:], (chunk_s, None, False))
        yield from here(spans[0].stop)
        for fut in futures:
            pieces, _ = runner.result(fut)
            while pieces:  # the segment's chunks, each let go once it is passed on
                yield pieces.pop(0)


@checked(only=("progress", "pose_rate_hz"))  # stream_parallel checks the rest itself, in its own words
def simulate_parallel(human, motion: SeatMotion, workers: int = 2, segment_s: float | None = None,
                      lead_in_s: float | None = None, client=None, progress: Callable | None = None,
                      pose_rate_hz: float | None = None) -> RunResult:
    """The nonlinear run of ``motion`` in segments on ``workers`` processes (or a Dask ``client``'s cluster), as
    one :class:`~ehm.RunResult` with the continuous run's time axis and fields; the arguments are
    :func:`~ehm.routes.parallel.stream_parallel`'s.  Within 1 % of the continuous run with the default lead-in (module
    docstring)."""
    return concatenate_runs(list(stream_parallel(human, motion, workers=workers, segment_s=segment_s,
                                                 lead_in_s=lead_in_s, client=client, progress=progress,
                                                 pose_rate_hz=pose_rate_hz)))


class _Runner:
    """Segments on local processes (spawned, SIGINT ignored, one thread each) or on a Dask client; on an error or
    Ctrl-C the local processes are stopped at once, and a Dask client's tasks cancelled."""

    def __init__(self, client, n: int):
        self.client, self.n, self.pool, self.futures, self.hand_over = client, n, None, [], None

    def __enter__(self):
        return self

    def submit_all(self, recipe, motion, segments, args):
        if self.client is not None:
            motion_f = self.client.scatter(motion, broadcast=True)
            recipe_f = self.client.scatter(recipe, broadcast=True)
            # largest work first is the plan's order already: the first segment has no lead-in but more steps
            self.futures = [self.client.submit(_run_segment, recipe_f, motion_f, s, *args, pure=False)
                            for s in segments]
            return self.futures
        import tempfile
        from concurrent.futures import ProcessPoolExecutor

        # results come back through files in memory (removed on leaving, whatever happens)
        shm = "/dev/shm"
        self.hand_over = tempfile.mkdtemp(prefix="ehm-segments-", dir=shm if os.path.isdir(shm) else None)
        # the processes are spawned while SIGINT is ignored (they inherit it: only this process answers Ctrl-C)
        # and with one thread each for the numerical libraries; submitting starts them all here
        with sigint_ignored(), environ_default(ONE_THREAD):
            self.pool = ProcessPoolExecutor(self.n, mp_context=multiprocessing.get_context("spawn"),
                                            initializer=ignore_sigint)
            return [self.pool.submit(_run_segment, recipe, motion, s, *args, self.hand_over) for s in segments]

    def result(self, future):
        out, times = future.result()
        return (out if self.hand_over is None else _from_file(out)), times

    def __exit__(self, kind, exc, tb):
        if self.client is not None:
            if kind is not None:
                import contextlib

                with contextlib.suppress(Exception):
                    self.client.cancel(self.futures)
            return False
        if self.pool is not None:
            if kind is not None:  # stop the workers now, not after their segments (and reap them)
                processes = list((getattr(self.pool, "_processes", None) or {}).values())
                for p in processes:
                    p.terminate()
                self.pool.shutdown(wait=False, cancel_futures=True)
                for p in processes:
                    p.join(2.0)
            else:
                self.pool.shutdown(wait=True)
        if self.hand_over is not None:
            import shutil

            shutil.rmtree(self.hand_over, ignore_errors=True)
        return False
