"""Faults: oversized numbers (seed, maxeval, n_starts) are refused naming the field, before any work."""

from __future__ import annotations

import numpy as np
import pytest

from railopt.design import CampaignStore, DesignVariable, MinimaxProblem, multistart, start_points
from railopt.design.solve import MAX_EVAL, method_options
from railopt.design.starts import MAX_SEED, MAX_STARTS

CALLS: list[np.ndarray] = []


def _f(x: np.ndarray) -> np.ndarray:
    CALLS.append(x)
    return np.array([(x[0] - 0.6) ** 2 + x[1], (x[1] - 0.2) ** 2 + 0.1])


def _problem() -> MinimaxProblem:
    return MinimaxProblem([DesignVariable("a", 0.0, 1.0), DesignVariable("b", 0.0, 1.0)], _f)


def test_limits_are_what_sqlite_and_nlopt_hold() -> None:
    assert MAX_SEED == np.iinfo(np.int64).max and MAX_EVAL == np.iinfo(np.int32).max and MAX_STARTS == 10**7


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"seed": 2**70}, "seed"),
        ({"seed": 2**63}, "seed"),
        ({"seed": -1}, "seed"),
        ({"n_starts": 10**7 + 1}, "n_starts"),
        ({"n_starts": 2**70}, "n_starts"),
        ({"options": {"maxeval": 10**10}}, "options.maxeval"),
        ({"options": {"maxeval": 2**31}}, "options.maxeval"),
        ({"options": {"maxeval": 1e10}}, "options.maxeval"),
        ({"options": {"maxtime": float("inf")}}, "options.maxtime"),
        ({"method": "cobyla", "options": {"initial_step": 1e400}}, "options.initial_step"),
    ],
)
def test_multistart_refuses_oversized_numbers_before_any_work(kwargs: dict, field: str, tmp_path) -> None:
    store = CampaignStore.create(tmp_path / "c.sqlite", "c", {}, ["a", "b"])
    CALLS.clear()
    args = {"n_starts": 3, **kwargs}
    with pytest.raises(ValueError, match=f"^{field}:"):
        multistart(_problem(), store=store, **args)
    assert CALLS == [] and store.finished_ids() == set()  # nothing evaluated, nothing stored
    store.close()


def test_the_largest_accepted_values_run_and_store() -> None:
    """seed = 2**63 − 1 is stored and read back exactly; maxeval = 2**31 − 1 reaches NLopt."""
    table = multistart(_problem(), 2, seed=MAX_SEED, options={"maxeval": MAX_EVAL})
    assert table["seed"].tolist() == [MAX_SEED, MAX_SEED]
    # closed form: U* = 0.7 − √0.35 where f1 = f2 at a = 0.6
    assert table["value"].min() == pytest.approx(0.7 - np.sqrt(0.35), abs=1e-7)
    assert method_options("slsqp", {"maxeval": MAX_EVAL})["maxeval"] == 2**31 - 1


def test_start_points_names_the_field() -> None:
    space = _problem().space
    with pytest.raises(ValueError, match="^seed: 1180591620717411303424 does not fit"):
        start_points(space, 4, seed=2**70)
    with pytest.raises(ValueError, match="^n_starts: .* more than the limit"):
        start_points(space, MAX_STARTS - 1, points=[[0.5, 0.5]] * 2)
    assert len(start_points(space, 4, seed=np.int64(MAX_SEED))) == 4
