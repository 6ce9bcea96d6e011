"""Multi-start campaigns: reproducible starts, clustering, the store, resume, and dask."""

from __future__ import annotations

import os
import re
import signal
import sqlite3
import time

import numpy as np
import pandas as pd
import pytest

from railopt.design import (
    CampaignStore,
    DesignVariable,
    MinimaxProblem,
    check_designs,
    dask_client,
    distinct_optima,
    multistart,
    start_points,
)
from railopt.design.test_problems import minimax_test_problems

DETERMINISTIC = ["start_id", "origin", "x0_x1", "x0_x2", "x1", "x2", "value", "t", "status", "evaluations",
                 "solver", "seed", "constraint_violation", "bound_violation", "success", "cluster"]


def double_well() -> MinimaxProblem:
    """Two local minimax optima: w(x1) + x2², w(x1) + (x2 − 0.1)², w = (x1² − 1)² + 0.1 x1.

    The optimum has x2 = 0.05 and x1 at the outer roots of w' = 4x1(x1² − 1) + 0.1 = 0.
    """
    v = [DesignVariable("x1", -2.0, 2.0), DesignVariable("x2", -1.0, 1.0)]

    def f(x):
        w = (x[0] ** 2 - 1) ** 2 + 0.1 * x[0]
        return np.array([w + x[1] ** 2, w + (x[1] - 0.1) ** 2])

    return MinimaxProblem(v, f)


def test_same_seed_same_starts_and_user_points_first():
    sp = double_well().space
    a = start_points(sp, 8, seed=11, points=[[0.5, 0.5]])
    b = start_points(sp, 8, seed=11, points=[[0.5, 0.5]])
    c = start_points(sp, 8, seed=12)
    assert [s.origin for s in a[:2]] == ["user", "sobol"]
    np.testing.assert_array_equal(np.array([s.x0 for s in a]), np.array([s.x0 for s in b]))
    assert not np.allclose(np.array([s.x0 for s in a[1:]]), np.array([s.x0 for s in c]))
    lhs = start_points(sp, 16, sampler="lhs", seed=1)
    u = sp.to_u(np.array([s.x0 for s in lhs]))
    # Latin hypercube: one point in each of the 16 strata of every coordinate
    for j in range(2):
        assert sorted(np.floor(u[:, j] * 16).astype(int)) == list(range(16))


@pytest.mark.parametrize("field,kwargs", [("n_starts", {"n_starts": 0}), ("sampler", {"sampler": "halton"}),
                                          ("seed", {"seed": -1}), ("method", {"method": "bfgs"}),
                                          ("points[0]", {"points": [[9.0, 0.0]]})])
def test_bad_campaign_arguments_name_the_field(field, kwargs, tmp_path):
    args = {"n_starts": 4, **kwargs}
    path = tmp_path / "c.sqlite"
    store = CampaignStore.create(path, "c", {}, ["x1", "x2"])
    with pytest.raises(ValueError, match="^" + re.escape(field) + ":"):
        multistart(double_well(), store=store, **args)
    assert store.starts().empty  # refused before any start was written
    store.close()


def test_distinct_optima_are_clustered():
    p = double_well()
    table = multistart(p, 16, seed=3)
    optima = distinct_optima(table, p)
    assert len(optima) == 2
    # f' = 4x(x²−1) + 0.1 = 0 near ±1: compare with the root of the cubic
    roots = np.sort(np.roots([4, 0, -4, 0.1]).real)
    np.testing.assert_allclose(np.sort(optima["x1"].to_numpy()), roots[[0, 2]], atol=1e-6)
    np.testing.assert_allclose(optima["x2"], 0.05, atol=1e-6)
    assert optima["count"].sum() == table["success"].sum() == 16
    assert optima["value"].iloc[0] < optima["value"].iloc[1]  # sorted: global optimum is cluster 0


def test_store_round_trip_inf_and_no_duplicates(tmp_path):
    p = double_well()
    path = tmp_path / "c.sqlite"
    store = CampaignStore.create(path, "c", {"a": 1}, list(p.space.names))
    table = multistart(p, 4, seed=0, store=store)
    with pytest.raises(sqlite3.IntegrityError):  # start_id is the primary key
        from railopt.design import solve

        store.add_start(0, "user", 0, solve(p, [0.1, 0.1]))
    store.close()
    with CampaignStore.open(path, expect_config={"a": 1}) as s2:
        assert s2.meta()["schema_version"] == "1"
        assert len(s2.starts()) == 4
        pd.testing.assert_series_equal(s2.starts()["value"], table["value"])
    with pytest.raises(ValueError, match="different config"):
        CampaignStore.open(path, expect_config={"a": 2})
    with pytest.raises(FileExistsError, match="^store:"):
        CampaignStore.create(path, "c", {"a": 1}, list(p.space.names))


