"""``multistart``: many local solves from Sobol/LHS/user starts, streamed into a campaign store."""

from __future__ import annotations

import math
import numbers
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import nullcontext
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from railopt.design.parallel import (
    Shipped,
    WorkerLost,
    call,
    map_unordered_groups,
    no_progress,
    progress_of,
    resolve,
    shipping,
    worker_threads,
)
from railopt.design.problem import MinimaxProblem
from railopt.design.result import SolveResult, succeeded
from railopt.design.runner import Runner
from railopt.design.solve import method_options, solve
from railopt.design.starts import Start, start_points
from railopt.design.store import CampaignStore


@dataclass(frozen=True)
class _StartBatch:
    """Starts shipped to a worker as one task (NLopt objects are built there, inside :func:`solve`), solved one
    after the other: one start, or several short ones (dask's per-task cost amortised).  ``problem`` is the
    problem itself (serial) or the :class:`~railopt.design.parallel.Shipped` handle of the copy every worker got
    once for the campaign (dask)."""

    problem: MinimaxProblem | Shipped
    starts: tuple[Start, ...]
    method: str
    options: dict[str, Any]

    def __call__(self) -> list[tuple[Start, SolveResult]]:
        problem = resolve(self.problem)
        return [(s, solve(problem, s.x0, method=self.method, **self.options)) for s in self.starts]


@dataclass(frozen=True)
class _LostBatch:
    starts: tuple[Start, ...]


MAX_BATCH = 16  # starts per task at most: a killed campaign redoes at most this many per worker
COMMIT_TASKS = 32  # finished tasks committed in one store transaction at most (up to 32 × MAX_BATCH starts)
TASK_SHARE = 2  # a task holds at most 1/TASK_SHARE of a worker's even share of the starts left
TASK_SECONDS = 0.25  # a batch is made about this long: dask's per-task cost is a few ms of the driver's time
TASKS_IN_FLIGHT = 2  # unfinished tasks per worker: one running, one waiting at the scheduler
RECENT_STARTS = 64  # the batch is sized from the median time of at most this many latest starts
WORKERS_REFRESH_S = 2.0  # s between two questions to the scheduler about its workers during a campaign


def batch_size(n_todo: int, workers: int, start_seconds: float | None) -> int:
    """Starts in the next dask task (guided self-scheduling): one while no start has finished
    (``start_seconds`` None), else enough for a task of ``TASK_SECONDS`` at ``start_seconds`` a start (the median
    of the latest starts), no more than ``1/TASK_SHARE`` of a worker's even share of the ``n_todo`` starts
    left — tasks shrink towards the end, so no worker is left with a long one while the others idle — 1 to
    ``MAX_BATCH``."""
    if start_seconds is None:
        return 1
    enough = math.ceil(TASK_SECONDS / max(start_seconds, 1e-9))
    share = math.ceil(n_todo / (TASK_SHARE * max(workers, 1)))
    return int(max(1, min(MAX_BATCH, enough, share)))


class _WorkerThreads:
    """The threads of a cluster's workers, asked again at most every ``WORKERS_REFRESH_S`` seconds: workers that
    join a cluster during a campaign get work (the window of unfinished tasks grows with them)."""

    def __init__(self, client: Runner) -> None:
        self.client = client
        self.asked = -math.inf
        self.threads = 1 << 30  # until a scheduler answers: every start in a task of its own, all submitted at once

    def __call__(self) -> int:
        now = time.monotonic()
        if now - self.asked >= WORKERS_REFRESH_S:
            self.asked = now
            self.threads = worker_threads(self.client) or self.threads
        return self.threads


def _lost_batch(task: _StartBatch, lost: WorkerLost) -> _LostBatch:
    return _LostBatch(task.starts)


def _lost_starts(task: _StartBatch, lost: WorkerLost) -> list[tuple[Start, SolveResult]]:
    """The rows of starts whose task killed every worker it ran on: x = x0, U = inf, status ``worker_lost``."""
    rows = []
    for start in task.starts:
        x0 = np.asarray(start.x0, dtype=float)
        rows.append((start, SolveResult(
            x=x0, value=np.inf, t=np.inf, status="worker_lost",
            message=f"worker lost: {lost}; not retried on --resume unless asked (retry_failed)",
            evaluations=0, wall_time=0.0, method=task.method, x0=x0, constraint_violation=0.0, bound_violation=0.0,
        )))
    return rows


