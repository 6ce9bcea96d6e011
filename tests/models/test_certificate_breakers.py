"""Inputs built to break the certified band maximum (issue 27 R2): ``certified`` must be true only when U is the band
maximum to CERTIFIED_RTOL (1e-8 relative); otherwise a reason.  One group per kind — near-zero damping and peaks far
from 1, delays whose phase turns many times inside one resonance, (nearly) repeated poles, free rigid-body roots at
0 Hz, poles on a band edge — each with the input the issue names and others of the same kind.

The references never call railopt: closed forms, or a dense sweep of Z(Ω)X = F solved here with numpy (plus
windows around every pole, found here from the state matrix) whose local maxima are refined by scipy's Brent and
whose final values are exact rational arithmetic (fractions) for these small systems.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from railopt.models import Forcing, LinearSystem
from railopt.models.response_maxima import CERTIFIED_RTOL

QUANTITY = {0: "displacement", 1: "velocity", 2: "acceleration"}


class Case:
    """M, C, K, forcing terms [(amplitude (n,), delay s)], output row, order q (0, 1, 2) and the band (rad/s)."""

    def __init__(self, M, C, K, terms, row, q, band):
        self.M, self.C, self.K = (np.atleast_2d(np.asarray(a, dtype=float)) for a in (M, C, K))
        self.terms = [(np.asarray(a, dtype=complex), float(t)) for a, t in terms]
        self.row, self.q, self.band = np.asarray(row, dtype=float), q, band

    def system(self) -> LinearSystem:
        return LinearSystem(self.M, self.C, self.K, Forcing.delayed(self.terms), self.row,
                            response=QUANTITY[self.q])

    # ---------------------------------------------------------------- the independent reference
    def magnitude(self, w: np.ndarray) -> np.ndarray:
        """|H(Ω)| by numpy's batched solve (chunks of 100,000 frequencies)."""
        w = np.atleast_1d(np.asarray(w, dtype=float))
        out = np.empty(w.size)
        for i in range(0, w.size, 100_000):
            x = w[i:i + 100_000]
            Z = self.K[None] - x[:, None, None] ** 2 * self.M[None] + 1j * x[:, None, None] * self.C[None]
            F = sum(a[None, :] * np.exp(-1j * x * t)[:, None] for a, t in self.terms)
            with np.errstate(all="ignore"):
                X = np.linalg.solve(Z, F[..., None])[..., 0]
            out[i:i + 100_000] = np.abs(X @ self.row) * x**self.q
        return out

    def exact(self, omega: float) -> float:
        """|H(Ω)| in exact rational arithmetic (the delays' cos and sin in double precision)."""
        w = Fraction(float(omega))
        n = self.M.shape[0]
        A = [[(Fraction(float(self.K[i, j])) - w * w * Fraction(float(self.M[i, j])),
               w * Fraction(float(self.C[i, j]))) for j in range(n)] for i in range(n)]
        for i in range(n):
            re = im = Fraction(0)
            for a, t in self.terms:
                c, s = (math.cos(float(omega) * t), -math.sin(float(omega) * t)) if t else (1.0, 0.0)
                ar, ai = Fraction(float(a[i].real)), Fraction(float(a[i].imag))
                re += ar * Fraction(c) - ai * Fraction(s)
                im += ar * Fraction(s) + ai * Fraction(c)
            A[i].append((re, im))

        def mul(a, b):
            return (a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0])

        def div(a, b):
            d = b[0] * b[0] + b[1] * b[1]
            return ((a[0] * b[0] + a[1] * b[1]) / d, (a[1] * b[0] - a[0] * b[1]) / d)

        for col in range(n):  # Gaussian elimination, exact
            piv = next(r for r in range(col, n) if A[r][col] != (0, 0))
            A[col], A[piv] = A[piv], A[col]
            for r in range(col + 1, n):
                f = div(A[r][col], A[col][col])
                A[r] = [(A[r][j][0] - mul(f, A[col][j])[0], A[r][j][1] - mul(f, A[col][j])[1]) for j in range(n + 1)]
        X = [None] * n
        for i in reversed(range(n)):
            acc = A[i][n]
            for j in range(i + 1, n):
                p = mul(A[i][j], X[j])
                acc = (acc[0] - p[0], acc[1] - p[1])
            X[i] = div(acc, A[i][i])
        hr = sum((Fraction(float(self.row[i])) * X[i][0] for i in range(n)), Fraction(0))
        hi = sum((Fraction(float(self.row[i])) * X[i][1] for i in range(n)), Fraction(0))
        return math.sqrt(float(hr * hr + hi * hi)) * float(omega) ** self.q

    def poles(self) -> np.ndarray:
        n = self.M.shape[0]
        Minv = np.linalg.inv(self.M)
        G = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ self.K, -Minv @ self.C]])
        return np.linalg.eigvals(G)

    def reference(self, points: int = 400_001) -> float:
        """Dense sweep of the band plus a window of ±200 half-widths around every pole in it; every sampled local
        maximum within 10 % of the best refined by Brent; the final values exact."""
        lo, hi = self.band
        grids = [np.linspace(lo, hi, points)]
        for s in self.poles():
            if s.imag > 0 and lo <= s.imag <= hi:
                half = 200 * abs(s.real) + 1e-12 * s.imag
                grids.append(np.linspace(max(lo, s.imag - half), min(hi, s.imag + half), 20_001))
        best = max(self.exact(lo) if lo > 0 else 0.0, self.exact(hi))
        for w in grids:
            a = self.magnitude(w)
            a = np.where(np.isfinite(a), a, 0.0)
            idx = np.flatnonzero((a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:])) + 1
            if not idx.size:
                continue
            for k in idx[a[idx] >= 0.9 * a[idx].max()]:
                r = minimize_scalar(lambda x: -self.magnitude(x)[0], bounds=(w[k - 1], w[k + 1]), method="bounded",
                                    options={"xatol": 1e-15 * hi})
                best = max(best, self.exact(r.x), self.exact(w[k]))
        return best


