"""Wheel/rail geometry (thesis (4.1)–(4.8)) against an exact numerical solution of circular-arc profiles."""

from __future__ import annotations

import math

import numpy as np
import pytest

from railopt.models.contact import WheelRailGeometry


def _rot(phi: float, v: np.ndarray) -> np.ndarray:
    c, s = math.cos(phi), math.sin(phi)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def _exact_contact(y: float, r0: float, e0: float, d0: float, Rw: float, Rr: float) -> dict[str, float]:
    """Exact rigid wheelset on two circular rail heads (radius Rr) with circular concave treads (radius Rw).

    Independent of the linearisation: the wheelset (lateral y, positive to the LEFT, i.e. y = −v) takes the
    vertical position z and roll φ for which both wheel/rail centre distances equal Rw − Rr (Fig. 4.3).
    Returns contact angles from the horizontal, rolling radii (distance from the axle line) and contact
    positions (distance from the track centre line) of both wheels.
    """
    s, c = math.sin(d0), math.cos(d0)
    D = Rw - Rr
    rail_centre = {"r": np.array([-e0 - Rr * s, -Rr * c]), "l": np.array([e0 + Rr * s, -Rr * c])}
    wheel_centre_body = {"r": np.array([-e0 - Rw * s, -Rw * c - r0]), "l": np.array([e0 + Rw * s, -Rw * c - r0])}

    def residual(u: np.ndarray) -> list[float]:
        z, phi = u
        axle_centre = np.array([y, r0 + z])
        return [
            float(np.linalg.norm(axle_centre + _rot(phi, wheel_centre_body[k]) - rail_centre[k]) - D)
            for k in ("r", "l")
        ]

    u = np.zeros(2)
    for _ in range(20):  # Newton with a forward-difference Jacobian
        f = np.array(residual(u))
        if np.max(np.abs(f)) < 1e-16:
            break
        J = np.column_stack([(np.array(residual(u + 1e-7 * e)) - f) / 1e-7 for e in np.eye(2)])
        u = u - np.linalg.solve(J, f)
    z, phi = u
    assert np.max(np.abs(residual(u))) < 1e-15
    axle_centre = np.array([y, r0 + z])
    out = {"z": z, "phi": phi}
    for side, sign in (("r", 1.0), ("l", -1.0)):
        Cw = axle_centre + _rot(phi, wheel_centre_body[side])
        n = (rail_centre[side] - Cw) / D
        P = rail_centre[side] + Rr * n
        axle = _rot(phi, np.array([1.0, 0.0]))
        q = P - axle_centre
        out["theta_" + side] = math.atan2(sign * n[0], n[1])
        out["r_" + side] = float(np.linalg.norm(q - (q @ axle) * axle))
        out["e_" + side] = abs(float(P[0]))
    return out


CASES = [  # r0, e0, delta0, R_wheel, R_rail (m, rad)
    (0.508, 0.75, 0.05, 0.45, 0.254),  # worn tread on a 10 in rail head
    (0.46, 0.7465, 0.025, 0.33, 0.3),  # close conformity
    (0.5, 0.75, 0.04, 2.0, 0.3),
]


@pytest.mark.parametrize("case", CASES)
def test_circular_profiles_match_exact_geometry(case: tuple[float, ...]) -> None:
    # independent source: central finite differences of the exact geometry; v = −y
    r0, e0, d0, Rw, Rr = case
    g = WheelRailGeometry.from_circular_profiles(r0, e0, d0, Rw, Rr)
    h = 1e-6
    p, m = _exact_contact(h, *case), _exact_contact(-h, *case)
    dv = -2.0 * h
    assert (p["r_r"] - m["r_r"]) / dv == pytest.approx(g.conicity, rel=1e-6)  # (4.5)
    assert (p["r_l"] - m["r_l"]) / dv == pytest.approx(-g.conicity, rel=1e-6)  # (4.6)
    assert e0 * (p["theta_r"] - m["theta_r"]) / dv == pytest.approx(g.epsilon, rel=1e-6)  # (4.1)
    assert e0 * (p["theta_l"] - m["theta_l"]) / dv == pytest.approx(-g.epsilon, rel=1e-6)  # (4.2)
    assert -(p["e_r"] - m["e_r"]) / dv == pytest.approx(g.eta, rel=1e-6)  # (4.3)
    assert (p["e_l"] - m["e_l"]) / dv == pytest.approx(g.eta, rel=1e-6)  # (4.4)
    # roll per unit lateral displacement: exact first order sin δ0 / (e0 cos δ0 − r0 sin δ0); (4.8) is its
    # small-angle form θ0/(e0 − r0 θ0): they agree to O(δ0²)
    roll_rate = abs(p["phi"] - m["phi"]) / (2.0 * h)
    assert roll_rate == pytest.approx(math.sin(d0) / (e0 * math.cos(d0) - r0 * math.sin(d0)), rel=1e-6)
    assert g.psi == pytest.approx(roll_rate, rel=d0**2)