def test_interrupted_campaign_resumes_each_start_exactly_once(tmp_path):
    tp = minimax_test_problems()["CB2"]
    path = tmp_path / "c.sqlite"
    reference = multistart(tp.problem, 12, seed=5, points=[tp.start])

    class Interrupt(Exception):
        pass

    def stop_after_five(done, total):
        if done == 5:
            raise Interrupt

    store = CampaignStore.create(path, "c", {}, ["x1", "x2"])
    with pytest.raises(Interrupt):
        multistart(tp.problem, 12, seed=5, points=[tp.start], store=store, progress=stop_after_five)
    assert len(store.finished_ids()) == 5
    resumed = multistart(tp.problem, 12, seed=5, points=[tp.start], store=store)
    store.close()
    assert list(resumed["start_id"]) == list(range(13))
    pd.testing.assert_frame_equal(resumed[DETERMINISTIC], reference[DETERMINISTIC])


@pytest.fixture(scope="module")
def client():
    with dask_client(workers=2) as c:
        yield c


def test_local_cluster_gives_the_serial_table(client):
    assert len(client.scheduler_info()["workers"]) == 2
    tp = minimax_test_problems()["CB2"]
    serial = multistart(tp.problem, 16, seed=9, points=[tp.start])
    parallel = multistart(tp.problem, 16, seed=9, points=[tp.start], client=client)
    pd.testing.assert_frame_equal(parallel[DETERMINISTIC], serial[DETERMINISTIC])


def test_batched_starts_give_the_serial_table(client):
    """Short starts go several to a task (the batch chosen from the first starts' time): same rows, same order."""
    tp = minimax_test_problems()["CB2"]
    serial = multistart(tp.problem, 150, seed=4, points=[tp.start])
    calls = []

    def progress(done, total):
        calls.append((done, total))

    parallel = multistart(tp.problem, 150, seed=4, points=[tp.start], client=client, progress=progress)
    pd.testing.assert_frame_equal(parallel[DETERMINISTIC], serial[DETERMINISTIC])
    assert calls[0] == (0, 151) and calls[-1] == (151, 151) and len(calls) == 152  # every start reported


def _megabyte(i: int) -> np.ndarray:
    return np.full(125_000, float(i))  # 1 MB


def test_a_read_result_is_freed_on_the_worker(client):
    """map_unordered holds only the unfinished tasks: a result read by the driver leaves the worker's memory, so a
    long campaign's workers do not keep every result to its end (the 10,000-start memory row of ``railopt bench``)."""
    from railopt.design.parallel import map_unordered

    stream = map_unordered(_megabyte, range(40), client=client)
    seen = [float(next(stream)[0]) for _ in range(30)]
    deadline = time.monotonic() + 10.0  # releasing is a message to the scheduler, then to the workers
    while (held := sum(client.run(lambda dask_worker: len(dask_worker.data)).values())) > 10:
        if time.monotonic() > deadline:
            break
        time.sleep(0.05)
    assert held <= 10  # at most the 10 results not read yet (30 read and freed)
    seen += [float(r[0]) for r in stream]
    assert sorted(seen) == [float(i) for i in range(40)]


def test_batch_size_rule() -> None:
    """Guided self-scheduling: one start a task until a time is known, then about TASK_SECONDS a task, at most half
    a worker's even share of the starts left, 1 to MAX_BATCH."""
    from railopt.design.multistart import MAX_BATCH, TASK_SECONDS, TASK_SHARE, batch_size

    assert (TASK_SECONDS, TASK_SHARE, MAX_BATCH) == (0.25, 2, 16)  # the numbers the cases below are worked out with
    assert batch_size(10_000, 2, None) == 1  # no start finished yet: no time to size a batch from
    assert batch_size(10_000, 2, 0.04) == 7  # ceil(0.25 / 0.04)
    assert batch_size(10_000, 2, 1e-4) == MAX_BATCH
    assert batch_size(10_000, 2, 0.5) == 1  # long starts: one per task
    assert batch_size(40, 2, 1e-4) == 10  # ceil(40 / (2 × 2)): shrinking with the starts left
    assert batch_size(40, 5, 1e-4) == 4  # ceil(40 / (2 × 5))
    assert batch_size(3, 2, 1e-4) == 1
    assert batch_size(1, 1, 0.0) == 1  # a zero time does not divide by zero


