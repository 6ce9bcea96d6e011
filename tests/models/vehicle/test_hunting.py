"""The vehicle-level nonlinear hunting analysis (railopt.models.vehicle.hunting).

References: the ramp's verdict logic against hand-built ramps; the steady cycle's indicators against the ramp
detector (a second method for period and amplitude: least squares over the sampled extrema of a long record, not
the section return), the flange onset of the contact table, and Prud'homme's limit by hand arithmetic; the fold
of the continuation against the fine ramp's bracket (two methods, the issue's "agree within the ramp's step").
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from railopt.models.bifurcation import (
    CycleVerdict,
    IntegrationSettings,
    NonlinearCriticalSpeed,
    RampResult,
    detect_limit_cycle,
)
from railopt.models.vehicle import load_vehicle
from railopt.models.vehicle.hunting import (
    HuntingAnalysis,
    HuntingResult,
    cycle_indicators,
    leading_wheelset,
    nonlinear_hunting,
    profile_vehicle,
)

WHEELSET = Path(__file__).parent / "data" / "wheelset-s1002.toml"


def verdict(kind: str, amplitude: float = 1e-3) -> CycleVerdict:
    return CycleVerdict(kind, amplitude, 8.0, 0.0, 0.0, 10, "hand-made")


def result(speeds, kinds, critical: NonlinearCriticalSpeed | None = None) -> HuntingResult:
    ramp = RampResult(np.array(speeds, float), tuple(verdict(k) for k in kinds), np.zeros((len(speeds), 2)), 1.0)
    critical = critical or NonlinearCriticalSpeed(math.nan, math.nan, ramp.fold_bracket, False, "not run")
    return HuntingResult("hand", 80.0, ramp, None, critical, 10.0, "w.v", "hand")


def test_verdict_at_the_required_speed_follows_the_bracket():
    r = result([60, 55, 50, 45], ["steady", "steady", "decaying", "rest"])
    assert r.bracket == (50.0, 55.0)
    assert r.lowest_hunting_speed() == 55.0  # no confirmed fold: the last speed with a steady cycle
    assert r.passes(45.0) is True  # the cycle is lost at 50 ≥ 45: the fold is above 50
    assert r.passes(50.0) is True
    assert r.passes(55.0) is False  # a steady cycle at 55 ≤ 55
    assert r.passes(52.0) is None  # the bracket (50, 55] straddles it, no fold: undecided, never a pass
    confirmed = result([60, 55, 50, 45], ["steady", "steady", "decaying", "rest"],
                       NonlinearCriticalSpeed(51.3, 51.3, (50.0, 55.0), True, "fold inside"))
    assert confirmed.lowest_hunting_speed() == 51.3
    assert confirmed.passes(52.0) is False and confirmed.passes(51.0) is True


def test_a_model_limit_is_not_a_cycle_and_no_cycle_passes():
    r = result([90, 80, 70], ["model_limit", "decaying", "rest"])
    assert r.bracket is None and r.lowest_hunting_speed() == math.inf
    assert r.passes(100.0) is None  # a speed the model could not follow: not a pass
    quiet = result([90, 80, 70], ["decaying", "rest", "rest"])
    assert quiet.passes(100.0) is True


def test_settings_refuse_bad_values_naming_the_field():
    for kwargs, field in [({"initial_amplitude": 3.0}, "initial_amplitude"), ({"rtol": -1.0}, "rtol"),
                          ({"step": math.inf}, "step"), ({"search": (50.0, 10.0)}, "search"),
                          ({"max_points": 0}, "max_points"), ({"method": "Euler"}, "method")]:
        with pytest.raises(ValueError, match=field):
            HuntingAnalysis(**kwargs)


def test_profile_vehicle_needs_a_wheel_rail_table():
    with pytest.raises(ValueError, match=r"\[wheel_rail\]"):
        profile_vehicle(load_vehicle("single-wheelset"))


def test_the_leading_wheelset_is_the_one_furthest_forward():
    coach = load_vehicle("manchester-coach")
    xs = {b.name: b.cg[0] for b in coach.bodies if b.kind == "wheelset"}
    assert leading_wheelset(coach) == max(xs, key=xs.get)
    with pytest.raises(ValueError, match="no wheelsets"):
        leading_wheelset(type("V", (), {"bodies": (), "name": "empty"})())


def test_cycle_indicators_against_the_ramp_detector_and_the_table():
    vehicle = load_vehicle(WHEELSET)
    nv = profile_vehicle(vehicle)
    watched = "wheelset.v"
    i = nv.index(watched)
    x0 = np.zeros(2 * nv.n_dof)
    x0[i] = 0.9e-3
    settings = IntegrationSettings(method="RK45", rtol=1e-7, atol=1e-10)
    speed = 50.0
    settled = solve_ivp(nv.rhs, (0.0, 4.0), x0, args=(speed,), **settings.options()).y[:, -1]
    ind = cycle_indicators(nv, vehicle, speed, settled, watched, settings)
    # the detector on a sampled 2 s record (least squares over the extrema)
    t = np.linspace(0.0, 2.0, 4001)
    record = solve_ivp(nv.rhs, (0.0, 2.0), settled, args=(speed,), t_eval=t, **settings.options())
    seen = detect_limit_cycle(record.t, record.y[i])
    assert seen.classification == "steady"
    assert ind.period == pytest.approx(1.0 / seen.frequency_hz, rel=1e-4)
    assert ind.peak_displacement == pytest.approx(np.max(np.abs(record.y[i])), rel=2e-3)
    table = vehicle.contact_table()
    assert ind.flange_clearance == table.flange_onset()
    assert ind.flange_use == pytest.approx(ind.peak_displacement / table.flange_onset(), rel=1e-12)
    # Prud'homme / 2 by hand: P = 98 066.5 N, (10 000 + P/3)/2 N
    assert ind.sum_y_limit == pytest.approx((10_000.0 + 98_066.5 / 3.0) / 2.0, rel=1e-12)
    assert ind.sum_y_ratio == pytest.approx(ind.sum_y_rms / ind.sum_y_limit, rel=1e-12)
    # ΣY of a wheelset with no lateral suspension force other than its spring is of the order of k·y plus inertia:
    # its r.m.s. lies between the spring's share and the total gravitational + creep force bound
    assert 0.0 < ind.sum_y_rms < 0.5 * vehicle.wheel_rail().axle_load
    assert 0.0 < ind.derailment_quotient < 0.8


@pytest.mark.slow
def test_wheelset_fold_from_continuation_lies_in_the_fine_ramp_bracket():
    """The issue's must-show on the wheelset of the S1002/60E1 docs study: the continuation's fold (shooting with
    Newton on the Poincaré map, continued through the turning point) and the descending ramp's bracket agree
    within the ramp's step, below the linear critical speed."""
    vehicle = load_vehicle(WHEELSET)
    analysis = HuntingAnalysis(top_speed=50.0, step=2.5, fine_step=0.5, lowest_speed=40.0, initial_amplitude=2e-3,
                               max_points=120, points_after_fold=3)
    r = nonlinear_hunting(vehicle, analysis)
    low, high = r.bracket
    assert high - low <= 0.5 + 1e-9
    assert r.critical.confirmed, r.critical.reason
    assert low <= r.critical.speed <= high
    assert r.critical.speed < r.linear_critical_speed
    # the branch turns at the fold: stable before it, the multiplier through +1 after it
    d = r.diagram
    assert d.stable[0] and not d.stable[-1] and int(np.sum(d.branch >= 1)) == 3
    assert np.all(np.diff(d.speed[: np.argmin(d.speed) + 1]) < 0)
    # the ramp's cycle at its last steady speed is the continuation's first point (two methods, one cycle)
    assert d.amplitude[0] == pytest.approx(r.ramp.verdicts[r.ramp.last_steady].amplitude, rel=2e-3)
