"""Response maxima (4.71)-(4.73): exact option vs brute force, invariants of the thesis method."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from railopt.models import LinearSystem

from conftest import random_system


def brute_force_peak(sys: LinearSystem, band, points=400_001) -> float:
    """Independent: a uniform 400k-point sweep, every local maximum refined by Brent."""
    w = np.linspace(*band, points)
    a = np.abs(sys.frf(omega_rad_s=w))
    best = max(a[0], a[-1])
    idx = np.flatnonzero((a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:])) + 1
    for k in idx:
        r = minimize_scalar(lambda x: -abs(sys.frf(omega_rad_s=x)), bounds=(w[k - 1], w[k + 1]), method="bounded",
                            options={"xatol": 1e-14})
        best = max(best, -r.fun, a[k])
    return float(best)


@pytest.mark.parametrize("seed", range(6))
def test_exact_band_maximum_equals_brute_force(seed):
    sys = random_system(4, seed, damping=0.01)
    band = (0.05, 1.1 * sys.damped_frequencies().max())
    rm = sys.response_maxima(band_rad_s=band, exact=True)
    assert rm.certified
    assert rm.value == pytest.approx(brute_force_peak(sys, band), rel=1e-10)


@pytest.mark.parametrize("seed", range(6))
def test_thesis_values_never_exceed_exact_cell_maxima(seed):
    sys = random_system(4, seed, damping=0.05)
    band = (0.1, 2.0)
    thesis = sys.response_maxima(band_rad_s=band)
    exact = sys.response_maxima(band_rad_s=band, exact=True)
    assert np.all(thesis.values <= exact.values * (1 + 1e-12))
    np.testing.assert_allclose(thesis.values[-2:], exact.values[-2:], rtol=0)  # edges identical


def test_count_is_n_plus_two_and_clipped_modes_take_edge_values():
    sys = random_system(4, 7)
    wd = sys.damped_frequencies()
    band = (0.5 * (wd[0] + wd[1]), 0.5 * (wd[2] + wd[3]))  # modes 1 and 4 outside the band
    rm = sys.response_maxima(band_rad_s=band)
    assert rm.values.shape == (6,)
    assert rm.values[0] == rm.values[4] == pytest.approx(abs(sys.frf(omega_rad_s=band[0])))  # clipped to Ω_l
    assert rm.values[3] == rm.values[5] == pytest.approx(abs(sys.frf(omega_rad_s=band[1])))  # clipped to Ω_u
    assert rm.values[1] == pytest.approx(abs(sys.frf(omega_rad_s=wd[1])))


def test_lightly_damped_sdof_peak_closed_form():
    """SDOF displacement peak 1/(2ζ sqrt(1−ζ²)) / k at Ω = ωn sqrt(1 − 2ζ²)."""
    m, k, zeta = 1.0, 100.0, 0.002
    c = 2 * zeta * np.sqrt(k * m)
    sys = LinearSystem([[m]], [[c]], [[k]], [1.0], [k])
    rm = sys.response_maxima(band_rad_s=(0.0, 20.0), exact=True)
    assert rm.value == pytest.approx(1 / (2 * zeta * np.sqrt(1 - zeta**2)), rel=1e-10)
    # a flat maximum located on values: to Brent's bound 2·sqrt(ε)|Ω| ≈ 3e-8 relative at best, so 1e-7 (its scale,
    # the half-power width 2ζΩ = 0.04 rad/s, is 4e4 times the 1e-6 rad/s allowed); the value is the well-determined one
    assert rm.argmax_frequency == pytest.approx(10 * np.sqrt(1 - 2 * zeta**2), rel=1e-7)
    # thesis method: value at ω_d = ωn sqrt(1−ζ²), closed form 1/(ζ sqrt(4 − 3ζ²))
    thesis = sys.response_maxima(band_rad_s=(0.0, 20.0)).value
    assert thesis == pytest.approx(1 / (zeta * np.sqrt(4 - 3 * zeta**2)), rel=1e-10)


def test_overdamped_mode_contributes_value_at_lower_edge():
    M, K, C = np.diag([1.0, 1.0]), np.diag([1.0, 100.0]), np.diag([0.1, 1000.0])
    sys = LinearSystem(M, C, K, [1.0, 1.0], [0.0, 1.0])
    rm = sys.response_maxima(band_rad_s=(0.2, 3.0))
    assert rm.frequencies[0] == 0.2
    assert rm.values[0] == pytest.approx(abs(sys.frf(omega_rad_s=0.2)))


@pytest.mark.parametrize("band", [(2.0, 1.0), (1.0, 1.0), (-1.0, 2.0), (0.0, np.inf), (np.nan, 1.0)])
def test_bad_band_is_rejected_naming_the_field(chain3, band):
    with pytest.raises(ValueError, match="^band_rad_s:"):
        chain3.response_maxima(band_rad_s=band)
    with pytest.raises(ValueError, match="^band_hz:"):
        chain3.response_maxima(band_hz=band)


def test_exact_option_grid_is_logarithmic_in_damping():
    """The certified grid grows like log(1/ζ), not 1/ζ: 1000× less damping, < 3× the points."""
    from railopt.models.response_maxima import band_grid

    counts = []
    for zeta in (1e-2, 1e-5):
        sys = LinearSystem([[1.0]], [[2 * zeta]], [[1.0]], [1.0], [1.0])
        counts.append(len(band_grid(sys.eigenvalues(), (0.0, 3.0))[0]))
    assert counts[1] < 3 * counts[0]
