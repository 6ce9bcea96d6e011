"""Every method on minimax problems with published optima; statuses instead of crashes."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from railopt.design import METHODS, STATUSES, DesignVariable, MinimaxProblem, SolveResult, solve
from railopt.design.test_problems import minimax_test_problems

PROBLEMS = minimax_test_problems()


@pytest.mark.parametrize("method", sorted(METHODS))
@pytest.mark.parametrize("name", sorted(PROBLEMS))
def test_published_optimum_from_standard_start(name, method):
    tp = PROBLEMS[name]
    r = solve(tp.problem, tp.start, method=method)
    assert r.value == pytest.approx(tp.optimum_value, abs=1e-6)
    assert r.feasible
    assert r.status in ("converged", "maxeval")  # COBYLA may exhaust maxeval while already at f*


@pytest.mark.parametrize("method", ["slsqp", "slp"])
def test_finite_difference_gradients_reach_the_same_optima(method):
    for name, tp in minimax_test_problems(analytic=False).items():
        r = solve(tp.problem, tp.start, method=method)
        assert r.value == pytest.approx(tp.optimum_value, abs=1e-6), name


def test_analytic_jacobians_agree_with_finite_differences():
    rng = np.random.default_rng(0)
    for tp in PROBLEMS.values():
        for _ in range(3):
            x = rng.uniform(-2, 2, tp.problem.space.dim)
            assert tp.problem.gradient_check(x) < 1e-6


def test_every_method_fills_every_field():
    """Every field has its documented type and a value consistent with re-evaluating the problem."""
    tp = PROBLEMS["CB3"]
    fields = {f.name for f in dataclasses.fields(SolveResult)}
    for method in METHODS:
        r = solve(tp.problem, tp.start, method=method)
        assert set(r.to_dict()) == fields
        ev = tp.problem.evaluate(r.x)
        assert r.x.shape == (tp.problem.space.dim,) and np.all(np.isfinite(r.x))
        np.testing.assert_array_equal(r.functions, ev.f)  # f_k at x, re-evaluated
        assert r.value == float(np.max(ev.f))  # U(x) recomputed, not the solver's t
        assert np.isfinite(r.t) and abs(r.value - r.t) < 1e-6  # the epigraph variable is tight at the optimum
        assert r.status in STATUSES and isinstance(r.message, str)
        assert isinstance(r.evaluations, int) and r.evaluations > 0 and r.wall_time > 0 and r.method == method
        np.testing.assert_array_equal(r.x0, tp.start)
        assert r.constraint_violation == 0.0 and 0.0 <= r.bound_violation <= 1e-9


def _quadratic_problem(functions=None, jacobian=None):
    v = [DesignVariable("a", -5, 5), DesignVariable("b", -5, 5)]
    f = functions or (lambda x: np.array([x[0] ** 2 + x[1] ** 2 + 1, (x[0] - 1) ** 2 + 1]))
    return MinimaxProblem(v, f, jacobian=jacobian)


def test_wrong_gradient_becomes_a_status_with_the_best_point():
    wrong = lambda x: -np.array([[2 * x[0], 2 * x[1]], [2 * (x[0] - 1), 0.0]])  # noqa: E731
    problem = _quadratic_problem(jacobian=wrong)
    assert problem.gradient_check([3.0, 3.0]) > 1.0  # the gradient check catches the wrong sign
    r = solve(problem, [3.0, 3.0], method="slsqp")
    assert r.status in ("roundoff_limited", "failure")
    assert r.value == problem.value(r.x)  # the reported value is U at the reported point, re-evaluated


def test_exception_in_model_becomes_error_status():
    def f(x):
        if x[0] < 0.5:
            raise RuntimeError("model blew up")
        return np.array([x[0] ** 2 + x[1] ** 2 + 1, (x[0] - 1) ** 2 + 1])

    for method in METHODS:
        r = solve(_quadratic_problem(f), [3.0, 3.0], method=method)
        assert r.status == "error" and "model blew up" in r.message
        assert r.x[0] >= 0.5 and r.value < 19.0


def test_maxeval_becomes_a_status():
    r = solve(_quadratic_problem(), [3.0, 3.0], method="cobyla", maxeval=10)
    assert r.status == "maxeval" and r.evaluations <= 11


def test_unbounded_response_is_inf_and_solvers_carry_on():
    f = lambda x: np.array([np.inf if x[0] > 2 else x[0] ** 2 + 1, (x[0] - 1) ** 2])  # noqa: E731
    for method in METHODS:
        r = solve(_quadratic_problem(f), [3.0, 3.0], method=method)
        assert r.value == np.inf and r.status in STATUSES and not r.success
        r = solve(_quadratic_problem(f), [1.5, 0.0], method=method)  # a finite start stays finite
        assert np.isfinite(r.value)


def test_bad_input_names_the_field():
    tp = PROBLEMS["CB2"]
    with pytest.raises(ValueError, match="^method:"):
        solve(tp.problem, tp.start, method="newton")
    with pytest.raises(ValueError, match=r"^options\.tolerance:"):
        solve(tp.problem, tp.start, tolerance=1e-3)
    with pytest.raises(ValueError, match=r"^options\.maxeval:"):
        solve(tp.problem, tp.start, maxeval=0)
    with pytest.raises(ValueError, match="^x0:"):
        solve(tp.problem, [50.0, 0.0])
    with pytest.raises(ValueError, match="^k2: bounds inverted"):
        DesignVariable("k2", 5.0, 1.0)
    with pytest.raises(ValueError, match=r"^k2\.lower:"):
        DesignVariable("k2", float("nan"), 1.0)


def test_nan_from_the_model_is_an_error_status_not_a_crash():
    r = solve(_quadratic_problem(lambda x: np.array([np.nan, 1.0])), [1.0, 1.0])
    assert r.status == "error" and "functions: returned NaN" in r.message and r.value == np.inf


def test_log_scaled_variables_round_trip_and_solve():
    v = [DesignVariable("k", 1e2, 1e8, scale="log"), DesignVariable("c", 1.0, 1e4, scale="log")]
    p = MinimaxProblem(v, lambda x: np.array([np.log10(x[0]) - 5, 5 - np.log10(x[0]), abs(np.log10(x[1]) - 2)]))
    x = np.array([3e4, 17.0])
    np.testing.assert_allclose(p.space.to_x(p.space.to_u(x)), x, rtol=1e-14)
    r = solve(p, [1e7, 1e3], method="slsqp")
    assert r.value == pytest.approx(0.0, abs=1e-6) and r.x[0] == pytest.approx(1e5, rel=1e-4)
