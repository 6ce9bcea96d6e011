"""Shen–Hedrick–Elkins creep saturation: limits, the cubic's continuity, the Jacobian, and exact theory.

Independent references: the linear law (4.9) itself (written out here as −f ξ), the polynomial's own algebra
(value and slope at F' = 3μN), central finite differences for the Jacobian, invariants (odd, direction,
|T| ≤ μN, monotone), and Kalker's exact theory as computed by CONTACT (eve70a/CONTACT, examples/tractcurv.ref_out).
"""

from __future__ import annotations

import numpy as np
import pytest

from railopt.models.contact import CreepCoefficients, creep_coefficients
from railopt.models.contact.saturation import she_force_ratio, shen_hedrick_elkins, shen_hedrick_elkins_jacobian

G, NU = 8.2e10, 0.28
N, MU = 1.0e5, 0.3
COEF = creep_coefficients(6.0e-3, 4.0e-3, G, NU, theory="kalker")  # f11 ≈ 9.3e6 N, f23 ≈ 2e4 N·m


def _linear(c: CreepCoefficients, xx: np.ndarray, xy: np.ndarray, xs: np.ndarray) -> np.ndarray:
    """(4.9) written out: T'_x = −f11 ξx, T'_y = −f22 ξy − f23 ξsp, M'_z = −f32 ξy − f33 ξsp."""
    return np.array([-c.f11 * xx, -c.f22 * xy - c.f23 * xs, -c.f32 * xy - c.f33 * xs])


def _creepages(rng: np.random.Generator, n: int, scale: float) -> np.ndarray:
    return rng.normal(size=(3, n)) * np.array([[scale], [scale], [scale * 200.0]])  # spin in 1/m


# --------------------------------------------------------------------------------------------- the law's limits


def test_zero_creep_gives_zero_force() -> None:
    out = shen_hedrick_elkins(COEF, 0.0, 0.0, 0.0, N, MU)
    assert out.Tx == 0.0 and out.Ty == 0.0 and out.Mz == 0.0 and out.epsilon == 1.0


@pytest.mark.parametrize("r", [1e-8, 1e-5, 1e-3])
def test_small_creep_is_linear_to_first_order(r: float) -> None:
    # ε = 1 − r/3 + r²/27 exactly (the cubic divided by r): the relative departure from linear is r/3 + O(r²)
    direction = np.array([0.6, -0.8, 0.0])
    scale = r * MU * N / np.hypot(COEF.f11 * direction[0], COEF.f22 * direction[1])
    xi = direction * scale
    out = shen_hedrick_elkins(COEF, *xi, N, MU)
    lin = _linear(COEF, *xi)
    assert out.ratio == pytest.approx(r, rel=1e-12)
    for t, tl in zip((out.Tx, out.Ty, out.Mz), lin, strict=True):
        assert t / tl == pytest.approx(1.0 - r / 3.0 + r * r / 27.0, rel=1e-13)
        assert abs(t / tl - 1.0) <= r / 3.0 + 1e-15  # round-off of the ratio


@pytest.mark.parametrize("factor", [3.0, 3.0 + 1e-9, 10.0, 1e6])
def test_large_creep_saturates_at_mu_n(factor: float) -> None:
    xi = np.array([0.3, 0.4, 50.0])  # ξx, ξy, ξsp (1/m): a direction, scaled so that F'/(μN) = factor
    xi *= factor * MU * N / np.hypot(*_linear(COEF, *xi)[:2])
    out = shen_hedrick_elkins(COEF, *xi, N, MU)
    assert out.ratio == pytest.approx(factor, rel=1e-12)
    assert np.hypot(out.Tx, out.Ty) == pytest.approx(MU * N, rel=1e-12)


def test_cubic_is_continuous_with_zero_slope_at_three() -> None:
    # F/μN = 1 − (1 − r/3)³ (Vermeulen & Johnson's form): value 1 and slope (1 − r/3)² = 0 at r = 3
    for d in (1e-3, 1e-5, 1e-7):
        left, right = she_force_ratio(3.0 - d), she_force_ratio(3.0 + d)
        assert left == pytest.approx(1.0 - (d / 3.0) ** 3, abs=1e-15)
        assert right == 1.0
        slope_left = (she_force_ratio(3.0 - d) - she_force_ratio(3.0 - 2.0 * d)) / d
        assert abs(slope_left) <= 3.0 * (2.0 * d / 3.0) ** 2 + 1e-9  # → 0 quadratically
    r = np.linspace(0.0, 6.0, 6001)
    assert np.all(np.diff(she_force_ratio(r)) >= 0.0)  # monotone
    assert np.allclose(she_force_ratio(r[r <= 3]), 1.0 - (1.0 - r[r <= 3] / 3.0) ** 3, rtol=0, atol=1e-15)


