"""The bifurcation machinery on a 2-DOF system with a subcritical Hopf, against harmonic balance and brute force.

The system: a self-excited oscillator (a van der Pol-type quintic damping law, negative for small motion when
μ > 0 and for moderate motion through the x1² term) coupled by a spring to a damped second mass::

    x1'' + x1 + k (x1 − x2) − ε (μ + x1² − x1⁴) x1' = 0,
    x2'' + c x2' + w2² x2 + k (x2 − x1) = 0,           μ = (V − V_c)/V_ref.

Nothing here has a closed form; three references that share no code with ``railopt.models.bifurcation``:

* **harmonic balance** (Galerkin on 11 harmonics per coordinate, trigonometric collocation on 96 points so that
  the quintic term is not aliased into the retained harmonics, Newton with a finite-difference Jacobian): the
  cycle family parametrised by the first cosine harmonic A of x1, started from the linear Hopf point; its fold
  is min μ(A) (Brent) — Nayfeh & Mook, *Nonlinear Oscillations* (Wiley 1979), ch. 4 (harmonic balance);
* **brute-force integration** to the attractor (DOP853, rtol 1e-11) for the stable cycle's amplitude and to
  show which cycle attracts and which repels;
* the **monodromy matrix by central differences of the flow** (four pairs of perturbed trajectories over one
  harmonic-balance period) for the Floquet multipliers.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

from railopt.models.bifurcation import (
    ContinuationOptions,
    PoincareSection,
    ShootingOptions,
    continue_periodic_orbit,
    find_periodic_orbit,
)

EPS, K, C, W2 = 0.4, 0.3, 0.3, 1.6
V_C, V_REF = 30.0, 20.0
SECTION = PoincareSection(index=2, value=0.0, direction=-1)  # x1' = 0 decreasing: x1 at its maximum


def rhs(t: float, x: np.ndarray, speed: float) -> np.ndarray:
    mu = (speed - V_C) / V_REF
    x1, x2, v1, v2 = x
    return np.array([v1, v2, -x1 - K * (x1 - x2) + EPS * (mu + x1**2 - x1**4) * v1,
                     -C * v2 - W2**2 * x2 - K * (x2 - x1)])


# ---------------------------------------------------------------- harmonic balance (the independent reference)
H, M = 11, 96
TAU = 2 * np.pi * np.arange(M) / M
HARMONICS = np.arange(1, H + 1)
COS, SIN = np.cos(np.outer(TAU, HARMONICS)), np.sin(np.outer(TAU, HARMONICS))
NC = 2 * H + 1  # a0, a1..aH, b1..bH


def _series(c: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    a0, a, b = c[0], c[1:H + 1], c[H + 1:]
    return (a0 + COS @ a + SIN @ b, -SIN @ (a * HARMONICS) + COS @ (b * HARMONICS),
            -COS @ (a * HARMONICS**2) - SIN @ (b * HARMONICS**2))


def _project(r: np.ndarray) -> np.ndarray:
    return np.r_[r.mean(), 2 * COS.T @ r / M, 2 * SIN.T @ r / M]


def _residual(c1: np.ndarray, c2: np.ndarray, w: float, mu: float) -> np.ndarray:
    """Galerkin residual in τ = ωt (d/dt = ω d/dτ)."""
    x1, d1, dd1 = _series(c1)
    x2, d2, dd2 = _series(c2)
    r1 = w * w * dd1 + x1 + K * (x1 - x2) - EPS * (mu + x1**2 - x1**4) * w * d1
    r2 = w * w * dd2 + C * w * d2 + W2**2 * x2 + K * (x2 - x1)
    return np.r_[_project(r1), _project(r2)]


def _newton(f, u: np.ndarray) -> np.ndarray:
    for _ in range(30):
        r = f(u)
        if np.max(np.abs(r)) < 1e-12:
            return u
        jac = np.column_stack([(f(u + 1e-7 * e) - f(u - 1e-7 * e)) / 2e-7 for e in np.eye(u.size)])
        u = u - np.linalg.solve(jac, r)
    raise AssertionError(f"harmonic balance did not converge: residual {np.max(np.abs(r)):.3g}")


def _by_amplitude(u: np.ndarray, amplitude: float) -> tuple[np.ndarray, np.ndarray, float, float]:
    """Unknowns u = (c1 without a1, b1; c2; ω; μ); a1 = amplitude fixes the size, b1 = 0 the phase."""
    c1 = np.r_[u[0], amplitude, u[1:H], 0.0, u[H:2 * H - 1]]
    return c1, u[2 * H - 1:2 * H - 1 + NC], u[-2], u[-1]


def _by_speed(u: np.ndarray, mu: float) -> tuple[np.ndarray, np.ndarray, float, float]:
    """Unknowns u = (c1 without b1; c2; ω) at fixed μ."""
    c1 = np.r_[u[:H + 1], 0.0, u[H + 1:2 * H]]
    return c1, u[2 * H:2 * H + NC], u[-1], mu


def _linear_hopf() -> tuple[float, float]:
    """μ and ω where the linearised system's eigenvalues cross the imaginary axis."""
    def matrix(mu: float) -> np.ndarray:
        return np.array([[0, 0, 1, 0], [0, 0, 0, 1], [-(1 + K), K, EPS * mu, 0], [K, -(W2**2 + K), 0, -C]])
    mu_h = brentq(lambda m: np.max(np.linalg.eigvals(matrix(m)).real), -0.5, 1.0, xtol=1e-14)
    ev = np.linalg.eigvals(matrix(mu_h))
    return mu_h, float(np.max(np.abs(ev.imag)))


