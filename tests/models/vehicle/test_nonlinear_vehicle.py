"""The nonlinear vehicle (models/vehicle/nonlinear.py) against railopt's linear model.

Consistency (issue 26 item 4): linearising the nonlinear model at x = 0 with the linear model's conical
geometry and linear creep law gives the linear lateral view's state matrix (4.53), its K and C at speed S, and
its critical speed, to 1e-9 relative.  The linearisation here is a second method, independent of
``NonlinearVehicle.jacobian``: central differences of ``rhs`` with the absolute step H = 1e-5 (m, rad, m/s,
rad/s); at that step the difference to the state matrix is ≤ 1.1e-11 of its largest entry for the three
vehicles (the forces of the conical geometry are polynomial in the states to the order that matters, so the
error is round-off).  Time integration: below the linear critical speed a small disturbance decays at the rate
Re s of the least-damped linear root, above it grows at Re s > 0 until the creep saturation bounds it.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq
from scipy.signal import argrelextrema

from railopt.models.stability import critical_speed
from railopt.models.vehicle import load_vehicle
from railopt.models.vehicle.nonlinear import nonlinear_vehicle
from railopt.models.vehicle.wheelset_forces import (
    ConicalGeometry,
    FlangeSpring,
    SaturatedCreepLaw,
    WheelsetForces,
)

H = 1e-5
VEHICLES = ["single-wheelset", "manchester-coach", "sd40-2"]


def central_differences(model, speed: float) -> np.ndarray:
    n2 = 2 * model.n_dof
    x = np.zeros(n2)
    J = np.empty((n2, n2))
    for j in range(n2):
        e = np.zeros(n2)
        e[j] = H
        J[:, j] = (model.rhs(0.0, x + e, speed) - model.rhs(0.0, x - e, speed)) / (2.0 * H)
    return J


def rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


@pytest.fixture(scope="module", params=VEHICLES)
def pair(request):
    vehicle = load_vehicle(request.param)
    return vehicle, nonlinear_vehicle(vehicle), vehicle.lateral("rigid")


@pytest.mark.parametrize("speed", [12.0, 45.0])
def test_linearisation_is_the_linear_state_matrix(pair, speed: float) -> None:
    """State matrix, K and C at S: the nonlinear model's linearisation equals the linear view's to 1e-9."""
    _, model, view = pair
    assert model.coordinates == view.coordinates
    linear = view.at(speed)
    J = central_differences(model, speed)
    assert rel(J, linear.state_matrix()) < 1e-9
    n = model.n_dof
    assert rel(-model.M @ J[n:, :n], view.K) < 1e-9
    assert rel(-model.M @ J[n:, n:], linear.C) < 1e-9
    # the model's own Jacobian (central differences, its default step) agrees too
    assert rel(model.jacobian(np.zeros(2 * n), speed), linear.state_matrix()) < 1e-9


def test_linearised_critical_speed(pair) -> None:
    """The speed where the linearisation's spectral abscissa crosses zero (Brent on the central-difference
    Jacobian) equals railopt's certified linear critical speed to 1e-9 relative."""
    _, model, view = pair
    cs = critical_speed(view, speed_range=(1.0, 200.0), tol=1e-10)
    assert np.isfinite(cs.speed)

    def abscissa(speed: float) -> float:
        return float(np.max(np.linalg.eigvals(central_differences(model, speed)).real))

    found = brentq(abscissa, 0.9 * cs.speed, 1.1 * cs.speed, xtol=1e-12, rtol=1e-14)
    assert found == pytest.approx(cs.speed, rel=1e-9)


@pytest.mark.parametrize("name", VEHICLES)
def test_full_block_linearisation(name: str) -> None:
    """All coordinates (block "full"): the wheelsets' fore-aft and pitch rows (longitudinal creep (4.40),
    (4.42)) join; the linearisation equals ``vehicle.full()``'s state matrix at 30 m/s to 1e-9."""
    vehicle = load_vehicle(name)
    model = nonlinear_vehicle(vehicle, block="full")
    view = vehicle.full("rigid")
    assert model.coordinates == view.coordinates
    assert rel(central_differences(model, 30.0), view.at(30.0).state_matrix()) < 1e-9


def test_contact_plane_model_linearises_to_the_linear_model_without_contact_angle() -> None:
    """The coach (θ0 = ε = 0): creep in the contact plane with the spin of the inclined contact changes nothing
    to first order, so the physical model's linearisation is the linear model too."""
    vehicle = load_vehicle("manchester-coach")
    wr = vehicle.wheel_rail()
    forces = WheelsetForces(ConicalGeometry.from_wheel_rail(wr), wr.creep, wr.axle_load, plane="contact")
    model = nonlinear_vehicle(vehicle, forces)
    linear = vehicle.lateral("rigid").at(35.0)
    assert rel(central_differences(model, 35.0), linear.state_matrix()) < 1e-9


