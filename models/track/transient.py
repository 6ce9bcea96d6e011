"""Transient response of the track beam from rest for the load cases (i)–(vi) of §3.2.2.

Method (an alternative to the thesis's Bessel-kernel integrals (3.9)–(3.12), which it evaluated with
Clenshaw–Curtis and adaptive Simpson quadrature):

1. Fourier transform in x.  Each wavenumber κ is a damped oscillator
   ``m Ÿ + c Ẏ + K(κ) Y = Q(κ, t)``, ``K(κ) = EI κ⁴ − N κ² + k`` (A.1.4), with impulse response
   ``g(κ, t) = (e^{p₁t} − e^{p₂t}) / (m (p₁ − p₂))``, ``p₁,₂ = −ζ ± √(ζ² − K/m)``, ``ζ = c/2m``.
2. Exact time convolution.  For a point load ``P cos(Ωt) δ(x − s(t))`` the transformed load is a sum
   of exponentials in τ when ``s`` is linear in τ, so ``∫₀^t Q(τ) e^{p(t−τ)} dτ`` is evaluated in
   closed form.  For the accelerating load (vi) ``s(t) = x₀ + v t + a t²/2`` is replaced by its chord
   on short steps (phase error β |a| h² / 8 ≤ 1e-6 rad at the wavenumbers that carry the deflection)
   and the same exact formula is applied step by step (exact recursion of the two modal states).
3. Inverse transform by the trapezoidal rule on a uniform κ grid on [0, κ_max], whose spacing makes
   the periodic image of the response lie outside the region reached by loads and by not yet damped
   dispersive waves, plus the quasi-static tail ``(P cos Ωt / π EI) ∫_{κ_max}^∞ cos(κ(x − s))/κ⁴ dκ``
   in closed form (sine and cosine integrals).

Load cases (thesis numbering; zero initial conditions throughout):

(i)   :class:`SuddenLoad` — ``P δ(x − x₀)`` applied at t = 0 (→ (3.19) for large t with damping);
(ii)  :class:`ImpulseLoad` — ``I δ(x − x₀) δ(t)`` (→ (3.24) at the load point);
(iii) :class:`DistributedImpulse` — ``I' δ(t)`` on ``x₁ ≤ x ≤ x₂`` (I' in N·s/m);
(iv)  :class:`MovingLoad` with ``Omega = 0, acceleration = 0`` — ``P δ(x − vt)``;
(v)   :class:`MovingLoad` with ``Omega ≠ 0`` — ``P cos(Ωt) δ(x − vt)``;
(vi)  :class:`MovingLoad` with ``acceleration ≠ 0`` — ``P f(t) δ(x − vt ∓ ρt²)``, here with
      ``f(t) = cos(Ωt)`` (f = 1 for Ω = 0) and ``acceleration = ∓2ρ`` (m/s²).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import special

from railopt.models.track.beam import Beam
from railopt.models.validation import number as _check_finite
from railopt.records import ArrayRecord


@dataclass(frozen=True)
class MovingLoad:
    """Point load ``P cos(Ω t) δ(x − x₀ − v t − a t²/2)`` from t = 0, cases (i), (iv)–(vi).

    Parameters
    ----------
    P : float
        Load amplitude, N.
    v : float
        Initial speed, m/s.
    x0 : float
        Position at t = 0, m.
    Omega : float
        Circular frequency of the load, rad/s (0: constant load).
    acceleration : float
        Acceleration of the load point, m/s² (thesis ``∓2ρ``).
    """

    P: float
    v: float = 0.0
    x0: float = 0.0
    Omega: float = 0.0
    acceleration: float = 0.0

    def __post_init__(self) -> None:
        for name in ("P", "v", "x0", "Omega", "acceleration"):
            object.__setattr__(self, name, _check_finite(name, getattr(self, name)))

    def position(self, t: np.ndarray | float) -> np.ndarray:
        """Load position s(t), m."""
        t = np.asarray(t, dtype=float)
        return self.x0 + self.v * t + 0.5 * self.acceleration * t * t

    def amplitude(self, t: np.ndarray | float) -> np.ndarray:
        """Load value P cos(Ω t), N."""
        return self.P * np.cos(self.Omega * np.asarray(t, dtype=float))


def SuddenLoad(P: float, x0: float = 0.0) -> MovingLoad:  # noqa: N802 - a load-case constructor
    """Case (i): a constant point load ``P δ(x − x₀)`` (N, m) applied suddenly at t = 0."""
    return MovingLoad(P=P, v=0.0, x0=x0)


@dataclass(frozen=True)
class ImpulseLoad:
    """Case (ii): ``I δ(x − x₀) δ(t)``; ``impulse`` in N·s, ``x0`` in m."""

    impulse: float
    x0: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "impulse", _check_finite("impulse", self.impulse))
        object.__setattr__(self, "x0", _check_finite("x0", self.x0))


@dataclass(frozen=True)
class DistributedImpulse:
    """Case (iii): ``I' δ(t)`` on ``x1 ≤ x ≤ x2``; ``impulse_per_length`` in N·s/m, x in m."""

    impulse_per_length: float
    x1: float
    x2: float

    def __post_init__(self) -> None:
        for name in ("impulse_per_length", "x1", "x2"):
            object.__setattr__(self, name, _check_finite(name, getattr(self, name)))
        if not self.x2 > self.x1:
            raise ValueError(f"x2: must be greater than x1, got x1={self.x1!r}, x2={self.x2!r}")


