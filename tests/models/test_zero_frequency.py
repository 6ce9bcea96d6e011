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


# ---------------------------------------------------------------- gradients at Ω = 0 (issue 27 R7)
def free_masses_family():
    """The free masses as a family in (k, c, Δm1): acceleration of mass 2 under a force on mass 1."""
    from railopt.models import ParameterPart, ParametricSystem

    e = np.array([[1.0, -1.0], [-1.0, 1.0]])
    return ParametricSystem(np.diag([2.0, 1.0]), np.zeros((2, 2)), np.zeros((2, 2)), np.array([1.0, 0.0]),
                            np.array([0.0, 1.0]), {"k": ParameterPart(K=e), "c": ParameterPart(C=e),
                                                   "dm1": ParameterPart(M=np.diag([1.0, 0.0]))},
                            response="acceleration")


def central_differences(family, p, band, exact, output, rel=1e-5):
    """d f_k / dp_i by central differences of the values (every f_k, both sides at the same band)."""
    from railopt.models.response_maxima import all_response_maxima

    columns = []
    for i in range(len(p)):
        h = rel * max(abs(p[i]), 1.0)
        up, down = p.copy(), p.copy()
        up[i] += h
        down[i] -= h
        f_up = all_response_maxima(family.at(up), band_rad_s=band, exact=exact, outputs=[output])[output].values
        f_down = all_response_maxima(family.at(down), band_rad_s=band, exact=exact, outputs=[output])[output].values
        columns.append((f_up - f_down) / (2 * h))
    return np.column_stack(columns)


@pytest.mark.parametrize("exact", [True, False])
def test_gradient_of_the_maxima_from_zero_hz_equals_central_differences(exact) -> None:
    """A band from 0 Hz on free masses: every f_k's gradient, the lower edge's (the limit 1/(m1 + m2)) included,
    where Z(0) is singular (it raised LinAlgError)."""
    from railopt.models.sensitivity import maxima_jacobians

    family = free_masses_family()
    p = np.array([100.0, 0.4, 0.0])
    band = (0.0, 30.0)
    rm, J = maxima_jacobians(family.at(p), band_rad_s=band, exact=exact)["output"]
    assert rm.frequencies[-2] == 0.0
    fd = central_differences(family, p, band, exact, "output")
    np.testing.assert_allclose(J, fd, rtol=1e-6, atol=1e-7 * np.max(np.abs(fd)))
    # the lower edge: d(1/(m1 + m2 + Δm1))/dΔm1 = −1/9, the spring and damper do not move the limit
    np.testing.assert_allclose(J[-2], [0.0, 0.0, -1.0 / 9.0], atol=1e-9)


def test_gradient_from_zero_hz_on_the_locomotive_vertical_model(sd40) -> None:
    """Seven free rigid-body roots (fore-aft translation, wheelset pitches) and delayed axle inputs."""
    from railopt.models.sensitivity import maxima_jacobians

    family = sd40.vertical("rigid", speed=30.0).family(["K1", "C1", "K6", "C6"],
                                                       input=Irregularity("vertical", amplitude_m=0.00635),
                                                       outputs=["body.w"], quantity="acceleration")
    p = np.array(family.values, dtype=float)
    band = (0.0, 8 * HZ)
    rm, J = maxima_jacobians(family.at(p), band_rad_s=band, exact=True)["body.w"]
    assert rm.certified and rm.frequencies[-2] == 0.0
    fd = central_differences(family, p, band, True, "body.w")
    scale = np.max(np.abs(fd), axis=0)
    assert np.max(np.abs(J - fd) / scale) < 1e-5


def test_a_minimax_solve_from_zero_hz_converges_with_analytic_gradients() -> None:
    """End to end: the band maximum from 0 Hz of the free masses minimised over the damper rate with SLSQP and the
    analytic Jacobian — every start ended in LinAlgError before; now it converges, and to the same optimum as with
    finite differences."""
    from railopt.design import DesignVariable, MinimaxProblem, solve
    from railopt.models.response_maxima import all_response_maxima
    from railopt.models.sensitivity import maxima_jacobians

    family = free_masses_family()
    band = (0.0, 30.0)

    def values(x):
        return all_response_maxima(family.at([100.0, x[0], 0.0]), band_rad_s=band, exact=True)["output"].values

    def jacobian(x):
        return maxima_jacobians(family.at([100.0, x[0], 0.0]), band_rad_s=band, exact=True)["output"][1][:, [1]]

    variables = [DesignVariable("c", 0.1, 20.0)]
    analytic = solve(MinimaxProblem(variables, values, jacobian=jacobian), [0.5], "slsqp")
    finite = solve(MinimaxProblem(variables, values), [0.5], "slsqp")
    assert analytic.status == "converged" and analytic.success, analytic.message
    assert analytic.value == pytest.approx(finite.value, rel=1e-6)
    assert analytic.x[0] == pytest.approx(finite.x[0], rel=1e-3)


@pytest.mark.parametrize("masses", [(2.0, 1.0), (2.0, 1.0, 3.3)])
def test_damped_frequency_derivatives_beside_a_defective_zero_root(masses) -> None:
    """Free masses: the double root s = 0 has one eigenvector, V is singular to rounding and V⁻¹ spoiled the left
    vectors of the other roots too (dω_d/dc came out 5e-19 instead of −0.018); central differences of ω_d."""
    from railopt.models import ParameterPart, ParametricSystem
    from railopt.models.sensitivity import damped_frequency_jacobian

    n = len(masses)
    parts = {}
    for j in range(n - 1):
        e = np.zeros((n, n))
        e[j, j] = e[j + 1, j + 1] = 1.0
        e[j, j + 1] = e[j + 1, j] = -1.0
        parts[f"k{j}"], parts[f"c{j}"] = ParameterPart(K=e), ParameterPart(C=e)
    parts["dm0"] = ParameterPart(M=np.diag([1.0] + [0.0] * (n - 1)))
    family = ParametricSystem(np.diag(masses), np.zeros((n, n)), np.zeros((n, n)), np.eye(n)[0], np.eye(n)[-1],
                              parts, response="acceleration")
    p = np.array([v for j in range(n - 1) for v in (100.0 * (j + 1), 0.4 + 0.3 * j)] + [0.0])
    system = family.at(p)
    assert system.modal().condition > 1e6
    J = damped_frequency_jacobian(system)
    fd = np.zeros_like(J)
    for i in range(len(p)):
        h = 1e-6 * max(abs(p[i]), 1.0)
        up, down = p.copy(), p.copy()
        up[i] += h
        down[i] -= h
        fd[:, i] = (family.at(up).damped_frequencies() - family.at(down).damped_frequencies()) / (2 * h)
    moving = system.damped_frequencies() > 1e-6  # the rigid-body 'mode' (ω_d = 0) has no frequency to move
    np.testing.assert_allclose(J[moving], fd[moving], rtol=1e-6, atol=1e-7 * np.max(np.abs(fd)))
