"""The certified band maximum in one compiled call (kernels.certified_maxima) and over a batch of designs
(kernels.certified_maxima_batch via batch_response_maxima): each member's values equal the single-design path to
1e-12, the band maximum equals a dense direct-solve sweep refined by scipy's bounded Brent (written here, calling
no railopt code), and a refused or general-path member is handled as the single path handles it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from railopt.models import kernels
from railopt.models.response_maxima import all_response_maxima, batch_response_maxima
from railopt.models.vehicle.cab import CabInput, cab_lateral_model

BAND = (0.0, 2 * math.pi * 3.0)  # the flagship's 0–3 Hz
OUTPUT = "cab_acceleration"


@pytest.fixture(scope="module")
def cab(sd40):
    """The flagship's cab family (fixed-speed input), with the vehicle file's parameter values."""
    model = cab_lateral_model(sd40, CabInput(mode="fixed_speed"))
    return model.system, model.parameters()


def designs(cab, B: int, seed: int) -> np.ndarray:
    """B designs: the file's values, each scaled by 0.3–3."""
    _, base = cab
    return base * np.random.default_rng(seed).uniform(0.3, 3.0, size=(B, base.size))


def dense_peak(M, C, K, A, delays, row, q, band, points=20_001) -> float:
    """max over the band of |(iΩ)^q row·Z(Ω)⁻¹F(Ω)|, F = Σ_t e^{−iΩτ_t} Σ_j (iΩ)^j A[t, j]: a dense sweep of numpy
    solves, each local maximum refined by scipy's bounded Brent between its neighbours."""
    def mag(x):
        F = sum(np.exp(-1j * x * tau) * sum((1j * x) ** j * A[t, j] for j in range(A.shape[1]))
                for t, tau in enumerate(delays))
        return abs(row @ np.linalg.solve(K - x**2 * M + 1j * x * C, F) * (1j * x) ** q)

    w = np.linspace(*band, points)
    a = np.array([mag(x) for x in w])
    best = max(a[0], a[-1])
    for i in np.flatnonzero((a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:])) + 1:
        r = minimize_scalar(lambda x: -mag(x), bounds=(w[i - 1], w[i + 1]), method="bounded",
                            options={"xatol": 1e-13 * w[i]})
        best = max(best, -r.fun, a[i])
    return float(best)


def test_batch_equals_the_single_path_and_a_dense_sweep(cab):
    family, _ = cab
    P = designs(cab, 5, seed=3)
    stack = family.stack(P)
    values = batch_response_maxima(stack, band_rad_s=BAND, output=OUTPUT)
    assert values.shape == (5, family.n + 2)
    for b, p in enumerate(P):
        alone = all_response_maxima(family.at(p), band_rad_s=BAND, exact=True, outputs=[OUTPUT])[OUTPUT]
        assert alone.certified and alone.evaluation == "pole-residue"  # the one compiled call
        scale = np.max(alone.values)
        assert np.max(np.abs(values[b] - alone.values)) <= 1e-12 * scale
        out = stack.outputs[OUTPUT]
        ref = dense_peak(stack.M[b], stack.C[b], stack.K[b], stack.coefficients[b], stack.delays, out.row,
                         out.order, BAND)
        assert abs(values[b].max() - ref) <= 1e-9 * ref


def test_a_refused_member_is_inf_and_an_unstable_one_takes_the_general_path(cab):
    P = designs(cab, 4, seed=4)
    stack = cab[0].stack(P)
    stack.M[1] = 0.0  # a singular M: LinearSystem refuses it, the batch gives +inf
    stack.C[2] = -stack.C[2]  # negative damping: growing roots, the single path's +inf with its reason
    values = batch_response_maxima(stack, band_rad_s=BAND, output=OUTPUT)
    assert np.all(np.isinf(values[1])) and np.all(np.isinf(values[2]))
    with pytest.raises(ValueError, match="M: is singular"):
        stack.member(1)
    for b in (0, 3):
        alone = all_response_maxima(stack.member(b), band_rad_s=BAND, exact=True, outputs=[OUTPUT])[OUTPUT]
        np.testing.assert_allclose(values[b], alone.values, rtol=1e-12, atol=0)


