"""LinearSystem against closed forms: SDOF roots, base-excited transmissibility, residuals."""

from __future__ import annotations

import numpy as np
import pytest

from railopt.models import LinearSystem

from conftest import random_system


def sdof(m=2.0, k=800.0, zeta=0.05):
    c = 2 * zeta * np.sqrt(k * m)
    return m, c, k


def test_sdof_roots_match_closed_form():
    m, c, k = sdof()
    wn, zeta = np.sqrt(k / m), c / (2 * np.sqrt(k * m))
    s = LinearSystem([[m]], [[c]], [[k]], [1.0], [1.0]).eigenvalues()
    expected = -zeta * wn + 1j * wn * np.sqrt(1 - zeta**2) * np.array([-1, 1])
    np.testing.assert_allclose(np.sort_complex(s), np.sort_complex(expected), rtol=1e-12)


def test_base_excited_sdof_transmissibility_closed_form():
    """x'' m + c(x' − y') + k(x − y) = 0: |X/Y| = sqrt((1+(2ζr)²)/((1−r²)²+(2ζr)²))."""
    m, c, k = sdof(zeta=0.1)
    wn, zeta = np.sqrt(k / m), 0.1
    sys = LinearSystem([[m]], [[c]], [[k]], lambda w: np.array([k + 1j * w * c]), [1.0])
    w = np.linspace(0.0, 3 * wn, 301)
    r = w / wn
    closed = np.sqrt((1 + (2 * zeta * r) ** 2) / ((1 - r**2) ** 2 + (2 * zeta * r) ** 2))
    np.testing.assert_allclose(np.abs(sys.frf(omega_rad_s=w)), closed, rtol=1e-12)
    assert abs(sys.frf(omega_rad_s=0.0)) == pytest.approx(1.0, abs=1e-15)  # static transmissibility 1


def test_acceleration_is_minus_omega_squared_displacement(chain3):
    w = np.linspace(0.1, 5.0, 50)
    acc = LinearSystem(chain3.M, chain3.C, chain3.K, chain3.forcing, chain3.output, response="acceleration")
    vel = LinearSystem(chain3.M, chain3.C, chain3.K, chain3.forcing, chain3.output, response="velocity")
    np.testing.assert_allclose(acc.frf(omega_rad_s=w), -(w**2) * chain3.frf(omega_rad_s=w), rtol=1e-12)
    np.testing.assert_allclose(vel.frf(omega_rad_s=w), 1j * w * chain3.frf(omega_rad_s=w), rtol=1e-12)


@pytest.mark.parametrize("seed", range(5))
def test_residual_of_impedance_solve(seed):
    sys = random_system(6, seed)
    for w in (0.0, 0.37, 1.3, 4.0):
        X = sys.solve(w)
        F = sys.forcing.value(w)
        assert np.linalg.norm(sys.impedance(w) @ X - F) <= 1e-12 * np.linalg.norm(F) * np.linalg.cond(sys.impedance(w))


def test_batched_frf_equals_pointwise(chain3):
    w = np.linspace(0.0, 4.0, 37)
    np.testing.assert_allclose(chain3.frf(omega_rad_s=w), [chain3.frf(omega_rad_s=float(x)) for x in w], rtol=1e-13)


def test_state_matrix_eigenvalues_are_roots_of_quadratic_problem(chain3):
    """det(s²M + sC + K) = 0 at every root of G (4.57)."""
    for s in chain3.eigenvalues():
        Q = s**2 * chain3.M + s * chain3.C + chain3.K
        smin = np.linalg.svd(Q, compute_uv=False)[-1]
        assert smin <= 1e-10 * np.linalg.norm(Q)


def test_damped_frequencies_count_is_n_with_overdamped_modes():
    """Two masses, one heavily overdamped: n = 2 frequencies, the overdamped one 0."""
    M = np.diag([1.0, 1.0])
    K = np.diag([1.0, 100.0])
    C = np.diag([0.02, 1000.0])
    sys = LinearSystem(M, C, K, [1.0, 0.0], [1.0, 0.0])
    wd = sys.damped_frequencies()
    assert wd.shape == (2,)
    assert wd[0] == 0.0
    assert wd[1] == pytest.approx(np.sqrt(1 - 0.01**2), rel=1e-12)


def test_undamped_resonance_gives_inf_not_nan():
    sys = LinearSystem([[1.0]], [[0.0]], [[4.0]], [1.0], [1.0])
    assert sys.frf(omega_rad_s=2.0) == np.inf
    assert np.isinf(sys.response_maxima(band_rad_s=(0.0, 3.0)).value)
    assert np.isinf(sys.response_maxima(band_rad_s=(0.0, 3.0), exact=True).value)


@pytest.mark.parametrize("field", ["M", "C", "K"])
def test_nan_matrix_is_rejected_naming_the_field(field):
    mats = {"M": np.eye(2), "C": np.eye(2), "K": np.eye(2)}
    mats[field] = mats[field].copy()
    mats[field][0, 1] = np.nan
    with pytest.raises(ValueError, match=f"^{field}:"):
        LinearSystem(mats["M"], mats["C"], mats["K"], [1.0, 0.0], [1.0, 0.0])


def test_bad_shapes_and_response_are_rejected():
    with pytest.raises(ValueError, match="^output:"):
        LinearSystem(np.eye(2), np.eye(2), np.eye(2), [1.0, 0.0], [1.0])
    with pytest.raises(ValueError, match="^response:"):
        LinearSystem(np.eye(2), np.eye(2), np.eye(2), [1.0, 0.0], [1.0, 0.0], response="jerk")
    with pytest.raises(ValueError, match="^M:"):
        LinearSystem(np.zeros((2, 2)), np.eye(2), np.eye(2), [1.0, 0.0], [1.0, 0.0])


@pytest.mark.parametrize("field", ["M", "C", "K"])
def test_complex_matrix_is_an_error_not_a_dropped_imaginary_part(field):
    mats = {"M": np.eye(2), "C": np.eye(2), "K": np.eye(2)}
    mats[field] = mats[field] + 1e-3j
    with pytest.raises(ValueError, match=f"^{field}: must be real"):
        LinearSystem(mats["M"], mats["C"], mats["K"], [1.0, 0.0], [1.0, 0.0])


def test_empty_system_complex_output_and_band_of_three_name_the_field():
    with pytest.raises(ValueError, match="^M: must be a non-empty square matrix"):
        LinearSystem(np.zeros((0, 0)), np.zeros((0, 0)), np.zeros((0, 0)), [], [])
    with pytest.raises(ValueError, match="^output: must be real"):
        LinearSystem(np.eye(2), np.eye(2), np.eye(2), [1.0, 0.0], [1.0 + 1j, 0.0])
    sys = LinearSystem([[1.0]], [[0.1]], [[1.0]], [1.0], [1.0])
    with pytest.raises(ValueError, match=r"^band_rad_s: must be a pair \(lower, upper\) in rad/s"):
        sys.response_maxima(band_rad_s=(0.0, 1.0, 2.0))


def test_numpy_scalars_are_accepted_where_numbers_are():
    sys = LinearSystem([[1.0]], [[0.1]], [[1.0]], [1.0], [1.0])
    a = sys.response_maxima(band_rad_s=(np.float32(0.0), np.int64(2)), exact=True)
    b = sys.response_maxima(band_rad_s=(0.0, 2.0), exact=True)
    assert a == b
