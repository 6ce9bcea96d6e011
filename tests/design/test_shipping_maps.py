"""Objective surfaces (``grid_map``), ε-constraint sweeps and design checks send their problem (or check) to the
workers once, like a campaign: tasks of under 2 kB where the problem pickles to ~400 kB, and the results equal to
a serial run's, bit for bit (the transport changes, not the numbers).  Test problem and closed form as in
test_scatter_dispatch.py: U = max((a − 0.6)² + b, (b − 0.2)² + 0.1) on [0, 1]²; the ε-sweep's constraint
g = a, so at ε ≥ 0.6 the optimum is the unconstrained U* = 0.7 − √0.35."""

from __future__ import annotations

from dataclasses import dataclass

import cloudpickle
import numpy as np
import pandas as pd
import pytest

from railopt.design import DesignVariable, MinimaxProblem, check_designs, dask_client, epsilon_sweep, grid_map
from tests.design.test_scatter_dispatch import PROBLEM, U_STAR, Heavy


@dataclass(frozen=True)
class HeavyConstraint:
    weight: np.ndarray

    def __call__(self, x: np.ndarray) -> np.ndarray:
        return np.array([x[0] + self.weight[0]])


CONSTRAINED = MinimaxProblem([DesignVariable("a", 0.0, 1.0), DesignVariable("b", 0.0, 1.0)], Heavy(np.zeros(50_000)),
                             constraints=HeavyConstraint(np.zeros(50_000)), epsilon=1.0)


@dataclass(frozen=True)
class HeavyCheck:
    weight: np.ndarray

    def __call__(self, x: np.ndarray):
        return float(x[0] + x[1] + self.weight[0]), {"sum": float(x.sum())}


@pytest.fixture(scope="module")
def client():
    with dask_client(workers=2) as c:
        yield c


def _spy(client, sizes):
    submit = client.map

    def spy_map(fn, items, **kwargs):
        items = list(items)
        sizes.extend(len(cloudpickle.dumps(item)) for item in items)
        return submit(fn, items, **kwargs)

    return spy_map


@pytest.mark.timeout(240)
def test_surface_sweep_and_checks_ship_once_and_equal_serial(client):
    sizes: list[int] = []
    original = client.map
    client.map = _spy(client, sizes)
    try:
        fn = PROBLEM.value
        xi, xj = np.linspace(0.1, 0.9, 5), np.linspace(0.0, 0.5, 4)
        grid = grid_map(fn, ["a", "b"], ("a", "b"), xi, xj, [0.5, 0.5], client=client)
        sweep = epsilon_sweep(CONSTRAINED, [0.3, 0.8], n_starts=2, seed=1, client=client)
        designs = pd.DataFrame({"start_id": [0, 1, 2], "a": [0.1, 0.2, 0.3], "b": [0.4, 0.5, 0.6]})
        checks = check_designs(HeavyCheck(np.zeros(50_000)), designs, ["a", "b"], "sum", client=client)
    finally:
        client.map = original
    assert len(cloudpickle.dumps(CONSTRAINED)) > 400_000 and sizes and max(sizes) < 2_000
    np.testing.assert_array_equal(grid, grid_map(fn, ["a", "b"], ("a", "b"), xi, xj, [0.5, 0.5]))
    serial = epsilon_sweep(CONSTRAINED, [0.3, 0.8], n_starts=2, seed=1)
    pd.testing.assert_frame_equal(sweep, serial)
    assert sweep["value"].iloc[1] == pytest.approx(U_STAR, abs=1e-7)
    pd.testing.assert_frame_equal(checks, check_designs(HeavyCheck(np.zeros(50_000)), designs, ["a", "b"], "sum"))
    np.testing.assert_allclose(checks["value"], designs["a"] + designs["b"])
