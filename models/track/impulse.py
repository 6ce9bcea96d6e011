"""Deflection at the load point after an impulse ``q = I δ(x) δ(t)`` (thesis (3.20)–(3.24)).

Derivation (zero initial conditions).  Fourier transforming (3.2) in x, each wavenumber κ is a damped
oscillator ``m Ÿ + c Ẏ + (EI κ⁴ − N κ² + k) Y = I δ(t)``, so
``Y(κ, t) = I e^{−ζt} sin(ω_d t) / (m ω_d)`` with ``ζ = c/2m`` and
``ω_d² = a² (κ² − b)² + λ²``, ``a² = EI/m``, ``b = N/2EI``, ``λ² = k/m − ζ² − a² b²`` (A.1.7).
At x = 0::

    y(0, t) = I e^{−ζt} / (π m) ∫₀^∞ sin(ω_d t) / ω_d dκ .                                   (1)

For ``N = 0`` substitute ``u = a κ²`` and use ``sin(t√(λ²+u²))/√(λ²+u²) = ∫₀^t J₀(λ√(t²−s²)) cos(us) ds``
and ``∫₀^∞ u^{−1/2} cos(us) du = √(π/2s)``; this gives (3.21) with ``λ`` for ``ω₀``.  The remaining
integral is Sonine's first finite integral with μ = 0, ν = −3/4:
``∫₀^t J₀(λ√(t²−s²)) s^{−1/2} ds = √t 2^{−3/4} Γ(1/4) J_{1/4}(λt) / (λt)^{1/4}``, hence::

    y(0, t) = I Γ(1/4) / (2^{9/4} √π m √a) · e^{−ζt} √t (λt)^{−1/4} J_{1/4}(λt)              (2)

and for ``c = 0`` (λ = ω₀ = √(k/m))::

    y(0, t) = I Γ(1/4) / (2^{9/4} √π √m (k EI)^{1/4}) · (ω₀t)^{1/4} J_{1/4}(ω₀t).            (3)

The constant of (3) equals the one printed in (3.24), ``√(k/m) Γ(1/4) / (2√π (4EI)^{1/4} (2k)^{3/4})``,
once ``P`` there is read as the impulse (N·s); the printed Sonine step before it is wrong
(its ``1/(√ω t)`` must read ``1/(ωt)^{1/4}``).  For ``ζ > ω₀`` the Bessel function becomes
``I_{1/4}(μt)/(μt)^{1/4}`` with ``μ = √(ζ² − ω₀²)``.  The numerical method evaluates (1) directly
by adaptive quadrature (QUADPACK, QAWF on the oscillatory tail) and serves as the independent check.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import integrate, special

from railopt.models.track.beam import Beam

_METHODS = ("closed", "numerical")


def impulse_constant(beam: Beam) -> float:
    """Constant ``C`` of (3): ``y(0,t) = I C (ω₀t)^{1/4} J_{1/4}(ω₀t)`` for ``c = N = 0``, m/(N·s)."""
    return math.gamma(0.25) / (
        2.0**2.25 * math.sqrt(math.pi) * math.sqrt(beam.m) * (beam.k * beam.EI) ** 0.25
    )


def printed_impulse_constant(beam: Beam) -> float:
    """The constant of the thesis's (3.24) as transcribed, m/(N·s) (for comparison only)."""
    return (
        math.sqrt(beam.k / beam.m)
        * math.gamma(0.25)
        / (2.0 * math.sqrt(math.pi) * (4.0 * beam.EI) ** 0.25 * (2.0 * beam.k) ** 0.75)
    )


def _check_times(t: np.ndarray | float) -> np.ndarray:
    t = np.asarray(t, dtype=float)
    if not np.all(np.isfinite(t)):
        raise ValueError("t: must contain finite values only")
    if np.any(t < 0.0):
        raise ValueError("t: must be non-negative (s)")
    return t


