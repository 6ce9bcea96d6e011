"""Semi-infinite constraints by exchange (``MinimaxProblem(refine=...)``), against a closed form.

min (x1 − 2)² + (x2 − 4)² subject to x1 cos t + x2 sin t ≤ 1 for every t in [0, π/2]: the feasible set is the
quarter unit disk, the optimum the projection of (2, 4) onto it, x* = (1, 2)/√5, with U* = (√20 − 1)².
Rows start at t = 0 and π/2 only (the grid optimum (1, 1) violates the continuum by √2 − 1); the certificate
adds the worst t = atan2(x2, x1) while the violation exceeds its tolerance.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from railopt.design import DesignVariable, MinimaxProblem, solve
from railopt.design.solve import MAX_EXCHANGES

VARIABLES = [DesignVariable("x1", 0.0, 2.0), DesignVariable("x2", 0.0, 2.0)]


def _violation(x: np.ndarray) -> tuple[float, float]:
    """The largest g over the continuum, in closed form: |x| − 1 at t = atan2(x2, x1)."""
    return float(np.hypot(x[0], x[1]) - 1.0), float(math.atan2(x[1], x[0]))


def _objective(x: np.ndarray) -> np.ndarray:
    return np.array([(x[0] - 2.0) ** 2 + (x[1] - 4.0) ** 2])


def _gradient(x: np.ndarray) -> np.ndarray:
    return np.array([[2.0 * (x[0] - 2.0), 2.0 * (x[1] - 4.0)]])


U_STAR = (math.sqrt(20.0) - 1.0) ** 2


def disk_problem(rows: tuple[float, ...], tolerance: float, calls: list | None = None,
                 pause: float = 0.0) -> MinimaxProblem:
    t = np.asarray(rows)

    def refine(x: np.ndarray) -> MinimaxProblem | None:
        if calls is not None:
            calls.append(np.array(x))
        time.sleep(pause)  # a certification that takes time (the flagship's certified critical speed: ~0.1 s)
        worst, where = _violation(x)
        return None if worst <= tolerance else disk_problem((*rows, where), tolerance, calls, pause)

    return MinimaxProblem(
        VARIABLES, _objective, jacobian=_gradient,
        constraints=lambda x: x[0] * np.cos(t) + x[1] * np.sin(t) - 1.0,
        constraint_jacobian=lambda x: np.column_stack([np.cos(t), np.sin(t)]), epsilon=np.zeros(len(t)),
        refine=refine)


def test_exchange_reaches_the_continuum_optimum_and_certifies_it() -> None:
    calls: list = []
    result = solve(disk_problem((0.0, math.pi / 2), 1e-3, calls), [0.5, 0.5], "slsqp", xtol=1e-10, ftol=1e-12)
    assert result.success and result.status == "converged"
    assert 1 < len(calls) <= MAX_EXCHANGES + 1 and "exchange round" in result.message
    worst, _ = _violation(result.x)
    assert worst <= 1e-3  # certified: the continuum holds to the certificate's tolerance, not just the rows
    assert result.value == pytest.approx(U_STAR, rel=2e-3)
    np.testing.assert_allclose(result.x, np.array([1.0, 2.0]) / math.sqrt(5.0), atol=5e-2)
    # the grid alone stops at (1, 1), violating the continuum by √2 − 1
    grid = solve(MinimaxProblem(VARIABLES, _objective, jacobian=_gradient,
                                constraints=lambda x: np.array([x[0] - 1.0, x[1] - 1.0]), epsilon=np.zeros(2)),
                 [0.5, 0.5], "slsqp")
    assert _violation(grid.x)[0] == pytest.approx(math.sqrt(2.0) - 1.0, abs=1e-6)


def test_a_certificate_that_cannot_be_met_is_uncertified_never_success() -> None:
    result = solve(disk_problem((0.0, math.pi / 2), 1e-14), [0.5, 0.5], "slsqp", xtol=1e-10, ftol=1e-12)
    assert result.status == "uncertified" and not result.success
    assert f"after {MAX_EXCHANGES} exchange rounds" in result.message
    assert _violation(result.x)[0] > 1e-14


def test_a_design_certified_at_once_is_solved_once() -> None:
    calls: list = []
    result = solve(disk_problem((0.0, math.atan2(2.0, 1.0), math.pi / 2), 1e-9, calls), [0.5, 0.5], "slsqp",
                   xtol=1e-12, ftol=1e-14)
    assert result.success and len(calls) == 1 and "exchange" not in result.message
    assert result.value == pytest.approx(U_STAR, rel=1e-9)


def test_refine_must_be_callable() -> None:
    with pytest.raises(ValueError, match="refine"):
        MinimaxProblem(VARIABLES, lambda x: x, refine=3)


@pytest.mark.parametrize("rows", [(0.0, math.pi / 2), (0.0, math.atan2(2.0, 1.0), math.pi / 2)],
                         ids=["exchanged", "certified-at-once"])
def test_a_start_s_wall_time_includes_its_certifications(rows) -> None:
    """Each certification sleeps 0.05 s: the start's wall time counts every one (it once counted the solves only)."""
    calls: list = []
    began = time.perf_counter()
    result = solve(disk_problem(rows, 1e-3, calls, pause=0.05), [0.5, 0.5], "slsqp", xtol=1e-10, ftol=1e-12)
    elapsed = time.perf_counter() - began
    assert result.success and len(calls) >= 1
    assert 0.05 * len(calls) <= result.wall_time <= elapsed
