"""The compiled wheel/rail forces (models/vehicle/wheelset_kernel.py) against independent references.

The physics of the forces is tested in ``test_wheelset_forces.py`` (closed forms, virtual work, the contact
module's saturation law) and ``test_nonlinear_vehicle.py`` (the linearisation is the linear model's state matrix,
the Jacobian equals central differences of ``rhs``); both run through these kernels.  Here: the table
interpolation against scipy's own interpolants, invariants of the batching (K wheelsets at once equal K calls of
one), the compiled right-hand side against the same equations assembled in numpy with ``np.linalg.solve``, and the
errors and refusals of the compiled paths.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from railopt.models.vehicle import load_vehicle
from railopt.models.vehicle.hunting import leading_wheelset, profile_vehicle
from railopt.models.vehicle.nonlinear import nonlinear_vehicle
from railopt.models.vehicle.wheelrail import Creep
from railopt.models.vehicle.wheelset_forces import (
    ConicalGeometry,
    FlangeSpring,
    LinearCreepLaw,
    SaturatedCreepLaw,
    TabulatedGeometry,
    WheelLift,
    WheelsetForces,
    profile_forces,
)

WHEELSET = Path(__file__).parent / "data" / "wheelset-s1002.toml"


@pytest.fixture(scope="module")
def coach():
    return load_vehicle("manchester-coach")


@pytest.fixture(scope="module")
def table(coach):
    return coach.contact_table()


def _fields(geometry: TabulatedGeometry) -> np.ndarray:
    return np.concatenate([geometry.radius, geometry.angle, geometry.lateral_arm, geometry.vertical_arm])  # (8, n)


def test_table_points_equal_scipys_pchip_and_numpys_interp(table) -> None:
    """The kernel evaluates the table's cubics itself; at nodes, between them and at both ends it gives scipy's
    ``PchipInterpolator`` (kind "pchip") and ``np.interp`` (kind "linear") of every field to round-off."""
    y = np.concatenate([table.y[[0, 1, 7, -2, -1]], np.random.default_rng(2).uniform(table.y[0], table.y[-1], 40)])
    for kind in ("pchip", "linear"):
        geometry = TabulatedGeometry.from_table(table, kind=kind)
        fields = _fields(geometry)
        p = geometry.points(y)
        got = np.concatenate([p.radius, p.angle, p.lateral_arm, p.vertical_arm])
        if kind == "pchip":
            expected = PchipInterpolator(geometry.y, fields, axis=1)(y)
        else:
            expected = np.stack([np.interp(y, geometry.y, f) for f in fields])
        scale = np.max(np.abs(fields), axis=1, keepdims=True)
        assert np.max(np.abs(got - expected) / scale) < 1e-13, kind


def test_the_cone_is_its_closed_form() -> None:
    """r = r0 ± λy, tan δ = θ0 ± εy/e0, a = e0 ∓ ηy, h = r0 (left, right)."""
    g = ConicalGeometry(conicity=0.2, r0=0.46, e0=0.75, theta0=0.03, epsilon=0.4, eta=0.05)
    y = np.array([-0.004, 0.0, 0.0065])
    p = g.points(y)
    for side, sigma in enumerate((1.0, -1.0)):
        np.testing.assert_allclose(p.radius[side], 0.46 + sigma * 0.2 * y, rtol=1e-15)
        np.testing.assert_allclose(np.tan(p.angle[side]), 0.03 + sigma * 0.4 * y / 0.75, rtol=1e-14, atol=1e-17)
        np.testing.assert_allclose(p.lateral_arm[side], 0.75 - sigma * 0.05 * y, rtol=1e-15)
    np.testing.assert_array_equal(p.vertical_arm, 0.46)


@pytest.mark.parametrize("law", [LinearCreepLaw(), SaturatedCreepLaw(0.3), SaturatedCreepLaw(0.2, "linear", False)])
@pytest.mark.parametrize("plane", ["contact", "track"])
def test_k_wheelsets_at_once_equal_k_calls_of_one(coach, table, law, plane) -> None:
    """The normal loads of a batch are iterated together (until the largest change is ≤ 1e-10 W), so a batch may
    take more passes than one wheelset alone: the states agree within that tolerance, every field."""
    spring = FlangeSpring(0.003, 1e7)  # active beyond 3 mm: some of the shifts below reach it
    forces = profile_forces(coach.wheel_rail(), table, law, plane=plane, flange=spring)
    rng = np.random.default_rng(5)
    k = 9
    args = [rng.uniform(-0.005, 0.005, k), rng.uniform(-1e-3, 1e-3, k)] + [rng.uniform(-0.02, 0.02, k)
                                                                             for _ in range(5)]
    batch = forces.evaluate(*args, speed=41.0)
    W = coach.wheel_rail().axle_load
    for i in range(k):
        one = forces.evaluate(*[a[i:i + 1] for a in args], speed=41.0)
        np.testing.assert_allclose(one.N[:, 0], batch.N[:, i], rtol=0, atol=1e-9 * W)
        np.testing.assert_allclose(one.forces[:, 0], batch.forces[:, i], rtol=1e-8, atol=1e-9 * W)
        for name in ("xi_x", "xi_y", "xi_sp"):
            np.testing.assert_array_equal(getattr(one, name)[:, 0], getattr(batch, name)[:, i])
    # scalars broadcast to the wheelsets, as numpy would
    np.testing.assert_array_equal(forces.evaluate(args[0], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, speed=41.0).forces,
                                  forces.evaluate(args[0], *[np.zeros(k)] * 6, speed=41.0).forces)


@pytest.mark.parametrize("block", ["lateral", "full"])
def test_compiled_rhs_equals_the_equations_assembled_in_numpy(coach, table, block) -> None:
    """ẋ = (q̇, M⁻¹(Tᵀ Q − C q̇ − K q)) with Q from ``WheelsetForces.generalized_forces`` and M⁻¹ applied by
    ``np.linalg.solve`` (the kernel uses M⁻¹K, M⁻¹C, M⁻¹Tᵀ formed once): equal to round-off."""
    model = nonlinear_vehicle(coach, profile_forces(coach.wheel_rail(), table, SaturatedCreepLaw(0.3)), block=block)
    n = model.n_dof
    rng = np.random.default_rng(11)
    for _ in range(3):
        x = np.concatenate([2e-3 * rng.standard_normal(n), 2e-2 * rng.standard_normal(n)])
        q, qd = x[:n], x[n:]
        k = len(model.wheelsets)
        z, zd = (model.T_rows @ q).reshape(5, k), (model.T_rows @ qd).reshape(5, k)
        Q = model.forces.generalized_forces(z[1], z[4], zd[1], zd[2], zd[4], zd[0], zd[3], 37.0).reshape(-1)
        expected = np.concatenate([qd, np.linalg.solve(model.M, model.T_rows.T @ Q - model.C @ qd - model.K @ q)])
        got = model.rhs(0.0, x, 37.0)
        assert np.max(np.abs(got - expected)) <= 1e-10 * np.max(np.abs(expected))


def test_errors_of_the_compiled_paths_name_their_cause() -> None:
    """A state beyond the table, a wheel that lifts at the flange root (S1002/60E1, 7.5 mm, see
    ``test_wheel_lift_at_the_flange_root``) and a non-positive speed: the same errors from ``rhs``, ``jacobian``
    and ``evaluate``; other geometries and creep laws are refused when the forces are built."""
    vehicle = load_vehicle(WHEELSET)
    model = profile_vehicle(vehicle)
    i = model.index(f"{leading_wheelset(vehicle)}.v")
    x = np.zeros(2 * model.n_dof)
    for y, error, match in ((0.02, ValueError, r"contact table: lateral shift 0.02\d* m outside the table"),
                            (0.0075, WheelLift, "a wheel lifts"), (-0.0075, WheelLift, "a wheel lifts")):
        x[i] = y
        with pytest.raises(error, match=match):
            model.rhs(0.0, x, 30.0)
        with pytest.raises(error, match=match):
            model.jacobian(x, 30.0)
    x[i] = 0.0
    for speed in (0.0, -3.0, float("nan")):
        with pytest.raises(ValueError, match="speed: forward speed must be a positive"):
            model.rhs(0.0, x, speed)
    assert np.all(np.isfinite(model.rhs(0.0, x, 30.0)))  # nothing left behind by the failed calls

    class Cone:
        r0 = 0.46

        def points(self, y):
            return ConicalGeometry(0.2, 0.46, 0.75).points(y)

    class Law:
        load_dependent = False

        def __call__(self, creep, xi_x, xi_y, xi_sp, N, N0):
            return -xi_x, -xi_y, -xi_sp

    with pytest.raises(ValueError, match="geometry: a ConicalGeometry or TabulatedGeometry.*got Cone"):
        WheelsetForces(Cone(), Creep(1e7, 1e7), 1e5)
    with pytest.raises(ValueError, match="creep_law: a LinearCreepLaw or SaturatedCreepLaw.*got Law"):
        WheelsetForces(ConicalGeometry(0.2, 0.46, 0.75), Creep(1e7, 1e7), 1e5, Law())


@pytest.mark.parametrize("law", [LinearCreepLaw(), SaturatedCreepLaw(0.3)])
def test_a_state_that_is_not_finite_is_an_error_not_nan_forces(law) -> None:
    """A NaN passes every comparison of the normal-load iteration unnoticed (numba's max(0, nan) is 0): the kernel
    refuses NaN or infinite states by name instead of returning NaN forces or a 'converged' load."""
    forces = WheelsetForces(ConicalGeometry(0.2, 0.46, 0.75, theta0=0.03, epsilon=0.3), Creep(1e7, 1e7), 1e5, law)
    good = [1e-3, 0.0, 0.01, 0.0, 0.0, 0.0, 0.0]
    assert np.all(np.isfinite(forces.generalized_forces(*good, speed=30.0)))
    for i in range(7):
        for bad in (np.nan, np.inf):
            args = list(good)
            args[i] = [0.0, bad]  # the second of two wheelsets
            with pytest.raises(ValueError, match=r"state: wheelset 1's state \(y, yaw or a rate\) is not finite"):
                forces.generalized_forces(*args, speed=30.0)
    model = profile_vehicle(load_vehicle(WHEELSET))
    x = np.zeros(2 * model.n_dof)
    x[model.n_dof] = np.nan  # a rate
    for call in (lambda: model.rhs(0.0, x, 40.0), lambda: model.jacobian(x, 40.0)):
        with pytest.raises(ValueError, match="is not finite"):
            call()


def test_inputs_the_kernels_do_not_take_are_refused_or_normalised() -> None:
    """Subclasses of the known geometries and laws are refused (the kernels would not read their overrides); a
    speed that is not a number and 2-D wheelset inputs are refused; read-only or strided states give the same
    values through the one compiled signature."""
    from dataclasses import dataclass

    from railopt.models.vehicle import wheelset_kernel

    @dataclass(frozen=True)
    class HalfFriction(SaturatedCreepLaw):
        def __call__(self, *args):
            return tuple(0.5 * v for v in super().__call__(*args))

    class MyCone(ConicalGeometry):
        pass

    with pytest.raises(ValueError, match="creep_law: .*got HalfFriction"):
        WheelsetForces(ConicalGeometry(0.2, 0.46, 0.75), Creep(1e7, 1e7), 1e5, HalfFriction(0.3))
    with pytest.raises(ValueError, match="geometry: .*got MyCone"):
        WheelsetForces(MyCone(0.2, 0.46, 0.75), Creep(1e7, 1e7), 1e5)
    forces = WheelsetForces(ConicalGeometry(0.2, 0.46, 0.75), Creep(1e7, 1e7), 1e5, SaturatedCreepLaw(0.3))
    for speed in ("30", np.array([30.0]), True):
        with pytest.raises(ValueError, match="speed: forward speed must be a positive finite number"):
            forces.generalized_forces(1e-3, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, speed=speed)
    with pytest.raises(ValueError, match=r"speed: .* got -1\.0$"):
        forces.generalized_forces(1e-3, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, speed=-1)
    with pytest.raises(ValueError, match=r"y: one value per wheelset .* shape \(2, 3\)"):
        forces.generalized_forces(np.full((2, 3), 1e-3), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, speed=30.0)
    model = profile_vehicle(load_vehicle(WHEELSET))
    X = 1e-3 * np.random.default_rng(4).standard_normal((2 * model.n_dof, 3))
    x = np.ascontiguousarray(X[:, 1])
    expected_rhs, expected_jac = model.rhs(0.0, x, 40.0), model.jacobian(x, 40.0)
    frozen = x.copy()
    frozen.flags.writeable = False
    for state in (frozen, X[:, 1]):  # read-only; a strided column
        np.testing.assert_array_equal(model.rhs(0.0, state, 40.0), expected_rhs)
        np.testing.assert_array_equal(model.jacobian(state, 40.0), expected_jac)
    assert len(wheelset_kernel.vehicle_rhs.signatures) == 1
    assert len(wheelset_kernel.vehicle_jacobian.signatures) == 1
