"""The compiled kernels of the certified band maximum (railopt.models.kernels), each against an independent reference:
dense direct solves ``np.linalg.solve(K − Ω²M + iΩC, F(Ω))`` written here, closed forms (the single-DOF peak
1/(2ζ√(1−ζ²))/k at Ω = ω_n√(1−2ζ²)), scipy's ``fminbound``, and invariants of the grid rule."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import fminbound, minimize_scalar
from test_forcing import delayed_system

from railopt.models import Forcing, LinearSystem, kernels
from railopt.models.peak_search import bracketed_maximum, cell_maxima, vertex_refine
from railopt.models.response_maxima import CERTIFIED_RATIO, band_grid, response_maxima


def chain(n: int, seed: int, terms: int = 2, max_delay: float = 0.7) -> tuple:
    """test_forcing's delayed chain (stiffness + damper inputs: degree 1 in iΩ, delayed) with two outputs, its own
    acceleration row and a velocity row.  Returns (M, C, K, A (T, J, n), delays (T,), rows (m, n), q (m,))."""
    sys = delayed_system(n, terms, max_delay, seed)
    A = np.array([t.coefficients for t in sys.forcing.terms])
    delays = np.array([t.delay for t in sys.forcing.terms])
    rows = np.array([np.random.default_rng(seed + 100).standard_normal(n), sys.output])
    return np.array(sys.M), np.array(sys.C), np.array(sys.K), A, delays, rows, np.array([1, 2])


def direct_frf(M, C, K, A, delays, rows, q, w):
    """Reference: H (N, m) by one dense solve per frequency."""
    H = np.empty((len(w), len(rows)), dtype=complex)
    for i, x in enumerate(w):
        F = sum(np.exp(-1j * x * tau) * sum((1j * x) ** j * A[t, j] for j in range(A.shape[1]))
                for t, tau in enumerate(delays))
        X = np.linalg.solve(K - x**2 * M + 1j * x * C, F)
        H[i] = (rows @ X) * (1j * x) ** q
    return H


def residues(M, C, K, A, rows):
    """R[k, o, t, j] = (c_o·V_x[:, k]) (W_v M⁻¹ A_tj)_k from numpy's eig of the state matrix (the kernel's input)."""
    n = M.shape[0]
    G = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    s, V = np.linalg.eig(G)
    W = np.linalg.inv(V)
    B = W[:, n:] @ np.linalg.inv(M)
    R = np.einsum("ok,ktj->kotj", rows @ V[:n], np.einsum("kn,tjn->ktj", B, A))
    return np.ascontiguousarray(s), np.ascontiguousarray(R)


def test_pole_residue_sums_equal_dense_direct_solves():
    """Polynomial (degree 1) delayed forcing, two outputs (velocity, acceleration): the kernel's sum times (iΩ)^q
    equals the dense direct solve to ≤ 1e-12 relative."""
    M, C, K, A, delays, rows, q = chain(4, seed=3)
    s, R = residues(M, C, K, A, rows)
    w = np.linspace(0.05, 4.0, 301)
    S = kernels.pole_residue_sums(w, s, R, np.array([0, 1], dtype=np.int64), delays)
    H = S * (1j * w[:, None]) ** q[None, :]
    ref = direct_frf(M, C, K, A, delays, rows, q, w)
    assert np.max(np.abs(H - ref) / np.abs(ref)) < 1e-12
    for o in range(2):
        mag = kernels.pole_residue_magnitudes(w, s, R, o, delays, int(q[o]))
        assert np.max(np.abs(mag - np.abs(ref[:, o])) / np.abs(ref[:, o])) < 1e-12


def sdof(zeta: float, m: float = 2.0, k: float = 50.0):
    """Single DOF: poles, residues of x/F (R± = ±1/(m(s₊ − s₋))), ω_n."""
    wn = np.sqrt(k / m)
    wd = wn * np.sqrt(1 - zeta**2)
    s = np.array([-zeta * wn + 1j * wd, -zeta * wn - 1j * wd])
    r = 1.0 / (m * (s[0] - s[1]))
    R = np.zeros((2, 1, 1, 1), dtype=complex)
    R[:, 0, 0, 0] = [r, -r]
    return s, R, wn, m, k


def test_single_dof_magnitude_is_the_closed_form_at_a_pole_inf():
    s, R, wn, m, k = sdof(0.05)
    c = 2 * 0.05 * np.sqrt(k * m)
    w = np.linspace(0.0, 3 * wn, 97)
    mag = kernels.pole_residue_magnitudes(w, s, R, 0, np.zeros(1), 0)
    np.testing.assert_allclose(mag, 1.0 / np.abs(k - m * w**2 + 1j * c * w), rtol=1e-13)
    # an undamped pole hit exactly: |H| = +inf (never NaN, never an exception)
    s0 = np.array([3j, -3j])
    assert kernels.pole_residue_magnitudes(np.array([3.0]), s0, R, 0, np.zeros(1), 0)[0] == np.inf


@pytest.mark.parametrize("zeta", [0.3, 0.02, 1e-4])
def test_single_dof_cell_maximum_is_the_closed_form_peak(zeta):
    """Peak of |1/(k − mΩ² + icΩ)| is 1/(2ζ√(1−ζ²))/k at Ω = ω_n√(1−2ζ²): value to 1e-12, location to 1e-9."""
    s, R, wn, m, k = sdof(zeta)
    hi = 2.5 * wn
    grid, ratio = band_grid(s, (0.0, hi), extra=np.array([0.0, hi]))
    assert ratio <= CERTIFIED_RATIO
    values = kernels.pole_residue_magnitudes(grid, s, R, 0, np.zeros(1), 0)
    x, f, empty = kernels.cell_maxima_pole_residue(grid, values, np.array([0.0, hi]), 1e-6, s, R, 0,
                                                   np.zeros(1), 0)
    assert empty == -1
    peak = 1.0 / (2 * zeta * np.sqrt(1 - zeta**2)) / k
    assert abs(f[0] - peak) <= 1e-12 * peak
    assert abs(x[0] - wn * np.sqrt(1 - 2 * zeta**2)) <= 1e-9 * wn


def test_the_python_driver_runs_the_same_algorithm_on_a_callable():
    """A Python callable through the same driver: cells of 2 + sin x have their maximum 3 at π/2 + 2πj (closed
    form), and the pole–residue |H| as a callable gives the compiled driver's result to the last bit."""
    bounds = np.array([0.0, 2 * np.pi, 4 * np.pi, 6 * np.pi])
    grid = np.linspace(0.0, 6 * np.pi, 61)
    x, f = cell_maxima(lambda w: 2 + np.sin(w), grid, 2 + np.sin(grid), bounds)
    np.testing.assert_allclose(f, 3.0, rtol=1e-13)
    np.testing.assert_allclose(x, np.pi / 2 + 2 * np.pi * np.arange(3), rtol=1e-7)
    s, R, wn, *_ = sdof(0.01)
    grid, _ = band_grid(s, (0.0, 3 * wn))
    values = kernels.pole_residue_magnitudes(grid, s, R, 0, np.zeros(1), 0)
    b = np.array([0.0, 3 * wn])
    compiled = kernels.cell_maxima_pole_residue(grid, values, b, 1e-6, s, R, 0, np.zeros(1), 0)
    python = kernels.refine_cells(grid, values, b, 1e-6,
                                  lambda w: kernels.pole_residue_magnitudes(w, s, R, 0, np.zeros(1), 0))
    assert compiled[0][0] == python[0][0] and compiled[1][0] == python[1][0]


