"""Pseudo-arclength continuation of a periodic orbit in speed, through folds.

Unknowns y = (z, V): the n − 1 free coordinates of the orbit's point on the Poincaré section and the speed.
Equations G(y) = P(z, V) − z = 0 (n − 1 of them, :mod:`.variational` gives A = [DP − I, ∂P/∂V]).  In scaled
variables u = (z/state_scale, V/speed_scale) the branch is followed by Keller's pseudo-arclength method:

* tangent t: the unit null vector of A·diag(scale) (last right singular vector), oriented so that tᵀ t_prev > 0;
* predictor u_p = u + h t;
* corrector: Newton on [G(y); tᵀ(u − u_p)] = 0 with the bordered Jacobian [A·diag(scale); tᵀ].

Step control: h grows by 1.3 after a corrector of ≤ 3 iterations and shrinks by 0.7 after one of more than 5;
a failed corrector, or a turn of the tangent by more than ``max_turn_deg``, halves h and retries.  Folds are
where the tangent's speed component changes sign between two points; each is located by Brent's method on the
arclength h ∈ (0, h_step) from the earlier point (the speed component of the tangent at the corrected point as
the function), so the fold speed is as accurate as the corrector.  On a non-smooth map (tabulated contact
geometry with two-point-contact jumps) Newton can fail at a trial point inside a step whose ends both converged;
the fold is then the extremum of the cubic Hermite interpolant of V(s) through those two corrected points and
their tangents, and is marked ``located = "hermite"`` (Keller, "Numerical solution of bifurcation and
nonlinear eigenvalue problems", in *Applications of Bifurcation Theory*, Academic Press 1977; Seydel 2010).

Stability of each point: all non-trivial Floquet multipliers (eigenvalues of DP) inside the unit circle.

The continuation stops, with the reason recorded, at the edge of the speed range (the step is shortened once to
end within EDGE_TOL·speed_scale of the edge, halved while the corrector overshoots it and re-aimed while the
corrector moves it off; no point outside the range is kept),
when the cycle's amplitude falls below the shooting ``min_amplitude`` (the branch ends at a Hopf point), when the
step falls below ``min_step``, or after ``max_points`` points.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from railopt.models.bifurcation.diagram import BifurcationDiagram, Fold
from railopt.models.bifurcation.integration import IntegrationSettings, Jacobian, RightHandSide
from railopt.models.bifurcation.limit_cycle import Coordinate
from railopt.models.bifurcation.periodic_orbit import PeriodicOrbit, ShootingOptions, orbit_amplitude
from railopt.models.bifurcation.section import PoincareSection
from railopt.models.bifurcation.variational import flow_to_section

EDGE_TOL = 1e-4  # the last point lies within EDGE_TOL·speed_scale (m/s) of the speed range's edge


@dataclass(frozen=True)
class ContinuationOptions:
    """Step control and scaling of the pseudo-arclength continuation.

    Attributes
    ----------
    step, min_step, max_step : float
        First, smallest and largest arclength step in scaled units (default 0.02, 1e-5, 0.2).
    max_points : int
        Points on the branch before stopping (default 400).
    state_scale : float
        The free coordinates are divided by this (state units; choose the cycle amplitude's order).
    speed_scale : float
        The speed is divided by this (m/s; choose the speed change over which the amplitude changes by
        ``state_scale``).
    corrector_iterations : int
        Newton steps of one corrector (default 8).
    max_turn_deg : float
        Largest angle between successive tangents (default 20°).
    points_after_fold : int or None
        Stop once this many points lie beyond the first fold (None: go on until another rule fires).  A
        nonlinear critical speed needs only the fold; the unstable branch beyond it (the basin's edge) costs the
        rest.
    """

    step: float = 0.02
    min_step: float = 1e-5
    max_step: float = 0.2
    max_points: int = 400
    state_scale: float = 1.0
    speed_scale: float = 1.0
    corrector_iterations: int = 8
    max_turn_deg: float = 20.0
    points_after_fold: int | None = None

    def __post_init__(self) -> None:
        for name in ("step", "min_step", "max_step", "state_scale", "speed_scale", "max_turn_deg"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name}: must be > 0, got {getattr(self, name)!r}")
        if not self.min_step <= self.step <= self.max_step:
            raise ValueError(f"step: must lie in [min_step, max_step] = [{self.min_step}, {self.max_step}]")
        for name in ("max_points", "corrector_iterations"):
            value = getattr(self, name)
            if not (isinstance(value, int) and value >= 2):
                raise ValueError(f"{name}: must be an int >= 2, got {value!r}")
        if self.points_after_fold is not None and not (isinstance(self.points_after_fold, int)
                                                       and self.points_after_fold >= 1):
            raise ValueError(f"points_after_fold: must be an int >= 1 or None, got {self.points_after_fold!r}")


@dataclass
class _Point:
    u: np.ndarray  # scaled (z, V)
    tangent: np.ndarray
    period: float
    multipliers: np.ndarray
    iterations: int


class _Branch:
    """The corrector and tangent of one continuation run (shared state: rhs, section, scaling)."""

    def __init__(self, rhs: RightHandSide, n: int, section: PoincareSection, coordinate: Coordinate,
                 options: ContinuationOptions, shooting: ShootingOptions, settings: IntegrationSettings,
                 jacobian: Jacobian | None) -> None:
        self.rhs, self.n, self.section, self.coordinate = rhs, n, section, coordinate
        self.options, self.shooting, self.settings, self.jacobian = options, shooting, settings, jacobian
        self.scale = np.r_[np.full(n - 1, options.state_scale), options.speed_scale]

    def state(self, u: np.ndarray) -> tuple[np.ndarray, float]:
        y = u * self.scale
        return self.section.place(y[:-1], self.n), float(y[-1])

    def evaluate(self, u: np.ndarray, period_guess: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, float] | None:
        """(G, A·diag(scale), DP, period) at u; None when the trajectory did not return."""
        x, speed = self.state(u)
        trip = flow_to_section(self.rhs, x, speed, self.section, t_arm=self.shooting.arm_fraction * period_guess,
                               t_max=self.shooting.max_return_factor * period_guess, settings=self.settings,
                               jacobian=self.jacobian)
        if not trip.returned or not np.all(np.isfinite(trip.monodromy)):
            return None
        free = self.section.free(self.n)
        dp, dv = trip.map_jacobian(self.section)
        a = np.column_stack([dp - np.eye(self.n - 1), dv]) * self.scale
        return trip.state[free] - x[free], a, dp, trip.time

    @staticmethod
    def tangent(a: np.ndarray, previous: np.ndarray) -> np.ndarray:
        t = np.linalg.svd(a)[2][-1]
        return t if t @ previous >= 0 else -t

    def correct(self, u_pred: np.ndarray, direction: np.ndarray, period_guess: float) -> _Point | None:
        """Newton on [G; directionᵀ(u − u_pred)] from u_pred; None when it fails."""
        u = u_pred.copy()
        for iteration in range(self.options.corrector_iterations + 1):
            found = self.evaluate(u, period_guess)
            if found is None:
                return None
            g, a, dp, period = found
            if np.max(np.abs(g)) <= self.shooting.tol:
                mult = np.linalg.eigvals(dp)
                return _Point(u, self.tangent(a, direction), period, mult[np.argsort(-np.abs(mult), kind="stable")],
                              iteration)
            if iteration == self.options.corrector_iterations:
                return None
            bordered = np.vstack([a, direction])
            rhs = np.r_[-g, -direction @ (u - u_pred)]
            try:
                u = u + np.linalg.solve(bordered, rhs)
            except np.linalg.LinAlgError:
                return None
            period_guess = period
        return None


def continue_periodic_orbit(rhs: RightHandSide, orbit: PeriodicOrbit, section: PoincareSection,
                            coordinate: Coordinate, *, speed_range: tuple[float, float], direction: int = -1,
                            options: ContinuationOptions | None = None, shooting: ShootingOptions | None = None,
                            settings: IntegrationSettings | None = None, jacobian: Jacobian | None = None,
                            linear_critical_speed: float = math.nan,
                            progress: Callable[[str], None] | None = None) -> BifurcationDiagram:
    """Follow ``orbit``'s branch in speed, through folds, until a stopping rule fires.

    Parameters
    ----------
    rhs : callable
        ``rhs(t, x, speed) -> dx/dt`` (n,) → (n,), autonomous; speed in m/s.
    orbit : PeriodicOrbit
        A converged orbit on ``section`` (from :func:`.periodic_orbit.find_periodic_orbit`).
    section : PoincareSection
        The section the orbit was found on.
    coordinate : int or callable
        The watched coordinate for the amplitude column.
    speed_range : (float, float)
        (V_min, V_max) in m/s; leaving it stops the continuation.
    direction : int
        −1: start towards lower speeds (the usual way to the fold); +1: higher.
    options : ContinuationOptions, optional
    shooting : ShootingOptions, optional
        Newton tolerance, return window and min_amplitude, shared with the shooting.
    settings : IntegrationSettings, optional
    jacobian : callable, optional
        ``jacobian(t, x, speed) -> (n, n)``; central differences when omitted.
    linear_critical_speed : float
        Stored in the diagram for reference (m/s).
    progress : callable, optional
        ``progress(line)`` after each point (its speed, amplitude, largest multiplier) and at each fold.

    Returns
    -------
    BifurcationDiagram

    Raises
    ------
    ValueError
        If ``orbit`` did not converge, lies outside ``speed_range`` or the arguments are malformed.
    """
    options = options or ContinuationOptions()
    shooting = shooting or ShootingOptions()
    settings = settings or IntegrationSettings()
    if not orbit.converged:
        raise ValueError(f"orbit: must be converged, got: {orbit.reason}")
    low, high = (float(v) for v in speed_range)
    if not low < high:
        raise ValueError(f"speed_range: need V_min < V_max, got {speed_range!r}")
    if not low <= orbit.speed <= high:
        raise ValueError(f"orbit: speed {orbit.speed} outside speed_range {speed_range!r}")
    if direction not in (1, -1):
        raise ValueError(f"direction: must be +1 or -1, got {direction!r}")
    n = orbit.point.size
    section.check(n)
    free = section.free(n)
    branch = _Branch(rhs, n, section, coordinate, options, shooting, settings, jacobian)
    u0 = np.r_[orbit.point[free], orbit.speed] / branch.scale
    along = np.zeros(n)
    along[-1] = direction
    first = branch.correct(u0, along, orbit.period)
    if first is None:
        raise ValueError("orbit: the corrector failed at the starting orbit (tolerances inconsistent?)")
    points = [first]
    folds: list[Fold] = []
    branch_ids = [0]
    amplitudes = [orbit_amplitude(rhs, *branch.state(first.u), first.period, coordinate, settings)]
    h = options.step
    max_turn = math.cos(math.radians(options.max_turn_deg))
    reason = f"reached max_points = {options.max_points}"
    aimed_at_edge = False
    while len(points) < options.max_points:
        here = points[-1]
        new = branch.correct(here.u + h * here.tangent, here.tangent, here.period)
        if new is None or new.tangent @ here.tangent < max_turn:
            h /= 2
            if h < options.min_step:
                reason = (f"step below min_step {options.min_step:g} near V = "
                          f"{here.u[-1] * options.speed_scale:.6g} m/s (corrector failed or branch turned sharply)")
                break
            continue
        speed = new.u[-1] * options.speed_scale
        if not low <= speed <= high:
            edge = (low if speed < low else high) / options.speed_scale
            to_edge = (edge - here.u[-1]) / here.tangent[-1] if here.tangent[-1] != 0 else 0.0
            shorter = min(0.999 * to_edge, 0.5 * h)  # aim at the edge; halve while the corrector overshoots it
            if shorter >= options.min_step:
                h, aimed_at_edge = shorter, True
                continue
            reason = f"reached the edge of the speed range [{low:g}, {high:g}] m/s (next point at {speed:.6g} m/s)"
            break
        amplitude = orbit_amplitude(rhs, *branch.state(new.u), new.period, coordinate, settings)
        if not amplitude >= shooting.min_amplitude:
            reason = (f"cycle amplitude {amplitude:.3g} below min_amplitude {shooting.min_amplitude:.3g} near "
                      f"V = {speed:.6g} m/s (the branch ends at a Hopf point)")
            break
        if np.sign(new.tangent[-1]) != np.sign(here.tangent[-1]) and here.tangent[-1] != 0:
            try:
                folds.append(_locate_fold(branch, here, new, h, (amplitudes[-1], amplitude), rhs, coordinate,
                                            settings))
            except ValueError as error:
                reason = (f"a fold between {here.u[-1] * options.speed_scale:.6g} and {speed:.6g} m/s could not "
                          f"be located: {error}")
                break
        points.append(new)
        amplitudes.append(amplitude)
        branch_ids.append(len(folds))
        if progress is not None:
            largest = float(np.max(np.abs(new.multipliers))) if new.multipliers.size else math.nan
            progress(f"point {len(points)}: {speed:.4f} m/s, amplitude {amplitude:.4g}, |multiplier| {largest:.4f}"
                     + (f", fold at {folds[-1].speed:.4f} m/s ({folds[-1].located})"
                        if branch_ids[-1] != branch_ids[-2] else ""))
        beyond = sum(1 for b in branch_ids if b >= 1)
        if options.points_after_fold is not None and beyond >= options.points_after_fold:
            reason = f"{beyond} points beyond the fold at {folds[0].speed:.6g} m/s (points_after_fold)"
            break
        if aimed_at_edge:
            if min(speed - low, high - speed) <= EDGE_TOL * options.speed_scale:
                reason = (f"reached the edge of the speed range [{low:g}, {high:g}] m/s "
                          f"(last point at {speed:.8g} m/s)")
                break
            aimed_at_edge = False  # the corrector moved the point off the edge: aim again
        if new.iterations <= 3:
            h = min(h * 1.3, options.max_step)
        elif new.iterations > 5:
            h = max(h * 0.7, options.min_step)
    ys = np.array([p.u * branch.scale for p in points])
    mults = np.array([p.multipliers for p in points])
    return BifurcationDiagram(
        speed=ys[:, -1], amplitude=np.array(amplitudes), period=np.array([p.period for p in points]),
        multipliers=mults, stable=np.all(np.abs(mults) < 1.0, axis=1), branch=np.array(branch_ids),
        points=np.array([branch.state(p.u)[0] for p in points]), folds=tuple(folds), stop_reason=reason,
        linear_critical_speed=float(linear_critical_speed))


def _locate_fold(branch: _Branch, here: _Point, new: _Point, h: float, amplitudes: tuple[float, float],
                 rhs: RightHandSide, coordinate: Coordinate, settings: IntegrationSettings) -> Fold:
    """Brent's method on the arclength s ∈ (0, h) for a zero of the tangent's speed component; when the corrector
    fails inside the step, the cubic Hermite extremum through the closest pair of corrected points around the turn
    (``here``, ``new`` and Brent's points so far; see the module docstring).  ``amplitudes``: the watched
    coordinate's amplitude at ``here`` and ``new``."""
    cache: dict[float, _Point] = {}

    def speed_component(s: float) -> float:
        if s == 0.0:
            return float(here.tangent[-1])
        point = branch.correct(here.u + s * here.tangent, here.tangent, here.period)
        if point is None:
            raise _CorrectorFailed(s)
        cache[s] = point
        return float(point.tangent[-1])

    try:
        if speed_component(0.0) * speed_component(h) > 0:
            raise ValueError("fold: the tangent's speed component has the same sign at both ends of the step")
        s_fold = brentq(speed_component, 0.0, h, xtol=1e-12 * h, rtol=4 * np.finfo(float).eps)
    except _CorrectorFailed:
        return _hermite_fold(branch, here, new, h, amplitudes, cache, rhs, coordinate, settings)
    point = cache.get(s_fold) or branch.correct(here.u + s_fold * here.tangent, here.tangent, here.period)
    x, speed = branch.state(point.u)
    amplitude = orbit_amplitude(rhs, x, speed, point.period, coordinate, settings)
    between = (float(here.u[-1] * branch.scale[-1]), float(new.u[-1] * branch.scale[-1]))
    return Fold(float(speed), amplitude, point.period, x, located="brent", between=between)


def _hermite_fold(branch: _Branch, here: _Point, new: _Point, h: float, amplitudes: tuple[float, float],
                  cache: dict[float, _Point], rhs: RightHandSide, coordinate: Coordinate,
                  settings: IntegrationSettings) -> Fold:
    """The fold from :func:`hermite_turn` on the closest pair of corrected points whose tangents' speed components
    change sign; the point on the section, period and amplitude interpolated linearly between that pair."""
    known = {0.0: (here, amplitudes[0]), **{s: (p, math.nan) for s, p in cache.items() if s != h},
             h: (new, amplitudes[1])}
    ordered = sorted(known.items())
    pairs = [(a, b) for a, b in zip(ordered, ordered[1:], strict=False)
             if a[1][0].tangent[-1] * b[1][0].tangent[-1] <= 0]
    (s0, (p0, a0)), (s1, (p1, a1)) = min(pairs, key=lambda pair: pair[1][0] - pair[0][0])
    speed_scaled, w = hermite_turn(p0.u, p0.tangent, p1.u, p1.tangent)
    scale = branch.scale
    x = branch.section.place(((1 - w) * p0.u[:-1] + w * p1.u[:-1]) * scale[:-1], branch.n)
    amplitude_at = [a if math.isfinite(a) else orbit_amplitude(rhs, *branch.state(p.u), p.period, coordinate,
                                                                settings) for p, a in ((p0, a0), (p1, a1))]
    return Fold(float(speed_scaled * scale[-1]), (1 - w) * amplitude_at[0] + w * amplitude_at[1],
                (1 - w) * p0.period + w * p1.period, x, located="hermite",
                between=(float(p0.u[-1] * scale[-1]), float(p1.u[-1] * scale[-1])))


class _CorrectorFailed(Exception):
    """The corrector did not converge at a trial arclength while locating a fold."""


def hermite_turn(u0: np.ndarray, t0: np.ndarray, u1: np.ndarray, t1: np.ndarray) -> tuple[float, float]:
    """Extremum of the last coordinate along a branch between two points, from a cubic Hermite interpolant.

    The branch between ``u0`` and ``u1`` (scaled points, last coordinate the parameter) is parametrised by
    arclength s ∈ [0, L] with L = |u1 − u0| (the chord); V(s) is the cubic with V(0) = u0[−1], V(L) = u1[−1],
    V'(0) = t0[−1], V'(L) = t1[−1] (unit tangents), whose derivative — a quadratic — is zero at the turn.

    Parameters
    ----------
    u0, u1 : (m,) ndarray
        Two points on the branch (scaled).
    t0, t1 : (m,) ndarray
        Unit tangents there, oriented along the branch; ``t0[-1]`` and ``t1[-1]`` of opposite signs.

    Returns
    -------
    (float, float)
        The extremal value of the last coordinate (scaled) and the fraction w = s/L ∈ [0, 1] where it lies.

    Raises
    ------
    ValueError
        If the tangents' last components do not change sign (no turn between the points).
    """
    d0, d1 = float(t0[-1]), float(t1[-1])
    if d0 * d1 > 0:
        raise ValueError("hermite_turn: the tangents' last components have the same sign (no turn)")
    length = float(np.linalg.norm(np.asarray(u1) - np.asarray(u0)))
    v0, v1 = float(u0[-1]), float(u1[-1])
    # V(w) on w = s/L ∈ [0, 1]: Hermite basis with slopes m0 = L·d0, m1 = L·d1; V'(w) = a w² + b w + c
    m0, m1 = length * d0, length * d1
    dv = v1 - v0  # differenced once: the coefficients then keep their accuracy when v0 ≈ v1 are large
    a = -6 * dv + 3 * (m0 + m1)
    b = 6 * dv - 4 * m0 - 2 * m1
    c = m0
    if abs(a) <= 1e-14 * (abs(b) + abs(c)):
        roots = [-c / b] if b != 0 else [0.0]
    else:
        disc = math.sqrt(max(b * b - 4 * a * c, 0.0))
        q = -0.5 * (b + math.copysign(disc, b))  # the stable quadratic formula
        roots = [q / a, c / q] if q != 0 else [0.0]
    w = min((r for r in roots if -1e-12 <= r <= 1 + 1e-12), key=lambda r: abs(r - 0.5), default=None)
    if w is None:
        raise ValueError("hermite_turn: no turn of the cubic inside the step")
    w = min(max(w, 0.0), 1.0)
    h10, h01, h11 = w**3 - 2 * w**2 + w, -2 * w**3 + 3 * w**2, w**3 - w**2
    return v0 + h01 * dv + h10 * m0 + h11 * m1, w  # h00 + h01 = 1


__all__ = [
    "EDGE_TOL",
    "ContinuationOptions",
    "continue_periodic_orbit",
    "hermite_turn",
]
