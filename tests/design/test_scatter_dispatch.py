"""The problem is sent to the workers once per campaign (a worker plugin), not with every task.

Checked on a real LocalCluster of 2 worker processes: one shipment per campaign, tasks of under 2 kB where the
problem pickles to ~400 kB, the shipment removed from the scheduler and every worker when the campaign ends, a
worker started afresh (``client.restart``) gets it too, and the stored starts are bit-for-bit those of a serial run
(the transport changes, not the numbers).  The closed form of the test problem: f = ((a − 0.6)² + b + 0·w,
(b − 0.2)² + 0.1) on [0, 1]², U* = 0.7 − √0.35 = 0.108392 at a = 0.6, where f1 = f2 (w: 50,000 zeros, only weight).
Also the marking of ``railopt bench``'s parallel rows on a busy machine (a pure function of the measured ceiling).
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from pathlib import Path

import cloudpickle
import numpy as np
import pandas as pd
import pytest

from railopt.design import CampaignStore, DesignVariable, MinimaxProblem, dask_client, multistart
from railopt.design.parallel import Shipped, map_unordered, resolve, shipping

U_STAR = 0.7 - np.sqrt(0.35)
DETERMINISTIC = ["start_id", "origin", "x0_a", "x0_b", "a", "b", "value", "t", "status", "evaluations", "solver",
                 "seed", "constraint_violation", "bound_violation", "success", "cluster"]


@dataclass(frozen=True)
class Heavy:
    """The test problem's functions carrying 400 kB of zeros, as a model carries its matrices."""

    weight: np.ndarray

    def __call__(self, x: np.ndarray) -> np.ndarray:
        return np.array([(x[0] - 0.6) ** 2 + x[1] + self.weight[0], (x[1] - 0.2) ** 2 + 0.1])


PROBLEM = MinimaxProblem([DesignVariable("a", 0.0, 1.0), DesignVariable("b", 0.0, 1.0)], Heavy(np.zeros(50_000)))


def _names(problem) -> list[str]:
    return list(resolve(problem).space.names)


@pytest.fixture(scope="module")
def client():
    with dask_client(workers=2) as c:
        yield c


def _railopt_plugins(client) -> tuple[list[str], list[str]]:
    on_scheduler = client.run_on_scheduler(lambda dask_scheduler: list(dask_scheduler.worker_plugins))
    on_workers = client.run(lambda dask_worker: list(dask_worker.plugins))
    mine = [n for n in on_scheduler if n.startswith("railopt-")]
    return mine, sorted({n for names in on_workers.values() for n in names if n.startswith("railopt-")})


@pytest.mark.timeout(180)
def test_a_campaign_ships_its_problem_once_and_stores_the_serial_rows(client, tmp_path: Path) -> None:
    assert len(cloudpickle.dumps(PROBLEM)) > 400_000
    registered, sizes = [], []
    register, submit = client.register_plugin, client.map

    def spy_register(plugin, name=None):
        registered.append(name)
        return register(plugin, name=name)

    def spy_map(fn, items, **kwargs):
        items = list(items)
        sizes.extend(len(cloudpickle.dumps(item)) for item in items)
        return submit(fn, items, **kwargs)

    client.register_plugin, client.map = spy_register, spy_map
    try:
        with CampaignStore.create(tmp_path / "c.sqlite", "c", {}, ["a", "b"]) as store:
            table = multistart(PROBLEM, 40, seed=6, client=client, store=store)  # one start a task, then batches
            stored = store.starts()
    finally:
        del client.register_plugin, client.map
    assert len(registered) == 1  # one shipment for the campaign's maps (the first tasks and the refills)
    assert len(sizes) >= 3 and max(sizes) < 2_000  # every task carries a handle and its starts, not the problem
    assert _railopt_plugins(client) == ([], [])  # let go of on the scheduler and on every worker
    serial = multistart(PROBLEM, 40, seed=6)
    pd.testing.assert_frame_equal(table[DETERMINISTIC], serial[DETERMINISTIC])  # bit for bit: rtol 0
    stored_cols = DETERMINISTIC[:-2]  # the store's own columns (success and cluster are labels of the table)
    pd.testing.assert_frame_equal(stored[stored_cols], serial[stored_cols])
    assert all(np.array_equal(a, b) for a, b in zip(stored["functions"], serial["functions"], strict=True))
    assert table["value"].min() == pytest.approx(U_STAR, abs=1e-7)


def _task_sizes(client, n_starts: int, **kwargs) -> tuple[pd.DataFrame, list[list[int]]]:
    """A campaign's table and, for each ``client.map`` it made, the starts in each task of that map."""
    seen: list[list[int]] = []
    submit = client.map

    def spy_map(fn, items, **map_kwargs):
        items = list(items)
        seen.append([len(item.starts) for item in items])
        return submit(fn, items, **map_kwargs)

    client.map = spy_map
    try:
        return multistart(PROBLEM, n_starts, seed=6, client=client, **kwargs), seen
    finally:
        del client.map


