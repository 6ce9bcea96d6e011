"""Flags that must hold when set: the detector does not mistake a slow transient for a cycle, shooting reports
failure instead of a wrong orbit, continuation stops with its reason at the edge of the speed range, and bad
arguments raise ValueError naming the argument."""

from __future__ import annotations

import math

import numpy as np
import pytest

from railopt.models.bifurcation import (
    BifurcationDiagram,
    ContinuationOptions,
    CycleTolerances,
    Dwell,
    Fold,
    IntegrationSettings,
    ModelLimit,
    PoincareSection,
    RampResult,
    bifurcation_diagram,
    continue_periodic_orbit,
    detect_limit_cycle,
    find_periodic_orbit,
    speed_ramp,
)
from railopt.models.bifurcation.continuation import EDGE_TOL

V_C, V_REF, OMEGA = 30.0, 20.0, 2 * math.pi
SECTION = PoincareSection(index=1, value=0.0, direction=1)


def normal_form(t: float, x: np.ndarray, speed: float) -> np.ndarray:
    """r' = μ r + r³ − r⁵, θ' = ω; fold at V = 25 m/s, Hopf at 30 m/s."""
    r2 = x[0] ** 2 + x[1] ** 2
    g = (speed - V_C) / V_REF + r2 - r2 * r2
    return np.array([g * x[0] - OMEGA * x[1], g * x[1] + OMEGA * x[0]])


def damped_oscillator(zeta: float, omega: float = 2 * math.pi) -> object:
    def rhs(t: float, x: np.ndarray, speed: float) -> np.ndarray:
        return np.array([x[1], -2 * zeta * omega * x[1] - omega**2 * x[0]])
    return rhs


def oscillator_free_response(t: np.ndarray, zeta: float, omega: float) -> np.ndarray:
    """Closed form of x'' + 2ζωx' + ω²x = 0, x(0) = 1, x'(0) = −ζω: e^{−ζωt} cos(ω_d t)."""
    return np.exp(-zeta * omega * t) * np.cos(omega * math.sqrt(1 - zeta**2) * t)


def test_detector_does_not_call_a_weakly_damped_transient_steady():
    zeta, omega = 1e-3, 2 * math.pi * 2.0
    t = np.arange(0.0, 20.0, 1 / 100.0)  # the detector's window: 40 cycles at 100 samples/s
    verdict = detect_limit_cycle(t, oscillator_free_response(t, zeta, omega))
    assert verdict.classification != "steady"
    assert verdict.classification == "decaying", verdict.reason
    # the growth per cycle is minus the logarithmic decrement 2πζ/√(1−ζ²)
    assert verdict.growth_per_cycle == pytest.approx(-2 * math.pi * zeta / math.sqrt(1 - zeta**2), rel=1e-3)
    assert verdict.frequency_hz == pytest.approx(2.0 * math.sqrt(1 - zeta**2), rel=1e-6)
    # the stated limit: a decrement below the tolerance is indistinguishable from a cycle
    slow = detect_limit_cycle(t, oscillator_free_response(t, 1e-5, omega))
    assert slow.classification == "steady"
    assert detect_limit_cycle(t, oscillator_free_response(t, 1e-3, omega),
                              CycleTolerances(growth_per_cycle=1e-2)).classification == "steady"


def test_detector_rest_and_undetermined():
    t = np.linspace(0.0, 10.0, 1001)
    assert detect_limit_cycle(t, 1e-9 * np.sin(2 * math.pi * t)).classification == "rest"
    assert detect_limit_cycle(t, np.exp(-t)).classification == "undetermined"  # no oscillation, not at rest
    assert detect_limit_cycle(t[:150], np.sin(2 * math.pi * t[:150])).classification == "undetermined"  # 1.5 cycles


def test_shooting_without_a_cycle_near_the_guess_fails_with_a_reason():
    below_fold = 24.0  # μ = −0.3: no cycle at all
    orbit = find_periodic_orbit(normal_form, np.array([0.7, 0.0]), below_fold, SECTION, 1.0, 0)
    assert not orbit.converged and orbit.reason
    assert not orbit.stable and math.isnan(orbit.amplitude)
    # a damped oscillator: Newton lands on the equilibrium, which is not an orbit
    focus = find_periodic_orbit(damped_oscillator(0.1), np.array([1.0, 0.0]), 10.0, SECTION, 1.0, 0)
    assert not focus.converged and "equilibrium" in focus.reason
    # a system that never comes back to the section
    def drift(t: float, x: np.ndarray, speed: float) -> np.ndarray:
        return np.array([-x[0], 1.0])
    gone = find_periodic_orbit(drift, np.array([1.0, 0.0]), 10.0, PoincareSection(index=0, value=1.0), 1.0, 0)
    assert not gone.converged and "no return" in gone.reason
    assert math.isnan(gone.period)