def test_vectorised_jacobian_at_a_saturated_state() -> None:
    """``jacobian`` pushes its 4n perturbed states through the forces in one call; away from x = 0, with
    saturated creep on a contact table, it equals column-by-column central differences of ``rhs`` (same
    step, so the difference is round-off and the normal-load iteration's 1e-10 W)."""
    from railopt.models.contact.rigid_contact import ContactTable
    from railopt.models.vehicle.wheelset_forces import profile_forces

    vehicle = load_vehicle("manchester-coach")
    wr = vehicle.wheel_rail()
    table = ContactTable.conical(0.15, np.linspace(-0.01, 0.01, 81), r0=wr.r0, e0=wr.e0)
    model = nonlinear_vehicle(vehicle, profile_forces(wr, table, SaturatedCreepLaw(0.3)))
    x = 1e-3 * np.random.default_rng(1).standard_normal(2 * model.n_dof)
    J = model.jacobian(x, 40.0)
    loop = np.empty_like(J)
    for j in range(x.size):
        h = 1e-6 * max(1.0, abs(x[j]))
        e = np.zeros(x.size)
        e[j] = h
        loop[:, j] = (model.rhs(0.0, x + e, 40.0) - model.rhs(0.0, x - e, 40.0)) / (2.0 * h)
    assert rel(J, loop) < 1e-9


def test_errors() -> None:
    vehicle = load_vehicle("single-wheelset")
    with pytest.raises(ValueError, match="rigid track only"):
        nonlinear_vehicle(vehicle, track="flexible")
    with pytest.raises(ValueError, match="block"):
        nonlinear_vehicle(vehicle, block="vertical")
    with pytest.raises(ValueError, match="x: state"):
        nonlinear_vehicle(vehicle).rhs(0.0, np.zeros(3), 20.0)


def envelope_rate(sol, t0: float, t1: float, limit: float = np.inf) -> float:
    """Slope of log|y| through the peaks of |y(t)| in [t0, t1] with |y| < limit (dense output, 1e-5 s grid)."""
    t = np.arange(t0, t1, 1e-5)
    y = np.abs(sol.sol(t)[0])
    i = argrelextrema(y, np.greater)[0]
    keep = y[i] < limit
    return float(np.polyfit(t[i][keep], np.log(y[i][keep]), 1)[0])


def test_decay_below_the_critical_speed() -> None:
    """Single wheelset at 50 m/s (linear critical 74.32 m/s), y0 = 1 mm: DOP853 (rtol 1e-10, atol 1e-13);
    the envelope after 0.5 s (the fast real roots gone) decays at Re s = −3.0812 1/s of the least-damped root,
    within 1e-4 relative."""
    vehicle = load_vehicle("single-wheelset")
    model = nonlinear_vehicle(vehicle)
    s = vehicle.lateral("rigid").at(50.0).eigenvalues()
    sigma = float(np.max(s.real))
    x0 = np.zeros(4)
    x0[model.index("wheelset.v")] = 1e-3
    sol = solve_ivp(model.rhs, (0.0, 3.0), x0, args=(50.0,), method="DOP853", rtol=1e-10, atol=1e-13,
                    dense_output=True)
    assert sol.success
    assert envelope_rate(sol, 0.5, 3.0) == pytest.approx(sigma, rel=1e-4)


def test_growth_above_the_critical_speed_until_saturation() -> None:
    """Single wheelset at 85 m/s with Shen–Hedrick–Elkins saturation (μ = 0.3) and a flange spring (7.5 mm,
    20 MN/m): from y0 = 1e-7 m the envelope grows at Re s = +2.2695 1/s of the linear model (while |y| < 3 µm,
    where the saturation changes the forces by < 0.5 %: within 1e-3), then saturation bounds it: a limit cycle
    of constant amplitude below the flange clearance.  LSODA, rtol 1e-8, atol 1e-12."""
    vehicle = load_vehicle("single-wheelset")
    wr = vehicle.wheel_rail()
    forces = WheelsetForces(ConicalGeometry.from_wheel_rail(wr), wr.creep, wr.axle_load, SaturatedCreepLaw(0.3),
                            flange=FlangeSpring(0.0075, 2e7))
    model = nonlinear_vehicle(vehicle, forces)
    sigma = float(np.max(vehicle.lateral("rigid").at(85.0).eigenvalues().real))
    assert sigma > 0.0
    x0 = np.zeros(4)
    x0[model.index("wheelset.v")] = 1e-7
    sol = solve_ivp(model.rhs, (0.0, 7.0), x0, args=(85.0,), method="LSODA", rtol=1e-8, atol=1e-12,
                    dense_output=True)
    assert sol.success
    assert envelope_rate(sol, 0.3, 3.0, limit=3e-6) == pytest.approx(sigma, rel=1e-3)
    t = np.arange(6.0, 7.0, 1e-5)
    y = np.abs(sol.sol(t)[0])
    peaks = y[argrelextrema(y, np.greater)[0]]
    assert 1e-3 < peaks.max() < 0.0075
    assert np.ptp(peaks) < 1e-6 * peaks.max()