Load = MovingLoad | ImpulseLoad | DistributedImpulse


@dataclass(frozen=True, eq=False, repr=False)
class TransientSolution(ArrayRecord):
    """Deflection ``y[i, j] = y(x[j], t[i])``, m; ``x`` in m, ``t`` in s."""

    x: np.ndarray
    t: np.ndarray
    y: np.ndarray
    load: Load
    beam: Beam
    kappa_max: float
    n_kappa: int

    def to_pandas(self) -> pd.DataFrame:
        """Long table with columns ``t_s``, ``x_m``, ``y_m``."""
        tt, xx = np.meshgrid(self.t, self.x, indexing="ij")
        return pd.DataFrame({"t_s": tt.ravel(), "x_m": xx.ravel(), "y_m": self.y.ravel()})


def _exp_conv(sigma: np.ndarray, p: np.ndarray, h: float, eph: np.ndarray) -> np.ndarray:
    """``∫₀^h e^{στ} e^{p(h−τ)} dτ = (e^{σh} − e^{ph}) / (σ − p)``, stable as σ → p; ``eph = e^{ph}``."""
    diff = sigma - p
    with np.errstate(invalid="ignore", divide="ignore"):
        out = (np.exp(sigma * h) - eph) / diff
    z = diff * h
    small = np.abs(z) < 1e-3
    if np.any(small):
        zs = z[small]
        phi1 = 1.0 + zs / 2.0 + zs * zs / 6.0 + zs**3 / 24.0
        out[small] = np.broadcast_to(eph, out.shape)[small] * h * phi1
    return out


def _quasi_static_tail(u: np.ndarray, kappa_max: float) -> np.ndarray:
    """``∫_K^∞ cos(κu) / κ⁴ dκ`` in closed form (by parts down to the sine integral)."""
    K = kappa_max
    b = np.asarray(u, dtype=float)
    si, _ = special.sici(np.abs(b) * K)
    s_int = np.sign(b) * (0.5 * math.pi - si)  # ∫_K^∞ sin(bκ)/κ dκ
    c, s = np.cos(b * K), np.sin(b * K)
    return c / (3 * K**3) - b * s / (6 * K**2) - b * b * c / (6 * K) + b**3 * s_int / 6.0