def multistart(
    problem: MinimaxProblem,
    n_starts: int,
    method: str = "slsqp",
    seed: int = 0,
    sampler: str = "sobol",
    points: Sequence[Sequence[float]] | None = None,
    client: Runner | None = None,
    store: CampaignStore | None = None,
    options: dict[str, Any] | None = None,
    progress: Callable[[int, int], None] | None = None,
    cluster_xtol: float = 1e-3,
    retry_failed: bool = False,
    batch: int | None = None,
) -> pd.DataFrame:
    """Solve from user ``points`` plus ``n_starts`` quasi-random starts; one row per start.

    Parameters
    ----------
    problem : MinimaxProblem
    n_starts : int
        Number of Sobol/LHS starts (> 0), in addition to ``points``.
    method : str
        A registered method (``slsqp``, ``cobyla``, ``slp``).
    seed : int
        Seed of the sampler: the same seed gives the same starts.
    sampler : {"sobol", "lhs"}
    points : sequence of designs, optional
        User starts (e.g. the existing suspension), ids 0.. before the sampled ones.
    client : Runner, optional
        A dask.distributed.Client (any :class:`~railopt.design.runner.Runner`).
        Runs the starts as dask tasks (one or a batch per task, see ``batch``); ``None`` runs serially in-process.
        The problem is sent to the workers once for the campaign (:func:`~railopt.design.parallel.shipping`),
        not with every task.
    store : CampaignStore, optional
        Finished starts already in it are skipped (resume); new ones are committed as they finish: the starts of
        the tasks that finished together (at most :data:`COMMIT_TASKS` tasks) in one transaction, never waiting
        for more.  ``progress`` reports a start only once it is committed.
    options : dict, optional
        Solver options (see :func:`railopt.design.solve.solve`).
    progress : callable(done, total), optional
        Called after every finished start, once it is stored (and first with the starts already stored); default:
        the enclosing :func:`~railopt.design.parallel.reporting_progress` block's, if any, counting starts.
    cluster_xtol : float
        Distance (∞-norm in unit-cube coordinates) under which optima count as the same.
    retry_failed : bool
        Re-run the stored starts whose task killed every worker it ran on (status ``worker_lost``);
        by default a resume skips them, as it skips every finished start.
    batch : int, optional
        Starts per dask task; default: guided by :func:`batch_size` — one start a task until a start has
        finished, then tasks of about 0.25 s at the median time of the latest starts, shrinking towards the end
        of the campaign, 1 to 16 starts.  Each task is sized when it is submitted, a few ahead of the workers
        (:data:`TASKS_IN_FLIGHT` per worker thread, the workers counted again every
        :data:`WORKERS_REFRESH_S` s): no worker waits for the first starts to finish.  A fixed ``batch``
        submits every task at once.
        Each start is solved, stored and reported exactly as alone: batching changes no number.

    A start whose task kills every dask worker that runs it (a crash in native code, out of memory)
    is stored with status ``worker_lost`` and the campaign goes on with the others.  The starts of a lost
    task run again one at a time, alone on the cluster, so only a start that crashes by itself is stored as lost.

    Raises
    ------
    ValueError
        Before any work: a bad method, option, seed, ``n_starts`` or point (naming the field), or a
        problem that cannot be sent to dask workers (naming what does not pickle).
    railopt.design.parallel.SchedulerError
        The dask scheduler was lost or has no workers; the finished starts are in the store.

    Returns
    -------
    pandas.DataFrame
        Sorted by ``start_id``; columns ``start_id, origin, x0_<var>…, <var>…, value, t, status,
        message, evaluations, wall_time, solver, seed, constraint_violation, bound_violation,
        success, cluster``.
    """
    method_options(method, options)  # validates method and options before any work is done
    if batch is not None and (isinstance(batch, bool) or not isinstance(batch, numbers.Integral) or batch < 1):
        raise ValueError(f"batch: must be a whole number of starts per task >= 1, got {batch!r}")
    starts = start_points(problem.space, n_starts, sampler=sampler, seed=seed, points=points)
    owned = store is None
    if owned:
        store = CampaignStore.in_memory(problem.space.names)
    try:
        done_ids = store.finished_ids(retry_failed=bool(retry_failed))
        todo = [s for s in starts if s.start_id not in done_ids]
        total, done = len(starts), len(starts) - len(todo)
        progress = progress_of(progress)  # else the enclosing reporting_progress block's, counting starts
        if progress is not None:
            progress(done, total)
        user_options = dict(options or {})

        seconds: list[float] = []  # solve times of the starts recorded so far

        def record(rows: list[tuple[Start, SolveResult]]) -> None:
            """Store ``rows`` in one transaction, then report them: a start reported is a start stored."""
            nonlocal done
            if not rows:
                return
            store.add_starts([(start.start_id, start.origin, seed, result) for start, result in rows])
            for _, result in rows:
                seconds.append(result.wall_time)
                done += 1
                if progress is not None:
                    progress(done, total)

        def run(tasks: Iterable[_StartBatch], on_lost: Callable = _lost_batch,
                window: Callable[[], int] | None = None) -> list[Start]:
            """Record every start of ``tasks``; return the starts of the tasks that were lost (``on_lost`` may
            instead give their rows, which are recorded).  The tasks that finished together are committed in one
            transaction (group commit: never waiting for more results to fill it).  With a ``window``, ``tasks``
            is drawn lazily (see :func:`~railopt.design.parallel.map_unordered_groups`)."""
            lost: list[Start] = []
            for group in map_unordered_groups(call, tasks, client=client, on_lost=on_lost, most=COMMIT_TASKS,
                                              window=window, progress=no_progress):  # progress: in starts, above
                rows: list[tuple[Start, SolveResult]] = []
                for out in group:
                    if isinstance(out, _LostBatch):
                        lost.extend(out.starts)
                    else:
                        rows.extend(out)
                record(rows)
            return lost

        # the problem goes to the workers once for the campaign (nothing to ship when every start is stored)
        with shipping(client, problem) if todo else nullcontext(problem) as shipped:

            def batches(starts: list[Start], size: int | None, workers: Callable[[], int] = lambda: 1
                        ) -> Iterator[_StartBatch]:
                """``starts`` in tasks of ``size`` starts, or (``None``) of :func:`batch_size` starts, each sized
                when it is drawn, from the times of the starts recorded by then."""
                i = 0
                while i < len(starts):
                    step = size or batch_size(len(starts) - i, workers(),
                                              float(np.median(seconds[-RECENT_STARTS:])) if seconds else None)
                    yield _StartBatch(shipped, tuple(starts[i:i + step]), method, user_options)
                    i += step

            if client is None or batch is not None:  # sizes known up front: every task submitted at once
                suspects = run(batches(todo, int(batch or 1)))
            else:  # a few tasks ahead of the workers, each sized when it is submitted: no wait for a probe
                workers = _WorkerThreads(client)
                suspects = run(batches(todo, None, workers), window=lambda: TASKS_IN_FLIGHT * workers())
            # A lost task's starts run again one at a time, each alone on the cluster: dask also holds a worker's
            # death against a task queued there, so only a start that kills two workers by itself is stored as lost.
            for start in suspects:
                run(batches([start], 1), on_lost=_lost_starts)
        table = store.starts()
    finally:
        if owned:
            store.close()
    return label_clusters(table, problem, cluster_xtol)