@pytest.mark.timeout(180)
@pytest.mark.parametrize("n_starts", [12, 40])
def test_a_campaign_submits_a_few_tasks_ahead_each_sized_when_submitted(client, n_starts, monkeypatch) -> None:
    """No probe to wait for: the first map is TASKS_IN_FLIGHT one-start tasks per worker (no start's time is known
    yet), and every later map refills the window as results come, with tasks sized by batch_size from the times
    recorded by then — never more than the window unfinished, every start in exactly one task, the table a serial
    run's."""
    from railopt.design.multistart import MAX_BATCH, TASK_SECONDS, TASKS_IN_FLIGHT, batch_size

    timed = []  # the start times batch_size was given (a loaded machine can make a start look long)

    def spy(n_todo: int, workers: int, start_seconds: float | None) -> int:
        timed.append(start_seconds)
        return batch_size(n_todo, workers, start_seconds)

    monkeypatch.setattr(sys.modules["railopt.design.multistart"], "batch_size", spy)  # the module, not the function
    window = TASKS_IN_FLIGHT * 2
    table, seen = _task_sizes(client, n_starts)
    assert seen[0] == [1] * window  # one start a task until a time is known: nothing waits on a probe map
    assert len(seen) > 1 and all(len(sizes) <= window for sizes in seen[1:])  # the rest drawn as results came
    assert sum(map(sum, seen)) == n_starts and max(max(sizes) for sizes in seen) <= MAX_BATCH
    # the starts take well under a millisecond: once timed, tasks hold half a worker's share of what is left
    share = -(-(n_starts - window) // 4)
    assert timed[:window] == [None] * window and timed[window] is not None
    if timed[window] <= TASK_SECONDS / share:  # else a start was slowed by other work: sized by its time instead
        assert seen[1][0] == batch_size(n_starts - window, 2, 1e-3) == share > 1
    assert seen[1][0] == batch_size(n_starts - window, 2, timed[window]) > 1
    pd.testing.assert_frame_equal(table[DETERMINISTIC], multistart(PROBLEM, n_starts, seed=6)[DETERMINISTIC])


@pytest.mark.timeout(180)
def test_a_fixed_batch_submits_every_task_at_once(client) -> None:
    table, seen = _task_sizes(client, 40, batch=3)
    assert seen == [[3] * 13 + [1]]
    pd.testing.assert_frame_equal(table[DETERMINISTIC], multistart(PROBLEM, 40, seed=6)[DETERMINISTIC])


@pytest.mark.timeout(180)
def test_a_campaign_inside_a_progress_block_reports_its_starts(client) -> None:
    """A trade-off sweep runs its campaigns inside ``reporting_progress``: a campaign drawing its tasks lazily
    reports to that block in starts (0 first, then every start once), as it does to its own ``progress``."""
    from railopt.design.parallel import reporting_progress

    calls: list[tuple[int, int]] = []
    with reporting_progress(lambda done, total: calls.append((done, total))):
        table = multistart(PROBLEM, 24, seed=6, client=client)
    assert calls == [(k, 24) for k in range(25)]
    pd.testing.assert_frame_equal(table[DETERMINISTIC], multistart(PROBLEM, 24, seed=6)[DETERMINISTIC])


def test_the_worker_count_is_asked_again_as_workers_join(monkeypatch) -> None:
    """The window of a campaign follows the cluster: the threads are asked again every WORKERS_REFRESH_S s, an
    unanswered question keeps the last count, and before any answer every task goes at once (1 << 30)."""
    import importlib

    ms = importlib.import_module("railopt.design.multistart")
    answers = iter([None, 2, None, 6])
    monkeypatch.setattr(ms, "worker_threads", lambda client: next(answers))
    monkeypatch.setattr(ms, "WORKERS_REFRESH_S", 0.0)
    threads = ms._WorkerThreads(object())
    assert [threads() for _ in range(4)] == [1 << 30, 2, 2, 6]
    monkeypatch.setattr(ms, "WORKERS_REFRESH_S", 3600.0)
    assert threads() == 6  # not asked again within the hour (the iterator would be exhausted)


@pytest.mark.timeout(60)
def test_worker_threads_counts_the_threads_of_a_real_cluster(client) -> None:
    from railopt.design.parallel import worker_threads

    assert worker_threads(client) == 2 == sum(client.nthreads().values())


@pytest.mark.timeout(180)
def test_workers_started_afresh_get_the_shipped_problem(client) -> None:
    with shipping(client, PROBLEM) as handle:
        assert isinstance(handle, Shipped) and len(cloudpickle.dumps(handle)) < 200
        assert list(map_unordered(_names, [handle] * 4, client=client)) == [["a", "b"]] * 4
        client.restart()  # every worker process replaced: the scheduler hands the plugin to the new ones
        assert list(map_unordered(_names, [handle] * 4, client=client)) == [["a", "b"]] * 4
    assert _railopt_plugins(client) == ([], [])
    with pytest.raises(RuntimeError, match="not on worker"):  # after the campaign the handle resolves no more
        list(map_unordered(_names, [handle], client=client))


def test_serially_nothing_is_shipped_and_a_handle_resolves_only_in_a_task() -> None:
    with shipping(None, PROBLEM) as same:
        assert same is PROBLEM and resolve(same) is PROBLEM
    with pytest.raises(RuntimeError, match="only inside a dask task"):
        Shipped("railopt-problem-x").get()


# ---------------------------------------------------------------------- railopt bench on a busy machine
def test_parallel_rows_are_marked_when_the_ceiling_is_below_1_8() -> None:
    from railopt.studies.bench import BUSY_CEILING, busy_marked

    row = {"benchmark": "multistart throughput", "ours_s": 0.01, "reference_s": 0.02, "ratio": 0.5,
           "reference": "serial", "note": "100 starts/s"}
    assert BUSY_CEILING == 1.8
    assert busy_marked(row, 1.85, 2) == row  # a free machine: the row is a result
    busy = busy_marked(row, 1.34, 2)
    assert busy["benchmark"] == "[machine busy: not a result] multistart throughput"
    assert math.isnan(busy["ratio"])  # no ratio printed as a result
    assert busy["note"] == ("machine busy: 2 plain processes reached 1.34× one alone (< 1.8×); measured ratio 0.5; "
                            "100 starts/s")
    assert busy["ours_s"] == row["ours_s"] and row["ratio"] == 0.5  # the measurement kept, the input untouched