def test_one_call_values_equal_dense_solves_on_a_delayed_chain():
    """kernels.certified_maxima on a 4-DOF chain with three delayed contact points and two outputs (velocity,
    acceleration): every band maximum equals the dense sweep of direct solves to 1e-9, and status 0 (certified
    path), finite samples, a certified grid ratio."""
    rng = np.random.default_rng(11)
    n = 4
    M = np.diag(rng.uniform(0.5, 2.0, n))
    k = rng.uniform(0.5, 3.0, n)
    K = np.diag(k + np.r_[k[1:], 0.0]) - np.diag(k[1:], 1) - np.diag(k[1:], -1)
    C = 0.03 * K + 0.01 * np.eye(n)
    delays = np.array([0.0, 0.7, 1.9])
    A = (rng.standard_normal((3, 2, n)) + 0j) * np.array([1.0, 0.1])[None, :, None]
    rows = rng.standard_normal((2, n))
    orders = np.array([1, 2], dtype=np.int64)
    n2 = 2 * n
    G = np.zeros((n2, n2))
    G[:n, n:] = np.eye(n)
    G[n:] = -np.linalg.solve(M, np.hstack([K, C]))
    s, V = np.linalg.eig(G)
    band = (0.05, 4.0)
    from railopt.models.response_maxima import _SETTINGS

    status, values, freqs, ratio, points, finite, resonant, soft, unresolved, *_ = kernels.certified_maxima(
        M, C, K, np.ascontiguousarray(s), np.ascontiguousarray(V), np.ascontiguousarray(A), delays,
        np.ascontiguousarray(rows), orders, band[0], band[1], 1.9, 200, _SETTINGS)
    assert status == kernels.CERT_OK and finite and ratio <= 0.25 / 0.75 * (1 + 1e-9) and points > 0
    assert soft == -1 and unresolved == -1 and not resonant.any()

    def mag(x, o):
        F = sum(np.exp(-1j * x * tau) * (A[t, 0] + 1j * x * A[t, 1]) for t, tau in enumerate(delays))
        return abs(rows[o] @ np.linalg.solve(K - x**2 * M + 1j * x * C, F) * (1j * x) ** orders[o])

    w = np.linspace(*band, 40_001)
    for o in range(2):
        a = np.array([mag(x, o) for x in w])
        best = max(a[0], a[-1])
        for i in np.flatnonzero((a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:])) + 1:
            r = minimize_scalar(lambda x, o=o: -mag(x, o), bounds=(w[i - 1], w[i + 1]), method="bounded",
                                options={"xatol": 1e-13})
            best = max(best, -r.fun)
        assert abs(values[o].max() - best) <= 1e-9 * best
        # each value is |H| at its reported frequency (a direct solve here)
        for j in range(n + 2):
            assert abs(values[o, j] - mag(freqs[o, j], o)) <= 1e-12 * values[o].max()


def test_a_member_with_an_exactly_singular_impedance_takes_the_general_path():
    """Undamped two-mass system, ω = 1 and 2 rad/s, band [0.5, 2]: Z(2) = K − 4M is exactly singular at the upper
    edge, so the compiled call raises inside the batch (status −2) and that member is recomputed on the general path:
    its values are the single path's (inf at both undamped peaks and at the edge, |H(0.5)| = 1/0.75 + 1/3.75 = 1.6
    at the lower edge, the closed form of two uncoupled unit masses); the damped member beside it is unaffected."""
    from railopt.models import ParametricSystem
    from railopt.models.parametric import ParameterPart
    from railopt.models.response_maxima import _SETTINGS

    family = ParametricSystem(np.eye(2), np.zeros((2, 2)), np.diag([1.0, 4.0]), F0=[1.0, 1.0], output=[1.0, 1.0],
                              parts={"c": ParameterPart(C=np.eye(2))})
    P = np.array([[0.0], [0.1]])
    stack = family.stack(P)
    G, regular = kernels.state_matrices(stack.M, stack.C, stack.K, 1e-14)
    s, V = np.linalg.eig(G)
    status = kernels.certified_maxima_batch(stack.M, stack.C, stack.K, np.ascontiguousarray(s), np.ascontiguousarray(V),
                                            np.ascontiguousarray(stack.coefficients), stack.delays,
                                            np.array([[1.0, 1.0]]), np.array([0]), 0.5, 2.0, 0.0, 33, _SETTINGS,
                                            regular)[0]
    assert status.tolist() == [-2, kernels.CERT_OK]
    with np.errstate(invalid="ignore"):
        values = batch_response_maxima(stack, band_rad_s=(0.5, 2.0))
        for b, p in enumerate(P):
            alone = all_response_maxima(family.at(p), band_rad_s=(0.5, 2.0), exact=True)["output"]
            np.testing.assert_allclose(values[b], alone.values, rtol=1e-12, atol=0)
    assert np.isinf(values[0, [0, 1, 3]]).all() and values[0, 2] == pytest.approx(1 / 0.75 + 1 / 3.75, rel=1e-14)