def check(case: Case, reference: float) -> object:
    """The invariant: certified ⇒ U is the band maximum to CERTIFIED_RTOL; not certified ⇒ a reason."""
    rm = case.system().response_maxima(band_rad_s=case.band, exact=True)
    if rm.certified:
        assert rm.reason == ""
        assert rm.value == pytest.approx(reference, rel=CERTIFIED_RTOL), rm
    else:
        assert rm.reason, rm
    return rm


def sdof(zeta: float, q: int = 0, band=(0.0, 20.0), amplitude: float = 100.0, terms=None) -> Case:
    """m = 1, k = 100 (ω_n = 10 rad/s) under a force (amplitude k: the static displacement is 1)."""
    c = 2 * zeta * 10.0
    return Case([[1.0]], [[c]], [[100.0]], terms or [([amplitude], 0.0)], [1.0], q, band)


def sdof_peak(zeta: float) -> float:
    """Closed form: the peak of |X/(F/k)| (displacement) or of |A/(F/m)| (acceleration), 1/(2ζ√(1−ζ²))."""
    return 1.0 / (2 * zeta * math.sqrt(1 - zeta * zeta))


# ------------------------------------------------------------------ near-zero damping, peaks far from 1
def test_sdof_with_zeta_1e_12_is_not_certified_infinite():
    """The issue's input: a finite closed-form peak 5e11 was reported as U = inf, certified."""
    rm = check(sdof(1e-12), sdof_peak(1e-12))
    assert not rm.certified and "damping ratio" in rm.reason and "undamped to rounding" in rm.reason


