"""Compiled kernels (numba) of the certified band maximum: the one implementation of its hot formulas.

What lives here, each written once:

- :func:`eigen_pairs` (``np.linalg.eig`` of a real matrix, LAPACK dgeev from scipy's build, without numpy's
  per-call cost; :func:`state_eigen_pairs` of the state matrix, :func:`stacked_eigen_pairs` of a stack) and
  :func:`state_matrix` (G of thesis eq. 4.53);
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
from numba import njit, types
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


# numba's own binding of LAPACK dgeev (scipy's cython_lapack: scipy's OpenBLAS build, not numpy's), found by its
# symbol name so that the kernels that call it stay cacheable (a ctypes pointer would not be)
_RGEEV = types.ExternalFunction("numba_ez_rgeev", types.intc(
    types.char, types.char, types.char, types.intp, types.CPointer(types.float64), types.intp,
    types.CPointer(types.float64), types.CPointer(types.float64), types.CPointer(types.float64), types.intp,
    types.CPointer(types.float64), types.intp))


@njit(**JIT)
def eigen_pairs(G: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Roots s (N,) and right eigenvectors V (N, N, columns) of a real square G (N, N), both complex128, as
    ``np.linalg.eig(G)`` gives them: LAPACK dgeev with jobvl = 'N', jobvr = 'V' and numpy's pairing of its real
    output (a pair wr ± i·wi takes columns v_re ± i·v_im), without numpy's per-call cost.  The dgeev is scipy's
    OpenBLAS build (numba's binding): the result equals ``scipy.linalg.eig(G)``'s bit for bit and numpy's to
    rounding (bit for bit on the tests' matrices with one BLAS thread, as railopt's tasks run).

    That build's dgeev does not undo its own scaling of a matrix whose largest entry lies outside about
    [6.7e-139, 1.5e138] (its roots come back off by the scale factor), so such a G is first scaled here by a power
    of two, exactly, to a largest entry in [0.5, 1), and the roots scaled back (the vectors do not change).

    Raises numpy's ``LinAlgError`` when G is not square, holds inf or NaN, or LAPACK fails (no convergence of the
    QR iteration, or a refused argument)."""
    N = G.shape[0]
    if G.shape[1] != N:
        raise np.linalg.LinAlgError("Last 2 dimensions of the array must be square")
    largest = 0.0
    for i in range(N):
        for j in range(N):
            if not math.isfinite(G[i, j]):
                raise np.linalg.LinAlgError("Array must not contain infs or NaNs")
            largest = max(largest, abs(G[i, j]))
    scale = 1.0
    if largest > 2.0**400 or 0.0 < largest < 2.0**-400:
        scale = math.ldexp(1.0, -math.frexp(largest)[1])
    a = np.empty((N, N))  # C order holding Gᵀ: LAPACK reads it as G in Fortran order
    for i in range(N):
        for j in range(N):
            a[j, i] = G[i, j] * scale
    wr, wi, vl, vr = np.empty(N), np.empty(N), np.empty((1, 1)), np.empty((N, N))  # vr holds Vᵀ (Fortran)
    s = np.empty(N, np.complex128)
    V = np.empty((N, N), np.complex128)
    if N == 0:
        return s, V
    info = _RGEEV(ord("d"), ord("N"), ord("V"), N, a.ctypes, N, wr.ctypes, wi.ctypes, vl.ctypes, 1, vr.ctypes, N)
    if info > 0:
        raise np.linalg.LinAlgError("Eigenvalues did not converge")
    if info < 0:
        raise np.linalg.LinAlgError("LAPACK dgeev refused an argument or could not allocate its workspace")
    if scale != 1.0:
        for k in range(N):
            wr[k] /= scale
            wi[k] /= scale
    k = 0
    while k < N:
        if wi[k] == 0.0:
            s[k] = wr[k]
            for i in range(N):
                V[i, k] = vr[k, i]
            k += 1
        else:
            s[k] = complex(wr[k], wi[k])
            s[k + 1] = complex(wr[k + 1], wi[k + 1])
            for i in range(N):
                V[i, k] = complex(vr[k, i], vr[k + 1, i])
                V[i, k + 1] = complex(vr[k, i], -vr[k + 1, i])
            k += 2
    return s, V


