"""TMD model against Den Hartog's textbook FRF and the Nishihara-Asami closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

from railopt.models.tmd import (
    amplification,
    den_hartog,
    den_hartog_fixed_point_height,
    nishihara_asami,
    peak_amplification,
    tmd_parameters,
    tmd_system,
)


@pytest.mark.parametrize("mu", [0.02, 0.05, 0.1, 0.25])
def test_model_frf_equals_textbook_two_dof_formula(mu):
    m1, k1 = 1000.0, 1000.0 * (2 * np.pi * 2.0) ** 2
    w1 = np.sqrt(k1 / m1)
    gam, z = 0.93, 0.11
    p, _ = tmd_parameters(gam, z, mu, m1, k1)
    g = np.linspace(0.01, 2.0, 300)
    np.testing.assert_allclose(np.abs(tmd_system(mu, m1, k1).at(p).frf(omega_rad_s=g * w1)),
                               amplification(g, gam, z, mu), rtol=1e-11)


def test_parameter_map_jacobian_matches_finite_differences():
    x = np.array([0.9, 0.12])
    _, J = tmd_parameters(*x, 0.05, 3.0, 70.0)
    h = 1e-7
    fd = np.column_stack([(tmd_parameters(*(x + h * e), 0.05, 3.0, 70.0)[0] - tmd_parameters(*(x - h * e), 0.05, 3.0,
                          70.0)[0]) / (2 * h) for e in np.eye(2)])
    np.testing.assert_allclose(J, fd, rtol=1e-8)


@pytest.mark.parametrize("mu", [0.05, 0.1])
def test_nishihara_asami_closed_form_is_the_numerical_hinf_optimum(mu):
    """Independent check of the published formulas: Nelder-Mead on the textbook peak."""
    na = nishihara_asami(mu)
    res = minimize(lambda x: peak_amplification(x[0], x[1], mu), [1 / (1 + mu), np.sqrt(3 * mu / 8)],
                   method="Nelder-Mead", options={"xatol": 1e-10, "fatol": 1e-13, "maxiter": 4000})
    assert res.x[0] == pytest.approx(na.tuning, abs=1e-6)
    assert res.x[1] == pytest.approx(na.damping_ratio, abs=1e-5)
    assert res.fun == pytest.approx(na.peak, rel=1e-11)


def test_den_hartog_fixed_point_height_and_near_optimality():
    for mu in (0.05, 0.1):
        dh, na = den_hartog(mu), nishihara_asami(mu)
        assert den_hartog_fixed_point_height(mu) == pytest.approx(np.sqrt(1 + 2 / mu))
        # the true peak of the fixed-point design lies above the fixed points and above the H∞ optimum
        assert dh.peak > den_hartog_fixed_point_height(mu)
        assert na.peak < dh.peak < 1.001 * na.peak


@pytest.mark.parametrize("field,args", [("mass_ratio", (0.0,)), ("primary_mass", (0.1, -1.0)),
                                        ("primary_stiffness", (0.1, 1.0, np.nan))])
def test_bad_tmd_inputs_name_the_field(field, args):
    with pytest.raises(ValueError, match=f"^{field}:"):
        tmd_system(*args)
