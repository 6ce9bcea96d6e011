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

INV_PHI = (np.sqrt(5.0) - 1.0) / 2.0
BRACKET_RTOL = 1e-6  # stop when the best point is located to this fraction of its bracket (value error ~1e-13)
MAX_ITERATIONS = 80
SCALAR_CELLS = 12  # kept for compatibility: every cell is now refined by the one vectorised Brent
CANDIDATE_MARGIN = 0.1  # sampled local maxima within this fraction of their cell's best sample are refined too


def bracketed_maximum(fun: Callable[[np.ndarray], np.ndarray], lower: np.ndarray, upper: np.ndarray,
                      rtol: float = BRACKET_RTOL) -> tuple[np.ndarray, np.ndarray]:
    """Maximise a vectorised ``fun`` over each bracket ``[lower_i, upper_i]`` by Brent's method.

    Brent's bounded minimisation (parabolic interpolation through the three best points,
    safeguarded by golden-section steps; as in scipy's ``fminbound``), vectorised over brackets:
    ``fun(x)`` takes one abscissa per still-active bracket.  A bracket stops when its best point is
    located to ``rtol`` times its initial width; the value error of a smooth maximum is then
    ~rtol² relative.  Returns the best point of each bracket and its value.

    All brackets advance together (no loop over brackets); a bracket that has converged is written
    out and dropped from the working arrays, so each step costs a fixed number of array operations.
    """
    a = np.asarray(lower, dtype=float).copy()
    b = np.asarray(upper, dtype=float).copy()
    if a.size == 0:
        return a, a.copy()
    g = 1.0 - INV_PHI  # 0.381966…
    tol1 = np.maximum(rtol * (b - a), 4 * np.finfo(float).eps * np.maximum(np.abs(a), np.abs(b))) / 3.0
    x = a + g * (b - a)
    fx = -fun(x)  # minimise −f
    w, v, fw, fv = x.copy(), x.copy(), fx.copy(), fx.copy()
    d = np.zeros_like(a)
    e = np.zeros_like(a)
    out_x, out_f = x.copy(), fx.copy()
    where = np.arange(a.size)  # original index of each working bracket
    for _ in range(MAX_ITERATIONS):
        xm = 0.5 * (a + b)
        keep = np.abs(x - xm) > 2.0 * tol1 - 0.5 * (b - a)
        if not keep.all():  # write out the converged brackets, drop them from the working set
            done = ~keep
            out_x[where[done]], out_f[where[done]] = x[done], fx[done]
            if not keep.any():
                break
            where, a, b, x, w, v, fx, fw, fv, d, e, tol1, xm = (
                arr[keep] for arr in (where, a, b, x, w, v, fx, fw, fv, d, e, tol1, xm))
        # parabola through (x, w, v)
        r = (x - w) * (fx - fv)
        q = (x - v) * (fx - fw)
        p = (x - v) * q - (x - w) * r
        q = 2.0 * (q - r)
        p = np.where(q > 0, -p, p)
        q = np.abs(q)
        with np.errstate(divide="ignore", invalid="ignore"):
            para = ((np.abs(e) > tol1) & (np.abs(p) < np.abs(0.5 * q * e))
                    & (p > q * (a - x)) & (p < q * (b - x)) & (q != 0))
            dp = np.where(para, p / np.where(q == 0, 1.0, q), 0.0)
        up = x + dp
        near_end = para & (((up - a) < 2 * tol1) | ((b - up) < 2 * tol1))
        dp = np.where(near_end, np.where(xm >= x, tol1, -tol1), dp)
        e_gold = np.where(x >= xm, a - x, b - x)
        new_e = np.where(para, d, e_gold)
        new_d = np.where(para, dp, g * e_gold)
        step = np.where(np.abs(new_d) >= tol1, new_d, np.where(new_d >= 0, tol1, -tol1))
        u = x + step
        fu = -fun(u)
        better = fu <= fx
        right = u >= x
        # bracket update
        a = np.where(better, np.where(right, x, a), np.where(right, a, u))
        b = np.where(better, np.where(right, b, x), np.where(right, u, b))
        take_w = ~better & ((fu <= fw) | (w == x))
        take_v = ~better & ~take_w & ((fu <= fv) | (v == x) | (v == w))
        v, fv = np.where(better | take_w, w, np.where(take_v, u, v)), np.where(better | take_w, fw,
                                                                             np.where(take_v, fu, fv))
        w, fw = np.where(better, x, np.where(take_w, u, w)), np.where(better, fx, np.where(take_w, fu, fw))
        x, fx = np.where(better, u, x), np.where(better, fu, fx)
        d, e = step, new_e
    else:
        out_x[where], out_f[where] = x, fx
    return out_x, -out_f


