"""Certified stability (issue: every hunting crossing found without a speed grid).

The references never call the code they check: the bialternate product against λ_i + λ_j of a dense eigen-solve;
a hand-built family's window against the roots of its Routh–Hurwitz polynomial; decay-rate lines against the
closed-form roots of one oscillator; vehicles against a dense 0.05 m/s scan of the spectral abscissa (computed
here from ``at(speed).eigenvalues()``) refined by ``brentq``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.polynomial import polynomial as P
from scipy.optimize import brentq

from railopt.models import LinearSystem, ParametricSystem
from railopt.models.crossings import bialternate, crossing_speeds, speed_pencil
from railopt.models.stability import critical_speed
from railopt.models.stability_map import stability_map
from railopt.models.vehicle import load_vehicle

# ---------------------------------------------------------------------------------------------- the product


@pytest.mark.parametrize("N", [2, 5, 9])
def test_bialternate_eigenvalues_are_the_pair_sums(N: int) -> None:
    G = np.random.default_rng(N).standard_normal((N, N))
    lam = np.linalg.eigvals(G)
    expected = np.array([lam[i] + lam[j] for i in range(N) for j in range(i)])
    got = np.linalg.eigvals(bialternate(G))
    assert got.shape == expected.shape == (N * (N - 1) // 2,)
    scale = np.max(np.abs(expected))
    for e in expected:  # every pair sum is an eigenvalue of 2G⊙I (and the counts match)
        assert np.min(np.abs(got - e)) <= 1e-10 * scale


# ---------------------------------------------------------------------------------------------- a window
# A 2-DOF family M q'' + (C0 + Cs/S) q' + K q = 0 whose roots cross the imaginary axis twice in (1, 100) m/s:
# stable, an unstable window, stable again (found by a random search; the crossings below are not taken from it).
M2 = np.diag([0.58, 0.8])
C0 = np.array([[0.0077, -0.0037], [0.0049, 0.0069]])
CS = np.array([[2.19, 1.32], [4.31, 2.79]])
K2 = np.array([[2.52, -0.34], [3.52, 6.23]])


def _window_family() -> ParametricSystem:
    return ParametricSystem(M2, C0, K2, C_speed=CS, values=[], names=("x1", "x2"))


def _hurwitz_crossings(lo: float, hi: float) -> np.ndarray:
    """Speeds where the Hurwitz determinant Δ3 = a3 a2 a1 − a3² a0 − a4 a1² of det(M s² + (C0 + u Cs) s + K)
    vanishes (u = 1/S), from the coefficients as polynomials in u: the crossings of a quartic, in closed form."""
    def entry(i, j):
        return {(2, 0): M2[i, j], (1, 0): C0[i, j], (1, 1): CS[i, j], (0, 0): K2[i, j]}

    def mul(a, b):
        out: dict = {}
        for (s1, u1), c1 in a.items():
            for (s2, u2), c2 in b.items():
                out[(s1 + s2, u1 + u2)] = out.get((s1 + s2, u1 + u2), 0.0) + c1 * c2
        return out

    det = mul(entry(0, 0), entry(1, 1))
    for key, value in mul(entry(0, 1), entry(1, 0)).items():
        det[key] = det.get(key, 0.0) - value
    a = [np.zeros(3) for _ in range(5)]
    for (s, u), c in det.items():
        a[s][u] += c
    a0, a1, a2, a3, a4 = a
    delta = P.polysub(P.polysub(P.polymul(P.polymul(a3, a2), a1), P.polymul(P.polymul(a3, a3), a0)),
                      P.polymul(a4, P.polymul(a1, a1)))
    u = P.polyroots(delta)
    u = u[(np.abs(u.imag) < 1e-12) & (u.real > 0)].real
    S = np.sort(1.0 / u)
    return S[(S > lo) & (S < hi)]


def test_a_hand_built_window_has_its_closed_form_ends() -> None:
    exact = _hurwitz_crossings(1.0, 100.0)
    assert len(exact) == 2  # the window
    smap = stability_map(_window_family(), (1.0, 100.0), tol=1e-9)
    assert smap.method == "pencil" and smap.certified and smap.note == ""
    assert [iv.stable for iv in smap.intervals] == [True, False, True]
    np.testing.assert_allclose(smap.crossings, exact, rtol=1e-9)
    table = smap.to_pandas()
    assert list(table["state"]) == ["stable", "unstable", "stable"] and table.attrs["certified"] is True
    # the critical speed is the window's start for every range that contains it, and any range inside the window
    # starts unstable
    for rng in [(1.0, 100.0), (1.0, exact[0] + 0.01), (exact[0] - 0.01, 400.0), (2.0, exact[1] + 50.0)]:
        cs = critical_speed(_window_family(), speed_range=rng, tol=1e-9)
        assert cs.certified and cs.method == "pencil"
        assert cs.speed == pytest.approx(exact[0], rel=1e-9)
    inside = critical_speed(_window_family(), speed_range=(exact[0] + 1.0, exact[1] - 1.0))
    assert inside.unstable_at_lower_end and inside.certified
    beyond = critical_speed(_window_family(), speed_range=(exact[1] + 0.5, 100.0))
    assert beyond.stable_over_range and beyond.certified


def test_a_sampled_grid_can_step_over_the_window_the_pencil_cannot() -> None:
    """The former sampled search on a coarse grid over a wide range misses the window; the pencil does not."""
    exact = _hurwitz_crossings(1.0, 2000.0)

    class Sampled:  # the same family behind a plain at(speed=S): no declared creep term
        def at(self, speed: float) -> LinearSystem:
            return LinearSystem(M2, C0 + CS / speed, K2)

    sampled = critical_speed(Sampled(), speed_range=(1.0, 2000.0), grid=3)
    assert sampled.method == "sampled" and not sampled.certified and sampled.map is None
    certified = critical_speed(_window_family(), speed_range=(1.0, 2000.0))
    assert certified.speed == pytest.approx(exact[0], abs=0.01)
    smap = stability_map(Sampled(), (1.0, 100.0))
    assert smap.method == "sampled" and not smap.certified and "no creep term" in smap.note


# ---------------------------------------------------------------------------------------------- decay-rate lines


@pytest.mark.parametrize("k", [50.0, 0.5])
def test_the_decay_rate_line_of_one_oscillator_in_closed_form(k: float) -> None:
    """m x'' + (c0 + cs/S) x' + k x = 0 against the line Re s = −σ.  Underdamped (c² < 4mk): Re s = −c/(2m) = −σ
    at c = 2mσ; overdamped: the slow real root is −σ where mσ² − cσ + k = 0, c = (mσ² + k)/σ; S = cs/(c − c0).
    The states between the crossings from the roots of the quadratic (numpy.roots)."""
    m, c0, cs, sigma = 2.0, 0.4, 120.0, 0.8 if k > 1 else 0.05
    lines = [(2 * m * sigma, True), ((m * sigma**2 + k) / sigma, False)]  # (damping on the line, underdamped?)
    exact = sorted(cs / (c - c0) for c, under in lines if c > c0 and (c * c < 4 * m * k) == under
                   and 1.0 < cs / (c - c0) < 1000.0)

    def holds(S: float) -> bool:
        return bool(np.max(np.roots([m, c0 + cs / S, k]).real) <= -sigma)

    fam = ParametricSystem([[m]], [[c0]], [[k]], C_speed=[[cs]], values=[], names=("x",))
    smap = stability_map(fam, (1.0, 1000.0), sigma=sigma, tol=1e-9)
    assert smap.certified and len(exact) >= 1
    assert smap.crossings == pytest.approx(exact, rel=1e-9)
    points = [1.0, *exact, 1000.0]
    assert [iv.stable for iv in smap.intervals] == [holds(0.5 * (a + b))
                                                   for a, b in zip(points, points[1:], strict=False)]


def test_speed_independent_roots_are_separated_not_a_singular_pencil() -> None:
    """A free rigid-body coordinate (K q = 0, C q = 0 at every speed: a double root s = 0) and a mode the creep
    never reaches stay out of the pencil; the map of the rest is certified."""
    M = np.eye(3)
    K = np.diag([0.0, 4.0, 9.0])  # x0 free, x1 a plain spring-damper, x2 crept
    C = np.diag([0.0, 0.3, -0.2])
    Cs = np.diag([0.0, 0.0, 10.0])
    fam = ParametricSystem(M, C, K, C_speed=Cs, values=[], names=("x0", "x1", "x2"))
    pen = speed_pencil(fam.at(speed=10.0))
    assert pen.size == 2 and len(pen.constant_roots) == 4
    smap = stability_map(fam, (1.0, 200.0), tol=1e-9)
    assert smap.certified and smap.crossings == pytest.approx([50.0], rel=1e-9)  # c = −0.2 + 10/S = 0
    assert crossing_speeds(pen, (1.0, 200.0)) == pytest.approx([50.0], rel=1e-9)


# ---------------------------------------------------------------------------------------------- vehicles


def _scan_abscissa(view, speeds: np.ndarray) -> np.ndarray:
    out = []
    for S in speeds:
        s = view.at(speed=float(S)).eigenvalues()
        live = s[np.abs(s) > 1e-8 * np.max(np.abs(s))]
        out.append(np.max(live.real))
    return np.array(out)


def _scan_crossings(view, lo: float, hi: float) -> tuple[list[float], list[bool]]:
    """Sign changes of the abscissa on a 0.05 m/s grid, each refined by brentq to 0.01 m/s; and the states."""
    speeds = np.arange(lo, hi + 1e-9, 0.05)
    a = _scan_abscissa(view, speeds)
    unstable = a > 0.0
    crossings = []

    def f(S: float) -> float:
        return float(_scan_abscissa(view, np.array([S]))[0])

    for i in np.nonzero(unstable[1:] != unstable[:-1])[0]:
        crossings.append(brentq(f, speeds[i], speeds[i + 1], xtol=0.01))
    return crossings, [bool(unstable[0])] + [bool(unstable[i + 1]) for i in np.nonzero(
        unstable[1:] != unstable[:-1])[0]]


SD40_PARAMETERS = [
    "secondary_pivot_longitudinal_stiffness", "secondary_pivot_longitudinal_damping", "secondary_lateral_stiffness",
    "secondary_lateral_damping", "sidebearer1_vertical_stiffness", "sidebearer1_longitudinal_stiffness",
    "sidebearer1_lateral_stiffness", "sidebearer1_vertical_damping", "sidebearer1_longitudinal_damping",
    "sidebearer1_lateral_damping", "sidebearer2_vertical_stiffness", "sidebearer2_longitudinal_stiffness",
    "sidebearer2_lateral_stiffness", "sidebearer2_vertical_damping", "sidebearer2_longitudinal_damping",
    "sidebearer2_lateral_damping", "secondary_yaw_stiffness_1", "secondary_yaw_stiffness_2", "secondary_yaw_damping_1",
    "secondary_yaw_damping_2", "lateral_shock_absorber_damping", "rotational_shock_absorber_damping",
    "primary_vertical_stiffness", "primary_vertical_damping_1", "primary_vertical_damping_2", "motor_nose_stiffness",
    "motor_nose_damping"]
COACH_PARAMETERS = ["ksx", "ksy", "ksz", "csx", "csy", "csz", "ksyaw", "karb", "kpx", "kpy", "kpz", "cpx", "cpy",
                    "cpz"]
FLAGSHIP_BOUNDS = {"secondary_lateral_stiffness": (1.0e5, 5.0e6), "sidebearer1_vertical_stiffness": (5.0e6, 2.0e8),
                   "lateral_shock_absorber_damping": (1.0e4, 1.0e6),
                   "rotational_shock_absorber_damping": (1.0e4, 2.0e6)}
ISSUE_CASE = {"secondary_lateral_stiffness": 1e5, "sidebearer1_vertical_stiffness": 1.99e8,
              "lateral_shock_absorber_damping": 3.67e4, "rotational_shock_absorber_damping": 8.11e4}


def _designs(vehicle, names: list[str], corners: int, flagship: int, seed: int) -> list[dict]:
    rng = np.random.default_rng(seed)
    designs = []
    for _ in range(corners):  # each suspension parameter ×0.2 or ×5, the left and right elements alike
        factor = {}
        for n in names:
            side_free = n.replace("sidebearer1", "sidebearer").replace("sidebearer2", "sidebearer").rstrip("_12")
            factor.setdefault(side_free, rng.choice([0.2, 5.0]))
        designs.append({n: vehicle.parameter(n) * factor[n.replace("sidebearer1", "sidebearer").replace(
            "sidebearer2", "sidebearer").rstrip("_12")] for n in names})
    for _ in range(flagship):  # log-uniform in the flagship's bounds
        designs.append({n: math.exp(rng.uniform(math.log(a), math.log(b))) for n, (a, b) in FLAGSHIP_BOUNDS.items()})
    return designs


def _check_against_scan(view, lo: float, hi: float) -> None:
    exact, states = _scan_crossings(view, lo, hi)
    smap = stability_map(view, (lo, hi), tol=0.01)
    assert smap.certified, smap.note
    got = list(smap.crossings)
    # every sign change of the scan is a crossing of the map (within the scan's refinement)
    for c in exact:
        assert min(abs(c - g) for g in got) <= 0.02, (c, got)
    # a map crossing the scan did not see bounds a window narrower than the scan's step
    extra = [g for g in got if min((abs(g - c) for c in exact), default=math.inf) > 0.02]
    for g in extra:
        k = got.index(g)
        neighbour = min(abs(g - got[k - 1]) if k > 0 else math.inf, abs(got[k + 1] - g) if k + 1 < len(got) else
                        math.inf)
        assert neighbour < 0.05, (g, got, exact)
    cs = critical_speed(view, speed_range=(lo, hi), tol=0.01)
    first_up = math.inf if not any(s for s in states[1:]) else None
    if states[0]:
        assert cs.unstable_at_lower_end
    elif first_up is not None:
        assert cs.stable_over_range or all(abs(g - h) < 0.05 for g, h in zip(got[::2], got[1::2], strict=False))
    else:
        up = exact[0]
        assert cs.speed == pytest.approx(up, abs=0.02)
        # the same answer from any range that contains it
        for rng in [(lo, up + 1.0), (max(lo, up - 3.0), 2 * hi)]:
            assert critical_speed(view, speed_range=rng, tol=0.01).speed == pytest.approx(cs.speed, abs=0.011)


def test_the_issue_cases_window_of_the_flagship_design_space() -> None:
    view = load_vehicle("sd40-2").with_parameters(ISSUE_CASE).lateral(track="rigid")
    for rng in [(1.0, 120.0), (1.0, 60.0)]:
        cs = critical_speed(view, speed_range=rng, tol=1e-3)
        assert cs.certified and cs.speed == pytest.approx(27.12, abs=0.01)
    smap = critical_speed(view, speed_range=(1.0, 120.0), tol=1e-3).map
    states = [iv.stable for iv in smap.intervals]
    assert states[:3] == [True, False, True]  # the window 27.12–35.0 m/s, then stable again
    assert smap.intervals[1].end == pytest.approx(35.0, abs=0.01)
    _check_against_scan(view, 1.0, 120.0)


@pytest.mark.slow
@pytest.mark.parametrize("track", ["rigid", "flexible"])
def test_sd40_designs_equal_a_dense_scan(track: str) -> None:
    vehicle = load_vehicle("sd40-2")
    for design in _designs(vehicle, SD40_PARAMETERS, 4 if track == "rigid" else 2, 4 if track == "rigid" else 2,
                           seed=11 if track == "rigid" else 12):
        _check_against_scan(vehicle.with_parameters(design).lateral(track=track), 1.0, 80.0)


@pytest.mark.slow
def test_coach_designs_equal_a_dense_scan() -> None:
    vehicle = load_vehicle("manchester-coach")
    for design in _designs(vehicle, COACH_PARAMETERS, 6, 0, seed=21):
        _check_against_scan(vehicle.with_parameters(design).lateral(track="rigid"), 1.0, 120.0)


def test_the_low_rank_pencil_equals_the_qz_of_the_full_bialternate_pencil() -> None:
    """2B⊙I = L R exactly, and the candidate u from the rank-rN eigenproblem equal those of a QZ of size m, on a random
    low-rank pencil and on the locomotive's flexible-track pencil."""
    from railopt.models.crossings import _pencil_values, bialternate_factors, bialternate_values

    rng = np.random.default_rng(4)
    N, r = 10, 3
    A = rng.standard_normal((N, N))
    B = rng.standard_normal((N, r)) @ rng.standard_normal((r, N))
    L, R = bialternate_factors(B)
    assert L.shape == (N * (N - 1) // 2, r * N)
    np.testing.assert_allclose(L @ R, bialternate(B), atol=1e-12 * np.max(np.abs(bialternate(B))))
    pen = speed_pencil(load_vehicle("sd40-2").lateral(track="flexible").at(speed=30.0))
    for A_, B_ in ((A, B), (pen.A, pen.B)):
        qz = np.sort(_pencil_values(bialternate(A_), bialternate(B_)))
        low = np.sort(bialternate_values(A_, B_, 0.05))
        # QZ also returns numerically infinite eigenvalues (|u| ~ 1e7–1e11, tiny β): compare speeds above 1 mm/s
        qz, low = qz[np.abs(qz) < 1e3], low[np.abs(low) < 1e3]
        assert len(low) == len(qz)
        np.testing.assert_allclose(low, qz, rtol=1e-7)