def test_two_dof_with_zeta_1e_9_is_the_exact_maximum():
    M, K = np.diag([1.0, 2.0]), np.array([[300.0, -100.0], [-100.0, 100.0]])
    C = 2e-9 * 7.0 * M + 3e-10 * np.array([[1.0, -1.0], [-1.0, 1.0]])  # ζ ≈ 1e-9, 3e-10: not proportional
    case = Case(M, C, K, [([1.0, 0.5], 0.0)], [0.3, 1.0], 0, (0.0, 40.0))
    rm = check(case, case.reference())
    assert rm.certified  # resolved in double precision: certified, and then exact (check)


def test_three_dof_with_zeta_near_1e_11_and_a_mode_below_the_undamped_threshold():
    M = np.diag([1.0, 1.5, 0.7])
    K = np.array([[250.0, -100.0, 0.0], [-100.0, 180.0, -80.0], [0.0, -80.0, 80.0]])
    light = Case(M, 2e-11 * K + 1e-11 * np.eye(3), K, [([0.0, 1.0, 0.2], 0.0)], [1.0, 0.0, 0.5], 1, (0.0, 25.0))
    check(light, light.reference())
    below = Case(M, 2e-14 * K, K, [([0.0, 1.0, 0.2], 0.0)], [1.0, 0.0, 0.5], 1, (0.0, 25.0))  # ζ ≲ 1e-12
    rm = below.system().response_maxima(band_rad_s=below.band, exact=True)
    assert not rm.certified and "undamped to rounding" in rm.reason


@pytest.mark.parametrize("amplitude", [1e160 * 100.0, 1e-170 * 100.0, 1e300])
def test_peaks_far_from_one_are_located_without_over_or_underflow(amplitude):
    """|H|² overflows at 1e160 and underflows at 1e-170: the refinement is scale-free."""
    rm = check(sdof(0.005, amplitude=amplitude), sdof_peak(0.005) * amplitude / 100.0)
    assert rm.certified and rm.value == pytest.approx(sdof_peak(0.005) * amplitude / 100.0, rel=1e-12)


# ------------------------------------------------------------------ delays: many interference lobes in a resonance
def test_sdof_with_a_delay_of_3000_s():
    """The issue's input: F = k(1 + e^{−iΩτ}), τ = 3000 s; the lobes (period 2.1e-3 rad/s) inside the resonance
    (half-width 0.2 rad/s) are nearly equal and each sampled below its top."""
    case = sdof(0.02, terms=[([100.0], 0.0), ([100.0], 3000.0)])
    rm = check(case, case.reference(2_000_001))
    assert rm.certified


def test_two_dof_with_two_large_delays():
    M, K = np.diag([1.0, 2.0]), np.array([[300.0, -100.0], [-100.0, 100.0]])
    case = Case(M, 0.002 * K + 0.01 * M, K, [([1.0, 0.3], 0.0), ([0.5, 1.0], 700.0), ([0.2, -0.4], 1900.0)],
                [0.3, 1.0], 2, (0.0, 30.0))
    rm = check(case, case.reference(2_000_001))
    assert rm.certified


def test_three_dof_three_inputs_and_an_inner_band():
    M = np.diag([1.0, 1.5, 0.7])
    K = np.array([[250.0, -100.0, 0.0], [-100.0, 180.0, -80.0], [0.0, -80.0, 80.0]])
    case = Case(M, 0.004 * K, K, [([1.0, 0.0, 0.0], 0.0), ([0.0, 0.7, 0.0], 450.0), ([0.0, 0.0, 1.3], 2600.0)],
                [0.0, 0.0, 1.0], 0, (4.0, 16.0))
    rm = check(case, case.reference(2_000_001))
    assert rm.certified


def test_a_delay_too_long_for_the_grid_is_not_certified_and_says_so():
    rm = sdof(0.02, terms=[([100.0], 0.0), ([100.0], 1e5)]).system().response_maxima(band_rad_s=(0.0, 20.0),
                                                                                     exact=True)
    assert not rm.certified and "the delay 100000 s alone needs" in rm.reason


