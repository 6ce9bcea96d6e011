"""The analytic gradient of the RMS response (issue 27 item 13): public in the model layer
(:func:`rms_and_gradient` for a parametric family, :func:`rms_gradient` on a response's rule), checked against
central finite differences of independently recomputed RMS values."""

from __future__ import annotations

import numpy as np
import pytest

from railopt.models.random_response import random_response, rms, rms_and_gradient, rms_gradient
from railopt.models.track.spectra import irregularity_spectrum
from railopt.models.vehicle import Irregularity, load_vehicle

from conftest import base_excited_parametric


def central_differences(family, p, spectrum, speed, band, output, rel=1e-4):
    """dRMS/dp by central differences of :func:`rms` at p ± h (tight quadrature: its noise ≪ the step's error)."""
    grad = np.zeros(len(p))
    for i in range(len(p)):
        h = rel * abs(p[i])
        up, down = p.copy(), p.copy()
        up[i] += h
        down[i] -= h
        at = (lambda q: family.at(q, speed=speed)) if family.has_speed else family.at
        grad[i] = (rms(at(up), spectrum, speed, band, output, rtol=1e-12)
                   - rms(at(down), spectrum, speed, band, output, rtol=1e-12)) / (2 * h)
    return grad


@pytest.mark.parametrize(("view", "kind", "component", "output", "quantity", "names"), [
    ("vertical", "vertical", "profile", "body.w", "acceleration", ["K1", "C1", "K6", "C6"]),
    ("lateral", "alignment", "alignment", "body.v", "displacement", None),
])
def test_rms_gradient_of_a_vehicle_family_equals_central_differences(view, kind, component, output, quantity,
                                                                      names):
    sd40 = load_vehicle("sd40-2")
    v = getattr(sd40, view)("rigid", speed=30.0)
    family = v.family(names if names is not None else list(v.family().parameters)[:4],
                      input=Irregularity(kind, amplitude_m=1.0), outputs=[output], quantity=quantity)
    spectrum = irregularity_spectrum("erri_b176", level="low", component=component)
    p = np.array(family.values, dtype=float)
    value, grad = rms_and_gradient(family, p, spectrum, 30.0, (0.5, 15.0), output, rtol=1e-12)
    assert value == pytest.approx(rms(family.at(p), spectrum, 30.0, (0.5, 15.0), output, rtol=1e-12), rel=1e-12)
    fd = central_differences(family, p, spectrum, 30.0, (0.5, 15.0), output)
    np.testing.assert_allclose(grad, fd, rtol=2e-5, atol=2e-5 * np.max(np.abs(fd)))
    assert np.max(np.abs(fd)) > 0  # the parameters do move the RMS


def test_rms_gradient_chain_rule_and_a_callable_delayed_forcing():
    """The conftest family (callable, delayed base forcing; acceleration output): the gradient on the response's
    rule against central differences, and ``dp`` folding the chain rule dRMS/dx = dRMS/dp · dp/dx."""
    family = base_excited_parametric()
    spectrum = irregularity_spectrum("erri_b176", level="high", component="profile")
    p = np.array([3.0, 0.2, 0.5])
    system = family.at(p)
    response = random_response(system, spectrum, 10.0, (0.05, 1.5), rtol=1e-12)
    grad = rms_gradient(system, response)
    fd = central_differences(family, p, spectrum, 10.0, (0.05, 1.5), None)
    np.testing.assert_allclose(grad, fd, rtol=2e-5, atol=2e-5 * np.max(np.abs(fd)))
    dp = np.array([[1.0, 0.0], [0.0, 2.0], [0.5, -1.0]])  # (P, d)
    np.testing.assert_allclose(rms_gradient(system, response, dp), grad @ dp, rtol=1e-12, atol=1e-15)
    with pytest.raises(ValueError, match=r"^dp: must have shape \(3, d\)"):
        rms_gradient(system, response, np.ones((2, 2)))
    with pytest.raises(ValueError, match="^system: carries no parameter derivatives"):
        from railopt.models import LinearSystem

        plain = LinearSystem(system.M, system.C, system.K, system.forcing, system.output, response="acceleration")
        rms_gradient(plain, random_response(plain, spectrum, 10.0, (0.05, 1.5)))
