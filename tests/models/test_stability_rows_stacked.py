"""The stability rows of one design at all speeds in one stacked eigen-decomposition (issue 25): the roots against
``np.linalg.eigvals`` of each speed's state matrix written here (thesis (4.53)), the root derivatives against
central differences of those reference roots, on the flagship's locomotive and on systems built to break it —
near-repeated roots, free rigid-body (zero) roots, simple and defective, a speed where a pair crosses the
imaginary axis (the Routh–Hurwitz critical speed of a wheelset) and a single speed."""

from __future__ import annotations

import numpy as np
import pytest

from railopt.models import ParameterPart, ParametricSystem
from railopt.models.sensitivity import LEFT_CONDITION
from railopt.models.stability_rows import StabilityRows
from railopt.models.vehicle import load_vehicle

from conftest import routh_hurwitz

FLAGSHIP_SPEEDS = list(np.linspace(15.0, 31.29, 12))  # cab_lateral_minimax.toml: 12 speeds, 15 m/s to 70 mph
FD_STEP = 1e-6  # relative step of the central differences


def state_matrix(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> np.ndarray:
    """G = [[0, I], [−M⁻¹K, −M⁻¹C]] (thesis (4.53)), written here as the independent reference."""
    n = len(M)
    Minv = np.linalg.inv(M)
    return np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])


def reference_roots(family: ParametricSystem, p: np.ndarray, speed: float) -> np.ndarray:
    """All 2n roots of the member's state matrix by ``np.linalg.eigvals``."""
    member = family.at(p, speed=speed)
    return np.linalg.eigvals(state_matrix(member.M, member.C, member.K))


def one_per_mode(roots: np.ndarray, like: np.ndarray) -> np.ndarray:
    """The roots one per mode by the SPEC's order (ascending |Im s|, then Re s; every second), each taken as itself
    or its conjugate, whichever is nearer ``like`` (the two roots of a pair are the same mode)."""
    a = roots[np.lexsort((roots.real, np.abs(roots.imag)))][1::2]
    return np.where(np.abs(a - like) <= np.abs(np.conj(a) - like), a, np.conj(a))


def check_rows(family: ParametricSystem, speeds: list[float], defective_tol: float = 1e-12,
               track_modes: int = 0) -> StabilityRows:
    """Roots, rows and root derivatives of :class:`StabilityRows` against the per-speed references.

    Roots: each to 1e-12 of its own magnitude, in the SPEC's order; a neutral root (|s| ≤ 1e-6·max|s|) to
    ``defective_tol``·max|s| (a defective double zero is only determined to √ε).  Rows: Re s + σ_min, −1 for every
    neutral root and for ``track_modes`` others per speed (the lumped track's modes).  Derivatives p_i ds/dp_i:
    central differences of the real parts of the reference roots (step 1e-6·p_i) on the kept rows, to 1e-6 of the
    largest at that speed."""
    p = np.asarray(family.values, dtype=float)
    rows = StabilityRows(family, p, speeds)
    roots = rows.mode_roots
    assert roots.shape == (len(speeds), family.n)
    g = rows.roots(sigma_min=0.01).reshape(len(speeds), family.n)
    ds = rows.roots_jacobian().reshape(len(speeds), family.n, -1)
    live, kept = np.zeros(roots.shape, dtype=bool), np.zeros(roots.shape, dtype=bool)
    for k, S in enumerate(speeds):
        ref = reference_roots(family, p, S)
        scale = np.max(np.abs(ref))
        expected = one_per_mode(ref, roots[k])
        live[k] = np.abs(expected) > 1e-6 * scale
        err = np.abs(roots[k] - expected)
        assert np.all(err[live[k]] <= 1e-12 * np.abs(expected[live[k]])), (S, np.max(err[live[k]] / scale))
        assert np.all(err[~live[k]] <= defective_tol * scale)
        kept[k] = g[k] != -1.0
        np.testing.assert_allclose(g[k][kept[k]], expected[kept[k]].real + 0.01, rtol=1e-12, atol=1e-12 * scale)
        assert not np.any(kept[k] & ~live[k])  # a neutral (rigid-body) root is a dropped row
        assert np.sum(live[k] & ~kept[k]) == track_modes
    assert np.all(ds[~kept] == 0.0)  # a dropped row has a zero gradient
    np.testing.assert_array_equal(rows.kept, kept)
    for i in range(len(p)):
        h = FD_STEP * abs(p[i])
        up, down = p.copy(), p.copy()
        up[i] += h
        down[i] -= h
        for k, S in enumerate(speeds):
            fd = (one_per_mode(reference_roots(family, up, S), roots[k])
                  - one_per_mode(reference_roots(family, down, S), roots[k])) * p[i] / (2 * h)
            fd_scale = np.max(np.abs(fd[kept[k]]))
            assert np.all(np.abs(ds[k, kept[k], i] * p[i] - fd.real[kept[k]]) <= 1e-6 * fd_scale), (i, S)
    return rows


