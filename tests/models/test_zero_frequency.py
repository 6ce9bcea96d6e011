"""A band from 0 Hz on a system with free rigid-body motion (Z(0) singular): the limit Ω → 0 where it exists,
a refusal naming the band where the output is truly unbounded (issue 16 item 3; SPEC §2.4)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from railopt.models import LinearSystem
from railopt.models.vehicle import Irregularity

HZ = 2 * np.pi


def free_masses(m1: float, m2: float, k: float, c: float, response: str) -> LinearSystem:
    """Two masses joined by a spring and a damper, nothing to ground; force on mass 1, output of mass 2."""
    return LinearSystem(np.diag([m1, m2]), np.array([[c, -c], [-c, c]]), np.array([[k, -k], [-k, k]]),
                        [1.0, 0.0], output=[0.0, 1.0], response=response)


def closed_form(w: np.ndarray, m1: float, m2: float, k: float, c: float) -> np.ndarray:
    """|a2/F| by Cramer's rule: −Ω² kc / ((kc − Ω²m1)(kc − Ω²m2) − kc²), kc = k + iΩc."""
    kc = k + 1j * w * c
    return np.abs(-(w**2) * kc / ((kc - w**2 * m1) * (kc - w**2 * m2) - kc**2))


@pytest.mark.parametrize(("m1", "m2", "k", "c"), [(2.0, 1.0, 100.0, 0.4), (5.0, 0.5, 3e3, 2.0), (1.0, 1.0, 10.0, 1.0)])
def test_acceleration_of_free_masses_from_zero_hz_is_the_closed_form(m1, m2, k, c) -> None:
    system = free_masses(m1, m2, k, c, "acceleration")
    band = (0.0, 3.0 * np.sqrt(k * (m1 + m2) / (m1 * m2)))
    grid = np.linspace(1e-3, band[1], 20001)
    i = int(np.argmax(closed_form(grid, m1, m2, k, c)))
    best = minimize_scalar(lambda w: -closed_form(np.array([w]), m1, m2, k, c)[0],
                           bounds=(grid[max(i - 1, 0)], grid[i + 1]), method="bounded", options={"xatol": 1e-12})
    reference = max(-best.fun, 1.0 / (m1 + m2))
    rm = system.response_maxima(band_rad_s=band, exact=True)
    assert rm.value == pytest.approx(reference, rel=1e-9)
    assert rm.certified and rm.reason == ""
    # the lower edge is the limit Ω → 0: the whole vehicle accelerates as one mass, 1/(m1 + m2)
    assert rm.values[-2] == pytest.approx(1.0 / (m1 + m2), rel=1e-7)
    assert rm.frequencies[-2] == 0.0
    thesis = system.response_maxima(band_rad_s=band, exact=False)
    assert np.all(np.isfinite(thesis.values)) and thesis.values[-2] == pytest.approx(1.0 / (m1 + m2), rel=1e-7)


def test_an_output_unbounded_at_zero_hz_is_refused_naming_the_band() -> None:
    system = free_masses(2.0, 1.0, 100.0, 0.4, "displacement")
    with pytest.raises(ValueError, match=r"^band: starts at 0 Hz, where the output\(s\) \['output'\] are unbounded"):
        system.response_maxima(band_rad_s=(0.0, 10.0), exact=True)
    with pytest.raises(ValueError, match="^band: starts at 0 Hz"):
        system.peak(band_rad_s=(0.0, 10.0), exact=False)
    assert np.isfinite(system.peak(band_rad_s=(0.1, 10.0)))  # above 0 it is an ordinary band


def test_locomotive_vertical_acceleration_from_zero_hz_equals_a_dense_sweep(sd40) -> None:
    """The vertical view has seven free rigid-body roots (fore-aft translation, six wheelset pitches)."""
    system = sd40.vertical("rigid", speed=30.0).forced_system(Irregularity("vertical", amplitude_m=0.00635),
                                                             ["body.w"], quantity="acceleration")
    assert np.sum(np.abs(system.eigenvalues()) < 1e-6) >= 7
    w = np.linspace(1e-3, 8 * HZ, 40001)
    dense = np.abs(system.frf(omega_rad_s=w))
    i = int(np.argmax(dense))
    best = minimize_scalar(lambda x: -abs(system.frf(omega_rad_s=x)), bounds=(w[i - 1], w[i + 1]), method="bounded",
                           options={"xatol": 1e-10})
    rm = system.response_maxima(band_rad_s=(0.0, 8 * HZ), exact=True)
    assert rm.value == pytest.approx(-best.fun, rel=1e-9)
    assert rm.value == pytest.approx(11.87859, rel=1e-6)  # the fault report's dense sweep
    assert rm.argmax_frequency / HZ == pytest.approx(2.304, abs=1e-3)
