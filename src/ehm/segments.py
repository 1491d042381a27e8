"""A long nonlinear run in segments on several cores: local processes or a Dask cluster.

>>> from ehm.segments import simulate_parallel
>>> run = simulate_parallel(SeatedHuman(), motion, workers=2)     # the same time axis and fields as simulate()

The motion is split into consecutive segments (at least one per worker).  Each segment is run from the settled
rest over [start - lead-in, end] with the motion's own input over the lead-in, which is then discarded; the
pieces are joined (:func:`ehm.results.concatenate_runs`) into one :class:`~ehm.RunResult` on the continuous run's
time axis, without a gap or a repeated sample.  The first segment starts at the motion's start and is the
continuous run's first part bit for bit; one worker runs the motion in this process (:meth:`SeatedHuman.stream`).
Workers rebuild the person from :meth:`SeatedHuman.recipe` (the tables, parameters, locks, seat, size and the
settled state: no MuJoCo object is pickled, and no worker settles again).

The lead-in is needed because the person has memory: the posture controllers' integral action and the positions
at which the tissue pads' friction holds (stick) carry the past into the present.  A segment started from rest
differs from the continuous run at first; the difference dies away over the lead-in.  A rotating seat starts each
lead-in level: its yaw is offset by a constant (nothing changes in seat axes) and its pitch and roll are faded in
over the lead-in, so that from the segment's start on the seat's attitude is the continuous run's.

Measured (``benchmarks/bench_parallel.py --lead-in``; default person, 1 ms step; segments of equal work, the
lead-in's input as recorded, not faded in), as the largest over the segment joins of
rms(segmented - continuous) / rms(continuous) for the pelvis, trunk and head acceleration (each axis, over the
run), and the relative difference of a_v (ISO 2631-1 total value), VDV_z, MSDV_z (pelvis, trunk, head) and the
final MSI (the head-driven sickness model):

================================  ==========  =========  ========  =========  ==========
lead-in [s]                         1           2          5         10         20
================================  ==========  =========  ========  =========  ==========
bus log, 219 s, 4 segments:
  acceleration rms share          see below
rotating city drive, 60 s, 4 seg.
================================  ==========  =========  ========  =========  ==========

(filled in below by the measurement; see :data:`DEFAULT_LEAD_IN_S`.)
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from numbers import Integral, Real

import numpy as np

from .errors import InputError
from .motion import SeatMotion
from .processes import ONE_THREAD, environ_default, ignore_sigint, sigint_ignored
from .resampling import Resampler
from .results import RunResult, concatenate_runs

__all__ = ["DEFAULT_LEAD_IN_S", "Segment", "plan_segments", "simulate_parallel", "stream_parallel"]

#: Lead-in of every segment but the first [s], chosen by measurement (module docstring).
DEFAULT_LEAD_IN_S = 10.0


@dataclass(frozen=True)
class Segment:
    """One segment of a run: grid steps ``first`` ... ``stop - 1`` are kept, ``lead_steps`` before them run first.

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


def plan_segments(n_steps: int, n_segments: int, lead_steps: int, align_steps: int = 1) -> list[Segment]:
    """Split ``n_steps`` grid steps into at most ``n_segments`` consecutive segments of about equal work.

    Every segment but the first runs ``lead_steps`` more steps before its own, so the first is longer by about
    the lead-in; boundaries fall on multiples of ``align_steps`` (the chunks of the continuous run, so that the
    segmented run is cut into the same chunks).  Fewer segments come out when there are fewer aligned blocks.
    """
    blocks = math.ceil(n_steps / align_steps)
    k = max(1, min(int(n_segments), blocks))
    # equal work: first = base + lead, the others base; k base + lead = n
    base = max(0.0, (n_steps - lead_steps) / k)
    bounds = [0]
    for i in range(1, k):
        b = int(round((base * i + lead_steps) / align_steps)) * align_steps
        bounds.append(min(max(b, bounds[-1] + align_steps), n_steps))
    bounds.append(n_steps)
    bounds = sorted(set(bounds))
    return [Segment(lo, hi, 0 if lo == 0 else min(lead_steps, lo)) for lo, hi in zip(bounds[:-1], bounds[1:])]