def test_continuation_stops_at_the_edge_of_the_speed_range():
    start = find_periodic_orbit(normal_form, np.array([1.0, 0.0]), 33.0, SECTION, 1.0, 0)
    low, high = 27.0, 34.0  # the fold (25 m/s) lies outside
    diagram = continue_periodic_orbit(normal_form, start, SECTION, 0, speed_range=(low, high),
                                      options=ContinuationOptions(speed_scale=V_REF))
    assert "edge of the speed range" in diagram.stop_reason
    assert diagram.folds == () and math.isnan(diagram.fold_speed)
    assert diagram.speed.min() >= low and diagram.speed.max() <= high
    assert diagram.speed.min() - low <= EDGE_TOL * V_REF  # the last step was shortened to end at the edge
    critical = diagram.nonlinear_critical_speed()
    assert not critical.confirmed and math.isnan(critical.speed) and "no fold" in critical.reason
    upwards = continue_periodic_orbit(normal_form, start, SECTION, 0, speed_range=(low, high), direction=1,
                                      options=ContinuationOptions(speed_scale=V_REF))
    assert "edge of the speed range" in upwards.stop_reason and upwards.speed.min() >= 33.0 - 1e-9
    assert high - upwards.speed.max() <= EDGE_TOL * V_REF


def test_continuation_stops_a_given_number_of_points_past_the_fold():
    """Normal form: fold at V = 25 m/s, r² = 1/2 there (closed form); 3 points past it and no more."""
    start = find_periodic_orbit(normal_form, np.array([1.0, 0.0]), 28.0, SECTION, 1.0, 0)
    diagram = continue_periodic_orbit(normal_form, start, SECTION, 0, speed_range=(20.0, 34.0),
                                      options=ContinuationOptions(speed_scale=V_REF, points_after_fold=3))
    assert "points beyond the fold" in diagram.stop_reason
    assert int(np.sum(diagram.branch >= 1)) == 3 and len(diagram.folds) == 1
    assert diagram.fold_speed == pytest.approx(25.0, abs=1e-8)
    assert diagram.folds[0].amplitude == pytest.approx(math.sqrt(0.5), rel=1e-6)
    with pytest.raises(ValueError, match="points_after_fold"):
        ContinuationOptions(points_after_fold=0)


def test_a_fold_outside_the_ramp_bracket_is_not_confirmed():
    verdict_steady = detect_limit_cycle(np.linspace(0, 10, 1001), np.sin(2 * math.pi * np.linspace(0, 10, 1001)))
    verdict_rest = detect_limit_cycle(np.linspace(0, 10, 1001), np.zeros(1001))
    ramp = RampResult(np.array([27.0, 26.0]), (verdict_steady, verdict_rest), np.zeros((2, 2)), 1.0)
    assert ramp.fold_bracket == (26.0, 27.0)
    empty = np.zeros(0)
    fold_at = [25.0]
    diagram = BifurcationDiagram(empty, empty, empty, np.zeros((0, 1), complex), np.zeros(0, bool),
                                 np.zeros(0, int), np.zeros((0, 2)), (Fold(fold_at[0], 0.7, 1.0, np.zeros(2)),),
                                 "test", ramp=ramp)
    critical = diagram.nonlinear_critical_speed()
    assert not critical.confirmed and math.isnan(critical.speed) and "outside" in critical.reason
    assert critical.fold_speed == 25.0


def test_a_model_limit_is_a_verdict_and_the_next_speed_starts_afresh():
    """The normal form's model 'stops applying' beyond r = 1.1 (a stand-in for a wheel lifting in flange contact):
    at 36 m/s the stable cycle r² = (1 + √(1 + 4μ))/2, μ = (V − 30)/20, has r = 1.114 > 1.1, so the ramp records
    a model limit; 34 m/s starts again from x0 and settles on its cycle r = 1.0817 (closed form); the fold of the
    closed form, 25 m/s, is still bracketed."""
    def limited(t: float, x: np.ndarray, speed: float) -> np.ndarray:
        if math.hypot(x[0], x[1]) > 1.1:
            raise ModelLimit(f"r = {math.hypot(x[0], x[1]):.4f} beyond 1.1")
        return normal_form(t, x, speed)

    ramp = speed_ramp(limited, np.array([1.05, 0.0]), np.array([36.0, 34.0, 30.0, 27.0, 26.0, 24.0]),
                      Dwell(seconds=40.0), 0, sample_rate_hz=40.0, settings=IntegrationSettings(rtol=1e-9))
    kinds = [v.classification for v in ramp.verdicts]
    assert kinds[0] == "model_limit" and "beyond 1.1" in ramp.verdicts[0].reason
    assert math.isnan(ramp.verdicts[0].amplitude)
    np.testing.assert_array_equal(ramp.states[0], [1.05, 0.0])  # what the next speed starts from
    mu = (34.0 - V_C) / V_REF
    assert kinds[1] == "steady"
    assert ramp.verdicts[1].amplitude == pytest.approx(math.sqrt((1 + math.sqrt(1 + 4 * mu)) / 2), rel=1e-4)
    assert ramp.fold_bracket == (24.0, 26.0)

    def broken(t: float, x: np.ndarray, speed: float) -> np.ndarray:
        if speed < 30:
            raise ValueError("a bad input, not a model limit")
        return normal_form(t, x, speed)

    with pytest.raises(ValueError, match="bad input"):  # other errors are not swallowed
        speed_ramp(broken, np.array([1.0, 0.0]), np.array([31.0, 29.0]), Dwell(seconds=1.0), 0, sample_rate_hz=40.0)


