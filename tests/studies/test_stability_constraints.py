"""Stability as a design constraint in campaigns (issue 14): the constrained optimum against a dense grid, no
unstable best, the warning on an unstable existing design, the hunting check on a forced vehicle model."""

from __future__ import annotations

import numpy as np
import pytest

from railopt.design import multistart
from railopt.models.stability import abscissa
from railopt.models.stability_rows import root_constraints
from railopt.studies.adapter import stability_target
from railopt.studies.cli import STUDIES_DIR
from railopt.studies.config import load_study
from railopt.studies.kinds.campaign import campaign_problem, warnings

TWO = '''
[[design.variables]]
name = "lateral_shock_absorber_damping"
lower = 5.0e4
upper = 5.6e4
scale = "log"

[[design.variables]]
name = "rotational_shock_absorber_damping"
lower = 1.0e4
upper = 1.5e4
scale = "log"
'''


def two_variable_flagship(tmp_path):
    """The flagship with K2, K3 at the recommended corner and (C13, C15) designed; rigid track, 3 speeds.  U rises
    steeply with C13 where the stability rows are active (dU/dln C13 ≈ U/2), so the box around the constrained
    optimum is narrow enough for a 100 × 100 grid to resolve it to 1e-3."""
    text = (STUDIES_DIR / "cab_lateral_minimax.toml").read_text()
    head, _, rest = text.partition("[[design.variables]]")
    rest = rest[rest.index("[design.options]"):]
    text = head + TWO + "\n" + rest[: rest.index("[report]")]
    text = text.replace("max_operating_speed_mph = 70.0 }",
                        "max_operating_speed_mph = 70.0, parameters = { K2 = 1.0e5, K3 = 2.0e8 } }")
    text = text.replace("speeds = 12 ", "speeds = 3 ")
    text = text.replace("sigma_min = 0.005", 'sigma_min = 0.005\ntracks = ["rigid"]')
    text = text.replace("zeta_min = 0.02", "")  # the decay-rate rows alone
    text = text.replace('start_from = ["existing"]', "start_from = []")
    path = tmp_path / "two.toml"
    path.write_text(text)
    return load_study(path)[1]


@pytest.mark.slow
def test_the_constrained_optimum_is_the_best_feasible_point_of_a_dense_grid(tmp_path) -> None:
    cfg = two_variable_flagship(tmp_path)
    setup = cfg.setups()["sd40-2"]
    problem = campaign_problem(cfg, setup, "exact", "constrained")
    table = multistart(problem, 4, method="slsqp", seed=3, options={"xtol": 1e-10, "ftol": 1e-12, "maxeval": 500})
    best = table[table["success"]].sort_values("value").iloc[0]
    x_opt = best[list(problem.space.names)].to_numpy(float)
    ev = problem.evaluate(x_opt)
    assert problem.constraint_violation(x_opt, ev) <= 1e-9  # every constraint met to its tolerance
    # grids of designs: 40 × 40 log-spaced over the bounds (nothing beats the optimum anywhere) and 30 × 30 within
    # ±8 % of it (the best feasible grid point is within 1e-3 of it); feasible where every root (none is a track
    # mode on rigid track; neutral roots aside) has Re s + σ ≤ 0 — eigenvalues alone — U there
    family = setup.stability["rigid"]
    speeds = stability_target(cfg.stability, setup).speeds
    names = [v.name for v in cfg.design.variables]
    grid = [np.concatenate([np.geomspace(v.lower, v.upper, 40),
                            np.clip(np.geomspace(0.92 * x, 1.08 * x, 30), v.lower, v.upper)])
            for v, x in zip(cfg.design.variables, x_opt, strict=True)]
    params = list(setup.family.parameters)
    rows = [params.index(n) for n in family.parameters]
    g_opt, _ = root_constraints(family, setup.parameters(names, x_opt)[0][rows], speeds, cfg.stability.sigma_min)
    assert np.max(g_opt) <= 1e-9
    objective = campaign_problem(cfg, setup, "exact", "unconstrained")  # U alone, no constraint rows
    # the criterion is every speed from the first row to the last (the rows are exchanged until it holds): a grid
    # design is feasible when Re s + σ ≤ 0 (to the rows' 1e-6 tolerance) on a 0.05 m/s scan of that range
    fine = np.arange(speeds[0], speeds[-1] + 1e-9, 0.05)
    fine = fine[np.argsort(-np.min(np.abs(fine[:, None] - np.asarray(speeds)[None, :]), axis=1))]  # far from rows first

    def feasible(p: np.ndarray, at: np.ndarray) -> bool:  # stops at the first violating speed
        return not any(abscissa(family.at(p[rows], speed=S).eigenvalues()) + cfg.stability.sigma_min > 1e-6
                       for S in at)

    worst_opt = max(abscissa(family.at(setup.parameters(names, x_opt)[0][rows], speed=S).eigenvalues())
                    for S in fine) + cfg.stability.sigma_min
    assert worst_opt <= 1e-6  # the optimum meets the criterion between the rows too
    at_rows = []  # feasible at the rows' speeds (necessary), with U
    for a in grid[0]:
        for b in grid[1]:
            p, _ = setup.parameters(names, np.array([a, b]))
            if feasible(p, np.asarray(speeds)):
                at_rows.append((objective.value([a, b]), p))
    assert len(at_rows) > 100
    grid_best = None
    for value, p in sorted(at_rows, key=lambda vp: vp[0]):  # ascending U: the first feasible over the range
        if feasible(p, fine):
            grid_best = value
            break
    assert grid_best is not None
    assert ev.value <= grid_best * (1 + 1e-9)  # nothing on the grid beats the optimum
    assert abs(ev.value - grid_best) <= 1e-3 * grid_best


