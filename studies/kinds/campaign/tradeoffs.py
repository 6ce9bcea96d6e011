"""Trade-offs and objective surfaces of a campaign study (thesis §4.3.3, Fig 4.18; SPEC §3, §2.5).

``[[tradeoffs]]``: constraint sweeps that solve the *constrained* problem at each target — the secondary
stroke held below ε (an output constraint), or the stability rows of SPEC §2.5 required up to a speed ε
(``check = "hunting"``, the critical speed confirmed afterwards by the hunting check) — so the front has no
gap where feasible designs exist.  The sweep optima and every start of the campaign are merged into one
table of distinct designs (identical designs counted once, with ``count``), and ``nondominated`` marks the
front of (U, traded quantity) among the designs that meet every other constraint of the constrained problem
(``feasible``: the certified stability criterion, the other output limits); the rest are listed and drawn apart.

``[[surfaces]]``: U over a grid of two design variables with the others at the recommended design, inside the
bounds (constrained) and on a grid relaxed toward zero (unconstrained), where the thesis notes the trivial
optimum of zero stiffness; with the values of the constraints on the constrained grid (critical speed, strokes)
so the figure draws the constraint boundaries.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from railopt.design import MinimaxProblem, Surface, grid_map, multistart, nondominated, objective_surface
from railopt.studies.kinds.campaign.config import SurfaceSpec, TradeoffSpec
from railopt.studies.output.records import Boundary

__all__ = ["Boundary", "Tradeoff", "TradeoffSurfaces", "distinct_designs", "grid_points_below", "surfaces", "sweep",
           "tradeoff_table"]

DISTINCT_DIGITS = 6  # designs equal to 1e-6 of their unit-cube coordinates are one design


@dataclass(frozen=True)
class Tradeoff:
    """One constraint sweep: every distinct design with U and the traded quantity, the non-dominated front,
    and — when the recommended design is judged against it — the best front design meeting the requirement."""

    spec: TradeoffSpec
    table: pd.DataFrame
    front: pd.DataFrame
    quantity: str
    required: float | None = None
    pick: pd.Series | None = None


@dataclass(frozen=True)
class TradeoffSurfaces:
    """U over two design variables: constrained (inside the bounds) and relaxed toward zero; the constraint
    boundaries on the constrained grid and the marked designs (label -> design values)."""

    spec: SurfaceSpec
    constrained: Surface
    unconstrained: Surface
    boundaries: list[Boundary] = field(default_factory=list)
    marks: dict[str, dict[str, float]] = field(default_factory=dict)
    units: tuple[str, str, str] = ("", "", "")  # of the two variables and of U (figure axes)
    below: list[dict[str, float]] = field(default_factory=list)  # grid points under U_ref meeting every boundary
    below_certified: list[dict[str, float]] = field(default_factory=list)  # ... of them, those meeting everything


def grid_points_below(g: TradeoffSurfaces, base: dict[str, float], U_ref: float,
                      feasible: Callable[[np.ndarray], bool], names: Sequence[str],
                      most: int = 12) -> TradeoffSurfaces:
    """The constrained grid's points with U below ``U_ref`` (to 1e-6) inside the bounds that meet every drawn
    boundary, and which of them (the ``most`` lowest) meet every constraint and the whole criterion
    (``feasible``): a grid point that beats the recommendation must be said so, with why it is not recommended."""
    surface = g.constrained
    ok = surface.inside & (surface.values < U_ref * (1 - 1e-6))
    for bd in g.boundaries:
        ok &= bd.values >= bd.limit if bd.at_least else bd.values <= bd.limit
    js, is_ = np.nonzero(ok)
    order = np.argsort(surface.values[js, is_])[:most]
    below = [{**base, surface.names[0]: float(surface.xi[is_[k]]), surface.names[1]: float(surface.xj[js[k]]),
              "U": float(surface.values[js[k], is_[k]])} for k in order]
    certified = [d for d in below if feasible(np.array([d[n] for n in names]))]
    return replace(g, below=below, below_certified=certified)


def sweep(problems: Sequence[tuple[float, MinimaxProblem]], spec: TradeoffSpec, seed: int,
          points: Sequence[Sequence[float]] | None = None, client=None) -> pd.DataFrame:
    """Solve each target's constrained problem from ``spec.n_starts`` Sobol starts (plus ``points``): one row per
    target with the best feasible converged design (``success`` False and NaN where none was found)."""
    names = list(problems[0][1].space.names)
    rows = []
    for target, problem in problems:
        table = multistart(problem, spec.n_starts, method=spec.method, seed=seed, points=points, client=client)
        ok = table[table["success"]]
        row = {"epsilon": target, "success": bool(len(ok)), "value": np.nan, **{n: np.nan for n in names}}
        if len(ok):
            best = ok.sort_values(["value", "start_id"]).iloc[0]
            row |= {"value": float(best["value"]), **{n: float(best[n]) for n in names}}
        rows.append(row)
    return pd.DataFrame(rows)


def distinct_designs(designs: pd.DataFrame, problem: MinimaxProblem) -> pd.DataFrame:
    """One row per distinct design (unit-cube coordinates equal to 1e-6), the first of each kept, with ``count``."""
    names = list(problem.space.names)
    u = np.round(np.array([problem.space.to_u(x) for x in designs[names].to_numpy(float)]), DISTINCT_DIGITS)
    key = pd.Series([tuple(r) for r in u], index=designs.index)
    counts = key.map(key.value_counts())
    keep = ~key.duplicated()
    return designs.loc[keep].assign(count=counts[keep].to_numpy()).reset_index(drop=True)


def tradeoff_table(spec: TradeoffSpec, problems: Sequence[tuple[float, MinimaxProblem]], starts: pd.DataFrame,
                   quantity: Callable[[np.ndarray], float], objective: Callable[[np.ndarray], float], seed: int,
                   points: Sequence[Sequence[float]] | None = None, client=None,
                   required: float | None = None,
                   feasible: Callable[[np.ndarray], bool] | None = None,
                   criterion: Callable[[np.ndarray], bool] | None = None) -> Tradeoff:
    """The sweep of ``spec`` over its targets, merged with the campaign's starts; U (``objective``, certified) and
    the traded ``quantity`` of every distinct design; the front; and, with ``required``, the best front design
    whose quantity meets it.

    ``feasible(x)`` says whether a design meets every constraint of the constrained problem other than the traded
    one (the stability criterion certified by the hunting check, the other output limits): the front holds only
    feasible designs; the others stay in the table (``feasible`` False: unconstrained starts, designs that hunt)
    and are drawn apart.  ``starts`` may carry ``problem`` ("constrained"/"unconstrained"), kept as ``source``.
    The pick (with ``required``) is the best feasible design whose quantity meets it (to 1e-6 relative) and, with
    ``criterion(x)`` (the whole stability criterion, when the traded quantity is part of it), meets that too: a
    design the study could recommend, comparable with its recommendation.
    """
    names = list(problems[0][1].space.names)
    swept = sweep(problems, spec, seed, points, client)
    ok = starts[np.isfinite(starts["value"])]
    kinds = ok["problem"].astype(str) if "problem" in ok.columns else pd.Series("", index=ok.index)
    designs = pd.concat([swept[swept["success"]][names].assign(source="sweep"),
                         ok[names].assign(source=("start " + kinds).str.strip())], ignore_index=True)
    table = distinct_designs(designs, problems[0][1])
    name = spec.output or ("least_damping_ratio" if spec.check == "damping" else "critical_speed_m_s")
    table["U"] = [objective(x) for x in table[names].to_numpy(float)]
    table[name] = [quantity(x) for x in table[names].to_numpy(float)]
    table = table[np.isfinite(table["U"])].reset_index(drop=True)
    table["feasible"] = [bool(feasible(x)) if feasible is not None else True for x in table[names].to_numpy(float)]
    at_least = spec.check is not None
    front_mask = np.zeros(len(table), dtype=bool)
    candidates = table[table["feasible"]]
    if len(candidates):
        front_mask[candidates.index.to_numpy()] = nondominated(candidates, ["U", name],
                                                    {"U": "min", name: "max" if at_least else "min"}).to_numpy()
    table["nondominated"] = front_mask
    front = table[table["nondominated"]].sort_values("U").reset_index(drop=True)
    pick = None
    if required is not None:
        slack = 1e-6 * abs(required)
        ok = table["feasible"] & ((table[name] >= required - slack) if at_least else (table[name] <= required + slack))
        meets = table[ok]
        if criterion is not None and len(meets):
            meets = meets[[bool(criterion(x)) for x in meets[names].to_numpy(float)]]
        pick = meets.sort_values("U").iloc[0] if len(meets) else None
    return Tradeoff(spec, table, front, name, required, pick)


def surfaces(problem: MinimaxProblem, spec: SurfaceSpec, base: np.ndarray, client=None,
             constraints: Callable[[np.ndarray], np.ndarray] | None = None,
             limits: Sequence[tuple[str, float, bool]] = (),
             marks: dict[str, dict[str, float]] | None = None,
             units: tuple[str, str, str] = ("", "", "")) -> TradeoffSurfaces:
    """The constrained and unconstrained :class:`~railopt.design.Surface` of U over ``spec.variables`` (the others
    at ``base``), and on the constrained grid the values of ``constraints(x) -> (len(limits),)`` with their
    ``limits`` ``(label, limit, at_least)``; ``units`` of the two variables and of U label the figure."""
    space = problem.space
    grids, axes_used = [], []
    for relaxed in (False, True):
        axes = []
        for name in spec.variables:
            k = space.names.index(name)
            lo, hi = space.lower[k], space.upper[k]
            if relaxed:
                lo = lo * spec.relax
            axes.append(np.geomspace(lo, hi, spec.points) if lo > 0 else np.linspace(lo, hi, spec.points))
        axes_used.append(axes)
        grids.append(objective_surface(problem, spec.variables, axes[0], axes[1], base, client=client))
    boundaries = []
    if constraints is not None and limits:
        xi, xj = axes_used[0]
        values = grid_map(constraints, space.names, spec.variables, xi, xj, base, client)  # (xj, xi, limits)
        boundaries = [Boundary(label, values[:, :, k], limit, at_least)
                      for k, (label, limit, at_least) in enumerate(limits)]
    return TradeoffSurfaces(spec, grids[0], grids[1], boundaries, dict(marks or {}), tuple(units))
