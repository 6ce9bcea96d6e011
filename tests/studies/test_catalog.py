"""The model catalog: one setup shape for every model, typed checks, one hunting check for every vehicle model."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from railopt.models.stability import critical_speed, least_damping
from railopt.studies.catalog import CheckResult, ModelRef, discover_models
from railopt.studies.config import ConfigError, load_study
from railopt.studies.output.writer import Writer

VEHICLE_MODELS = {
    "vehicle_lateral": {"vehicle": "sd40-2", "track": "rigid"},
    "vehicle_forced": {"vehicle": "sd40-2", "view": "lateral", "input": {"kind": "alignment"}, "outputs": ["body.v"]},
    "cab_lateral": {"vehicle": "sd40-2"},
}


def test_every_bundled_model_is_discovered():
    assert {"tmd", *VEHICLE_MODELS} <= set(discover_models())


@pytest.mark.parametrize("model", sorted(VEHICLE_MODELS))
def test_every_vehicle_model_has_the_hunting_and_abscissa_checks(model):
    setup = ModelRef(label="m", model=model, options=VEHICLE_MODELS[model]).setup()
    assert {"hunting", "spectral_abscissa"} <= set(setup.checks)
    assert setup.stability, "a vehicle model has stability families"
    for family in setup.stability.values():
        assert family.has_speed
        assert set(family.parameters) <= set(setup.family.parameters)
    np.testing.assert_array_equal(setup.defaults, setup.family.values)
    assert all(setup.named_designs["existing"][n] == v for n, v in zip(setup.family.parameters, setup.defaults,
                                                                         strict=True))


def test_the_tmd_has_no_stability_family_and_a_typed_abscissa_check():
    setup = ModelRef(label="m", model="tmd", options={"mass_ratio": 0.1}).setup()
    assert setup.stability == {}
    result = setup.checks["spectral_abscissa"](setup.defaults)
    assert isinstance(result, CheckResult)
    assert result.flags == {"stable": True} and result.value < 0
    assert setup.checks["spectral_abscissa"].flag_names == ("stable",)


def test_hunting_check_is_the_critical_speed_of_the_stability_family():
    setup = ModelRef(label="m", model="vehicle_lateral",
                     options={"vehicle": "sd40-2", "track": "rigid", "max_operating_speed_m_s": 20.0,
                              "critical_search_m_s": [2.0, 80.0]}).setup()
    result = setup.checks["hunting"](setup.defaults)
    model = setup.stability_model(setup.defaults)
    expected = critical_speed(model, speed_range=(2.0, 80.0), tol=0.01, grid=16).speed
    assert result.value == expected == result.data["critical_speed_rigid_m_s"]
    # the least damping ratio: the 24-speed samples refined by Brent, so never above them, and within a dense scan's
    zeta = result.data["least_damping_rigid"]
    dense = least_damping(model, np.linspace(2.0, 20.0, 1801))
    assert zeta <= least_damping(model, np.linspace(2.0, 20.0, 24)) and zeta <= dense + 1e-12
    assert zeta == pytest.approx(dense, abs=1e-5)
    assert result.data["required_speed_m_s"] == 20.0
    assert result.flags == {"stable": bool(expected > 20.0 and zeta > 0), "certified": True}
    assert list(result.payload()) == ["critical_speed_rigid_m_s", "least_damping_rigid",
                                      "least_damping_speed_rigid_m_s", "required_speed_m_s", "sigma_min", "zeta_min",
                                      "stable", "certified"]


def test_hunting_check_states_the_study_criterion_and_fails_a_design_between_rows():
    """With a decay-rate margin, ``stable`` needs Re s ≤ −σ at every speed up to the required one (certified), not
    at grid speeds: a margin just above the design's largest Re s (from a dense scan) fails it."""
    setup = ModelRef(label="m", model="vehicle_lateral",
                     options={"vehicle": "sd40-2", "track": "rigid", "max_operating_speed_m_s": 30.0,
                              "critical_search_m_s": [2.0, 80.0]}).setup()
    model = setup.stability_model(setup.defaults)
    def largest_real_part(S: float) -> float:
        s = model.at(speed=S).eigenvalues()
        return float(np.max(s[np.abs(s) > 1e-8 * np.max(np.abs(s))].real))

    largest = max(largest_real_part(S) for S in np.linspace(10.0, 30.0, 2001))
    assert largest < 0
    check = setup.checks["hunting"]
    met = check.with_criterion(sigma_min=-largest * 0.99, zeta_min=None, lowest_speed=10.0, max_speed=30.0)
    missed = check.with_criterion(sigma_min=-largest * 1.01, zeta_min=None, lowest_speed=10.0, max_speed=30.0)
    assert met(setup.defaults).flags == {"stable": check(setup.defaults).value > 30.0, "certified": True}
    assert missed(setup.defaults).flags == {"stable": False, "certified": True}
    strict = check.with_criterion(sigma_min=0.0, zeta_min=0.99, lowest_speed=10.0, max_speed=30.0)
    assert strict(setup.defaults).flags["stable"] is False


def test_parameter_map_aliases_and_jacobian():
    setup = ModelRef(label="m", model="cab_lateral", options={"vehicle": "sd40-2"}).setup()
    alias, element = next(iter(setup.parameter_map.aliases.items()))
    p, J = setup.parameters([alias], np.array([123.0]))
    k = list(setup.family.parameters).index(element)
    assert p[k] == 123.0 and J[k, 0] == 1.0 and np.count_nonzero(J) == 1
    assert alias in setup.designable


def test_a_method_name_is_checked_against_the_design_registry(tmp_path):
    from railopt.studies.cli import STUDIES_DIR

    text = (STUDIES_DIR / "tmd_hinf.toml").read_text()
    assert 'methods = ["slsqp"]' in text
    study = tmp_path / "bad.toml"
    study.write_text(text.replace('methods = ["slsqp"]', 'methods = ["newton"]'))
    with pytest.raises(ConfigError, match=r"design.methods.0: .*unknown method 'newton'; known: \["):
        load_study(study)


def test_tables_are_written_at_full_precision(tmp_path):
    df = pd.DataFrame({"x": [1 / 3, np.pi * 1e-300, 2.0 ** 0.5 * 1e300], "n": [1, 2, 3]})
    writer = Writer(tmp_path)
    assert writer.table(df, "t") == ["t.csv"] and writer.files == ["t.csv"]
    back = pd.read_csv(tmp_path / "t.csv")
    np.testing.assert_array_equal(back["x"].to_numpy(), df["x"].to_numpy())