def test_empty_cell_is_named():
    with pytest.raises(ValueError, match="grid: no sample in cell"):
        cell_maxima(np.cos, np.array([0.0, 1.0, 3.0]), np.cos([0.0, 1.0, 3.0]), np.array([0.0, 1.2, 1.5, 3.0]))


def test_brent_steps_agree_with_scipy_fminbound():
    """Brent's bounded search (the same algorithm as scipy's fminbound) on f(x) = x e^{−x²}·(1 + 0.3 sin 5x) over
    several brackets: the maximiser agrees with fminbound (xtol 1e-12) to 1e-6 of the bracket width."""
    def f(x):
        return x * np.exp(-x**2) * (1 + 0.3 * np.sin(5 * x))

    lower, upper = np.array([0.1, 0.5, -0.2, 1.5]), np.array([1.2, 0.9, 2.0, 2.5])
    x, value = bracketed_maximum(f, lower, upper, rtol=1e-8)
    for i in range(len(lower)):
        ref = fminbound(lambda t: -f(t), lower[i], upper[i], xtol=1e-12)
        assert abs(x[i] - ref) <= 1e-6 * (upper[i] - lower[i])
        assert value[i] == f(x[i]) and value[i] >= f(ref) - 1e-12 * abs(f(ref))


def test_vertex_steps_land_on_a_lorentzian_peak():
    """|H|² of one pole is 1/((Ω−ω)² + σ²): φ = 1/f² is an exact parabola, so the vertex is ω."""
    for omega, sigma in [(1.0, 0.01), (5.0, 0.2), (20.0, 1.0)]:
        def f(w, omega=omega, sigma=sigma):
            return 1.0 / np.sqrt((np.asarray(w) - omega) ** 2 + sigma**2)

        x, ok = vertex_refine(f, [omega + 0.3 * sigma], [omega - 2 * sigma], [omega + 2 * sigma], positive=True,
                              scale=[1.0 / sigma])
        assert ok.all()
        assert abs(x[0] - omega) <= 1e-12 * omega