def label_clusters(table: pd.DataFrame, problem: MinimaxProblem, xtol: float = 1e-3) -> pd.DataFrame:
    """Add ``success`` and ``cluster`` columns: successful optima within ``xtol`` share a cluster.

    Clusters are numbered 0, 1, … in order of increasing best U; unsuccessful starts get −1.
    """
    table = table.copy()
    names = list(problem.space.names)
    success = np.asarray(succeeded(table["status"].to_numpy(), table["constraint_violation"].to_numpy(),
                                   table["bound_violation"].to_numpy(), table["value"].to_numpy(dtype=float)),
                         dtype=bool)
    table["success"] = success
    # the successful starts from the best U (ties: the lower start id); each joins the first representative within
    # xtol, else becomes the next one — on arrays (a per-row .loc cost ~1 ms a start: 10 s for 10,000 starts)
    order = np.lexsort((table["start_id"].to_numpy(), table["value"].to_numpy(dtype=float)))
    order = order[success[order]]
    u = problem.space.to_u(table[names].to_numpy(dtype=float))
    cluster = np.full(len(table), -1, dtype=int)
    reps = np.empty((len(order), len(names)))
    found = 0
    for i in order:
        near = np.flatnonzero(np.max(np.abs(reps[:found] - u[i]), axis=1) <= xtol)
        if near.size:
            cluster[i] = near[0]
        else:
            reps[found] = u[i]
            cluster[i] = found
            found += 1
    table["cluster"] = cluster
    return table


def distinct_optima(table: pd.DataFrame, problem: MinimaxProblem) -> pd.DataFrame:
    """One row per cluster: best U, how many starts found it, the best design and its start id."""
    names = list(problem.space.names)
    rows = []
    for k, grp in table[table["cluster"] >= 0].groupby("cluster"):
        best = grp.sort_values(["value", "start_id"]).iloc[0]
        rows.append({"cluster": int(k), "value": best["value"], "count": len(grp),
                     "best_start": int(best["start_id"]), **{n: best[n] for n in names}})
    return pd.DataFrame(rows, columns=["cluster", "value", "count", "best_start", *names])


__all__ = [
    "COMMIT_TASKS", "MAX_BATCH", "RECENT_STARTS", "TASKS_IN_FLIGHT", "TASK_SECONDS", "TASK_SHARE", "WORKERS_REFRESH_S",
    "batch_size", "distinct_optima",
    "label_clusters", "multistart",
]
