"""Pole–residue evaluation of H(Ω) against direct solves; the ill-conditioned fallback."""

from __future__ import annotations

import numpy as np
import pytest
from test_forcing import brute_force_peak, delayed_system

from railopt.models import CONDITION_LIMIT, Forcing, LinearSystem

from conftest import random_system


@pytest.mark.parametrize("n", [3, 9, 15, 27])
def test_pole_residue_equals_direct_solves(n):
    sys = random_system(n, seed=n, damping=0.02)
    w = np.linspace(0.0, 1.3 * sys.damped_frequencies().max(), 3001)
    pr = sys.pole_residue()
    assert pr is not None and sys.modal().condition < CONDITION_LIMIT
    direct = sys.frf_outputs(omega_rad_s=w)
    err = np.max(np.abs(pr.evaluate(w) - direct)) / np.max(np.abs(direct))
    assert err < 1e-10


def test_pole_residue_with_delays_polynomial_and_callable_terms():
    sys = delayed_system(4, 3, 7.0, seed=11)
    w = np.linspace(0.0, 4.0, 2001)
    direct = sys.frf_outputs(omega_rad_s=w)
    np.testing.assert_allclose(sys.pole_residue().evaluate(w), direct, rtol=1e-10, atol=1e-12 * np.abs(direct).max())
    # the same forcing given as a callable amplitude (evaluated per frequency) gives the same H
    terms = [(lambda w, t=t: t.amplitude(w), t.delay) for t in sys.forcing.terms]
    callable_sys = LinearSystem(sys.M, sys.C, sys.K, Forcing.delayed(terms), sys.output, response=sys.response)
    np.testing.assert_allclose(callable_sys.pole_residue().evaluate(w), direct, rtol=1e-10,
                               atol=1e-12 * np.abs(direct).max())


def near_defective(detuning: float) -> LinearSystem:
    """Two oscillators with a one-way (circulatory) coupling, K = [[4, 1], [0, 4(1 + detuning)]], C = 0.1 I.

    At zero detuning each root s² + 0.1 s + 4 = 0 is double with one eigenvector (a Jordan block, as at
    a flutter coalescence): the eigenvector matrix of G is singular.  H has a sharp interior peak near 2 rad/s.
    """
    K = np.array([[4.0, 1.0], [0.0, 4.0 * (1 + detuning)]])
    return LinearSystem(np.eye(2), 0.1 * np.eye(2), K, [0.0, 1.0], [1.0, 0.0])


@pytest.mark.parametrize("detuning", [0.0, 1e-13])
def test_defective_system_falls_back_to_direct_solves(detuning):
    sys = near_defective(detuning)
    assert sys.modal().condition > CONDITION_LIMIT
    assert sys.pole_residue() is None
    rm = sys.response_maxima(band_rad_s=(0.0, 4.0), exact=True)
    assert rm.evaluation == "direct"
    assert 1.9 < rm.argmax_frequency < 2.1
    assert rm.value == pytest.approx(brute_force_peak(sys, (0.0, 4.0)), rel=1e-10)


def test_moderately_ill_conditioned_system_keeps_pole_residue_and_direct_values():
    """Below the threshold (cond ~1e6) the sampling uses the pole–residue form; the reported maximum is a
    direct solve, so it is as accurate as for a well-conditioned system."""
    sys = near_defective(1e-7)
    assert 1e4 < sys.modal().condition < CONDITION_LIMIT
    rm = sys.response_maxima(band_rad_s=(0.0, 4.0), exact=True)
    assert rm.evaluation == "pole-residue"
    assert rm.value == pytest.approx(brute_force_peak(sys, (0.0, 4.0)), rel=1e-10)


def test_two_outputs_with_nearly_repeated_complex_roots():
    """Two identical uncoupled oscillators with a 1e-9 detuning: nearly repeated roots, still diagonalisable
    with orthogonal modes, so the pole–residue form stays accurate (cond(V) small) and is used."""
    M = np.eye(2)
    K = np.diag([4.0, 4.0 * (1 + 1e-9)])
    C = 0.05 * K
    sys = LinearSystem(M, C, K, [1.0, 1.0], outputs={"a": [1.0, 0.0], "b": [1.0, 1.0]})
    assert sys.pole_residue() is not None
    for name in ("a", "b"):
        rm = sys.response_maxima(band_rad_s=(0.0, 4.0), exact=True, output=name)
        assert rm.evaluation == "pole-residue"
        assert rm.value == pytest.approx(brute_force_peak(LinearSystem(M, C, K, [1.0, 1.0], sys.outputs[name].row),
                                                          (0.0, 4.0)), rel=1e-10)
