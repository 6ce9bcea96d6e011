"""The Jacobians of the response maxima, all frequencies and parameter columns of one system in stacked calls (issue 25
part J), against central differences of the certified maxima themselves (the values path: ``all_response_maxima`` of
the members at p ± h·e_i, never the derivative code).

Systems: the flagship's cab model (20 parameters, five outputs, band from 0 Hz); a random non-symmetric chain with
delayed polynomial forcing, a callable forcing part, a mass part and an output with a feedthrough; and systems built
to break the stacking: a maximum on the band's upper edge, free rigid-body roots with maxima inside the zero zone
next to maxima solved directly (one stacked call holds both), and a maximum where Z(Ω) is exactly singular.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from railopt.models import Forcing, ParameterPart, ParametricSystem
from railopt.models.response_maxima import all_response_maxima, zero_zone
from railopt.models.sensitivity import maxima_jacobians
from railopt.models.system import Output

HZ = 2 * np.pi


def central_jacobian(family: ParametricSystem, p: np.ndarray, band: tuple[float, float], exact: bool,
                     outputs: list[str], rel: float = 1e-6) -> dict[str, np.ndarray]:
    """d f_k / d p_i (n+2, P) per output by central differences of the certified maxima (the values path)."""
    cols: dict[str, list[np.ndarray]] = {name: [] for name in outputs}
    for i in range(len(p)):
        h = rel * max(abs(p[i]), 1e-300)
        up, down = p.copy(), p.copy()
        up[i] += h
        down[i] -= h
        hi_ = all_response_maxima(family.at(up), band_rad_s=band, exact=exact, outputs=outputs)
        lo_ = all_response_maxima(family.at(down), band_rad_s=band, exact=exact, outputs=outputs)
        for name in outputs:
            cols[name].append((hi_[name].values - lo_[name].values) / (up[i] - down[i]))
    return {name: np.array(c).T for name, c in cols.items()}


def relative_error(J: np.ndarray, Jfd: np.ndarray, p: np.ndarray) -> float:
    """max |J − Jfd| over the entries, each column scaled by p_i (a change of f per relative change of p_i) and
    relative to the largest such entry of the finite differences."""
    scale = np.abs(p)[None, :]
    return float(np.max(np.abs(J - Jfd) * scale) / np.max(np.abs(Jfd) * scale))


# ---------------------------------------------------------------------------------------------- the cab model
@pytest.fixture(scope="module")
def cab():
    import railopt.studies as st
    from railopt.studies.config import load_study

    _, config, _ = load_study(Path(st.__file__).parent / "cab_lateral_minimax.toml")
    setup = config.setups()["sd40-2"]
    names = [v.name for v in config.design.variables]
    x0 = np.array([setup.named_designs["existing"][n] for n in names])
    p, _ = setup.parameters(names, x0)
    return setup.family, p


@pytest.mark.parametrize("exact", [True, False])
def test_cab_model_jacobians_equal_central_differences_of_the_certified_maxima(cab, exact) -> None:
    family, p = cab
    band = (0.0, 3.0 * HZ)  # the flagship's band, from 0 Hz
    outputs = list(family.output_names)
    result = maxima_jacobians(family.at(p), band_rad_s=band, exact=exact)
    reference = central_jacobian(family, p, band, exact, outputs)
    for name in outputs:
        rm, J = result[name]
        assert J.shape == (family.n + 2, len(p))
        assert relative_error(J, reference[name], p) < 2e-8, name


# ------------------------------------------------------------------------- a random non-symmetric delayed chain
def delayed_chain(seed: int = 11, n: int = 5) -> tuple[ParametricSystem, np.ndarray]:
    """n masses in a chain with non-symmetric perturbations of M, C, K, forced at two axles through a parameterised
    spring and damper (delays 0 and 0.35 s), a callable forcing part, and three outputs: an acceleration, a
    velocity and a stroke with the rail input subtracted (a feedthrough)."""
    rng = np.random.default_rng(seed)
    chain = np.diag(np.full(n, 2.0)) - np.diag(np.ones(n - 1), 1) - np.diag(np.ones(n - 1), -1)
    M = np.diag(rng.uniform(0.8, 1.6, n)) + 0.03 * rng.standard_normal((n, n))
    K = 40.0 * chain + 2.0 * rng.standard_normal((n, n))
    C = 0.4 * chain + 0.3 * np.eye(n) + 0.02 * rng.standard_normal((n, n))
    e0, e1 = np.eye(n)[0], np.eye(n)[1]
    tau = 0.35
    spring = Forcing.delayed([(e0, 0.0), (e1, tau)])  # k_in (y(t) e0 + y(t − τ) e1)
    damper = Forcing.delayed([(np.array([np.zeros(n), e0]), 0.0), (np.array([np.zeros(n), e1]), tau)])
    bend = 0.05 * rng.standard_normal((n, n))
    parts = {
        "k_in": ParameterPart(K=np.outer(e0, e0) + np.outer(e1, e1), F=spring),
        "c_in": ParameterPart(C=np.outer(e0, e0) + np.outer(e1, e1), F=damper),
        "k_mid": ParameterPart(K=chain + bend),  # non-symmetric
        "m_top": ParameterPart(M=np.outer(np.eye(n)[-1], np.eye(n)[-1]) + 0.1 * np.outer(np.eye(n)[-1], e0)),
        # a callable part, its delay declared (0.2 s)
        "a_cal": ParameterPart(F=Forcing(value=lambda w: 0.3 * np.exp(-1j * w * 0.2) * np.eye(n)[2], max_delay=0.2)),
    }
    outputs = {
        "top_acceleration": (np.eye(n)[-1], "acceleration"),
        "middle_velocity": (np.eye(n)[2], "velocity"),
        "stroke": Output(np.eye(n)[0], "displacement", Forcing.delayed([(np.array([-1.0]), 0.0)])),
    }
    family = ParametricSystem(M, C, K, np.zeros(n), parts=parts, outputs=outputs)
    p = np.array([30.0, 0.6, 5.0, 0.5, 1.0])
    return family, p


def test_the_chain_is_a_fair_test() -> None:
    """Preconditions: stable, non-symmetric in M, C and K, forced with a delay, and every maximum finite."""
    family, p = delayed_chain()
    sys = family.at(p)
    assert np.all(sys.eigenvalues().real < 0)
    for A in (sys.M, sys.C, sys.K):
        assert np.max(np.abs(A - A.T)) > 1e-3
    assert sys.forcing.max_delay == pytest.approx(0.35)
    for rm in all_response_maxima(sys, band_rad_s=(0.3, 12.0), exact=True).values():
        assert np.all(np.isfinite(rm.values)) and rm.certified


@pytest.mark.parametrize("exact", [True, False])
def test_random_nonsymmetric_delayed_chain_jacobians_equal_central_differences(exact) -> None:
    family, p = delayed_chain()
    band = (0.3, 12.0)
    outputs = list(family.output_names)
    result = maxima_jacobians(family.at(p), band_rad_s=band, exact=exact)
    reference = central_jacobian(family, p, band, exact, outputs)
    for name in outputs:
        assert relative_error(result[name][1], reference[name], p) < 2e-8, name


def test_one_output_alone_has_the_rows_it_has_among_all() -> None:
    """Stacking the frequencies of several outputs in one call mixes nothing between them (invariant)."""
    family, p = delayed_chain()
    sys = family.at(p)
    together = maxima_jacobians(sys, band_rad_s=(0.3, 12.0), exact=False)
    for name in sys.output_names:
        alone = maxima_jacobians(sys, band_rad_s=(0.3, 12.0), exact=False, outputs=[name])[name][1]
        np.testing.assert_allclose(alone, together[name][1], rtol=1e-12, atol=1e-14 * np.max(np.abs(alone)))


# ------------------------------------------------------------------------------------ built to break the stacking
def test_a_maximum_on_the_band_edge() -> None:
    """The band ends halfway up a resonance, so the last cell's maximum sits on the band's upper edge (a fixed
    frequency: its derivative is the partial derivative there, no envelope)."""
    family, p = delayed_chain()
    sys = family.at(p)
    wd = np.sort(sys.damped_frequencies())
    hi = wd[1] - 0.03  # below the second resonance, on its rising flank
    band = (0.3, hi)
    outputs = list(family.output_names)
    for exact in (True, False):
        result = maxima_jacobians(sys, band_rad_s=band, exact=exact)
        assert any(np.any(result[name][0].frequencies == hi) for name in outputs)  # precondition: a maximum on hi
        reference = central_jacobian(family, p, band, exact, outputs)
        for name in outputs:
            assert relative_error(result[name][1], reference[name], p) < 2e-8, (exact, name)


def free_chain() -> tuple[ParametricSystem, np.ndarray]:
    """Three masses joined by parameterised springs and dampers, nothing to ground (a rigid-body double root s = 0),
    forced on mass 1; outputs: the accelerations of masses 2 and 3 and the stroke x1 − x2 (all finite as Ω → 0)."""
    n = 3
    M = np.diag([2.0, 1.0, 1.5])
    link = [np.zeros((n, n)), np.zeros((n, n))]
    for j, (a, b) in enumerate([(0, 1), (1, 2)]):
        link[j][np.ix_([a, b], [a, b])] = [[1.0, -1.0], [-1.0, 1.0]]
    parts = {"k1": ParameterPart(K=link[0]), "c1": ParameterPart(C=link[0]),
             "k2": ParameterPart(K=link[1]), "c2": ParameterPart(C=link[1]),
             "m1": ParameterPart(M=np.diag([1.0, 0.0, 0.0]))}
    outputs = {"a2": (np.eye(n)[1], "acceleration"), "a3": (np.eye(n)[2], "acceleration"),
               "stroke": (np.array([1.0, -1.0, 0.0]), "displacement")}
    family = ParametricSystem(M, np.zeros((n, n)), np.zeros((n, n)), np.eye(n)[0], parts=parts, outputs=outputs)
    return family, np.array([100.0, 0.4, 300.0, 0.9, 0.5])


@pytest.mark.parametrize("exact", [True, False])
def test_rigid_body_roots_with_maxima_inside_the_zero_zone(exact) -> None:
    family, p = free_chain()
    sys = family.at(p)
    band = (0.0, 40.0)
    zone = zero_zone(sys, band[1])
    assert zone is not None  # precondition: the rigid-body roots make a zero zone
    outputs = list(family.output_names)
    result = maxima_jacobians(sys, band_rad_s=band, exact=exact)
    frequencies = np.concatenate([result[name][0].frequencies[np.isfinite(result[name][0].values)]
                                  for name in outputs])
    assert np.any(frequencies < zone.step) and np.any(frequencies > zone.step)  # both kinds in one stacked call
    # step 1e-3 (truncation ≈ 8e-7, measured as h² scaling from 3e-4 to 3e-3): the values near a rigid-body pair are
    # rough at the 1e-9 level (the pair s ≈ ±1e-7 from rounding moves the first cell boundary; the limit model's
    # direct solves at ε round as 1/ε²), which a step of 1e-6 would turn into derivative errors of 1e-3
    reference = central_jacobian(family, p, band, exact, outputs, rel=1e-3)
    for name in outputs:
        assert relative_error(result[name][1], reference[name], p) < 3e-6, name
    # the lower edge, Ω → 0: the masses accelerate as one, f = 1/(m1 + m2 + m3 + Δm1), so df/dΔm1 = −1/25 exactly
    for name in ("a2", "a3"):
        assert result[name][1][-2] == pytest.approx([0.0, 0.0, 0.0, 0.0, -1.0 / 25.0], abs=1e-11)


def test_an_exactly_singular_impedance_takes_the_limit_from_above_inside_the_stack() -> None:
    """Two decoupled masses, the first undamped: Z(2) = diag(0, 5 + 0.6i) is exactly singular, yet the second mass's
    response has a finite limit there.  One stacked call at Ω = 2 (singular) and Ω = 3 (regular) gives at both the
    closed form H = 1/(k2 − Ω² + iΩc2): ∂H/∂k2 = −H², ∂H/∂c2 = −iΩH², ∂H/∂k1 = 0, ∂H/∂Ω = (2Ω − ic2)H²."""
    from railopt.models.sensitivity import _partials_at

    parts = {"k2": ParameterPart(K=np.diag([0.0, 1.0])), "c2": ParameterPart(C=np.diag([0.0, 1.0])),
             "k1": ParameterPart(K=np.diag([1.0, 0.0]))}
    family = ParametricSystem(np.eye(2), np.zeros((2, 2)), np.zeros((2, 2)), np.array([0.0, 1.0]),
                              np.array([0.0, 1.0]), parts)
    k2, c2 = 9.0, 0.3
    sys = family.at([k2, c2, 4.0])
    omega = np.array([2.0, 3.0])
    assert np.linalg.slogdet(sys.impedance(2.0))[0] == 0  # precondition: exactly singular, the solve refuses it
    H, dH, dHw = _partials_at(sys, omega, np.zeros(2, dtype=int), np.ones(2, dtype=bool), None, 6.0)
    exact = 1.0 / (k2 - omega**2 + 1j * omega * c2)
    np.testing.assert_allclose(H, exact, rtol=1e-12)
    np.testing.assert_allclose(dH, np.column_stack([-exact**2, -1j * omega * exact**2, 0 * exact]),
                               rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(dHw, (2 * omega - 1j * c2) * exact**2, rtol=1e-12)
