"""Equivalent conicity of a Δr with a flat centre (EN 15302 case E4 kind) and of measured, noisy tables.

Independent references: the closed form of the flat-centre periodic solution (derived in the module doc of
:mod:`railopt.models.contact.conicity`: harmonic arcs outside the plateau, a straight crossing on it), its
asymmetric generalisation, and a time integration of the kinematic equation y'' = −Δr(y)/(2 e0 r0).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from railopt.models.contact import equivalent_conicity, kinematic_wavelength, turning_points
from railopt.models.contact.conicity import noise_level

R0, E0 = 0.46, 0.75
D = 1.7e-3  # EN 15302 case E4: Δr = 0 for |y| ≤ 1.7 mm
Y = np.round(np.arange(-68, 69) / 10.0, 1) * 1e-3  # the EN 15302 grid, ±6.8 mm in 0.1 mm steps


def _flat(lam: float, d: float = D, y: np.ndarray = Y) -> tuple[np.ndarray, np.ndarray]:
    return y, np.where(np.abs(y) <= d, 0.0, 2 * lam * (y - np.sign(y) * d))


def _closed_form(lam: float, amplitude: float, d: float = D) -> float:
    """tan γe = λπ²/(π + 2d/(ŷ − d))² for ŷ > d, else 0."""
    return 0.0 if amplitude <= d else lam * math.pi**2 / (math.pi + 2 * d / (amplitude - d)) ** 2


@pytest.mark.parametrize("lam", [0.05, 0.15, 0.4])
def test_flat_centre_against_the_closed_form(lam: float) -> None:
    y, dr = _flat(lam)
    amplitudes = [0.1e-3, 1.0e-3, 1.6e-3, 1.69e-3, 1.699e-3, 1.7e-3, 1.70001e-3, 1.701e-3, 1.75e-3, 2e-3, 3e-3,
                  4.5e-3, 6.7e-3]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the fault: divide-by-zero warnings and "Δr has the wrong sign" below d
        ours = [equivalent_conicity(y, dr, a, r0=R0, e0=E0) for a in amplitudes]
    for a, value in zip(amplitudes, ours, strict=True):
        exact = _closed_form(lam, a)
        if exact == 0.0:
            assert value == 0.0, a
        else:
            # measured: ≤ 4.4e-16 relative for ŷ − d ≥ 0.05 mm; 9.4e-9 at ŷ − d = 10 nm (tan γe ≈ 1e-11 there)
            assert value == pytest.approx(exact, rel=1e-8, abs=0), a
    assert ours[-1] < lam  # the plateau lowers the conicity at every amplitude


def test_flat_centre_wavelength_and_turning_points() -> None:
    y, dr = _flat(0.15)
    assert kinematic_wavelength(y, dr, 1.0e-3) == math.inf
    with pytest.raises(ValueError, match="^amplitude: .* flat centre"):
        turning_points(y, dr, 1.0e-3)
    assert turning_points(y, dr, 3e-3) == pytest.approx((-3e-3, 3e-3), rel=1e-12, abs=0)
    omega = math.sqrt(0.15 / (E0 * R0))
    assert kinematic_wavelength(y, dr, 3e-3, r0=R0, e0=E0) == pytest.approx(
        2 * math.pi / omega + 4 * D / (omega * (3e-3 - D)), rel=1e-10)


def _asymmetric(lam1: float, lam2: float, d1: float, d2: float) -> tuple[np.ndarray, np.ndarray]:
    """Δr = 0 on [−d1, d2], slope 2λ1 left of it, 2λ2 right of it (nodes on both edges)."""
    y = np.unique(np.concatenate([np.linspace(-0.008, 0.008, 161), [-d1, d2]]))
    dr = np.where(y < -d1, 2 * lam1 * (y + d1), np.where(y > d2, 2 * lam2 * (y - d2), 0.0))
    return y, dr


def test_asymmetric_flat_centre_against_its_closed_form() -> None:
    # energy: the crossing speed v is the same on both sides, v = ω1 ŷ1 = ω2 ŷ2 (ŷi: excursion beyond an edge),
    # ŷ1 + ŷ2 = 2ŷ − d1 − d2; one wavelength = two half arcs π/ω1 + π/ω2 and two crossings 2(d1 + d2)/v
    lam1, lam2, d1, d2 = 0.1, 0.3, 1.0e-3, 2.0e-3
    y, dr = _asymmetric(lam1, lam2, d1, d2)
    w1, w2 = math.sqrt(lam1 / (E0 * R0)), math.sqrt(lam2 / (E0 * R0))
    assert equivalent_conicity(y, dr, 1.4e-3) == 0.0 and equivalent_conicity(y, dr, 1.5e-3) == 0.0  # 2ŷ ≤ d1 + d2
    for amplitude in (1.6e-3, 2.5e-3, 4e-3, 5.5e-3):
        s = 2 * amplitude - d1 - d2
        v = s / (1 / w1 + 1 / w2)
        L = math.pi / w1 + math.pi / w2 + 2 * (d1 + d2) / v
        assert kinematic_wavelength(y, dr, amplitude, r0=R0, e0=E0) == pytest.approx(L, rel=1e-10)
        assert turning_points(y, dr, amplitude) == pytest.approx((-d1 - v / w1, d2 + v / w2), rel=1e-10, abs=0)


def _wavelength_by_time_integration(y: np.ndarray, dr: np.ndarray, y_start: float, L_guess: float) -> float:
    """Integrate y'' = −Δr(y)/(2 e0 r0) from rest at ``y_start`` and time one full cycle (next maximum)."""

    def rhs(_x: float, u: np.ndarray) -> list[float]:
        return [u[1], -np.interp(u[0], y, dr) / (2 * E0 * R0)]

    def back_at_top(_x: float, u: np.ndarray) -> float:
        return u[1]

    back_at_top.direction = -1.0
    sol = solve_ivp(rhs, (0.0, 1.5 * L_guess), [y_start, 0.0], method="DOP853", rtol=1e-13, atol=1e-16,
                    events=back_at_top, max_step=L_guess / 200)
    ev = sol.t_events[0]
    return float(ev[ev > 0.01 * L_guess][0])


@pytest.mark.parametrize("amplitude", [1.75e-3, 2.2e-3, 5e-3])
def test_flat_centre_agrees_with_time_integration(amplitude: float) -> None:
    y, dr = _flat(0.2)
    L = kinematic_wavelength(y, dr, amplitude, r0=R0, e0=E0)
    assert _wavelength_by_time_integration(y, dr, amplitude, L) == pytest.approx(L, rel=1e-6)
    y2, dr2 = _asymmetric(0.1, 0.3, 1.0e-3, 2.0e-3)
    lo, hi = turning_points(y2, dr2, amplitude)
    L2 = kinematic_wavelength(y2, dr2, amplitude, r0=R0, e0=E0)
    assert _wavelength_by_time_integration(y2, dr2, hi, L2) == pytest.approx(L2, rel=1e-6)


# ---------------------------------------------------------------------- measured (noisy) tables


@pytest.mark.parametrize("sigma", [1e-6, 3e-6])
def test_noise_level_estimates_the_noise(sigma: float) -> None:
    y, dr = _flat(0.15)
    assert noise_level(y, dr) == 0.0  # a clean piecewise-linear table: no noise
    estimates = [noise_level(y, dr + np.random.default_rng(s).normal(0, sigma, y.size)) for s in range(40)]
    assert np.median(estimates) == pytest.approx(sigma, rel=0.1)


def test_noisy_flat_centre_gives_its_noise_free_value() -> None:
    """E4-like table + white noise σ = 2 µm (a measured Δr): each of 40 tables against the noise-free closed form.

    Measured over 200 seeds: exactly 0 for every ŷ ≤ d; |error| ≤ 5.6e-4 for ŷ ≥ 1.9 mm (noise F = ∫Δr averages).
    """
    lam = 0.15
    y, dr = _flat(lam)
    small = [0.2e-3, 0.5e-3, 1.0e-3, 1.5e-3, 1.65e-3, 1.7e-3]
    large = [1.9e-3, 2.5e-3, 3e-3, 4e-3, 5e-3, 6.5e-3]
    for seed in range(40):
        noisy = dr + np.random.default_rng(seed).normal(0.0, 2e-6, y.size)
        assert np.sum(np.diff(np.sign(noisy[np.abs(y) <= D])) != 0) > 5  # the noise crosses zero many times
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert [equivalent_conicity(y, noisy, a) for a in small] == [0.0] * len(small)
            errors = [equivalent_conicity(y, noisy, a) - _closed_form(lam, a) for a in large]
        assert np.max(np.abs(errors)) < 1e-3, (seed, errors)


def test_noisy_linear_table_and_explicit_noise_band() -> None:
    """A conical pair (Δr = 2λy) measured with 3 µm noise: λ within the noise's effect at EN 15302 amplitudes."""
    lam = 0.2
    y = Y
    for seed in range(10):
        noisy = 2 * lam * y + np.random.default_rng(100 + seed).normal(0.0, 3e-6, y.size)
        for a in (1e-3, 3e-3, 6e-3):
            assert equivalent_conicity(y, noisy, a) == pytest.approx(lam, abs=3e-3)  # measured max 1.2e-3
            assert equivalent_conicity(y, noisy, a, noise=15e-6) == pytest.approx(lam, abs=3e-3)
    with pytest.raises(ValueError, match="^noise"):
        equivalent_conicity(y, 2 * lam * y, 1e-3, noise=-1.0)


def test_two_genuine_equilibria_are_still_refused() -> None:
    """A dip of 0.1 mm below zero is no noise: two stable equilibria, ambiguous, refused naming delta_r."""
    y, dr = _flat(0.15)
    dr = dr.copy()
    dr[(y > 3.5e-3) & (y < 4.5e-3)] = -1e-4
    with pytest.raises(ValueError, match="^delta_r: must change sign exactly once"):
        equivalent_conicity(y, dr, 2e-3)