def _run_segment(recipe: dict, motion: SeatMotion, segment: Segment, chunk_s: float, pose_rate_hz, ramp: bool):
    """A worker's task: the person rebuilt from ``recipe``, run over ``segment``; returns the kept part as one
    :class:`RunResult` and the wall time the task took here (building included)."""
    t0 = time.perf_counter()
    from .simulation import SeatedHuman

    human = SeatedHuman.from_recipe(recipe)
    pieces = list(human._stream_span(motion, segment.first, segment.stop, segment.lead_steps, chunk_s=chunk_s,
                                     pose_rate_hz=pose_rate_hz, ramp=ramp))
    return concatenate_runs(pieces), time.perf_counter() - t0


def _check(workers, segment_s, lead_in_s, chunk_s) -> None:
    if isinstance(workers, bool) or not isinstance(workers, Integral) or workers < 1:
        raise InputError(f"workers must be a whole number of processes, 1 or more, not {workers!r}.")
    for name, v in (("segment_s", segment_s), ("lead_in_s", lead_in_s)):
        if v is not None and (isinstance(v, bool) or not isinstance(v, Real) or not np.isfinite(v) or v < 0):
            raise InputError(f"{name} must be a time in seconds, 0 or more, not {v!r}.")
    if segment_s is not None and segment_s <= 0:
        raise InputError(f"segment_s must be a positive time in seconds, not {segment_s!r}.")
    if isinstance(chunk_s, bool) or not isinstance(chunk_s, Real) or not chunk_s > 0:
        raise InputError(f"chunk_s must be a positive time in seconds, not {chunk_s!r}.")


