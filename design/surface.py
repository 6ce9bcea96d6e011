"""Objective surfaces: U over a grid of two design variables with the others fixed (Fig 4.18).

The grid may extend beyond the variables' bounds (the unconstrained surface, where the thesis
notes the trivial optimum at zero stiffness); ``constrained`` marks the points inside them.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from railopt.design.parallel import ProgressCallback, call, check_picklable, map_unordered, resolve, shipping
from railopt.design.problem import MinimaxProblem
from railopt.design.runner import Runner
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
        """The grid as a long table: one row per point with both variables, ``U`` and ``inside_bounds``."""
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
    """One row of a grid (a task): ``fn`` at x with ``x[i]`` over ``xi`` and ``x[j] = xj_value``, the rest ``base``."""

    fn: Callable[[np.ndarray], object]
    base: np.ndarray
    i: int
    j: int
    xi: np.ndarray
    xj_value: float

    batched: bool = False  # fn takes the row's designs (len(xi), d) at once

    def __call__(self) -> tuple[float, np.ndarray]:
        fn = resolve(self.fn)  # fn shipped once per grid (a handle inside a dask task)
        X = np.repeat(self.base[None, :], len(self.xi), axis=0)
        X[:, self.i], X[:, self.j] = self.xi, self.xj_value
        if self.batched:
            return self.xj_value, np.asarray(fn(X), dtype=float)
        return self.xj_value, np.array([fn(x) for x in X], dtype=float)


@dataclass(frozen=True)
class _Values:
    """U at a row of designs (B, d); +inf where the model refuses a design (e.g. a singular model at zero
    stiffness): :meth:`MinimaxProblem.values`, batched when the problem has ``batch_functions``."""

    problem: MinimaxProblem

    def __call__(self, X: np.ndarray) -> np.ndarray:
        return self.problem.values(X)


def grid_map(fn: Callable[[np.ndarray], object], space_names: Sequence[str], names: tuple[str, str],
             xi: Sequence[float], xj: Sequence[float], base: Sequence[float],
             client: Runner | None = None, progress: ProgressCallback | None = None,
             batched: bool = False) -> np.ndarray:
    """``fn(x)`` on the grid ``xi × xj`` of the two named variables (the others at ``base``), one task per grid
    row: an array (len(xj), len(xi), …) — ``fn`` may return a number or a vector.  ``progress(done, total)``
    counts finished rows (default: the enclosing :func:`~railopt.design.parallel.reporting_progress`).
    ``batched``: ``fn`` takes a whole row of designs, shape (len(xi), d), and returns (len(xi), …)."""
    space_names = list(space_names)
    for n in names:
        if n not in space_names:
            raise ValueError(f"names: unknown design variable {n!r}; known: {tuple(space_names)}")
    if names[0] == names[1]:
        raise ValueError("names: need two different design variables")
    i, j = space_names.index(names[0]), space_names.index(names[1])
    base = np.asarray(base, dtype=float)
    if base.shape != (len(space_names),) or not np.all(np.isfinite(base)):
        raise ValueError(f"base: expected {len(space_names)} finite values")
    xi, xj = np.asarray(xi, dtype=float), np.asarray(xj, dtype=float)
    if client is not None:
        check_picklable(fn)  # named from fn's own fields (e.g. problem.functions), not the row task's
    with shipping(client, fn, "fn") as shipped:  # the problem goes to the workers once, not with every row
        rows = dict(map_unordered(call, [_Row(shipped, base, i, j, xi, float(v), batched) for v in xj],
                                  client=client, progress=progress))
    return np.array([rows[float(v)] for v in xj])


def objective_surface(
    problem: MinimaxProblem,
    names: tuple[str, str],
    xi: Sequence[float],
    xj: Sequence[float],
    base: Sequence[float],
    client: Runner | None = None,
    progress: ProgressCallback | None = None,
) -> Surface:
    """U over ``xi × xj`` for the two named variables, the others at ``base``; one task per grid row
    (``progress(done, total)`` in rows, as :func:`grid_map`), each row one call of the problem's
    ``batch_functions`` when it has them (:meth:`MinimaxProblem.values`)."""
    space = problem.space
    values = grid_map(_Values(problem), space.names, names, xi, xj, base, client, progress, batched=True)
    i, j = space.names.index(names[0]), space.names.index(names[1])
    xi, xj = np.asarray(xi, dtype=float), np.asarray(xj, dtype=float)
    inside_i = (xi >= space.lower[i]) & (xi <= space.upper[i])
    inside_j = (xj >= space.lower[j]) & (xj <= space.upper[j])
    return Surface(names, xi, xj, values, inside_j[:, None] & inside_i[None, :])


__all__ = ["Surface", "grid_map", "objective_surface"]