def test_band_grid_meets_the_spacing_rule_by_an_independent_count():
    """Every step ≤ CERTIFIED_RATIO × the distance to the nearest pole at its nearer end (computed here with
    numpy), the delay rule holds, and the grid is sorted, unique and contains the band edges and extra points."""
    M, C, K, A, delays, rows, q = chain(6, seed=8)
    s, _ = residues(M, C, K, A, rows)
    extra = np.array([0.3, 1.1, 2.0])
    grid, ratio = band_grid(s, (0.0, 4.0), max_delay=0.7, extra=extra)
    assert grid[0] == 0.0 and grid[-1] == 4.0 and np.all(np.diff(grid) > 0) and np.isin(extra, grid).all()
    dist = np.min(np.abs(1j * grid[:, None] - s[None, :]), axis=1)
    limit = np.minimum(dist, 2 * np.pi / (4 * 0.7))  # GRID_FACTOR × this is the admissible step
    worst = np.max(np.diff(grid) / np.minimum(limit[:-1], limit[1:]))
    assert worst <= CERTIFIED_RATIO
    assert abs(ratio - worst) <= 1e-12 * ratio


def test_certified_maximum_equals_a_dense_sweep():
    """End to end (delayed polynomial forcing, acceleration output): U equals a 200,001-point direct sweep with
    each local maximum refined by scipy's bounded Brent on direct solves, to 1e-9 relative."""
    M, C, K, A, delays, rows, q = chain(5, seed=11)
    spec = [(A[t], float(delays[t])) for t in range(len(delays))]
    sys = LinearSystem(M, C, K, Forcing.delayed(spec), rows[1], response="acceleration")
    band = (0.05, 4.0)
    rm = response_maxima(sys, band_rad_s=band, exact=True)
    assert rm.certified and rm.evaluation == "pole-residue"

    def mag(x):
        x = np.atleast_1d(x)
        return np.abs(direct_frf(M, C, K, A, delays, rows[1:], q[1:], x)[:, 0])

    w = np.linspace(*band, 200_001)
    Z = K[None] - w[:, None, None] ** 2 * M[None] + 1j * w[:, None, None] * C[None]
    F = np.einsum("nt,tjk,nj->nk", np.exp(-1j * np.outer(w, delays)), A, (1j * w[:, None]) ** np.arange(2))
    a = np.abs((np.linalg.solve(Z, F[..., None])[..., 0] @ rows[1]) * (1j * w) ** 2)
    best = max(a[0], a[-1])
    for i in np.flatnonzero((a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:])) + 1:
        r = minimize_scalar(lambda x: -mag(x)[0], bounds=(w[i - 1], w[i + 1]), method="bounded",
                            options={"xatol": 1e-13})
        best = max(best, -r.fun)
    assert abs(rm.value - best) <= 1e-9 * best