def _half_peak_to_peak(c: np.ndarray) -> float:
    t = np.linspace(0, 2 * np.pi, 4001)
    def x(s: float) -> float:
        return c[0] + np.cos(s * HARMONICS) @ c[1:H + 1] + np.sin(s * HARMONICS) @ c[H + 1:]
    values = np.array([x(s) for s in t])
    top = -minimize_scalar(lambda s: -x(s), bounds=(t[np.argmax(values)] - 0.01, t[np.argmax(values)] + 0.01),
                           method="bounded", options={"xatol": 1e-12}).fun
    bottom = minimize_scalar(x, bounds=(t[np.argmin(values)] - 0.01, t[np.argmin(values)] + 0.01),
                             method="bounded", options={"xatol": 1e-12}).fun
    return (top - bottom) / 2


@pytest.fixture(scope="module")
def harmonic_balance() -> dict[str, object]:
    """The cycle family μ(A) from the Hopf point; its fold; the two cycles at V = 29 m/s."""
    mu_h, w_h = _linear_hopf()
    u = np.zeros(2 * H - 1 + NC + 2)
    u[-2], u[-1] = w_h, mu_h
    amplitudes = np.linspace(0.02, 1.3, 33)
    family = []
    for a in amplitudes:
        u = _newton(lambda v, a=a: _residual(*_by_amplitude(v, a)), u)
        family.append(u.copy())
    mus = np.array([f[-1] for f in family])
    i = int(np.argmin(mus))
    fold = minimize_scalar(lambda a: _newton(lambda v: _residual(*_by_amplitude(v, a)), family[i])[-1],
                           bounds=(amplitudes[i - 1], amplitudes[i + 1]), method="bounded",
                           options={"xatol": 1e-10})
    speed = 29.0
    mu = (speed - V_C) / V_REF
    cycles = {}
    for name, pick in (("outer", lambda m: m[i:]), ("inner", lambda m: m[:i])):
        branch = pick(np.arange(len(family)))
        j = branch[np.argmin(np.abs(mus[branch] - mu))]
        c1, c2, w, _ = _by_amplitude(family[j], amplitudes[j])
        v = _newton(lambda v: _residual(*_by_speed(v, mu)), np.r_[c1[:H + 1], c1[H + 2:], c2, w])
        c1, c2, w, _ = _by_speed(v, mu)
        state = np.array([c1[0] + c1[1:H + 1].sum(), c2[0] + c2[1:H + 1].sum(),
                          w * (c1[H + 1:] * HARMONICS).sum(), w * (c2[H + 1:] * HARMONICS).sum()])  # τ = 0
        cycles[name] = {"amplitude": _half_peak_to_peak(c1), "period": 2 * np.pi / w, "state": state}
    return {"fold_speed": V_C + V_REF * fold.fun, "fold_amplitude_a1": fold.x, "hopf_speed": V_C + V_REF * mu_h,
            "speed": speed, **cycles}


def test_harmonic_balance_reference_is_a_subcritical_hopf(harmonic_balance):
    """Sanity of the reference itself: the fold lies below the linear Hopf speed (subcritical)."""
    assert harmonic_balance["fold_speed"] < harmonic_balance["speed"] < harmonic_balance["hopf_speed"]


