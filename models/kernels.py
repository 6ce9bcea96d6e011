"""Compiled kernels (numba) of the certified band maximum: the one implementation of its hot formulas.

What lives here, each written once:

- :func:`member_state` (M⁻¹[K C] with the regularity check of M), :func:`left_vectors` (W = V⁻¹ and cond₁(V)),
  :func:`residues` (the pole–residue coefficients) and :func:`direct_solutions` (``Z(Ω)X = F`` at many Ω);
- :func:`band_grid` — the frequency grid of the exact method (per-pole ``Ω = ω_k + σ_k sinh(u)`` points, a uniform
  floor/delay grid, bisection of any step that breaks ``step ≤ GRID_FACTOR·dist(iΩ, poles)``);
- :func:`pole_residue_sums` / :func:`pole_residue_magnitudes` — the pole–residue sum
  ``S_o(Ω) = Σ_t e^{−iΩτ_t} Σ_j (iΩ)^j Σ_k R[k, o, t, j] / (iΩ − s_k)`` (thesis eqs. 4.53–4.58 with the
  forcing's polynomial/delay terms; :mod:`railopt.models.pole_residue`) and ``|(iΩ)^q S_o(Ω)|``;
- the peak search of :mod:`railopt.models.peak_search`: candidate samples per cell, the parabolic vertex steps
  (:func:`vertex_start` / :func:`vertex_update`), Brent's bounded steps (:func:`brent_start` /
  :func:`brent_propose` / :func:`brent_accept`, the arithmetic of scipy's ``fminbound``) and their drivers
  :func:`vertex_run`, :func:`brent_run`, :func:`refine_cells`.

The drivers are plain Python functions that numba also compiles (``numba.extending.overload`` of the function by
itself): called from Python with a callable evaluator they drive the compiled step kernels from a thin Python loop
(the moving-load profile, the TMD formula, a callable forcing); inside :func:`cell_maxima_pole_residue` the same
source runs compiled with the pole–residue evaluator inline.  The algorithm is therefore written once.

Conventions: every kernel takes C-contiguous float64/complex128 arrays and int64 indices (the Python callers
normalise at the boundary, so each kernel has one compiled signature); ``@njit(cache=True, nogil=True)`` with
numpy's error model (a division by zero gives inf/nan, never an exception).  Compilation happens on first call
(about 10–15 s once per cache directory); the machine code is cached in ``NUMBA_CACHE_DIR`` (default:
``__pycache__`` beside this file when writable, else ``~/.cache/numba``), so later processes load it in ~0.1 s.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numba import njit
from numba.extending import overload

JIT = {"cache": True, "nogil": True, "error_model": "numpy"}
EPS = float(np.finfo(float).eps)
INV_PHI = (math.sqrt(5.0) - 1.0) / 2.0
BRACKET_RTOL = 1e-6  # stop when the best point is located to this fraction of its bracket (value error ~1e-13)
MAX_ITERATIONS = 80
VERTEX_ITERATIONS = 12
CANDIDATE_MARGIN = 0.1  # sampled local maxima within this fraction of their cell's best sample are refined too

# columns of the Brent state (one row per bracket)
_A, _B, _X, _W, _V, _FX, _FW, _FV, _D, _E, _TOL, _U, _NE, _DONE = range(14)
# columns of the vertex state
_VX, _VLO, _VHI, _VTOL, _VH, _VREF, _VOK = range(7)


def c_array(a: object, dtype: type = float) -> np.ndarray:
    """``a`` as a writeable C-contiguous array of ``dtype`` (float64 or complex128), copied only when needed: the
    kernels' one compiled signature per argument (a read-only or strided array would compile a second one)."""
    arr = np.asarray(a, dtype=dtype)
    if arr.flags.c_contiguous and arr.flags.writeable:
        return arr
    return np.array(arr, dtype=dtype, order="C")


def dual(function):
    """Make ``function`` callable from compiled code too (numba compiles its own source for a compiled caller)."""
    @functools.wraps(function)  # the typing function must show the implementation's signature
    def typer(*args, **kwargs):
        return function

    overload(function, jit_options={"error_model": "numpy", "nogil": True})(typer)
    return function


