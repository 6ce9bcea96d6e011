"""NLopt's SLSQP (LD_SLSQP, gradient-based) and COBYLA (LN_COBYLA, derivative-free) on the epigraph.

The NLopt object is created inside :meth:`NloptMethod.run`, i.e. inside the worker task, because
it does not pickle.  NLopt exceptions (RoundoffLimited, ForcedStop, the generic failure that
SLSQP raises for "more than iter SQP iterations" or a singular QP) become statuses with the best
point evaluated so far.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from railopt.design.methods.base import BIG, EpigraphView, Outcome, StopSolve, register

_RESULT_STATUS = {
    1: "converged",  # SUCCESS
    2: "converged",  # STOPVAL_REACHED
    3: "converged",  # FTOL_REACHED
    4: "converged",  # XTOL_REACHED
    5: "maxeval",  # MAXEVAL_REACHED
    6: "maxtime",  # MAXTIME_REACHED
}


@dataclass(frozen=True)
class NloptMethod:
    """An NLopt local algorithm applied to the scaled epigraph NLP."""

    name: str
    algorithm: str
    uses_gradient: bool
    defaults: Mapping[str, Any] = field(default_factory=dict)

    def run(self, view: EpigraphView, u0: np.ndarray, options: Mapping[str, Any]) -> Outcome:
        """Solve the epigraph NLP ``min τ s.t. f_k(u) ≤ τ, g_i(u) ≤ 0, 0 ≤ u ≤ 1`` with NLopt's ``algorithm``.

        The variables are z = (u, τ), shape (d+1,); τ starts just above the start's scaled value and is bounded
        to a wide finite interval.  NLopt's result code maps to ``converged``/``maxeval``/``maxtime``/``failure``; a
        :class:`~railopt.design.methods.base.StopSolve` returns the best point the view has seen.
        """
        import nlopt

        d = view.space.dim
        tau0 = view.tau0
        span = 1e6 * (1.0 + abs(tau0)) if tau0 < BIG else BIG  # finite, far from any optimum
        lower = np.concatenate([np.zeros(d), [tau0 - span if tau0 < BIG else -BIG]])
        upper = np.concatenate([np.ones(d), [tau0 + span if tau0 < BIG else BIG]])
        z0 = np.concatenate([u0, [min(tau0 * (1 + 1e-9) + 1e-12, upper[-1])]])

        opt = nlopt.opt(getattr(nlopt, self.algorithm), d + 1)
        opt.set_lower_bounds(lower)
        opt.set_upper_bounds(upper)

        def objective(z: np.ndarray, grad: np.ndarray) -> float:
            if grad.size:
                grad[:] = 0.0
                grad[-1] = 1.0
            return float(z[-1])

        m = view.problem.n_functions
        p = view.problem.n_constraints or 0  # counted at the view's first evaluation

        def constraints(result: np.ndarray, z: np.ndarray, grad: np.ndarray) -> None:
            want = grad.size > 0
            f, df, g, dg = view.evaluate_u(z[:d], gradient=want)
            result[:m] = f - z[-1]
            result[m:] = g
            if want:
                grad[:m, :d] = df
                grad[:m, d] = -1.0
                grad[m:, :d] = dg
                grad[m:, d] = 0.0

        opt.set_min_objective(objective)
        opt.add_inequality_mconstraint(constraints, np.full(m + p, 1e-10))
        opt.set_xtol_abs(np.concatenate([np.full(d, options["xtol"]), [0.0]]))
        opt.set_ftol_rel(options["ftol"])
        opt.set_maxeval(int(options["maxeval"]))
        opt.set_maxtime(float(options["maxtime"]))
        if not self.uses_gradient:
            opt.set_initial_step(np.concatenate([np.full(d, options["initial_step"]), [0.1 * (1 + abs(z0[-1]))]]))
        try:
            z = opt.optimize(z0)
            code = opt.last_optimize_result()
            status = _RESULT_STATUS.get(code, "failure")
            return Outcome(np.clip(z[:d], 0, 1), float(z[-1]) * view.scale, status, f"nlopt result {code}")
        except StopSolve as stop:
            return self._best(view, stop.status, stop.message)
        except nlopt.RoundoffLimited as exc:
            return self._best(view, "roundoff_limited", f"RoundoffLimited: {exc}")
        except nlopt.ForcedStop as exc:
            return self._best(view, "forced_stop", f"ForcedStop: {exc}")
        except (RuntimeError, ValueError, getattr(nlopt, "exception", RuntimeError)) as exc:  # NLOPT_FAILURE etc.
            # NLopt's generic failure (SLSQP: iteration limit, singular QP, a huge gradient) may carry no text
            return self._best(view, "failure", f"NLopt {type(exc).__name__}: {str(exc) or 'NLOPT_FAILURE'}")

    @staticmethod
    def _best(view: EpigraphView, status: str, message: str) -> Outcome:
        return Outcome(view.space.to_u(view.best_x), view.best_merit, status, message)


register(NloptMethod("slsqp", "LD_SLSQP", uses_gradient=True))
register(NloptMethod("cobyla", "LN_COBYLA", uses_gradient=False, defaults={"initial_step": 0.05}))


__all__ = ["NloptMethod"]
