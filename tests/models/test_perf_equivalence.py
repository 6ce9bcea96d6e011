"""The optimised response maxima against straightforward references (issue 18: identical results to 1e-10).

The certified band maximum is compared with a dense direct-solve sweep whose local maxima are refined by scipy's
bounded minimisation; the thesis values with direct solves at the clipped damped frequencies; the affine member
matrices with a plain sum; random systems with and without delays, n = 3..27, and the cab / full lateral models.
"""

from __future__ import annotations

from math import pi

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from railopt.models import LinearSystem, ParametricSystem
from railopt.models.forcing import DelayedTerm, Forcing
from railopt.models.parametric import ParameterPart, affine

RTOL = 1e-10


def stable_system(n: int, seed: int, delays: bool) -> LinearSystem:
    """A lightly damped non-symmetric n-DOF chain (stable); with ``delays``, a base input through two delayed
    contact points (coefficients of (iΩ)^0 and (iΩ)^1, as an axle input).  Outputs: a displacement and an
    acceleration row."""
    rng = np.random.default_rng(seed)
    M = np.diag(rng.uniform(0.5, 2.0, n))
    k = rng.uniform(0.5, 3.0, n)
    K = np.diag(k + np.r_[k[1:], 0.0]) - np.diag(k[1:], 1) - np.diag(k[1:], -1)
    K += (0.02 / n) * (rng.standard_normal((n, n)) - rng.standard_normal((n, n)).T)
    C = 0.02 * (np.diag(k + np.r_[k[1:], 0.0]) - np.diag(k[1:], 1) - np.diag(k[1:], -1)) + 0.01 * np.eye(n)
    if delays:
        terms = [DelayedTerm(tau, coefficients=np.array([rng.standard_normal(n), 0.1 * rng.standard_normal(n)],
                                                        dtype=complex)) for tau in (0.0, 0.7, 1.9)]
        F = Forcing(terms=terms)
    else:
        F = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    outputs = {"disp": (rng.standard_normal(n), "displacement"), "acc": (rng.standard_normal(n), "acceleration")}
    sys = LinearSystem(M, C, K, F, outputs=outputs)
    assert sys.is_stable()
    return sys


def reference_peak(sys: LinearSystem, band, output: str, points: int = 40_001) -> float:
    """Dense direct-solve sweep (with the damped frequencies added), each local maximum refined by scipy's bounded
    minimisation between its neighbours."""
    w = np.unique(np.concatenate([np.linspace(*band, points), np.clip(sys.damped_frequencies(), *band)]))
    a = np.abs(sys.frf(omega_rad_s=w, output=output))
    best = max(a[0], a[-1])
    idx = np.flatnonzero((a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:])) + 1
    for k in idx:
        r = minimize_scalar(lambda x: -abs(sys.frf(omega_rad_s=x, output=output)), bounds=(w[k - 1], w[k + 1]),
                            method="bounded", options={"xatol": 1e-13 * max(1.0, w[k])})
        best = max(best, -r.fun, a[k])
    return float(best)


def reference_thesis(sys: LinearSystem, band, output: str) -> np.ndarray:
    """f_j = |H| at the clipped damped frequencies, then the band edges, by direct solves."""
    w = np.concatenate([np.clip(sys.damped_frequencies(), *band), band])
    return np.abs(sys.frf(omega_rad_s=w, output=output))


CASES = [(n, seed, delays) for n in (3, 5, 9, 15, 27) for seed in (1, 2) for delays in (False, True)]


@pytest.mark.parametrize(("n", "seed", "delays"), CASES)
def test_certified_maximum_equals_reference(n, seed, delays):
    sys = stable_system(n, seed, delays)
    band = (0.05, 1.1 * sys.damped_frequencies().max())
    both = sys.response_maxima(band_rad_s=band, exact=True, output="acc"), \
        sys.response_maxima(band_rad_s=band, exact=True, output="disp")
    for rm, out in zip(both, ("acc", "disp"), strict=True):
        assert rm.certified, rm.reason
        assert rm.value == pytest.approx(reference_peak(sys, band, out), rel=RTOL)
        # each cell value is |H| by a direct solve at its reported frequency
        direct = np.abs(sys.frf(omega_rad_s=rm.frequencies, output=out))
        np.testing.assert_allclose(rm.values, direct, rtol=RTOL)
        thesis = sys.response_maxima(band_rad_s=band, output=out)
        np.testing.assert_allclose(thesis.values, reference_thesis(sys, band, out), rtol=RTOL)
        assert np.all(thesis.values <= rm.values * (1 + RTOL))


