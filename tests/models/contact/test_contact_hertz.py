"""Hertz ellipse (thesis (4.19)–(4.20)): closed forms, published Hertz tables, numerical Boussinesq check."""

from __future__ import annotations

import math

import pytest
from scipy.integrate import dblquad

from railopt.models.contact import hertz_coefficients, hertz_ellipse, wheel_rail_curvatures


def _ellipsoidal_load_integral(x0: float, y0: float, a: float, b: float, kernel_x: float = 0.0, kernel_y: float = 0.0):
    """∫∫ √(1 − x²/a² − y²/b²) k(θ)/ρ dA about the point (x0, y0), by brute-force 2-D quadrature.

    Polar coordinates centred on (x0, y0) make the 1/ρ kernel regular; k(θ) = 1 + kernel_x cos²θ + kernel_y sin²θ.
    """

    def reach(th: float) -> float:
        c, s = math.cos(th), math.sin(th)
        C = c * c / a**2 + s * s / b**2
        B = x0 * c / a**2 + y0 * s / b**2
        A = 1.0 - x0**2 / a**2 - y0**2 / b**2
        return (-B + math.sqrt(B * B + A * C)) / C

    def f(rho: float, th: float) -> float:
        x, y = x0 + rho * math.cos(th), y0 + rho * math.sin(th)
        q = max(0.0, 1.0 - x * x / a**2 - y * y / b**2)
        return math.sqrt(q) * (1.0 + kernel_x * math.cos(th) ** 2 + kernel_y * math.sin(th) ** 2)

    val, _ = dblquad(f, 0.0, 2.0 * math.pi, 0.0, reach, epsabs=0.0, epsrel=1e-11)
    return val


def test_sphere_on_plane_closed_form() -> None:
    # equal curvatures A = B = 1/(2R): a = b = (3 N R (1 − ν²) / (2E))^{1/3} (Hertz; sphere of radius R on a plane)
    N, E, nu, R = 1.0e5, 2.1e11, 0.3, 0.46
    h = hertz_ellipse(N, E, nu, 0.5 / R, 0.5 / R)
    a_exact = (3.0 * N * R * (1.0 - nu**2) / (2.0 * E)) ** (1.0 / 3.0)
    assert h.a == pytest.approx(a_exact, rel=1e-14) and h.b == pytest.approx(a_exact, rel=1e-14)
    assert (h.m, h.n) == (1.0, 1.0)
    assert h.p0 == pytest.approx(3 * N / (2 * math.pi * a_exact**2), rel=1e-13)


@pytest.mark.parametrize(
    ("tau_deg", "m_table", "n_table"),
    # Hertz's table as reproduced in Timoshenko & Goodier, Theory of Elasticity, §140 (cos τ = (B − A)/(A + B))
    [(30, 2.731, 0.493), (45, 1.926, 0.604), (60, 1.486, 0.717), (80, 1.128, 0.893), (90, 1.0, 1.0)],
)
def test_published_hertz_table(tau_deg: float, m_table: float, n_table: float) -> None:
    ct = math.cos(math.radians(tau_deg))
    m, n, _ = hertz_coefficients((1.0 - ct) / (1.0 + ct))
    assert m == pytest.approx(m_table, rel=1e-2) and n == pytest.approx(n_table, rel=1e-2)


def test_ellipse_reproduces_curvatures_by_boussinesq_integration() -> None:
    # independent check of the whole solution: the Hertz pressure p0 √(1 − x²/a² − y²/b²) on two identical
    # half-spaces (Boussinesq: w = (1 − ν²)/(πE) ∫∫ p/ρ dA each) must produce the quadratic gap A x² + B y²
    N, E, nu = 1.2e5, 2.1e11, 0.28
    A, B = wheel_rail_curvatures(0.46, 0.3, 0.45)  # worn tread
    h = hertz_ellipse(N, E, nu, A, B)
    scale = 2.0 * (1.0 - nu**2) / (math.pi * E) * h.p0
    w0 = scale * _ellipsoidal_load_integral(0.0, 0.0, h.a, h.b)
    wx = scale * _ellipsoidal_load_integral(0.5 * h.a, 0.0, h.a, h.b)
    wy = scale * _ellipsoidal_load_integral(0.0, 0.5 * h.b, h.a, h.b)
    assert (w0 - wx) / (0.5 * h.a) ** 2 == pytest.approx(A, rel=1e-7)
    assert (w0 - wy) / (0.5 * h.b) ** 2 == pytest.approx(B, rel=1e-7)
    assert A > B and h.b > h.a  # conformal worn tread: the major axis lies along the smaller (lateral) curvature


def test_axes_follow_the_smaller_curvature_and_scale_with_load() -> None:
    h1 = hertz_ellipse(1e5, 2.1e11, 0.3, 2.0, 0.5)
    h2 = hertz_ellipse(1e5, 2.1e11, 0.3, 0.5, 2.0)
    assert h1.a == pytest.approx(h2.b, rel=1e-14) and h1.b == pytest.approx(h2.a, rel=1e-14)
    h8 = hertz_ellipse(8e5, 2.1e11, 0.3, 2.0, 0.5)  # a, b ∝ N^{1/3}
    assert h8.a == pytest.approx(2.0 * h1.a, rel=1e-13) and h8.b == pytest.approx(2.0 * h1.b, rel=1e-13)


def test_wheel_rail_curvature_convention() -> None:
    A, B = wheel_rail_curvatures(0.5, 0.3)
    assert (A, B) == pytest.approx((1.0, 0.5 / 0.3))
    A, B = wheel_rail_curvatures(0.5, 0.3, 0.6)
    assert B == pytest.approx(0.5 * (1 / 0.3 - 1 / 0.6))


@pytest.mark.parametrize(
    ("args", "name"),
    [((-1.0, 2.1e11, 0.3, 1.0, 1.0), "N"), ((1e5, 2.1e11, 0.7, 1.0, 1.0), "nu"), ((1e5, 2.1e11, 0.3, 0.0, 1.0), "A")],
)
def test_bad_input(args: tuple[float, ...], name: str) -> None:
    with pytest.raises(ValueError, match=f"^{name}"):
        hertz_ellipse(*args)
    with pytest.raises(ValueError, match="^R_wheel_transverse"):
        wheel_rail_curvatures(0.5, 0.3, 0.2)
