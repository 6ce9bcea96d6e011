"""Group commits: the starts of the tasks that finished together go into the store in one transaction.

What must hold (and is checked here): a group is written whole or not at all; a start reported by ``progress`` is
a start stored; a campaign killed in the middle of a group (``os._exit`` during its transaction) keeps every start
it had reported, loses only that group's and the running ones, and its resume stores every start exactly once with
the very rows of a serial run; grouping changes no number.  Values against the closed form of the test problem
f = ((a − 0.6)² + b, (b − 0.2)² + 0.1) on [0, 1]²: U* = 0.7 − √0.35 = 0.108392 at a = 0.6, where f1 = f2.
"""

from __future__ import annotations

import ast
import dataclasses
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from railopt.design import CampaignStore, DesignVariable, MinimaxProblem, multistart, solve
from railopt.design.parallel import map_unordered, map_unordered_groups
from railopt.design.store import DuplicateStart

U_STAR = 0.7 - np.sqrt(0.35)
VARIABLES = [DesignVariable("a", 0.0, 1.0), DesignVariable("b", 0.0, 1.0)]
DETERMINISTIC = ["start_id", "origin", "x0_a", "x0_b", "a", "b", "value", "t", "status", "evaluations", "solver",
                 "seed", "constraint_violation", "bound_violation", "success", "cluster"]


def _f(x: np.ndarray) -> np.ndarray:
    return np.array([(x[0] - 0.6) ** 2 + x[1], (x[1] - 0.2) ** 2 + 0.1])


PROBLEM = MinimaxProblem(VARIABLES, _f)


def _square(i: int) -> int:
    return i * i


def _nap_square(i: int) -> int:
    time.sleep(0.01)
    return i * i


@pytest.fixture(scope="module")
def client():
    from dask.distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster, \
            Client(cluster) as c:
        yield c


def test_a_group_is_written_whole_or_not_at_all(tmp_path: Path) -> None:
    result = solve(PROBLEM, [0.5, 0.5])
    with CampaignStore.create(tmp_path / "c.sqlite", "c", {}, ["a", "b"]) as store:
        store.add_starts([(0, "user", 0, result), (1, "sobol", 0, result)])
        with pytest.raises(DuplicateStart, match=r"start 1 is already stored"):
            store.add_starts([(2, "sobol", 0, result), (3, "sobol", 0, result), (1, "sobol", 0, result)])
        assert store.finished_ids() == {0, 1}  # 2 and 3 came with the duplicate: rolled back with it
        store.add_starts([])  # nothing: no transaction, no error
        lost = dataclasses.replace(result, status="worker_lost")
        store.add_starts([(5, "sobol", 0, lost), (6, "sobol", 0, result)])
        store.add_starts([(5, "sobol", 0, result)])  # a retried worker_lost start replaces its row, in a group too
        rows = store.starts().set_index("start_id")
    assert rows.loc[5, "status"] == result.status and sorted(rows.index) == [0, 1, 5, 6]
    assert rows["value"].tolist() == [result.value] * 4


def test_serially_every_group_holds_one_result() -> None:
    groups = list(map_unordered_groups(_square, range(7)))
    assert groups == [[i * i] for i in range(7)]


def test_on_dask_results_that_finished_together_come_in_one_group(client) -> None:
    stream = map_unordered_groups(_nap_square, range(40), client=client, most=16)
    first = next(stream)
    time.sleep(1.0)  # meanwhile every other task finishes (40 × 10 ms on 2 workers)
    rest = list(stream)
    groups = [first, *rest]
    assert sorted(v for g in groups for v in g) == [i * i for i in range(40)]  # every result once
    assert max(len(g) for g in groups) == 16  # the waiting results came together, 16 at most
    assert len(rest) <= 3  # 39 waiting results in groups of 16: 3 groups
    with pytest.raises(ValueError, match="^most: "):
        next(map_unordered_groups(_square, range(3), most=0))
    assert sorted(map_unordered(_square, range(10), client=client)) == [i * i for i in range(10)]


