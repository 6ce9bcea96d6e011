"""Sequential linear programming with a trust region: Madsen's minimax method.

At u_k the functions are linearised and the LP
``min_{d,t} t + σ s  s.t.  f + J d ≤ t,  g + J_g d ≤ s,  s ≥ 0,  |d|_∞ ≤ Δ,  0 ≤ u_k + d ≤ 1``
is solved with cvxpy (built once with parameters, re-solved each iteration).  The step is taken
when the actual decrease of the merit ``φ(u) = max_k f_k + σ max(0, max_i g_i)`` is at least 1 %
of the decrease the LP predicts; Δ is quartered when the ratio is below 0.25 and doubled above
0.75 (K. Madsen, "An algorithm for minimax solution of overdetermined systems of non-linear
equations", J. Inst. Maths Applics 16 (1975) 321-328).
"""

from __future__ import annotations

import ctypes
import functools
import os
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from railopt.design.methods.base import BIG, EpigraphView, Outcome, StopSolve, register


@functools.cache
def _quiet_highs() -> None:
    """HiGHS prints a copyright banner to stdout (file descriptor 1, from C) the first time a process makes a solver,
    whatever cvxpy's ``verbose`` says: once per dask worker, in the middle of a run's output.  Make that first
    solver here with descriptor 1 pointed at /dev/null, once per process."""
    try:
        import highspy
    except ImportError:  # another LP solver: nothing to silence
        return
    sys.stdout.flush()
    saved, devnull = os.dup(1), os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        highspy.Highs()
        ctypes.CDLL(None).fflush(None)  # what C buffered goes to /dev/null too
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)


def _merit(f: np.ndarray, g: np.ndarray, penalty: float) -> float:
    return float(np.max(f) + penalty * max(0.0, float(np.max(g))) if g.size else np.max(f))


@dataclass(frozen=True)
class SLPMethod:
    """Madsen's sequential linear programming with a trust region, as a :class:`~railopt.design.methods.base.Method`.

    Options: ``initial_radius`` (Δ_0 in unit-cube coordinates), ``penalty`` (σ on the constraint excess) and
    ``lp_solver`` (a cvxpy solver name, HiGHS by default).
    """

    name: str = "slp"
    uses_gradient: bool = True
    defaults: Mapping[str, Any] = field(
        default_factory=lambda: {"initial_radius": 0.1, "penalty": 1e3, "lp_solver": "HIGHS"}
    )

    def run(self, view: EpigraphView, u0: np.ndarray, options: Mapping[str, Any]) -> Outcome:
        """Iterate the trust-region LP of the module docstring from ``u0`` (unit cube, shape (d,)).

        Stops ``converged`` when the predicted decrease falls below ``ftol`` or Δ below ``xtol``; ``failure`` when
        U = inf at the start or the LP subproblem fails; ``maxeval``/``maxtime`` (best point seen) from the view.
        """
        import cvxpy as cp

        if str(options["lp_solver"]).upper() == "HIGHS":
            _quiet_highs()
        d = view.space.dim
        m = view.problem.n_functions
        p = view.problem.n_constraints or 0  # counted at the view's first evaluation
        penalty = float(options["penalty"])
        fp, Jp = cp.Parameter(m), cp.Parameter((m, d))
        up, radius = cp.Parameter(d), cp.Parameter(nonneg=True)
        step, t = cp.Variable(d), cp.Variable()
        cons = [fp + Jp @ step <= t, cp.abs(step) <= radius, up + step >= 0, up + step <= 1]
        objective = t
        if p:
            gp, Jgp, s = cp.Parameter(p), cp.Parameter((p, d)), cp.Variable(nonneg=True)
            cons.append(gp + Jgp @ step <= s)
            objective = t + penalty * s
        lp = cp.Problem(cp.Minimize(objective), cons)

        u = np.asarray(u0, dtype=float)
        delta = float(options["initial_radius"])
        tau = np.inf
        try:
            f, df, g, dg = view.evaluate_u(u, gradient=True)
            phi = _merit(f, g, penalty)
            if phi >= BIG:
                return Outcome(u, np.inf, "failure", "U = inf at the start (undamped or singular response)")
            while True:
                fp.value, Jp.value, up.value, radius.value = f, df, u, delta
                if p:
                    gp.value, Jgp.value = g, dg
                try:
                    lp.solve(solver=options["lp_solver"])
                except (cp.error.SolverError, ValueError, ArithmeticError) as exc:  # e.g. NaN/inf problem data
                    best = view.space.to_u(view.best_x)
                    return Outcome(best, view.best_merit, "failure", f"LP subproblem: {type(exc).__name__}: {exc}")
                if lp.status not in ("optimal", "optimal_inaccurate") or step.value is None:
                    return Outcome(u, phi * view.scale, "failure", f"LP subproblem {lp.status}")
                tau = float(t.value)
                predicted = phi - float(lp.value)
                if predicted <= options["ftol"] * (1.0 + abs(phi)):
                    return Outcome(u, tau * view.scale, "converged", "predicted decrease below ftol")
                u_new = np.clip(u + step.value, 0.0, 1.0)
                f_new, df_new, g_new, dg_new = view.evaluate_u(u_new, gradient=True)
                phi_new = _merit(f_new, g_new, penalty)
                ratio = (phi - phi_new) / predicted
                if ratio > 0.01:
                    u, f, df, g, dg, phi = u_new, f_new, df_new, g_new, dg_new, phi_new
                if ratio < 0.25:
                    delta = float(np.max(np.abs(step.value))) / 4.0
                elif ratio > 0.75:
                    delta = min(2.0 * delta, 1.0)
                if delta < options["xtol"]:
                    return Outcome(u, tau * view.scale, "converged", "trust radius below xtol")
        except StopSolve as stop:
            return Outcome(view.space.to_u(view.best_x), view.best_merit, stop.status, stop.message)


register(SLPMethod())


__all__ = ["SLPMethod"]
