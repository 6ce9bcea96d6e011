"""Creep coefficients (thesis (4.9)–(4.32)): Vermeulen–Johnson, Kalker's Table E.3, Johnson's spin, Carter."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import dblquad, quad

from railopt.models.contact import (
    CreepCoefficients,
    carter_coefficient,
    creep_coefficients,
    kalker_coefficients,
    vermeulen_johnson_phi_psi,
)
from railopt.models.contact import kalker_table as kt

# ------------------------------------------------------------------------------------------------
# Vermeulen–Johnson Φ, Ψ1


def _vj_quadrature(a_over_b: float, nu: float) -> tuple[float, float]:
    """Φ, Ψ1 as the θ-integrals of the derivation, a²b ∫_0^{π/2} (kernel) sin²θ /(b²cos²θ + a²sin²θ)^{3/2} dθ."""
    a, b = a_over_b, 1.0

    def f(t: float, lateral: bool) -> float:
        s2, c2 = math.sin(t) ** 2, math.cos(t) ** 2
        kernel = 1.0 - nu + nu * (s2 if lateral else c2)
        return a * a * b * kernel * s2 / (b * b * c2 + a * a * s2) ** 1.5

    return tuple(quad(f, 0.0, 0.5 * math.pi, args=(lat,), epsabs=0.0, epsrel=1e-13)[0] for lat in (False, True))


@pytest.mark.parametrize("a_over_b", [0.12, 0.5, 0.97, 1.0, 1.03, 2.0, 8.0])
@pytest.mark.parametrize("nu", [0.0, 0.28, 0.5])
def test_vj_closed_form_equals_quadrature(a_over_b: float, nu: float) -> None:
    phi, psi = vermeulen_johnson_phi_psi(a_over_b, nu)
    q_phi, q_psi = _vj_quadrature(a_over_b, nu)
    assert phi == pytest.approx(q_phi, rel=1e-11) and psi == pytest.approx(q_psi, rel=1e-11)


@pytest.mark.parametrize("nu", [0.0, 0.25, 0.3, 0.5])
def test_vj_circle_matches_johnson_sphere(nu: float) -> None:
    # Johnson's circular-contact tangential displacement under q0 √(1 − r²/a²) (Contact Mechanics §7.2):
    # u_x = π q0 /(32 G a) [4(2 − ν) a² − (4 − 3ν) x² − (4 − ν) y²]  ⇒  Φ = π(4 − 3ν)/16, Ψ1 = π(4 − ν)/16
    phi, psi = vermeulen_johnson_phi_psi(1.0, nu)
    assert phi == pytest.approx(math.pi * (4 - 3 * nu) / 16, rel=1e-14)
    assert psi == pytest.approx(math.pi * (4 - nu) / 16, rel=1e-14)


def _cerruti_x2_coefficient(a: float, b: float, nu: float, lateral: bool) -> float:
    """Brute-force 2-D Cerruti integral: x² coefficient (× a G/q0) of the relative tangential displacement."""

    def integral(x0: float) -> float:
        def reach(th: float) -> float:
            c, s = math.cos(th), math.sin(th)
            C = c * c / a**2 + s * s / b**2
            B = x0 * c / a**2
            A = 1.0 - x0**2 / a**2
            return (-B + math.sqrt(B * B + A * C)) / C

        def f(rho: float, th: float) -> float:
            x, y = x0 + rho * math.cos(th), rho * math.sin(th)
            q = math.sqrt(max(0.0, 1.0 - x * x / a**2 - y * y / b**2))
            return q * (1.0 - nu + nu * (math.sin(th) if lateral else math.cos(th)) ** 2)

        return dblquad(f, 0.0, 2.0 * math.pi, 0.0, reach, epsabs=0.0, epsrel=1e-11)[0]

    x1 = 0.5 * a
    # relative displacement of two identical bodies = 2 × (1/(2πG)) ∫∫ q kernel/ρ dA
    return a * (integral(0.0) - integral(x1)) / (math.pi * x1**2)


@pytest.mark.parametrize("a_over_b", [0.6, 1.8])
def test_vj_phi_psi_against_brute_force_cerruti(a_over_b: float) -> None:
    # independent of the closed-form algebra: Φ (Ψ1) is the x²-coefficient of the relative longitudinal
    # (lateral) displacement under the ellipsoidal traction, in units q0/(G a)
    nu = 0.28
    phi, psi = vermeulen_johnson_phi_psi(a_over_b, nu)
    assert phi == pytest.approx(_cerruti_x2_coefficient(a_over_b, 1.0, nu, lateral=False), rel=1e-7)
    assert psi == pytest.approx(_cerruti_x2_coefficient(a_over_b, 1.0, nu, lateral=True), rel=1e-7)


@pytest.mark.parametrize(("nu", "col"), [(0.0, 0), (0.25, 1), (0.5, 2)])
def test_vj_against_kalker_at_circle(nu: float, col: int) -> None:
    # Measured: VJ/Kalker − 1 at a/b = 1 is +17.6 % / +17.6 % (ν = 0), +19.5 % / +16.3 % (ν = 0.25),
    # +23.1 % / +14.9 % (ν = 0.5) for f11 / f22: Vermeulen–Johnson's stick-ellipse model over-predicts
    # the small-creep slope (cf. Shen–Hedrick–Elkins 1983, who pair Kalker's slopes with VJ's saturation law).
    G, c = 8.0e10, 0.006
    vj = creep_coefficients(c, c, G, nu, "vermeulen-johnson")
    k = creep_coefficients(c, c, G, nu, "kalker")
    row = kt.A_OVER_B_LE_1[9]  # published table, a/b = 1
    assert k.f11 == pytest.approx(G * c * c * row[0, col], rel=1e-14)
    assert k.f22 == pytest.approx(G * c * c * row[1, col], rel=1e-14)
    assert vj.f11 == pytest.approx(16 * G * c * c / (4 - 3 * nu), rel=1e-13)  # Johnson's circle, (4.25)
    assert vj.f22 == pytest.approx(16 * G * c * c / (4 - nu), rel=1e-13)  # (4.26)
    for ratio in (vj.f11 / k.f11, vj.f22 / k.f22):
        assert 1.14 < ratio < 1.24


# ------------------------------------------------------------------------------------------------
# Kalker


def test_kalker_returns_table_nodes_exactly() -> None:
    for branch, table in ((False, kt.A_OVER_B_LE_1), (True, kt.B_OVER_A_LE_1)):
        for i, g in enumerate(kt.G_NODES):
            for j, nu in enumerate(kt.NU_NODES):
                r = 1.0 / g if branch else g
                np.testing.assert_allclose(kalker_coefficients(r, nu), table[i, :, j], rtol=1e-13)
    # the documented choice between CONTACT's two files
    assert kalker_coefficients(0.8, 0.25)[2] == pytest.approx(1.25, rel=1e-14)


def test_kalker_nu_interpolation_is_inverse_quadratic() -> None:
    # at ν = 0.3 between nodes: 1/C is the quadratic through the three nodes (CONTACT's linrol scheme)
    row = kt.A_OVER_B_LE_1[9]
    nus = np.array([0.0, 0.25, 0.5])
    for k in range(4):
        coef = np.polyfit(nus, 1.0 / row[k], 2)
        assert kalker_coefficients(1.0, 0.3)[k] == pytest.approx(1.0 / np.polyval(coef, 0.3), rel=1e-12)


@pytest.mark.parametrize(("col", "nu"), [(0, 0.0), (1, 0.25), (2, 0.5)])
def test_kalker_narrow_ellipse_limits(col: int, nu: float) -> None:
    # a/b → 0 (Kalker's asymptotes, as coded in CONTACT's linrol): C11 → π²/(4(1 − ν)), C22 → π²/4,
    # C23 → π√g/(3(1 − ν)) (1 + ν(ln(16/g) − 5)); strip theory (docs/contact.md): C33 → π²/(16(1 − ν) g)
    g = 0.1
    row = kt.A_OVER_B_LE_1[0]
    assert row[0, col] == pytest.approx(math.pi**2 / (4 * (1 - nu)), rel=0.03)
    assert row[1, col] == pytest.approx(math.pi**2 / 4, rel=0.03)
    c23 = math.pi * math.sqrt(g) / (3 * (1 - nu)) * (1 + nu * (math.log(16 / g) - 5))
    assert row[2, col] == pytest.approx(c23, rel=0.07)
    assert row[3, col] == pytest.approx(math.pi**2 / (16 * (1 - nu) * g), rel=0.06)


def test_kalker_invariants_and_monotonicity() -> None:
    ratios = np.concatenate([np.linspace(0.1, 1.0, 91), 1.0 / np.linspace(0.99, 0.1, 90)])
    for nu in (0.0, 0.25, 0.3, 0.5):
        C = np.array([kalker_coefficients(r, nu) for r in ratios])
        assert np.all(np.diff(C[:, 1:3], axis=0) > 0.0)  # C22, C23 grow with a/b
        # C11 too, except the table's own shallow dip at ν = 0.5 for a/b ≤ 0.3 (4.85, 4.81, 4.80)
        start = 20 if nu == 0.5 else 0
        assert np.all(np.diff(C[start:, 0]) > 0.0)
        if nu > 0.0:
            assert np.all(np.diff(C[:, 3]) < 0.0)  # C33 falls with a/b
    for i in range(10):  # ν = 0: C11 = C22 (longitudinal and lateral problems coincide)
        assert kt.A_OVER_B_LE_1[i, 0, 0] == kt.A_OVER_B_LE_1[i, 1, 0]
        assert kt.B_OVER_A_LE_1[i, 0, 0] == kt.B_OVER_A_LE_1[i, 1, 0]
    np.testing.assert_array_equal(kt.A_OVER_B_LE_1[9], kt.B_OVER_A_LE_1[9])  # both branches meet at a = b
    with pytest.raises(ValueError):
        kt.A_OVER_B_LE_1[0, 0, 0] = 1.0  # read-only data


def test_kalker_scaling_of_coefficients() -> None:
    a, b, G, nu = 0.007, 0.005, 8.1e10, 0.27
    C = kalker_coefficients(a / b, nu)
    cc = creep_coefficients(a, b, G, nu, "kalker", factor=0.6)
    assert cc.f11 == pytest.approx(0.6 * G * a * b * C[0], rel=1e-14)
    assert cc.f22 == pytest.approx(0.6 * G * a * b * C[1], rel=1e-14)
    assert cc.f23 == pytest.approx(0.6 * G * (a * b) ** 1.5 * C[2], rel=1e-14)
    assert cc.f33 == pytest.approx(0.6 * G * (a * b) ** 2 * C[3], rel=1e-14)
    assert cc.f32 == -cc.f23


# ------------------------------------------------------------------------------------------------
# Johnson's spin, Carter, data type


def test_johnson_spin_terms() -> None:
    a, b, G, nu = 0.006, 0.005, 8.0e10, 0.27
    cc = creep_coefficients(a, b, G, nu, "vermeulen-johnson")
    c = math.sqrt(a * b)
    assert cc.f33 == pytest.approx(32 / 9 * (2 - nu) / (3 - 2 * nu) * G * c**4, rel=1e-14)  # (4.29)
    assert cc.f23 == pytest.approx(0.469 * c * cc.f22, rel=1e-3)  # the thesis's rounded form of (4.32) (ν ≈ 0.27)
    assert cc.f32 == -cc.f23


def test_carter_units() -> None:
    # (4.10) in its own units: r0 = 20 in, N = 30 000 lbf  →  f = 3500 √(r0 N) lbf
    lbf, inch = 4.4482216152605, 0.0254
    f_lbf = 3500.0 * math.sqrt(20.0 * 30000.0)
    assert carter_coefficient(20 * inch, 30000 * lbf) == pytest.approx(f_lbf * lbf, rel=1e-14)
    cc = creep_coefficients(1.0, 1.0, 1.0, 0.3, "carter", factor=2.0, r0=20 * inch, N=30000 * lbf)
    assert cc.f11 == cc.f22 == pytest.approx(2 * f_lbf * lbf) and cc.f23 == cc.f33 == 0.0


def test_creep_coefficients_data_type() -> None:
    cc = CreepCoefficients(1e7, 9e6, 2e4, 50.0)
    assert cc.f32 == -2e4
    assert CreepCoefficients(1e7, 9e6, 2e4, 50.0, f32=1.0).f32 == 1.0
    # (4.9): T_x = −f11 ξx, T_y = −f22 ξy − f23 ξsp, M_z = −f32 ξy − f33 ξsp
    assert cc.forces(1e-3, 2e-3, 0.1) == pytest.approx((-1e4, -9e6 * 2e-3 - 2e4 * 0.1, 2e4 * 2e-3 - 50.0 * 0.1))
    s = cc.scaled(0.5)
    assert (s.f11, s.f22, s.f23, s.f33, s.f32) == (5e6, 4.5e6, 1e4, 25.0, -1e4)
    with pytest.raises(AttributeError):
        cc.f11 = 1.0  # type: ignore[misc]


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"theory": "polach"}, "theory"),
        ({"a": 0.0}, "a"),
        ({"nu": 0.6}, "nu"),
        ({"a": 0.05}, "a_over_b"),
        ({"theory": "carter"}, "r0, N"),
    ],
)
def test_bad_input(kwargs: dict, name: str) -> None:
    args = {"a": 0.004, "b": 0.004, "G": 8e10, "nu": 0.28, "theory": "kalker"} | kwargs
    with pytest.raises(ValueError, match=f"^{name}"):
        creep_coefficients(**args)
    with pytest.raises(ValueError, match="^f11"):
        CreepCoefficients(float("nan"), 1.0)