# ------------------------------------------------------------------ (nearly) repeated poles
@pytest.mark.parametrize(("detuning", "damping"), [(0.0, 1e-3), (1e-10, 1e-5), (1e-7, 0.1)])
def test_near_defective_pairs(detuning, damping):
    """K = [[4, 1], [0, 4(1 + δ)]], C = c·I: at δ = 0 a Jordan block (one eigenvector)."""
    case = Case(np.eye(2), damping * np.eye(2), [[4.0, 1.0], [0.0, 4.0 * (1 + detuning)]], [([0.0, 1.0], 0.0)],
                [1.0, 0.0], 0, (0.0, 4.0))
    check(case, case.reference())


def test_nearly_repeated_weakly_coupled_light_modes():
    K = np.array([[4.0, 1e-5], [1e-5, 4.0 * (1 + 1e-9)]])
    case = Case(np.eye(2), 1e-4 * K, K, [([1.0, 1.0], 0.0)], [1.0, 1.0], 0, (0.0, 4.0))
    rm = check(case, case.reference())
    assert rm.certified


# ------------------------------------------------------------------ free rigid-body roots at 0 Hz
def free_masses(q: int, rotation: float = 0.0, lo: float = 0.0, c: float = 0.4) -> Case:
    """Two masses (2, 1 kg) joined by k = 100 N/m and c, free; force on mass 1, output of mass 2.  Rotated
    coordinates (same H) make the double root at 0 come out as ±iδ instead of 0."""
    R = np.array([[math.cos(rotation), -math.sin(rotation)], [math.sin(rotation), math.cos(rotation)]])
    e = np.array([[1.0, -1.0], [-1.0, 1.0]])
    return Case(R.T @ np.diag([2.0, 1.0]) @ R, R.T @ (c * e) @ R, R.T @ (100.0 * e) @ R,
                [(R.T @ np.array([1.0, 0.0]), 0.0)], R.T @ np.array([0.0, 1.0]), q, (lo, 30.0))


def free_masses_peak(c: float) -> float:
    """Closed form (Cramer's rule) of |a2/F| = |Ω² kc / ((kc − 2Ω²)(kc − Ω²) − kc²)|, kc = k + iΩc, maximised by
    a sweep and Brent; at Ω → 0 it is 1/(m1 + m2)."""
    def a2(w):
        kc = 100.0 + 1j * w * c
        return abs(w * w * kc / ((kc - 2 * w * w) * (kc - w * w) - kc * kc))

    w = np.linspace(1e-3, 30.0, 300_001)
    v = np.array([a2(x) for x in w[::100]])
    i = int(np.argmax(v)) * 100
    r = minimize_scalar(lambda x: -a2(x), bounds=(w[max(i - 100, 0)], w[min(i + 100, len(w) - 1)]), method="bounded",
                        options={"xatol": 1e-13})
    return max(-r.fun, 1 / 3)


@pytest.mark.parametrize(("rotation", "lo"), [(0.3, 1e-8), (0.3, 1e-9), (0.0, 1e-6), (0.3, 0.0), (0.0, 1e-12)])
def test_free_masses_with_the_band_starting_near_or_at_zero(rotation, lo):
    """Rotated, the rigid double root is ±5e-8i: a 'mode' inside a band from 1e-8 rad/s, whose cell was sampled on the
    singular Z and reported U = inf, certified.  A lower edge inside the rounding zone of Z near 0 takes the limit
    model instead of a solve that rounding ruins."""
    rm = check(free_masses(2, rotation, lo), free_masses_peak(0.4))
    assert rm.certified
    assert rm.values[-2] == pytest.approx(1 / 3, rel=1e-9)  # the lower edge: the limit 1/(m1 + m2)