@pytest.mark.parametrize("track", ["rigid", "flexible"])
def test_the_flagships_rows_at_its_twelve_speeds(track: str) -> None:
    """The locomotive's lateral model with creep (n = 9 rigid, 15 flexible track) at the flagship's 12 speeds."""
    vehicle = load_vehicle("sd40-2")
    family = vehicle.lateral(track).family(["K2", "K3", "C13", "C15"])
    # on flexible track one lumped track mode per wheelset is left out (tests/models/test_stability_design.py)
    check_rows(family, FLAGSHIP_SPEEDS, track_modes=len(vehicle.wheelsets) if track == "flexible" else 0)


def test_near_repeated_roots() -> None:
    """Two equal oscillators coupled by a spring 1e-9 of theirs: each pair of roots 1e-9 apart (relative), both
    moved alike by the parameters (a common stiffness and damping)."""
    k = 4e4
    family = ParametricSystem(np.diag([100.0, 100.0]), np.zeros((2, 2)), 1e-9 * k * np.array([[1.0, -1.0],
                                                                                                [-1.0, 1.0]]),
                              parts={"k": ParameterPart(K=np.eye(2)), "c": ParameterPart(C=np.eye(2))},
                              C_speed=np.diag([2e3, 2e3]), values=[k, 50.0], names=("a.y", "b.y"))
    rows = check_rows(family, [5.0, 20.0, 80.0])
    split = np.abs(np.diff(np.abs(rows.mode_roots.imag), axis=1))[:, 0] / np.abs(rows.mode_roots[:, 0])
    assert np.all((split > 1e-11) & (split < 1e-8))  # the case is what it claims


CHAIN = np.array([[1.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]])  # springs between the bodies, none to ground


def free_chain(C_speed: np.ndarray) -> ParametricSystem:
    """Three bodies joined by springs (no spring to ground: a free rigid-body motion, K singular) and a damper;
    ``C_speed`` the creep damping.  Half the first body's mass is a parameter (the derivatives' ∂M/∂p term)."""
    damper = np.array([[1.0, -1.0, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, 0.0]])
    return ParametricSystem(np.diag([250.0, 300.0, 200.0]), np.zeros((3, 3)), np.zeros((3, 3)),
                            parts={"k": ParameterPart(K=CHAIN), "c": ParameterPart(C=damper),
                                   "m": ParameterPart(M=np.diag([1.0, 0.0, 0.0]))},
                            C_speed=C_speed, values=[2e5, 3e3, 250.0], names=("a.y", "b.y", "c.y"))


def test_a_simple_rigid_body_zero_root() -> None:
    """Creep on the third body damps the free motion: s = 0 is a simple root (its row dropped, −1)."""
    rows = check_rows(free_chain(np.diag([0.0, 0.0, 4e4])), [5.0, 20.0])
    assert np.all(np.sum(rows.roots() == -1.0) == 2)  # one neutral root per speed


def test_a_defective_double_zero_root() -> None:
    """Creep only on the relative motion: the free motion x = a + bt is a Jordan block at s = 0, V is singular to
    rounding (cond₁ above LEFT_CONDITION), so the left vectors come from eig(Gᵀ); the other roots' derivatives
    must not be spoilt by it."""
    family = free_chain(4e4 * np.array([[0.0, 0.0, 0.0], [0.0, 1.0, -1.0], [0.0, -1.0, 1.0]]))
    for S in (5.0, 20.0):  # the case is what it claims
        member = family.at(None, speed=S)
        V = np.linalg.eig(state_matrix(member.M, member.C, member.K))[1]
        assert np.linalg.cond(V, 1) > LEFT_CONDITION
    rows = check_rows(family, [5.0, 20.0], defective_tol=1e-7)  # the zero pair: ±√ε·‖G‖
    assert np.sum(rows.roots() == -1.0) == 2