@njit(**JIT)
def state_eigen_pairs(minv_kc: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`eigen_pairs` of the state matrix G = [[0, I], [−M⁻¹K, −M⁻¹C]] (thesis eq. 4.53) built from
    ``minv_kc`` = M⁻¹[K C] (n, 2n) (:func:`member_state`): s (2n,), V (2n, 2n) complex128."""
    return eigen_pairs(state_matrix(minv_kc))


@njit(**JIT)
def state_matrix(minv_kc: np.ndarray) -> np.ndarray:
    """G = [[0, I], [−M⁻¹K, −M⁻¹C]] (2n, 2n) of thesis eq. (4.53) from ``minv_kc`` = M⁻¹[K C] (n, 2n)."""
    n = minv_kc.shape[0]
    G = np.zeros((2 * n, 2 * n))
    for i in range(n):
        G[i, n + i] = 1.0
        for j in range(2 * n):
            G[n + i, j] = -minv_kc[i, j]
    return G


@njit(**JIT)
def stacked_eigen_pairs(G: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`eigen_pairs` of every matrix of a stack G (B, N, N): s (B, N), V (B, N, N) complex128 (raises as
    :func:`eigen_pairs` does)."""
    B, N = G.shape[0], G.shape[1]
    s = np.empty((B, N), np.complex128)
    V = np.empty((B, N, N), np.complex128)
    for b in range(B):
        s[b], V[b] = eigen_pairs(np.ascontiguousarray(G[b]))
    return s, V


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
def impedance(M: np.ndarray, C: np.ndarray, K: np.ndarray, w: float, Z: np.ndarray) -> bool:
    """Z (n, n) ← K − Ω²M + iΩC at Ω = ``w`` (thesis eq. 4.69); False when an entry is not finite."""
    finite = True
    for i in range(M.shape[0]):
        for j in range(M.shape[0]):
            Z[i, j] = complex(K[i, j] - w * w * M[i, j], w * C[i, j])
            if not (math.isfinite(Z[i, j].real) and math.isfinite(Z[i, j].imag)):
                finite = False
    return finite


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
    for t in range(w.size):  # first every Z is checked, then (none overflowing) solved
        overflow[t] = not impedance(M, C, K, w[t], Z)
    if overflow.any():
        return X, overflow
    for t in range(w.size):
        impedance(M, C, K, w[t], Z)
        X[t] = np.linalg.solve(Z, np.ascontiguousarray(F[t]))
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
            # sinh(u0 + iδ) = (eᵘ − e⁻ᵘ)/2 with eᵘ stepped by e^δ (a few ulps of drift over the ≤ ~100 points, where
            # a sinh call per point costs several times more); the step rule is checked on the points made
            up, down = math.exp(u0), math.exp(-u0)
            grow, shrink = math.exp(delta), math.exp(-delta)
            for i in range(counts[k]):
                v = 0.5 * (up - down)
                pts[p] = omega + sigma * (v if math.isfinite(v) else math.sinh(u0 + i * delta))
                up *= grow
                down *= shrink
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
def magnitude(h: complex) -> float:
    """|h|, +inf where not finite: √(re² + im²) where the squares neither overflow nor underflow (within two ulps
    of ``abs``, several times faster than its hypot), else ``abs``."""
    a2 = h.real * h.real + h.imag * h.imag
    if 1e-290 < a2 < 1e290:
        return math.sqrt(a2)
    a = abs(h)
    return a if math.isfinite(a) else math.inf


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
        out[i] = magnitude(h)
    return out


def magnitudes(w: np.ndarray, data) -> np.ndarray:
    """f(Ω) of the peak search at the points ``w`` (1-D float64): ``data(w)`` for a Python callable, the
    pole–residue magnitude for ``data = (poles, R, o, delays, q)``, or the direct-solve magnitude of
    :func:`direct_magnitudes` for ``data = (M, C, K, A, delays, row, order)`` (what compiled drivers receive)."""
    if callable(data):
        return np.asarray(data(w), dtype=float)
    if len(data) == 7:
        return direct_magnitudes(w, *data)
    return pole_residue_magnitudes(w, *data)


@overload(magnitudes, jit_options={"error_model": "numpy", "nogil": True})
def _magnitudes_compiled(w, data):
    if len(data) == 7:
        def direct(w, data):
            return direct_magnitudes(w, data[0], data[1], data[2], data[3], data[4], data[5], data[6])

        return direct

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



# ---------------------------------------------------------------------------------------------------- direct outputs
@njit(**JIT)
def forcing_values(w: float, A: np.ndarray, delays: np.ndarray, out: np.ndarray) -> bool:
    """out (n,) = F(Ω) = Σ_t e^{−iΩτ_t} Σ_j (iΩ)^j A[t, j] (thesis eqs. 4.63–4.66); False when not finite."""
    iw = complex(0.0, w)
    out[:] = 0j
    for t in range(A.shape[0]):
        phase = complex(math.cos(w * delays[t]), -math.sin(w * delays[t])) if delays[t] != 0.0 else 1.0 + 0j
        power = phase
        for j in range(A.shape[1]):
            for i in range(A.shape[2]):
                out[i] += power * A[t, j, i]
            power *= iw
    for i in range(out.size):
        if not (math.isfinite(out[i].real) and math.isfinite(out[i].imag)):
            return False
    return True


@njit(**JIT)
def direct_outputs(M: np.ndarray, C: np.ndarray, K: np.ndarray, w: np.ndarray, A: np.ndarray, delays: np.ndarray,
                   rows: np.ndarray, orders: np.ndarray) -> tuple[np.ndarray, int]:
    """H (N, m) = (iΩ)^q_o c_o·Z(Ω)⁻¹F(Ω) (thesis eqs. 4.69–4.70) at each Ω of ``w`` (N,) for the polynomial
    delayed forcing A (T, J, n), delays (T,), output rows (m, n) and orders (m,) int64; +inf where not finite.
    Status 0, or 1 when F or Z(Ω) is not finite somewhere (nothing solved: the caller names it); numpy's
    ``LinAlgError`` when a Z(Ω) is exactly singular.  THE direct-solve formula of the certified path."""
    n, m = M.shape[0], rows.shape[0]
    H = np.full((w.size, m), complex(math.inf, 0.0))
    F = np.empty((w.size, n), np.complex128)
    for t in range(w.size):
        if not forcing_values(w[t], A, delays, F[t]):
            return H, 1
    X, overflow = direct_solutions(M, C, K, w, F)
    if overflow.any():
        return H, 1
    for t in range(w.size):
        for o in range(m):
            h = 0j
            for i in range(n):
                h += rows[o, i] * X[t, i]
            for _ in range(orders[o]):
                h *= complex(0.0, w[t])
            if math.isfinite(h.real) and math.isfinite(h.imag):
                H[t, o] = h
    return H, 0


@njit(**JIT)
def direct_magnitudes(w: np.ndarray, M: np.ndarray, C: np.ndarray, K: np.ndarray, A: np.ndarray,
                      delays: np.ndarray, rows: np.ndarray, orders: np.ndarray) -> np.ndarray:
    """|H| (N,) of the one output ``rows`` (1, n) by :func:`direct_outputs` (+inf where Z or F is not finite)."""
    H, status = direct_outputs(M, C, K, w, A, delays, rows, orders)
    out = np.empty(w.size)
    for i in range(w.size):
        a = abs(H[i, 0])
        out[i] = a if status == 0 and math.isfinite(a) else math.inf
    return out


# ---------------------------------------------------------------------------------------------------- certified path
CERT_OK, CERT_UNSTABLE, CERT_ZERO_ZONE, CERT_ILL_CONDITIONED, CERT_INCONSISTENT, CERT_NOT_FINITE = range(6)
CERTIFIED_MAXIMA_STATUS = ("ok", "unstable", "zero zone", "ill-conditioned eigenvectors",
                           "pole–residue inconsistent with direct solves", "forcing or impedance not finite")


@njit(**JIT)
def mode_order(s: np.ndarray) -> np.ndarray:
    """Order of the roots by |Im s|, then Re s (ascending; stable): :func:`railopt.models.modal.mode_order`."""
    N = s.size
    idx = np.arange(N)
    for i in range(1, N):  # insertion sort: 2n is small and the order must be stable as numpy's lexsort
        k = idx[i]
        j = i - 1
        while j >= 0 and (abs(s[idx[j]].imag) > abs(s[k].imag)
                          or (abs(s[idx[j]].imag) == abs(s[k].imag) and s[idx[j]].real > s[k].real)):
            idx[j + 1] = idx[j]
            j -= 1
        idx[j + 1] = k
    return idx


@njit(**JIT)
def certified_maxima(M: np.ndarray, C: np.ndarray, K: np.ndarray, s: np.ndarray, V: np.ndarray, A: np.ndarray,
                     delays: np.ndarray, rows: np.ndarray, orders: np.ndarray, lo: float, hi: float,
                     max_delay: float, count: int, settings: np.ndarray):
    """The certified band maximum of every output in one call (:mod:`railopt.models.response_maxima`).

    M, C, K (n, n) float64; s (2n,), V (2n, 2n) complex128 from ``np.linalg.eig(G)``; A (T, J, n) complex128
    forcing coefficients with delays (T,) s; rows (m, n) output rows, orders (m,) int64; band [lo, hi] rad/s;
    ``count`` points of the uniform floor/delay grid; settings = (UNDAMPED_ROOT, NEUTRAL_ROOT, ZERO_STEP,
    CONDITION_LIMIT, CONSISTENCY_RTOL, POLISH_RTOL, BRACKET_RTOL, GRID_FACTOR, POLE_STEP, MAX_GRID_POINTS,
    RESOLVED_DAMPING).

    The chain: mode order and the checks on the roots (growth → status 1; free rigid-body roots with the band
    below their zone's step → 2), W = V⁻¹ and cond₁(V) (beyond the limit → 3), residues, band grid, pole–residue
    |H| on it, the cell maxima refined on it, the n + 2 confirmation solves (values), the consistency of the two
    (beyond CONSISTENCY_RTOL → 4), and a noisy maximiser located again on direct solves; F or Z not finite → 5.
    A status ≠ 0 means the caller takes the general path.

    Returns (status, values (m, n+2), freqs (m, n+2), ratio, grid points, all samples finite, resonant (n,) bool,
    soft root index into s (−1: none), unresolved pole index into s (−1: none), its eigenvalue condition, W, cond,
    the damped frequencies ω_d (n,) in mode order).
    An undamped mode inside the band (resonant) has value inf at its clipped ω_d.
    """
    undamped_root, neutral_root, zero_step, condition_limit = settings[0], settings[1], settings[2], settings[3]
    consistency_rtol, polish_rtol, rtol, grid_factor = settings[4], settings[5], settings[6], settings[7]
    pole_step, max_points, resolved = settings[8], int(settings[9]), settings[10]
    n, m, N = M.shape[0], rows.shape[0], s.size
    values = np.full((m, n + 2), math.inf)
    freqs = np.zeros((m, n + 2))
    resonant = np.zeros(n, np.bool_)
    W = np.zeros((0, 0), np.complex128)
    order = mode_order(s)
    scale = 0.0
    for k in range(N):
        scale = max(scale, abs(s[k]))
    wd = np.empty(n)
    clipped = np.empty(n)
    for j in range(n):
        mode = s[order[2 * j + 1]]
        wd[j] = abs(mode.imag)
        clipped[j] = min(max(wd[j], lo), hi)
        freqs[:, j] = clipped[j]
        neutral = abs(mode) <= neutral_root * scale
        resonant[j] = (abs(mode.real) <= undamped_root * abs(mode) and mode.imag != 0 and not neutral
                       and wd[j] >= lo and wd[j] <= hi)
    freqs[:, n], freqs[:, n + 1] = lo, hi
    nneutral, least = 0, math.inf
    for k in range(N):
        if s[k].real > undamped_root * abs(s[k]) and abs(s[k]) > neutral_root * scale:
            return (CERT_UNSTABLE, values, freqs, math.nan, 0, False, resonant, -1, -1, math.nan, W, math.inf, wd)
        if abs(s[k]) <= neutral_root * scale:
            nneutral += 1
        else:
            least = min(least, abs(s[k]))
    if scale > 0 and 0 < nneutral < N and lo < min(zero_step * least, 1e-3 * hi):
        return (CERT_ZERO_ZONE, values, freqs, math.nan, 0, False, resonant, -1, -1, math.nan, W, math.inf, wd)
    W, cond = left_vectors(V)
    if cond > condition_limit:
        return (CERT_ILL_CONDITIONED, values, freqs, math.nan, 0, False, resonant, -1, -1, math.nan, W, cond, wd)
    # the grid's poles: not undamped (their cells are inf anyway)
    keep = np.zeros(N, np.bool_)
    for k in range(N):
        keep[k] = abs(s[k].real) > undamped_root * abs(s[k])
    poles = np.ascontiguousarray(s[keep])
    bounds = np.empty(n + 1)
    bounds[0], bounds[n] = lo, hi
    for j in range(1, n):
        bounds[j] = max(0.5 * (clipped[j] + clipped[j - 1]), lo)
    extra = np.concatenate((clipped, bounds))
    grid, ratio = band_grid(poles, lo, hi, max_delay, extra, count, grid_factor, pole_step, max_points)
    R, _ = residues(M, V, W, rows, A)
    cx = np.empty((m, n))
    cf = np.empty((m, n))
    all_finite = True
    for o in range(m):
        mags = pole_residue_magnitudes(grid, s, R, o, delays, orders[o])
        for i in range(mags.size):
            if not math.isfinite(mags[i]):
                all_finite = False
        x, f, _ = refine_cells(grid, mags, bounds, rtol, (s, R, o, delays, orders[o]))
        cx[o], cf[o] = x, f
    # confirmation: the n refined maxima of each output and the two edges, by direct solves
    pts = np.empty(m * n + 2)
    for o in range(m):
        pts[o * n:(o + 1) * n] = cx[o]
    pts[m * n], pts[m * n + 1] = lo, hi
    H, status = direct_outputs(M, C, K, pts, A, delays, rows, orders)
    if status:
        return (CERT_NOT_FINITE, values, freqs, ratio, grid.size, all_finite, resonant, -1, -1, math.nan, W, cond,
                wd)
    top = 0.0
    for o in range(m):
        for j in range(n):
            values[o, j] = abs(H[o * n + j, o])
            if not math.isfinite(values[o, j]):
                values[o, j] = math.inf
            elif math.isfinite(cf[o, j]):
                top = max(top, values[o, j])
        for e in range(2):
            a = abs(H[m * n + e, o])
            values[o, n + e] = a if math.isfinite(a) else math.inf
    for o in range(m):
        for j in range(n):
            f, d = cf[o, j], values[o, j]
            if math.isfinite(f) and math.isfinite(d) and abs(f - d) > consistency_rtol * max(top, 1e-300):
                return (CERT_INCONSISTENT, values, freqs, ratio, grid.size, all_finite, resonant, -1, -1, math.nan,
                        W, cond, wd)
    for o in range(m):  # a maximiser found on the noisy sum (noise ≳ POLISH_RTOL) is located again on direct solves
        row = np.ascontiguousarray(rows[o:o + 1])
        order_o = orders[o:o + 1].copy()
        for j in range(n):
            f, d, x = cf[o, j], values[o, j], cx[o, j]
            if math.isfinite(f) and math.isfinite(d) and abs(f - d) > polish_rtol * abs(d):
                a = max(grid[max(np.searchsorted(grid, x, side="left") - 1, 0)], bounds[j])
                b = min(grid[min(np.searchsorted(grid, x, side="right"), grid.size - 1)], bounds[j + 1])
                if a < x < b:
                    trio = np.array([a, x, b])
                    data = (M, C, K, A, delays, row, order_o)
                    xr, fr, _ = refine_cells(trio, direct_magnitudes(trio, *data), np.array([a, b]), rtol, data)
                    if fr[0] > d:
                        cx[o, j], values[o, j] = xr[0], fr[0]
    for o in range(m):
        for j in range(n):
            if resonant[j]:
                values[o, j], freqs[o, j] = math.inf, clipped[j]
            else:
                freqs[o, j] = cx[o, j]
    soft, unresolved, kappa_u = weak_roots(s, V, W, lo, hi, neutral_root, undamped_root, resolved)
    return (CERT_OK, values, freqs, ratio, grid.size, all_finite, resonant, soft, unresolved, kappa_u, W, cond, wd)


@njit(**JIT)
def weak_roots(s: np.ndarray, V: np.ndarray, W: np.ndarray, lo: float, hi: float, neutral_root: float,
               undamped_root: float, resolved: float) -> tuple[int, int, float]:
    """The roots the band search cannot trust (:mod:`railopt.models.response_maxima`'s certificate): the first root
    below ``neutral_root``·max|s| (taken as free rigid-body motion) that is complex and damped beyond
    ``resolved``·ε·max|s| (a mode too soft for the search), and the first pole with ω inside [lo, hi], neither
    neutral nor undamped, whose damping is within ``resolved``·ε·κ_k·max|s| of zero, κ_k = ‖v_k‖‖w_k‖ its eigenvalue
    condition (the grid around it may not resolve the peak).  s (N,), V (N, N) right eigenvectors, W = V⁻¹ (rows
    left).  Returns (soft index, unresolved index, its κ); −1 and NaN where there is none."""
    N = s.size
    scale = 0.0
    for k in range(N):
        scale = max(scale, abs(s[k]))
    soft, unresolved, kappa_u = -1, -1, math.nan
    for k in range(N):
        if (soft < 0 and abs(s[k]) <= neutral_root * scale and s[k].imag != 0
                and -s[k].real > resolved * EPS * scale):
            soft = k
        inside = (abs(s[k].imag) >= lo and abs(s[k].imag) <= hi and abs(s[k]) > neutral_root * scale
                  and abs(s[k].real) > undamped_root * abs(s[k]))
        if inside and unresolved < 0:
            nv, nw = 0.0, 0.0
            for i in range(N):
                nv += abs(V[i, k]) ** 2
                nw += abs(W[k, i]) ** 2
            kappa = math.sqrt(nv) * math.sqrt(nw)
            if not abs(s[k].real) > resolved * EPS * kappa * scale:
                unresolved, kappa_u = k, kappa
    return soft, unresolved, kappa_u


@njit(**JIT)
def state_matrices(M: np.ndarray, C: np.ndarray, K: np.ndarray,
                   singular_pivot: float) -> tuple[np.ndarray, np.ndarray]:
    """G (B, 2n, 2n) = [[0, I], [−M⁻¹K, −M⁻¹C]] (thesis eq. 4.53) of B stacked members (M, C, K (B, n, n)) by
    :func:`member_state`, and which have a regular M (B,) bool (G is zero otherwise)."""
    B, n = M.shape[0], M.shape[1]
    G = np.zeros((B, 2 * n, 2 * n))
    regular = np.zeros(B, np.bool_)
    for b in range(B):
        kc, ok = member_state(M[b], K[b], C[b], singular_pivot)
        regular[b] = ok
        if ok:
            G[b] = state_matrix(kc)
    return G, regular


@njit(**JIT)
def certified_maxima_batch(M: np.ndarray, C: np.ndarray, K: np.ndarray, s: np.ndarray, V: np.ndarray,
                           A: np.ndarray, delays: np.ndarray, rows: np.ndarray, orders: np.ndarray, lo: float,
                           hi: float, max_delay: float, count: int, settings: np.ndarray, regular: np.ndarray):
    """:func:`certified_maxima` of B stacked designs in one call: M, C, K (B, n, n), s (B, 2n), V (B, 2n, 2n),
    A (B, T, J, n); the rest shared.  ``regular`` (B,) False skips a design (status −1).  A design whose V or a
    Z(Ω) is exactly singular gets status −2 (the caller redoes it on the general path).

    Returns (status (B,) int64, values (B, m, n+2), freqs (B, m, n+2), ratio (B,), grid points (B,), all samples
    finite (B,), soft (B,), unresolved (B,)): the same items as :func:`certified_maxima`, per design.
    """
    B, n, m = M.shape[0], M.shape[1], rows.shape[0]
    status = np.full(B, -1, np.int64)
    values = np.full((B, m, n + 2), math.inf)
    freqs = np.zeros((B, m, n + 2))
    ratio = np.full(B, math.nan)
    points = np.zeros(B, np.int64)
    finite = np.zeros(B, np.bool_)
    soft = np.full(B, -1, np.int64)
    unresolved = np.full(B, -1, np.int64)
    for b in range(B):
        if not regular[b]:
            continue
        try:
            out = certified_maxima(M[b], C[b], K[b], s[b], V[b], A[b], delays, rows, orders, lo, hi, max_delay,
                                   count, settings)
        except Exception:  # noqa: BLE001 — numba raises LinAlgError for an exactly singular V or Z(Ω)
            status[b] = -2
            continue
        status[b] = out[0]
        values[b], freqs[b], ratio[b], points[b], finite[b] = out[1], out[2], out[3], out[4], out[5]
        soft[b], unresolved[b] = out[7], out[8]
    return status, values, freqs, ratio, points, finite, soft, unresolved


__all__ = [
    "BRACKET_RTOL", "CANDIDATE_MARGIN", "INV_PHI", "MAX_ITERATIONS", "VERTEX_ITERATIONS", "all_positive", "c_array",
    "band_grid", "brent_accept", "brent_points", "brent_propose", "brent_run", "brent_set_start", "brent_start",
    "cell_candidates", "cell_maxima_pole_residue", "cell_select", "certified_maxima", "certified_maxima_batch",
    "direct_magnitudes",
    "direct_outputs", "direct_solutions", "forcing_values", "impedance", "mode_order", "drop_falling_edges", "dual",
    "edge_probes", "eigen_pairs", "left_vectors", "log_or_value", "magnitude", "magnitudes", "member_state",
    "pole_residue_magnitudes", "pole_residue_sums", "refine_cells", "residues", "stacked_eigen_pairs",
    "state_eigen_pairs", "state_matrices", "state_matrix", "take_better",
    "vertex_points", "vertex_run", "vertex_start", "vertex_update", "weak_roots",
]