VERTEX_ITERATIONS = 12


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
    """
    lo = np.asarray(lower, dtype=float)
    hi = np.asarray(upper, dtype=float)
    x = np.asarray(x0, dtype=float).copy()
    tol = np.maximum(rtol * (hi - lo), 4 * np.finfo(float).eps * np.maximum(np.abs(lo), np.abs(hi))) / 3.0
    ok = np.zeros(x.size, dtype=bool)
    # a start near an end of its bracket would fit the parabola over a sliver: start such brackets mid-way
    quarter = 0.25 * (hi - lo)
    x = np.where((x - lo > quarter) & (hi - x > quarter), x, 0.5 * (lo + hi))
    live = np.flatnonzero(hi > lo)
    h = 0.5 * np.minimum(x - lo, hi - x)[live]
    ref = np.ones(x.size) if scale is None else np.asarray(scale, dtype=float)
    for _ in range(VERTEX_ITERATIONS):
        if live.size == 0:
            break
        xl, a, b = x[live], lo[live], hi[live]
        left, right = np.maximum(xl - h, a), np.minimum(xl + h, b)
        k = live.size
        f = fun(np.concatenate([left, xl, right]))
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            phi = np.square(np.tile(ref[live], 3) / f) if positive else -f
            pl, pm, pr = phi[:k], phi[k:2 * k], phi[2 * k:]
            dl, dr = xl - left, right - xl
            num = dl * dl * (pm - pr) - dr * dr * (pm - pl)
            den = dl * (pr - pm) + dr * (pl - pm)  # > 0: the parabola through the three points is convex
            step = 0.5 * num / den
        good = (np.isfinite(phi).reshape(3, k).all(axis=0) & (den > 0) & (dl > 0) & (dr > 0)
                & (step > a - xl) & (step < b - xl))
        new = xl + np.where(good, step, 0.0)
        # done: a step below tol from a parabola fitted over ≤ 100·tol (its vertex is then exact to far below tol)
        done = good & (np.abs(step) <= tol[live]) & (h <= 100.0 * tol[live])
        ok[live[done]] = True
        x[live[good]] = new[good]
        keep = good & ~done
        live, h = live[keep], np.maximum(0.1 * np.abs(step[keep]), 10.0 * tol[live[keep]])
    return x, ok


def brent_maximum(fun: Callable[[float], float], lower: float, upper: float,
                  rtol: float = BRACKET_RTOL) -> tuple[float, float]:
    """Scalar twin of :func:`bracketed_maximum` (same algorithm, plain floats): for a few brackets of a cheap
    scalar function it avoids numpy's per-call overhead."""
    a, b = float(lower), float(upper)
    g = 1.0 - INV_PHI
    tol1 = max(rtol * (b - a), 4 * np.finfo(float).eps * max(abs(a), abs(b))) / 3.0
    x = w = v = a + g * (b - a)
    fx = fw = fv = -fun(x)
    d = e = 0.0
    for _ in range(MAX_ITERATIONS):
        xm = 0.5 * (a + b)
        tol2 = 2.0 * tol1
        if abs(x - xm) <= tol2 - 0.5 * (b - a):
            break
        para = False
        if abs(e) > tol1:
            r = (x - w) * (fx - fv)
            q = (x - v) * (fx - fw)
            p = (x - v) * q - (x - w) * r
            q = 2.0 * (q - r)
            if q > 0:
                p = -p
            q = abs(q)
            if q != 0 and abs(p) < abs(0.5 * q * e) and q * (a - x) < p < q * (b - x):
                para = True
                e, d = d, p / q
                u = x + d
                if u - a < tol2 or b - u < tol2:
                    d = tol1 if xm >= x else -tol1
        if not para:
            e = (a - x) if x >= xm else (b - x)
            d = g * e
        u = x + (d if abs(d) >= tol1 else (tol1 if d >= 0 else -tol1))
        fu = -fun(u)
        if fu <= fx:
            if u >= x:
                a = x
            else:
                b = x
            v, fv, w, fw, x, fx = w, fw, x, fx, u, fu
        else:
            if u < x:
                a = u
            else:
                b = u
            if fu <= fw or w == x:
                v, fv, w, fw = w, fw, u, fu
            elif fu <= fv or v == x or v == w:
                v, fv = u, fu
    return x, -fx