def test_each_kernel_keeps_one_compiled_signature():
    """The Python callers normalise at the boundary (float64/complex128, C order, int64): calls with lists, int
    arrays and strided views add no specialisation (each would be a compile of seconds)."""
    s, R, wn, *_ = sdof(0.1)
    grid, _ = band_grid(list(s), (0, 3 * int(wn)), extra=[1, 2])
    grid, _ = band_grid(s[::1], (0.0, 3 * wn), extra=np.array([1, 2]))
    sys = LinearSystem(np.eye(2), 0.1 * np.eye(2), np.array([[2, -1], [-1, 2]]), [1, 0], [0, 1])
    response_maxima(sys, band_rad_s=(0.0, 3.0), exact=True)
    x = np.arange(10.0)[::2]
    cell_maxima(np.cos, x, np.cos(x), np.array([0.0, 8.0]))
    sys.frf(omega_rad_s=[1, 2])
    for kernel in (kernels.band_grid, kernels.pole_residue_magnitudes, kernels.cell_maxima_pole_residue,
                   kernels.pole_residue_sums, kernels.vertex_start, kernels.brent_start, kernels.member_state,
                   kernels.left_vectors, kernels.residues, kernels.direct_solutions, kernels.eigen_pairs,
                   kernels.state_eigen_pairs, kernels.state_matrix):
        assert len(kernel.signatures) <= 1, kernel


def test_member_state_and_left_vectors_against_scipy():
    """M⁻¹[K C] against scipy.linalg.solve, a singular M refused by the pivot rule (ValueError naming M);
    W = V⁻¹ against scipy.linalg.inv and cond₁(V) against numpy's cond(V, 1)."""
    import scipy.linalg as sla

    M, C, K, *_ = chain(5, seed=4)
    minv_kc, regular = kernels.member_state(M, K, C, 1e-14)
    assert regular
    np.testing.assert_allclose(minv_kc, sla.solve(M, np.hstack([K, C])), rtol=1e-14, atol=1e-14 * np.abs(K).max())
    singular = M.copy()
    singular[2] = 0.0
    assert not kernels.member_state(singular, K, C, 1e-14)[1]
    with pytest.raises(ValueError, match="M: is singular"):
        LinearSystem(singular, C, K, np.ones(5), np.ones(5))
    G = np.block([[np.zeros((5, 5)), np.eye(5)], [-minv_kc[:, :5], -minv_kc[:, 5:]]])
    _, V = np.linalg.eig(G)
    W, cond = kernels.left_vectors(np.ascontiguousarray(V))
    np.testing.assert_allclose(W, sla.inv(V), rtol=1e-12, atol=1e-12 * np.abs(W).max())
    assert abs(cond - np.linalg.cond(V, 1)) <= 1e-12 * cond


def _eig_cases() -> list[np.ndarray]:
    """Real square matrices of each kind LAPACK's dgeev meets: complex pairs, all real roots, a mix, a defective
    Jordan block, repeated roots, a zero matrix, a 1×1, random dense ones of several sizes."""
    rng = np.random.default_rng(7)
    cases = [rng.standard_normal((N, N)) for N in (1, 2, 3, 6, 18, 40)]
    cases.append(np.diag([3.0, -1.0, 2.0, 0.5]) + np.triu(rng.standard_normal((4, 4)), 1))  # all real
    cases.append(np.array([[0.0, 1.0], [0.0, 0.0]]))  # a Jordan block at 0
    cases.append(np.kron(np.eye(3), np.array([[0.0, 1.0], [-4.0, -0.1]])))  # a triple complex pair
    cases.append(np.zeros((5, 5)))
    M, C, K, *_ = chain(7, seed=2)
    cases.append(LinearSystem(M, C, K, np.ones(7), np.ones(7)).state_matrix())
    return cases


def test_compiled_eigen_pairs_are_lapack_dgeev_as_numpy_pairs_it():
    """kernels.eigen_pairs calls LAPACK dgeev (scipy's build) and pairs its real output as numpy does: roots and
    vectors equal ``scipy.linalg.eig``'s exactly (the same routine of the same library; complex128 always), one by
    one and stacked; each pair is an eigen-pair (residual ‖GV − V diag(s)‖ at rounding); and the roots of the
    non-defective cases are numpy's (another OpenBLAS build) to rounding, matched root by root."""
    import scipy.linalg as sla

    for G in _eig_cases():
        s_ref, V_ref = sla.eig(G)
        s, V = kernels.eigen_pairs(np.ascontiguousarray(G))
        assert s.dtype == V.dtype == np.complex128
        np.testing.assert_array_equal(s, s_ref)
        np.testing.assert_array_equal(V, V_ref)
        scale = max(np.abs(G).max(), 1.0)
        assert np.abs(G @ V - V * s).max() <= 1e-12 * scale * max(np.abs(V).max(), 1.0)
        if np.linalg.cond(V) < 1e6:  # a well-conditioned eigenbasis: the roots are well determined
            s_np = np.linalg.eigvals(G)
            gap = np.abs(s[:, None] - s_np[None, :]).min(axis=1)
            assert gap.max() <= 1e-12 * max(np.abs(s).max(), 1e-300)
    G = np.random.default_rng(3).standard_normal((4, 6, 6))
    s, V = kernels.stacked_eigen_pairs(G)
    for b in range(4):
        s_ref, V_ref = sla.eig(G[b])
        np.testing.assert_array_equal(s[b], s_ref)
        np.testing.assert_array_equal(V[b], V_ref)
    s, V = kernels.eigen_pairs(np.zeros((0, 0)))
    assert s.shape == (0,) and V.shape == (0, 0)


