"""``solve(problem, x0, method=...)``: one local minimax solve, re-evaluated by railopt."""

from __future__ import annotations

import math
import numbers
import time
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from railopt.design.methods import METHODS
from railopt.design.methods.base import COMMON_OPTIONS, EpigraphView, Outcome, StopSolve
from railopt.design.problem import Evaluation, MinimaxProblem
from railopt.design.result import SUCCESS_STATUSES, SolveResult

MAX_EVAL = 2**31 - 1  # NLopt's set_maxeval takes a C int
MAX_EXCHANGES = 6  # rounds of rows added by a semi-infinite constraint's certificate before "uncertified"


def method_options(method: str, options: dict[str, Any] | None = None) -> dict[str, Any]:
    """Merge defaults and user options; unknown methods or option names raise naming the field.

    Raises
    ------
    ValueError
        Naming ``method`` or ``options.<name>``: an unknown method or option, a tolerance or time
        that is not a positive finite number, or ``maxeval`` not an integer in [1, 2**31 − 1].
    """
    if method not in METHODS:
        raise ValueError(f"method: unknown method {method!r}; registered: {sorted(METHODS)}")
    spec = METHODS[method]
    merged = {**COMMON_OPTIONS, **spec.defaults}
    for key, value in (options or {}).items():
        if key not in merged:
            raise ValueError(f"options.{key}: unknown option for method {method!r}; known: {sorted(merged)}")
        merged[key] = value
    for key in ("xtol", "ftol", "maxtime", *(k for k in ("initial_step", "initial_radius", "penalty") if k in merged)):
        value = merged[key]
        if isinstance(value, bool) or not (isinstance(value, numbers.Real) and math.isfinite(value) and value > 0):
            raise ValueError(f"options.{key}: must be a positive number, got {value!r}")
        merged[key] = float(value)
    value = merged["maxeval"]
    if isinstance(value, bool) or not (isinstance(value, numbers.Integral) and value > 0):
        raise ValueError(f"options.maxeval: must be a positive integer, got {value!r}")
    if value > MAX_EVAL:
        raise ValueError(f"options.maxeval: {value} is more than NLopt accepts (a C int: at most 2**31 - 1 = "
                         f"{MAX_EVAL})")
    merged["maxeval"] = int(value)
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
        With ``value`` = U(x) re-evaluated at the returned x; never raises for solver failures.  A problem with
        ``refine`` (semi-infinite constraints) is solved by exchange: each successful solve is certified by
        ``refine(x)``; where it returns a refined problem the solve resumes from x on it, at most
        ``MAX_EXCHANGES`` times, then the status is ``"uncertified"`` (never a success).  The message counts the
        rounds; evaluations add up over them, and ``wall_time`` is the whole solve's, the certifications included.
    """
    began = time.perf_counter()
    result = _solve_once(problem, x0, method, options)
    rounds, evaluations = 0, result.evaluations
    while problem.refine is not None and result.success:
        refined = problem.refine(result.x)
        if refined is None:
            if rounds:
                result = replace(result, message=f"{result.message}; certified after {rounds} exchange round(s)")
            break
        if rounds == MAX_EXCHANGES:
            result = replace(result, status="uncertified",
                             message=f"{result.message}; still violated after {rounds} exchange rounds")
            break
        rounds += 1
        problem = refined
        result = _solve_once(problem, result.x, method, options)
        evaluations += result.evaluations
    # the start's time is the whole solve's: its certification by refine() included (on the flagship ~0.1 s a
    # start, the certified critical speed), which the time of the rounds alone left out
    wall = time.perf_counter() - began
    return replace(result, evaluations=evaluations, wall_time=wall,
                   x0=np.asarray(x0, dtype=float)) if rounds else replace(result, wall_time=wall)


def _solve_once(problem: MinimaxProblem, x0: Sequence[float], method: str, options: dict[str, Any]) -> SolveResult:
    opts = method_options(method, options)
    x0 = problem.space.check_point(x0)
    start = time.perf_counter()
    try:
        view = EpigraphView(problem, x0, opts)
    except StopSolve as stop:  # the model fails at the start point itself
        return _result(problem, x0, x0, None, np.inf, stop.status, stop.message, 0, start, method)
    try:
        outcome = METHODS[method].run(view, problem.space.to_u(x0), opts)
    except StopSolve as stop:
        outcome = Outcome(problem.space.to_u(view.best_x), view.best_merit, stop.status, stop.message)
    except Exception as exc:  # anything else a method lets through: a status with the best point, never a raise
        outcome = Outcome(problem.space.to_u(view.best_x), view.best_merit, "failure",
                          f"{method} raised {type(exc).__name__}: {exc}")
    if outcome.status not in SUCCESS_STATUSES and view.gradient_note:  # say why a solver may have failed
        outcome = Outcome(outcome.u, outcome.tau, outcome.status, f"{outcome.message}; {view.gradient_note}")
    # re-evaluate ourselves: the solver's point, or the best point it evaluated if that is better
    x_solver = problem.space.to_x(np.clip(outcome.u, 0.0, 1.0))
    evaluated = [(x_solver, _safe_evaluate(problem, x_solver))]
    if np.isfinite(view.best_merit) and not np.array_equal(view.best_x, x_solver):
        evaluated.append((view.best_x, _safe_evaluate(problem, view.best_x)))
    feasible = [(x, ev) for x, ev in evaluated if ev is not None and problem.constraint_violation(x, ev) <= 1e-9]
    # nothing feasible: report the solver's point as it is
    best_x, best_ev = min(feasible, key=lambda xe: xe[1].value) if feasible else evaluated[0]
    return _result(problem, x0, best_x, best_ev, outcome.tau, outcome.status, outcome.message,
                   view.evaluations, start, method)


def _safe_evaluate(problem: MinimaxProblem, x: np.ndarray) -> Evaluation | None:
    try:
        return problem.evaluate(x)
    except Exception:  # reported through the status of the solve, which already stopped on it
        return None


def _result(problem: MinimaxProblem, x0: np.ndarray, x: np.ndarray, ev: Evaluation | None, tau: float,
            status: str, message: str, evaluations: int, start: float, method: str) -> SolveResult:
    return SolveResult(
        x=np.asarray(x, dtype=float),
        value=ev.value if ev is not None else np.inf,
        t=float(tau),
        status=status,
        message=message,
        evaluations=evaluations,
        wall_time=time.perf_counter() - start,
        method=method,
        x0=np.asarray(x0, dtype=float),
        constraint_violation=problem.constraint_violation(x, ev) if ev is not None else np.inf,
        bound_violation=problem.space.bound_violation(x),
        functions=ev.f if ev is not None else np.zeros(0),
    )


__all__ = ["MAX_EVAL", "MAX_EXCHANGES", "method_options", "solve"]
