"""Nonlinear wheel/rail forces of one wheelset (models/vehicle/wheelset_forces.py).

Independent references: closed forms of the conical geometry (the gravitational stiffness of thesis
(4.43)–(4.46) reduced through the roll constraint (4.7)–(4.8), the yaw gravitational stiffness (4.48), the
longitudinal-creep yaw moment of a rolling-radius difference), the virtual work of a workless rigid contact
(the normal forces' lateral resultant equals −W dh/dy, h the axle height of the rigid contact table), the
friction limit of a saturated law, and the contact package's own Shen–Hedrick–Elkins function.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from railopt.models.contact.creep import CreepCoefficients
from railopt.models.contact.profiles import rail_60e1, s1002
from railopt.models.contact.rigid_contact import ContactTable, WheelsetTrack, rigid_contact_table
from railopt.models.contact.saturation import shen_hedrick_elkins
from railopt.models.vehicle.wheelrail import Creep
from railopt.models.vehicle.wheelset_forces import (
    ConicalGeometry,
    FlangeSpring,
    LinearCreepLaw,
    SaturatedCreepLaw,
    TabulatedGeometry,
    WheelsetForces,
)

W = 1.2e5  # axle load, N
NO_CREEP = Creep(0.0, 0.0)
# SD40-2-like cone (theta0 = epsilon = 0.05) with a non-zero eta, so every term of (4.43)-(4.46) is present
CONE = ConicalGeometry(conicity=0.05, r0=0.5, e0=0.75, theta0=0.05, epsilon=0.05, eta=0.1)


def rates(k: int) -> list[np.ndarray]:
    return [np.zeros(k)] * 5


@pytest.mark.parametrize("plane", ["track", "contact"])
def test_lateral_gravitational_stiffness_closed_form(plane: str) -> None:
    """Normal forces only (no creep): Q_v(y) = −W y [ε/e0 + ψ(η + r0 ε/e0)] exactly, ψ = θ0/(e0 − r0θ0).

    Derivation (independent of the code): Q_l + Q_r = W, Q_l(a_l − r0 t_l) = Q_r(a_r − r0 t_r) (roll balance),
    lateral −Q_l t_l + Q_r t_r with t = θ0 ± εy/e0, a = e0 ∓ ηy — the thesis's W ε/e0 of (4.44) plus ψ times
    its roll-row term (Wη + r0Wε/e0) of (4.46), as the roll constraint (4.7) adds them."""
    f = WheelsetForces(CONE, NO_CREEP, W, plane=plane)
    y = np.array([-0.006, -0.002, 0.001, 0.004, 0.008])
    Q = f.generalized_forces(y, np.zeros(5), *rates(5), speed=30.0)
    g = CONE
    psi = g.theta0 / (g.e0 - g.r0 * g.theta0)
    expected = -W * y * (g.epsilon / g.e0 + psi * (g.eta + g.r0 * g.epsilon / g.e0))
    np.testing.assert_allclose(Q[1], expected, rtol=1e-12)
    np.testing.assert_allclose(Q[2], 0.0, atol=1e-9 * W)  # the roll balance leaves no roll moment


def test_yaw_gravitational_stiffness() -> None:
    """At y = 0 the yawed arms of the normal loads' lateral components give +W e0 θ0 sin γ: the negative yaw
    stiffness −W e0 θ0 of thesis (4.48)."""
    f = WheelsetForces(CONE, NO_CREEP, W, plane="track")
    yaw = np.array([-0.01, 0.002, 0.02])
    Q = f.generalized_forces(np.zeros(3), yaw, *rates(3), speed=30.0)
    np.testing.assert_allclose(Q[4], W * CONE.e0 * CONE.theta0 * np.sin(yaw), rtol=1e-12)


def test_rolling_radius_difference_yaw_moment_from_a_table() -> None:
    """Pure rolling at a shift y: ξx = ∓λy/r0 from the exact radii, yaw moment −2 e0 f11 λ y / r0 (the
    longitudinal-creep couple of (4.15)–(4.16), (4.48)), here through the contact package's conical
    ContactTable (track contacts at ±e0, so the arms are e0 ∓ y and sum to 2e0)."""
    lam, r0, e0, f11 = 0.15, 0.46, 0.75, 8.0e6
    table = ContactTable.conical(lam, np.linspace(-0.01, 0.01, 41), r0=r0, e0=e0)
    f = WheelsetForces(TabulatedGeometry.from_table(table), Creep(f11, 7.0e6), W, LinearCreepLaw(), plane="track")
    y = np.array([-0.0071, 0.0005, 0.0043])
    Q = f.generalized_forces(y, np.zeros(3), *rates(3), speed=40.0)
    np.testing.assert_allclose(Q[4], -2.0 * e0 * f11 * lam * y / r0, rtol=1e-10)


@pytest.fixture(scope="module")
def s1002_uic60() -> tuple[np.ndarray, ContactTable]:
    """S1002 on 60E1 inclined 1:40, nodes y and y ± 1e-6 m for the axle height's derivative."""
    track = WheelsetTrack.symmetric(s1002(), rail_60e1(), inclination=1 / 40)
    ys = np.array([-0.004, 0.002, 0.004, 0.006, 0.0075, 0.009])  # 7.5 mm: flange root (see test_wheel_lift)
    d = 1e-6
    return ys, rigid_contact_table(track, np.sort(np.concatenate([ys - d, ys, ys + d])))


