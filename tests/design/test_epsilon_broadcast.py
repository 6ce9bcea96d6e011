"""``epsilon`` of g(x) ≤ ε as documented (issue 27 item 4): a scalar applies to every constraint, an array needs one
value per constraint, and a wrong length is a ValueError naming ``epsilon`` — at construction when the count is known
(``n_constraints``), otherwise at the first evaluation.  Every registered method, 1–3 constraints, against the
closed-form optimum of a constrained minimax problem."""

from __future__ import annotations

import numpy as np
import pytest

from railopt.design import METHODS, DesignVariable, MinimaxProblem, epsilon_sweep, solve
from railopt.design.problem import ProblemDefinitionError

A, B = np.array([2.0, 0.0, 0.0]), np.array([0.0, 2.0, 0.0])


def functions(x: np.ndarray) -> np.ndarray:
    """f_1 = |x − a|², f_2 = |x − b|²: the unconstrained minimax optimum is x = (1, 1, 0), U = 2."""
    return np.array([np.sum((x - A) ** 2), np.sum((x - B) ** 2)])


def jacobian(x: np.ndarray) -> np.ndarray:
    return np.array([2 * (x - A), 2 * (x - B)])


def lower_bounds_as_constraints(p: int):
    """g_j(x) = −x_j ≤ ε_j, j < p: the constraints x_j ≥ −ε_j."""
    return (lambda x: -x[:p].copy()), (lambda x: -np.eye(3)[:p])


def closed_form(lower: np.ndarray) -> tuple[np.ndarray, float]:
    """The optimum subject to x_j ≥ L_j (j < p).  By the symmetry of f_1, f_2 under x_1 ↔ x_2 the optimum keeps
    x_1 = x_2 = m with m = max(1, L_1, L_2) (at m the two values are equal; KKT multipliers (λ_1, λ_2) ≥ 0 with a
    non-negative multiplier on the binding bound), and x_3 = max(0, L_3) adds x_3² to both values:
    U = (m − 2)² + m² + x_3²."""
    L = np.full(3, -np.inf)
    L[: len(lower)] = lower
    m = max(1.0, L[0], L[1])
    x3 = max(0.0, L[2])
    return np.array([m, m, x3]), (m - 2) ** 2 + m**2 + x3**2


CASES = [  # (p, epsilon as given, the lower bounds −ε it means)
    (1, -1.5, [1.5]),
    (1, [-1.5], [1.5]),
    (2, -1.5, [1.5, 1.5]),
    (2, [-1.5, -1.8], [1.5, 1.8]),
    (2, np.array([-1.8, -0.5]), [1.8, 0.5]),
    (3, -0.5, [0.5, 0.5, 0.5]),
    (3, -1.5, [1.5, 1.5, 1.5]),
    (3, [-1.5, -1.8, -0.5], [1.5, 1.8, 0.5]),
]


@pytest.mark.parametrize("method", sorted(METHODS))
@pytest.mark.parametrize(("p", "epsilon", "lower"), CASES)
@pytest.mark.parametrize("analytic", [True, False])
def test_every_method_reaches_the_closed_form_optimum_with_scalar_or_array_epsilon(method, p, epsilon, lower,
                                                                                   analytic):
    g, dg = lower_bounds_as_constraints(p)
    variables = [DesignVariable(f"x{i + 1}", -3.0, 3.0) for i in range(3)]
    problem = MinimaxProblem(variables, functions, jacobian=jacobian if analytic else None, constraints=g,
                             constraint_jacobian=dg if analytic else None, epsilon=epsilon)
    x_star, u_star = closed_form(np.array(lower))
    result = solve(problem, [0.2, -0.3, 0.1], method)
    assert result.status == "converged", result.message
    assert result.success
    assert result.value == pytest.approx(u_star, rel=1e-6)
    np.testing.assert_allclose(result.x, x_star, atol=2e-4)
    assert result.constraint_violation <= 1e-6
    assert problem.n_constraints == p
    np.testing.assert_array_equal(problem.epsilon, np.broadcast_to(-np.asarray(lower), (p,)))