# ---------------------------------------------------------------------------------------------------- member, modes
@njit(**JIT)
def member_state(M: np.ndarray, K: np.ndarray, C: np.ndarray, singular_pivot: float) -> tuple[np.ndarray, bool]:
    """M⁻¹[K C] (n, 2n) of the state matrix G = [[0, I], [−M⁻¹K, −M⁻¹C]] (thesis eq. 4.53), and whether M is
    regular: its partial-pivot LU (LAPACK getrf's pivot rule) has every |pivot| > ``singular_pivot``·max|pivot|.
    The solve is LAPACK gesv (numpy's ``solve``); a singular M returns zeros and False."""
    n = M.shape[0]
    LU = M.copy()
    for k in range(n):
        p = k
        for i in range(k + 1, n):
            if abs(LU[i, k]) > abs(LU[p, k]):
                p = i
        if p != k:
            for j in range(n):
                LU[k, j], LU[p, j] = LU[p, j], LU[k, j]
        if LU[k, k] != 0.0:
            for i in range(k + 1, n):
                LU[i, k] /= LU[k, k]
                for j in range(k + 1, n):
                    LU[i, j] -= LU[i, k] * LU[k, j]
    pmax, pmin = 0.0, math.inf
    for i in range(n):
        pmax, pmin = max(pmax, abs(LU[i, i])), min(pmin, abs(LU[i, i]))
    if n and not pmin > singular_pivot * max(pmax, 1e-300):
        return np.zeros((n, 2 * n)), False
    KC = np.empty((n, 2 * n))
    KC[:, :n] = K
    KC[:, n:] = C
    return np.ascontiguousarray(np.linalg.solve(M, KC)), True


@njit(**JIT)
def left_vectors(V: np.ndarray) -> tuple[np.ndarray, float]:
    """W = V⁻¹ (LAPACK gesv on V W = I) and cond₁(V) = ‖V‖₁‖W‖₁ (inf when it overflows); raises numpy's
    ``LinAlgError`` when V is exactly singular."""
    N = V.shape[0]
    W = np.ascontiguousarray(np.linalg.solve(V, np.eye(N, dtype=np.complex128)))  # LAPACK gives Fortran order
    nv, nw = 0.0, 0.0
    for j in range(N):
        a, b = 0.0, 0.0
        for i in range(N):
            a += abs(V[i, j])
            b += abs(W[i, j])
        nv, nw = max(nv, a), max(nw, b)
    cond = nv * nw
    return W, cond if math.isfinite(cond) else math.inf


@njit(**JIT)
def residues(M: np.ndarray, V: np.ndarray, W: np.ndarray, rows: np.ndarray, A: np.ndarray) -> tuple[np.ndarray,
                                                                                                     np.ndarray]:
    """Residues R[k, o, t, j] = (c_o·V_x[:, k]) (W_v M⁻¹ A_tj)_k (thesis eqs. 4.53–4.58) and B = W_v M⁻¹ (2n, n).

    M (n, n) real; V, W (2n, 2n) complex; rows (m, n) real output rows; A (T, J, n) complex forcing coefficients.
    """
    n = M.shape[0]
    N = V.shape[0]
    Wv = np.ascontiguousarray(W[:, n:])
    B = np.ascontiguousarray(np.linalg.solve(np.ascontiguousarray(M.T).astype(np.complex128),
                                             np.ascontiguousarray(Wv.T)).T)
    T, J, m = A.shape[0], A.shape[1], rows.shape[0]
    R = np.zeros((N, m, T, J), np.complex128)
    for k in range(N):
        for o in range(m):
            cv = 0j
            for i in range(n):
                cv += rows[o, i] * V[i, k]
            for t in range(T):
                for j in range(J):
                    ba = 0j
                    for i in range(n):
                        ba += B[k, i] * A[t, j, i]
                    R[k, o, t, j] = cv * ba
    return R, B