@pytest.mark.parametrize("method", ["slsqp", "cobyla", "slp"])
def test_every_constrained_method_takes_the_stability_rows(tmp_path, method: str) -> None:
    """SLSQP (gradients), COBYLA (values only) and SLP (gradients, LP steps) solve the same stability-constrained
    problem: each ends feasible, on the stability boundary (the optimum lies inside the box, held by the roots), at
    the U that SLSQP finds from a dense set of starts."""
    cfg = two_variable_flagship(tmp_path)
    problem = campaign_problem(cfg, cfg.setups()["sd40-2"], "exact", "constrained")
    reference = multistart(problem, 4, method="slsqp", seed=11, options={"xtol": 1e-10, "ftol": 1e-12})
    U_ref = reference[reference["success"]]["value"].min()
    table = multistart(problem, 3, method=method, seed=3)
    best = table[table["success"]].sort_values("value").iloc[0]
    x = best[list(problem.space.names)].to_numpy(float)
    ev = problem.evaluate(x)
    assert problem.constraint_violation(x, ev) <= 1e-8
    setup = cfg.setups()["sd40-2"]
    family = setup.stability["rigid"]
    params = list(setup.family.parameters)
    p = setup.parameters(list(problem.space.names), x)[0][[params.index(n) for n in family.parameters]]
    g_roots, _ = root_constraints(family, p, stability_target(cfg.stability, setup).speeds, cfg.stability.sigma_min)
    assert np.allclose(ev.g[-len(g_roots):], g_roots, rtol=0, atol=1e-12)  # the stability rows come last
    assert float(np.max(g_roots)) <= 1e-6
    # on the stability boundary of the continuum (the rows are exchanged until every speed holds): the largest
    # Re s + σ over a 0.05 m/s scan of the rows' range is zero, to the rows' tolerance and the scan's resolution
    target = stability_target(cfg.stability, setup)
    scan = np.arange(target.speeds[0], target.speeds[-1] + 1e-9, 0.05)
    worst = max(abscissa(family.at(p, speed=S).eigenvalues()) for S in scan) + cfg.stability.sigma_min
    assert -1e-4 <= worst <= 1e-6
    lower, upper = problem.space.lower, problem.space.upper
    assert lower[0] * (1 + 1e-3) < x[0] < upper[0] * (1 - 1e-3)  # C13 held by the roots, not by its bounds
    assert ev.value == pytest.approx(U_ref, rel=1e-6)


COACH = '''
[study]
name = "coach_hunting"
kind = "campaign"

[[models]]
label = "coach"
model = "vehicle_forced"
options = {{ vehicle = "manchester-coach", view = "lateral", speed_m_s = {speed}, track = "rigid", {rest} }}

[objective]
output = "cab.lateral"
band_hz = [0.5, 8.0]

[design]
methods = ["slsqp"]
objectives = ["exact"]
n_starts = 6
seed = 5
{starts}
checks = ["hunting"]

[[design.variables]]
name = "kpx"
lower = 1.0e6
upper = 3.0e8
scale = "log"
'''


