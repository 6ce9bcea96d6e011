"""ε-constraint sweeps, non-dominated filtering and objective surfaces against closed forms."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from railopt.design import DesignVariable, MinimaxProblem
from railopt.design import surface as surface_module
from railopt.design.surface import grid_map, objective_surface
from railopt.design.tradeoff import epsilon_sweep, nondominated


def test_nondominated_matches_brute_force_definition():
    rng = np.random.default_rng(4)
    df = pd.DataFrame(rng.uniform(size=(60, 2)), columns=["a", "b"])
    mask = nondominated(df, ["a", "b"])
    for i in range(len(df)):
        dominated = any((df.a[j] <= df.a[i]) and (df.b[j] <= df.b[i]) and (df.a[j] < df.a[i] or df.b[j] < df.b[i])
                        for j in range(len(df)))
        assert mask[i] == (not dominated)
    flipped = nondominated(df.assign(b=-df.b), ["a", "b"], sense={"b": "max"})
    pd.testing.assert_series_equal(mask, flipped)


def test_epsilon_sweep_traces_the_closed_form_tradeoff():
    """min max(x1, x2... ): U = (x−2)², g = x²  ⇒  optimum x = min(2, √ε), U = (x−2)²."""
    v = [DesignVariable("x", 0.0, 3.0)]
    problem = MinimaxProblem(v, lambda x: np.array([(x[0] - 2) ** 2]), constraints=lambda x: np.array([x[0] ** 2]))
    eps = [0.25, 1.0, 2.25, 9.0]
    table = epsilon_sweep(problem, eps, n_starts=3, seed=1)
    xs = np.minimum(2.0, np.sqrt(eps))
    np.testing.assert_allclose(table["x"], xs, atol=1e-6)
    np.testing.assert_allclose(table["value"], (xs - 2) ** 2, atol=1e-6)
    assert table["success"].all()
    assert nondominated(table, ["value", "g"]).all()  # a trade-off curve: every point is Pareto-optimal
    worse = pd.concat([table, pd.DataFrame({"value": [1.5], "g": [1.5]})], ignore_index=True)
    assert list(nondominated(worse, ["value", "g"])) == [True] * 4 + [False]  # (1.5, 1.5) is dominated by (1, 1)


def test_surface_values_and_bounds_mask():
    v = [DesignVariable("a", 0.0, 1.0), DesignVariable("b", 0.0, 1.0), DesignVariable("c", 0.0, 1.0)]
    problem = MinimaxProblem(v, lambda x: np.array([x[0] + 2 * x[1] + x[2], -x[0]]))
    xi, xj = np.linspace(-0.5, 1.0, 7), np.linspace(0.0, 2.0, 5)
    s = objective_surface(problem, ("a", "b"), xi, xj, base=[0.5, 0.5, 0.1])
    A, B = np.meshgrid(xi, xj)
    np.testing.assert_allclose(s.values, np.maximum(A + 2 * B + 0.1, -A))
    assert s.inside.sum() == (xi >= 0).sum() * (xj <= 1).sum()
    assert s.minimum() == {"a": 0.0, "b": 0.0, "U": 0.1}
    assert s.minimum(inside_only=False)["U"] == pytest.approx(np.min(np.maximum(A + 2 * B + 0.1, -A)))
    with pytest.raises(ValueError, match="^names:"):
        objective_surface(problem, ("a", "z"), xi, xj, base=[0.5, 0.5, 0.1])


def test_a_batched_surface_calls_the_batch_once_per_block_of_rows_and_equals_the_closed_form(monkeypatch):
    """A batched surface is one ``batch_functions`` call per block of whole rows of at most BLOCK_POINTS points
    (one call for a small grid), in any case the closed form, with the refused designs +inf."""
    v = [DesignVariable("a", 0.0, 1.0), DesignVariable("b", 0.0, 1.0), DesignVariable("c", 0.0, 1.0)]
    calls = []

    def point(x):
        if x[0] < 0:
            raise ValueError("a: the model refuses a < 0")
        return np.array([x[0] + 2 * x[1] + x[2], -x[0]])

    def batch(X):
        calls.append(len(X))
        F = np.column_stack([X[:, 0] + 2 * X[:, 1] + X[:, 2], -X[:, 0]])
        F[X[:, 0] < 0] = np.inf  # the refused designs, as the point function's ValueError
        return F

    xi, xj = np.linspace(-0.5, 1.0, 7), np.linspace(0.0, 2.0, 5)
    batched = objective_surface(MinimaxProblem(v, point, batch_functions=batch), ("a", "b"), xi, xj, [0.5, 0.5, 0.1])
    plain = objective_surface(MinimaxProblem(v, point), ("a", "b"), xi, xj, [0.5, 0.5, 0.1])
    A, B = np.meshgrid(xi, xj)
    expected = np.where(A < 0, np.inf, np.maximum(A + 2 * B + 0.1, -A))
    np.testing.assert_array_equal(batched.values, expected)
    np.testing.assert_array_equal(plain.values, expected)
    assert calls == [len(xi) * len(xj)]  # 35 points: one block
    calls.clear()
    monkeypatch.setattr(surface_module, "BLOCK_POINTS", 2 * len(xi) + 3)  # two whole rows a block
    again = objective_surface(MinimaxProblem(v, point, batch_functions=batch), ("a", "b"), xi, xj, [0.5, 0.5, 0.1])
    np.testing.assert_array_equal(again.values, expected)
    assert calls == [2 * len(xi), 2 * len(xi), len(xi)]
    rows = []
    objective_surface(MinimaxProblem(v, point, batch_functions=batch), ("a", "b"), xi, xj, [0.5, 0.5, 0.1],
                      progress=lambda done, total: rows.append((done, total)))
    assert rows == [(0, 5), (2, 5), (4, 5), (5, 5)]  # progress in rows, whatever the blocks


def test_batch_values_refuse_malformed_shapes_and_nan():
    v = [DesignVariable("a", 0.0, 1.0), DesignVariable("b", 0.0, 1.0)]
    problem = MinimaxProblem(v, lambda x: x.copy(), batch_functions=lambda X: X[:, :1].T)
    with pytest.raises(ValueError, match="^batch_functions: must return shape"):
        problem.values(np.zeros((3, 2)))
    with pytest.raises(ValueError, match="^X: must have shape"):
        problem.values(np.zeros(2))
    nan = MinimaxProblem(v, lambda x: x.copy(), batch_functions=lambda X: np.full_like(X, np.nan))
    with pytest.raises(ValueError, match="NaN"):
        nan.values(np.zeros((2, 2)))
    with pytest.raises(ValueError, match="^batch_functions: must be callable"):
        MinimaxProblem(v, lambda x: x.copy(), batch_functions=3)
    constrained = MinimaxProblem(v, lambda x: x.copy(), batch_functions=lambda X: X.copy(),
                                 constraints=lambda x: x[:1]).with_epsilon(0.5)
    assert constrained.has_batch
    np.testing.assert_array_equal(constrained.values([[0.2, 0.7], [0.9, 0.1]]), [0.7, 0.9])
    wrong_count = MinimaxProblem(v, lambda x: x.copy(), batch_functions=lambda X: np.ones((len(X), 5)))
    wrong_count.evaluate([0.1, 0.2])  # m = 2 learnt
    with pytest.raises(ValueError, match="count must be fixed"):
        wrong_count.values(np.zeros((2, 2)))


def test_row_by_row_and_batched_values_agree_on_refusals_nan_counts_and_constraints():
    v = [DesignVariable("a", 0.0, 1.0), DesignVariable("b", 0.0, 1.0)]

    def refusing_constraint(x):
        raise ValueError("the constraint model refuses every design")

    plain = MinimaxProblem(v, lambda x: x.copy(), constraints=refusing_constraint)
    batched = MinimaxProblem(v, lambda x: x.copy(), constraints=refusing_constraint, batch_functions=lambda X: X)
    X = np.array([[0.2, 0.7], [0.9, 0.1]])
    np.testing.assert_array_equal(plain.values(X), [0.7, 0.9])  # U alone: the constraints are not evaluated
    np.testing.assert_array_equal(batched.values(X), [0.7, 0.9])
    for nan_problem in (MinimaxProblem(v, lambda x: np.array([np.nan, 1.0])),
                        MinimaxProblem(v, lambda x: x, batch_functions=lambda X: np.full_like(X, np.nan))):
        with pytest.raises(ValueError, match="NaN"):
            nan_problem.values(X)
    changing = MinimaxProblem(v, lambda x: np.ones(2 if x[0] < 0.5 else 3))
    with pytest.raises(ValueError, match="count must be fixed"):
        changing.values(X)


def test_a_surface_without_batch_functions_is_one_task_per_row():
    """A problem evaluated a design at a time keeps one task per row (a cluster shares the rows; progress per row)."""
    v = [DesignVariable("a", 0.0, 1.0), DesignVariable("b", 0.0, 1.0)]
    rows = []
    xi, xj = np.linspace(0.0, 1.0, 21), np.linspace(0.0, 1.0, 4)
    s = objective_surface(MinimaxProblem(v, lambda x: np.array([x[0] + 10 * x[1]])), ("a", "b"), xi, xj,
                          [0.5, 0.5], progress=lambda done, total: rows.append((done, total)))
    assert rows == [(k, 4) for k in range(5)]
    np.testing.assert_array_equal(s.values, xi[None, :] + 10 * xj[:, None])


def test_grid_rows_stay_apart_by_position_and_a_wrong_batch_is_refused():
    """Rows are kept by position, so -0.0 and 0.0 (equal as floats) or NaN in xj each get their own values; a
    batched fn returning another count of values than designs is a ValueError naming fn; an empty axis is an empty
    grid."""
    def sign(X):
        return np.where(np.signbit(X[:, 1]), -1.0, 1.0) + 0.0 * X[:, 0]

    for batched in (True, False):
        fn = sign if batched else (lambda x: sign(x[None, :])[0])
        grid = grid_map(fn, ["a", "b"], ("a", "b"), [0.0, 1.0], [-0.0, 0.0, np.nan], [0.5, 0.5], batched=batched)
        np.testing.assert_array_equal(grid, [[-1.0, -1.0], [1.0, 1.0], [1.0, 1.0]])
    with pytest.raises(ValueError, match=r"^fn: a batched fn must return one value .* per design, shape \(4,"):
        grid_map(lambda X: np.zeros(len(X) - 1), ["a", "b"], ("a", "b"), [0.0, 1.0], [0.0, 1.0], [0.5, 0.5],
                 batched=True)
    with pytest.raises(ValueError, match="^fn: a batched fn"):
        grid_map(lambda X: 42.0, ["a", "b"], ("a", "b"), [0.0], [0.0], [0.5, 0.5], batched=True)
    assert grid_map(lambda X: X[:, 0], ["a", "b"], ("a", "b"), [], [0.0, 1.0], [0.5, 0.5], batched=True).shape == (2, 0)
    assert grid_map(lambda x: 0.0, ["a", "b"], ("a", "b"), [0.0, 1.0], [], [0.5, 0.5]).shape == (0, 2)


def test_values_of_designs_all_refused_before_the_count_is_known_are_inf():
    """A fresh problem whose first designs are all refused by the model (a ValueError) gives +inf for each, not an
    error for want of the function count."""
    v = [DesignVariable("a", -1.0, 1.0)]

    def refuse(x):
        raise ValueError("a: refused")

    np.testing.assert_array_equal(MinimaxProblem(v, refuse).values([[-0.5], [0.5]]), [np.inf, np.inf])