@njit(**JIT)
def direct_solutions(M: np.ndarray, C: np.ndarray, K: np.ndarray, w: np.ndarray,
                     F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """X (N, n): Z(Ω)X = F(Ω) with Z = K − Ω²M + iΩC (thesis eqs. 4.69–4.70) at each Ω of ``w`` (N,), F (N, n)
    complex; LAPACK gesv per frequency (numpy's ``LinAlgError`` when a Z is exactly singular).  Also ``overflow``
    (N,) bool: Z(Ω) has a non-finite entry there; when any has, nothing is solved (X is NaN)."""
    n = M.shape[0]
    X = np.full((w.size, n), complex(math.nan, math.nan))
    overflow = np.zeros(w.size, np.bool_)
    Z = np.empty((n, n), np.complex128)
    for solve in (False, True):  # first every Z is checked, then (none overflowing) solved
        for t in range(w.size):
            x = w[t]
            for i in range(n):
                for j in range(n):
                    Z[i, j] = complex(K[i, j] - x * x * M[i, j], x * C[i, j])
                    if not (math.isfinite(Z[i, j].real) and math.isfinite(Z[i, j].imag)):
                        overflow[t] = True
            if solve:
                X[t] = np.linalg.solve(Z, np.ascontiguousarray(F[t]))
        if overflow.any():
            break
    return X, overflow


# ---------------------------------------------------------------------------------------------------- band grid
@njit(**JIT)
def _step_limit(w: float, poles: np.ndarray, delay_step: float, grid_factor: float) -> float:
    """GRID_FACTOR × distance from iΩ to the nearest pole, at most ``delay_step`` (inf without either)."""
    best = math.inf
    for k in range(poles.size):
        d = (w - poles[k].imag) ** 2 + poles[k].real ** 2
        if d < best:
            best = d
    return min(grid_factor * math.sqrt(best), delay_step)


@njit(**JIT)
def _sorted_unique(a: np.ndarray) -> np.ndarray:
    a = np.sort(a)
    out = np.empty(a.size)
    m = 0
    for i in range(a.size):
        if m == 0 or a[i] != out[m - 1]:
            out[m] = a[i]
            m += 1
    return out[:m]


@njit(**JIT)
def band_grid(poles: np.ndarray, lo: float, hi: float, max_delay: float, extra: np.ndarray, count: int,
              grid_factor: float, pole_step: float, max_points: int) -> tuple[np.ndarray, float]:
    """Frequency grid (rad/s) over [lo, hi] with step ≤ ``grid_factor``·dist(iΩ, poles), and its worst step ratio.

    poles (k,) complex128; extra (e,) float64 points to include; ``count`` points of a uniform grid (the floor and
    the delay rule: step ≤ grid_factor·2π/(4·max_delay)); around each upper pole s = −σ + iω the points
    ω + σ sinh(u), u = u0 + i·pole_step.  Steps breaking the rule are bisected (at most 30 rounds, or until the grid
    exceeds ``max_points``).  The ratio is max over steps of grid_factor·step / min(limit at its two ends)
    (see :func:`railopt.models.response_maxima.band_grid`); NaN propagates as numpy's max does.
    """
    certified_ratio = grid_factor / (1.0 - grid_factor)
    delay_step = grid_factor * 2.0 * math.pi / (4.0 * max_delay) if max_delay > 0 else math.inf
    total = count + extra.size
    counts = np.zeros(poles.size, np.int64)
    for k in range(poles.size):
        if poles[k].imag >= 0 and poles[k].real != 0:
            sigma, omega = abs(poles[k].real), poles[k].imag
            u0, u1 = math.asinh((lo - omega) / sigma), math.asinh((hi - omega) / sigma)
            counts[k] = int(max(math.ceil((u1 + pole_step - u0) / pole_step), 0.0))
            total += counts[k]
    pts = np.empty(total)
    step = (hi - lo) / (count - 1) if count > 1 else 0.0
    for i in range(count):
        pts[i] = lo + i * step
    if count > 1:
        pts[count - 1] = hi
    p = count
    for k in range(poles.size):
        if counts[k]:
            sigma, omega = abs(poles[k].real), poles[k].imag
            u0 = math.asinh((lo - omega) / sigma)
            delta = (u0 + pole_step) - u0
            for i in range(counts[k]):
                pts[p] = omega + sigma * math.sinh(u0 + i * delta)
                p += 1
    for i in range(extra.size):
        pts[p + i] = extra[i]
    for i in range(total):
        pts[i] = min(max(pts[i], lo), hi)
    grid = _sorted_unique(pts)
    ratio = 0.0
    for _ in range(30):
        limit = np.empty(grid.size)
        for i in range(grid.size):
            limit[i] = _step_limit(grid[i], poles, delay_step, grid_factor)
        ratio = 0.0
        bad = np.zeros(grid.size, np.bool_)
        nbad = 0
        for i in range(grid.size - 1):
            r = grid_factor * (grid[i + 1] - grid[i]) / min(limit[i], limit[i + 1])
            if math.isnan(r) or math.isnan(ratio):
                ratio = math.nan
            elif r > ratio:
                ratio = r
            if r > certified_ratio:
                bad[i] = True
                nbad += 1
        if nbad == 0 or grid.size > max_points:
            break
        more = np.empty(grid.size + nbad)
        more[: grid.size] = grid
        q = grid.size
        for i in range(grid.size - 1):
            if bad[i]:
                more[q] = 0.5 * (grid[i] + grid[i + 1])
                q += 1
        grid = _sorted_unique(more)
    return grid, ratio


# ---------------------------------------------------------------------------------------------------- pole–residue
@njit(**JIT)
def _reciprocals(w: float, poles: np.ndarray, out: np.ndarray) -> None:
    """out[k] = 1 / (iΩ − s_k) = conj(d)/|d|² (d = iΩ − s_k), by Smith's division where |d|² would over- or
    underflow; inf at a pole."""
    for k in range(poles.size):
        dr, di = -poles[k].real, w - poles[k].imag
        d2 = dr * dr + di * di
        if 1e-290 < d2 < 1e290:
            r = 1.0 / d2
            out[k] = complex(dr * r, -di * r)
        elif dr == 0.0 and di == 0.0:
            out[k] = complex(math.inf, 0.0)
        elif abs(dr) >= abs(di):
            r = di / dr
            den = dr + di * r
            out[k] = complex(1.0 / den, -r / den)
        else:
            r = dr / di
            den = di + dr * r
            out[k] = complex(r / den, -1.0 / den)


@njit(**JIT)
def _pole_residue_sum(w: float, inv: np.ndarray, R: np.ndarray, o: int, delays: np.ndarray) -> complex:
    """S_o(Ω) = Σ_t e^{−iΩτ_t} Σ_j (iΩ)^j Σ_k R[k, o, t, j]·inv[k], inv[k] = 1/(iΩ − s_k): THE pole–residue formula."""
    iw = complex(0.0, w)
    h = 0j
    for t in range(R.shape[2]):
        term = 0j
        power = 1.0 + 0j
        for j in range(R.shape[3]):
            acc = 0j
            for k in range(inv.size):
                acc += R[k, o, t, j] * inv[k]
            term += power * acc
            power *= iw
        if delays[t] != 0.0:
            term *= complex(math.cos(w * delays[t]), -math.sin(w * delays[t]))
        h += term
    return h


@njit(**JIT)
def pole_residue_sums(w: np.ndarray, poles: np.ndarray, R: np.ndarray, outputs: np.ndarray,
                      delays: np.ndarray) -> np.ndarray:
    """S (N, m) complex: the pole–residue sum of each output in ``outputs`` (int64) at each Ω of ``w`` (N,).

    poles (k,) complex128; R (k, m_all, T, J) complex128 residues; delays (T,) s.  The output's (iΩ)^q and any
    feedthrough or callable term are applied by the caller (:meth:`railopt.models.pole_residue.PoleResidue.evaluate`).
    """
    S = np.empty((w.size, outputs.size), np.complex128)
    inv = np.empty(poles.size, np.complex128)
    for i in range(w.size):
        _reciprocals(w[i], poles, inv)
        for c in range(outputs.size):
            S[i, c] = _pole_residue_sum(w[i], inv, R, outputs[c], delays)
    return S


@njit(**JIT)
def pole_residue_magnitudes(w: np.ndarray, poles: np.ndarray, R: np.ndarray, o: int, delays: np.ndarray,
                            q: int) -> np.ndarray:
    """|H_o(Ω)| = |(iΩ)^q S_o(Ω)| at each Ω of ``w`` (N,), +inf where not finite (a pole hit)."""
    out = np.empty(w.size)
    inv = np.empty(poles.size, np.complex128)
    for i in range(w.size):
        _reciprocals(w[i], poles, inv)
        h = _pole_residue_sum(w[i], inv, R, o, delays)
        if q:
            h *= complex(0.0, w[i]) ** q
        a = abs(h)
        out[i] = a if math.isfinite(a) else math.inf
    return out


def magnitudes(w: np.ndarray, data) -> np.ndarray:
    """f(Ω) of the peak search at the points ``w`` (1-D float64): ``data(w)`` for a Python callable, or the
    pole–residue magnitude for ``data = (poles, R, o, delays, q)`` (what compiled drivers receive)."""
    if callable(data):
        return np.asarray(data(w), dtype=float)
    return pole_residue_magnitudes(w, *data)


@overload(magnitudes, jit_options={"error_model": "numpy", "nogil": True})
def _magnitudes_compiled(w, data):
    def impl(w, data):
        return pole_residue_magnitudes(w, data[0], data[1], data[2], data[3], data[4])

    return impl


# ---------------------------------------------------------------------------------------------------- Brent steps
@njit(**JIT)
def brent_start(lower: np.ndarray, upper: np.ndarray, rtol: float) -> np.ndarray:
    """State (B, 14) of Brent's bounded minimisation of −f on each bracket [lower_i, upper_i]; the caller sets
    column _FX (= −f at column _X) before the first :func:`brent_propose`."""
    S = np.zeros((lower.size, 14))
    for i in range(lower.size):
        a, b = lower[i], upper[i]
        S[i, _A], S[i, _B] = a, b
        S[i, _TOL] = max(rtol * (b - a), 4 * EPS * max(abs(a), abs(b))) / 3.0
        x = a + (1.0 - INV_PHI) * (b - a)
        S[i, _X] = S[i, _W] = S[i, _V] = x
    return S


@njit(**JIT)
def brent_set_start(S: np.ndarray, fx: np.ndarray) -> None:
    """Store the first values −f(x) (fx) as f at x, w and v."""
    for i in range(fx.size):
        S[i, _FX] = S[i, _FW] = S[i, _FV] = fx[i]


@njit(**JIT)
def brent_propose(S: np.ndarray) -> np.ndarray:
    """Mark converged brackets done; for the others compute the next point u (column _U).  Returns their rows."""
    g = 1.0 - INV_PHI
    live = np.empty(S.shape[0], np.int64)
    n = 0
    for i in range(S.shape[0]):
        if S[i, _DONE]:
            continue
        a, b, x, w, v = S[i, _A], S[i, _B], S[i, _X], S[i, _W], S[i, _V]
        fx, fw, fv, d, e, tol1 = S[i, _FX], S[i, _FW], S[i, _FV], S[i, _D], S[i, _E], S[i, _TOL]
        xm = 0.5 * (a + b)
        if not abs(x - xm) > 2.0 * tol1 - 0.5 * (b - a):
            S[i, _DONE] = 1.0
            continue
        r = (x - w) * (fx - fv)
        q = (x - v) * (fx - fw)
        p = (x - v) * q - (x - w) * r
        q = 2.0 * (q - r)
        if q > 0:
            p = -p
        q = abs(q)
        para = abs(e) > tol1 and abs(p) < abs(0.5 * q * e) and p > q * (a - x) and p < q * (b - x) and q != 0
        dp = p / q if para else 0.0
        up = x + dp
        if para and ((up - a) < 2 * tol1 or (b - up) < 2 * tol1):
            dp = tol1 if xm >= x else -tol1
        e_gold = (a - x) if x >= xm else (b - x)
        new_d = dp if para else g * e_gold
        S[i, _NE] = d if para else e_gold
        step = new_d if abs(new_d) >= tol1 else (tol1 if new_d >= 0 else -tol1)
        S[i, _D] = step
        S[i, _U] = x + step
        live[n] = i
        n += 1
    return live[:n]


@njit(**JIT)
def brent_points(S: np.ndarray, live: np.ndarray) -> np.ndarray:
    """The proposed points u of the rows ``live``."""
    return S[live, _U].copy()


@njit(**JIT)
def brent_accept(S: np.ndarray, live: np.ndarray, fu: np.ndarray) -> None:
    """Take the values −f(u) (fu) of the proposed points: the bracket and the three best points move."""
    for c in range(live.size):
        i = live[c]
        a, b, x, w, v, u = S[i, _A], S[i, _B], S[i, _X], S[i, _W], S[i, _V], S[i, _U]
        fx, fw, fv, f = S[i, _FX], S[i, _FW], S[i, _FV], fu[c]
        better = f <= fx
        right = u >= x
        if better:
            a, b = (x, b) if right else (a, x)
        else:
            a, b = (a, u) if right else (u, b)
        take_w = not better and (f <= fw or w == x)
        take_v = not better and not take_w and (f <= fv or v == x or v == w)
        if better or take_w:
            v, fv = w, fw
        elif take_v:
            v, fv = u, f
        if better:
            w, fw, x, fx = x, fx, u, f
        elif take_w:
            w, fw = u, f
        S[i, _A], S[i, _B], S[i, _X], S[i, _W], S[i, _V] = a, b, x, w, v
        S[i, _FX], S[i, _FW], S[i, _FV], S[i, _E] = fx, fw, fv, S[i, _NE]


@njit(**JIT)
def log_or_value(f: np.ndarray, use_log: bool) -> np.ndarray:
    """log f (−inf at 0) when ``use_log``, else f: Brent's scale-free target for a positive f."""
    if not use_log:
        return f
    out = np.empty(f.size)
    for i in range(f.size):
        out[i] = math.log(f[i]) if f[i] > 0 else (-math.inf if f[i] == 0 else math.nan)
    return out


@dual
def brent_run(lower: np.ndarray, upper: np.ndarray, rtol: float, use_log: bool, data) -> tuple[np.ndarray,
                                                                                               np.ndarray]:
    """Maximise f (log f when ``use_log``) over each bracket by Brent's method; f from :func:`magnitudes`.

    Returns (x, value of the target at x), one per bracket.  Same source in Python and compiled code.
    """
    S = brent_start(lower, upper, rtol)
    brent_set_start(S, -log_or_value(magnitudes(S[:, _X].copy(), data), use_log))
    for _ in range(MAX_ITERATIONS):
        live = brent_propose(S)
        if live.size == 0:
            break
        brent_accept(S, live, -log_or_value(magnitudes(brent_points(S, live), data), use_log))
    return S[:, _X].copy(), -S[:, _FX]


# ---------------------------------------------------------------------------------------------------- vertex steps
@njit(**JIT)
def vertex_start(x0: np.ndarray, lower: np.ndarray, upper: np.ndarray, rtol: float,
                 scale: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """State (B, 7) of the parabolic vertex steps and the live rows (non-empty brackets).  A start within a quarter
    of its bracket from an end starts mid-way; h = half the distance to the nearer end."""
    S = np.zeros((x0.size, 7))
    live = np.empty(x0.size, np.int64)
    n = 0
    for i in range(x0.size):
        lo, hi, x = lower[i], upper[i], x0[i]
        quarter = 0.25 * (hi - lo)
        if not (x - lo > quarter and hi - x > quarter):
            x = 0.5 * (lo + hi)
        S[i, _VX], S[i, _VLO], S[i, _VHI], S[i, _VREF] = x, lo, hi, scale[i]
        S[i, _VTOL] = max(rtol * (hi - lo), 4 * EPS * max(abs(lo), abs(hi))) / 3.0
        if hi > lo:
            S[i, _VH] = 0.5 * min(x - lo, hi - x)
            live[n] = i
            n += 1
    return S, live[:n]


@njit(**JIT)
def vertex_points(S: np.ndarray, live: np.ndarray) -> np.ndarray:
    """The 3k points [x − h (clipped) for all live, x for all, x + h (clipped) for all]."""
    k = live.size
    pts = np.empty(3 * k)
    for c in range(k):
        i = live[c]
        x, h = S[i, _VX], S[i, _VH]
        pts[c], pts[k + c], pts[2 * k + c] = max(x - h, S[i, _VLO]), x, min(x + h, S[i, _VHI])
    return pts


@njit(**JIT)
def vertex_update(S: np.ndarray, live: np.ndarray, f: np.ndarray, positive: bool) -> np.ndarray:
    """One Newton step on the parabola through the 3 samples of φ = (ref/f)² (``positive``) or −f; returns the rows
    still live.  A step that leaves the bracket or a non-convex parabola ends a row with ok = 0 (Brent then)."""
    k = live.size
    keep = np.empty(k, np.int64)
    n = 0
    for c in range(k):
        i = live[c]
        x, lo, hi, tol, h, ref = S[i, _VX], S[i, _VLO], S[i, _VHI], S[i, _VTOL], S[i, _VH], S[i, _VREF]
        left, right = max(x - h, lo), min(x + h, hi)
        if positive:
            pl, pm, pr = (ref / f[c]) ** 2, (ref / f[k + c]) ** 2, (ref / f[2 * k + c]) ** 2
        else:
            pl, pm, pr = -f[c], -f[k + c], -f[2 * k + c]
        dl, dr = x - left, right - x
        num = dl * dl * (pm - pr) - dr * dr * (pm - pl)
        den = dl * (pr - pm) + dr * (pl - pm)  # > 0: the parabola through the three points is convex
        step = 0.5 * num / den
        good = (math.isfinite(pl) and math.isfinite(pm) and math.isfinite(pr) and den > 0 and dl > 0 and dr > 0
                and step > lo - x and step < hi - x)
        if not good:
            continue
        S[i, _VX] = x + step
        # done: a step below tol from a parabola fitted over ≤ 100·tol (its vertex is then exact to far below tol)
        if abs(step) <= tol and h <= 100.0 * tol:
            S[i, _VOK] = 1.0
            continue
        S[i, _VH] = max(0.1 * abs(step), 10.0 * tol)
        keep[n] = i
        n += 1
    return keep[:n]


@dual
def vertex_run(x0: np.ndarray, lower: np.ndarray, upper: np.ndarray, rtol: float, positive: bool,
               scale: np.ndarray, data) -> tuple[np.ndarray, np.ndarray]:
    """Vertex steps from ``x0`` in each bracket, f from :func:`magnitudes`: (x, ok) (ok False: refine by Brent)."""
    S, live = vertex_start(x0, lower, upper, rtol, scale)
    for _ in range(VERTEX_ITERATIONS):
        if live.size == 0:
            break
        live = vertex_update(S, live, magnitudes(vertex_points(S, live), data), positive)
    return S[:, _VX].copy(), S[:, _VOK] != 0


# ---------------------------------------------------------------------------------------------------- cell maxima
@njit(**JIT)
def cell_candidates(grid: np.ndarray, values: np.ndarray, bounds: np.ndarray):
    """Best sample of each cell [bounds[j], bounds[j+1]] and the candidates to refine.

    Returns (x, f, empty, cells, cx, cf, lo, hi): x, f (ncell,) the first best sample of each cell (NaN counts as
    −inf); ``empty`` the first cell without a sample (−1 if none); per candidate (a sampled local maximum within
    CANDIDATE_MARGIN of its cell's best sample, finite, or the best sample itself) its cell, abscissa, value and
    bracket (its grid neighbours clipped to the cell).
    """
    ncell = bounds.size - 1
    N = grid.size
    x, f = np.empty(ncell), np.empty(ncell)
    cap = 0
    start = np.searchsorted(grid, bounds[:-1], side="left")
    stop = np.searchsorted(grid, bounds[1:], side="right")
    for j in range(ncell):
        if stop[j] <= start[j]:
            return x, f, j, np.empty(0, np.int64), np.empty(0), np.empty(0), np.empty(0), np.empty(0)
        cap += stop[j] - start[j]
    cells, gi = np.empty(cap, np.int64), np.empty(cap, np.int64)
    n = 0
    for j in range(ncell):
        top, at = -math.inf, start[j]
        for i in range(start[j], stop[j]):
            v = -math.inf if math.isnan(values[i]) else values[i]
            if v > top:
                top, at = v, i
        x[j], f[j] = grid[at], values[at]
        if not math.isfinite(top):
            continue
        for i in range(start[j], stop[j]):
            v = -math.inf if math.isnan(values[i]) else values[i]
            left = -math.inf if i == start[j] or math.isnan(values[i - 1]) else values[i - 1]
            right = -math.inf if i == stop[j] - 1 or math.isnan(values[i + 1]) else values[i + 1]
            near = v >= top - CANDIDATE_MARGIN * abs(top)
            if (i == at or (near and v > left and v >= right)) and math.isfinite(v):
                cells[n], gi[n] = j, i
                n += 1
    cells, gi = cells[:n], gi[:n]
    lo, hi = np.empty(n), np.empty(n)
    for c in range(n):
        i = gi[c]
        lo[c] = max(grid[max(i - 1, 0)], bounds[cells[c]])
        hi[c] = min(grid[min(i + 1, N - 1)], bounds[cells[c] + 1])
    return x, f, -1, cells, grid[gi], values[gi], lo, hi


@njit(**JIT)
def edge_probes(cells: np.ndarray, cx: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                bounds: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Which candidates to refine (a non-empty bracket), and for those on a cell boundary a probe 1e-6 of the
    bracket inside the cell: (refine, edge rows, probe points).  A boundary candidate is the maximum there when f
    falls into the cell from it (:func:`drop_falling_edges`)."""
    k = cx.size
    refine = hi > lo
    edge = np.empty(k, np.int64)
    probe = np.empty(k)
    n = 0
    for c in range(k):
        if not refine[c]:
            continue
        at_lo, at_hi = cx[c] <= bounds[cells[c]], cx[c] >= bounds[cells[c] + 1]
        if at_lo or at_hi:
            h = 1e-6 * (hi[c] - lo[c])
            edge[n], probe[n] = c, (cx[c] + h if at_lo else cx[c] - h)
            n += 1
    return refine, edge[:n], probe[:n]


@njit(**JIT)
def drop_falling_edges(refine: np.ndarray, edge: np.ndarray, probed: np.ndarray, cf: np.ndarray) -> None:
    """No refinement for a boundary candidate whose probe inside the cell is not above it."""
    for c in range(edge.size):
        if probed[c] <= cf[edge[c]]:
            refine[edge[c]] = False


@njit(**JIT)
def all_positive(values: np.ndarray) -> bool:
    """Every finite value > 0 (then φ = (s/f)² and log f are usable)."""
    for v in values:
        if math.isfinite(v) and not v > 0:
            return False
    return True


@njit(**JIT)
def take_better(cx: np.ndarray, cf: np.ndarray, idx: np.ndarray, xr: np.ndarray, fr: np.ndarray) -> None:
    """Candidate idx[c] moves to its refined point where that is higher."""
    for c in range(idx.size):
        if fr[c] > cf[idx[c]]:
            cx[idx[c]], cf[idx[c]] = xr[c], fr[c]


@njit(**JIT)
def cell_select(x: np.ndarray, f: np.ndarray, cells: np.ndarray, cx: np.ndarray, cf: np.ndarray) -> None:
    """Each cell's best candidate (largest, first on ties; candidates are in cell order) replaces its best sample
    when higher."""
    c = 0
    while c < cells.size:
        j, best = cells[c], c
        while c < cells.size and cells[c] == j:
            if cf[c] > cf[best]:
                best = c
            c += 1
        if cf[best] > f[j]:
            x[j], f[j] = cx[best], cf[best]


@dual
def refine_cells(grid: np.ndarray, values: np.ndarray, bounds: np.ndarray, rtol: float, data):
    """Maximum of f over each cell (the algorithm of :func:`railopt.models.peak_search.cell_maxima`), f from
    :func:`magnitudes`: returns (x, f, empty) with ``empty`` the first cell without a sample (−1 when none)."""
    x, f, empty, cells, cx, cf, lo, hi = cell_candidates(grid, values, bounds)
    if empty >= 0 or cells.size == 0:
        return x, f, empty
    refine, edge, probe = edge_probes(cells, cx, lo, hi, bounds)
    if edge.size:
        drop_falling_edges(refine, edge, magnitudes(probe, data), cf)
    idx = np.flatnonzero(refine)
    if idx.size:
        # −(s/f)² (s: the candidate's sample) has the same maximiser as f > 0 and is exactly a parabola near a
        # resonance of one pole (|H|² ∝ 1/((Ω−ω)² + σ²)), so the vertex steps converge in a few iterations
        positive = all_positive(values)
        ref = cf[idx] if positive else np.ones(idx.size)
        xr, ok = vertex_run(cx[idx], lo[idx], hi[idx], rtol, positive, ref, data)
        bad = np.flatnonzero(~ok)
        if bad.size:  # the safeguard: Brent where the local parabola did not settle (log f: scale-free)
            xb, _ = brent_run(lo[idx[bad]], hi[idx[bad]], rtol, positive, data)
            xr[bad] = xb
        take_better(cx, cf, idx, xr, magnitudes(xr, data))
    cell_select(x, f, cells, cx, cf)
    return x, f, empty


@njit(**JIT)
def cell_maxima_pole_residue(grid: np.ndarray, values: np.ndarray, bounds: np.ndarray, rtol: float,
                             poles: np.ndarray, R: np.ndarray, o: int, delays: np.ndarray, q: int):
    """:func:`refine_cells` compiled with the pole–residue |H_o| of :func:`pole_residue_magnitudes` inline."""
    return refine_cells(grid, values, bounds, rtol, (poles, R, o, delays, q))


__all__ = [
    "BRACKET_RTOL", "CANDIDATE_MARGIN", "INV_PHI", "MAX_ITERATIONS", "VERTEX_ITERATIONS", "all_positive", "c_array",
    "band_grid", "brent_accept", "brent_points", "brent_propose", "brent_run", "brent_set_start", "brent_start",
    "cell_candidates", "cell_maxima_pole_residue", "cell_select", "direct_solutions", "drop_falling_edges", "dual",
    "edge_probes", "left_vectors", "log_or_value", "magnitudes", "member_state", "pole_residue_magnitudes",
    "pole_residue_sums", "refine_cells", "residues", "take_better",
    "vertex_points", "vertex_run", "vertex_start", "vertex_update",
]