def coach_study(tmp_path, speed: float, starts: str = 'start_from = ["existing"]'):
    path = tmp_path / f"coach{speed:g}.toml"
    rest = ('input = { kind = "alignment", amplitude_m = 0.001 }, outputs = ["cab.lateral"], '
            f'quantity = "acceleration", max_operating_speed_m_s = {speed}')
    path.write_text(COACH.format(speed=speed, rest=rest, starts=starts))
    return path


def test_an_existing_design_that_hunts_is_warned_of(tmp_path) -> None:
    _, cfg, _ = load_study(coach_study(tmp_path, 85.0))  # the coach hunts from 79.9 m/s
    found = warnings(cfg)
    assert len(found) == 1
    assert found[0].startswith("models[0] (coach): the existing design fails the 'hunting' check (stable is false")
    _, cfg, _ = load_study(coach_study(tmp_path, 60.0))
    assert warnings(cfg) == []


@pytest.mark.slow
def test_a_campaign_from_an_unstable_design_reports_no_unstable_best(tmp_path) -> None:
    """At 78 m/s, from a design that hunts from 29.5 m/s (kpx = 1 MN/m; the file's 31.4 MN/m is stable to 79.9):
    U is inf for every unstable design (no steady state), the hunting check runs on every optimum of a
    vehicle_forced model, and the best reported design passes it."""
    from railopt.studies.cli import main

    study = coach_study(tmp_path, 78.0, "points = [{ kpx = 1.0e6 }]")
    assert main(["run", str(study), "--results", str(tmp_path / "r"), "--workers", "0", "--no-progress"]) == 0
    import pandas as pd

    out = tmp_path / "r" / "coach_hunting"
    starts = pd.read_csv(out / "starts.csv")
    assert np.isinf(starts.loc[starts["start_id"] == 0, "value"]).all()  # the existing (unstable) start
    optima = pd.read_csv(out / "optima.csv")
    assert "hunting" in optima.columns and "critical_speed_rigid_m_s" in optima.columns
    comparison = pd.read_csv(out / "comparison.csv").iloc[0]
    assert np.isfinite(comparison["true_peak"])
    best = optima[optima["start_id"] == comparison["best_start"]].iloc[0]
    assert bool(best["stable"]) and best["critical_speed_rigid_m_s"] > 78.0
    assert int(comparison["failing_optima"]) == int((~optima["stable"].astype(bool)).sum())


def test_values_first_then_the_jacobian_from_the_same_maxima_and_members(tmp_path, monkeypatch) -> None:
    """The problem's values need no derivative (COBYLA asks for none): no Jacobian is computed for them, and the
    values and Jacobians asked for afterwards are those of one evaluation with both, bit for bit; the Jacobian
    matches central differences."""
    import railopt.studies.adapter as adapter

    config = load_study(STUDIES_DIR / "cab_lateral_minimax.toml")[1]
    config = config.model_copy(update={"stability": config.stability.model_copy(update={"zeta_min": None})})
    setup = config.setups()["sd40-2"]  # the decay-rate rows (the damping rows' Jacobian: test_stability_design)
    problem = campaign_problem(config, setup, "exact")
    x = np.array([3.0e5, 1.0e8, 8.0e4, 5.0e4])
    both = problem.evaluate(x, gradient=True)
    import railopt.models.sensitivity as sensitivity
    import railopt.models.stability_rows as rows_module

    calls, maxima, roots, members = [], [], [], []
    real, real_maxima = adapter.maxima_jacobians, adapter.all_response_maxima
    real_roots, real_members = rows_module.stacked_eigenvalue_derivatives, rows_module._family_rows
    monkeypatch.setattr(adapter, "maxima_jacobians", lambda *a, **k: calls.append(1) or real(*a, **k))
    for module in (adapter, sensitivity):
        monkeypatch.setattr(module, "all_response_maxima", lambda *a, **k: maxima.append(1) or real_maxima(*a, **k))
    monkeypatch.setattr(rows_module, "stacked_eigenvalue_derivatives",
                        lambda *a, **k: roots.append(len(a[1])) or real_roots(*a, **k))  # a[1]: the stack
    monkeypatch.setattr(rows_module, "_family_rows", lambda *a, **k: members.append(1) or real_members(*a, **k))
    fresh = campaign_problem(config, setup, "exact")
    tracks = len(stability_target(config.stability, setup).tracks)
    speeds = len(stability_target(config.stability, setup).speeds)
    values = fresh.evaluate(x, gradient=False)
    # values alone: objective and two stroke peaks, the stability members solved once per track, no derivative
    assert calls == [] and len(maxima) == 3 and roots == [] and len(members) == tracks
    np.testing.assert_array_equal(values.f, both.f)
    np.testing.assert_array_equal(values.g, both.g)
    again = fresh.evaluate(x, gradient=True)
    # the Jacobians from the maxima and the members already solved: root derivatives of all speeds in one stacked
    # call per track
    assert len(calls) == 3 and len(maxima) == 3 and len(members) == tracks and roots == [speeds] * tracks
    np.testing.assert_array_equal(again.df, both.df)
    np.testing.assert_array_equal(again.dg, both.dg)
    h = 1e-6
    row_scale = np.maximum(np.abs(both.g), np.max(np.abs(both.dg * x), axis=1))
    for i in range(len(x)):
        up, down = x.copy(), x.copy()
        up[i] *= 1 + h
        down[i] *= 1 - h
        fd = (fresh.evaluate(up).f - fresh.evaluate(down).f) / (2 * h * x[i])
        live = np.abs(fd) > 1e-8 * np.max(np.abs(fd))
        np.testing.assert_allclose(both.df[live, i], fd[live], rtol=2e-4)
        # strokes and stability rows, as relative sensitivities x_i dg/dx_i; each row to 1e-6 of its own scale
        fd_g = (fresh.evaluate(up).g - fresh.evaluate(down).g) / (2 * h)
        err = np.abs(both.dg[:, i] * x[i] - fd_g)
        assert np.all(err <= 2e-4 * np.abs(fd_g) + 1e-6 * row_scale), (i, np.max(err / row_scale))