@pytest.mark.parametrize("exponent", [-1000, -600, -461, -300, -140, 0, 140, 300, 459, 600, 1000])
def test_compiled_eigen_pairs_keep_their_scale_far_from_one(exponent):
    """A damped oscillator's state matrix times 2^e (exact) has the roots 2^e·(−ζω ± iω√(1−ζ²)) — the closed form,
    to 1e-14 — at every scale a double holds, also where LAPACK's own scaling of the matrix (largest entry outside
    about [6.7e-139, 1.5e138]) is not undone by the library's dgeev; the vectors are those of the unscaled
    matrix to rounding."""
    zeta, omega = 0.05, 1.0
    G0 = np.array([[0.0, 1.0], [-omega**2, -2 * zeta * omega]])
    G = np.ldexp(G0, exponent)
    assert np.isfinite(G).all() and np.abs(G).max() > 0
    s, V = kernels.eigen_pairs(G)
    exact = np.ldexp(1.0, exponent) * omega * (-zeta + 1j * np.sqrt(1 - zeta**2) * np.array([1.0, -1.0]))
    assert np.abs(np.sort_complex(s) - np.sort_complex(exact)).max() <= 1e-14 * np.abs(exact).max()
    _, V0 = kernels.eigen_pairs(G0)
    assert np.abs(np.abs(V) - np.abs(V0)).max() <= 1e-14


def test_a_system_at_an_extreme_scale_keeps_its_modes_and_an_honest_maximum():
    """Stiffnesses of 1e140 (ω ≈ 1e70 rad/s), where the library's dgeev alone returned roots 2000× too low and a
    band maximum half the true one marked certified: the damped frequencies are numpy's (its eig scales correctly)
    to 1e-12, and the maximum is not below a 400,001-point dense sweep of direct solves (numpy) — equal to it to
    the sweep's resolution."""
    M = np.diag([1.0, 2.0])
    K = 1e140 * np.array([[30.0, -10.0], [-10.0, 10.0]])
    C = 1e68 * np.array([[3.0, -1.0], [-1.0, 1.0]])
    sys = LinearSystem(M, C, K, [1.0, 0.0], [1.0, 0.0])
    G = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    wd = np.sort(np.abs(np.linalg.eigvals(G).imag))[1::2]
    np.testing.assert_allclose(np.sort(sys.damped_frequencies()), wd, rtol=1e-12)
    band = (8.86e69, 1.13e71)
    rm = response_maxima(sys, band_rad_s=band, exact=True)
    w = np.linspace(*band, 400_001)
    Z = K[None] - w[:, None, None] ** 2 * M[None] + 1j * w[:, None, None] * C[None]
    dense = np.abs(np.linalg.solve(Z, np.broadcast_to([[1.0], [0.0]], (len(w), 2, 1)).astype(complex))[:, 0, 0])
    assert rm.value >= dense.max() * (1 - 1e-12)
    assert rm.value <= dense.max() * (1 + 1e-4)


def test_modal_of_a_complex_matrix_is_numpys_eig():
    """modal(G) of a complex G (outside the real kernel's domain) is numpy's eig of it, never of its real part."""
    from railopt.models.modal import modal

    G = np.array([[0.0, 1j], [1.0, 0.0]])
    s_ref, V_ref = np.linalg.eig(G)
    m = modal(G)
    np.testing.assert_array_equal(m.s, s_ref)
    np.testing.assert_array_equal(m.V, V_ref)


