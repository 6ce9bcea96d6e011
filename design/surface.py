"""Objective surfaces: U over a grid of two design variables with the others fixed (Fig 4.18).

The grid may extend beyond the variables' bounds (the unconstrained surface, where the thesis
notes the trivial optimum at zero stiffness); ``constrained`` marks the points inside them.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from railopt.design.parallel import (
    ProgressCallback,
    call,
    check_picklable,
    map_unordered,
    no_progress,
    progress_of,
    resolve,
    shipping,
)
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


BLOCK_POINTS = 512
"""Grid points of one task of a batched grid (whole rows, at least one): one ``fn`` call evaluates them all.  A
call's fixed cost (the model's stacked matrices, one stacked eigen-decomposition, one compiled call) is ~0.8 ms
against ~35 µs a point of the flagship's cab model: a 21-point row per call spends half its time on it."""


@dataclass(frozen=True)
class _Rows:
    """Rows ``first``, ``first + 1``, … of a grid (a task): ``fn`` at x with ``x[i]`` over ``xi`` and ``x[j]`` each
    of ``xj_values`` in turn, the rest ``base``; returns ``(first, values (rows, len(xi), …))``."""

    fn: Callable[[np.ndarray], object]
    base: np.ndarray
    i: int
    j: int
    xi: np.ndarray
    xj_values: tuple[float, ...]
    first: int = 0

    batched: bool = False  # fn takes all the task's designs (rows × len(xi), d) at once

    def __call__(self) -> tuple[int, np.ndarray]:
        fn = resolve(self.fn)  # fn shipped once per grid (a handle inside a dask task)
        X = np.repeat(self.base[None, :], len(self.xi) * len(self.xj_values), axis=0)
        X[:, self.i] = np.tile(self.xi, len(self.xj_values))
        X[:, self.j] = np.repeat(self.xj_values, len(self.xi))
        if self.batched:
            values = np.asarray(fn(X), dtype=float)
            if values.ndim == 0 or values.shape[0] != len(X):
                raise ValueError(f"fn: a batched fn must return one value (or vector) per design, shape ({len(X)}, "
                                 f"…), got shape {values.shape}")
        else:
            values = np.array([fn(x) for x in X], dtype=float)
        return self.first, values.reshape(len(self.xj_values), len(self.xi), *values.shape[1:])


@dataclass(frozen=True)
class _Values:
    """U at a block of designs (B, d) or at one design; +inf where the model refuses a design (e.g. a singular
    model at zero stiffness): :meth:`MinimaxProblem.values`, batched when the problem has ``batch_functions``."""

    problem: MinimaxProblem

    def __call__(self, X: np.ndarray) -> np.ndarray | float:
        """U at the designs X (B, d), or at one design x (d,) (a grid evaluated a design at a time)."""
        if X.ndim == 1:
            return float(self.problem.values(X[None, :])[0])
        return self.problem.values(X)


def grid_map(fn: Callable[[np.ndarray], object], space_names: Sequence[str], names: tuple[str, str],
             xi: Sequence[float], xj: Sequence[float], base: Sequence[float],
             client: Runner | None = None, progress: ProgressCallback | None = None,
             batched: bool = False) -> np.ndarray:
    """``fn(x)`` on the grid ``xi × xj`` of the two named variables (the others at ``base``): an array
    (len(xj), len(xi), …) — ``fn`` may return a number or a vector.  One task per grid row, or with ``batched`` (``fn``
    takes many designs at once, shape (B, d), and returns (B, …)) one task and one call per block of whole rows of
    about :data:`BLOCK_POINTS` points.  ``progress(done, total)`` counts finished rows (default: the enclosing
    :func:`~railopt.design.parallel.reporting_progress`)."""
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
    if len(xi) == 0 or len(xj) == 0:
        return np.zeros((len(xj), len(xi)))
    per_task = max(1, BLOCK_POINTS // len(xi)) if batched else 1
    tasks = [(k, tuple(float(v) for v in xj[k:k + per_task])) for k in range(0, len(xj), per_task)]
    report = progress_of(progress)  # counted in rows, whatever the tasks
    blocks: dict[int, np.ndarray] = {}  # by position (equal, -0.0 or NaN values of xj stay apart)
    finished = 0
    with shipping(client, fn, "fn") as shipped:  # the problem goes to the workers once, not with every task
        if report is not None:
            report(0, len(xj))
        for first, values in map_unordered(call, [_Rows(shipped, base, i, j, xi, b, k, batched) for k, b in tasks],
                                           client=client, progress=no_progress):
            blocks[first] = values
            finished += len(values)
            if report is not None:
                report(finished, len(xj))
    return np.concatenate([blocks[k] for k, _ in tasks])


def objective_surface(
    problem: MinimaxProblem,
    names: tuple[str, str],
    xi: Sequence[float],
    xj: Sequence[float],
    base: Sequence[float],
    client: Runner | None = None,
    progress: ProgressCallback | None = None,
) -> Surface:
    """U over ``xi × xj`` for the two named variables, the others at ``base`` (``progress(done, total)`` in rows, as
    :func:`grid_map`).  A problem with ``batch_functions`` (:meth:`MinimaxProblem.values`) goes in blocks of whole
    rows of about :data:`BLOCK_POINTS` points, one task and one call each; any other one task per grid row, a design
    at a time (so that a cluster shares the rows)."""
    space = problem.space
    values = grid_map(_Values(problem), space.names, names, xi, xj, base, client, progress,
                      batched=problem.has_batch)
    i, j = space.names.index(names[0]), space.names.index(names[1])
    xi, xj = np.asarray(xi, dtype=float), np.asarray(xj, dtype=float)
    inside_i = (xi >= space.lower[i]) & (xi <= space.upper[i])
    inside_j = (xj >= space.lower[j]) & (xj <= space.upper[j])
    return Surface(names, xi, xj, values, inside_j[:, None] & inside_i[None, :])


__all__ = ["BLOCK_POINTS", "Surface", "grid_map", "objective_surface"]