@pytest.mark.parametrize("kind", ["linear", "pchip"])
def test_normal_forces_do_no_virtual_work(s1002_uic60: tuple[np.ndarray, ContactTable], kind: str) -> None:
    """Rigid contact is workless: along the contact constraint (axle height h(y), roll φ(y)) the normal forces'
    resultant satisfies F_y + F_z h' + M_x φ' = 0; with F_z = W and M_x = 0 (the balance), F_y = −W dh/dy.
    h' by central differences (±1e-6 m) of the table's axle height; tread and flange contact (δ = 50° at 9 mm).
    Both interpolants pass through the nodes, where this is checked."""
    ys, table = s1002_uic60
    ys = ys[ys != 0.0075]
    f = WheelsetForces(TabulatedGeometry.from_table(table, kind=kind), NO_CREEP, W, plane="contact")
    z = np.zeros(ys.size)
    state = f.evaluate(ys, z, *rates(ys.size), speed=30.0)
    k = np.searchsorted(table.y, ys)
    dh = (table.axle_height[k + 1] - table.axle_height[k - 1]) / 2e-6
    np.testing.assert_allclose(state.forces[1], -W * dh, rtol=1e-5)
    np.testing.assert_allclose(state.Q.sum(axis=0), W, rtol=1e-12)  # vertical balance
    assert np.max(state.points.angle) > math.radians(45.0)  # the flange is reached: the contact angle rises
    assert state.forces[1][-1] < -0.9 * W  # the flange force from the geometry (no spring)


def test_wheel_lift_at_the_flange_root(s1002_uic60: tuple[np.ndarray, ContactTable]) -> None:
    """At y = 7.5 mm the left contact is on the flange root (δ ≈ 58°) and its normal force's line of action
    passes below the wheelset centre (a cos δ − h sin δ < 0, statics): its roll moment has the sign of the
    right wheel's, so only a negative right-wheel load balances it — the wheel lifts, and the model says so."""
    ys, table = s1002_uic60
    geometry = TabulatedGeometry.from_table(table)
    p = geometry.points(np.array([0.0075]))
    assert p.lateral_arm[0, 0] * np.cos(p.angle[0, 0]) - p.vertical_arm[0, 0] * np.sin(p.angle[0, 0]) < 0.0
    with pytest.raises(ValueError, match="wheel lifts"):
        WheelsetForces(geometry, NO_CREEP, W).generalized_forces([0.0075], [0.0], *rates(1), speed=30.0)


def test_balance_with_saturated_creep(s1002_uic60: tuple[np.ndarray, ContactTable]) -> None:
    """With creep forces (saturated, contact plane) the vertical and roll balances still hold (invariants)."""
    ys, table = s1002_uic60
    f = WheelsetForces(TabulatedGeometry.from_table(table), Creep(9e6, 8e6, 3e3, 2e3), W, SaturatedCreepLaw(0.3))
    k = ys.size - 2  # tread contact: the flange root lifts the far wheel (test_wheel_lift_at_the_flange_root)
    rng = np.random.default_rng(3)
    args = [ys[:k], 0.003 * rng.standard_normal(k)] + [0.05 * rng.standard_normal(k) for _ in range(5)]
    state = f.evaluate(*args, speed=35.0)
    np.testing.assert_allclose(state.Q.sum(axis=0), W, rtol=1e-12)
    np.testing.assert_allclose(state.forces[2], 0.0, atol=1e-9 * W)
    resultant = np.hypot(state.Fx, state.Fy)
    assert np.all(resultant <= 0.3 * state.N * (1 + 1e-9))  # never beyond μN (N converged to 1e-10 W)


def test_saturation_reaches_the_friction_limit() -> None:
    """A yawed wheelset (γ = 0.05 rad, lateral creepage −0.05, spin off): both wheels slide, the lateral force
    is μ W (Shen–Hedrick–Elkins: F = μN for F'/μN ≥ 3).  Its roll moment h μ W shifts load to the right wheel,
    N_r − N_l = h μ W/(e0 cos γ), so the yawed arms leave a yaw moment e0 sin γ μ (N_r − N_l) = μ² h W tan γ."""
    geom = ConicalGeometry(conicity=0.1, r0=0.45, e0=0.75)
    f = WheelsetForces(geom, Creep(10e6, 9e6), W, SaturatedCreepLaw(0.3), plane="contact")
    Q = f.generalized_forces([0.0], [0.05], *rates(1), speed=30.0)
    assert Q[1, 0] == pytest.approx(0.3 * W, rel=1e-12)
    assert Q[4, 0] == pytest.approx(0.3**2 * 0.45 * W * math.tan(0.05), rel=1e-9)


