"""Several named outputs share one eigen-decomposition; maxima and gradients per output."""

from __future__ import annotations

import numpy as np
import pytest
from test_parametric import BAND, P0, central_difference

from railopt.models import Forcing, LinearSystem, ParametricSystem
from railopt.models.sensitivity import maxima_jacobians

from conftest import base_excited_parametric


def two_output_system() -> ParametricSystem:
    base = base_excited_parametric()
    b = base._base
    rows = {"top_acceleration": (np.array([0.0, 0.0, 1.0]), "acceleration"),
            "stroke": (np.array([1.0, -1.0, 0.0]), "displacement"),
            "middle_velocity": (np.array([0.0, 1.0, 0.0]), "velocity")}
    parts = {name: part for name, part in zip(base.parameters, _parts(base), strict=True)}
    return ParametricSystem(b.M, b.C, b.K, b.forcing, parts=parts, outputs=rows)


def _parts(ps: ParametricSystem):
    from railopt.models import ParameterPart

    return [ParameterPart(M=ps._M[i], C=ps._C[i], K=ps._K[i], F=ps._F[i]) for i in range(len(ps.parameters))]


def test_each_output_equals_a_single_output_system():
    ps = two_output_system()
    sys = ps.at(P0)
    for name, out in sys.outputs.items():
        single = LinearSystem(sys.M, sys.C, sys.K, sys.forcing, out.row, response=out.quantity)
        for exact in (False, True):
            a = sys.response_maxima(band_rad_s=BAND, exact=exact, output=name)
            b = single.response_maxima(band_rad_s=BAND, exact=exact)
            np.testing.assert_allclose(a.values, b.values, rtol=1e-13)
        w = np.linspace(0.1, 3.0, 50)
        np.testing.assert_allclose(sys.frf(omega_rad_s=w, output=name), single.frf(omega_rad_s=w), rtol=1e-13)


@pytest.mark.parametrize("exact", [False, True])
def test_gradients_of_every_output_match_finite_differences(exact):
    ps = two_output_system()
    sys = ps.at(P0)
    result = maxima_jacobians(sys, band_rad_s=BAND, exact=exact)
    assert set(result) == set(sys.output_names)
    for name, (rm, J) in result.items():
        Jfd = central_difference(
            lambda q, name=name: ps.response_maxima(q, band_rad_s=BAND, exact=exact, output=name).values, P0)
        np.testing.assert_allclose(rm.values, ps.response_maxima(P0, band_rad_s=BAND, exact=exact, output=name).values,
                                   rtol=1e-14)
        np.testing.assert_allclose(J, Jfd, rtol=2e-5, atol=2e-6 * np.max(np.abs(Jfd)))


def test_one_eigen_decomposition_serves_every_output(monkeypatch):
    import railopt.models.system as ls

    calls = []
    original = ls.modal
    monkeypatch.setattr(ls, "modal", lambda G: calls.append(1) or original(G))
    sys = two_output_system().at(P0)
    maxima_jacobians(sys, band_rad_s=BAND, exact=True)
    assert len(calls) == 1


def test_unknown_output_and_bad_rows_name_the_field():
    sys = two_output_system().at(P0)
    with pytest.raises(ValueError, match="^output: unknown output 'cab'"):
        sys.response_maxima(band_rad_s=BAND, output="cab")
    with pytest.raises(ValueError, match=r"^outputs\['z'\]: must be real"):
        LinearSystem(np.eye(2), np.eye(2), np.eye(2), [1.0, 0.0], outputs={"z": [1j, 0.0]})
    with pytest.raises(ValueError, match=r"^outputs\['z'\].quantity"):
        LinearSystem(np.eye(2), np.eye(2), np.eye(2), [1.0, 0.0], outputs={"z": ([1.0, 0.0], "jerk")})


def test_feedthrough_gives_the_relative_displacement_of_a_base_excited_sdof():
    """Stroke x − y of m x'' + c(x' − y') + k(x − y) = 0: |X − Y|/|Y| = r²/√((1 − r²)² + (2ζr)²)."""
    m, k, zeta = 2.0, 800.0, 0.1
    c = 2 * zeta * np.sqrt(k * m)
    wn = np.sqrt(k / m)
    forcing = np.array([[k], [c]], dtype=complex)  # (k + iΩc)·Y, Y = 1
    sys = LinearSystem([[m]], [[c]], [[k]], Forcing.polynomial(forcing),
                       outputs={"stroke": ([1.0], "displacement", [-1.0]), "body": ([1.0], "displacement")})
    w = np.linspace(0.0, 3 * wn, 301)
    r = w / wn
    closed = r**2 / np.sqrt((1 - r**2) ** 2 + (2 * zeta * r) ** 2)
    np.testing.assert_allclose(np.abs(sys.frf(omega_rad_s=w, output="stroke")), closed, rtol=1e-11, atol=1e-14)
    np.testing.assert_allclose(sys.pole_residue().evaluate(w)[:, 0], sys.frf(omega_rad_s=w, output="stroke"),
                               rtol=1e-10, atol=1e-14)
    rm = sys.response_maxima(band_rad_s=(0.0, 3 * wn), exact=True, output="stroke")
    # closed-form peak of r²/√(...): at r² = 1/(1 − 2ζ²), value 1/(2ζ√(1 − ζ²))
    assert rm.certified and rm.value == pytest.approx(1 / (2 * zeta * np.sqrt(1 - zeta**2)), rel=1e-10)


@pytest.mark.parametrize("exact", [False, True])
def test_feedthrough_gradients_match_finite_differences(exact):
    """Base-excited chain with a parametric base spring/damper; stroke output with a feedthrough."""
    from railopt.models import ParameterPart

    M = np.diag([1.0, 0.5])
    K0 = np.array([[1.0, -1.0], [-1.0, 1.0]])
    C0 = 0.02 * K0
    e0 = np.array([1.0, 0.0])
    ps = ParametricSystem(M, C0, K0, np.zeros(2), parts={
        "k_b": ParameterPart(K=np.outer(e0, e0), F=Forcing.polynomial(np.array([e0]))),
        "c_b": ParameterPart(C=np.outer(e0, e0), F=Forcing.polynomial(np.array([0 * e0, e0]))),
    }, outputs={"stroke": (e0, "displacement", [-1.0]), "acc": (np.array([0.0, 1.0]), "acceleration")})
    p = np.array([2.0, 0.1])
    band = (0.1, 3.0)
    for name, (_rm, J) in maxima_jacobians(ps.at(p), band_rad_s=band, exact=exact).items():
        Jfd = central_difference(
            lambda q, name=name: ps.response_maxima(q, band_rad_s=band, exact=exact, output=name).values, p)
        np.testing.assert_allclose(J, Jfd, rtol=2e-5, atol=2e-6 * np.max(np.abs(Jfd)))
