"""One peak search for the whole model layer: grid → best sample per cell → golden-section refine.

Used for the certified band maximum of a frequency response (:mod:`railopt.models.response_maxima`),
the maximum of a moving-load deflection profile (:mod:`railopt.models.track.moving_load`) and the
closed-form TMD peak (:mod:`railopt.models.tmd`).  The caller owns the grid (its resolution is
what makes the result trustworthy); this module only finds, in each cell, the best sample and
refines it between that sample's neighbours (parabolic interpolation safeguarded by golden
section), vectorised across cells.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

INV_PHI = (np.sqrt(5.0) - 1.0) / 2.0
BRACKET_RTOL = 1e-6  # stop when the best point is located to this fraction of its bracket (value error ~1e-13)
MAX_ITERATIONS = 80
SCALAR_CELLS = 12  # up to this many cells, refine each with the scalar Brent (no numpy overhead per step)


def bracketed_maximum(fun: Callable[[np.ndarray], np.ndarray], lower: np.ndarray, upper: np.ndarray,
                      rtol: float = BRACKET_RTOL) -> tuple[np.ndarray, np.ndarray]:
    """Maximise a vectorised ``fun`` over each bracket ``[lower_i, upper_i]`` by Brent's method.

    Brent's bounded minimisation (parabolic interpolation through the three best points,
    safeguarded by golden-section steps; as in scipy's ``fminbound``), vectorised over brackets:
    ``fun(x)`` takes one abscissa per still-active bracket.  A bracket stops when its best point is
    located to ``rtol`` times its initial width; the value error of a smooth maximum is then
    ~rtol² relative.  Returns the best point of each bracket and its value.
    """
    a = np.asarray(lower, dtype=float).copy()
    b = np.asarray(upper, dtype=float).copy()
    if a.size == 0:
        return a, a.copy()
    g = 1.0 - INV_PHI  # 0.381966…
    tol1 = np.maximum(rtol * (b - a), 4 * np.finfo(float).eps * np.maximum(np.abs(a), np.abs(b))) / 3.0
    x = a + g * (b - a)
    w, v = x.copy(), x.copy()
    fx = -fun(x)  # minimise −f
    fw, fv = fx.copy(), fx.copy()
    d = np.zeros_like(a)
    e = np.zeros_like(a)
    active = np.ones(a.size, dtype=bool)
    for _ in range(MAX_ITERATIONS):
        xm = 0.5 * (a + b)
        tol2 = 2.0 * tol1
        active &= np.abs(x - xm) > tol2 - 0.5 * (b - a)
        i = np.flatnonzero(active)
        if i.size == 0:
            break
        ai, bi, xi, wi, vi = a[i], b[i], x[i], w[i], v[i]
        fxi, fwi, fvi, di, ei, t1, xmi = fx[i], fw[i], fv[i], d[i], e[i], tol1[i], xm[i]
        # parabola through (x, w, v)
        r = (xi - wi) * (fxi - fvi)
        q = (xi - vi) * (fxi - fwi)
        p = (xi - vi) * q - (xi - wi) * r
        q = 2.0 * (q - r)
        p = np.where(q > 0, -p, p)
        q = np.abs(q)
        with np.errstate(divide="ignore", invalid="ignore"):
            para = ((np.abs(ei) > t1) & (np.abs(p) < np.abs(0.5 * q * ei))
                    & (p > q * (ai - xi)) & (p < q * (bi - xi)) & (q != 0))
            dp = np.where(para, p / np.where(q == 0, 1.0, q), 0.0)
        up = xi + dp
        near_end = para & (((up - ai) < 2 * t1) | ((bi - up) < 2 * t1))
        dp = np.where(near_end, np.where(xmi >= xi, t1, -t1), dp)
        e_gold = np.where(xi >= xmi, ai - xi, bi - xi)
        new_e = np.where(para, di, e_gold)
        new_d = np.where(para, dp, g * e_gold)
        step = np.where(np.abs(new_d) >= t1, new_d, np.where(new_d >= 0, t1, -t1))
        u = xi + step
        fu = -fun(u)
        better = fu <= fxi
        # bracket update
        a[i] = np.where(better, np.where(u >= xi, xi, ai), np.where(u < xi, u, ai))
        b[i] = np.where(better, np.where(u >= xi, bi, xi), np.where(u < xi, bi, u))
        take_w = ~better & ((fu <= fwi) | (wi == xi))
        take_v = ~better & ~take_w & ((fu <= fvi) | (vi == xi) | (vi == wi))
        v[i] = np.where(better, wi, np.where(take_w, wi, np.where(take_v, u, vi)))
        fv[i] = np.where(better, fwi, np.where(take_w, fwi, np.where(take_v, fu, fvi)))
        w[i] = np.where(better, xi, np.where(take_w, u, wi))
        fw[i] = np.where(better, fxi, np.where(take_w, fu, fwi))
        x[i] = np.where(better, u, xi)
        fx[i] = np.where(better, fu, fxi)
        d[i], e[i] = step, new_e
    return x, -fx


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
    samples.  In each cell the best sample is refined between its grid neighbours (clipped to the
    cell).  A non-finite best sample (a pole hit) is returned as it is.  Returns (x, f), one per cell.
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
    order = np.repeat(np.arange(len(start)), stop - start)
    members = np.concatenate([np.arange(a, b) for a, b in zip(start, stop, strict=True)])
    cell_max = np.full(len(start), -np.inf)
    np.maximum.at(cell_max, order, masked[members])
    hit = masked[members] == cell_max[order]
    best = np.full(len(start), -1)
    best[order[hit][::-1]] = members[hit][::-1]  # first sample attaining the cell's maximum
    x, f = grid[best].copy(), values[best].copy()
    lo_cell, hi_cell = bounds[:-1], bounds[1:]
    lo = np.maximum(grid[np.maximum(best - 1, 0)], lo_cell)
    hi = np.minimum(grid[np.minimum(best + 1, len(grid) - 1)], hi_cell)
    refine = np.isfinite(f) & (hi > lo)
    # a best sample on a cell boundary is the maximum when f falls into the cell from it (no bump
    # inside the first step): one probe instead of a one-sided search
    at_lo, at_hi = refine & (x <= lo_cell), refine & (x >= hi_cell)
    edge = np.flatnonzero(at_lo | at_hi)
    if edge.size:
        h = 1e-6 * (hi[edge] - lo[edge])
        probe = np.where(at_lo[edge], x[edge] + h, x[edge] - h)
        refine[edge[fun(probe) <= f[edge]]] = False
    idx = np.flatnonzero(refine)
    if idx.size:
        # −1/f² has the same maximiser as f > 0 and is exactly a parabola near a resonance of one
        # pole (|H|² ∝ 1/((Ω−ω)² + σ²)), so the parabolic steps converge in a few iterations
        positive = bool(np.all(values[np.isfinite(values)] > 0))
        if scalar is not None and idx.size <= SCALAR_CELLS:
            target_s = (lambda w: -1.0 / scalar(w) ** 2) if positive else scalar
            xr = np.array([brent_maximum(target_s, lo[i], hi[i], rtol)[0] for i in idx])
        else:
            target = (lambda w: -1.0 / np.square(fun(w))) if positive else fun
            xr, _ = bracketed_maximum(target, lo[idx], hi[idx], rtol)
        fr = fun(xr)
        better = fr > f[idx]
        x[idx] = np.where(better, xr, x[idx])
        f[idx] = np.where(better, fr, f[idx])
    return x, f


def grid_maximum(fun: Callable[[np.ndarray], np.ndarray], grid: np.ndarray, values: np.ndarray | None = None,
                 rtol: float = BRACKET_RTOL) -> tuple[float, float]:
    """Global maximum of ``fun`` sampled on ``grid``: the best sample refined between its neighbours."""
    grid = np.asarray(grid, dtype=float)
    values = fun(grid) if values is None else values
    x, f = cell_maxima(fun, grid, values, np.array([grid[0], grid[-1]]), rtol)
    return float(x[0]), float(f[0])