def _closed(beam: Beam, t: np.ndarray, impulse: float) -> np.ndarray:
    if beam.N != 0.0:
        raise ValueError(
            f"N = {beam.N:.6g} N: the closed form (3.24) holds for N = 0 only; use method='numerical'"
        )
    zeta = beam.c / (2.0 * beam.m)
    a = math.sqrt(beam.EI / beam.m)
    lam2 = beam.k / beam.m - zeta * zeta
    const = impulse * math.gamma(0.25) / (2.0**2.25 * math.sqrt(math.pi) * beam.m * math.sqrt(a))
    out = np.zeros_like(t)
    pos = t > 0.0
    tp = t[pos]
    if lam2 > 0.0:
        z = math.sqrt(lam2) * tp
        decayed = np.exp(-zeta * tp) * special.jv(0.25, z) / z**0.25
    elif lam2 < 0.0:
        mu = math.sqrt(-lam2)
        z = mu * tp
        # e^{−ζt} I_ν(μt) = ive(ν, μt) e^{(μ−ζ)t}, finite for any t since μ < ζ
        decayed = np.exp((mu - zeta) * tp) * special.ive(0.25, z) / z**0.25
    else:
        decayed = np.exp(-zeta * tp) / (2.0**0.25 * math.gamma(1.25))
    out[pos] = const * np.sqrt(tp) * decayed
    return out


def _numerical_one(beam: Beam, t: float) -> float:
    """(1/π m) ∫₀^∞ sin(ω_d t)/ω_d dκ (without e^{−ζt}) by adaptive quadrature."""
    m = beam.m
    a = math.sqrt(beam.EI / m)
    zeta = beam.c / (2.0 * m)
    b = beam.N / (2.0 * beam.EI)
    lam2 = beam.k / m - zeta * zeta - a * a * b * b

    def kernel(kappa: float) -> float:
        w2 = a * a * (kappa * kappa - b) ** 2 + lam2
        if w2 > 0.0:
            w = math.sqrt(w2)
            return math.sin(w * t) / w
        if w2 < 0.0:
            w = math.sqrt(-w2)
            return math.sinh(w * t) / w
        return t

    u_c = max(4.0 * math.sqrt(abs(lam2)), 4.0 * a * abs(b), 1.0 / t)
    kappa_c = math.sqrt(u_c / a + b)
    n_cycles = max(u_c * t / (2.0 * math.pi), 1.0)
    pts = np.linspace(0.0, kappa_c, int(min(n_cycles, 2000)) + 2)
    head = sum(
        integrate.quad(kernel, lo, hi, limit=200, epsabs=1e-13 * t * (hi - lo), epsrel=1e-11)[0]
        for lo, hi in zip(pts[:-1], pts[1:], strict=True)
    )

    # u = a(κ² − b), w = √(u² + λ²) = u + δ,  sin(tw) = sin(tu) cos(tδ) + cos(tu) sin(tδ)
    def jac(u: float) -> float:
        return 1.0 / (2.0 * a * math.sqrt(u / a + b) * math.sqrt(u * u + lam2))

    def delta(u: float) -> float:
        return lam2 / (math.sqrt(u * u + lam2) + u)

    opts = {"limlst": 200, "limit": 400, "epsabs": 1e-12 * jac(u_c) / t}
    tail = integrate.quad(
        lambda u: jac(u) * math.cos(t * delta(u)), u_c, np.inf, weight="sin", wvar=t, **opts
    )[0]
    tail += integrate.quad(
        lambda u: jac(u) * math.sin(t * delta(u)), u_c, np.inf, weight="cos", wvar=t, **opts
    )[0]
    return (head + tail) / (math.pi * m)


def impulse_response_at_load(
    beam: Beam, t: np.ndarray | float, impulse: float, method: str = "closed"
) -> np.ndarray:
    """Deflection under the load point after ``q = I δ(x) δ(t)``, from rest (3.20)–(3.24).

    Parameters
    ----------
    beam : Beam
        The track beam.  ``method="closed"`` needs ``N = 0`` (any damping).
    t : array_like
        Times after the impulse, s (>= 0).
    impulse : float
        Impulse ``I``, N·s.
    method : {"closed", "numerical"}
        Closed form (2) of the module docstring, or numerical inversion of the Fourier integral (1).

    Returns
    -------
    numpy.ndarray
        ``y(0, t)``, m, same shape as ``t``.
    """
    if method not in _METHODS:
        raise ValueError(f"method: must be one of {_METHODS}, got {method!r}")
    impulse = float(impulse)
    if not math.isfinite(impulse):
        raise ValueError(f"impulse: must be a finite number, got {impulse!r}")
    t = _check_times(t)
    if method == "closed":
        return _closed(beam, t, impulse)
    zeta = beam.c / (2.0 * beam.m)
    flat = np.array(
        [0.0 if ti == 0.0 else _numerical_one(beam, ti) * math.exp(-zeta * ti) for ti in t.ravel()]
    )
    return impulse * flat.reshape(t.shape)


__all__ = ["impulse_constant", "impulse_response_at_load", "printed_impulse_constant"]