def test_a_one_term_forcing_gives_the_kernels_float_delays():
    """forcing_arrays of a hand-built one-term forcing with an integer delay gives float64 delays (the kernels'
    one signature) and complex128 coefficients (T, J, n)."""
    from railopt.models.forcing import DelayedTerm
    from railopt.models.pole_residue import forcing_arrays

    A, delays = forcing_arrays(Forcing(terms=[DelayedTerm(0, coefficients=np.ones((1, 3), dtype=complex))]), 3)
    assert delays.dtype == np.float64 and delays.tolist() == [0.0]
    assert A.dtype == np.complex128 and A.shape == (1, 1, 3)


def test_compiled_eigen_pairs_refuse_a_non_square_matrix():
    """A 2×3 or 3×2 G raises numpy's LinAlgError (never the eigenvalues of a corner, or memory past the end)."""
    for shape in ((2, 3), (3, 2)):
        with pytest.raises(np.linalg.LinAlgError, match="square"):
            kernels.eigen_pairs(np.ones(shape))


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_compiled_eigen_pairs_refuse_non_finite_entries_as_numpy_does(bad):
    """A NaN or infinite entry raises numpy's LinAlgError, as ``np.linalg.eig`` does (never a NaN root)."""
    G = np.eye(3)
    G[1, 2] = bad
    with pytest.raises(np.linalg.LinAlgError):
        np.linalg.eig(G)
    with pytest.raises(np.linalg.LinAlgError, match="infs or NaNs"):
        kernels.eigen_pairs(G)