@pytest.mark.parametrize(("p", "epsilon"), [(2, [-1.0, -1.0, -1.0]), (3, [0.0, 0.0]), (1, [1.0, 2.0])])
def test_a_wrong_length_is_refused_naming_epsilon_at_construction_when_the_count_is_known(p, epsilon):
    g, dg = lower_bounds_as_constraints(p)
    variables = [DesignVariable(f"x{i + 1}", -3.0, 3.0) for i in range(3)]
    with pytest.raises(ValueError, match=rf"^epsilon: has {len(epsilon)} values, but there are {p} constraints"):
        MinimaxProblem(variables, functions, jacobian=jacobian, constraints=g, constraint_jacobian=dg,
                       epsilon=epsilon, n_constraints=p)


@pytest.mark.parametrize("method", sorted(METHODS))
@pytest.mark.parametrize(("p", "epsilon"), [(2, [-1.0, -1.0, -1.0]), (3, [0.0, 0.0])])
def test_a_wrong_length_is_refused_naming_epsilon_at_the_first_evaluation(method, p, epsilon):
    g, dg = lower_bounds_as_constraints(p)
    variables = [DesignVariable(f"x{i + 1}", -3.0, 3.0) for i in range(3)]
    problem = MinimaxProblem(variables, functions, jacobian=jacobian, constraints=g, constraint_jacobian=dg,
                             epsilon=epsilon)
    with pytest.raises(ValueError, match=rf"^epsilon: has {len(epsilon)} values, but there are {p} constraints"):
        solve(problem, [0.0, 0.0, 0.0], method)  # raised, not reported as a failed start
    with pytest.raises(ProblemDefinitionError, match="^epsilon:"):
        problem.evaluate([0.0, 0.0, 0.0])


def test_bad_epsilon_and_n_constraints_are_refused_naming_the_field():
    g, dg = lower_bounds_as_constraints(2)
    variables = [DesignVariable("x1", -3.0, 3.0), DesignVariable("x2", -3.0, 3.0), DesignVariable("x3", -3.0, 3.0)]
    with pytest.raises(ValueError, match="^epsilon: 2 values, but the problem has no constraints"):
        MinimaxProblem(variables, functions, epsilon=[0.0, 1.0])
    with pytest.raises(ValueError, match="^epsilon: must be a number or a non-empty 1-D array"):
        MinimaxProblem(variables, functions, constraints=g, epsilon=np.zeros((2, 1)))
    with pytest.raises(ValueError, match="^epsilon: must be finite"):
        MinimaxProblem(variables, functions, constraints=g, epsilon=[0.0, np.inf])
    with pytest.raises(ValueError, match="^n_constraints: must be a positive integer"):
        MinimaxProblem(variables, functions, constraints=g, n_constraints=0)
    with pytest.raises(ValueError, match="^n_constraints: given, but the problem has no constraints"):
        MinimaxProblem(variables, functions, n_constraints=2)
    # a declared count the constraints then break is the constraints' error
    problem = MinimaxProblem(variables, functions, constraints=g, constraint_jacobian=dg, n_constraints=3)
    with pytest.raises(ValueError, match="^constraints: returned 2 values, expected 3"):
        problem.evaluate([0.0, 0.0, 0.0])


def test_an_epsilon_sweep_broadcasts_each_scalar_over_several_constraints():
    """ε-constraint trade-off over two constraints with one scalar per point: each point is the closed form."""
    g, dg = lower_bounds_as_constraints(2)
    variables = [DesignVariable(f"x{i + 1}", -3.0, 3.0) for i in range(3)]
    problem = MinimaxProblem(variables, functions, jacobian=jacobian, constraints=g, constraint_jacobian=dg)
    table = epsilon_sweep(problem, [-1.2, -1.6], n_starts=2)
    for row in table.itertuples():
        assert row.success
        assert row.value == pytest.approx(closed_form(np.array([-row.epsilon] * 2))[1], rel=1e-7)