def test_maxima_of_another_band_or_method_are_refused() -> None:
    """``maxima_jacobians(..., maxima=...)`` reuses maxima only of the same band and method (else ValueError)."""
    from railopt.models.response_maxima import all_response_maxima
    from railopt.models.sensitivity import maxima_jacobians

    config = load_study(STUDIES_DIR / "cab_lateral_minimax.toml")[1]
    setup = config.setups()["sd40-2"]
    sys_ = setup.family.at(setup.family.values)
    band = (0.1, 18.0)
    thesis = all_response_maxima(sys_, band_rad_s=band, outputs=["cab_acceleration"])
    with pytest.raises(ValueError, match="maxima"):
        maxima_jacobians(sys_, band_rad_s=band, exact=True, outputs=["cab_acceleration"], maxima=thesis)
    with pytest.raises(ValueError, match="maxima"):
        maxima_jacobians(sys_, band_rad_s=(0.1, 9.0), outputs=["cab_acceleration"], maxima=thesis)
    reused = maxima_jacobians(sys_, band_rad_s=band, outputs=["cab_acceleration"], maxima=thesis)
    fresh = maxima_jacobians(sys_, band_rad_s=band, outputs=["cab_acceleration"])
    np.testing.assert_array_equal(reused["cab_acceleration"][1], fresh["cab_acceleration"][1])


def test_a_target_reusing_a_freed_targets_id_is_computed_afresh() -> None:
    """The evaluator keeps each piece with the target it belongs to: a new target object that Python gave a freed
    one's id (simulated by moving the cached piece under the new id) gets its own rows, not the stale ones."""
    from dataclasses import replace

    from railopt.studies.adapter import _Evaluator

    config = load_study(STUDIES_DIR / "cab_lateral_minimax.toml")[1]
    setup = config.setups()["sd40-2"]
    names = [v.name for v in config.design.variables]
    x = np.array([3.0e5, 1.0e8, 8.0e4, 5.0e4])
    first = replace(stability_target(config.stability, setup), speeds=(15.0, 20.0, 25.0), sigma_min=0.0)
    second = replace(first, speeds=(26.0, 28.0, 30.0), sigma_min=0.5)
    evaluator = _Evaluator(setup, names)
    stale = evaluator.stability(x, first)
    for kind in ("stability", "stability rows"):
        evaluator._pieces[(kind, id(second))] = evaluator._pieces.pop((kind, id(first)))
    rows = evaluator.stability(x, second)
    expected = _Evaluator(setup, names)
    np.testing.assert_array_equal(rows, expected.stability(x, second))
    np.testing.assert_array_equal(evaluator.stability_jacobian(x, second), expected.stability_jacobian(x, second))
    assert not np.array_equal(rows, stale)