def cell_maxima(fun: Callable[[np.ndarray], np.ndarray], grid: np.ndarray, values: np.ndarray,
                boundaries: np.ndarray, rtol: float = BRACKET_RTOL,
                scalar: Callable[[float], float] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Maximum of ``fun`` over each cell ``[boundaries[j], boundaries[j+1]]``.

    ``grid`` (sorted, containing every boundary) and ``values = fun(grid)`` are the caller's
    samples.  In each cell every sampled local maximum within :data:`CANDIDATE_MARGIN` of the cell's
    best sample is refined between its grid neighbours (clipped to the cell), and the cell's value is
    the best refined one (never below its best sample).  A non-finite best sample (a pole hit) is
    returned as it is.  Returns (x, f), one per cell.
    """
    grid = np.asarray(grid, dtype=float)
    values = np.asarray(values, dtype=float)
    bounds = np.asarray(boundaries, dtype=float)
    # index range of each cell in the sorted grid, then the best sample of each (no loop over cells)
    start = np.searchsorted(grid, bounds[:-1], side="left")
    stop = np.searchsorted(grid, bounds[1:], side="right")
    if np.any(stop <= start):
        j = int(np.flatnonzero(stop <= start)[0])
        raise ValueError(f"grid: no sample in cell [{bounds[j]:g}, {bounds[j + 1]:g}]; include the boundaries")
    masked = np.where(np.isnan(values), -np.inf, values)
    # the samples of every cell laid end to end (cells share their boundary samples), then one segmented
    # reduction per quantity
    counts = stop - start
    n_cells = len(start)
    offsets = np.zeros(n_cells, dtype=np.intp)
    np.cumsum(counts[:-1], out=offsets[1:])
    size = int(counts.sum())
    members = np.arange(size) + np.repeat(start - offsets, counts)
    cell_values = masked[members]
    cell_max = np.maximum.reduceat(cell_values, offsets)
    top = np.repeat(cell_max, counts)
    at_top = np.minimum.reduceat(np.where(cell_values == top, np.arange(size), size), offsets)
    best = members[at_top]  # first sample attaining the cell's maximum
    x, f = grid[best].copy(), values[best].copy()
    # candidates: the cell's sampled local maxima (above the left neighbour, not below the right one, within the
    # cell) within CANDIDATE_MARGIN of its best sample; the best sample is always one
    left = np.empty(size)
    left[1:], left[offsets] = cell_values[:-1], -np.inf
    right = np.empty(size)
    right[:-1], right[offsets + counts - 1] = cell_values[1:], -np.inf
    with np.errstate(invalid="ignore"):  # an infinite best sample has no candidates (it is returned as it is)
        near = cell_values >= top - CANDIDATE_MARGIN * np.abs(top)
    candidate = near & (cell_values > left) & (cell_values >= right)
    candidate[at_top] = True
    candidate &= np.isfinite(cell_values) & np.isfinite(top)
    which = np.flatnonzero(candidate)
    if which.size == 0:
        return x, f
    cells = np.searchsorted(offsets, which, side="right") - 1
    gi = members[which]
    cx, cf = grid[gi], values[gi]
    lo_cell, hi_cell = bounds[:-1][cells], bounds[1:][cells]
    lo = np.maximum(grid[np.maximum(gi - 1, 0)], lo_cell)
    hi = np.minimum(grid[np.minimum(gi + 1, len(grid) - 1)], hi_cell)
    refine = hi > lo
    # a candidate on a cell boundary is the maximum there when f falls into the cell from it (no bump
    # inside the first step): one probe instead of a one-sided search
    at_lo, at_hi = refine & (cx <= lo_cell), refine & (cx >= hi_cell)
    edge = np.flatnonzero(at_lo | at_hi)
    if edge.size:
        h = 1e-6 * (hi[edge] - lo[edge])
        probe = np.where(at_lo[edge], cx[edge] + h, cx[edge] - h)
        refine[edge[fun(probe) <= cf[edge]]] = False
    idx = np.flatnonzero(refine)
    if idx.size:
        # −(s/f)² (s: the candidate's sample) has the same maximiser as f > 0 and is exactly a parabola near a
        # resonance of one pole (|H|² ∝ 1/((Ω−ω)² + σ²)), so the parabolic steps converge in a few iterations
        positive = bool(np.all(values[np.isfinite(values)] > 0))
        ref = cf[idx] if positive else None
        xr, ok = vertex_refine(fun, cx[idx], lo[idx], hi[idx], rtol, positive, ref)  # every candidate at once
        if not ok.all():  # the safeguard: Brent where the local parabola did not settle (log f: scale-free)
            def target(w: np.ndarray) -> np.ndarray:
                with np.errstate(divide="ignore"):
                    return np.log(fun(w)) if positive else fun(w)

            xr[~ok], _ = bracketed_maximum(target, lo[idx[~ok]], hi[idx[~ok]], rtol)
        fr = fun(xr)
        better = fr > cf[idx]
        cx[idx] = np.where(better, xr, cx[idx])
        cf[idx] = np.where(better, fr, cf[idx])
    # each cell's best candidate (candidates are in cell order): the largest value, the first on ties
    if which.size == n_cells:  # one candidate per cell (the usual case): it is the cell's
        winners, pick = cells, np.arange(which.size)
    else:
        order = np.lexsort((-cf, cells))
        pick = order[np.r_[True, cells[order][1:] != cells[order][:-1]]]
        winners = cells[pick]
    take = cf[pick] > f[winners]
    x[winners[take]], f[winners[take]] = cx[pick][take], cf[pick][take]
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
    "bracketed_maximum", "brent_maximum", "cell_maxima", "grid_maximum", "vertex_refine",
]
