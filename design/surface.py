"""Objective surfaces: U over a grid of two design variables with the others fixed (Fig 4.18).

The grid may extend beyond the variables' bounds (the unconstrained surface, where the thesis
notes the trivial optimum at zero stiffness); ``constrained`` marks the points inside them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from railopt.design.parallel import call, map_unordered
from railopt.design.problem import MinimaxProblem
from railopt.records import ArrayRecord


@dataclass(frozen=True, eq=False, repr=False)
class Surface(ArrayRecord):
    """U(x) on a grid: ``values[j, i]`` at ``x[names[0]] = xi[i]``, ``x[names[1]] = xj[j]``."""

    names: tuple[str, str]
    xi: np.ndarray
    xj: np.ndarray
    values: np.ndarray
    inside: np.ndarray  # True where the grid point satisfies the bounds

    def to_pandas(self) -> pd.DataFrame:
        XI, XJ = np.meshgrid(self.xi, self.xj)
        return pd.DataFrame({self.names[0]: XI.ravel(), self.names[1]: XJ.ravel(), "U": self.values.ravel(),
                             "inside_bounds": self.inside.ravel()})

    def minimum(self, inside_only: bool = True) -> dict[str, float]:
        """Grid point of least U (inside the bounds by default)."""
        v = np.where(self.inside, self.values, np.inf) if inside_only else self.values
        j, i = np.unravel_index(int(np.argmin(v)), v.shape)
        return {self.names[0]: float(self.xi[i]), self.names[1]: float(self.xj[j]), "U": float(v[j, i])}


@dataclass(frozen=True)
class _Row:
    problem: MinimaxProblem
    base: np.ndarray
    i: int
    j: int
    xi: np.ndarray
    xj_value: float

    def __call__(self) -> tuple[float, np.ndarray]:
        out = np.empty(len(self.xi))
        for k, v in enumerate(self.xi):
            x = self.base.copy()
            x[self.i], x[self.j] = v, self.xj_value
            try:
                out[k] = self.problem.value(x)
            except ValueError:  # e.g. a singular model at zero stiffness: no finite response
                out[k] = np.inf
        return self.xj_value, out


def objective_surface(
    problem: MinimaxProblem,
    names: tuple[str, str],
    xi: Sequence[float],
    xj: Sequence[float],
    base: Sequence[float],
    client: Any = None,
) -> Surface:
    """U over ``xi × xj`` for the two named variables, the others at ``base``; one task per grid row."""
    space = problem.space
    for n in names:
        if n not in space.names:
            raise ValueError(f"names: unknown design variable {n!r}; known: {space.names}")
    if names[0] == names[1]:
        raise ValueError("names: need two different design variables")
    i, j = space.names.index(names[0]), space.names.index(names[1])
    base = np.asarray(base, dtype=float)
    if base.shape != (space.dim,) or not np.all(np.isfinite(base)):
        raise ValueError(f"base: expected {space.dim} finite values")
    xi, xj = np.asarray(xi, dtype=float), np.asarray(xj, dtype=float)
    rows = dict(map_unordered(call, [_Row(problem, base, i, j, xi, float(v)) for v in xj], client=client))
    values = np.array([rows[float(v)] for v in xj])
    inside_i = (xi >= space.lower[i]) & (xi <= space.upper[i])
    inside_j = (xj >= space.lower[j]) & (xj <= space.upper[j])
    return Surface(names, xi, xj, values, inside_j[:, None] & inside_i[None, :])
