"""Steady state under a moving load: closed form vs the independent Fourier integral (SPEC §5)."""

import itertools

import numpy as np
import pytest

from railopt.models.track import Beam, closed_form_solution, moving_load

EI, M, K, P = 7.59e6, 136.3, 2.068e7, 1.0e5


def _beam(zeta, nu):
    return Beam.from_ratios(EI, M, K, damping_ratio=zeta, axial_ratio=nu)


GRID = [
    (zeta, theta, nu)
    for zeta, theta, nu in itertools.product(
        [0.0, 0.05, 0.2, 0.5], [0.0, 0.3, 0.8, 1.0, 1.3, 2.0], [-0.6, 0.0, 0.6]
    )
    if not (zeta == 0.0 and theta >= 1.0)
]


@pytest.mark.parametrize(("zeta", "theta", "nu"), GRID)
def test_closed_form_equals_fourier_integral(zeta, theta, nu):
    b = _beam(zeta, nu)
    xi = np.linspace(-7, 7, 15) / b.beta * 1.3
    v = theta * b.critical_velocity()
    closed = moving_load(b, xi, P, v)
    fourier = moving_load(b, xi, P, v, method="fourier")
    scale = np.max(np.abs(closed.y))
    assert np.max(np.abs(closed.y - fourier.y)) / scale < 1e-6
    assert fourier.y_max == pytest.approx(closed.y_max, rel=1e-6)
    assert fourier.x_max == pytest.approx(closed.x_max, abs=1e-4 / b.beta)


@pytest.mark.parametrize(
    ("zeta", "theta", "nu"), [(0.0, 0.5, 0.3), (0.1, 0.7, -0.4), (0.3, 1.5, 0.2), (0.0, 1.4, 0.0)]
)
def test_closed_form_satisfies_the_ode_and_jump_conditions(zeta, theta, nu):
    b = _beam(zeta, nu)
    v = theta * b.critical_velocity()
    sol = closed_form_solution(b, P, v)
    xi = np.concatenate([np.linspace(-6, -0.01, 50), np.linspace(0.01, 6, 50)])
    d = [sol.evaluate(xi, n) for n in range(5)]
    residual = b.EI * d[4] + (b.N + b.m * v * v) * d[2] - b.c * v * d[1] + b.k * d[0]
    assert np.max(np.abs(residual)) < 1e-9 * b.k * np.max(np.abs(d[0]))
    eps = 1e-12
    for n in range(3):
        assert sol.evaluate(np.array([eps]), n)[0] == pytest.approx(
            sol.evaluate(np.array([-eps]), n)[0], rel=1e-8
        )
    jump = sol.evaluate(np.array([eps]), 3)[0] - sol.evaluate(np.array([-eps]), 3)[0]
    assert b.EI * jump == pytest.approx(P, rel=1e-8)


def test_undamped_profile_is_symmetric_and_damped_maximum_lags():
    xi = np.linspace(-5, 5, 201)
    v = 0.5 * _beam(0, 0).critical_velocity()
    b = _beam(0.0, 0.0)
    und = moving_load(b, xi, P, v)
    assert np.allclose(und.y, und.y[::-1], rtol=0, atol=1e-12 * und.y_max)
    # the value at the maximum is well-determined: (A.2.14) y(0) = P/(8 EI β² g), g = sqrt(β² − m v²/(4 EI))
    assert und.y_max == pytest.approx(P / (8 * b.EI * b.beta**2 * np.sqrt(b.beta**2 - b.m * v * v / (4 * b.EI))),
                                      rel=1e-12)
    # its location is the root of y' (slope y'' ≠ 0 there), so it is determined to ~ε of the length scale 1/β;
    # a search on values alone would place this flat maximum only to ~sqrt(ε)/β ≈ 1.6e-8 m
    assert abs(und.x_max) < 1e-9 / b.beta
    lags = [moving_load(_beam(z, 0.0), xi, P, v).x_max for z in (0.05, 0.1, 0.2, 0.4)]
    assert all(lag < 0 for lag in lags)  # behind the load
    assert all(b < a for a, b in zip(lags, lags[1:], strict=False))  # growing with damping
    ymax = [moving_load(_beam(z, 0.0), xi, P, v).y_max for z in (0.0, 0.1, 0.2)]
    assert ymax[0] > ymax[1] > ymax[2]


def _dominant_wavenumber(b, v):
    from railopt.models.track import characteristic_roots

    return np.max(np.abs(characteristic_roots(b, v).imag))


def test_compression_raises_maximum_and_wave_frequency_tension_lowers_them():
    v = 0.3 * _beam(0, 0).critical_velocity()
    results = {nu: moving_load(_beam(0.1, nu), np.array([0.0]), P, v) for nu in (-0.5, 0.0, 0.5)}
    assert results[-0.5].y_max < results[0.0].y_max < results[0.5].y_max
    waves = [_dominant_wavenumber(_beam(0.1, nu), v) for nu in (-0.5, 0.0, 0.5)]
    assert waves[0] < waves[1] < waves[2]


def test_velocity_effect_is_small_at_thesis_speeds():
    b = _beam(0.1, 0.0)
    static = moving_load(b, np.array([0.0]), P, 0.0).y_max
    fast = moving_load(b, np.array([0.0]), P, 67.0).y_max  # 150 mph
    assert 1.0 < fast / static < 1.02
    # undamped amplification below v_cr from the closed form (A.2.14): y(0) = P/(8 EI ω² g)
    bu = _beam(0.0, 0.0)
    for theta in (0.2, 0.6, 0.9):
        v = theta * bu.critical_velocity()
        omega = bu.beta
        alpha1 = np.sqrt(bu.m * v * v / (4 * bu.EI))
        g = np.sqrt(omega**2 - alpha1**2)
        ref = P / (8 * bu.EI * omega**2 * g)
        assert moving_load(bu, np.array([0.0]), P, v).y_max == pytest.approx(ref, rel=1e-10)


def test_resonance_and_supercritical_handling():
    b = _beam(0.0, 0.0)
    v_cr = b.critical_velocity()
    with pytest.raises(ValueError, match=r"^v = "):
        moving_load(b, np.array([0.0]), P, v_cr)
    with pytest.raises(ValueError, match="Fourier"):
        moving_load(b, np.array([0.0]), P, 1.2 * v_cr, method="fourier")
    with pytest.raises(ValueError, match="method"):
        moving_load(b, np.array([0.0]), P, 10.0, method="fft")
    with pytest.raises(ValueError, match=r"^v: must"):
        moving_load(b, np.array([0.0]), P, -1.0)
    # undamped supercritical branch = the limit c -> 0+ of the damped solution (radiation condition)
    xi = np.linspace(-6, 6, 41)
    und = moving_load(b, xi, P, 1.4 * v_cr)
    tiny = moving_load(b.with_(c=1e-7 * b.critical_damping), xi, P, 1.4 * v_cr)
    assert np.all(np.isfinite(und.y))
    assert np.max(np.abs(und.y - tiny.y)) < 1e-5 * np.max(np.abs(und.y))
