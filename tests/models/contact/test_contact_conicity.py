"""Equivalent conicity (EN 15302 integral method) against closed forms and a time integration."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import ellipk

from railopt.models.contact import (
    equivalent_conicity,
    kinematic_wavelength,
    linear_delta_r_table,
    turning_points,
)

R0, E0 = 0.46, 0.75


def _wavelength_by_time_integration(y: np.ndarray, dr: np.ndarray, y_start: float) -> float:
    """Second method: integrate y'' = −Δr(y)/(2 e0 r0) from rest at ``y_start`` and time one full cycle."""

    def rhs(_x: float, u: np.ndarray) -> list[float]:
        return [u[1], -np.interp(u[0], y, dr) / (2 * E0 * R0)]

    def back_at_top(_x: float, u: np.ndarray) -> float:
        return u[1]

    back_at_top.direction = -1.0  # y' crosses zero downwards: the next maximum of y
    L_guess = 2 * math.pi * math.sqrt(R0 * E0 / 0.01)
    sol = solve_ivp(
        rhs, (0.0, 3 * L_guess), [y_start, 0.0], method="DOP853", rtol=1e-13, atol=1e-16, events=back_at_top
    )
    ev = sol.t_events[0]
    return float(ev[ev > 1.0][0])  # skip the start point itself


def _klingel(L: float) -> float:
    return E0 * R0 * (2 * math.pi / L) ** 2


@pytest.mark.parametrize("lam", [0.02, 0.05, 0.15, 0.4])
@pytest.mark.parametrize("amplitude", [1e-5, 0.001, 0.003, 0.0119])
def test_linear_table_gives_lambda(lam: float, amplitude: float) -> None:
    y, dr = linear_delta_r_table(lam, y_max=0.012, n=97)
    assert equivalent_conicity(y, dr, amplitude, r0=R0, e0=E0) == pytest.approx(lam, rel=1e-10, abs=0)


def test_shifted_linear_table_and_r0_e0_invariance() -> None:
    # Δr = 2λ(y − y0): same oscillation about y0; the turning points are y0 ± ŷ
    y = np.linspace(-0.01, 0.01, 301)
    dr = 2 * 0.08 * (y - 0.0013)
    assert equivalent_conicity(y, dr, 0.004) == pytest.approx(0.08, rel=1e-10)
    lo, hi = turning_points(y, dr, 0.004)
    assert (lo, hi) == pytest.approx((0.0013 - 0.004, 0.0013 + 0.004), rel=1e-10)
    # tan γe is independent of r0, e0 (L ∝ √(r0 e0) in Klingel's formula)
    yc = np.linspace(-0.01, 0.01, 101)
    drc = 0.1 * yc + 500 * yc**3
    assert equivalent_conicity(yc, drc, 0.006, r0=0.3, e0=0.6) == pytest.approx(
        equivalent_conicity(yc, drc, 0.006, r0=0.5, e0=0.8), rel=1e-13
    )


@pytest.mark.parametrize("amplitude", [0.002, 0.004, 0.008])
def test_cubic_table_against_elliptic_closed_form(amplitude: float) -> None:
    # Δr = 2λy + 2κy³ ⇒ y'' + ω0² y + β y³ = 0 (Duffing) with ω0² = λ/(e0 r0), β = κ/(e0 r0):
    # y = ŷ cn(ωx, m), ω² = ω0² + βŷ², m = βŷ²/(2ω²), L = 4K(m)/ω
    # ⇒ tan γe = π² (λ + κŷ²) / (4 K(m)²)
    lam, kap = 0.05, 300.0
    m = kap * amplitude**2 / (2 * (lam + kap * amplitude**2))
    exact = math.pi**2 * (lam + kap * amplitude**2) / (4 * ellipk(m) ** 2)
    errors = []
    for n in (401, 2001):
        y = np.linspace(-0.01, 0.01, n)
        errors.append(abs(equivalent_conicity(y, 2 * lam * y + 2 * kap * y**3, amplitude) / exact - 1))
    # measured: 6.9e-6 (n = 401) and 2.9e-7 (n = 2001) at ŷ = 2 mm — the O(h²) error of interpolating Δr linearly
    assert errors[1] < 1e-6
    assert 20 < errors[0] / errors[1] < 30  # (2000/400)² = 25


def _two_slope_table(lam1: float, lam2: float, y1: float) -> tuple[np.ndarray, np.ndarray]:
    """Odd piecewise-linear Δr: slope 2λ1 for |y| ≤ y1 (tread), 2λ2 beyond (flange root); kink on a node."""
    y = np.concatenate([np.linspace(-0.012, -y1, 50)[:-1], np.linspace(-y1, y1, 41), np.linspace(y1, 0.012, 50)[1:]])
    dr = np.where(np.abs(y) <= y1, 2 * lam1 * y, np.sign(y) * (2 * lam1 * y1 + 2 * lam2 * (np.abs(y) - y1)))
    return y, dr


@pytest.mark.parametrize("amplitude", [0.0045, 0.007, 0.011])
def test_two_slope_table_against_closed_form(amplitude: float) -> None:
    # piecewise harmonic motion, quarter cycle = time in the outer band + time in the inner band:
    # outer: centre yc = y1 − λ1 y1/λ2, ω2² = λ2/(e0 r0), x_out = arccos((y1 − yc)/(ŷ − yc))/ω2
    # inner: energy E = ω2²(ŷ − yc)²/2 − ω2²(y1 − yc)²/2 + ω1² y1²/2, amplitude A1 = √(2E)/ω1, x_in = arcsin(y1/A1)/ω1
    lam1, lam2, y1 = 0.04, 0.6, 0.004
    y, dr = _two_slope_table(lam1, lam2, y1)
    w1, w2 = math.sqrt(lam1 / (E0 * R0)), math.sqrt(lam2 / (E0 * R0))
    yc = y1 - lam1 * y1 / lam2
    x_out = math.acos((y1 - yc) / (amplitude - yc)) / w2
    energy = 0.5 * w2**2 * ((amplitude - yc) ** 2 - (y1 - yc) ** 2) + 0.5 * w1**2 * y1**2
    x_in = math.asin(y1 * w1 / math.sqrt(2 * energy)) / w1
    exact = _klingel(4 * (x_out + x_in))
    assert equivalent_conicity(y, dr, amplitude, r0=R0, e0=E0) == pytest.approx(exact, rel=1e-10)
    assert exact > lam1  # flange contact stiffens the pair


@pytest.mark.parametrize(
    "table",
    ["cubic-coarse", "two-slope", "asymmetric"],
)
def test_quadrature_agrees_with_time_integration(table: str) -> None:
    if table == "cubic-coarse":
        y = np.linspace(-0.01, 0.01, 41)
        dr = 0.1 * y + 600 * y**3
    elif table == "two-slope":
        y, dr = _two_slope_table(0.04, 0.6, 0.004)
    else:  # Δr with a quadratic (asymmetric) part: unequal turning points on one energy level
        y = np.linspace(-0.012, 0.012, 121)
        dr = 0.12 * y + 6.0 * y**2 + 400 * y**3
    amplitude = 0.0065
    lo, hi = turning_points(y, dr, amplitude)
    assert hi - lo == pytest.approx(2 * amplitude, rel=1e-12)
    L = kinematic_wavelength(y, dr, amplitude, r0=R0, e0=E0)
    L_ivp = _wavelength_by_time_integration(y, dr, hi)
    assert L == pytest.approx(L_ivp, rel=1e-6)
    assert equivalent_conicity(y, dr, amplitude, r0=R0, e0=E0) == pytest.approx(_klingel(L_ivp), rel=2e-6)


@pytest.mark.parametrize(
    ("y", "dr", "amplitude", "name"),
    [
        ([0.0, -0.001, 0.002], [0.0, -1e-4, 2e-4], 0.001, "y"),
        ([-0.01, 0.0, 0.01], [-1e-3, float("nan"), 1e-3], 0.001, "delta_r"),
        ([-0.01, 0.0, 0.01], [-1e-3, 0.0, 1e-3], 0.02, "amplitude"),
        ([-0.01, 0.0, 0.01], [-1e-3, 0.0, 1e-3], float("nan"), "amplitude"),
        ([-0.01, 0.0, 0.01], [-1e-3, 0.0, 1e-3], -0.001, "amplitude"),
        ([-0.01, 0.0, 0.01], [1e-3, 2e-3, 3e-3], 0.001, "delta_r"),
        ([-0.01, 0.0, 0.01], [-1e-3, 1e-3], 0.001, "delta_r"),
        ([-0.01, -0.005, 0.0, 0.005, 0.01], [-1e-3, 1e-3, -1e-4, 1e-3, 2e-3], 0.001, "delta_r"),
    ],
)
def test_bad_input_names_the_argument(y: list, dr: list, amplitude: float, name: str) -> None:
    with pytest.raises(ValueError, match=f"^{name}"):
        equivalent_conicity(np.array(y), np.array(dr), amplitude)


def test_linear_table_helper() -> None:
    y, dr = linear_delta_r_table(0.05, y_max=0.01, n=5)
    np.testing.assert_allclose(dr, 0.1 * y)
    assert y[0] == -0.01 and y[-1] == 0.01 and not y.flags.writeable
    with pytest.raises(ValueError, match="^conicity"):
        linear_delta_r_table(-0.1)