def test_guided_batches_shrink_to_one_start_and_cover_every_start_once() -> None:
    """The sizes batch_size gives over a whole campaign: each start in one task, tasks never growing once the time
    is known, the last tasks one start each (no worker left holding a long task at the end)."""
    from railopt.design.multistart import batch_size

    for n, workers, seconds in [(64, 2, 0.015), (1024, 2, 0.015), (1000, 8, 1e-4), (33, 3, 0.1)]:
        sizes, left = [], n
        while left:
            sizes.append(batch_size(left, workers, seconds))
            left -= sizes[-1]
        assert sum(sizes) == n and all(a >= b for a, b in zip(sizes, sizes[1:], strict=False))
        assert sizes[-2 * workers:] == [1] * (2 * workers)  # the even share of the last starts is under one
        assert sizes[0] == min(16, -(-n // (2 * workers)), -(-0.25 // seconds))


def test_local_cluster_gives_the_serial_table_for_a_lapack_model(client):
    """Eigen-decompositions and complex solves round identically in workers and in-process."""
    from railopt.studies.cli import STUDIES_DIR
    from railopt.studies.config import load_study
    from railopt.studies.kinds.campaign import campaign_problem

    _, config, _ = load_study(STUDIES_DIR / "tmd_hinf.toml")
    problem = campaign_problem(config, config.setups()["mu0.05"], "exact")
    serial = multistart(problem, 8, seed=2002)
    parallel = multistart(problem, 8, seed=2002, client=client)
    cols = [c.replace("x1", "tuning").replace("x2", "damping_ratio") for c in DETERMINISTIC]
    pd.testing.assert_frame_equal(parallel[cols], serial[cols])


def slow_cb3() -> MinimaxProblem:
    base = minimax_test_problems()["CB3"].problem

    def f(x):
        time.sleep(0.01)
        return base.evaluate(x).f

    return MinimaxProblem(base.variables, f)


@pytest.mark.slow
def test_killed_worker_campaign_still_completes(client, tmp_path):
    problem = slow_cb3()
    store = CampaignStore.create(tmp_path / "c.sqlite", "c", {}, ["x1", "x2"])
    pids = list(client.run(os.getpid).values())
    killed = []

    def kill_one_worker(done, total):
        if done == 2 and not killed:
            os.kill(pids[0], signal.SIGKILL)
            killed.append(pids[0])

    table = multistart(problem, 12, method="cobyla", seed=2, client=client, store=store, progress=kill_one_worker)
    store.close()
    assert killed
    assert list(table["start_id"]) == list(range(12))
    assert table["success"].sum() >= 11
    assert np.nanmin(table["value"]) == pytest.approx(2.0, abs=1e-6)


def test_checks_of_optima_run_as_tasks_and_land_in_the_store(client, tmp_path):
    """A stability-style check: the spectral abscissa of x'' + 2ζω x' + ω² x = 0 is −ζω."""
    store = CampaignStore.create(tmp_path / "c.sqlite", "c", {}, ["zeta", "omega"])
    designs = pd.DataFrame({"start_id": [3, 1, 2], "zeta": [0.1, 0.3, 0.05], "omega": [2.0, 1.0, 10.0]})

    def abscissa(x):
        s = np.roots([1.0, 2 * x[0] * x[1], x[1] ** 2])
        return float(np.max(s.real)), {"stable": bool(np.max(s.real) < 0)}

    out = check_designs(abscissa, designs, ["zeta", "omega"], "spectral_abscissa", client=client, store=store)
    np.testing.assert_allclose(out["value"], [-0.3, -0.5, -0.2], rtol=1e-12)
    stored = store.checks()
    store.close()
    assert list(stored["start_id"]) == [1, 2, 3] and stored["payload"].map(lambda p: p["stable"]).all()
    np.testing.assert_allclose(stored["value"], out["value"], rtol=0)