def test_monotone_along_rays_and_bounded_by_mu_n() -> None:
    rng = np.random.default_rng(1)
    for d in rng.normal(size=(20, 3)):
        s = np.geomspace(1e-7, 1e-1, 400)
        xi = d[:, None] * s * np.array([[1.0], [1.0], [200.0]])
        out = shen_hedrick_elkins(COEF, *xi, N, MU)
        F = np.hypot(out.Tx, out.Ty)
        assert np.all(np.diff(F) >= -1e-9 * MU * N)
        assert np.all(F <= MU * N * (1 + 1e-14))


def test_odd_in_creepage_and_direction_of_linear_forces() -> None:
    rng = np.random.default_rng(2)
    xi = _creepages(rng, 500, 3e-3)
    pos, neg = shen_hedrick_elkins(COEF, *xi, N, MU), shen_hedrick_elkins(COEF, *(-xi), N, MU)
    for p, m in ((pos.Tx, neg.Tx), (pos.Ty, neg.Ty), (pos.Mz, neg.Mz)):
        np.testing.assert_array_equal(p, -m)
    lin = _linear(COEF, *xi)
    cross = pos.Tx * lin[1] - pos.Ty * lin[0]  # (T_x, T_y) parallel to (T'_x, T'_y), same sense
    assert np.max(np.abs(cross)) <= 1e-12 * np.max(np.abs(lin[:2])) ** 2
    assert np.all(pos.Tx * lin[0] + pos.Ty * lin[1] >= 0.0)


def test_spin_moment_options() -> None:
    xi = (1e-3, -2e-3, 0.4)
    scaled = shen_hedrick_elkins(COEF, *xi, N, MU)
    linear = shen_hedrick_elkins(COEF, *xi, N, MU, spin_moment="linear")
    mz = _linear(COEF, *xi)[2]
    assert linear.Mz == pytest.approx(mz, rel=1e-15)
    assert scaled.Mz == pytest.approx(scaled.epsilon * mz, rel=1e-15)
    assert scaled.Tx == linear.Tx and scaled.Ty == linear.Ty


def test_vectorised_over_contacts_and_a_sequence_of_coefficients() -> None:
    coefs = [COEF, COEF.scaled(0.5), creep_coefficients(4e-3, 7e-3, G, NU, theory="kalker")]
    xi = np.array([[1e-3], [-2e-3], [0.3]]) * np.array([1.0, 2.0, 3.0])  # (3, 3): one column per contact
    out = shen_hedrick_elkins(coefs, *xi, np.array([8e4, 9e4, 1e5]), 0.35)
    assert out.Tx.shape == (3,)
    for k, c in enumerate(coefs):
        single = shen_hedrick_elkins(c, *xi[:, k], [8e4, 9e4, 1e5][k], 0.35)
        assert (out.Tx[k], out.Ty[k], out.Mz[k]) == (single.Tx, single.Ty, single.Mz)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [({"N": 0.0}, "N:"), ({"mu": -0.1}, "mu:"), ({"xi_x": np.nan}, "xi_x:"), ({"xi_y": [1j]}, "xi_y:"),
     ({"spin_moment": "zero"}, "spin_moment:"), ({"coefficients": []}, "coefficients:"),
     ({"xi_x": [0.0, 1.0], "xi_y": [0.0, 1.0, 2.0]}, "broadcast")],
)
def test_bad_input_raises(kwargs: dict, match: str) -> None:
    args = {"coefficients": COEF, "xi_x": 0.0, "xi_y": 0.0, "xi_sp": 0.0, "N": N, "mu": MU} | kwargs
    with pytest.raises(ValueError, match=match):
        shen_hedrick_elkins(**args)


# ------------------------------------------------------------------------------------------------------ Jacobian


