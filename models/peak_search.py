"""One peak search for the whole model layer: grid → candidate samples per cell → bracketed refine.

Used for the certified band maximum of a frequency response (:mod:`railopt.models.response_maxima`),
the maximum of a moving-load deflection profile (:mod:`railopt.models.track.moving_load`) and the
closed-form TMD peak (:mod:`railopt.models.tmd`).  The caller owns the grid (its resolution is
what makes the result trustworthy); this module finds, in each cell, every sampled local maximum
that could hold the cell's true maximum — those within :data:`CANDIDATE_MARGIN` of the cell's best
sample, since a resolved peak is sampled within a few per cent of its top — and refines each between
its grid neighbours (parabolic steps safeguarded by Brent's method), vectorised across candidates.
Refining the best sample alone is not enough: many nearly equal lobes in one cell (the interference
of delayed inputs inside one resonance) are each sampled a little below their tops, and the best
sample need not sit on the highest lobe.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from railopt.models import kernels
from railopt.models.kernels import BRACKET_RTOL, CANDIDATE_MARGIN, INV_PHI, MAX_ITERATIONS, VERTEX_ITERATIONS

SCALAR_CELLS = 12  # kept for compatibility: every cell is refined by the one Brent of railopt.models.kernels


def _floats(a: object) -> np.ndarray:
    return kernels.c_array(np.ravel(a))


def bracketed_maximum(fun: Callable[[np.ndarray], np.ndarray], lower: np.ndarray, upper: np.ndarray,
                      rtol: float = BRACKET_RTOL) -> tuple[np.ndarray, np.ndarray]:
    """Maximise a vectorised ``fun`` over each bracket ``[lower_i, upper_i]`` by Brent's method.

    Brent's bounded minimisation (parabolic interpolation through the three best points,
    safeguarded by golden-section steps; as in scipy's ``fminbound``), over all brackets at once:
    ``fun(x)`` takes one abscissa per still-active bracket.  A bracket stops when its best point is
    located to ``rtol`` times its initial width; the value error of a smooth maximum is then
    ~rtol² relative.  Returns the best point of each bracket and its value.  The steps are the compiled
    :func:`railopt.models.kernels.brent_run`; only the calls of ``fun`` are Python.
    """
    a, b = _floats(lower), _floats(upper)
    if a.size == 0:
        return a, a.copy()
    return kernels.brent_run(a, b, float(rtol), False, fun)


def vertex_refine(fun: Callable[[np.ndarray], np.ndarray], x0: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                  rtol: float = BRACKET_RTOL, positive: bool = True,
                  scale: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Maximiser of ``fun`` in each bracket ``[lower_i, upper_i]`` from its best sample ``x0_i``, all brackets at once.

    Newton steps on the local parabola: each step samples x ± h (one call of ``fun`` for every bracket) and moves
    to the vertex of the parabola through the three points of φ = 1/f² (``positive``; exactly a parabola near a
    resonance of one pole, see :func:`cell_maxima`) or of −f, with h a tenth of the last step (at least
    10·tol), so the steps contract superlinearly; a start within a quarter of the bracket from its ends starts
    mid-way instead.  ``scale`` (one positive value per bracket, e.g. its best sample) makes φ = (scale/f)², so
    that neither f² nor 1/f² over- or underflows for values far from 1 (a peak of 1e160 or 1e-170).  A bracket
    is done when a step is below tol (Brent's ``rtol``·width/3, as in :func:`bracketed_maximum`) from a parabola
    fitted over at most 100·tol.  Returns ``(x, ok)``; ``ok`` is False
    where a step would leave the bracket or the parabola is not convex (the caller refines those by Brent).
    The steps are the compiled :func:`railopt.models.kernels.vertex_run`.
    """
    x = _floats(x0)
    ref = np.ones(x.size) if scale is None else _floats(scale)
    return kernels.vertex_run(x, _floats(lower), _floats(upper), float(rtol), bool(positive), ref, fun)


def cell_maxima(fun: Callable[[np.ndarray], np.ndarray], grid: np.ndarray, values: np.ndarray,
                boundaries: np.ndarray, rtol: float = BRACKET_RTOL,
                scalar: Callable[[float], float] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Maximum of ``fun`` over each cell ``[boundaries[j], boundaries[j+1]]``.

    ``grid`` (sorted, containing every boundary) and ``values = fun(grid)`` are the caller's
    samples.  In each cell every sampled local maximum within :data:`CANDIDATE_MARGIN` of the cell's
    best sample is refined between its grid neighbours (clipped to the cell), and the cell's value is
    the best refined one (never below its best sample).  A non-finite best sample (a pole hit) is
    returned as it is.  Returns (x, f), one per cell.  ``scalar`` is accepted for compatibility and unused.
    The algorithm is :func:`railopt.models.kernels.refine_cells` (the same source runs compiled for the
    pole–residue |H|); raises ``ValueError`` naming ``grid`` when a cell holds no sample.
    """
    bounds = _floats(boundaries)
    x, f, empty = kernels.refine_cells(_floats(grid), _floats(values), bounds, float(rtol), fun)
    if empty >= 0:
        raise ValueError(f"grid: no sample in cell [{bounds[empty]:g}, {bounds[empty + 1]:g}]; include the "
                         "boundaries")
    return x, f


def grid_maximum(fun: Callable[[np.ndarray], np.ndarray], grid: np.ndarray, values: np.ndarray | None = None,
                 rtol: float = BRACKET_RTOL) -> tuple[float, float]:
    """Global maximum of ``fun`` sampled on ``grid``: the best sample refined between its neighbours."""
    grid = np.asarray(grid, dtype=float)
    values = fun(grid) if values is None else values
    x, f = cell_maxima(fun, grid, values, np.array([grid[0], grid[-1]]), rtol)
    return float(x[0]), float(f[0])


__all__ = [
    "BRACKET_RTOL", "CANDIDATE_MARGIN", "INV_PHI", "MAX_ITERATIONS", "SCALAR_CELLS", "VERTEX_ITERATIONS",
    "bracketed_maximum", "cell_maxima", "grid_maximum", "vertex_refine",
]
