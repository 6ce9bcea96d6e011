"""One frequency convention at the public API (issue 15 finding 6): bands and frequencies are named with their
unit (``band_hz=``/``band_rad_s=``, ``frequencies_hz=``/``omega_rad_s=``); a positional one is refused, so the
13×-low answer of a Hz band read as rad/s cannot happen silently."""

from __future__ import annotations

import numpy as np
import pytest

from railopt.models import peak, response_maxima
from railopt.models.sensitivity import maxima_jacobians
from railopt.models.vehicle import Irregularity

from conftest import base_excited_parametric

HZ = 2 * np.pi


@pytest.fixture(scope="module")
def coach_cab(coach):
    return coach.lateral("rigid", 40.0).forced_system(Irregularity("alignment", amplitude_m=0.001), ["cab.lateral"],
                                                      quantity="acceleration")


def test_band_in_hz_equals_the_same_band_in_rad_s(coach_cab) -> None:
    hz = coach_cab.peak(band_hz=(0.2, 5.0))
    rad = coach_cab.peak(band_rad_s=(0.2 * HZ, 5.0 * HZ))
    assert hz == rad
    slip = coach_cab.peak(band_rad_s=(0.2, 5.0))  # the slip of the report: Hz numbers read as rad/s
    assert slip < hz / 5  # a different answer entirely — which is why the unit must be named
    for exact in (False, True):
        a = response_maxima(coach_cab, band_hz=(0.2, 5.0), exact=exact)
        b = response_maxima(coach_cab, band_rad_s=(0.2 * HZ, 5.0 * HZ), exact=exact)
        assert a == b


def test_a_positional_band_or_frequency_is_refused(coach_cab) -> None:
    for call in (lambda: coach_cab.peak((0.2, 5.0)), lambda: peak(coach_cab, (0.2, 5.0)),
                 lambda: coach_cab.response_maxima((0.2, 5.0), exact=True),
                 lambda: response_maxima(coach_cab, (0.2, 5.0))):
        with pytest.raises(ValueError, match=r"^band: a positional band is ambiguous \(Hz or rad/s\?\)"):
            call()
    with pytest.raises(ValueError, match="^omega: a positional frequency is ambiguous"):
        coach_cab.frf(1.0)
    with pytest.raises(ValueError, match="^band_hz: give exactly one"):
        coach_cab.peak(band_hz=(0.2, 5.0), band_rad_s=(1.0, 30.0))
    with pytest.raises(ValueError, match="^band_hz: give exactly one"):
        coach_cab.peak()
    with pytest.raises(ValueError, match=r"^band_hz: must be a pair \(lower, upper\) in Hz"):
        coach_cab.peak(band_hz=5.0)


def test_frequencies_in_hz_equal_the_same_in_rad_s(coach_cab) -> None:
    f = np.array([0.3, 1.0, 2.5])
    assert np.array_equal(coach_cab.frf(frequencies_hz=f), coach_cab.frf(omega_rad_s=HZ * f))
    assert coach_cab.frf(frequencies_hz=1.0) == coach_cab.frf(omega_rad_s=HZ)


def test_gradients_take_the_band_in_either_unit() -> None:
    ps = base_excited_parametric()
    sys = ps.at([1.0, 0.1, 0.5])
    (rm_hz, J_hz), = maxima_jacobians(sys, band_hz=(0.05, 0.5), exact=True).values()
    (rm_rad, J_rad), = maxima_jacobians(sys, band_rad_s=(0.05 * HZ, 0.5 * HZ), exact=True).values()
    assert rm_hz == rm_rad and np.array_equal(J_hz, J_rad)