def test_state_matrix_kernel_is_the_thesis_block_form():
    """G = [[0, I], [−M⁻¹K, −M⁻¹C]] (thesis eq. 4.53) built here with numpy's solve, against the kernel's (and
    LinearSystem.state_matrix, which is the kernel), its eigen-pairs those of the kernel on that G, and its roots
    numpy's eigvals of the G built here to rounding."""
    M, C, K, *_ = chain(4, seed=9)
    G_ref = np.block([[np.zeros((4, 4)), np.eye(4)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    sys = LinearSystem(M, C, K, np.ones(4), np.ones(4))
    np.testing.assert_allclose(sys.state_matrix(), G_ref, rtol=1e-14, atol=1e-14 * np.abs(G_ref).max())
    s, V = sys.eigen_pairs()
    s_ref, V_ref = kernels.eigen_pairs(sys.state_matrix())
    np.testing.assert_array_equal(s, s_ref)
    np.testing.assert_array_equal(V, V_ref)
    gap = np.abs(s[:, None] - np.linalg.eigvals(G_ref)[None, :]).min(axis=1)
    assert gap.max() <= 1e-12 * np.abs(s).max()


def test_magnitude_is_abs_to_two_ulps_and_inf_where_not_finite():
    """kernels.magnitude (√(re² + im²) where the squares are safe, else abs) against numpy's abs (hypot): within
    two ulps (three roundings, halved by the root, plus the root's own) on random values of every scale, exactly
    abs where the squares over- or underflow, +inf for inf or NaN parts."""
    rng = np.random.default_rng(5)
    z = (rng.standard_normal(2000) + 1j * rng.standard_normal(2000)) * 10.0 ** rng.uniform(-150, 150, 2000)
    ours = np.array([kernels.magnitude(complex(x)) for x in z])
    assert np.all(np.abs(ours - np.abs(z)) <= 2 * np.spacing(np.abs(z)))
    for x in (1e200 + 1e200j, 3e-200 - 4e-200j, 1e-320 + 0j, 0j):
        assert kernels.magnitude(x) == abs(x)
    for x in (complex(np.inf, 1.0), complex(1.0, np.nan), complex(np.nan, np.nan)):
        assert kernels.magnitude(x) == np.inf


def test_band_grid_pole_points_are_the_sinh_formula():
    """The per-pole points stepped by the exponential recurrence equal ω + σ·sinh(u0 + i·δ) (numpy's sinh, here)
    to the recurrence's drift (a few ulps per step, of σ·cosh(u)): for each pole of a lightly damped chain, every
    such point lies in the grid within that distance."""
    M, C, K, A, delays, rows, q = chain(6, seed=8)
    s, _ = residues(M, C, K, A, rows)
    lo, hi, step = 0.0, 4.0, 0.2  # POLE_STEP
    grid, _ = band_grid(s, (lo, hi), max_delay=0.7)
    for pole in s[s.imag > 0]:
        sigma, omega = abs(pole.real), pole.imag
        u0, u1 = np.arcsinh((lo - omega) / sigma), np.arcsinh((hi - omega) / sigma)
        u = u0 + np.arange(int(np.ceil((u1 + step - u0) / step))) * step
        points = np.clip(omega + sigma * np.sinh(u), lo, hi)
        gap = np.min(np.abs(points[:, None] - grid[None, :]), axis=1)
        drift = 4 * (len(u) + 4) * np.finfo(float).eps
        assert np.all(gap <= drift * np.maximum(np.abs(points), sigma * np.cosh(u)))


def test_compiled_residues_and_direct_solutions_equal_dense_solves():
    """The compiled residues summed by the compiled pole–residue kernel, and the compiled batched solves, both
    equal the dense direct solve of this file to 1e-12 relative (polynomial delayed forcing, two outputs)."""
    M, C, K, A, delays, rows, q = chain(4, seed=5)
    s, _ = residues(M, C, K, A, rows)  # numpy's eig: the roots and vectors are inputs here
    n = M.shape[0]
    G = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    s, V = np.linalg.eig(G)
    V = np.ascontiguousarray(V)
    W, _ = kernels.left_vectors(V)
    R, _ = kernels.residues(M, V, W, rows, np.ascontiguousarray(A))
    w = np.linspace(0.1, 3.5, 157)
    ref = direct_frf(M, C, K, A, delays, rows, q, w)
    H = kernels.pole_residue_sums(w, np.ascontiguousarray(s), R, np.array([0, 1], dtype=np.int64), delays)
    H *= (1j * w[:, None]) ** q[None, :]
    assert np.max(np.abs(H - ref) / np.abs(ref)) < 1e-12
    F = np.einsum("nt,tjk,nj->nk", np.exp(-1j * np.outer(w, delays)), A, (1j * w[:, None]) ** np.arange(2))
    X, overflow = kernels.direct_solutions(M, C, K, w, np.ascontiguousarray(F))
    Hd = (X @ rows.T) * (1j * w[:, None]) ** q[None, :]
    assert np.max(np.abs(Hd - ref) / np.abs(ref)) < 1e-13 and not overflow.any()
    # Ω² M overflows at 1e160 rad/s: that row is flagged, not solved
    _, overflow = kernels.direct_solutions(M, C, K, np.array([1.0, 1e160]), np.ascontiguousarray(F[:2]))
    assert overflow.tolist() == [False, True]


def test_an_overflowing_impedance_is_named():
    """Ω² M overflows at Ω = 1e160 rad/s: an error naming omega, never a silent number."""
    sys = LinearSystem(np.eye(2), 0.1 * np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), [1.0, 0.0], [0.0, 1.0])
    with pytest.raises(ValueError, match="omega: Z"):
        sys.frf(omega_rad_s=np.array([1.0, 1e160]))


def test_a_noisy_pole_residue_maximiser_is_located_again_on_direct_solves():
    """Free masses (rigid-body pair: cond(V) ≈ 2.7e7, pole–residue sum noisy at ~1e-9): the mode's cell maximum
    equals scipy's bounded Brent on dense direct solves written here to 1e-12 relative (it was 1.3e-10 low when the
    maximiser was taken from the noisy sum)."""
    M, K, C = np.diag([2.00001, 1.0]), 100.0 * np.array([[1.0, -1.0], [-1.0, 1.0]]), 0.4 * np.array([[1.0, -1.0],
                                                                                                     [-1.0, 1.0]])
    sys = LinearSystem(M, C, K, [1.0, 0.0], [0.0, 1.0], response="acceleration")
    assert sys.modal().condition > 1e6
    rm = sys.response_maxima(band_rad_s=(0.0, 30.0), exact=True)

    def mag(w):
        return abs(np.linalg.solve(K - w**2 * M + 1j * w * C, [1.0, 0.0])[1] * w**2)

    wd = np.abs(np.linalg.eigvals(np.block([[np.zeros((2, 2)), np.eye(2)],
                                            [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])).imag).max()
    r = minimize_scalar(lambda w: -mag(w), bounds=(0.95 * wd, wd), method="bounded", options={"xatol": 1e-12})
    assert abs(rm.values[1] + r.fun) <= 1e-12 * -r.fun