@pytest.mark.parametrize("spin_moment", ["scaled", "linear"])
def test_jacobian_at_zero_is_the_linear_law(spin_moment: str) -> None:
    for c in (COEF, creep_coefficients(4e-3, 7e-3, G, NU), CreepCoefficients(3e6, 2.5e6, 1e3, 5.0, 7e2)):
        J = shen_hedrick_elkins_jacobian(c, 0.0, 0.0, 0.0, N, MU, spin_moment=spin_moment)
        expected = -np.array([[c.f11, 0, 0], [0, c.f22, c.f23], [0, c.f32, c.f33]])
        np.testing.assert_array_equal(J, expected)  # exactly: ε(0) = 1 and the ε' term vanishes


@pytest.mark.parametrize("spin_moment", ["scaled", "linear"])
@pytest.mark.parametrize("scale", [2e-4, 1.5e-3, 2e-2])  # r ≈ 0.1, 1, 10: cubic branch and saturated branch
def test_jacobian_against_central_differences(spin_moment: str, scale: float) -> None:
    rng = np.random.default_rng(3)
    xi = _creepages(rng, 6, scale)
    J = shen_hedrick_elkins_jacobian(COEF, *xi, N, MU, spin_moment=spin_moment)
    assert J.shape == (6, 3, 3)
    for j in range(3):
        h = 1e-6 * np.max(np.abs(xi[j]))
        e = np.zeros((3, 1))
        e[j] = h
        up = shen_hedrick_elkins(COEF, *(xi + e), N, MU, spin_moment=spin_moment)
        dn = shen_hedrick_elkins(COEF, *(xi - e), N, MU, spin_moment=spin_moment)
        fd = np.array([(up.Tx - dn.Tx), (up.Ty - dn.Ty), (up.Mz - dn.Mz)]).T / (2 * h)  # (6, 3)
        np.testing.assert_allclose(J[:, :, j], fd, rtol=1e-6, atol=1e-6 * np.max(np.abs(J[:, :, j])))


# ------------------------------------------------------------------------------- against Kalker's exact theory


# CONTACT (Vollebregt & Kalker), examples/tractcurv.inp, first series (cases 1–11): Kalker's exact theory, Coulomb
# friction μ = 0.33, FN = 106.7 kN, G = 82 000 N/mm², ν = 0.28, Hertzian ellipse with semi-axes printed in
# tractcurv.ref_out "BASIC SEMIAXES AA,BB = 6.304, 12.61 mm" (a along rolling), pure longitudinal creepage CKSI;
# the columns below are CKSI and the printed "FX/FSTAT/FN" (sign dropped; CONTACT's FX is negative for positive
# CKSI as in creep.py's T = −f ξ).
EXACT_TRACTION_CURVE = [
    (1e-5, 0.007015), (4e-4, 0.2588), (8e-4, 0.4742), (1.2e-3, 0.6482), (1.6e-3, 0.7831), (2.0e-3, 0.8816),
    (2.4e-3, 0.9467), (2.8e-3, 0.9832), (3.2e-3, 0.9976), (3.6e-3, 0.9991), (4.0e-3, 0.9993),
]


def test_against_contact_exact_theory_pure_longitudinal() -> None:
    """The cubic is a heuristic fit, not exact theory.  Asserted: within 0.05 μN of Kalker's exact creep curve
    over the whole curve (measured: 0.038 μN at ξ = 2e-3, the knee, where the cubic saturates too slowly),
    and the sign convention (force opposite to creepage, as CONTACT's FX)."""
    a, b, fn, mu = 6.304e-3, 12.61e-3, 106.7e3, 0.33
    c = creep_coefficients(a, b, G, NU, theory="kalker")
    xi = np.array([p[0] for p in EXACT_TRACTION_CURVE])
    exact = np.array([p[1] for p in EXACT_TRACTION_CURVE])
    out = shen_hedrick_elkins(c, xi, 0.0, 0.0, fn, mu)
    assert np.all(out.Tx < 0.0)
    she = -out.Tx / (mu * fn)
    assert np.max(np.abs(she - exact)) <= 0.05
    assert she[0] == pytest.approx(exact[0], rel=0.02)  # initial slope: Kalker's C11 vs CONTACT's grid, 1.7 %
