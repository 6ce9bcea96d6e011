"""Analytic gradients of f_k (eigenvalue and FRF derivatives) against finite differences."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import base_excited_parametric

P0 = np.array([3.0, 0.15, 0.8])
BAND = (0.2, 3.0)


def central_difference(fun, p, rel=1e-6):
    cols = []
    for i in range(len(p)):
        h = rel * max(abs(p[i]), 1.0)
        dp = np.zeros_like(p)
        dp[i] = h
        cols.append((fun(p + dp) - fun(p - dp)) / (2 * h))
    return np.array(cols).T


def test_assembly_is_affine_in_parameters():
    ps = base_excited_parametric()
    a, b = ps.at(P0), ps.at(2 * P0)
    z = ps.at(np.zeros(3))
    np.testing.assert_allclose(b.K - a.K, a.K - z.K, atol=1e-14)
    np.testing.assert_allclose(b.C - a.C, a.C - z.C, atol=1e-14)


def test_damped_frequency_jacobian_matches_finite_differences():
    ps = base_excited_parametric()
    J = ps.damped_frequency_jacobian(P0)
    Jfd = central_difference(lambda p: ps.at(p).damped_frequencies(), P0)
    np.testing.assert_allclose(J, Jfd, rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize("exact", [False, True])
@pytest.mark.parametrize("p", [P0, np.array([1.0, 0.05, 2.0]), np.array([6.0, 0.6, 0.3])])
def test_response_maxima_jacobian_matches_finite_differences(exact, p):
    ps = base_excited_parametric()
    rm, J = ps.response_maxima_jacobian(p, band_rad_s=BAND, exact=exact)
    np.testing.assert_allclose(rm.values, ps.response_maxima(p, band_rad_s=BAND, exact=exact).values, rtol=1e-14)
    Jfd = central_difference(lambda q: ps.response_maxima(q, band_rad_s=BAND, exact=exact).values, p)
    scale = np.max(np.abs(Jfd))
    np.testing.assert_allclose(J, Jfd, rtol=2e-5, atol=2e-6 * scale)


def test_unknown_or_nan_parameters_are_rejected():
    ps = base_excited_parametric()
    with pytest.raises(ValueError, match="^p:"):
        ps.at([1.0, 2.0])
    with pytest.raises(ValueError, match="k_b"):
        ps.at([np.nan, 0.1, 0.1])