@pytest.mark.parametrize("n", [3, 9, 27])
def test_band_from_zero_and_all_outputs_share_one_grid(n):
    sys = stable_system(n, 7, True)
    band = (0.0, 1.2 * sys.damped_frequencies().max())
    from railopt.models.response_maxima import all_response_maxima

    rms = all_response_maxima(sys, band_rad_s=band, exact=True)
    for out, rm in rms.items():
        assert rm.certified
        assert rm.value == pytest.approx(reference_peak(sys, band, out), rel=RTOL)
        assert rm.values == pytest.approx(sys.response_maxima(band_rad_s=band, exact=True, output=out).values,
                                          rel=RTOL)


def test_affine_equals_plain_sum():
    rng = np.random.default_rng(0)
    base = rng.standard_normal((5, 5))
    parts = rng.standard_normal((4, 5, 5))
    p = np.array([1.5, 0.0, -2.0, 3e-7])
    expected = base + sum(pi * part for pi, part in zip(p, parts, strict=True))
    np.testing.assert_allclose(affine(base, parts, p), expected, rtol=1e-14, atol=1e-15)
    # exact cancellations stay exact
    parts[1] = -parts[0]
    np.testing.assert_array_equal(affine(np.zeros((5, 5)), parts[:2], np.array([2.0, 2.0])), 0.0)


def test_parametric_member_equals_direct_assembly():
    rng = np.random.default_rng(3)
    n = 4
    M0, C0, K0 = np.eye(n), 0.01 * np.eye(n), np.diag(rng.uniform(1, 3, n))
    parts = {"k": ParameterPart(K=np.diag(rng.uniform(0, 1, n))),
             "c": ParameterPart(C=np.diag(rng.uniform(0, 0.1, n)), F=rng.standard_normal(n))}
    fam = ParametricSystem(M0, C0, K0, F0=rng.standard_normal(n), output=rng.standard_normal(n), parts=parts,
                           response="acceleration")
    p = np.array([0.7, 1.3])
    member = fam.at(p)
    np.testing.assert_allclose(member.K, K0 + 0.7 * parts["k"].K, rtol=1e-15)
    np.testing.assert_allclose(member.C, C0 + 1.3 * parts["c"].C, rtol=1e-15)
    band = (0.05, 3.0)
    rm = member.response_maxima(band_rad_s=band, exact=True)
    assert rm.value == pytest.approx(reference_peak(member, band, member.output_names[0]), rel=RTOL)


def _cab():
    from railopt.models.vehicle import load_vehicle
    from railopt.models.vehicle.cab import CabInput, cab_lateral_model

    model = cab_lateral_model(load_vehicle("sd40-2"), CabInput())
    return model.system.at(model.parameters())


def _full_lateral():
    from railopt.models.vehicle import load_vehicle
    from railopt.models.vehicle.irregularity import Irregularity

    return load_vehicle("sd40-2").lateral("rigid", 30.0).forced_system(Irregularity("alignment", 0.00635),
                                                                       ["cab.lateral"], quantity="acceleration")


@pytest.mark.parametrize(("build", "band", "output"), [
    (_cab, (0.0, 6 * pi), "cab_acceleration"),
    (_full_lateral, (0.2 * pi, 6 * pi), None),
])
def test_vehicle_models_equal_reference(build, band, output):
    sys = build()
    out = output or sys.output_names[0]
    rm = sys.response_maxima(band_rad_s=band, exact=True, output=out)
    assert rm.certified, rm.reason
    lo = band[0] if band[0] > 0 else 1e-6  # the limit Ω → 0 is extrapolated; the sweep starts just above it
    ref = reference_peak(sys, (lo, band[1]), out)
    assert rm.value == pytest.approx(max(ref, rm.values[-2]), rel=RTOL)
    finite = rm.frequencies > 0
    np.testing.assert_allclose(rm.values[finite], np.abs(sys.frf(omega_rad_s=rm.frequencies[finite], output=out)),
                               rtol=RTOL)
    thesis = sys.response_maxima(band_rad_s=band, output=out)
    assert np.all(thesis.values <= rm.values * (1 + RTOL))