@pytest.mark.parametrize("scaling", [False, True])
def test_saturated_law_against_the_contact_module(scaling: bool) -> None:
    """The force model's SHE law equals :func:`shen_hedrick_elkins` (creep.py signs: f23 → −f23), with the
    coefficients scaled to the load as a Hertz contact (f11, f22 ∝ N^(2/3), f23 ∝ N, f33 ∝ N^(4/3))."""
    creep = Creep(9e6, 8e6, 4e3, 1.5e3)
    law = SaturatedCreepLaw(0.35, load_scaling=scaling)
    rng = np.random.default_rng(7)
    xi_x, xi_y = 2e-3 * rng.standard_normal(20), 2e-3 * rng.standard_normal(20)
    xi_sp = 0.3 * rng.standard_normal(20)
    N0 = 6e4
    N = N0 * rng.uniform(0.3, 2.5, 20)
    k = N / N0 if scaling else np.ones(20)
    ref = [shen_hedrick_elkins(CreepCoefficients(creep.f11 * ki ** (2 / 3), creep.f22 * ki ** (2 / 3),
                                                 -creep.f23 * ki, creep.f33 * ki ** (4 / 3)), a, b, c, n, 0.35)
           for ki, a, b, c, n in zip(k, xi_x, xi_y, xi_sp, N, strict=True)]
    Fx, Fy, Mz = law(creep, xi_x, xi_y, xi_sp, N, N0)
    np.testing.assert_allclose(Fx, [r.Tx for r in ref], rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(Fy, [r.Ty for r in ref], rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(Mz, [r.Mz for r in ref], rtol=1e-12, atol=1e-9)


def test_flange_spring_dead_band() -> None:
    """Optional flange spring: zero inside the clearance, −k(|y| − d) sign(y) outside (stated closed form)."""
    spring = FlangeSpring(clearance=0.0075, stiffness=2e7)
    y = np.array([-0.01, -0.0075, 0.0, 0.007, 0.009])
    np.testing.assert_allclose(spring.force(y), [2e7 * 0.0025, 0.0, 0.0, 0.0, -2e7 * 0.0015])
    geom = ConicalGeometry(conicity=0.1, r0=0.45, e0=0.75)
    f = WheelsetForces(geom, NO_CREEP, W, flange=spring)
    assert f.generalized_forces([0.009], [0.0], *rates(1), speed=20.0)[1, 0] == pytest.approx(-2e7 * 0.0015)


def test_errors() -> None:
    """Bad inputs are refused with the argument named."""
    table = ContactTable.conical(0.1, np.linspace(-0.008, 0.008, 9))
    f = WheelsetForces(TabulatedGeometry.from_table(table), Creep(9e6, 8e6), W, SaturatedCreepLaw(0.3))
    with pytest.raises(ValueError, match="outside the table"):
        f.generalized_forces([0.0085], [0.0], *rates(1), speed=30.0)
    with pytest.raises(ValueError, match="speed"):
        f.generalized_forces([0.0], [0.0], *rates(1), speed=0.0)
    with pytest.raises(ValueError, match="mu"):
        SaturatedCreepLaw(0.0)
    with pytest.raises(ValueError, match="plane"):
        WheelsetForces(CONE, NO_CREEP, W, plane="rail")
    with pytest.raises(ValueError, match="clearance"):
        FlangeSpring(-1e-3, 1e7)


def test_profile_forces_checks_the_rolling_radius(s1002_uic60: tuple[np.ndarray, ContactTable]) -> None:
    """A table and a vehicle contact with different nominal radii are refused (creepages and coefficients would
    disagree); with the same radius the forces are those of the table (zero creep: −W dh/dy as above)."""
    from railopt.models.vehicle.wheelrail import WheelRail
    from railopt.models.vehicle.wheelset_forces import profile_forces

    ys, table = s1002_uic60
    ys = ys[ys != 0.0075]
    wr = WheelRail(conicity=0.2, r0=table.r0, e0=0.75, creep=NO_CREEP, axle_load=W)
    f = profile_forces(wr, table, kind="linear")
    k = np.searchsorted(table.y, ys)
    dh = (table.axle_height[k + 1] - table.axle_height[k - 1]) / 2e-6
    z = np.zeros(ys.size)
    np.testing.assert_allclose(f.generalized_forces(ys, z, *rates(ys.size), speed=30.0)[1], -W * dh, rtol=1e-5)
    with pytest.raises(ValueError, match="rolling radius"):
        profile_forces(WheelRail(conicity=0.2, r0=0.45, e0=0.75, creep=NO_CREEP, axle_load=W), table)
