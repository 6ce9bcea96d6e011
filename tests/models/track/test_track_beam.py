"""Beam constants, validation, Hetényi and the lumped track (SPEC §2.1, §5)."""

import math

import numpy as np
import pytest

from railopt.models.track import Beam, hetenyi_deflection, lumped, static_deflection, wooden_tie_track
from railopt.models.track.moving_load import characteristic_roots

EI, M, K = 7.59e6, 136.3, 2.068e7


def test_critical_values_follow_the_corrected_formulas():
    b = Beam(EI, M, K, N=3.0e6)
    assert b.buckling_load() == pytest.approx(2 * math.sqrt(K * EI), rel=1e-14)
    assert b.critical_velocity() == pytest.approx(math.sqrt((2 * math.sqrt(K * EI) - 3.0e6) / M), rel=1e-14)
    assert b.critical_damping == pytest.approx(2 * math.sqrt(K * M), rel=1e-14)
    # the transcript's (3.4) sqrt(4kEI/m² - N/m) is dimensionally different and much larger
    printed = math.sqrt(4 * K * EI / M**2 - 3.0e6 / M)
    assert printed / b.critical_velocity() > 10


def test_critical_velocity_is_where_two_characteristic_roots_merge_on_the_imaginary_axis():
    b = Beam(EI, M, K, N=-2.0e6)
    v_cr = b.critical_velocity()
    below = characteristic_roots(b, 0.999 * v_cr)
    above = characteristic_roots(b, 1.001 * v_cr)
    assert np.min(np.abs(below.real)) > 1e-3 * b.beta  # decaying: no free wave
    assert np.max(np.abs(above.real)) < 1e-6 * b.beta  # all four on the imaginary axis
    # minimum phase speed of free waves ω(κ)/κ of (3.3) equals v_cr
    kappa = np.linspace(0.05, 5, 200001) * b.beta
    phase = np.sqrt((EI * kappa**4 - b.N * kappa**2 + K) / M) / kappa
    assert phase.min() == pytest.approx(v_cr, rel=1e-8)


def test_hetenyi_matches_closed_form_static_and_ode_jump():
    b = Beam(EI, M, K)
    x = np.linspace(-8, 8, 161)
    assert np.allclose(static_deflection(b, x, 1e5), hetenyi_deflection(x, 1e5, K, EI), rtol=0, atol=1e-16)
    # total foundation reaction equals the load: ∫ k y dx = P
    xs = np.linspace(-40, 40, 400001)
    assert np.trapezoid(K * hetenyi_deflection(xs, 1e5, K, EI), xs) == pytest.approx(1e5, rel=1e-8)


def test_compression_increases_and_tension_decreases_static_deflection():
    y = [
        float(static_deflection(Beam.from_ratios(EI, M, K, axial_ratio=nu), 0.0, 1e5))
        for nu in (-0.5, 0, 0.5)
    ]
    assert y[0] < y[1] < y[2]
    # exact static value with axial force: y(0) = P/(π) ∫ dκ/(EIκ⁴ − Nκ² + k)
    from scipy.integrate import quad

    b = Beam.from_ratios(EI, M, K, axial_ratio=0.5)
    ref = (
        quad(lambda q: 1 / (EI * q**4 - b.N * q**2 + K), 0, np.inf, epsabs=0, epsrel=1e-12)[0] * 1e5 / math.pi
    )
    assert y[2] == pytest.approx(ref, rel=1e-10)


@pytest.mark.parametrize(
    ("field", "kwargs"),
    [
        ("EI", {"EI": 0.0}),
        ("m", {"m": -1.0}),
        ("k", {"k": float("nan")}),
        ("c", {"c": -1.0}),
        ("N", {"N": 2 * math.sqrt(K * EI)}),
        ("N", {"N": float("inf")}),
    ],
)
def test_bad_input_names_the_field(field, kwargs):
    params = {"EI": EI, "m": M, "k": K} | kwargs
    with pytest.raises(ValueError, match=rf"^{field}\b"):
        Beam(**params)


def test_lumped_equivalents():
    b = wooden_tie_track()
    lt = lumped(b, 0.1, contact_spacing=1.5)
    beta = (b.k / (4 * b.EI)) ** 0.25
    assert lt.K_e == pytest.approx(2 * b.k / beta)
    # K_e is P / y(0) of Hetényi's solution (4.37)
    assert lt.K_e == pytest.approx(1.0 / float(hetenyi_deflection(0.0, 1.0, b.k, b.EI)), rel=1e-12)
    assert lt.l_e == pytest.approx(2 / beta)
    assert lt.m_e == pytest.approx(b.m * 2 / beta)
    assert lt.f0 == pytest.approx(62.0, rel=1e-12)
    assert math.sqrt(lt.K_e / lt.m_e) / (2 * math.pi) == pytest.approx(math.sqrt(b.k / b.m) / (2 * math.pi))
    assert lt.C_e / (2 * math.sqrt(lt.K_e * lt.m_e)) == pytest.approx(0.1)
    # the distributed damping c gives the same ratio: C_e = c l_e
    bc = b.with_(c=0.1 * b.critical_damping)
    assert lumped(bc, bc.damping_ratio).C_e == pytest.approx(bc.c * 2 / beta)
    # roll: two rails at ±ℓ/2
    assert lt.roll_stiffness == pytest.approx(2 * lt.K_e_prime * 0.75**2)
    assert lt.roll_inertia == pytest.approx(0.25 * 1.5**2 * lt.m_e_pair)
    assert lt.K_e_pair == pytest.approx(2 * lt.K_e)
    with pytest.raises(ValueError, match="damping_ratio"):
        lumped(b, -0.1)
    with pytest.raises(ValueError, match="contact_spacing"):
        lumped(b, 0.1, contact_spacing=0.0)


def test_wooden_tie_track_parameters_give_thesis_f0():
    b = wooden_tie_track()
    assert b.f0 == pytest.approx(62.0)
    assert b.EI == pytest.approx(30e6 * 88.2 * 4.4482216152605 * 0.0254**2, rel=1e-12)
