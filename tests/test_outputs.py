"""Several named outputs share one eigen-decomposition; maxima and gradients per output."""

from __future__ import annotations

import numpy as np
import pytest
from test_parametric import BAND, P0, central_difference

from railopt.models import LinearSystem, ParametricSystem

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
            a = sys.response_maxima(BAND, exact=exact, output=name)
            b = single.response_maxima(BAND, exact=exact)
            np.testing.assert_allclose(a.values, b.values, rtol=1e-13)
        w = np.linspace(0.1, 3.0, 50)
        np.testing.assert_allclose(sys.frf(w, name), single.frf(w), rtol=1e-13)


@pytest.mark.parametrize("exact", [False, True])
def test_gradients_of_every_output_match_finite_differences(exact):
    ps = two_output_system()
    sys = ps.at(P0)
    result = ps.maxima_jacobians(sys, BAND, exact=exact)
    assert set(result) == set(sys.output_names)
    for name, (rm, J) in result.items():
        Jfd = central_difference(lambda q, name=name: ps.response_maxima(q, BAND, exact=exact, output=name).values, P0)
        np.testing.assert_allclose(rm.values, ps.response_maxima(P0, BAND, exact=exact, output=name).values,
                                   rtol=1e-14)
        np.testing.assert_allclose(J, Jfd, rtol=2e-5, atol=2e-6 * np.max(np.abs(Jfd)))


def test_one_eigen_decomposition_serves_every_output(monkeypatch):
    import railopt.models.linear_system as ls

    calls = []
    original = ls.modal
    monkeypatch.setattr(ls, "modal", lambda G: calls.append(1) or original(G))
    sys = two_output_system().at(P0)
    two_output_system().maxima_jacobians(sys, BAND, exact=True)
    assert len(calls) == 1


def test_unknown_output_and_bad_rows_name_the_field():
    sys = two_output_system().at(P0)
    with pytest.raises(ValueError, match="^output: unknown output 'cab'"):
        sys.response_maxima(BAND, output="cab")
    with pytest.raises(ValueError, match=r"^outputs\['z'\]: must be real"):
        LinearSystem(np.eye(2), np.eye(2), np.eye(2), [1.0, 0.0], outputs={"z": [1j, 0.0]})
    with pytest.raises(ValueError, match=r"^outputs\['z'\].quantity"):
        LinearSystem(np.eye(2), np.eye(2), np.eye(2), [1.0, 0.0], outputs={"z": ([1.0, 0.0], "jerk")})