@pytest.mark.parametrize("window", [1, 3])
def test_a_window_draws_items_lazily_and_never_holds_more_unfinished(client, window) -> None:
    """With a window, an item is drawn only when the consumer asks for more, with at most ``window`` items drawn and
    not yet given back; with a window of 1 the result stream runs dry before every draw, and a new pump takes it
    over each time (no result lost, none twice)."""
    given = [0]
    ahead = []

    def items():
        for i in range(25):
            ahead.append(i + 1 - given[0])  # drawn so far (this one included) minus results given back
            yield i

    pumps = []
    start = threading.Thread.start

    def counted(thread):
        pumps.append(thread.name)
        return start(thread)

    threading.Thread.start = counted
    try:
        for group in map_unordered_groups(_nap_square, items(), client=client, window=window, most=4):
            given[0] += len(group)
            assert all(isinstance(v, int) for v in group)
    finally:
        threading.Thread.start = start
    assert given[0] == 25 and max(ahead) <= window and ahead[:window] == list(range(1, window + 1))
    if window == 1:  # every result left the stream empty before the next draw: a new pump each time
        assert pumps.count("railopt-as-completed") > 1
    # every result once, in any order, and serially the same lazy draw
    assert sorted(v for g in map_unordered_groups(_square, items(), client=client, window=window) for v in g) \
        == [i * i for i in range(25)]
    assert [g for g in map_unordered_groups(_square, iter(range(4)), window=2)] == [[0], [1], [4], [9]]
    assert list(map_unordered_groups(_square, iter(()), client=client, window=2)) == []


class _EndsAtOnce:
    """A result stream that ends at once, its tasks unfinished: what a client that broke down gives."""

    def __init__(self, futures) -> None:
        self.futures = list(futures)

    def update(self, futures) -> None:
        self.futures += list(futures)

    def __iter__(self):
        return iter(())


@pytest.mark.timeout(60)  # without the check, a pump would be started again and again: a hang
@pytest.mark.parametrize("window", [None, 2])
def test_a_stream_that_ends_with_tasks_unfinished_is_a_lost_scheduler_not_a_hang(client, monkeypatch, window):
    import distributed

    from railopt.design.parallel import SchedulerError

    monkeypatch.setattr(distributed, "as_completed", _EndsAtOnce)
    with pytest.raises(SchedulerError):
        list(map_unordered_groups(_nap_square, range(6), client=client, window=window))


def test_a_window_may_follow_the_cluster_and_is_checked_each_time(client) -> None:
    sizes = iter([1, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3])
    got = [v for g in map_unordered_groups(_square, range(12), client=client, window=lambda: next(sizes)) for v in g]
    assert sorted(got) == [i * i for i in range(12)]
    with pytest.raises(ValueError, match="^window: "):
        list(map_unordered_groups(_square, range(12), client=client, window=lambda: 0))


def test_a_window_is_checked_and_progress_needs_a_count() -> None:
    for bad in (0, -1, 1.5, True, "2"):
        with pytest.raises(ValueError, match="^window: "):
            next(map_unordered_groups(_square, range(3), window=bad))
    with pytest.raises(ValueError, match="^progress: "):
        next(map_unordered_groups(_square, iter(range(3)), window=2, progress=lambda d, t: None))
    calls = []
    groups = list(map_unordered_groups(_square, range(3), window=2, progress=lambda d, t: calls.append((d, t))))
    assert groups == [[0], [1], [4]] and calls == [(0, 3), (1, 3), (2, 3), (3, 3)]


