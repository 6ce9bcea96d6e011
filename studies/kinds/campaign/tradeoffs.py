"""Trade-offs and objective surfaces of a campaign study (thesis §4.3.3, Fig 4.18; SPEC §3).

``[[tradeoffs]]``: ε-constraint sweeps of the campaign's problem — minimise U subject to the response
maxima of another output below ε (e.g. the secondary lateral stroke), or subject to a check's value above ε
(e.g. the critical speed from the ``hunting`` check) — and the non-dominated designs among the sweep
optima *and every start of the campaign*, so no row of a Pareto table is dominated by anything computed.

``[[surfaces]]``: U over a grid of two design variables with the others at the optimum, inside the bounds
(constrained) and on a grid relaxed toward zero (unconstrained), where the thesis notes the trivial
optimum of zero stiffness.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from railopt.design import MinimaxProblem, Surface, epsilon_sweep, nondominated, objective_surface
from railopt.studies.adapter import ResponseTarget, minimax_problem
from railopt.studies.catalog import ModelSetup
from railopt.studies.kinds.campaign.config import SurfaceSpec, TradeoffSpec

__all__ = ["Tradeoff", "TradeoffSurfaces", "constrained_problem", "surfaces", "sweep_designs", "tradeoff_table"]


@dataclass(frozen=True)
class Tradeoff:
    """One ε-constraint sweep: every distinct design with U and the traded quantity, the non-dominated front,
    and — when the best optimum fails its first check — that check's result and the best design meeting it."""

    spec: TradeoffSpec
    table: pd.DataFrame
    front: pd.DataFrame
    quantity: str
    after_check: dict | None = None
    pick: pd.Series | None = None

    @property
    def flagged(self) -> bool:
        """The best optimum fails the check this sweep trades against."""
        return (self.spec.check is not None and self.after_check is not None
                and not self.after_check.get("stable", True))


@dataclass(frozen=True)
class TradeoffSurfaces:
    """U over two design variables: constrained (inside the bounds) and relaxed toward zero."""

    spec: SurfaceSpec
    constrained: Surface
    unconstrained: Surface


def constrained_problem(problem: MinimaxProblem, setup: ModelSetup, objective: ResponseTarget,
                        spec: TradeoffSpec, band: tuple[float, float]) -> MinimaxProblem:
    """``problem`` with the constraint of ``spec`` (ε set later by the sweep).  An output constraint goes
    through the one adapter, so objective and constraint share each x's system and eigen-decomposition."""
    names = list(problem.space.names)
    if spec.output is not None:
        target = ResponseTarget(spec.output, band, spec.exact)
        return minimax_problem(setup, problem.variables, objective, [target], [0.0])
    check = setup.checks[spec.check]

    def negative_check(x: np.ndarray) -> np.ndarray:
        p, _ = setup.parameters(names, x)
        value = check(p).value
        return np.array([-value if np.isfinite(value) else -1e12])  # stable over the range: no constraint

    return problem.with_constraints(negative_check)


def sweep_designs(problem: MinimaxProblem, setup: ModelSetup, objective: ResponseTarget, spec: TradeoffSpec,
                  band: tuple[float, float], starts: pd.DataFrame, seed: int, client=None) -> pd.DataFrame:
    """Sweep optima and campaign starts with U and the traded quantity; ``nondominated`` marks the front."""
    names = list(problem.space.names)
    cp = constrained_problem(problem, setup, objective, spec, band)
    eps = [-e for e in spec.epsilons] if spec.check is not None else list(spec.epsilons)
    sweep = epsilon_sweep(cp, eps, n_starts=spec.n_starts, method=spec.method, seed=seed, client=client)
    sweep = sweep[sweep["success"]].assign(source="sweep")
    designs = pd.concat([sweep[[*names, "source"]],
                         starts[np.isfinite(starts["value"])][names].assign(source="start")], ignore_index=True)
    # one row per distinct design (many starts find the same optimum)
    designs = designs.loc[~designs[names].round(9).duplicated()].reset_index(drop=True)
    quantity = spec.output or spec.check
    U, q = [], []
    for _, row in designs.iterrows():
        ev = cp.evaluate(row[names].to_numpy(float))
        U.append(ev.value)
        q.append(float(np.max(ev.g)) if spec.output is not None else -float(ev.g[0]))
    designs["U"], designs[quantity] = U, q
    sense = {"U": "min", quantity: "max" if spec.check is not None else "min"}
    designs["nondominated"] = nondominated(designs, ["U", quantity], sense)
    return designs


def tradeoff_table(problem: MinimaxProblem, setup: ModelSetup, objective: ResponseTarget, spec: TradeoffSpec,
                   band: tuple[float, float], starts: pd.DataFrame, seed: int, client=None,
                   after_check: dict | None = None) -> Tradeoff:
    """The sweep of ``spec`` (:func:`sweep_designs`), its front, and the best front design meeting the check."""
    table = sweep_designs(problem, setup, objective, spec, band, starts, seed, client)
    quantity = spec.output or spec.check
    front = table[table["nondominated"]].sort_values("U")
    result = Tradeoff(spec, table, front, quantity, after_check)
    if result.flagged:
        ok = front[front[quantity] > after_check.get("required_speed_m_s", np.nan)]
        if len(ok):
            result = Tradeoff(spec, table, front, quantity, after_check, ok.sort_values("U").iloc[0])
    return result


def surfaces(problem: MinimaxProblem, spec: SurfaceSpec, optimum: np.ndarray, client=None) -> TradeoffSurfaces:
    """The constrained and unconstrained :class:`~railopt.design.Surface` of U over ``spec.variables``."""
    space = problem.space
    grids = []
    for relaxed in (False, True):
        axes = []
        for name in spec.variables:
            k = space.names.index(name)
            lo, hi = space.lower[k], space.upper[k]
            if relaxed:
                lo = lo * spec.relax
            axes.append(np.geomspace(lo, hi, spec.points) if lo > 0 else np.linspace(lo, hi, spec.points))
        grids.append(objective_surface(problem, spec.variables, axes[0], axes[1], optimum, client=client))
    return TradeoffSurfaces(spec, grids[0], grids[1])
