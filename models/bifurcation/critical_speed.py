"""The nonlinear critical speed end to end: descending ramp, shooting at the last steady speed, continuation.

1. :func:`.ramp.speed_ramp` runs the descending ramp with the state carried over and brackets the fold
   (V_low, V_high].
2. From the state at the end of the dwell at V_high the trajectory is run to the Poincaré section and
   :func:`.periodic_orbit.find_periodic_orbit` converges the stable cycle there (period guess 1/frequency from
   the detector).
3. :func:`.continuation.continue_periodic_orbit` follows it up to the top of the speed range and down,
   through the fold, onto the unstable branch, until a stopping rule fires; the two runs are joined in order
   of arclength (highest speed of the stable branch first).

The diagram returned carries the ramp; ``diagram.nonlinear_critical_speed()`` gives the fold speed confirmed
by the ramp's bracket.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.integrate import solve_ivp

from railopt.models.bifurcation.continuation import ContinuationOptions, continue_periodic_orbit
from railopt.models.bifurcation.diagram import BifurcationDiagram
from railopt.models.bifurcation.integration import IntegrationSettings, Jacobian, RightHandSide, check_state
from railopt.models.bifurcation.limit_cycle import Coordinate, CycleTolerances
from railopt.models.bifurcation.periodic_orbit import ShootingOptions, find_periodic_orbit
from railopt.models.bifurcation.ramp import Dwell, RampResult, speed_ramp
from railopt.models.bifurcation.section import PoincareSection


def _empty(n: int, reason: str, ramp: RampResult, linear_critical_speed: float) -> BifurcationDiagram:
    none = np.zeros(0)
    return BifurcationDiagram(none, none, none, np.zeros((0, n - 1), complex), np.zeros(0, bool),
                              np.zeros(0, int), np.zeros((0, n)), (), reason, float(linear_critical_speed), ramp)


def bifurcation_diagram(rhs: RightHandSide, x0: np.ndarray, speeds: np.ndarray, dwell: Dwell,
                        coordinate: Coordinate, section: PoincareSection, *, sample_rate_hz: float,
                        speed_range: tuple[float, float] | None = None, window: float = 0.5,
                        tolerances: CycleTolerances | None = None, shooting: ShootingOptions | None = None,
                        continuation: ContinuationOptions | None = None,
                        settings: IntegrationSettings | None = None, jacobian: Jacobian | None = None,
                        linear_critical_speed: float = math.nan) -> BifurcationDiagram:
    """Ramp, shoot and continue: the bifurcation diagram of the cycle the ramp loses, with the ramp attached.

    Parameters
    ----------
    rhs : callable
        ``rhs(t, x, speed) -> dx/dt``, (n,) → (n,), autonomous; speed in m/s.
    x0 : (n,) ndarray
        State at the start of the ramp (on or near the large cycle at ``speeds[0]``).
    speeds : (k,) array_like
        Strictly decreasing ramp speeds (m/s).
    dwell : Dwell
    coordinate : int or callable
        The watched coordinate (amplitudes in its units).
    section : PoincareSection
    sample_rate_hz : float
        Detector sampling (Hz).
    speed_range : (float, float), optional
        Continuation range (m/s); default (min(speeds), max(speeds)).
    window, tolerances : see :func:`.ramp.speed_ramp`.
    shooting, continuation, settings, jacobian : see :func:`.continuation.continue_periodic_orbit`.
    linear_critical_speed : float
        Stored for reference (m/s).

    Returns
    -------
    BifurcationDiagram
        Empty (no points) with the reason in ``stop_reason`` when the ramp never lost a steady cycle or no
        orbit converged at its last steady speed.
    """
    settings = settings or IntegrationSettings()
    x0 = check_state(x0)
    n = x0.size
    section.check(n)
    ramp = speed_ramp(rhs, x0, speeds, dwell, coordinate, sample_rate_hz=sample_rate_hz, window=window,
                      settings=settings, tolerances=tolerances)
    k = ramp.last_steady
    if k is None:
        return _empty(n, "the ramp never lost a steady cycle: no fold bracketed", ramp, linear_critical_speed)
    speed = float(ramp.speeds[k])
    period = 1.0 / ramp.verdicts[k].frequency_hz
    event = section.event()
    arrived = solve_ivp(lambda t, x: rhs(t, x, speed), (0.0, 3 * period), ramp.states[k], events=event,
                        **settings.options())
    if not arrived.t_events[0].size:
        return _empty(n, f"the ramp's state at {speed:g} m/s did not reach the section", ramp, linear_critical_speed)
    orbit = find_periodic_orbit(rhs, arrived.y_events[0][0], speed, section, period, coordinate,
                                options=shooting, settings=settings, jacobian=jacobian)
    if not orbit.converged:
        return _empty(n, f"no periodic orbit at the last steady ramp speed {speed:g} m/s: {orbit.reason}", ramp,
                      linear_critical_speed)
    low, high = speed_range if speed_range is not None else (float(np.min(speeds)), float(np.max(speeds)))
    up, down = (continue_periodic_orbit(rhs, orbit, section, coordinate, speed_range=(low, high),
                                        direction=direction, options=continuation, shooting=shooting,
                                        settings=settings, jacobian=jacobian,
                                        linear_critical_speed=linear_critical_speed) for direction in (1, -1))
    return dataclasses.replace(_joined(up, down), ramp=ramp)


def _joined(up: BifurcationDiagram, down: BifurcationDiagram) -> BifurcationDiagram:
    """One diagram from the two continuations out of the same start: ``up`` reversed, then ``down``."""
    passed = len(up.folds)

    def join(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return np.concatenate([a[:0:-1], b])

    return BifurcationDiagram(
        speed=join(up.speed, down.speed), amplitude=join(up.amplitude, down.amplitude),
        period=join(up.period, down.period), multipliers=join(up.multipliers, down.multipliers),
        stable=join(up.stable, down.stable), branch=join(passed - up.branch, down.branch + passed),
        points=join(up.points, down.points), folds=(*up.folds[::-1], *down.folds),
        stop_reason=f"upwards: {up.stop_reason}; downwards: {down.stop_reason}",
        linear_critical_speed=down.linear_critical_speed)


__all__ = [
    "bifurcation_diagram",
]
