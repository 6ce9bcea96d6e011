"""A periodic orbit by shooting on a Poincaré section with Newton's method, and its Floquet multipliers.

Unknowns: the n − 1 free coordinates z of a point on the section Σ = {x : x[index] = value}.  Equation: the
Poincaré map returns to it, P(z) − z = 0.  Newton's step solves (DP − I) Δz = −(P(z) − z) with DP from the
variational equations (:mod:`.variational`): DP = (I − f e_iᵀ/f_i) Φ(τ) on the free coordinates.  The period is
the return time τ.

Floquet multipliers: the eigenvalues of the monodromy matrix Φ(T) (n of them, one equal to 1 — the trivial
multiplier along the orbit); the n − 1 eigenvalues of DP are the non-trivial ones (the trivial one is projected
out exactly).  The orbit is stable when all |non-trivial multipliers| < 1 (Floquet theory; Seydel,
*Practical Bifurcation and Stability Analysis*, 3rd ed., Springer 2010).  Both come from the variational
equations integrated with the state, not from finite differences of the flow; J = ∂f/∂x is the caller's
``jacobian`` or central differences of ``rhs``.

Failure is reported, never hidden: ``converged=False`` with a ``reason`` when the trajectory does not come back
to the section, Newton does not reach the tolerance, DP − I is singular (a multiplier at 1: a fold), or Newton
slides onto the equilibrium (the orbit's amplitude falls below ``min_amplitude`` — a point of the section next
to an equilibrium "returns" to itself to within any absolute tolerance).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from railopt.models.bifurcation.integration import IntegrationSettings, Jacobian, RightHandSide, check_state
from railopt.models.bifurcation.limit_cycle import Coordinate, watched_values
from railopt.models.bifurcation.section import PoincareSection
from railopt.models.bifurcation.variational import SectionReturn, flow_to_section
from railopt.records import ArrayRecord


@dataclass(frozen=True)
class ShootingOptions:
    """Newton and return-time settings of the shooting method.

    Attributes
    ----------
    tol : float
        Newton stops when max |P(z) − z| ≤ tol (state units); default 1e-9.
    max_iterations : int
        Newton steps before giving up (default 25).
    arm_fraction : float
        The section is armed after this fraction of the period guess (default 0.25).
    max_return_factor : float
        No return within this many period guesses means no orbit (default 3).
    min_amplitude : float
        Orbits whose watched amplitude is below this (state units) count as the equilibrium (default 1e-6).
    """

    tol: float = 1e-9
    max_iterations: int = 25
    arm_fraction: float = 0.25
    max_return_factor: float = 3.0
    min_amplitude: float = 1e-6

    def __post_init__(self) -> None:
        if not self.tol > 0:
            raise ValueError(f"tol: must be > 0, got {self.tol!r}")
        if not (isinstance(self.max_iterations, int) and self.max_iterations >= 1):
            raise ValueError(f"max_iterations: must be an int >= 1, got {self.max_iterations!r}")
        if not 0 < self.arm_fraction < 1:
            raise ValueError(f"arm_fraction: must be in (0, 1), got {self.arm_fraction!r}")
        if not self.max_return_factor > 1:
            raise ValueError(f"max_return_factor: must be > 1, got {self.max_return_factor!r}")
        if not self.min_amplitude >= 0:
            raise ValueError(f"min_amplitude: must be >= 0, got {self.min_amplitude!r}")


@dataclass(frozen=True, eq=False, repr=False)
class PeriodicOrbit(ArrayRecord):
    """A periodic orbit found (or not) by shooting.

    Attributes
    ----------
    speed : float
        The parameter (m/s).
    point : (n,) ndarray
        The orbit's point on the section (the last Newton iterate when not converged).
    period : float
        T (s); NaN when the trajectory did not return.
    amplitude : float
        Half the peak-to-peak of the watched coordinate over one period (state units); NaN if not computed.
    multipliers : (n−1,) complex ndarray
        Non-trivial Floquet multipliers (eigenvalues of the Poincaré map's Jacobian), largest modulus first.
    monodromy : (n, n) ndarray
        Φ(T), whose eigenvalues are all n Floquet multipliers (one of them 1 up to the integration error).
    converged : bool
    reason : str
        How Newton ended (the residual, or why it failed).
    iterations : int
        Newton steps taken.
    residual : float
        max |P(z) − z| at ``point`` (state units).
    """

    speed: float
    point: np.ndarray
    period: float
    amplitude: float
    multipliers: np.ndarray
    monodromy: np.ndarray
    converged: bool
    reason: str
    iterations: int
    residual: float

    @property
    def stable(self) -> bool:
        """Converged and every non-trivial multiplier strictly inside the unit circle."""
        return bool(self.converged and np.all(np.abs(self.multipliers) < 1.0))

    @property
    def frequency_hz(self) -> float:
        """1/T (Hz)."""
        return 1.0 / self.period

    @property
    def floquet_multipliers(self) -> np.ndarray:
        """All n eigenvalues of the monodromy matrix (the trivial one included), largest modulus first."""
        if not np.all(np.isfinite(self.monodromy)):
            return np.full(self.monodromy.shape[0], np.nan + 0j)
        mu = np.linalg.eigvals(self.monodromy)
        return mu[np.argsort(-np.abs(mu), kind="stable")]


def orbit_amplitude(rhs: RightHandSide, point: np.ndarray, speed: float, period: float, coordinate: Coordinate,
                    settings: IntegrationSettings, samples: int = 256) -> float:
    """Half the peak-to-peak of the watched coordinate over one period from ``point`` (state units).

    The extremes on ``samples`` points of the dense output are refined by bounded Brent searches
    (:func:`scipy.optimize.minimize_scalar`) on the dense output between the neighbouring samples.
    """
    sol = solve_ivp(rhs, (0.0, period), point, dense_output=True, args=(speed,), **settings.options())
    if sol.status != 0:
        raise ValueError(f"rhs: integration over one period failed at speed {speed}: {sol.message}")
    t = np.linspace(0.0, period, samples + 1)

    def q(s: float) -> float:
        return float(watched_values(sol.sol(s)[:, None], coordinate)[0])

    values = watched_values(sol.sol(t), coordinate)
    extremes = []
    for sign in (1.0, -1.0):
        k = int(np.argmax(sign * values))
        lo, hi = t[max(k - 1, 0)], t[min(k + 1, samples)]
        found = minimize_scalar(lambda s, sign=sign: -sign * q(s), bounds=(lo, hi), method="bounded",
                                options={"xatol": 1e-12 * period})
        extremes.append(max(sign * values[k], -found.fun) * sign)
    return float(extremes[0] - extremes[1]) / 2


def _shoot(rhs: RightHandSide, x: np.ndarray, speed: float, section: PoincareSection, period_guess: float,
           options: ShootingOptions, settings: IntegrationSettings, jacobian: Jacobian | None) -> SectionReturn:
    return flow_to_section(rhs, x, speed, section, t_arm=options.arm_fraction * period_guess,
                           t_max=options.max_return_factor * period_guess, settings=settings, jacobian=jacobian)


def find_periodic_orbit(rhs: RightHandSide, guess: np.ndarray, speed: float, section: PoincareSection,
                        period_guess: float, coordinate: Coordinate, *, options: ShootingOptions | None = None,
                        settings: IntegrationSettings | None = None,
                        jacobian: Jacobian | None = None) -> PeriodicOrbit:
    """Newton shooting for the periodic orbit through the section near ``guess`` at ``speed``.

    Parameters
    ----------
    rhs : callable
        ``rhs(t, x, speed) -> dx/dt``, (n,) → (n,), autonomous.
    guess : (n,) ndarray
        A state near the orbit; its section coordinate is replaced by the section's value.
    speed : float
        m/s.
    section : PoincareSection
    period_guess : float
        Expected period (s), e.g. 1/frequency from the limit-cycle detector; sets when the section is armed
        and how long to wait for the return (``options``).
    coordinate : int or callable
        The watched coordinate whose half peak-to-peak is the orbit's ``amplitude``.
    options : ShootingOptions, optional
    settings : IntegrationSettings, optional
    jacobian : callable, optional
        ``jacobian(t, x, speed) -> (n, n)``; central differences when omitted.

    Returns
    -------
    PeriodicOrbit
        ``converged`` False with a ``reason`` when no orbit was found; never raises for a failed search.

    Raises
    ------
    ValueError
        On bad arguments (the message names the argument).
    """
    options = options or ShootingOptions()
    settings = settings or IntegrationSettings()
    x = check_state(guess, "guess").copy()
    n = x.size
    section.check(n)
    if not (period_guess > 0 and math.isfinite(period_guess)):
        raise ValueError(f"period_guess: must be a finite time > 0 (s), got {period_guess!r}")
    speed = float(speed)
    free = section.free(n)
    x[section.index] = section.value
    nan_mult = np.full(n - 1, np.nan + 0j)

    def failed(point: np.ndarray, reason: str, iterations: int, residual: float,
               trip: SectionReturn | None = None) -> PeriodicOrbit:
        period = trip.time if trip is not None and trip.returned else math.nan
        mono = trip.monodromy if trip is not None else np.full((n, n), np.nan)
        return PeriodicOrbit(speed, point, period, math.nan, nan_mult, mono, False, reason, iterations, residual)

    residual = math.inf
    for iteration in range(options.max_iterations + 1):
        trip = _shoot(rhs, x, speed, section, period_guess, options, settings, jacobian)
        if not trip.returned:
            return failed(x, f"no return to the section within {options.max_return_factor:g} period guesses "
                             f"({options.max_return_factor * period_guess:.4g} s): {trip.message}",
                          iteration, residual, trip)
        gap = trip.state[free] - x[free]
        residual = float(np.max(np.abs(gap)))
        if not np.isfinite(residual):
            return failed(x, "the return map is not finite", iteration, residual, trip)
        dp, _ = trip.map_jacobian(section)
        if residual <= options.tol:
            amplitude = orbit_amplitude(rhs, x, speed, trip.time, coordinate, settings)
            multipliers = np.linalg.eigvals(dp)
            multipliers = multipliers[np.argsort(-np.abs(multipliers), kind="stable")]
            if not amplitude >= options.min_amplitude:
                return PeriodicOrbit(speed, x, trip.time, amplitude, multipliers, trip.monodromy, False,
                                     f"collapsed onto the equilibrium: amplitude {amplitude:.3g} < min_amplitude "
                                     f"{options.min_amplitude:.3g}", iteration, residual)
            return PeriodicOrbit(speed, x, trip.time, amplitude, multipliers, trip.monodromy, True,
                                 f"converged: max |P(z) - z| = {residual:.3g} <= tol {options.tol:.3g}",
                                 iteration, residual)
        if iteration == options.max_iterations:
            break
        a = dp - np.eye(n - 1)
        if np.linalg.cond(a) > 1e13:
            return failed(x, "DP - I is singular (a Floquet multiplier at 1: fold or no isolated orbit)",
                          iteration, residual, trip)
        x[free] = x[free] + np.linalg.solve(a, -gap)
        period_guess = trip.time
    return failed(x, f"Newton did not converge in {options.max_iterations} iterations "
                     f"(residual {residual:.3g} > tol {options.tol:.3g})", options.max_iterations, residual)


__all__ = [
    "PeriodicOrbit",
    "ShootingOptions",
    "find_periodic_orbit",
    "orbit_amplitude",
]
