"""The bifurcation machinery against the closed-form cycles of the subcritical Hopf normal form.

In polar form r' = μ r + r³ − r⁵, θ' = ω (integrated in Cartesian x = r cos θ, y = r sin θ), with
μ = (V − V_c)/V_ref.  Closed forms (independent of the code): cycles at r² = (1 ± √(1 + 4μ))/2 (outer +,
inner −), the fold at μ = −1/4 (r² = 1/2, V_fold = V_c − V_ref/4), the Hopf point at μ = 0; period 2π/ω; the
non-trivial Floquet multiplier exp(T · d(r')/dr) with d(r')/dr = μ + 3r² − 5r⁴ on the cycle (negative on the
outer branch: stable; positive on the inner: unstable).  Strogatz, *Nonlinear Dynamics and Chaos*, 2nd ed.
(Westview 2015), §8.2 (subcritical Hopf, r' = μr + r³ − r⁵) and §8.4 (saddle-node bifurcation of cycles at
μ_c = −1/4).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from railopt.models.bifurcation import (
    ContinuationOptions,
    Dwell,
    IntegrationSettings,
    PoincareSection,
    ShootingOptions,
    bifurcation_diagram,
    continue_periodic_orbit,
    detect_limit_cycle,
    find_periodic_orbit,
)
from railopt.models.bifurcation.continuation import hermite_turn

V_C, V_REF = 30.0, 20.0  # m/s: Hopf at 30 m/s, μ changes by 1 over 20 m/s
OMEGA = 2 * math.pi * 1.3  # rad/s: the cycles run at 1.3 Hz
PERIOD = 2 * math.pi / OMEGA
V_FOLD = V_C - V_REF / 4  # μ = −1/4
SECTION = PoincareSection(index=1, value=0.0, direction=1)  # y = 0 crossed upwards (x > 0)


def mu(speed: float | np.ndarray) -> float | np.ndarray:
    return (speed - V_C) / V_REF


def rhs(t: float, x: np.ndarray, speed: float) -> np.ndarray:
    r2 = x[0] ** 2 + x[1] ** 2
    g = mu(speed) + r2 - r2 * r2
    return np.array([g * x[0] - OMEGA * x[1], g * x[1] + OMEGA * x[0]])


def jacobian(t: float, x: np.ndarray, speed: float) -> np.ndarray:
    r2 = x[0] ** 2 + x[1] ** 2
    g = mu(speed) + r2 - r2 * r2
    dg = (1 - 2 * r2) * 2 * x  # ∂g/∂(x, y)
    return np.array([[g + x[0] * dg[0], x[0] * dg[1] - OMEGA], [x[1] * dg[0] + OMEGA, g + x[1] * dg[1]]])


def radius(speed: float | np.ndarray, sign: int) -> np.ndarray:
    """Closed-form cycle radius: r² = (1 ± √(1 + 4μ))/2."""
    return np.sqrt((1 + sign * np.sqrt(1 + 4 * mu(speed))) / 2)


def multiplier(speed: float | np.ndarray, r: float | np.ndarray) -> np.ndarray:
    """Closed-form non-trivial Floquet multiplier exp(T (μ + 3r² − 5r⁴))."""
    return np.exp(PERIOD * (mu(speed) + 3 * r**2 - 5 * r**4))


@pytest.mark.parametrize("use_jacobian", [False, True], ids=["fd-jacobian", "analytic-jacobian"])
def test_shooting_finds_both_cycles_with_their_closed_form_multipliers(use_jacobian):
    speed = 27.0
    for sign, start in ((+1, 0.95), (-1, 0.35)):
        orbit = find_periodic_orbit(rhs, np.array([start, 0.0]), speed, SECTION, 0.8 * PERIOD, 0,
                                    jacobian=jacobian if use_jacobian else None)
        r = radius(speed, sign)
        assert orbit.converged, orbit.reason
        assert orbit.amplitude == pytest.approx(r, rel=1e-8)
        assert orbit.period == pytest.approx(PERIOD, rel=1e-9)
        assert orbit.frequency_hz == pytest.approx(1.3, rel=1e-9)
        assert orbit.multipliers.shape == (1,)
        assert abs(orbit.multipliers[0] - multiplier(speed, r)) < 1e-7
        # the monodromy matrix holds the trivial multiplier 1 beside the non-trivial one
        full = np.sort(orbit.floquet_multipliers.real)
        np.testing.assert_allclose(full, np.sort([1.0, multiplier(speed, r)]), atol=1e-7)
        assert orbit.stable is (sign == +1)


def test_continuation_follows_both_branches_through_the_closed_form_fold():
    start = find_periodic_orbit(rhs, np.array([1.05, 0.0]), 33.0, SECTION, PERIOD, 0)
    assert start.converged, start.reason
    diagram = continue_periodic_orbit(rhs, start, SECTION, 0, speed_range=(20.0, 34.0),
                                      options=ContinuationOptions(speed_scale=V_REF),
                                      shooting=ShootingOptions(min_amplitude=0.05))
    assert len(diagram.folds) == 1
    assert diagram.fold_speed == pytest.approx(V_FOLD, rel=1e-6)  # measured: 2e-10 relative
    assert diagram.folds[0].amplitude == pytest.approx(math.sqrt(0.5), rel=1e-6)
    table = diagram.to_pandas()
    outer, inner = table[table.branch == 0], table[table.branch == 1]
    assert len(outer) >= 5 and len(inner) >= 5
    # amplitudes along both branches against r² = (1 ± √(1+4μ))/2
    np.testing.assert_allclose(outer.amplitude, radius(outer.speed_m_s.to_numpy(), +1), rtol=1e-6)
    np.testing.assert_allclose(inner.amplitude, radius(inner.speed_m_s.to_numpy(), -1), rtol=1e-6)
    np.testing.assert_allclose(table.period_s, PERIOD, rtol=1e-8)
    # multipliers against exp(T d(r')/dr), stability against its sign
    r = np.array([radius(v, +1 if b == 0 else -1) for v, b in zip(table.speed_m_s, table.branch, strict=True)])
    expected = multiplier(table.speed_m_s.to_numpy(), r)
    np.testing.assert_allclose(diagram.multipliers[:, 0].real, expected, atol=1e-5)
    np.testing.assert_array_equal(diagram.stable, expected < 1)
    assert outer.stable.all() and not inner.stable.any()
    # the inner branch ends at the Hopf point μ = 0, where the cycle shrinks to nothing
    assert "Hopf" in diagram.stop_reason
    assert inner.speed_m_s.max() < V_C and inner.speed_m_s.max() > V_C - 1.0


def test_ramp_brackets_the_fold_and_agrees_with_continuation_within_its_step():
    step = 0.5  # m/s ramp step; the speeds 31.3, 30.8, … put the closed-form fold 25 m/s between two of them
    speeds = np.arange(31.3, 22.5, -step)
    wavelength = 20.0  # m; 60 wavelengths: 1200/V s ≈ 45 s ≈ 60 cycles per speed
    diagram = bifurcation_diagram(rhs, np.array([0.05, 0.0]), speeds, Dwell(wavelengths=60, wavelength_m=wavelength),
                                  0, SECTION, sample_rate_hz=40.0, speed_range=(20.0, 34.0),
                                  settings=IntegrationSettings(rtol=1e-10, atol=1e-12),
                                  continuation=ContinuationOptions(speed_scale=V_REF),
                                  shooting=ShootingOptions(min_amplitude=0.05), linear_critical_speed=V_C)
    ramp = diagram.ramp
    low, high = ramp.fold_bracket
    assert high - low == pytest.approx(step) and ramp.step == pytest.approx(step)
    assert low < V_FOLD < high  # the closed-form fold inside the ramp's bracket
    critical = diagram.nonlinear_critical_speed()
    assert critical.confirmed, critical.reason
    assert critical.speed == pytest.approx(V_FOLD, rel=1e-6)
    assert abs(critical.speed - high) <= step and abs(critical.speed - low) <= step
    # above the fold the ramp sat on the stable cycle: the detector's amplitude is the closed-form radius
    k = ramp.last_steady
    assert ramp.verdicts[k].amplitude == pytest.approx(radius(ramp.speeds[k], +1), rel=1e-4)
    table = diagram.to_pandas()
    assert table.attrs["linear_critical_speed_m_s"] == V_C
    # continued up from the last steady ramp speed to the range's top and down through the fold to the Hopf point
    assert table.speed_m_s.iloc[0] == pytest.approx(34.0, abs=1e-2) and np.all(table.branch.diff().iloc[1:] >= 0)
    outer = table[table.branch == 0]
    np.testing.assert_allclose(outer.amplitude, radius(outer.speed_m_s.to_numpy(), +1), rtol=1e-6)
    assert outer.stable.all() and not table[table.branch == 1].stable.any()


def _trajectory(speed: float, r0: float, t_end: float, rate: float) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(0.0, t_end, 1.0 / rate)
    sol = solve_ivp(rhs, (0.0, t_end), [r0, 0.0], t_eval=t, args=(speed,), method="DOP853", rtol=1e-11, atol=1e-13)
    return sol.t, sol.y[0]


def test_detector_reads_the_stable_cycle_and_calls_the_motion_below_the_fold_decaying():
    speed = 28.0
    t, x = _trajectory(speed, radius(speed, +1) * 1.02, 30.0, 60.0)
    late = t > 15.0  # ≈ 20 cycles after the transient died out
    steady = detect_limit_cycle(t[late], x[late])
    assert steady.classification == "steady", steady.reason
    assert steady.amplitude == pytest.approx(radius(speed, +1), rel=1e-5)
    assert steady.frequency_hz == pytest.approx(OMEGA / (2 * math.pi), rel=1e-6)
    below = V_FOLD - 1.0
    t, x = _trajectory(below, 0.8, 12.0, 60.0)
    verdict = detect_limit_cycle(t, x)
    assert verdict.classification == "decaying", verdict.reason
    assert verdict.frequency_hz == pytest.approx(OMEGA / (2 * math.pi), rel=1e-3)


@pytest.mark.parametrize("method, rtol", [("LSODA", 1e-10), ("Radau", 1e-9), ("BDF", 1e-10), ("DOP853", 1e-10)])
def test_every_integration_method_gives_the_closed_form_cycle(method, rtol):
    """The stiff methods get the augmented Jacobian blockdiag(J, J ⊗ I); all reach the closed form."""
    speed = 27.0
    r = radius(speed, +1)
    orbit = find_periodic_orbit(rhs, np.array([0.95, 0.0]), speed, SECTION, 0.8 * PERIOD, 0,
                                settings=IntegrationSettings(method=method, rtol=rtol, atol=1e-12))
    assert orbit.converged, orbit.reason
    assert orbit.amplitude == pytest.approx(r, rel=1e-6)
    assert abs(orbit.multipliers[0] - multiplier(speed, r)) < 1e-5


def _on_curve(r: float) -> tuple[np.ndarray, np.ndarray]:
    """A point (r, μ) of the closed-form cycle family μ = r⁴ − r² (from r' = 0) and its unit tangent, oriented
    towards larger r."""
    u = np.array([r, r**4 - r**2])
    t = np.array([1.0, 4 * r**3 - 2 * r])
    return u, t / np.linalg.norm(t)


def test_hermite_turn_finds_the_closed_form_fold_with_fourth_order_accuracy():
    # the family turns at r² = 1/2, μ = −1/4; points straddle it unevenly, at shrinking spacing
    errors = []
    for spacing in (0.2, 0.1, 0.05):
        u0, t0 = _on_curve(math.sqrt(0.5) - 0.4 * spacing)
        u1, t1 = _on_curve(math.sqrt(0.5) + 0.6 * spacing)
        value, w = hermite_turn(u0, t0, u1, t1)
        assert 0.0 < w < 1.0
        assert value <= min(u0[1], u1[1])  # the turn lies below both points
        errors.append(abs(value + 0.25))
    assert errors[-1] < 1e-5  # measured 5.9e-6 at spacing 0.05 (1.7e-3, 1.0e-4 at 0.2, 0.1)
    # halving the spacing divides the error by about 16 (fourth order: the interpolant is exact to cubics)
    assert errors[0] / errors[1] > 12 and errors[1] / errors[2] > 12
    with pytest.raises(ValueError, match="no turn"):
        hermite_turn(*_on_curve(0.3), *_on_curve(0.4))


def test_a_fold_the_corrector_cannot_bracket_is_located_by_hermite_and_marked(monkeypatch):
    """The coach's failure mode — Newton fails at trial points inside the turning step on a non-smooth map —
    forced here on the smooth normal form: the fold then comes from the two corrected points around the turn."""
    from railopt.models.bifurcation import continuation

    def failing_brentq(fun, a, b, **kwargs):
        raise continuation._CorrectorFailed(0.5 * (a + b))

    monkeypatch.setattr(continuation, "brentq", failing_brentq)
    start = find_periodic_orbit(rhs, np.array([1.05, 0.0]), 33.0, SECTION, PERIOD, 0)
    diagram = continue_periodic_orbit(rhs, start, SECTION, 0, speed_range=(20.0, 34.0),
                                      options=ContinuationOptions(speed_scale=V_REF, points_after_fold=3),
                                      shooting=ShootingOptions(min_amplitude=0.05))
    assert len(diagram.folds) == 1
    fold = diagram.folds[0]
    assert fold.located == "hermite"
    assert fold.speed <= min(fold.between) and V_FOLD < min(fold.between) < V_FOLD + 1.0
    assert fold.speed == pytest.approx(V_FOLD, abs=5e-3)  # m/s; measured 1.8e-4 (the chord was 0.09 m/s)
    assert fold.amplitude == pytest.approx(math.sqrt(0.5), rel=2e-3)  # measured 2.9e-4
    assert diagram.to_pandas().attrs["fold_located"] == ["hermite"]


def test_hermite_turn_finds_every_turn_of_random_steps_far_from_the_origin():
    """Random steps (points up to 100 from the origin, chords down to 1e-8, speed slopes down to 1e-12) with the
    speed component changing sign: a turn always lies inside, at or below both ends.  The coefficients are formed
    from v1 − v0; formed from v0 and v1 separately they pushed about 1 % of these turns out of [0, 1] by round-off
    (review finding)."""
    rng = np.random.default_rng(0)
    for _ in range(3000):
        u0 = rng.normal(size=3) * 10 ** rng.uniform(-6, 2, size=3)
        u1 = u0 + rng.normal(size=3) * 10 ** rng.uniform(-8, 1)
        t0, t1 = rng.normal(size=3), rng.normal(size=3)
        t0, t1 = t0 / np.linalg.norm(t0), t1 / np.linalg.norm(t1)
        t0[-1], t1[-1] = -abs(t0[-1]) * 10 ** rng.uniform(-12, 0), abs(t1[-1]) * 10 ** rng.uniform(-12, 0)
        value, w = hermite_turn(u0, t0, u1, t1)
        assert 0.0 <= w <= 1.0
        assert value <= min(u0[-1], u1[-1]) + 1e-12 * max(abs(u0[-1]), abs(u1[-1]))


def test_a_fold_whose_bisection_fails_midway_uses_the_closest_corrected_pair(monkeypatch):
    """Brent corrects some trial points before the corrector fails: the Hermite turn then uses the closest pair of
    corrected points around the turn, not the whole step — a tighter pair and a closer fold."""
    from railopt.models.bifurcation import continuation

    def halfway_brentq(fun, a, b, **kwargs):
        for s in (a + 0.5 * (b - a), a + 0.25 * (b - a), a + 0.75 * (b - a)):
            fun(s)  # corrected and kept, as Brent's own trial points
        raise continuation._CorrectorFailed(0.6 * b)

    def whole_step_brentq(fun, a, b, **kwargs):
        raise continuation._CorrectorFailed(0.5 * (a + b))

    folds = {}
    for name, fake in (("halfway", halfway_brentq), ("whole", whole_step_brentq)):
        monkeypatch.setattr(continuation, "brentq", fake)
        start = find_periodic_orbit(rhs, np.array([1.05, 0.0]), 33.0, SECTION, PERIOD, 0)
        diagram = continue_periodic_orbit(rhs, start, SECTION, 0, speed_range=(20.0, 34.0),
                                          options=ContinuationOptions(speed_scale=V_REF, points_after_fold=2),
                                          shooting=ShootingOptions(min_amplitude=0.05))
        folds[name] = diagram.folds[0]
    half, whole = folds["halfway"], folds["whole"]
    assert half.located == whole.located == "hermite"
    assert max(half.between) - V_FOLD < max(whole.between) - V_FOLD  # a closer pair around the turn
    assert half.speed <= min(half.between)
    assert abs(half.speed - V_FOLD) < abs(whole.speed - V_FOLD)
    assert half.speed == pytest.approx(V_FOLD, abs=2e-5)  # m/s
    assert half.amplitude == pytest.approx(math.sqrt(0.5), rel=2e-3)
