"""Steady state of the track beam under a constant load moving at constant speed (3.25–3.30, App. A.2).

In the moving coordinate ``ξ = x − v t`` (positive ahead of the load) the deflection satisfies (3.26)::

    EI y'''' + (N + m v²) y'' − c v y' + k y = P δ(ξ)

Two independent solutions are provided:

``closed``
    From the four characteristic roots of ``EI r⁴ + (N + m v²) r² − c v r + k = 0`` (A.2.3): the two
    roots with negative real part build the solution ahead of the load (ξ > 0), the two with positive
    real part the solution behind it (ξ < 0); the four constants follow from continuity of
    ``y, y', y''`` at ξ = 0 and the shear jump ``EI [y''']₀ = P`` (A.2.10–A.2.11; the thesis's
    ``−P/EI`` belongs to deflection measured against the load).
``fourier``
    The Fourier integral ``y(ξ) = (P/2π) ∫ e^{iκξ} / D(κ) dκ`` with
    ``D(κ) = EI κ⁴ − (N + m v²) κ² + k − i c v κ``, folded onto κ > 0 and evaluated with adaptive
    oscillatory quadrature (QUADPACK QAWO on finite pieces split at the peaks of 1/|D|, QAWF on the
    tail); it never uses the roots.

Undamped beam above the critical velocity: the four roots are imaginary and the steady state is not
unique.  The closed form applies the radiation condition as the limit c → 0⁺ (limiting absorption):
each imaginary root is assigned to the side towards which it moves when a little damping is added,
``Re(dr/dc) = Re(v r / p'(r))``.  At ``v = v_cr`` exactly with ``c = 0`` the response is unbounded
(resonance) and a ``ValueError`` naming ``v`` is raised.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import integrate, optimize

from railopt.models.peak_search import grid_maximum
from railopt.models.track.beam import Beam
from railopt.records import ArrayRecord

_METHODS = ("closed", "fourier")


def _check_load(P: float, v: float) -> tuple[float, float]:
    P = float(P)
    v = float(v)
    if not math.isfinite(P):
        raise ValueError(f"P: must be a finite number, got {P!r}")
    if not math.isfinite(v):
        raise ValueError(f"v: must be a finite number, got {v!r}")
    if v < 0.0:
        raise ValueError(f"v: must be non-negative (the load moves towards +x), got {v!r}")
    return P, v


def _check_xi(xi: np.ndarray | float, name: str = "xi") -> np.ndarray:
    arr = np.asarray(xi, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: must contain finite values only")
    return arr


def characteristic_roots(beam: Beam, v: float) -> np.ndarray:
    """Roots of the characteristic equation (A.2.3) ``EI r⁴ + (N + m v²) r² − c v r + k = 0``.

    Parameters
    ----------
    beam : Beam
        The track beam.
    v : float
        Load speed, m/s (>= 0).

    Returns
    -------
    numpy.ndarray
        The four complex roots, 1/m, sorted by real part.
    """
    _, v = _check_load(0.0, v)
    b = beam.beta
    # scaled variable s = r / β: (k/4)(s⁴ + 4 a s² − 4 e s + 4) with a, e dimensionless
    a = (beam.N + beam.m * v * v) * b * b / beam.k
    e = beam.c * v * b / beam.k
    s = np.roots([1.0, 0.0, 4.0 * a, -4.0 * e, 4.0])
    # one Newton polish step on the unscaled polynomial for full accuracy
    r = s * b
    coeff = np.array([beam.EI, 0.0, beam.N + beam.m * v * v, -beam.c * v, beam.k])
    dcoeff = np.polyder(coeff)
    for _ in range(2):
        r = r - np.polyval(coeff, r) / np.polyval(dcoeff, r)
    return r[np.argsort(r.real)]


@dataclass(frozen=True, eq=False, repr=False)
class ClosedFormSolution(ArrayRecord):
    """The closed-form steady state as sums of exponentials (A.2.10).

    ``y(ξ) = Σ A_j exp(r_j ξ)`` for ξ > 0 (``roots_ahead``, Re r < 0) and
    ``y(ξ) = Σ B_j exp(s_j ξ)`` for ξ < 0 (``roots_behind``, Re s > 0).  Units: roots 1/m,
    coefficients m.
    """

    roots_ahead: np.ndarray
    coef_ahead: np.ndarray
    roots_behind: np.ndarray
    coef_behind: np.ndarray

    def evaluate(self, xi: np.ndarray | float, derivative: int = 0) -> np.ndarray:
        """The ``derivative``-th derivative d^n y / dξ^n at ``xi`` (m^(1-n)); at ξ = 0 the ahead branch."""
        xi = np.asarray(xi, dtype=float)
        out = np.zeros(xi.shape, dtype=complex)
        ahead = xi >= 0.0
        xa = xi[ahead][..., None]
        xb = xi[~ahead][..., None]
        out[ahead] = np.sum(
            self.coef_ahead * self.roots_ahead**derivative * np.exp(self.roots_ahead * xa), -1
        )
        out[~ahead] = np.sum(
            self.coef_behind * self.roots_behind**derivative * np.exp(self.roots_behind * xb), -1
        )
        return out.real


def _split_roots(beam: Beam, v: float, roots: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    scale = beam.beta
    tol = 1e-9 * scale
    on_axis = np.abs(roots.real) < tol
    if not np.any(on_axis):
        ahead = roots[roots.real < 0.0]
        behind = roots[roots.real > 0.0]
    else:
        # undamped beam, v > v_cr: radiation condition as the limit c -> 0+ (limiting absorption)
        p1 = np.polyder(np.array([beam.EI, 0.0, beam.N + beam.m * v * v, 0.0, beam.k]))
        drift = np.real(v * roots / np.polyval(p1, roots))
        side = np.where(on_axis, drift, roots.real)
        ahead = roots[side < 0.0]
        behind = roots[side > 0.0]
    if ahead.size != 2 or behind.size != 2:
        raise ValueError(
            f"v = {v:.6g} m/s: cannot split the characteristic roots into two decaying pairs "
            f"(roots {roots}); the load speed is at or too close to the critical velocity"
        )
    return ahead, behind


def closed_form_solution(beam: Beam, P: float, v: float) -> ClosedFormSolution:
    """Coefficients of the closed-form steady state (A.2.10–A.2.11) for any damping and speed.

    Parameters
    ----------
    beam : Beam
        The track beam.
    P : float
        Load, N.
    v : float
        Load speed, m/s.

    Raises
    ------
    ValueError
        ``v`` at the critical velocity of an undamped beam (resonance, unbounded response).
    """
    P, v = _check_load(P, v)
    v_cr = beam.critical_velocity()
    if beam.c == 0.0 and abs(v - v_cr) <= 1e-6 * v_cr:
        raise ValueError(
            f"v = {v:.6g} m/s equals the critical velocity v_cr = {v_cr:.6g} m/s of an undamped beam: "
            "the steady response is unbounded (resonance); add damping c > 0 or change v"
        )
    roots = characteristic_roots(beam, v)
    ahead, behind = _split_roots(beam, v, roots)
    # continuity of y, y', y'' and EI [y'''] = P at ξ = 0, in the scaled variable s = r/β
    b = beam.beta
    sa, sb = ahead / b, behind / b
    mat = np.zeros((4, 4), dtype=complex)
    for n in range(4):
        mat[n, :2] = sa**n
        mat[n, 2:] = -(sb**n)
    rhs = np.array([0.0, 0.0, 0.0, 1.0], dtype=complex)
    sol = np.linalg.solve(mat, rhs)
    # y = Σ C (β ξ)-exponentials;  y''' jump = C β³ Σ... = P/EI  ->  scale by P/(EI β³)
    scale = P / (beam.EI * b**3)
    return ClosedFormSolution(ahead, sol[:2] * scale, behind, sol[2:] * scale)


# --- Fourier integral ----------------------------------------------------------------------------
@dataclass(frozen=True)
class _FourierKernel:
    """Dimensionless integrand of y(ξ) (P β / π k) ∫₀^∞ [Re d cos(s u) − e s sin(s u)] / |d|² ds."""

    a: float  # (N + m v²) β² / k
    e: float  # c v β / k
    breaks: tuple[float, ...] = field(default=())

    def re_d(self, s: float) -> float:
        return 0.25 * s**4 - self.a * s * s + 1.0

    def den(self, s: float) -> float:
        r = self.re_d(s)
        return r * r + (self.e * s) ** 2

    def even(self, s: float) -> float:
        return self.re_d(s) / self.den(s)

    def odd(self, s: float) -> float:
        return self.e * s / self.den(s)


def _fourier_kernel(beam: Beam, v: float) -> _FourierKernel:
    b = beam.beta
    a = (beam.N + beam.m * v * v) * b * b / beam.k
    e = beam.c * v * b / beam.k
    breaks = {0.5, 1.0, 2.0, 4.0}
    if a > 0.0:
        breaks.add(math.sqrt(2.0 * a))  # minimum of Re d(s)
    disc = a * a - 1.0
    if disc >= 0.0:  # supercritical: Re d(s) = 0 at s² = 2a ± 2 sqrt(a² − 1)
        for sign in (-1.0, 1.0):
            s2 = 2.0 * a + sign * 2.0 * math.sqrt(disc)
            if s2 > 0.0:
                root = math.sqrt(s2)
                width = max(e * root / max(abs(root**3 - 2.0 * a * root), 1e-300), 1e-6)
                for f in (-4.0, -1.0, 0.0, 1.0, 4.0):
                    breaks.add(max(root + f * width, 1e-12))
    s_end = max(12.0, 4.0 * math.sqrt(max(2.0 * a, 1.0)))
    pts = tuple(sorted(p for p in breaks if 0.0 < p < s_end)) + (s_end,)
    return _FourierKernel(a=a, e=e, breaks=pts)


def _fourier_point(kernel: _FourierKernel, u: float) -> float:
    """∫₀^∞ [Re d cos(s u) − e s sin(s u)] / |d|² ds for one u = β ξ."""
    opts = {"limit": 400, "epsabs": 1e-13, "epsrel": 1e-12}
    total = 0.0
    lo = 0.0
    w = abs(u)
    sgn = 1.0 if u >= 0.0 else -1.0
    for hi in kernel.breaks:
        if w == 0.0:
            total += integrate.quad(kernel.even, lo, hi, **opts)[0]
        else:
            total += integrate.quad(kernel.even, lo, hi, weight="cos", wvar=w, **opts)[0]
            if kernel.e != 0.0:
                total -= sgn * integrate.quad(kernel.odd, lo, hi, weight="sin", wvar=w, **opts)[0]
        lo = hi
    tail_opts = {"limlst": 200, "limit": 400, "epsabs": 1e-13}
    if w < 1.0:
        # slow oscillation: QAWF's cycles would be too long; the tail decays like 4/s⁴
        def tail(s: float) -> float:
            return kernel.even(s) * math.cos(s * w) - sgn * kernel.odd(s) * math.sin(s * w)

        mid = 200.0
        total += integrate.quad(tail, lo, mid, limit=400, epsabs=1e-13, epsrel=1e-12)[0]
        if w < 1e-3:
            total += integrate.quad(tail, mid, np.inf, limit=400, epsabs=1e-14, epsrel=1e-10)[0]
        else:
            total += integrate.quad(kernel.even, mid, np.inf, weight="cos", wvar=w, **tail_opts)[0]
            if kernel.e != 0.0:
                total -= sgn * integrate.quad(kernel.odd, mid, np.inf, weight="sin", wvar=w, **tail_opts)[0]
    else:
        total += integrate.quad(kernel.even, lo, np.inf, weight="cos", wvar=w, **tail_opts)[0]
        if kernel.e != 0.0:
            total -= sgn * integrate.quad(kernel.odd, lo, np.inf, weight="sin", wvar=w, **tail_opts)[0]
    return total


def fourier_deflection(beam: Beam, xi: np.ndarray | float, P: float, v: float) -> np.ndarray:
    """Steady-state deflection from the Fourier integral, independent of the characteristic roots.

    Parameters
    ----------
    beam : Beam
        The track beam; needs ``c > 0`` when ``v > v_cr`` (the integral has real poles otherwise).
    xi : array_like
        ξ = x − v t, m (positive ahead of the load).
    P : float
        Load, N.
    v : float
        Load speed, m/s.

    Returns
    -------
    numpy.ndarray
        Deflection, m, same shape as ``xi``.
    """
    P, v = _check_load(P, v)
    xi = _check_xi(xi)
    v_cr = beam.critical_velocity()
    if beam.c == 0.0 and v >= v_cr * (1.0 - 1e-6):
        raise ValueError(
            f"v = {v:.6g} m/s >= v_cr = {v_cr:.6g} m/s with c = 0: the Fourier integral has poles on "
            "the real axis; use method='closed' (radiation condition) or give the beam damping c > 0"
        )
    kernel = _fourier_kernel(beam, v)
    b = beam.beta
    flat = np.array([_fourier_point(kernel, b * x) for x in xi.ravel()])
    return (P * b / (math.pi * beam.k) * flat).reshape(xi.shape)


# --- results -------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False, repr=False)
class MovingLoadSolution(ArrayRecord):
    """Steady-state deflection under a moving load.

    Attributes
    ----------
    xi : numpy.ndarray
        ξ = x − v t, m; positive ahead of the load.
    y : numpy.ndarray
        Deflection, m, positive in the load direction.
    x_max : float
        Position of the maximum deflection, m; negative means behind the load (the lag).
    y_max : float
        Maximum deflection, m.
    P, v : float
        Load (N) and speed (m/s).
    beam : Beam
        The beam.
    method : str
        ``"closed"`` or ``"fourier"``.
    """

    xi: np.ndarray
    y: np.ndarray
    x_max: float
    y_max: float
    P: float
    v: float
    beam: Beam
    method: str

    @property
    def speed_ratio(self) -> float:
        """v / v_cr."""
        return self.v / self.beam.critical_velocity()

    @property
    def amplification(self) -> float:
        """y_max divided by the static deflection under the load (same N), dimensionless."""
        return self.y_max / float(static_deflection(self.beam, 0.0, self.P))

    def to_pandas(self) -> pd.DataFrame:
        """Profile table with columns ``xi_m`` and ``y_m``; maximum and parameters in ``attrs``."""
        df = pd.DataFrame({"xi_m": self.xi.ravel(), "y_m": self.y.ravel()})
        df.attrs.update(x_max_m=self.x_max, y_max_m=self.y_max, P_N=self.P, v_m_s=self.v, method=self.method)
        return df


def _maximum_closed(sol: ClosedFormSolution, beam: Beam) -> tuple[float, float]:
    """Maximum of the closed-form profile: a grid resolving the shortest wave, the peak search, then y'(xi) = 0.

    A search on values alone places a smooth maximum only to ~sqrt(machine eps) of the length scale (the
    value is flat there), so the location is finished as the root of the closed-form slope y' (continuous
    across xi = 0, where only the third derivative jumps), bracketed by the neighbouring grid points.
    """
    b = beam.beta
    decay = min(np.min(np.abs(sol.roots_ahead.real)), np.min(np.abs(sol.roots_behind.real)))
    width = min(max(6.0 / b, 3.0 / max(decay, 1e-300)), 60.0 / b)
    wave = max(np.max(np.abs(sol.roots_ahead.imag)), np.max(np.abs(sol.roots_behind.imag)), b)
    n = int(min(max(2001, 2.0 * width * wave / (2.0 * math.pi) * 60), 200_001))
    x, y = grid_maximum(sol.evaluate, np.linspace(-width, width, n), rtol=1e-10)
    step = 2.0 * width / (n - 1)
    lo, hi = max(x - step, -width), min(x + step, width)

    def slope(s: float) -> float:
        return float(sol.evaluate(np.array([s]), 1)[0])

    if slope(lo) > 0.0 > slope(hi):
        x = optimize.brentq(slope, lo, hi, xtol=4 * np.finfo(float).eps / b, rtol=4 * np.finfo(float).eps)
        y = max(y, float(sol.evaluate(np.array([x]))[0]))
    return float(x), float(y)


def _maximum_fourier(beam: Beam, P: float, v: float) -> tuple[float, float]:
    """Maximum of the Fourier-integral profile (each point a quadrature: a coarse grid, then refined)."""
    b = beam.beta
    return grid_maximum(lambda x: fourier_deflection(beam, x, P, v), np.linspace(-4.0 / b, 4.0 / b, 33), rtol=1e-7)


def moving_load(
    beam: Beam, xi: np.ndarray | float, P: float, v: float, method: str = "closed"
) -> MovingLoadSolution:
    """Steady-state deflection under a constant load ``P`` moving at speed ``v`` (3.26, A.2.12).

    Parameters
    ----------
    beam : Beam
        The track beam.
    xi : array_like
        ξ = x − v t, m; positive ahead of the load.
    P : float
        Load, N.
    v : float
        Speed, m/s, >= 0.
    method : {"closed", "fourier"}
        Closed form from the characteristic roots, or the independent Fourier integral.

    Returns
    -------
    MovingLoadSolution
        Profile, and the location (``x_max`` < 0: behind the load) and value of the maximum.

    Raises
    ------
    ValueError
        Unknown ``method``; ``v`` at the critical velocity of an undamped beam; ``method="fourier"``
        with ``c = 0`` and ``v >= v_cr``.
    """
    if method not in _METHODS:
        raise ValueError(f"method: must be one of {_METHODS}, got {method!r}")
    P, v = _check_load(P, v)
    xi = _check_xi(xi)
    if method == "closed":
        sol = closed_form_solution(beam, P, v)
        y = sol.evaluate(xi)
        x_max, y_max = _maximum_closed(sol, beam)
    else:
        y = fourier_deflection(beam, xi, P, v)
        x_max, y_max = _maximum_fourier(beam, P, v)
    return MovingLoadSolution(xi=xi, y=y, x_max=x_max, y_max=y_max, P=P, v=v, beam=beam, method=method)


def static_deflection(beam: Beam, x: np.ndarray | float, P: float) -> np.ndarray:
    """Static deflection under a point load ``P`` at x = 0 with the beam's axial force, m.

    The ``v = 0`` case of the closed form; for ``N = 0`` it is Hetényi's (3.19).

    Parameters
    ----------
    beam : Beam
        The track beam (damping is irrelevant).
    x : array_like
        Distance from the load, m.
    P : float
        Load, N.
    """
    x = _check_xi(x, "x")
    return closed_form_solution(beam, P, 0.0).evaluate(x)


__all__ = [
    "ClosedFormSolution", "MovingLoadSolution", "characteristic_roots", "closed_form_solution",
    "fourier_deflection", "moving_load", "static_deflection",
]