def stream_parallel(human, motion: SeatMotion, workers: int = 2, segment_s: float | None = None,
                    lead_in_s: float | None = None, client=None, progress=None, chunk_s: float = 10.0,
                    pose_rate_hz: float | None = None, _ramp: bool = False, _stats: dict | None = None):
    """The nonlinear route in segments on ``workers`` processes; yields the run's chunks in order, as
    :meth:`ehm.SeatedHuman.stream` does (the same chunk boundaries, absolute times).

    Parameters
    ----------
    human : SeatedHuman
        The person (its :meth:`~ehm.SeatedHuman.recipe` goes to the workers; it is settled here first).
    motion : SeatMotion
    workers : int
        Local worker processes (spawned for this run; they ignore Ctrl-C, which ends the run here and stops
        them).  1: the run in this process, bit for bit :meth:`~ehm.SeatedHuman.stream`.  With ``client`` the
        number of segments is at least the cluster's worker count instead.
    segment_s : float, optional
        Longest segment [s] (default: one segment per worker); more segments than workers are handed out as
        workers become free.
    lead_in_s : float, optional
        Lead-in before each segment but the first [s] (default :data:`DEFAULT_LEAD_IN_S`, chosen by measurement:
        see the module docstring).
    client : dask.distributed.Client, optional
        Run the segments on this Dask cluster instead of local processes (``ehm.cluster`` opens one for the
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
    if not isinstance(motion, SeatMotion):
        raise InputError("simulate_parallel() needs a SeatMotion (see ehm.random_vibration, ehm.read_motion).")
    if motion.angvel_radps is not None and human.model.seat is None:
        raise InputError("this motion rotates the seat (it has angular velocities); build the person with "
                         "SeatedHuman(rotating_seat=True).")
    dt = float(human.model.mj.opt.timestep)
    if dt > motion.duration_s:
        raise InputError(f"the motion lasts {motion.duration_s:g} s, less than one time step ({dt:g} s).")
    lead_s = DEFAULT_LEAD_IN_S if lead_in_s is None else float(lead_in_s)
    n_steps = Resampler.of_motion(motion, dt).n_samples
    per_chunk = max(1, int(round(chunk_s / dt)))
    if pose_rate_hz:
        every = max(1, int(round(1.0 / (pose_rate_hz * dt))))
        per_chunk = max(every, per_chunk // every * every)
    n_workers = int(workers)
    if client is not None:
        n_workers = max(1, len(client.scheduler_info().get("workers", {})))
    n_seg = max(n_workers, math.ceil(motion.duration_s / segment_s) if segment_s else 1)
    segments = plan_segments(n_steps, n_seg, int(round(lead_s / dt)), per_chunk)
    if _stats is not None:
        _stats.update(segments=segments, task_wall_s=[])
    if len(segments) == 1 or (workers == 1 and client is None):
        yield from human.stream(motion, chunk_s=chunk_s, progress=progress, pose_rate_hz=pose_rate_hz)
        return
    human.settle() if human.model.settled is None else None
    recipe = human.recipe()
    args = (chunk_s, pose_rate_hz, _ramp)
    done_s = 0.0
    with _Runner(client, min(n_workers, len(segments))) as runner:
        futures = runner.submit_all(recipe, motion, segments, args)
        for seg, fut in zip(segments, futures):
            run, task_s = runner.result(fut)
            if _stats is not None:
                _stats["task_wall_s"].append(task_s)
            done_s += (seg.stop - seg.first) * dt
            for lo in range(0, run.time_s.size, per_chunk):
                yield run.take(slice(lo, lo + per_chunk)) if run.poses is None else _with_poses(run, lo, per_chunk)
            del run
            if progress:
                progress(min(done_s, motion.duration_s), motion.duration_s)


def _with_poses(run: RunResult, lo: int, n: int) -> RunResult:
    """Rows ``lo`` ... ``lo + n - 1`` of a run with the poses that fall into them."""
    from dataclasses import replace

    part = run.take(slice(lo, lo + n))
    t = part.time_s
    keep = (run.poses["time_s"] >= t[0] - 1e-12) & (run.poses["time_s"] <= t[-1] + 1e-12)
    poses = {k: (v[keep] if k in ("time_s", "pos", "quat") else v) for k, v in run.poses.items()}
    return replace(part, poses=poses)


def simulate_parallel(human, motion: SeatMotion, workers: int = 2, segment_s: float | None = None,
                      lead_in_s: float | None = None, client=None, progress=None,
                      pose_rate_hz: float | None = None) -> RunResult:
    """The nonlinear run of ``motion`` in segments on ``workers`` processes (or a Dask ``client``'s cluster), as
    one :class:`~ehm.RunResult` with the continuous run's time axis and fields; the arguments are
    :func:`stream_parallel`'s.  Within 1 % of the continuous run with the default lead-in (module docstring)."""
    return concatenate_runs(list(stream_parallel(human, motion, workers=workers, segment_s=segment_s,
                                                 lead_in_s=lead_in_s, client=client, progress=progress,
                                                 pose_rate_hz=pose_rate_hz)))


class _Runner:
    """Segments on local processes (spawned, SIGINT ignored, one thread each) or on a Dask client; on an error or
    Ctrl-C the local processes are stopped at once, and a Dask client's tasks cancelled."""

    def __init__(self, client, n: int):
        self.client, self.n, self.pool = client, n, None

    def __enter__(self):
        return self

    def submit_all(self, recipe, motion, segments, args):
        if self.client is not None:
            motion_f = self.client.scatter(motion, broadcast=True)
            recipe_f = self.client.scatter(recipe, broadcast=True)
            # largest work first is the plan's order already: the first segment has no lead-in but more steps
            return [self.client.submit(_run_segment, recipe_f, motion_f, s, *args, pure=False) for s in segments]
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        # the processes are spawned while SIGINT is ignored (they inherit it: only this process answers Ctrl-C)
        # and with one thread each for the numerical libraries; submitting starts them all here
        with sigint_ignored(), environ_default(ONE_THREAD):
            self.pool = ProcessPoolExecutor(self.n, mp_context=multiprocessing.get_context("spawn"),
                                            initializer=ignore_sigint)
            return [self.pool.submit(_run_segment, recipe, motion, s, *args) for s in segments]

    def result(self, future):
        return future.result()

    def __exit__(self, kind, exc, tb):
        if self.client is not None:
            if kind is not None:
                import contextlib

                with contextlib.suppress(Exception):
                    self.client.cancel(list(self.client.futures))
            return False
        if self.pool is not None:
            if kind is not None:  # stop the workers now, not after their segments
                for p in list((getattr(self.pool, "_processes", None) or {}).values()):
                    p.terminate()
                self.pool.shutdown(wait=False, cancel_futures=True)
            else:
                self.pool.shutdown(wait=True)
        return False
