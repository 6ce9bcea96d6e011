"""The flagship's objective surface (studies/cab_lateral_minimax.toml's [[surfaces]]: U over (K2, K3), 21 × 21,
on the bounds and relaxed toward zero stiffness) evaluated in batches (one compiled call for the grid) equals the
same surface evaluated point by point through the problem's own objective, to 1e-12 relative."""

from __future__ import annotations

import numpy as np
import pytest

from railopt.design import objective_surface
from railopt.studies.cli import STUDIES_DIR
from railopt.studies.config import load_study
from railopt.studies.kinds.campaign.problems import campaign_problem


@pytest.fixture(scope="module")
def flagship():
    _, cfg, _ = load_study(STUDIES_DIR / "cab_lateral_minimax.toml")
    setup = next(iter(cfg.setups().values()))
    return cfg, campaign_problem(cfg, setup, "exact", "unconstrained")


def test_flagship_surface_batched_equals_point_by_point(flagship):
    cfg, problem = flagship
    assert problem.has_batch
    (spec,) = cfg.surfaces
    space = problem.space
    base = np.sqrt(np.asarray(space.lower) * np.asarray(space.upper))  # geometric middle of the bounds
    i, j = (space.names.index(name) for name in spec.variables)

    def point(xi: float, xj: float) -> float:
        """U at one point through the problem's own objective (what a solver calls), +inf where refused."""
        x = base.copy()
        x[i], x[j] = xi, xj
        try:
            return problem.value(x)
        except ValueError:
            return np.inf

    for relax in (1.0, spec.relax):
        axes = []
        for name in spec.variables:
            k = space.names.index(name)
            axes.append(np.geomspace(space.lower[k] * relax, space.upper[k], spec.points))
        batched = objective_surface(problem, tuple(spec.variables), axes[0], axes[1], base)
        pointwise = np.array([[point(a, b) for a in axes[0]] for b in axes[1]])  # rows: the second variable
        assert batched.values.shape == pointwise.shape == (spec.points, spec.points)
        finite = np.isfinite(pointwise)
        assert finite.all() or relax != 1.0
        np.testing.assert_array_equal(np.isfinite(batched.values), finite)
        np.testing.assert_allclose(batched.values[finite], pointwise[finite], rtol=1e-12, atol=0)
