"""Faults: points a rounding step outside the bounds; infinite or NaN gradients; exceptions inside a method.

Every point the design layer hands the user's function must lie inside [lower, upper] (a model may refuse
anything else), whatever the method, the finite-difference steps or the re-evaluation.  Optima at a bound
are checked against the closed form U* = f(upper).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import pytest

from railopt.design import METHODS, STATUSES, DesignVariable, MinimaxProblem, multistart, solve, start_points
from railopt.design.methods.base import Outcome
from railopt.design.variables import Space


class _Guarded:
    """f(x) = (lo0/x0 + (hi1 − x1)/(hi1 − lo1), 0.5 lo0/x0): decreasing in both, U* = lo0/hi0 at (hi0, hi1).

    Raises for any point outside the bounds (as a model with a validity range would) and records it.
    """

    def __init__(self, lower: np.ndarray, upper: np.ndarray) -> None:
        self.lower, self.upper = lower, upper
        self.outside: list[list[float]] = []

    def __call__(self, x: np.ndarray) -> np.ndarray:
        if not (np.all(self.lower <= x) and np.all(x <= self.upper)):
            self.outside.append(list(x))
            raise ValueError(f"x = {x!r} outside the model's range")
        lo, hi = self.lower, self.upper
        return np.array([lo[0] / x[0] + (hi[1] - x[1]) / (hi[1] - lo[1]), 0.5 * lo[0] / x[0]])


def _random_variables(rng: np.random.Generator) -> list[DesignVariable]:
    lo0 = 10.0 ** rng.uniform(-6, 4)
    log_var = DesignVariable("k", lo0, lo0 * 10.0 ** rng.uniform(0.05, 6), scale="log")
    lo1 = rng.uniform(-1e6, 1e6) * 10.0 ** rng.uniform(-6, 0)
    lin_var = DesignVariable("c", lo1, lo1 + abs(lo1) * 10.0 ** rng.uniform(-8, 1) + 10.0 ** rng.uniform(-3, 3))
    return [log_var, lin_var]


def test_to_x_never_leaves_the_bounds_and_hits_them_exactly() -> None:
    # the fault's variable: exp(log(0.3)) = 0.30000000000000004
    sp = Space([DesignVariable("zeta", 0.01, 0.3, scale="log")])
    lo, hi = math.log(0.01), math.log(0.3)
    assert math.exp(lo + 1.0 * (hi - lo)) > 0.3  # the rounding the clip guards against
    assert sp.to_x(np.array([1.0]))[0] == 0.3 and sp.to_x(np.array([0.0]))[0] == 0.01
    rng = np.random.default_rng(11)
    u = np.concatenate([[0.0, 1.0, 1.0 - 2**-53, 2**-53], rng.random(200)])
    for _ in range(500):
        variables = _random_variables(rng)
        sp = Space(variables)
        x = sp.to_x(np.column_stack([u, u[::-1]]))
        assert np.all(x >= sp.lower) and np.all(x <= sp.upper)
        np.testing.assert_array_equal(sp.to_x(np.ones(2)), sp.upper)  # u = 1 is the upper bound itself
        np.testing.assert_array_equal(sp.to_x(np.zeros(2)), sp.lower)
        starts = start_points(sp, 16, seed=int(rng.integers(1000)))
        assert all(np.all(s.x0 >= sp.lower) and np.all(s.x0 <= sp.upper) for s in starts)


def test_linear_variables_with_large_values_give_no_overflow_warning() -> None:
    sp = Space([DesignVariable("k", 1e3, 1e300), DesignVariable("z", 0.01, 0.3, scale="log")])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # exp(1e300) on a linear entry used to warn "overflow in exp"
        x = sp.to_x(np.array([0.5, 1.0]))
        chain = sp.dx_du(np.array([0.5, 0.5]))
    assert x[0] == pytest.approx(1e3 + 0.5 * (1e300 - 1e3), rel=1e-15) and x[1] == 0.3
    assert chain[0] == pytest.approx(1e300 - 1e3, rel=1e-15)
    assert chain[1] == pytest.approx(math.sqrt(0.01 * 0.3) * math.log(30), rel=1e-14)  # x du-derivative at u = ½


def test_the_faults_log_variable_converges_at_the_bound_for_every_method() -> None:
    lo, hi = 0.01, 0.3
    outside: list[float] = []

    def functions(x: np.ndarray) -> np.ndarray:  # the fault's model: refuses ζ outside [0.01, 0.3]
        if not lo <= x[0] <= hi:
            outside.append(float(x[0]))
            raise ValueError("outside the model's range")
        return np.array([1.0 / x[0], 0.5 / x[0]])

    problem = MinimaxProblem([DesignVariable("zeta", lo, hi, scale="log")], functions)
    for method in METHODS:
        r = solve(problem, [0.05], method=method)
        assert r.status == "converged", (method, r.message)
        assert r.x[0] == 0.3 and r.value == pytest.approx(1 / 0.3, rel=1e-15), method  # U* = 1/0.3 (closed form)
    assert outside == []


@pytest.mark.parametrize("method", sorted(METHODS))
def test_random_bounds_no_method_steps_outside(method: str) -> None:
    rng = np.random.default_rng({"slsqp": 1, "cobyla": 2, "slp": 3}.get(method, 4))
    converged = 0
    for trial in range(150):
        variables = _random_variables(rng)
        sp = Space(variables)
        model = _Guarded(sp.lower, sp.upper)
        analytic = trial % 2 == 0

        def with_jacobian(x: np.ndarray, model: _Guarded = model) -> tuple[np.ndarray, np.ndarray]:
            lo, hi = model.lower, model.upper
            J = np.array([[-lo[0] / x[0] ** 2, -1.0 / (hi[1] - lo[1])], [-0.5 * lo[0] / x[0] ** 2, 0.0]])
            return model(x), J

        problem = MinimaxProblem(variables, with_jacobian if analytic else model, jacobian=True if analytic else None)
        x0 = sp.to_x(rng.random(2))
        r = solve(problem, x0, method=method)
        assert model.outside == [], (trial, model.outside[:2])
        assert r.status in STATUSES and r.bound_violation == 0.0
        assert np.all(r.x >= sp.lower) and np.all(r.x <= sp.upper)
        if r.status == "converged":  # closed form: U* = lo0/hi0 at the upper corner
            assert r.value == pytest.approx(sp.lower[0] / sp.upper[0], rel=1e-6, abs=0), (trial, r)
            converged += 1
    assert converged >= 140, converged  # measured: 150 (slsqp), 146 (cobyla), 150 (slp) of 150
    # multistart: starts, solves and re-evaluations, for the last problem
    table = multistart(problem, 8, method=method, seed=5, points=[sp.upper.tolist(), sp.lower.tolist()])
    assert model.outside == [] and len(table) == 10
    assert np.all(table[["k", "c"]].to_numpy() <= sp.upper) and np.all(table[["k", "c"]].to_numpy() >= sp.lower)


def test_converged_share_for_random_bounds() -> None:
    """Most random problems converge at the corner with U* = lo0/hi0 (independent closed form)."""
    rng = np.random.default_rng(7)
    hits = 0
    for _ in range(40):
        variables = _random_variables(rng)
        sp = Space(variables)
        model = _Guarded(sp.lower, sp.upper)
        r = solve(MinimaxProblem(variables, model), sp.to_x(np.full(2, 0.5)), method="cobyla")
        hits += r.status == "converged" and abs(r.value / (sp.lower[0] / sp.upper[0]) - 1) < 1e-6
        assert model.outside == []
    assert hits >= 36, hits


# ---------------------------------------------------------------------- infinite / NaN gradients


def _sqrt_problem() -> MinimaxProblem:
    """The fault's problem: U = max(√c + t², ½√c − t), t = d − 0.3; U* = 0 at (0, 0.3) (closed form)."""

    def functions(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        c, d = float(x[0]), float(x[1])
        with np.errstate(divide="ignore"):
            g = 0.5 / np.sqrt(c)
        f = np.array([np.sqrt(c) + (d - 0.3) ** 2, 0.5 * np.sqrt(c) - (d - 0.3)])
        return f, np.array([[g, 2 * (d - 0.3)], [0.5 * g, -1.0]])

    return MinimaxProblem([DesignVariable("c", 0.0, 1.0), DesignVariable("d", 0.0, 1.0)], functions, jacobian=True)


def test_infinite_jacobian_entries_become_one_sided_differences() -> None:
    problem = _sqrt_problem()
    ev = problem.evaluate([0.0, 0.5], gradient=True)
    h = problem.fd_step * 1.0
    # forward difference into the box: (√h − 0)/h, and ½ of it; the finite entries are kept as supplied
    np.testing.assert_allclose(ev.df, [[math.sqrt(h) / h, 2 * 0.2], [0.5 * math.sqrt(h) / h, -1.0]], rtol=1e-12)
    assert ev.replaced and "dfunctions[0]/dc = inf" in ev.replaced[0]
    # a NaN entry in the interior: central difference of f1 = x² + y at (0.3, 0.5) → 0.6 (exact for a quadratic)
    nan_jac = MinimaxProblem([DesignVariable("x", -1, 1), DesignVariable("y", -1, 1)],
                             lambda x: (np.array([x[0] ** 2 + x[1]]), np.array([[np.nan, 1.0]])), jacobian=True)
    np.testing.assert_allclose(nan_jac.evaluate([0.3, 0.5], gradient=True).df, [[0.6, 1.0]], rtol=1e-8)


@pytest.mark.parametrize("method", sorted(METHODS))
@pytest.mark.parametrize("x0", [[0.5, 0.5], [0.0, 0.5], [0.9, 0.1]])
def test_infinite_gradient_at_a_bound_is_solved_or_failed_honestly(method: str, x0: list[float]) -> None:
    r = solve(_sqrt_problem(), x0, method=method)
    assert r.evaluations < 3000
    if r.status == "converged":
        assert r.value < 1e-8 and r.x == pytest.approx([0.0, 0.3], abs=1e-4)  # U* = 0 at (0, 0.3)
    else:
        assert r.status == "failure" and "non-finite gradient" in r.message, r
    if method in ("cobyla", "slp"):  # the derivative-free and the LP method reach the closed-form optimum
        assert r.status == "converged"


def test_multistart_with_infinite_gradient_never_raises() -> None:
    for method in METHODS:
        table = multistart(_sqrt_problem(), 3, method=method, seed=1, points=[[0.0, 0.5]])
        assert len(table) == 4 and set(table["status"]) <= set(STATUSES)
        assert table["value"].min() < 1e-8  # at least one start reaches U* = 0


@dataclass(frozen=True)
class _Exploding:
    """A method that evaluates two points, then raises something no method catches."""

    name: str = "exploding"
    uses_gradient: bool = False
    defaults: dict = None  # type: ignore[assignment]

    def run(self, view, u0, options) -> Outcome:  # noqa: ANN001
        view.evaluate_u(np.array([0.25]), gradient=False)
        view.evaluate_u(np.array([0.75]), gradient=False)
        raise ZeroDivisionError("inside the solver")


def test_any_exception_in_a_method_becomes_a_status_with_the_best_point(monkeypatch) -> None:
    monkeypatch.setitem(METHODS, "exploding", _Exploding(defaults={}))
    problem = MinimaxProblem([DesignVariable("x", 0.0, 1.0)], lambda x: np.array([(x[0] - 0.7) ** 2]))
    r = solve(problem, [0.0], method="exploding")
    assert r.status == "failure" and "ZeroDivisionError" in r.message
    assert r.x[0] == 0.75 and r.value == pytest.approx(0.05**2, rel=1e-12)  # best of 0, 0.25, 0.75
    table = multistart(problem, 2, method="exploding", seed=0)
    assert list(table["status"]) == ["failure", "failure"]
