"""ParameterMap.rows: the parameter vectors of many designs at once equal the one-design map row by row."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from railopt.studies.config import load_study

STUDIES = Path(__file__).resolve().parents[2] / "studies"


@pytest.mark.parametrize("study, model", [("cab_lateral_minimax.toml", "sd40-2"), ("tmd_hinf.toml", "mu0.05")])
def test_rows_equal_the_one_design_map(study, model):
    _, config, _ = load_study(STUDIES / study)
    setup = config.setups()[model]
    variables = config.design.variables
    names = [v.name for v in variables]
    rng = np.random.default_rng(3)
    X = np.array([[rng.uniform(v.lower, v.upper) for v in variables] for _ in range(6)])
    rows = setup.parameter_map.rows(names, X)
    np.testing.assert_array_equal(rows, np.array([setup.parameters(names, x)[0] for x in X]))
    assert rows.shape == (6, len(setup.family.parameters))
