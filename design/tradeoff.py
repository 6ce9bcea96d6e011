"""Trade-offs: ε-constraint sweeps and non-dominated filtering.

An ε-constraint sweep minimises U(x) subject to g(x) ≤ ε for a list of ε (e.g. peak cab
acceleration subject to a bound on the secondary lateral stroke); the best feasible optimum of
each ε forms a trade-off curve, and :func:`nondominated` keeps its Pareto-optimal points.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from railopt.design.parallel import ProgressCallback, call, map_unordered, resolve, shipping
from railopt.design.problem import MinimaxProblem
from railopt.design.runner import Runner
from railopt.design.solve import method_options, solve
from railopt.design.starts import start_points


def nondominated(df: pd.DataFrame, columns: Sequence[str], sense: Mapping[str, str] | None = None) -> pd.Series:
    """Boolean mask of rows no other row dominates on ``columns`` (minimised unless ``sense[c] == "max"``).

    Rows with NaN in any column are never non-dominated.  O(N²), fine for trade-off tables.
    """
    sense = dict(sense or {})
    for c in columns:
        if c not in df.columns:
            raise ValueError(f"columns: {c!r} is not a column of the table")
        if sense.get(c, "min") not in ("min", "max"):
            raise ValueError(f"sense.{c}: must be 'min' or 'max', got {sense[c]!r}")
    vals = np.column_stack([df[c].to_numpy(float) * (-1.0 if sense.get(c) == "max" else 1.0) for c in columns])
    ok = np.all(np.isfinite(vals), axis=1)
    mask = ok.copy()
    for i in np.flatnonzero(ok):
        others = vals[ok]
        dominated = np.any(np.all(others <= vals[i], axis=1) & np.any(others < vals[i], axis=1))
        mask[i] = not dominated
    return pd.Series(mask, index=df.index, name="nondominated")


@dataclass(frozen=True)
class _SweepTask:
    problem: MinimaxProblem
    epsilon: float
    x0: np.ndarray
    method: str
    options: dict[str, Any]

    def __call__(self) -> tuple[float, Any]:
        problem = resolve(self.problem)  # shipped once per sweep (a handle inside a dask task)
        return self.epsilon, solve(problem.with_epsilon(self.epsilon), self.x0, self.method, **self.options)



def epsilon_sweep(
    problem: MinimaxProblem,
    epsilons: Sequence[float],
    n_starts: int = 4,
    method: str = "slsqp",
    seed: int = 0,
    points: Sequence[Sequence[float]] | None = None,
    client: Runner | None = None,
    options: dict[str, Any] | None = None,
    progress: ProgressCallback | None = None,
) -> pd.DataFrame:
    """Minimise U s.t. g(x) ≤ ε for each ε (the problem's single constraint), multi-start each.

    Returns one row per ε: ``epsilon, value, g, status, success, <variables>…`` for the best
    feasible start (``success`` False and NaN values when no start was feasible).  ``progress(done, total)``
    counts finished solves (ε × starts; default: the enclosing
    :func:`~railopt.design.parallel.reporting_progress`).
    """
    if not problem.has_constraints:
        raise ValueError("problem: an ε-constraint sweep needs a problem with constraints g(x)")
    eps = [float(e) for e in epsilons]
    if not eps or not all(np.isfinite(eps)):
        raise ValueError("epsilons: need at least one finite value")
    method_options(method, options)
    starts = start_points(problem.space, n_starts, seed=seed, points=points)
    best: dict[float, Any] = {}
    with shipping(client, problem) as shipped:  # the problem goes to the workers once, not with every solve
        tasks = [_SweepTask(shipped, e, s.x0, method, dict(options or {})) for e in eps for s in starts]
        for e, r in map_unordered(call, tasks, client=client, progress=progress):
            if r.feasible and np.isfinite(r.value) and (e not in best or r.value < best[e].value):
                best[e] = r
    rows = []
    for e in eps:
        r = best.get(e)
        row = {"epsilon": e, "value": np.nan, "g": np.nan, "status": "infeasible", "success": False}
        if r is not None:
            g = problem.evaluate(r.x).g
            row |= {"value": r.value, "g": float(np.max(g)), "status": r.status, "success": r.success,
                    **dict(zip(problem.space.names, r.x, strict=True))}
        rows.append(row)
    return pd.DataFrame(rows, columns=["epsilon", "value", "g", "status", "success", *problem.space.names])


__all__ = ["epsilon_sweep", "nondominated"]