def _poles(beam: Beam, kappa: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    zeta = beam.c / (2.0 * beam.m)
    stiff = beam.EI * kappa**4 - beam.N * kappa**2 + beam.k
    root = np.sqrt(zeta * zeta - stiff / beam.m + 0j)
    p1, p2 = -zeta + root, -zeta - root
    degenerate = np.abs(root) < 1e-9 * math.sqrt(beam.k / beam.m)
    if np.any(degenerate):  # critically damped wavenumber: split the double pole slightly
        eps = 1e-9 * math.sqrt(beam.k / beam.m)
        p1 = np.where(degenerate, -zeta + eps, p1)
        p2 = np.where(degenerate, -zeta - eps, p2)
    return p1, p2


def _grid(beam: Beam, x: np.ndarray, t: np.ndarray, load: Load, kappa_max: float) -> np.ndarray:
    b = beam.beta
    t_max = float(t.max())
    if isinstance(load, MovingLoad):
        reach = float(np.max(np.abs(load.position(np.linspace(0.0, t_max, 201)))))
    elif isinstance(load, ImpulseLoad):
        reach = abs(load.x0)
    else:
        reach = max(abs(load.x1), abs(load.x2))
    kappa = kappa_max
    omega = math.sqrt((beam.EI * kappa**4 - beam.N * kappa**2 + beam.k) / beam.m)
    group = (2.0 * beam.EI * kappa**3 - beam.N * kappa) / (beam.m * omega)
    zeta = beam.c / (2.0 * beam.m)
    travel = t_max if zeta == 0.0 else min(t_max, 25.0 / zeta)
    half_period = float(np.max(np.abs(x))) + reach + group * travel + 20.0 / b
    dk = math.pi / half_period
    n = int(math.ceil(kappa_max / dk)) + 1
    if n > 2_000_000:
        raise ValueError(
            f"t = {t_max:.4g} s needs {n} wavenumbers: the undamped dispersive waves spread too far; "
            "use shorter times, damping c > 0 or a smaller kappa_max_factor"
        )
    return np.linspace(0.0, kappa_max, n)


def _modal_history(beam: Beam, kappa: np.ndarray, t: np.ndarray, load: Load):
    """Yield (i, Y(κ, t_i)) for the output times in order."""
    p1, p2 = _poles(beam, kappa)
    dp = beam.m * (p1 - p2)
    if isinstance(load, (ImpulseLoad, DistributedImpulse)):
        if isinstance(load, ImpulseLoad):
            shape = load.impulse * np.exp(-1j * kappa * load.x0)
        else:
            with np.errstate(invalid="ignore", divide="ignore"):
                shape = load.impulse_per_length * (
                    (np.exp(-1j * kappa * load.x1) - np.exp(-1j * kappa * load.x2)) / (1j * kappa)
                )
            shape[kappa == 0.0] = load.impulse_per_length * (load.x2 - load.x1)
        for i, ti in enumerate(t):
            yield i, shape * (np.exp(p1 * ti) - np.exp(p2 * ti)) / dp
        return
    # point load: states Z_p = ∫ Q e^{p(t−τ)} dτ for p = p1, p2 and the two halves of cos(Ωτ)
    poles = np.stack([p1, p2])[:, None, :]  # (2 poles, 1, nκ)
    omegas = np.array([load.Omega, -load.Omega])[None, :, None]  # (1, 2 signs, 1)
    state = np.zeros((2, 2, kappa.size), dtype=complex)
    a = load.acceleration
    if a == 0.0:
        h_max = math.inf
    else:
        # chord error of the position ≤ |a| h²/8; its phase error β|a|h²/8 ≤ 1e-6 rad at the
        # wavenumbers that carry the deflection (κ ≈ β; higher κ carry O((β/κ)⁴) of it)
        h_max = math.sqrt(8.0e-6 / (beam.beta * abs(a)))
    t_now = 0.0
    for i, t_out in enumerate(t):
        span = t_out - t_now
        n_steps = 0 if span <= 0.0 else max(1, int(math.ceil(span / h_max)))
        h = span / n_steps if n_steps else 0.0
        eph = np.exp(poles * h)
        for j in range(n_steps):
            t0 = t_now + span * j / n_steps
            s0, s1 = float(load.position(t0)), float(load.position(t0 + h))
            speed = (s1 - s0) / h
            # Q(τ) = (P/2) Σ± exp(±iΩt0 − iκ s0) exp((±iΩ − iκ speed)(τ − t0)) on the step
            start = 0.5 * load.P * np.exp(1j * omegas * t0 - 1j * kappa * s0)
            sigma = 1j * omegas - 1j * kappa * speed
            state = eph * state + start * _exp_conv(sigma, poles, h, eph)
        t_now = t_out if n_steps else t_now
        z = state.sum(axis=1)  # (2 poles, nκ)
        yield i, (z[0] - z[1]) / dp


def transient(
    beam: Beam,
    x: np.ndarray | float,
    t: np.ndarray | float,
    load: Load,
    *,
    kappa_max_factor: float | None = None,
) -> TransientSolution:
    """Transient deflection from rest under one of the load cases (i)–(vi) of §3.2.2 (3.11).

    Parameters
    ----------
    beam : Beam
        The track beam.
    x : array_like
        Positions, m (1-D).
    t : array_like
        Times, s, ascending, >= 0 (1-D).
    load : MovingLoad | ImpulseLoad | DistributedImpulse
        The load case (use :func:`SuddenLoad` for case (i)).
    kappa_max_factor : float, optional
        Truncation wavenumber in units of β.  Default 16 for point loads (plus the quasi-static
        tail) and 60 for impulses.

    Returns
    -------
    TransientSolution
        ``y[i, j] = y(x[j], t[i])``, m.
    """
    x = np.atleast_1d(np.asarray(x, dtype=float))
    t = np.atleast_1d(np.asarray(t, dtype=float))
    if x.ndim != 1 or not np.all(np.isfinite(x)):
        raise ValueError("x: must be a 1-D array of finite positions (m)")
    if t.ndim != 1 or not np.all(np.isfinite(t)) or np.any(t < 0.0):
        raise ValueError("t: must be a 1-D array of finite, non-negative times (s)")
    if np.any(np.diff(t) < 0.0):
        raise ValueError("t: must be ascending")
    if not isinstance(load, (MovingLoad, ImpulseLoad, DistributedImpulse)):
        raise ValueError(f"load: must be MovingLoad, ImpulseLoad or DistributedImpulse, got {type(load)!r}")
    point = isinstance(load, MovingLoad)
    if kappa_max_factor is None:
        kappa_max_factor = 16.0 if point else 60.0
    kappa_max_factor = _check_finite("kappa_max_factor", kappa_max_factor)
    if kappa_max_factor < 4.0:
        raise ValueError(f"kappa_max_factor: must be at least 4, got {kappa_max_factor!r}")
    kappa_max = kappa_max_factor * beam.beta
    kappa = _grid(beam, x, t, load, kappa_max)
    dk = kappa[1] - kappa[0]
    weights = np.full(kappa.size, dk)
    weights[0] = weights[-1] = 0.5 * dk

    y = np.zeros((t.size, x.size))
    precompute = x.size * kappa.size <= 4_000_000
    phase = np.exp(1j * np.outer(x, kappa)) * weights if precompute else None
    chunk = max(1, 4_000_000 // max(x.size, 1))
    for i, big_y in _modal_history(beam, kappa, t, load):
        if phase is not None:
            y[i] = (phase @ big_y).real / math.pi
        else:
            acc = np.zeros(x.size)
            for lo in range(0, kappa.size, chunk):
                sl = slice(lo, lo + chunk)
                acc += (np.exp(1j * np.outer(x, kappa[sl])) @ (weights[sl] * big_y[sl])).real
            y[i] = acc / math.pi
        if point and t[i] > 0.0:
            u = x - float(load.position(t[i]))
            y[i] += float(load.amplitude(t[i])) / (math.pi * beam.EI) * _quasi_static_tail(u, kappa_max)
    return TransientSolution(x=x, t=t, y=y, load=load, beam=beam, kappa_max=kappa_max, n_kappa=kappa.size)


__all__ = ["DistributedImpulse", "ImpulseLoad", "Load", "MovingLoad", "SuddenLoad", "TransientSolution", "transient"]