def test_shooting_matches_harmonic_balance_on_both_cycles(harmonic_balance):
    speed = harmonic_balance["speed"]
    for name, stable in (("outer", True), ("inner", False)):
        reference = harmonic_balance[name]
        orbit = find_periodic_orbit(rhs, reference["state"], speed, SECTION, reference["period"], 0)
        assert orbit.converged, orbit.reason
        assert orbit.amplitude == pytest.approx(reference["amplitude"], rel=1e-7)
        assert orbit.period == pytest.approx(reference["period"], rel=1e-8)
        assert orbit.stable is stable


def _flow(x0: np.ndarray, speed: float, t_end: float) -> np.ndarray:
    return solve_ivp(rhs, (0.0, t_end), x0, args=(speed,), method="DOP853", rtol=1e-12, atol=1e-14).y[:, -1]


def test_floquet_multipliers_match_the_monodromy_from_differences_of_the_flow(harmonic_balance):
    speed = harmonic_balance["speed"]
    for name in ("outer", "inner"):
        reference = harmonic_balance[name]
        x, period = reference["state"], reference["period"]
        h = 1e-5
        monodromy = np.column_stack([(_flow(x + h * e, speed, period) - _flow(x - h * e, speed, period)) / (2 * h)
                                     for e in np.eye(4)])
        mu_fd = np.linalg.eigvals(monodromy)
        nontrivial = np.delete(mu_fd, np.argmin(np.abs(mu_fd - 1.0)))  # drop the trivial multiplier 1
        orbit = find_periodic_orbit(rhs, x, speed, SECTION, period, 0)
        assert orbit.converged, orbit.reason
        got, want = np.sort_complex(orbit.multipliers), np.sort_complex(nontrivial)
        np.testing.assert_allclose(got, want, atol=1e-5)


def test_brute_force_integration_shows_the_outer_cycle_attracts_and_the_inner_repels(harmonic_balance):
    speed = harmonic_balance["speed"]
    outer, inner = harmonic_balance["outer"], harmonic_balance["inner"]
    t = np.linspace(200.0, 230.0, 6001)
    from_outside = solve_ivp(rhs, (0.0, 230.0), 1.1 * outer["state"], t_eval=t, args=(speed,), method="DOP853",
                             rtol=1e-11, atol=1e-13)
    attractor = (from_outside.y[0].max() - from_outside.y[0].min()) / 2
    orbit = find_periodic_orbit(rhs, outer["state"], speed, SECTION, outer["period"], 0)
    assert orbit.amplitude == pytest.approx(attractor, rel=1e-5)
    # either side of the inner cycle: just outside, the motion grows onto the outer cycle; just inside, it decays
    late = np.linspace(400.0, 430.0, 6001)
    for factor in (1.1, 0.9):
        sol = solve_ivp(rhs, (0.0, 430.0), factor * inner["state"], t_eval=late, args=(speed,), method="DOP853",
                        rtol=1e-10, atol=1e-12)
        amplitude = (sol.y[0].max() - sol.y[0].min()) / 2
        if factor > 1:
            assert amplitude == pytest.approx(outer["amplitude"], rel=1e-4)
        else:
            assert amplitude < 0.5 * inner["amplitude"]


def test_continuation_fold_matches_harmonic_balance(harmonic_balance):
    reference = harmonic_balance["outer"]
    start = find_periodic_orbit(rhs, reference["state"], harmonic_balance["speed"], SECTION, reference["period"], 0)
    diagram = continue_periodic_orbit(rhs, start, SECTION, 0, speed_range=(20.0, 34.0),
                                      options=ContinuationOptions(speed_scale=V_REF),
                                      shooting=ShootingOptions(min_amplitude=0.05),
                                      linear_critical_speed=harmonic_balance["hopf_speed"])
    assert len(diagram.folds) == 1
    assert diagram.fold_speed == pytest.approx(harmonic_balance["fold_speed"], rel=1e-7)
    table = diagram.to_pandas()
    assert table[table.branch == 0].stable.all() and not table[table.branch == 1].stable.any()
    # the unstable branch ends at the linear Hopf speed found from the eigenvalues
    assert "Hopf" in diagram.stop_reason
    assert table.speed_m_s.iloc[-1] == pytest.approx(harmonic_balance["hopf_speed"], abs=0.05)
    assert math.isfinite(diagram.linear_critical_speed)
