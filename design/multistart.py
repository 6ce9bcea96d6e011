"""``multistart``: many local solves from Sobol/LHS/user starts, streamed into a campaign store."""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Sequence
from contextlib import nullcontext
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from railopt.design.parallel import Shipped, WorkerLost, call, map_unordered_groups, resolve, shipping
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


MAX_BATCH = 8  # starts per task at most: a killed campaign redoes at most this many per worker
COMMIT_TASKS = 32  # finished tasks committed in one store transaction at most (up to 32 × MAX_BATCH starts)
TASKS_PER_WORKER = 8  # at least this many tasks per worker, so that uneven starts still balance
TASK_SECONDS = 0.25  # a batch is made about this long: dask's per-task cost is a few ms of the worker's time


def batch_size(n_todo: int, workers: int, start_seconds: float) -> int:
    """Starts per dask task: enough for a task of ``TASK_SECONDS`` at ``start_seconds`` a start (the median
    of the first starts), no more than keeps ``TASKS_PER_WORKER`` tasks per worker, 1 to ``MAX_BATCH``."""
    enough = math.ceil(TASK_SECONDS / max(start_seconds, 1e-9))
    balanced = n_todo // max(TASKS_PER_WORKER * workers, 1)
    return int(max(1, min(MAX_BATCH, enough, balanced)))


def _worker_threads(client: Runner) -> int:
    try:
        return max(sum(client.nthreads().values()), 1)
    except Exception:  # noqa: BLE001  (a scheduler that does not answer: one start per task, as before)
        return 1 << 30


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
        Called after every finished start, once it is stored.
    cluster_xtol : float
        Distance (∞-norm in unit-cube coordinates) under which optima count as the same.
    retry_failed : bool
        Re-run the stored starts whose task killed every worker it ran on (status ``worker_lost``);
        by default a resume skips them, as it skips every finished start.
    batch : int, optional
        Starts per dask task; default: one start on each worker first, then :func:`batch_size` from the
        median time of those (tasks of about 0.25 s, at least eight per worker, 1 to 8 starts) — or, when there
        are too few starts for a batch of two at any start time, one start per task from the outset (no wait for
        the first starts to finish).
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

        def run(tasks: list[_StartBatch], on_lost: Callable = _lost_batch) -> list[Start]:
            """Record every start of ``tasks``; return the starts of the tasks that were lost (``on_lost`` may
            instead give their rows, which are recorded).  The tasks that finished together are committed in one
            transaction (group commit: never waiting for more results to fill it)."""
            lost: list[Start] = []
            for group in map_unordered_groups(call, tasks, client=client, on_lost=on_lost, most=COMMIT_TASKS):
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

            def batches(starts: list[Start], size: int) -> list[_StartBatch]:
                return [_StartBatch(shipped, tuple(starts[i:i + size]), method, user_options)
                        for i in range(0, len(starts), size)]

            if client is None or batch is not None:
                suspects = run(batches(todo, int(batch or 1)))
            elif batch_size(len(todo) - (workers := _worker_threads(client)), workers, 0.0) == 1:
                suspects = run(batches(todo, 1))  # too few starts to batch, however short: no probe to wait for
            else:  # one start per worker first: how long a start takes decides the batch
                probe, rest = todo[:workers], todo[workers:]
                suspects = run(batches(probe, 1))
                size = batch_size(len(rest), workers, float(np.median(seconds)) if seconds else 0.0)
                suspects += run(batches(rest, size))
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
    "COMMIT_TASKS", "MAX_BATCH", "TASKS_PER_WORKER", "TASK_SECONDS", "batch_size", "distinct_optima",
    "label_clusters", "multistart",
]
