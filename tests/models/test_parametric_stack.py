"""ParametricSystem.stack: B members at once equal the members ``at`` builds one by one (the same sums)."""

from __future__ import annotations

import numpy as np
import pytest

from railopt.models.units import INCH
from railopt.models.vehicle.irregularity import Irregularity


@pytest.fixture(scope="module")
def forced_family(sd40):
    """The locomotive's full lateral family on rigid track (creep: a speed term), forced by a delayed alignment at
    every axle, with three designed suspension parameters."""
    view = sd40.lateral("rigid", speed=20.0)
    names = list(view.family().parameters)[:3]
    return view.family(names, input=Irregularity("alignment", 0.25 * INCH), outputs=["cab.lateral"],
                       quantity="acceleration")


def test_each_stacked_member_equals_the_member_built_alone(forced_family):
    rng = np.random.default_rng(5)
    base = np.asarray(forced_family.values, dtype=float)
    P = base * rng.uniform(0.5, 2.0, size=(7, base.size))
    for speed in (12.0, 30.0):
        stack = forced_family.stack(P, speed=speed)
        assert stack.M.shape == stack.C.shape == stack.K.shape == (7, forced_family.n, forced_family.n)
        assert len(stack) == 7 and stack.delays.size >= 2  # six axles: distinct delays d/S
        w = np.linspace(0.5, 20.0, 9)
        for b, p in enumerate(P):
            alone = forced_family.at(p, speed=speed)
            for name in ("M", "C", "K"):
                np.testing.assert_allclose(getattr(stack, name)[b], getattr(alone, name), rtol=1e-15, atol=0.0)
            member = stack.member(b)
            np.testing.assert_allclose(member.forcing.values(w), alone.forcing.values(w), rtol=1e-13)
            np.testing.assert_allclose(member.frf_outputs(omega_rad_s=w), alone.frf_outputs(omega_rad_s=w),
                                       rtol=1e-12)


def test_a_stack_refuses_a_malformed_parameter_array(forced_family):
    with pytest.raises(ValueError, match="^P: expected a finite"):
        forced_family.stack(np.ones(3))
    with pytest.raises(ValueError, match="^P: expected a finite"):
        forced_family.stack(np.full((2, 3), np.nan))


def test_a_stack_needs_polynomial_forcing():
    from conftest import base_excited_parametric

    family = base_excited_parametric()  # callable forcing terms
    with pytest.raises(ValueError, match="callable terms"):
        family.stack(np.ones((2, 3)))
