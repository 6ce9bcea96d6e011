"""``solve(problem, x0, method=...)``: one local minimax solve, re-evaluated by railopt."""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

import numpy as np
from railopt.design.methods import METHODS
from railopt.design.methods.base import COMMON_OPTIONS, EpigraphView
from railopt.design.problem import MinimaxProblem
from railopt.design.result import SolveResult


def method_options(method: str, options: dict[str, Any] | None = None) -> dict[str, Any]:
    """Merge defaults and user options; unknown methods or option names raise naming the field."""
    if method not in METHODS:
        raise ValueError(f"method: unknown method {method!r}; registered: {sorted(METHODS)}")
    spec = METHODS[method]
    merged = {**COMMON_OPTIONS, **spec.defaults}
    for key, value in (options or {}).items():
        if key not in merged:
            raise ValueError(f"options.{key}: unknown option for method {method!r}; known: {sorted(merged)}")
        merged[key] = value
    for key in ("xtol", "ftol", "maxtime"):
        if not (isinstance(merged[key], int | float) and merged[key] > 0):
            raise ValueError(f"options.{key}: must be a positive number, got {merged[key]!r}")
    if not (isinstance(merged["maxeval"], int) and merged["maxeval"] > 0):
        raise ValueError(f"options.maxeval: must be a positive integer, got {merged['maxeval']!r}")
    return merged


def solve(problem: MinimaxProblem, x0: Sequence[float], method: str = "slsqp", **options: Any) -> SolveResult:
    """Minimise U(x) = max_k f_k(x) (4.75) from ``x0`` with a registered method.

    Parameters
    ----------
    problem : MinimaxProblem
    x0 : sequence of float
        Start design, inside the bounds.
    method : {"slsqp", "cobyla", "slp"}
        NLopt LD_SLSQP, NLopt LN_COBYLA, or SLP with a trust region (cvxpy LP).
    **options
        ``xtol`` (unit-cube coordinates), ``ftol`` (relative), ``maxeval``, ``maxtime`` (s) and
        method-specific ones (``initial_step`` for COBYLA; ``initial_radius``, ``penalty``,
        ``lp_solver`` for SLP).  Unknown names raise.

    Returns
    -------
    SolveResult
        With ``value`` = U(x) re-evaluated at the returned x; never raises for solver failures.
    """
    opts = method_options(method, options)
    x0 = problem.space.check_point(x0)
    start = time.perf_counter()
    view = EpigraphView(problem, x0, opts)
    outcome = METHODS[method].run(view, problem.space.to_u(x0), opts)
    x_solver = problem.space.to_x(np.clip(outcome.u, 0.0, 1.0))
    ev = problem.evaluate(x_solver)
    x, ev_best = x_solver, ev
    violation = problem.constraint_violation(x, ev)
    if np.isfinite(view.best_merit) and (view.best_merit < ev.value or violation > 1e-9):
        ev_b = problem.evaluate(view.best_x)
        if problem.constraint_violation(view.best_x, ev_b) <= 1e-9 and ev_b.value < ev.value:
            x, ev_best = view.best_x, ev_b
    return SolveResult(
        x=np.asarray(x, dtype=float),
        value=ev_best.value,
        t=float(outcome.tau),
        status=outcome.status,
        message=outcome.message,
        evaluations=view.evaluations,
        wall_time=time.perf_counter() - start,
        method=method,
        x0=np.asarray(x0, dtype=float),
        constraint_violation=problem.constraint_violation(x, ev_best),
        bound_violation=problem.space.bound_violation(x),
        functions=ev_best.f,
    )