def test_wickens_small_angle_conicity() -> None:
    # published small-angle form: λ = δ0 R_w (e0 + R_r δ0) / ((R_w − R_r)(e0 − r0 δ0)) (Wickens 1965)
    for r0, e0, d0, Rw, Rr in CASES:
        g = WheelRailGeometry.from_circular_profiles(r0, e0, d0, Rw, Rr)
        wickens = d0 * Rw * (e0 + Rr * d0) / ((Rw - Rr) * (e0 - r0 * d0))
        assert g.conicity == pytest.approx(wickens, rel=d0**2)


def test_new_coned_wheels_give_epsilon_equal_lambda() -> None:
    # thesis §4.2.1: "for new wheels ε becomes λ" — coned tread (R_w → ∞) on a knife edge (R_r = 0)
    g = WheelRailGeometry.from_circular_profiles(0.5, 0.75, 0.05, math.inf, 0.0)
    assert g.epsilon == pytest.approx(g.conicity, rel=1e-14)
    assert g.eta == 0.0
    # and the exact limit of a very large tread radius approaches it
    big = WheelRailGeometry.from_circular_profiles(0.5, 0.75, 0.05, 1e9, 0.0)
    assert big.conicity == pytest.approx(g.conicity, rel=1e-8)
    c = WheelRailGeometry.coned(0.5, 0.75, 0.05)
    assert (c.theta0, c.epsilon, c.eta) == (0.05, 0.05, 0.0)


def test_linear_relations_4_1_to_4_8() -> None:
    g = WheelRailGeometry(r0=0.5, e0=0.75, conicity=0.12, theta0=0.05, epsilon=3.0, eta=1.2)
    v, a = 0.003, 0.001
    tr, tl = g.contact_angles(v, a)
    assert tr == pytest.approx(0.05 + 3.0 * v / 0.75 - a) and tl == pytest.approx(0.05 - 3.0 * v / 0.75 + a)
    er, el = g.contact_distances(v)
    assert (er, el) == pytest.approx((0.75 - 1.2 * v, 0.75 + 1.2 * v))
    rr, rl = g.rolling_radii(v)
    assert rr - rl == pytest.approx(2 * 0.12 * v) and rr + rl == pytest.approx(1.0)
    assert g.psi == pytest.approx(0.05 / (0.75 - 0.5 * 0.05))  # (4.8)
    assert g.roll(v) == pytest.approx(-g.psi * v)  # (4.7)
    assert (g.l18, g.l20) == (1.5, 0.5)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"r0": -0.5}, "r0"),
        ({"e0": float("nan")}, "e0"),
        ({"R_wheel": 0.2}, "R_wheel"),
        ({"R_rail": -1.0}, "R_rail"),
        ({"delta0": 2.0}, "delta0"),
    ],
)
def test_bad_input_names_the_argument(kwargs: dict[str, float], name: str) -> None:
    args = {"r0": 0.5, "e0": 0.75, "delta0": 0.05, "R_wheel": 0.45, "R_rail": 0.3} | kwargs
    with pytest.raises(ValueError, match=f"^{name}"):
        WheelRailGeometry.from_circular_profiles(**args)
