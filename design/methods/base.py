"""What every method shares: the scaled epigraph view of a problem and the method registry.

Solvers work in unit-cube coordinates u (see :class:`~railopt.design.variables.Space`) and on
the epigraph NLP ``min τ  s.t.  f_k(x(u))/s − τ ≤ 0,  (g_i(x(u)) − ε_i)/s_g ≤ 0,  0 ≤ u ≤ 1``
with s = max(|U(x0)|, 1) so that τ is of order one whatever the units of f.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from railopt.design.problem import Evaluation, MinimaxProblem, ProblemDefinitionError

BIG = 1e12  # stands in for +inf inside solvers (U = inf is reported as inf)

COMMON_OPTIONS: dict[str, Any] = {
    "xtol": 1e-10,  # on u (unit-cube coordinates)
    "ftol": 1e-12,  # relative, on τ
    "maxeval": 3000,
    "maxtime": 120.0,  # seconds
}


class StopSolve(Exception):
    """Raised inside a solve to stop it (limit reached or the problem functions raised)."""

    def __init__(self, status: str, message: str) -> None:
        super().__init__(message)
        self.status = status
        self.message = message


class EpigraphView:
    """Scaled, counted, best-point-tracking view of a problem for one solve."""

    def __init__(self, problem: MinimaxProblem, x0: np.ndarray, options: Mapping[str, Any]) -> None:
        self.problem = problem
        self.space = problem.space
        self.options = options
        self.evaluations = 0
        self.start_time = time.perf_counter()
        self.best_x = np.asarray(x0, dtype=float).copy()
        self.best_merit = np.inf
        self.gradient_note: str | None = None  # the first non-finite Jacobian entry met (replaced by differences)
        ev0 = self._raw(self.best_x, gradient=False)
        u0_value = ev0.value
        self.scale = max(abs(u0_value), 1.0) if np.isfinite(u0_value) else 1.0
        self.tau0 = min(u0_value / self.scale, BIG) if np.isfinite(u0_value) else BIG

    def _raw(self, x: np.ndarray, gradient: bool) -> Evaluation:
        if self.evaluations >= self.options["maxeval"]:
            raise StopSolve("maxeval", f"maxeval={self.options['maxeval']} reached")
        if time.perf_counter() - self.start_time > self.options["maxtime"]:
            raise StopSolve("maxtime", f"maxtime={self.options['maxtime']} s reached")
        try:
            ev = self.problem.evaluate(x, gradient=gradient)
        except ProblemDefinitionError:  # the problem, not the model at x: the caller's error, raised
            raise
        except Exception as exc:  # the user's model failed: keep the best point, report it
            raise StopSolve("error", f"{type(exc).__name__}: {exc}") from exc
        self.evaluations += 1
        if ev.replaced and self.gradient_note is None:
            self.gradient_note = (f"non-finite gradient {ev.replaced[0]} at x = {np.asarray(x).tolist()} "
                                  "(replaced by a one-sided finite difference)")
        violation = self.problem.constraint_violation(x, ev)
        merit = ev.value if violation <= 1e-9 else np.inf
        if merit < self.best_merit:
            self.best_merit = merit
            self.best_x = np.array(x, dtype=float)
        return ev

    def evaluate_u(self, u: np.ndarray, gradient: bool) -> tuple[np.ndarray, np.ndarray | None,
                                                                np.ndarray, np.ndarray | None]:
        """Scaled f/s and (g − ε)/s with Jacobians in u; inf capped at BIG with zero gradient."""
        u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
        x = self.space.to_x(u)
        ev = self._raw(x, gradient)
        f = ev.f / self.scale
        g = (ev.g - self.problem.epsilon) / self.scale  # ε has one value per constraint once they have been counted
        df = dg = None
        if gradient:
            chain = self.space.dx_du(u)
            df = ev.df * chain[None, :] / self.scale
            dg = ev.dg * chain[None, :] / self.scale
            df[~np.isfinite(f)] = 0.0
            dg[~np.isfinite(g)] = 0.0
            for jac, name in ((df, "functions"), (dg, "constraints")):
                bad = np.argwhere(~np.isfinite(jac))
                if bad.size:  # the problem already replaced non-finite analytic entries by differences
                    k, i = bad[0]
                    raise StopSolve("failure", f"non-finite gradient d{name}[{k}]/d{self.space.names[i]} = "
                                               f"{jac[k, i]} at x = {x.tolist()}")
        f = np.where(np.isfinite(f), f, BIG)
        g = np.where(np.isfinite(g), g, BIG)
        return f, df, g, dg


@dataclass(frozen=True)
class Outcome:
    """What a method hands back: final u, final epigraph τ, a status key and a message."""

    u: np.ndarray
    tau: float
    status: str
    message: str


class Method(Protocol):
    """The contract of a local solver of the scaled epigraph problem (an extension point).

    A method is an object with a ``name`` (the key in :data:`METHODS` and in ``[design] method``), a flag
    ``uses_gradient`` (whether it asks the view for Jacobians) and ``defaults``, its own options with their default
    values: :func:`~railopt.design.solve.method_options` merges them over the common ones (``xtol``, ``ftol``,
    ``maxeval``, ``maxtime``), lets the caller override any of them and rejects other names.  Make one known with
    :func:`register`; see :class:`~railopt.design.methods.nlopt_methods.NloptMethod` and
    :class:`~railopt.design.methods.slp.SLPMethod`.
    """

    name: str
    uses_gradient: bool
    defaults: Mapping[str, Any]

    def run(self, view: EpigraphView, u0: np.ndarray, options: Mapping[str, Any]) -> Outcome:
        """Solve from ``u0`` and return the :class:`Outcome`.

        ``view`` evaluates the problem in unit-cube coordinates u ∈ [0, 1]^d (shape (d,)) with the functions divided by
        ``view.scale``; it counts evaluations and raises :class:`StopSolve` at ``maxeval``/``maxtime``, which the method
        catches and reports as the outcome's status (``converged``, ``maxeval``, ``maxtime``, ``error`` when the
        problem's functions raised, or ``failure``).  The
        outcome's ``tau`` is in the problem's units (multiplied back by ``view.scale``).  A method must not raise for a
        failed solve: it returns status ``failure`` with a message.
        """


METHODS: dict[str, Method] = {}


def register(method: Method) -> Method:
    """Make ``method`` available under ``method.name`` in :data:`METHODS`; returns it (usable as a decorator).

    A second registration under the same name replaces the first.
    """
    METHODS[method.name] = method
    return method


__all__ = ["BIG", "COMMON_OPTIONS", "METHODS", "EpigraphView", "Method", "Outcome", "StopSolve", "register"]