@pytest.mark.parametrize("c", [0.4, 3.0])
def test_the_limit_at_zero_is_the_maximum(c):
    """A free body (2 kg) with a damper c to ground, velocity under a force: |H| = 1/|c + 2iΩ| is largest at 0."""
    case = Case([[2.0]], [[c]], [[0.0]], [([1.0], 0.0)], [1.0], 1, (0.0, 10.0))
    rm = check(case, 1.0 / c)
    assert rm.certified and rm.argmax_frequency == 0.0


def test_a_free_body_with_an_oscillator_velocity_from_zero():
    M = np.diag([2.0, 0.5])
    K = np.array([[50.0, -50.0], [-50.0, 50.0]])
    C = np.array([[1.6, -0.1], [-0.1, 0.1]])  # 1.5 N·s/m to ground: the limit at 0 is 1/1.5
    case = Case(M, C, K, [([1.0, 0.0], 0.0)], [1.0, 0.0], 1, (0.0, 30.0))
    lim = 1 / 1.5
    w = np.linspace(1e-4, 30.0, 300_001)
    reference = max(lim, float(np.max(case.magnitude(w))))
    rm = check(case, reference)
    assert rm.certified and rm.value == pytest.approx(lim, rel=CERTIFIED_RTOL)


def test_an_output_unbounded_at_zero_from_a_band_inside_the_rounding_zone():
    rm = free_masses(0, 0.3, 1e-7).system().response_maxima(band_rad_s=(1e-7, 30.0), exact=True)
    assert not rm.certified and "grows without bound as Ω → 0" in rm.reason


def test_a_mode_too_soft_for_the_search_is_not_certified():
    """A damped oscillator at 1e-5 rad/s beside one at 1e4 rad/s: below 1e-8·max|s| it is taken as free rigid-body
    motion, so its peak (50) is never sampled — not certified, never 1.0 certified."""
    case = Case(np.eye(2), np.diag([2e-7, 200.0]), np.diag([1e-10, 1e8]), [([1.0, 0.0], 0.0)], [1.0, 0.0], 2,
                (0.0, 2e4))
    rm = case.system().response_maxima(band_rad_s=case.band, exact=True)
    assert not rm.certified and "too soft" in rm.reason


# ------------------------------------------------------------------ poles on a band edge
ZETA = 1e-6
WD = 10.0 * math.sqrt(1 - ZETA**2)


@pytest.mark.parametrize(("q", "band", "reference"), [
    (0, (1.0, WD), sdof_peak(ZETA)),  # the displacement peak lies just below ω_d: inside
    (2, (WD, 20.0), sdof_peak(ZETA)),  # the acceleration peak lies just above ω_d: inside
    (0, (1.0, WD - 3 * 10 * ZETA), 1 / abs(1 - (WD - 3e-5) ** 2 / 100 + 2j * ZETA * (WD - 3e-5) / 10)),  # at hi
    (2, (WD + 3e-5, 20.0), (WD + 3e-5) ** 2 / 100 / abs(1 - (WD + 3e-5) ** 2 / 100 + 2j * ZETA * (WD + 3e-5) / 10)),
])
def test_a_light_pole_on_a_band_edge(q, band, reference):
    rm = check(sdof(ZETA, q, band, amplitude=100.0 if q == 0 else 1.0), reference)  # |X|/(F/k) or |A|/(F/m)
    assert rm.certified


def test_a_two_dof_pole_exactly_on_the_upper_edge():
    M, K = np.diag([1.0, 2.0]), np.array([[300.0, -100.0], [-100.0, 100.0]])
    C = 1e-7 * K
    s = Case(M, C, K, [([1.0, 0.5], 0.0)], [0.3, 1.0], 0, (0.0, 1.0)).poles()
    wd = float(np.sort(s.imag[s.imag > 0])[1])
    case = Case(M, C, K, [([1.0, 0.5], 0.0)], [0.3, 1.0], 0, (1.0, wd))
    rm = check(case, case.reference())
    assert rm.certified