def test_dwell_in_wavelengths_is_n_lambda_over_v():
    assert Dwell(wavelengths=30, wavelength_m=25.0).duration(50.0) == pytest.approx(30 * 25.0 / 50.0, rel=1e-15)
    assert Dwell(seconds=12.0).duration(80.0) == 12.0


@pytest.mark.parametrize("make, field", [
    (lambda: Dwell(), "dwell"),
    (lambda: Dwell(seconds=1.0, wavelengths=2.0, wavelength_m=1.0), "dwell"),
    (lambda: Dwell(wavelengths=2.0), "wavelength_m"),
    (lambda: PoincareSection(index=0, direction=0), "direction"),
    (lambda: PoincareSection(index=-1), "index"),
    (lambda: IntegrationSettings(method="Euler"), "method"),
    (lambda: IntegrationSettings(rtol=0.0), "rtol"),
    (lambda: CycleTolerances(growth_per_cycle=-1.0), "growth_per_cycle"),
    (lambda: ContinuationOptions(step=1.0, max_step=0.5), "step"),
    (lambda: speed_ramp(normal_form, np.zeros(2), [20.0, 21.0], Dwell(seconds=1.0), 0, sample_rate_hz=10.0),
     "speeds"),
    (lambda: speed_ramp(normal_form, np.zeros(2), [21.0, 20.0], Dwell(seconds=1.0), 5, sample_rate_hz=10.0),
     "coordinate"),
    (lambda: find_periodic_orbit(normal_form, np.zeros(2), 30.0, PoincareSection(index=3), 1.0, 0), "index"),
    (lambda: find_periodic_orbit(normal_form, np.zeros(2), 30.0, SECTION, -1.0, 0), "period_guess"),
    (lambda: detect_limit_cycle(np.arange(10.0), np.arange(9.0)), "values"),
])
def test_bad_arguments_raise_naming_the_field(make, field):
    with pytest.raises(ValueError, match=f"^{field}"):
        make()


def test_unconverged_orbit_cannot_start_a_continuation():
    failed = find_periodic_orbit(damped_oscillator(0.1), np.array([1.0, 0.0]), 10.0, SECTION, 1.0, 0)
    with pytest.raises(ValueError, match="^orbit"):
        continue_periodic_orbit(damped_oscillator(0.1), failed, SECTION, 0, speed_range=(0.0, 20.0))


def test_watched_coordinate_may_be_a_function_of_the_state():
    """h(x) = 2 x: the amplitude doubles (closed-form outer radius r² = (1 + √(1 + 4μ))/2 at μ = −0.1)."""
    speed = 28.0
    r = math.sqrt((1 + math.sqrt(1 + 4 * (speed - V_C) / V_REF)) / 2)
    orbit = find_periodic_orbit(normal_form, np.array([1.0, 0.0]), speed, SECTION, 1.0, lambda x: 2.0 * x[0])
    assert orbit.converged and orbit.amplitude == pytest.approx(2 * r, rel=1e-8)
    ramp = speed_ramp(normal_form, np.array([r, 0.0]), [speed, speed - 0.5], Dwell(seconds=20.0),
                      lambda x: 2.0 * x[0], sample_rate_hz=50.0)
    assert ramp.verdicts[0].classification == "steady"
    assert ramp.verdicts[0].amplitude == pytest.approx(2 * r, rel=1e-4)


def test_a_ramp_that_never_loses_its_cycle_gives_an_empty_unconfirmed_diagram():
    diagram = bifurcation_diagram(normal_form, np.array([1.0, 0.0]), np.arange(33.0, 27.0, -1.0),
                                  Dwell(seconds=15.0), 0, SECTION, sample_rate_hz=40.0)
    assert diagram.ramp.fold_bracket is None and diagram.speed.size == 0
    assert "never lost" in diagram.stop_reason
    critical = diagram.nonlinear_critical_speed()
    assert not critical.confirmed and math.isnan(critical.speed)


def test_results_are_read_only_records_with_tables():
    start = find_periodic_orbit(normal_form, np.array([1.0, 0.0]), 33.0, SECTION, 1.0, 0)
    with pytest.raises(ValueError):
        start.point[0] = 0.0  # read-only
    diagram = continue_periodic_orbit(normal_form, start, SECTION, 0, speed_range=(32.0, 34.0),
                                      options=ContinuationOptions(speed_scale=V_REF))
    with pytest.raises(ValueError):
        diagram.speed[0] = 0.0
    table = diagram.to_pandas()
    np.testing.assert_array_equal(table.speed_m_s, diagram.speed)
    np.testing.assert_array_equal(table.frequency_hz, 1.0 / diagram.period)
    assert len(repr(diagram)) < 600 and diagram == diagram