WHEELSET = dict(m=1500.0, iz=700.0, ky=1e6, kpsi=2e6, f11=10e6, f22=9e6, lam=0.1, e0=0.75, r0=0.45)


def wheelset_family() -> ParametricSystem:
    """An elastically restrained wheelset on rigid track (the model of ``conftest.routh_hurwitz``)."""
    w = WHEELSET
    K0 = np.array([[0.0, -2 * w["f22"]], [2 * w["f11"] * w["e0"] * w["lam"] / w["r0"], 0.0]])
    return ParametricSystem(np.diag([w["m"], w["iz"]]), np.zeros((2, 2)), K0,
                            parts={"ky": ParameterPart(K=np.diag([1.0, 0.0])),
                                   "kpsi": ParameterPart(K=np.diag([0.0, 1.0]))},
                            C_speed=np.diag([2 * w["f22"], 2 * w["f11"] * w["e0"] ** 2]),
                            values=[w["ky"], w["kpsi"]], names=("wheelset.v", "wheelset.gamma"))


def test_a_pair_crossing_the_imaginary_axis() -> None:
    """At the Routh–Hurwitz critical speed V_c (closed form, conftest) the hunting pair sits on the imaginary axis at
    ±i·2π f_c: its row is 0 to rounding, every row is negative at 0.6 V_c and one positive at 1.4 V_c."""
    vc, fc = routh_hurwitz(**WHEELSET)
    speeds = [0.6 * vc, vc, 1.4 * vc]
    rows = check_rows(wheelset_family(), speeds)
    g = rows.roots().reshape(3, 2)
    hunting = np.argmax(g[1])
    s = rows.mode_roots[1, hunting]
    assert abs(s.real) <= 1e-9 * abs(s)
    assert abs(s.imag) == pytest.approx(2 * np.pi * fc, rel=1e-9)
    assert np.all(g[0] < 0) and np.sum(g[2] > 0) == 1


def test_a_single_speed() -> None:
    """One speed is a stack of one (the speed is the member's own: no creep term is moved)."""
    vc, _ = routh_hurwitz(**WHEELSET)
    rows = check_rows(wheelset_family(), [0.8 * vc])
    assert rows.roots().shape == (2,) and rows.roots_jacobian().shape == (2, 2)


def test_two_free_masses_against_their_closed_form() -> None:
    """Two free masses m1, m2 joined by a spring k and a damper c + c_s/S: the free motion is a Jordan block at s = 0
    (V singular to rounding, cond₁ 1e8–1e9: the left vectors from eig(Gᵀ)); the relative motion has the closed form
    s = −c_t/(2μ) ± i√(k/μ − c_t²/(4μ²)), μ = m1 m2/(m1 + m2), c_t = c + c_s/S, so ∂Re s/∂k = 0,
    ∂Re s/∂c = −1/(2μ) and ∂Re s/∂m1 = c_t/(2μ²) · m2²/(m1 + m2)²."""
    e = np.array([[1.0, -1.0], [-1.0, 1.0]])
    m1, m2, k, c, c_s = 2.5, 1.0, 3.0, 0.2, 0.5
    family = ParametricSystem(np.diag([2.0, m2]), np.zeros((2, 2)), np.zeros((2, 2)),
                              parts={"k": ParameterPart(K=e), "c": ParameterPart(C=e),
                                     "dm1": ParameterPart(M=np.diag([1.0, 0.0]))},
                              C_speed=c_s * e, values=[k, c, m1 - 2.0], names=("a.y", "b.y"))
    speeds = [1.0, 5.0, 20.0]
    rows = StabilityRows(family, None, speeds)
    g, J = rows.roots().reshape(3, 2), rows.roots_jacobian().reshape(3, 2, 3)
    mu = m1 * m2 / (m1 + m2)
    for i, S in enumerate(speeds):
        ct = c + c_s / S
        assert g[i, 0] == -1.0  # the free motion: a neutral row
        assert g[i, 1] == pytest.approx(-ct / (2 * mu), rel=1e-12)
        assert abs(rows.mode_roots[i, 1].imag) == pytest.approx(np.sqrt(k / mu - ct**2 / (4 * mu**2)), rel=1e-12)
        expected = [0.0, -1 / (2 * mu), ct / (2 * mu**2) * m2**2 / (m1 + m2) ** 2]
        np.testing.assert_allclose(J[i, 1], expected, rtol=1e-9, atol=1e-12)
        np.testing.assert_array_equal(J[i, 0], 0.0)
