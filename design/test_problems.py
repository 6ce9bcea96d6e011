"""Minimax test problems with published optima (used by the tests and ``railopt bench``).

- CB2, CB3: Charalambous & Bandler (1976), "Non-linear minimax optimization as a sequence of
  least pth optimization with finite values of p", Int. J. Systems Sci. 7:377-391;
  f* = 1.9522245 at (1.1390, 0.8996) and f* = 2 at (1, 1); standard starts (1, −0.1) and (2, 2).
- Rosen-Suzuki in minimax form (Charalambous & Conn 1978, SIAM J. Numer. Anal. 15:162-187):
  f_1 = F, f_{i} = F + 10 g_i (i = 2..4); f* = −44 at (0, 1, 2, −1); standard start 0.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from railopt.design.problem import MinimaxProblem
from railopt.design.variables import DesignVariable


@dataclass(frozen=True)
class TestProblem:
    """A minimax test problem with its start and known optimum.

    ``start`` is x0, shape (d,); ``optimum_value`` is U at the optimum and ``optimum_x`` the optimum x (or
    ``None`` where only the value is published).
    """

    name: str
    problem: MinimaxProblem
    start: np.ndarray
    optimum_value: float
    optimum_x: np.ndarray | None


def _cb2(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    x1, x2 = x
    e = 2 * np.exp(-x1 + x2)
    f = np.array([x1**2 + x2**4, (2 - x1) ** 2 + (2 - x2) ** 2, e])
    J = np.array([[2 * x1, 4 * x2**3], [-2 * (2 - x1), -2 * (2 - x2)], [-e, e]])
    return f, J


def _cb3(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    x1, x2 = x
    e = 2 * np.exp(-x1 + x2)
    f = np.array([x1**4 + x2**2, (2 - x1) ** 2 + (2 - x2) ** 2, e])
    J = np.array([[4 * x1**3, 2 * x2], [-2 * (2 - x1), -2 * (2 - x2)], [-e, e]])
    return f, J


def _rosen_suzuki(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    x1, x2, x3, x4 = x
    F = x1**2 + x2**2 + 2 * x3**2 + x4**2 - 5 * x1 - 5 * x2 - 21 * x3 + 7 * x4
    dF = np.array([2 * x1 - 5, 2 * x2 - 5, 4 * x3 - 21, 2 * x4 + 7])
    g = np.array(
        [
            x1**2 + x2**2 + x3**2 + x4**2 + x1 - x2 + x3 - x4 - 8,
            x1**2 + 2 * x2**2 + x3**2 + 2 * x4**2 - x1 - x4 - 10,
            x1**2 + x2**2 + x3**2 + 2 * x1 - x2 - x4 - 5,
        ]
    )
    dg = np.array(
        [
            [2 * x1 + 1, 2 * x2 - 1, 2 * x3 + 1, 2 * x4 - 1],
            [2 * x1 - 1, 4 * x2, 2 * x3, 4 * x4 - 1],
            [2 * x1 + 2, 2 * x2 - 1, 2 * x3, -1.0],
        ]
    )
    return np.concatenate([[F], F + 10 * g]), np.vstack([dF, dF + 10 * dg])


def _make(name: str, fun: Callable, d: int, start: list[float], fstar: float, xstar: list[float] | None,
          bound: float = 10.0, analytic: bool = True) -> TestProblem:
    variables = [DesignVariable(f"x{i + 1}", -bound, bound) for i in range(d)]
    if analytic:
        problem = MinimaxProblem(variables, fun, jacobian=True)
    else:
        problem = MinimaxProblem(variables, lambda x: fun(x)[0])
    return TestProblem(name, problem, np.array(start, float), fstar, None if xstar is None else np.array(xstar))


def minimax_test_problems(analytic: bool = True) -> dict[str, TestProblem]:
    """CB2, CB3 and Rosen-Suzuki; ``analytic=False`` drops the Jacobians (finite differences)."""
    return {
        "CB2": _make("CB2", _cb2, 2, [1.0, -0.1], 1.9522245, [1.1390, 0.8996], analytic=analytic),
        "CB3": _make("CB3", _cb3, 2, [2.0, 2.0], 2.0, [1.0, 1.0], analytic=analytic),
        "Rosen-Suzuki": _make("Rosen-Suzuki", _rosen_suzuki, 4, [0, 0, 0, 0], -44.0, [0, 1, 2, -1],
                              analytic=analytic),
    }


__all__ = ["TestProblem", "minimax_test_problems"]