def test_a_start_reported_is_a_start_stored_and_grouping_changes_no_number(client, tmp_path: Path) -> None:
    serial = multistart(PROBLEM, 40, seed=3)
    seen = []
    with CampaignStore.create(tmp_path / "c.sqlite", "c", {}, ["a", "b"]) as store:
        groups = []
        add = store.add_starts

        def spy(rows):
            rows = list(rows)
            groups.append(len(rows))
            add(rows)

        store.add_starts = spy  # type: ignore[method-assign]

        def progress(done: int, total: int) -> None:
            seen.append((done, len(store.finished_ids())))
            time.sleep(0.02)  # a slow consumer: results wait, and come in groups

        table = multistart(PROBLEM, 40, seed=3, client=client, store=store, batch=1, progress=progress)
    assert all(stored >= done for done, stored in seen)  # never reported before stored
    assert [d for d, _ in seen] == list(range(41))  # every start reported once (0 first)
    assert max(groups) > 1 and sum(groups) == 40  # grouped, every start once
    pd.testing.assert_frame_equal(table[DETERMINISTIC], serial[DETERMINISTIC])
    assert table["value"].min() == pytest.approx(U_STAR, abs=1e-7)


KILLED = textwrap.dedent("""
    import os, sys, time
    import numpy as np
    from dask.distributed import Client, LocalCluster
    import railopt.design.store as st
    from railopt.design import CampaignStore, DesignVariable, MinimaxProblem, multistart

    def f(x):
        return np.array([(x[0] - 0.6) ** 2 + x[1], (x[1] - 0.2) ** 2 + 0.1])

    problem = MinimaxProblem([DesignVariable("a", 0.0, 1.0), DesignVariable("b", 0.0, 1.0)], f)
    add = st.CampaignStore.add_starts
    multi = []

    def add_starts(self, rows):
        rows = list(rows)
        if len(rows) > 1:
            multi.append(len(rows))
        if len(multi) == 2:  # the second group of several: die after half of its rows were written, uncommitted
            vec, calls = st._vec, [0]

            def dying(a):
                calls[0] += 1
                if calls[0] > 3 * (len(rows) // 2):  # 3 vectors a row
                    print("dying in a group of", len(rows), flush=True)
                    os._exit(3)
                return vec(a)

            st._vec = dying
        return add(self, rows)

    st.CampaignStore.add_starts = add_starts
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster, \\
            Client(cluster) as client:
        store = CampaignStore.open(sys.argv[1])

        def progress(done, total):
            print("reported", done, sorted(store.finished_ids()) if done else [], flush=True)
            time.sleep(0.02)

        multistart(problem, 60, seed=8, client=client, store=store, batch=1, progress=progress)
    print("finished", flush=True)
""")


@pytest.mark.timeout(180)
def test_a_kill_in_the_middle_of_a_group_keeps_every_reported_start_and_resumes(tmp_path: Path) -> None:
    path = tmp_path / "c.sqlite"
    CampaignStore.create(path, "c", {}, ["a", "b"]).close()
    script = tmp_path / "killed.py"
    script.write_text(KILLED)
    run = subprocess.run([sys.executable, str(script), str(path)], capture_output=True, text=True, timeout=150)
    assert run.returncode == 3, run.stdout + run.stderr
    lines = run.stdout.splitlines()
    assert any(line.startswith("dying in a group of") for line in lines) and "finished" not in lines
    reported = [line for line in lines if line.startswith("reported")]
    last = int(reported[-1].split()[1])
    stored_then = set(ast.literal_eval(reported[-1].split(" ", 2)[2]))  # what the store held at the last report
    with CampaignStore.open(path) as store:
        stored = store.finished_ids()
        assert len(stored) == last and stored == stored_then  # the reported starts; the dying group left nothing
        before = store.starts()
        table = multistart(PROBLEM, 60, seed=8, store=store)  # the resume (serial here)
        after = store.starts()
    serial = multistart(PROBLEM, 60, seed=8)
    assert list(after["start_id"]) == list(range(60))  # every start exactly once
    pd.testing.assert_frame_equal(table[DETERMINISTIC], serial[DETERMINISTIC])  # the rows of a serial run
    kept = after[after["start_id"].isin(stored)].reset_index(drop=True)
    pd.testing.assert_frame_equal(kept, before.reset_index(drop=True))  # the stored starts, untouched
